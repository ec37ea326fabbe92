//! Catching up with a step of the wanted set-points (a PLC frame step, a FILTER=0 switching,
//! a master that jumps) instead of stopping the machine for it.
//!
//! Every tick the guard is handed the *wanted* set-points. A tick whose wanted velocity and
//! acceleration (backward differences) are within the axis's limits is smooth; any other is
//! a step from where the smooth motion would have gone on at its velocity, and the step goes
//! into the axis's *lag*
//! `e = commanded - wanted`, which a jerk-limited profile of its own (the Ruckig generator of
//! the axis layer, planned in the lag's coordinates) brings back to zero. The axis is
//! commanded `wanted + e`: its velocity is the wanted one plus the lag's, so the lag's profile
//! gets what the wanted motion leaves of each limit (with a margin for sampling the profile
//! once per tick). The profile ends exactly on zero lag: from then on the axis is the wanted
//! set-point again, to the bit.
//!
//! A wanted motion that itself asks more than the axis can give (faster than its velocity
//! limit) keeps a lag that grows; the channel judges the lag against its bound
//! (`track_lag_max`) and stops safely beyond it.

use super::guard::SLACK;
use super::path::AxisLimits;
use crate::axis::generator::{MoveLimits, Progress, SetpointGenerator};
use crate::setpoint::{AxisValues, Kinematic, MAX_CHANNEL_AXES};

/// What of a limit the lag's profile may use beside the wanted motion: the rest is kept for
/// sampling the profile once per tick and for a wanted motion that changes under it.
const MARGIN: f64 = 0.9;

/// A limit left to the lag's profile is never planned below this share of the axis's limit
/// (a profile needs limits above zero): a wanted motion at its limit leaves the lag a crawl
/// within the guard's slack, so the lag grows and the channel's bound judges it.
const FLOOR: f64 = 1e-7;

/// Lags below this (mm or degrees) are zero.
const EPSILON: f64 = 1e-12;

/// The catch-up of one channel's axes. Allocates only when built.
pub struct CatchUp {
    cycle_s: f64,
    /// The wanted set-points of the last tick, the velocity of their smooth part (the
    /// reference the lag is measured against), and per axis the raw velocity of a tick that
    /// was a step (`None` after a smooth one).
    wanted: AxisValues,
    wanted_velocity: AxisValues,
    stepped: [Option<f64>; MAX_CHANNEL_AXES],
    /// Per axis: the reference's acceleration of the last tick and its change in that tick.
    wanted_acceleration: [(f64, f64); MAX_CHANNEL_AXES],
    /// Per axis: the lag's profile (position = the lag) and the limits it was planned with.
    lag: Vec<SetpointGenerator>,
    planned: [Option<MoveLimits>; MAX_CHANNEL_AXES],
    /// What was commanded last tick and its velocity (backward difference).
    commanded: AxisValues,
    commanded_velocity: AxisValues,
    /// Per axis: the last step was cut to the limits; the lag is planned anew.
    replan: [bool; MAX_CHANNEL_AXES],
    /// The axes commanded this tick were the followed ones (not the wanted).
    followed: bool,
    /// This tick the wanted motion of some axis was faster than the axis may go: its lag
    /// grows whatever the profile does.
    outrun: bool,
    /// Catch-ups started since start-up.
    started: u64,
    /// Ticks whose commanded step [`CatchUp::bounded`] had to cut.
    cuts: u64,
}

/// The lag's profile found no trajectory (never seen; the channel stops safely).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NoProfile {
    /// Axis index in the channel (0-based).
    pub axis: usize,
}

/// How one tick of the wanted set-point left the reference: a step of its position and of
/// its velocity (both taken by the lag), and the reference's own acceleration.
#[derive(Debug, Clone, Copy, Default)]
struct Change {
    position: f64,
    velocity: f64,
    /// Of the acceleration limit, what the reference uses (its acceleration and change).
    used_acceleration: f64,
}

