//! Planning a synchronising phase (seed 001, chapters 3-7 and 13): the refusals, the
//! optimisation steps that choose the polynomials, and the checks of the sync mode.
//!
//! Position-based phases are written over the master's travel `tau >= 0` from the coupling
//! position, so a master moving in the negative direction needs no special case: slope
//! `k = ds/dtau` is the slave velocity over the master speed `w = |v_master|`, the sync
//! slope is `ratio * dir`. For the master at constant velocity (what the characteristic
//! values assume) time is `tau / w`.

use super::profile::{Charac, Domain, Profile, Shape};
use super::shape::{
    change_time, change_time_from, jerk_limited_change, phases_to_pieces, quintic, slope_change,
    slope_change_travel, straight, Limits,
};
use crate::setpoint::Kinematic;
use hli::calls::saw::sync_mask as m;
use hli::calls::saw::SawError;

/// What to synchronise on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SyncOn {
    /// MC_GearInVelo: reach the sync velocity as fast as the limits allow.
    Velocity,
    /// MC_GearInPos: reach the sync velocity exactly at these positions.
    Position {
        /// MasterSyncPosition.
        master: f64,
        /// SlaveSyncPosition.
        slave: f64,
    },
}

/// A coupling command, checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SawRequest {
    /// Velocity or position sync.
    pub on: SyncOn,
    /// `GEARINSYNCMODE_TIMEBASED` (velocity sync only).
    pub time_based: bool,
    /// Check and operation bits.
    pub mask: u32,
    /// Coupling factor (numerator / denominator, x 1/cos(alpha) for a diagonal saw).
    pub ratio: f64,
    /// The limits of the synchronising phase.
    pub limits: Limits,
}

/// The planned phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plan {
    /// The slave profile.
    pub profile: Profile,
    /// Its characteristic values (master at constant velocity).
    pub charac: Charac,
    /// Master velocity at coupling (after IGNOREMASTERACC nothing else of it is used).
    pub master_velocity: f64,
}

/// The slave's software limits the MINPOS/MAXPOS checks use.
pub type SoftLimits = Option<[f64; 2]>;

/// The coupling factor of a diagonal saw whose slave runs at `alpha` (radians) to the
/// master: the slave's component along the master then moves with `ratio` times the master.
pub fn diagonal_ratio(alpha: f64, ratio: f64) -> Result<f64, SawError> {
    let c = alpha.cos();
    if !(alpha.is_finite() && ratio.is_finite()) {
        return Err(SawError::NotFinite);
    }
    if c.abs() < 1e-9 {
        return Err(SawError::RatioZero);
    }
    Ok(ratio / c)
}

/// The coupling factor from the block's numerator and denominator.
pub fn gear_ratio(numerator: f64, denominator: u32) -> Result<f64, SawError> {
    if !numerator.is_finite() {
        return Err(SawError::NotFinite);
    }
    if numerator == 0.0 || denominator == 0 {
        return Err(SawError::RatioZero);
    }
    Ok(numerator / denominator as f64)
}

/// Which check failed, as the command reports it.
fn failed(mask: u32, detailed: SawError) -> SawError {
    if mask & m::DETAILEDERRORCODES != 0 {
        detailed
    } else {
        SawError::Limit
    }
}

/// Relative slack of the checks (rounding of the polynomials' own arithmetic).
const SLACK: f64 = 1e-9;

fn over(value: f64, limit: f64) -> bool {
    value > limit + SLACK * (1.0 + limit.abs())
}

/// The acceleration checks alone (step 1 and 2 fall back when one of them fails).
fn acc_ok(c: &Charac, req: &SawRequest) -> bool {
    !((req.mask & m::MAXACC != 0 && over(c.speed_up, req.limits.acceleration))
        || (req.mask & m::MAXDEC != 0 && over(c.slow_down, req.limits.deceleration)))
}

