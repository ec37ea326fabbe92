//! The last check between a channel's set-points and its axes.
//!
//! Every tick the channel hands its new set-points to the guard. While the dynamic CS is on,
//! the guard checks each axis's step against that axis's velocity and acceleration limits
//! (velocity and acceleration as backward differences over the cycle, as the axis layer sees
//! them): the overlaid motion of a tracked workpiece can ask more of the joints than the path
//! planner allowed for. A step beyond a limit is refused, never passed on.
//!
//! When the channel fails (a refused step, an unreachable pose, a program or tracking error,
//! an axis fault) the guard *latches*: from the last accepted set-point, velocity and
//! acceleration, each axis brakes on its own jerk-limited profile with its own deceleration
//! and jerk and then holds where it came to rest. While latched, the set-points are the
//! guard's and nothing the channel computes reaches the axes; the channel releases the latch
//! once it has taken the held position over as its programmed position (see
//! `Channel::resync_to_set_points`).

use super::catch_up::{CatchUp, NoProfile};
use super::path::AxisLimits;
use crate::axis::generator::{Progress, SetpointGenerator};
use crate::setpoint::Kinematic;
use crate::setpoint::{AxisValues, MAX_CHANNEL_AXES};

/// Which limit a refused step broke.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimitKind {
    /// The velocity limit.
    Velocity,
    /// The acceleration limit.
    Acceleration,
}

/// A refused step: the axis (channel order), the limit and the value it asked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimitViolation {
    /// Axis index in the channel (0-based).
    pub axis: usize,
    /// Which limit.
    pub kind: LimitKind,
    /// The velocity (units/s) or acceleration (units/s^2) the step asked for.
    pub value: f64,
    /// The limit.
    pub limit: f64,
}

impl core::fmt::Display for LimitViolation {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let what = match self.kind {
            LimitKind::Velocity => "velocity",
            LimitKind::Acceleration => "acceleration",
        };
        write!(
            f,
            "axis {} {what} {:.3} beyond its limit {:.3}",
            self.axis + 1,
            self.value.abs(),
            self.limit
        )
    }
}

/// Relative slack of the checks: a step exactly at a limit passes despite rounding.
pub(super) const SLACK: f64 = 1e-6;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Set-points pass (checked while tracking).
    Pass,
    /// Latched: the axes brake on the guard's profiles.
    Braking,
    /// Latched: the axes hold where they came to rest.
    Holding,
}

/// The guard of one channel's axes. Allocates only when built.
pub struct JointGuard {
    cycle_s: f64,
    limits: [AxisLimits; MAX_CHANNEL_AXES],
    last: Kinematics,
    brakes: Vec<SetpointGenerator>,
    mode: Mode,
    catch_up: CatchUp,
}

/// Position, velocity and acceleration of every axis after the last accepted step.
#[derive(Debug, Clone, Copy)]
struct Kinematics {
    position: AxisValues,
    velocity: AxisValues,
    acceleration: AxisValues,
}

impl core::fmt::Debug for JointGuard {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("JointGuard")
            .field("mode", &self.mode)
            .field("position", &self.last.position)
            .finish()
    }
}

impl JointGuard {
    /// A guard for axes standing at `start`, each with its `limits` (one per axis), ticking
    /// every `cycle_s` seconds.
    pub fn new(start: &AxisValues, limits: &[AxisLimits], cycle_s: f64) -> Self {
        let n = start.len();
        let mut all = [limits.first().copied().unwrap_or(AxisLimits {
            velocity: f64::INFINITY,
            acceleration: f64::INFINITY,
            jerk: f64::INFINITY,
        }); MAX_CHANNEL_AXES];
        all[..limits.len().min(MAX_CHANNEL_AXES)]
            .copy_from_slice(&limits[..limits.len().min(MAX_CHANNEL_AXES)]);
        Self {
            cycle_s,
            limits: all,
            last: Kinematics {
                position: *start,
                velocity: AxisValues::zeros(n),
                acceleration: AxisValues::zeros(n),
            },
            brakes: start
                .iter()
                .map(|p| SetpointGenerator::new(cycle_s, *p))
                .collect(),
            mode: Mode::Pass,
            catch_up: CatchUp::new(start, cycle_s),
        }
    }