impl CatchUp {
    /// At rest at `start`, no lag.
    pub fn new(start: &AxisValues, cycle_s: f64) -> Self {
        Self {
            cycle_s,
            wanted: *start,
            wanted_velocity: AxisValues::zeros(start.len()),
            stepped: [None; MAX_CHANNEL_AXES],
            wanted_acceleration: [(0.0, 0.0); MAX_CHANNEL_AXES],
            lag: start
                .iter()
                .map(|_| SetpointGenerator::new(cycle_s, 0.0))
                .collect(),
            planned: [None; MAX_CHANNEL_AXES],
            commanded: *start,
            commanded_velocity: AxisValues::zeros(start.len()),
            replan: [false; MAX_CHANNEL_AXES],
            followed: false,
            outrun: false,
            started: 0,
            cuts: 0,
        }
    }

    /// Whether any axis lags behind its wanted set-point.
    pub fn lagging(&self) -> bool {
        self.planned.iter().any(Option::is_some)
    }

    /// Axis `i`'s lag (commanded minus wanted), 0 when it follows exactly.
    pub fn lag(&self, i: usize) -> f64 {
        match self.planned.get(i) {
            Some(Some(_)) => self.lag[i].state().position,
            _ => 0.0,
        }
    }

    /// Catch-ups started since start-up.
    pub fn started(&self) -> u64 {
        self.started
    }

    /// Whether the wanted motion of some axis was faster than its velocity limit this tick
    /// (its lag cannot shrink while that lasts).
    pub fn outrun(&self) -> bool {
        self.outrun
    }

    /// Ticks whose commanded step had to be cut to the limits (the reference's acceleration
    /// jumped while a catch-up ran): rare, and the only ticks whose jerk is not the lag's.
    pub fn cuts(&self) -> u64 {
        self.cuts
    }

    /// Turns this tick's wanted set-points into the commanded ones (in place).
    pub fn follow(
        &mut self,
        set_points: &mut AxisValues,
        limits: &[AxisLimits; MAX_CHANNEL_AXES],
    ) -> Result<(), NoProfile> {
        let was_lagging = self.lagging();
        self.outrun = false;
        for (i, p) in set_points.iter_mut().enumerate() {
            let l = limits[i];
            let change = self.reference(i, *p, l);
            if change.position == 0.0 && change.velocity == 0.0 && self.planned[i].is_none() {
                continue; // follows exactly
            }
            let left = |limit: f64, used: f64| (MARGIN * (limit - used)).max(FLOOR * limit);
            let limits = MoveLimits {
                velocity: left(l.velocity, self.wanted_velocity[i].abs()),
                acceleration: left(l.acceleration, change.used_acceleration),
                deceleration: left(l.acceleration, change.used_acceleration),
                jerk: l.jerk,
            };
            let lag = self
                .lag_step(i, change, limits)
                .map_err(|_| NoProfile { axis: i })?;
            *p = self.bounded(i, *p + lag, l, limits);
        }
        self.started += u64::from(!was_lagging && self.lagging());
        self.followed = true;
        Ok(())
    }