/// Every active check on a phase from slave `start` to `end` (positions and velocities).
fn check(
    c: &Charac,
    req: &SawRequest,
    soft: SoftLimits,
    start: [f64; 2],
    end: [f64; 2],
) -> Result<(), SawError> {
    let v = &c.values;
    let mask = req.mask;
    let on = |bit: u32| mask & bit != 0;
    let fail = |e| Err(failed(mask, e));
    if let Some([lo, hi]) = soft {
        if on(m::MINPOS) && over(lo, v.fSlavePosMin) {
            return fail(SawError::CheckMinPos);
        }
        if on(m::MAXPOS) && over(v.fSlavePosMax, hi) {
            return fail(SawError::CheckMaxPos);
        }
    }
    let l = &req.limits;
    if on(m::MAXVELO) && over(v.fSlaveVeloMax.abs().max(v.fSlaveVeloMin.abs()), l.velocity) {
        return fail(SawError::CheckMaxVelo);
    }
    if on(m::MAXACC) && over(c.speed_up, l.acceleration) {
        return fail(SawError::CheckMaxAcc);
    }
    if on(m::MAXDEC) && over(c.slow_down, l.deceleration) {
        return fail(SawError::CheckMaxDec);
    }
    if on(m::MAXJERK) && over(v.fSlaveJerkMax.abs().max(v.fSlaveJerkMin.abs()), l.jerk) {
        return fail(SawError::CheckMaxJerk);
    }
    // Direction of the slave's travel: towards its end position, else its sync velocity.
    let dir = if end[0] != start[0] {
        (end[0] - start[0]).signum()
    } else {
        end[1].signum()
    };
    let (beyond_end, behind_start) = if dir >= 0.0 {
        (v.fSlavePosMax - end[0], start[0] - v.fSlavePosMin)
    } else {
        (end[0] - v.fSlavePosMin, v.fSlavePosMax - start[0])
    };
    let scale = SLACK * (1.0 + start[0].abs() + end[0].abs());
    if on(m::OVERSHOOTPOS) && beyond_end > scale {
        return fail(SawError::CheckOvershootPos);
    }
    if on(m::UNDERSHOOTPOS) && behind_start > scale {
        return fail(SawError::CheckUndershootPos);
    }
    if on(m::OVERSHOOTVELO) && over(v.fSlaveVeloMax, start[1].max(end[1])) {
        return fail(SawError::CheckOvershootVelo);
    }
    if on(m::UNDERSHOOTVELO) && over(start[1].min(end[1]), v.fSlaveVeloMin) {
        return fail(SawError::CheckUndershootVelo);
    }
    if on(m::OVERSHOOTVELOZERO) && over(v.fSlaveVeloMax, 0.0) {
        return fail(SawError::CheckOvershootVeloZero);
    }
    if on(m::UNDERSHOOTVELOZERO) && over(0.0, v.fSlaveVeloMin) {
        return fail(SawError::CheckUndershootVeloZero);
    }
    Ok(())
}

/// The refusals of chapter 13 and of the block's inputs.
fn validate(req: &SawRequest, master: &Kinematic, slave: &Kinematic) -> Result<(), SawError> {
    let l = &req.limits;
    let values = [
        l.velocity,
        l.acceleration,
        l.deceleration,
        l.jerk,
        req.ratio,
    ];
    let states = [
        master.position,
        master.velocity,
        master.acceleration,
        slave.position,
        slave.velocity,
        slave.acceleration,
    ];
    if values.iter().chain(states.iter()).any(|v| !v.is_finite()) {
        return Err(SawError::NotFinite);
    }
    if req.mask & !(m::CHECKS | m::OPERATIONS) != 0 {
        return Err(SawError::Mode);
    }
    if req.ratio == 0.0 {
        return Err(SawError::RatioZero);
    }
    if [l.velocity, l.acceleration, l.deceleration, l.jerk]
        .iter()
        .any(|v| *v < 0.0)
    {
        return Err(SawError::NegativeLimit);
    }
    if [l.velocity, l.acceleration, l.deceleration, l.jerk].contains(&0.0) {
        // The caller puts the axis's own limits in place of 0; an axis without one is bad
        // input as well.
        return Err(SawError::NegativeLimit);
    }
    if master.velocity == 0.0 && slave.velocity != 0.0 {
        return Err(SawError::MasterAtRest);
    }
    if let SyncOn::Position {
        master: ms,
        slave: ss,
    } = req.on
    {
        if !(ms.is_finite() && ss.is_finite()) {
            return Err(SawError::NotFinite);
        }
        if req.time_based {
            return Err(SawError::TimeBasedPosition);
        }
        if master.velocity == 0.0 {
            return Err(SawError::MasterStands);
        }
        let dir = master.velocity.signum();
        if (ms - master.position) * dir <= 0.0 {
            return Err(SawError::MasterSyncNotAhead);
        }
        if (ss - slave.position) * dir * req.ratio.signum() <= 0.0 {
            return Err(SawError::SlaveSyncNotAhead);
        }
    }
    Ok(())
}