    /// Turns the wanted set-points into the ones to command: a step beyond an axis's limits
    /// is caught up on a jerk-limited profile instead of passed on (see
    /// [`super::catch_up`]). Then [`Self::check`] and [`Self::accept`] as ever.
    pub fn follow(&mut self, set_points: &mut AxisValues) -> Result<(), NoProfile> {
        self.catch_up.follow(set_points, &self.limits)
    }

    /// Whether an axis still lags behind its wanted set-point.
    pub fn lagging(&self) -> bool {
        self.mode == Mode::Pass && self.catch_up.lagging()
    }

    /// The catch-up of the channel's axes (their lags).
    pub fn catch_up(&self) -> &CatchUp {
        &self.catch_up
    }

    /// The limits of axis `i`.
    pub fn limits(&self, i: usize) -> AxisLimits {
        self.limits[i.min(MAX_CHANNEL_AXES - 1)]
    }

    /// The first axis whose step to `set_points` breaks its velocity or acceleration limit.
    pub fn check(&self, set_points: &AxisValues) -> Option<LimitViolation> {
        let dt = self.cycle_s;
        for (i, p) in set_points.iter().enumerate() {
            let l = self.limits[i];
            let v = (p - self.last.position[i]) / dt;
            let a = (v - self.last.velocity[i]) / dt;
            let checks = [
                (LimitKind::Velocity, v, l.velocity),
                (LimitKind::Acceleration, a, l.acceleration),
            ];
            for (kind, value, limit) in checks {
                // A NaN is beyond every limit.
                if value.is_nan() || value.abs() > limit * (1.0 + SLACK) {
                    return Some(LimitViolation {
                        axis: i,
                        kind,
                        value,
                        limit,
                    });
                }
            }
        }
        None
    }

    /// Takes `set_points` as this tick's step (the guard is not latched).
    pub fn accept(&mut self, set_points: &AxisValues) {
        let dt = self.cycle_s;
        for (i, p) in set_points.iter().enumerate() {
            let v = (p - self.last.position[i]) / dt;
            self.last.acceleration[i] = (v - self.last.velocity[i]) / dt;
            self.last.velocity[i] = v;
            self.last.position[i] = *p;
        }
        self.catch_up.taken(set_points);
    }

    /// The axes stand at `position` (taken over after an axis reset): the next step is
    /// measured from rest there.
    pub fn rest_at(&mut self, position: &AxisValues) {
        for (i, p) in position.iter().enumerate() {
            self.last.position[i] = *p;
            self.last.velocity[i] = 0.0;
            self.last.acceleration[i] = 0.0;
        }
        self.catch_up.rest_at(position);
    }

    /// Latches: every axis brakes from its last accepted state with its deceleration and
    /// jerk. Does nothing when latched already.
    pub fn latch(&mut self) {
        if self.mode != Mode::Pass {
            return;
        }
        // A catch-up under way is given up: the axes brake from where they were commanded.
        self.catch_up.rest_at(&self.last.position);
        for (i, g) in self.brakes.iter_mut().enumerate() {
            let l = self.limits[i];
            let v = self.last.velocity[i];
            let a = self.last.acceleration[i].clamp(-l.acceleration, l.acceleration);
            g.resume_from(Kinematic {
                position: self.last.position[i],
                velocity: v,
                acceleration: a,
                jerk: 0.0,
            });
            if (v != 0.0 || a != 0.0) && g.brake(l.acceleration, l.jerk).is_err() {
                // No profile (never seen): the axis holds where it is, which is what the
                // axis layer's own stop would have to do as well.
                g.hold(self.last.position[i]);
            }
        }
        self.mode = Mode::Braking;
    }

    /// Whether the guard owns the set-points.
    pub fn latched(&self) -> bool {
        self.mode != Mode::Pass
    }