    /// Moves axis `i`'s reference on to the wanted set-point `p`. A tick whose velocity and
    /// acceleration are within the axis's limits is smooth: the reference takes it. Any other
    /// is first taken as a step of the position (the reference goes on as it went, at its
    /// velocity and acceleration); when the next tick moves on steadily from that tick, the
    /// velocity stepped: the reference takes the new velocity (within the limit) and the lag
    /// the difference, so the commanded motion stays continuous either way.
    fn reference(&mut self, i: usize, p: f64, l: AxisLimits) -> Change {
        let dt = self.cycle_s;
        let before = self.wanted_velocity[i];
        let (accel_before, trend) = self.wanted_acceleration[i];
        let raw = (p - self.wanted[i]) / dt;
        // With the guard's slack: a tick exactly at a limit is smooth despite rounding.
        let (v_max, a_max) = (l.velocity * (1.0 + SLACK), l.acceleration * (1.0 + SLACK));
        let steady = |from: f64| (raw - from).abs() <= a_max * dt;
        let mut change = Change::default();
        let (velocity, acceleration, stepped) = if raw.abs() <= v_max && steady(before) {
            (raw, (raw - before) / dt, None)
        } else if let Some(last) = self.stepped[i].filter(|last| steady(*last)) {
            let velocity = raw.clamp(-l.velocity, l.velocity);
            let acceleration = (raw - last) / dt;
            change.velocity = velocity - (before + acceleration * dt);
            self.outrun |= velocity != raw;
            // Still faster than the axis: the next tick steps the same way.
            (velocity, acceleration, (velocity != raw).then_some(raw))
        } else {
            // The reference goes on as it went: its acceleration changing as it changed.
            let acceleration = (accel_before + trend).clamp(-l.acceleration, l.acceleration);
            let velocity = (before + acceleration * dt).clamp(-l.velocity, l.velocity);
            (velocity, (velocity - before) / dt, Some(raw))
        };
        change.position = p - (self.wanted[i] + velocity * dt);
        if stepped.is_none() && change.velocity == 0.0 {
            change.position = 0.0; // smooth: exactly on the wanted set-point
        }
        // What the reference uses of the acceleration, with room for its change going on
        // while the lag's profile, jerk-limited, makes room for it.
        let acceleration = acceleration.clamp(-l.acceleration, l.acceleration);
        let trend = acceleration - accel_before;
        change.used_acceleration = acceleration.abs() + 2.0 * trend.abs();
        self.wanted[i] = p;
        self.wanted_velocity[i] = velocity;
        self.wanted_acceleration[i] = (acceleration, trend);
        self.stepped[i] = stepped;
        change
    }

    /// One tick of axis `i`'s lag after the reference's `change`: replanned when it stepped
    /// or the limits left to the lag changed, else the running profile goes on.
    fn lag_step(&mut self, i: usize, change: Change, limits: MoveLimits) -> Result<f64, ()> {
        let g = &mut self.lag[i];
        let stepped = change.position != 0.0 || change.velocity != 0.0;
        if stepped || self.planned[i] != Some(limits) || self.replan[i] {
            self.replan[i] = false;
            let s = g.state();
            // An acceleration beyond what is left to the lag now (the reference's grew) is
            // taken back to it, with room for the generator's gentler retries (a profile
            // cannot start beyond its limit): a change of the lag's acceleration as large as
            // the reference's own, so the jerk stays the lag's plus the reference's.
            let acceleration = if s.acceleration.abs() > limits.acceleration {
                (0.98 * limits.acceleration).copysign(s.acceleration)
            } else {
                s.acceleration
            };
            let mut from = Kinematic {
                position: s.position - change.position,
                velocity: s.velocity - change.velocity,
                acceleration,
                ..s
            };
            g.resume_from(from);
            if g.move_to(0.0, limits).is_err() {
                // A numerical knife edge of the library: once more from no acceleration.
                from.acceleration = 0.0;
                g.resume_from(from);
                self.cuts += 1;
                g.move_to(0.0, limits).map_err(|_| ())?;
            }
            self.planned[i] = Some(limits);
        }
        let progress = g.step();
        let e = g.state().position;
        if progress != Progress::Moving || e.abs() <= EPSILON && g.state().velocity == 0.0 {
            g.hold(0.0);
            self.planned[i] = None;
            return Ok(0.0);
        }
        Ok(e)
    }

    /// The last line: axis `i`'s commanded step `p` within its velocity and acceleration
    /// limits by backward differences (as the guard checks them). The profile keeps it there
    /// but for a reference whose acceleration jumps while a catch-up runs; what is cut then
    /// goes back into the lag, planned anew next tick.
    fn bounded(&mut self, i: usize, p: f64, l: AxisLimits, limits: MoveLimits) -> f64 {
        let dt = self.cycle_s;
        let (from, v_before) = (self.commanded[i], self.commanded_velocity[i]);
        let v = (p - from) / dt;
        let a = ((v - v_before) / dt).clamp(-l.acceleration, l.acceleration);
        let bounded = (v_before + a * dt).clamp(-l.velocity, l.velocity);
        if bounded == v {
            return p;
        }
        let cut = from + bounded * dt;
        let g = &mut self.lag[i];
        let s = g.state();
        let reference = self.wanted_acceleration[i].0;
        g.resume_from(Kinematic {
            position: s.position + (cut - p),
            velocity: s.velocity + (bounded - v),
            acceleration: (bounded - v_before) / dt - reference,
            ..s
        });
        self.planned[i] = Some(limits);
        self.replan[i] = true;
        self.cuts += 1;
        cut
    }

