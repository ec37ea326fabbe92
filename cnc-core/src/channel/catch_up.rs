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
    /// The wanted set-points of the last tick and the velocity of their smooth part.
    wanted: AxisValues,
    wanted_velocity: AxisValues,
    /// Per axis: the lag's profile (position = the lag) and the limits it was planned with.
    lag: Vec<SetpointGenerator>,
    planned: [Option<MoveLimits>; MAX_CHANNEL_AXES],
    /// The axes commanded this tick were the followed ones (not the wanted).
    followed: bool,
    /// Catch-ups started since start-up.
    started: u64,
}

/// The lag's profile found no trajectory (never seen; the channel stops safely).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NoProfile {
    /// Axis index in the channel (0-based).
    pub axis: usize,
}

impl CatchUp {
    /// At rest at `start`, no lag.
    pub fn new(start: &AxisValues, cycle_s: f64) -> Self {
        Self {
            cycle_s,
            wanted: *start,
            wanted_velocity: AxisValues::zeros(start.len()),
            lag: start
                .iter()
                .map(|_| SetpointGenerator::new(cycle_s, 0.0))
                .collect(),
            planned: [None; MAX_CHANNEL_AXES],
            followed: false,
            started: 0,
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

    /// Turns this tick's wanted set-points into the commanded ones (in place).
    pub fn follow(
        &mut self,
        set_points: &mut AxisValues,
        limits: &[AxisLimits; MAX_CHANNEL_AXES],
    ) -> Result<(), NoProfile> {
        let was_lagging = self.lagging();
        let dt = self.cycle_s;
        for (i, p) in set_points.iter_mut().enumerate() {
            let l = limits[i];
            // A tick of the wanted motion within the axis's velocity and acceleration is
            // smooth; anything else is a step from where the smooth motion would be.
            let before = self.wanted_velocity[i];
            let raw_velocity = (*p - self.wanted[i]) / dt;
            let raw_acceleration = (raw_velocity - before) / dt;
            let smooth =
                raw_velocity.abs() <= l.velocity && raw_acceleration.abs() <= l.acceleration;
            let (velocity, acceleration, step) = if smooth {
                (raw_velocity, raw_acceleration, 0.0)
            } else {
                (before, 0.0, *p - (self.wanted[i] + before * dt))
            };
            self.wanted[i] = *p;
            self.wanted_velocity[i] = velocity;
            if step == 0.0 && self.planned[i].is_none() {
                continue; // follows exactly
            }
            let left = |limit: f64, used: f64| (MARGIN * (limit - used.abs())).max(FLOOR * limit);
            let limits = MoveLimits {
                velocity: left(l.velocity, velocity),
                acceleration: left(l.acceleration, acceleration),
                deceleration: left(l.acceleration, acceleration),
                jerk: l.jerk,
            };
            *p += self
                .lag_step(i, step, limits)
                .map_err(|_| NoProfile { axis: i })?;
        }
        self.started += u64::from(!was_lagging && self.lagging());
        self.followed = true;
        Ok(())
    }

    /// One tick of axis `i`'s lag after the wanted set-point stepped by `step`: replanned
    /// when it stepped or its limits shrank, else the running profile goes on.
    fn lag_step(&mut self, i: usize, step: f64, limits: MoveLimits) -> Result<f64, ()> {
        let g = &mut self.lag[i];
        let shrank = self.planned[i]
            .is_none_or(|p| limits.velocity < p.velocity || limits.acceleration < p.acceleration);
        if step != 0.0 || shrank {
            let s = g.state();
            g.resume_from(Kinematic {
                position: s.position - step,
                ..s
            });
            g.move_to(0.0, limits).map_err(|_| ())?;
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

    /// The guard took the commanded set-points: without a catch-up this tick they were the
    /// wanted ones (taken as the smooth motion the next step is measured from).
    pub fn taken(&mut self, set_points: &AxisValues) {
        if !self.followed {
            let dt = self.cycle_s;
            for (i, p) in set_points.iter().enumerate() {
                self.wanted_velocity[i] = (p - self.wanted[i]) / dt;
                self.wanted[i] = *p;
            }
        }
        self.followed = false;
    }

    /// The axes stand at `position` (braked, held or taken over): no lag, no motion.
    pub fn rest_at(&mut self, position: &AxisValues) {
        self.wanted = *position;
        self.wanted_velocity = AxisValues::zeros(position.len());
        for g in &mut self.lag {
            g.hold(0.0);
        }
        self.planned = [None; MAX_CHANNEL_AXES];
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