    /// Whether the axes are still braking.
    pub fn braking(&self) -> bool {
        self.mode == Mode::Braking
    }

    /// One tick while latched: the braking (or held) set-points into `set_points`.
    pub fn step(&mut self, set_points: &mut AxisValues) {
        let dt = self.cycle_s;
        let mut moving = false;
        for (i, g) in self.brakes.iter_mut().enumerate() {
            let progress = g.step();
            moving |= progress == Progress::Moving;
            let p = if progress == Progress::Moving {
                g.state().position
            } else {
                // Arrived (or never moved): stand exactly where the profile ends.
                let s = g.state().position;
                g.hold(s);
                s
            };
            let v = (p - self.last.position[i]) / dt;
            self.last.acceleration[i] = (v - self.last.velocity[i]) / dt;
            self.last.velocity[i] = v;
            self.last.position[i] = p;
            if let Some(out) = set_points.get_mut(i) {
                *out = p;
            }
        }
        if !moving && self.last.velocity.iter().all(|v| *v == 0.0) {
            self.mode = Mode::Holding;
        }
    }

    /// Hands the set-points back to the channel (at rest only; see the module docs).
    pub fn release(&mut self) {
        if self.mode == Mode::Holding {
            self.mode = Mode::Pass;
            self.catch_up.rest_at(&self.last.position);
        }
    }

    /// The set-points the guard holds or brakes through (its last step).
    pub fn position(&self) -> &AxisValues {
        &self.last.position
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> [AxisLimits; 2] {
        [AxisLimits {
            velocity: 100.0,
            acceleration: 1000.0,
            jerk: 20_000.0,
        }; 2]
    }

    #[test]
    fn a_step_beyond_a_limit_is_named_and_one_within_passes() {
        let start = AxisValues::zeros(2);
        let mut g = JointGuard::new(&start, &limits(), 0.001);
        // 0.5 mm in 1 ms from rest: 500 mm/s.
        let v = g.check(&AxisValues::from_slice(&[0.0, 0.5])).unwrap();
        assert_eq!((v.axis, v.kind), (1, LimitKind::Velocity));
        // 0.0005 mm: 0.5 mm/s, 500 mm/s^2: passes.
        let ok = AxisValues::from_slice(&[0.0005, 0.0]);
        assert_eq!(g.check(&ok), None);
        g.accept(&ok);
        // From 0.5 mm/s to 3.5 mm/s in one tick: 3000 mm/s^2.
        let v = g.check(&AxisValues::from_slice(&[0.004, 0.0])).unwrap();
        assert_eq!((v.axis, v.kind), (0, LimitKind::Acceleration));
    }

    #[test]
    fn a_latched_guard_brakes_within_the_limits_and_holds() {
        let start = AxisValues::zeros(2);
        let mut g = JointGuard::new(&start, &limits(), 0.001);
        // Run up to 80 mm/s within the limits.
        let mut p = AxisValues::zeros(2);
        let mut v = 0.0;
        while v < 80.0 {
            v += 0.5;
            p[0] += v * 0.001;
            p[1] -= v * 0.001;
            assert_eq!(g.check(&p), None);
            g.accept(&p);
        }
        g.latch();
        let (mut last, mut last_v) = (p, [v, -v]);
        let mut ticks = 0;
        while g.braking() {
            g.step(&mut p);
            for i in 0..2 {
                let vi = (p[i] - last[i]) / 0.001;
                let ai = (vi - last_v[i]) / 0.001;
                assert!(
                    vi.abs() <= 100.0 && ai.abs() <= 1000.0 * 1.01,
                    "tick {ticks}: {vi} {ai}"
                );
                assert!(vi * last_v[i] >= 0.0, "no reversal");
                last_v[i] = vi;
            }
            last = p;
            ticks += 1;
            assert!(ticks < 1000, "comes to rest");
        }
        let held = p;
        g.step(&mut p);
        assert_eq!(p, held);
        g.release();
        assert!(!g.latched());
    }
}