/// Plans the synchronising phase of a slave at `slave` onto a master at `master` (their
/// set-points at coupling). Refused with the error the command reports; nothing changes
/// then.
pub fn plan(
    req: &SawRequest,
    master: &Kinematic,
    slave: &Kinematic,
    soft: SoftLimits,
) -> Result<Plan, SawError> {
    validate(req, master, slave)?;
    let master_acc = if req.mask & m::IGNOREMASTERACC != 0 {
        0.0
    } else {
        master.acceleration
    };
    let slave_acc = if req.mask & m::IGNORESLAVEACC != 0 {
        0.0
    } else {
        slave.acceleration
    };
    let vm = master.velocity;
    let v_sync = req.ratio * vm;
    let start = [slave.position, slave.velocity, slave_acc, 0.0];
    let (profile, known) = if req.time_based {
        (
            time_based(req, slave.position, slave.velocity, slave_acc, v_sync),
            None,
        )
    } else if vm == 0.0 {
        // Master and slave at rest: synchronous at once (the slave stands with the master).
        let p = Profile::new(
            Domain::Master {
                m0: master.position,
                dir: 1.0,
            },
            Shape::Immediate,
            &[straight(0.0, 0.0, slave.position, 0.0)],
        );
        (p, None)
    } else {
        let dir = vm.signum();
        let w = vm.abs();
        let k0 = slave.velocity / w;
        // Slave acceleration a = c w^2 + k a_tau, a_tau = the master's along its direction.
        let c0 = (slave_acc - k0 * master_acc * dir) / (w * w);
        let travel = TravelFrame {
            m0: master.position,
            dir,
            w,
            s0: slave.position,
            k0,
            c0,
            k1: req.ratio * dir,
            accelerated: master_acc != 0.0 || slave_acc != 0.0,
        };
        match req.on {
            SyncOn::Velocity => (travel.on_velocity(req), None),
            SyncOn::Position {
                master: ms,
                slave: ss,
            } => travel.on_position(req, (ms - master.position) * dir, ss),
        }
    };
    let charac = known.unwrap_or_else(|| profile.charac(master.position, vm, start));
    let end = profile.end_state(vm);
    let finite = charac.values.fields().iter().all(|(_, v)| v.is_finite())
        && profile
            .pieces()
            .iter()
            .all(|p| p.poly.iter().all(|c| c.is_finite()));
    if !finite {
        return Err(SawError::NotFinite);
    }
    let end_pv = match req.on {
        SyncOn::Position { slave: ss, .. } => [ss, v_sync],
        SyncOn::Velocity => [end[0], v_sync],
    };
    check(&charac, req, soft, [slave.position, slave.velocity], end_pv)?;
    Ok(Plan {
        profile,
        charac,
        master_velocity: vm,
    })
}