    /// The guard took the commanded set-points: without a catch-up this tick they were the
    /// wanted ones (taken as the smooth motion the next step is measured from).
    pub fn taken(&mut self, set_points: &AxisValues) {
        let dt = self.cycle_s;
        for (i, p) in set_points.iter().enumerate() {
            self.commanded_velocity[i] = (p - self.commanded[i]) / dt;
            self.commanded[i] = *p;
        }
        if !self.followed {
            self.outrun = false;
            for (i, p) in set_points.iter().enumerate() {
                let velocity = (p - self.wanted[i]) / dt;
                let acceleration = (velocity - self.wanted_velocity[i]) / dt;
                let trend = acceleration - self.wanted_acceleration[i].0;
                self.wanted_acceleration[i] = (acceleration, trend);
                self.wanted_velocity[i] = velocity;
                self.wanted[i] = *p;
                self.stepped[i] = None;
            }
        }
        self.followed = false;
    }

    /// The axes stand at `position` (braked, held or taken over): no lag, no motion.
    pub fn rest_at(&mut self, position: &AxisValues) {
        self.wanted = *position;
        self.wanted_velocity = AxisValues::zeros(position.len());
        self.stepped = [None; MAX_CHANNEL_AXES];
        self.wanted_acceleration = [(0.0, 0.0); MAX_CHANNEL_AXES];
        for g in &mut self.lag {
            g.hold(0.0);
        }
        self.planned = [None; MAX_CHANNEL_AXES];
        self.commanded = *position;
        self.commanded_velocity = AxisValues::zeros(position.len());
        self.replan = [false; MAX_CHANNEL_AXES];
        self.followed = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 0.001;

    fn limits() -> [AxisLimits; MAX_CHANNEL_AXES] {
        [AxisLimits {
            velocity: 1000.0,
            acceleration: 5000.0,
            jerk: 1_000_000.0,
        }; MAX_CHANNEL_AXES]
    }

    /// A 0.1 mm step of an axis at rest: caught up within the limits, landing exactly.
    #[test]
    fn a_step_at_rest_is_caught_up_within_the_limits_and_lands_exactly() {
        let mut c = CatchUp::new(&AxisValues::zeros(1), DT);
        let (mut last, mut last_v) = (0.0, 0.0);
        let mut ticks = 0;
        loop {
            let mut p = AxisValues::from_slice(&[0.1]);
            c.follow(&mut p, &limits()).unwrap();
            c.taken(&p);
            let v = (p[0] - last) / DT;
            let a = (v - last_v) / DT;
            assert!(
                v.abs() <= 1000.0 && a.abs() <= 5000.0 * 1.001,
                "{ticks}: {v} {a}"
            );
            (last, last_v) = (p[0], v);
            ticks += 1;
            if !c.lagging() {
                break;
            }
            assert!(ticks < 100, "lands within 100 ticks");
        }
        assert_eq!(last, 0.1, "exactly on the wanted set-point");
        assert_eq!(c.started(), 1);
        assert!(ticks > 5, "not in one step ({ticks})");
    }

    /// A step while the wanted motion runs at constant velocity: the axis ends on the moving
    /// set-point, never beyond the limits.
    #[test]
    fn a_step_of_a_moving_set_point_is_caught_up_on_the_move() {
        let mut c = CatchUp::new(&AxisValues::zeros(1), DT);
        let (mut last, mut last_v) = (0.0, 0.0);
        let mut wanted = 0.0;
        let mut velocity: f64 = 0.0;
        for tick in 0..2000 {
            velocity = (velocity + 4000.0 * DT).min(300.0);
            wanted += velocity * DT;
            if tick == 200 {
                wanted -= 2.0; // the master jumps back 2 mm
            }
            let mut p = AxisValues::from_slice(&[wanted]);
            c.follow(&mut p, &limits()).unwrap();
            c.taken(&p);
            let v = (p[0] - last) / DT;
            let a = (v - last_v) / DT;
            if tick > 0 {
                assert!(
                    v.abs() <= 1000.0 && a.abs() <= 5000.0 * 1.001,
                    "{tick}: {v} {a}"
                );
            }
            (last, last_v) = (p[0], v);
        }
        assert!(!c.lagging());
        assert_eq!(last, wanted);
    }

    proptest::proptest! {
        /// Any steps (up to 20 mm) on a wanted motion planned within 80 % of the velocity
        /// and acceleration and 40 % of the jerk (a master's path, re-targeted every 100
        /// ticks): every commanded tick within the velocity and acceleration limits (1 % for
        /// the sampling), and once the wanted motion stands, the axis lands exactly on it.
        #[test]
        fn any_steps_on_a_planned_motion_stay_within_the_limits_and_land(
            targets in proptest::collection::vec(-200.0f64..200.0, 6),
            steps in proptest::collection::vec((0usize..700, -20.0f64..20.0), 1..4),
        ) {
            let mut c = CatchUp::new(&AxisValues::zeros(1), DT);
            let mut master = SetpointGenerator::new(DT, 0.0);
            let path = MoveLimits { velocity: 800.0, acceleration: 4000.0, deceleration: 4000.0, jerk: 400_000.0 };
            let mut offset = 0.0;
            let (mut last, mut last_v, mut last_a) = (0.0, 0.0, 0.0);
            let (mut cut_before, mut lagging_ticks) = (false, 0u32);
            for tick in 0..3000usize {
                if tick % 100 == 0 && tick / 100 < targets.len() {
                    master.move_to(targets[tick / 100], path).unwrap();
                }
                master.step();
                for (at, step) in &steps {
                    if *at == tick {
                        offset += step;
                    }
                }
                let wanted = master.state().position + offset;
                let mut p = AxisValues::from_slice(&[wanted]);
                let cuts = c.cuts();
                c.follow(&mut p, &limits()).unwrap();
                let cut = c.cuts() > cuts || cut_before;
                cut_before = c.cuts() > cuts;
                lagging_ticks += u32::from(c.lagging());
                c.taken(&p);
                let v = (p[0] - last) / DT;
                let acc = (v - last_v) / DT;
                proptest::prop_assert!(v.abs() <= 1000.0 * 1.01, "tick {}: v {}", tick, v);
                proptest::prop_assert!(acc.abs() <= 5000.0 * 1.01, "tick {}: a {}", tick, acc);
                // The jerk: the lag's and the master's, but at a step of the master (one
                // small enough to be within the velocity and acceleration passes at once).
                let jerk = (acc - last_a) / DT;
                let stepped = steps.iter().any(|(at, _)| tick >= *at && tick < at + 3);
                proptest::prop_assert!(stepped || cut || jerk.abs() <= 2e6, "tick {}: j {}", tick, jerk);
                (last, last_v, last_a) = (p[0], v, acc);
            }
            proptest::prop_assert!(!c.lagging(), "lag {}", c.lag(0));
            // A cut hands its rest back to the lag, planned anew next tick; the master's
            // re-targeting under a running catch-up cuts again (its acceleration changes
            // under the lag's profile): a few per step, and rare among the catch-up's ticks.
            let bound = 2 * steps.len() as u64 + 1 + u64::from(lagging_ticks) / 25;
            proptest::prop_assert!(c.cuts() <= bound, "{} cuts in {} ticks", c.cuts(), lagging_ticks);
            proptest::prop_assert_eq!(last, master.state().position + offset);
        }
    }

    /// A wanted motion faster than the axis keeps a growing lag.
    #[test]
    fn a_wanted_motion_beyond_the_velocity_limit_lags_more_and_more() {
        let mut c = CatchUp::new(&AxisValues::zeros(1), DT);
        let mut wanted = 0.0;
        let mut lags = Vec::new();
        for _ in 0..300 {
            wanted += 1.5; // 1500 mm/s against 1000 at once
            let mut p = AxisValues::from_slice(&[wanted]);
            c.follow(&mut p, &limits()).unwrap();
            c.taken(&p);
            lags.push(c.lag(0));
        }
        assert!(lags[299] < lags[100] && lags[100] < lags[10] && lags[10] < 0.0);
    }
}