/// Time-based: the jerk-limited velocity change to the sync velocity (all slave limits).
fn time_based(req: &SawRequest, s0: f64, v0: f64, a0: f64, v_sync: f64) -> Profile {
    if v0 == v_sync && a0 == 0.0 {
        return Profile::new(
            Domain::Time,
            Shape::Immediate,
            &[straight(0.0, 0.0, s0, v0)],
        );
    }
    let phases = jerk_limited_change(v0, a0, v_sync, &req.limits);
    let (pieces, n) = phases_to_pieces(0.0, s0, v0, a0, &phases);
    Profile::new(Domain::Time, Shape::JerkLimited, &pieces[..n])
}

/// The position-based frame: the slave as a function of master travel.
struct TravelFrame {
    m0: f64,
    dir: f64,
    /// Master speed at coupling.
    w: f64,
    s0: f64,
    /// Slave slope and curvature at coupling.
    k0: f64,
    c0: f64,
    /// Sync slope.
    k1: f64,
    /// Master or slave accelerated at coupling (after IGNOREMASTERACC / IGNORESLAVEACC).
    accelerated: bool,
}

impl TravelFrame {
    fn domain(&self) -> Domain {
        Domain::Master {
            m0: self.m0,
            dir: self.dir,
        }
    }

    /// On the synchronous line already: no phase.
    fn immediate(&self) -> Profile {
        Profile::new(
            self.domain(),
            Shape::Immediate,
            &[straight(0.0, 0.0, self.s0, self.k0)],
        )
    }

    /// Master travel a smooth slope change from `ka` to `kb` needs to keep the limits.
    fn change_len(&self, ka: f64, kb: f64, limits: &Limits) -> f64 {
        self.w * change_time(ka * self.w, kb * self.w, limits)
    }

    /// Velocity sync: one smooth slope change to the sync slope as short as the limits
    /// allow (monotone in velocity when the slave starts unaccelerated).
    fn on_velocity(&self, req: &SawRequest) -> Profile {
        if self.k0 == self.k1 && self.c0 == 0.0 {
            return self.immediate();
        }
        let w = self.w;
        let a0 = self.c0 * w * w;
        let len = w * change_time_from(self.k0 * w, a0, self.k1 * w, &req.limits);
        let p = slope_change(0.0, len, self.s0, self.k0, self.c0, self.k1);
        Profile::new(self.domain(), Shape::P5, &[p])
    }

    /// Position sync over master travel `x` to slave position `s1`: the optimisation steps
    /// of chapter 7. The characteristic values of the chosen phase come along when a step
    /// needed them already.
    fn on_position(&self, req: &SawRequest, x: f64, s1: f64) -> (Profile, Option<Charac>) {
        let d = s1 - self.s0;
        let p5 = || {
            Profile::new(
                self.domain(),
                Shape::P5,
                &[quintic(
                    0.0,
                    x,
                    [self.s0, self.k0, self.c0],
                    [s1, self.k1, 0.0],
                )],
            )
        };
        // Optimisations only for a master and slave without acceleration at coupling (seed
        // 001, chapter 7: both axes must be free of acceleration when they couple).
        // The curvature `c0` alone is 0 for a standing slave under an accelerating master
        // (and for a slave accelerating with k0 x the master's), so the master's acceleration
        // is asked for itself: either one accelerated gives the checked plain P5.
        if self.accelerated || self.c0 != 0.0 {
            return (p5(), None);
        }
        if self.k0 == self.k1 && (d - self.k1 * x).abs() <= SLACK * (1.0 + d.abs()) {
            return (self.immediate(), None);
        }
        let charac = |p: &Profile| p.charac(self.m0, self.w * self.dir, [self.s0, 0.0, 0.0, 0.0]);
        // A candidate the acceleration checks let pass, with its values.
        let passes = |p: Option<Profile>| {
            let p = p?;
            let c = charac(&p);
            acc_ok(&c, req).then_some((p, Some(c)))
        };
        if req.mask & m::PREFERCONSTVELO != 0 {
            if let Some(chosen) = passes(self.const_velo(req, x, d)) {
                return chosen;
            }
        }
        // Step 1: velocity overshoot-free, P1+P5 or P5+P1.
        if let Some(chosen) = passes(self.monotone(x, d)) {
            return chosen;
        }
        // Step 2: the plain P5, capped at the velocity limit if it passes it.
        let plain = p5();
        if req.mask & m::MAXVELO == 0 {
            return (plain, None);
        }
        let c = charac(&plain);
        let v = &c.values;
        let peak = if v.fSlaveVeloMax.abs() >= v.fSlaveVeloMin.abs() {
            v.fSlaveVeloMax
        } else {
            v.fSlaveVeloMin
        };
        if over(peak.abs(), req.limits.velocity) {
            let kv = peak.signum() * req.limits.velocity / self.w;
            if let Some(chosen) = passes(self.capped(req, x, d, kv)) {
                return chosen;
            }
        }
        (plain, Some(c))
    }

    /// P1+P5 or P5+P1 when the mean slope `d/x` lies between start and sync slope.
    fn monotone(&self, x: f64, d: f64) -> Option<Profile> {
        let (k0, k1) = (self.k0, self.k1);
        if k0 == k1 {
            return None;
        }
        let mean = d / x;
        if (mean - k0) * (mean - k1) > 0.0 {
            return None;
        }
        let half = 0.5 * (k0 + k1);
        if (mean - half) * (k0 - k1) >= 0.0 {
            // Closer to the start slope: hold it first, then change.
            let len = 2.0 * (d - k0 * x) / (k1 - k0);
            if len.is_nan() || len <= 0.0 {
                return None;
            }
            let hold = x - len;
            if hold <= 0.0 {
                return Some(Profile::new(
                    self.domain(),
                    Shape::P5,
                    &[slope_change(0.0, x, self.s0, k0, 0.0, k1)],
                ));
            }
            let a = straight(0.0, hold, self.s0, k0);
            let b = slope_change(hold, len, self.s0 + k0 * hold, k0, 0.0, k1);
            Some(Profile::new(self.domain(), Shape::P1P5, &[a, b]))
        } else {
            // Closer to the sync slope: change first, then run synchronously.
            let len = 2.0 * (k1 * x - d) / (k1 - k0);
            if len.is_nan() || len <= 0.0 {
                return None;
            }
            let a = slope_change(0.0, len, self.s0, k0, 0.0, k1);
            let s = self.s0 + slope_change_travel(len, k0, k1);
            let b = straight(len, x - len, s, k1);
            Some(Profile::new(self.domain(), Shape::P5P1, &[a, b]))
        }
    }

    /// P5-P1-P5 through slope `kv` with lengths `l1`, `l3` (the rest constant).
    fn three(&self, x: f64, kv: f64, l1: f64, l3: f64) -> Profile {
        let l2 = x - l1 - l3;
        let a = slope_change(0.0, l1, self.s0, self.k0, 0.0, kv);
        let s1 = self.s0 + slope_change_travel(l1, self.k0, kv);
        let b = straight(l1, l2, s1, kv);
        let s2 = s1 + kv * l2;
        let c = slope_change(l1 + l2, l3, s2, kv, 0.0, self.k1);
        Profile::new(self.domain(), Shape::P5P1P5, &[a, b, c])
    }

    /// Distance a P5-P1-P5 through `kv` covers over `x` with its changes as short as the
    /// limits allow; `None` when the changes alone are longer than `x`.
    fn three_travel(&self, req: &SawRequest, x: f64, kv: f64) -> Option<(f64, f64, f64)> {
        let l1 = self.change_len(self.k0, kv, &req.limits);
        let l3 = self.change_len(kv, self.k1, &req.limits);
        if l1 + l3 > x {
            return None;
        }
        let travel = slope_change_travel(l1, self.k0, kv)
            + slope_change_travel(l3, kv, self.k1)
            + kv * (x - l1 - l3);
        Some((travel, l1, l3))
    }

    /// PREFERCONSTVELO: the constant slope whose P5-P1-P5, changes at the limits, covers
    /// `d` over `x`. Sampled over the slopes the changes leave room for, the root nearest to
    /// the mean slope bisected.
    fn const_velo(&self, req: &SawRequest, x: f64, d: f64) -> Option<Profile> {
        let mean = d / x;
        // The widest slope range: grow the span until the changes no longer fit.
        let lo_hi = |sign: f64| {
            let base = if sign > 0.0 {
                self.k0.max(self.k1).max(mean)
            } else {
                self.k0.min(self.k1).min(mean)
            };
            let mut span = (self.k0 - self.k1).abs().max(mean.abs()).max(1e-6);
            let mut last_ok = base;
            for _ in 0..60 {
                let k = base + sign * span;
                if self.three_travel(req, x, k).is_none() {
                    break;
                }
                last_ok = k;
                span *= 2.0;
            }
            last_ok
        };
        let (lo, hi) = (lo_hi(-1.0), lo_hi(1.0));
        let f = |k: f64| self.three_travel(req, x, k).map(|(t, _, _)| t - d);
        const N: usize = 64;
        let mut best: Option<f64> = None;
        let mut prev: Option<(f64, f64)> = None;
        for i in 0..=N {
            let k = lo + (hi - lo) * i as f64 / N as f64;
            let Some(fk) = f(k) else {
                prev = None;
                continue;
            };
            if let Some((kp, fp)) = prev {
                if fp * fk <= 0.0 {
                    let (mut a, mut b, mut fa) = (kp, k, fp);
                    for _ in 0..60 {
                        let mid = 0.5 * (a + b);
                        let Some(fm) = f(mid) else { break };
                        if (fm < 0.0) == (fa < 0.0) {
                            a = mid;
                            fa = fm;
                        } else {
                            b = mid;
                        }
                    }
                    let root = 0.5 * (a + b);
                    if best.is_none_or(|r| (root - mean).abs() < (r - mean).abs()) {
                        best = Some(root);
                    }
                }
            }
            prev = Some((k, fk));
        }
        let kv = best?;
        let (_, l1, l3) = self.three_travel(req, x, kv)?;
        Some(self.three(x, kv, l1, l3))
    }

    /// Step 2: P5-P1-P5 at slope `kv` (the velocity limit), one change as short as the
    /// limits allow, the other as long as the distance asks.
    fn capped(&self, req: &SawRequest, x: f64, d: f64, kv: f64) -> Option<Profile> {
        let (k0, k1) = (self.k0, self.k1);
        if kv == k0 || kv == k1 {
            return None;
        }
        let l1_min = self.change_len(k0, kv, &req.limits);
        let l3_min = self.change_len(kv, k1, &req.limits);
        // l1 fixed: d = l1 (k0+kv)/2 + kv l2 + l3 (kv+k1)/2, l2 = x - l1 - l3.
        let l3 = 2.0 * (d - kv * x + 0.5 * l1_min * (kv - k0)) / (k1 - kv);
        if l3 >= l3_min && l1_min + l3 <= x {
            return Some(self.three(x, kv, l1_min, l3));
        }
        let l1 = 2.0 * (d - kv * x + 0.5 * l3_min * (kv - k1)) / (k0 - kv);
        if l1 >= l1_min && l1 + l3_min <= x {
            return Some(self.three(x, kv, l1, l3_min));
        }
        None
    }
}

/// A stop after a rollback: the velocity taken to 0 along a smooth change in time (as fast
/// as deceleration and jerk allow), from the slave's set-point.
pub fn rollback_stop(slave: &Kinematic, limits: &Limits) -> Profile {
    let t = change_time_from(slave.velocity, slave.acceleration, 0.0, limits).max(1e-6);
    let p = slope_change(
        0.0,
        t,
        slave.position,
        slave.velocity,
        slave.acceleration,
        0.0,
    );
    Profile::new(Domain::Time, Shape::Stop, &[p])
}
