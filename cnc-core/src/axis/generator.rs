//! The jerk-limited set-point generator of one axis, on top of the Ruckig algorithm
//! (`rsruckig`): time-optimal third-order profiles ("7 phases": jerk up, constant acceleration,
//! jerk down, cruise, and the mirror image) from *any* current state, so a move can be
//! re-targeted, sped up, slowed down or braked while it runs without a step in position,
//! velocity or acceleration.
//!
//! Limits honoured on every tick: |v| <= the command's velocity, |j| <= its jerk, and the
//! acceleration stays between -deceleration and +acceleration in the direction of travel (for
//! a move towards negative positions the two swap). When a new command starts above its
//! velocity limit, the generator first brakes within those limits. One exception keeps a
//! re-target safe: if the current acceleration cannot be taken out with the new command's
//! jerk before its velocity limit is passed, that move uses the axis's maximum jerk (see
//! [`SetpointGenerator::set_jerk_ceiling`]); a state reached under the axis limits then never
//! leads above the axis's maximum velocity.

use crate::setpoint::Kinematic;
use rsruckig::prelude::*;

/// The limits of one move, all strictly positive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveLimits {
    /// Velocity limit (or the velocity of a velocity move).
    pub velocity: f64,
    /// Acceleration limit.
    pub acceleration: f64,
    /// Deceleration limit.
    pub deceleration: f64,
    /// Jerk limit.
    pub jerk: f64,
}

/// What the generator is doing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Goal {
    /// Holding a position at rest.
    Hold,
    /// Moving to a position.
    Position(f64),
    /// Running at a signed velocity.
    Velocity(f64),
}

/// What one step produced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    /// Standing still, nothing to do.
    Idle,
    /// On the way to the goal.
    Moving,
    /// The goal was reached this step (position reached, or velocity reached).
    Reached,
    /// Moving at the goal velocity.
    AtVelocity,
}

/// The generator found no trajectory for the goal from the current state (the goal is then
/// refused and the running one goes on).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("set-point generator found no trajectory")]
pub struct GeneratorError;

/// Set-point generator of one axis.
pub struct SetpointGenerator {
    otg: Ruckig<1, ThrowErrorHandler>,
    input: InputParameter<1>,
    trajectory: Trajectory<1>,
    /// A new goal is planned here and swapped in only when a profile was found.
    candidate_input: InputParameter<1>,
    candidate: Trajectory<1>,
    cycle_s: f64,
    /// Time along `trajectory`.
    time: f64,
    state: Kinematic,
    goal: Goal,
    reached: bool,
    jerk_ceiling: f64,
}

impl core::fmt::Debug for SetpointGenerator {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("SetpointGenerator")
            .field("state", &self.state)
            .field("goal", &self.goal)
            .finish()
    }
}

fn usable(result: &RuckigResult) -> bool {
    matches!(result, RuckigResult::Working | RuckigResult::Finished)
}

fn one(value: f64) -> DataArrayOrVec<f64, 1> {
    DataArrayOrVec::Stack([value])
}

impl SetpointGenerator {
    /// A generator holding `position`, stepping `cycle_s` seconds per tick.
    pub fn new(cycle_s: f64, position: f64) -> Self {
        let mut generator = Self {
            otg: Ruckig::new(None, cycle_s),
            input: InputParameter::new(None),
            trajectory: Trajectory::new(None),
            candidate_input: InputParameter::new(None),
            candidate: Trajectory::new(None),
            cycle_s,
            time: 0.0,
            state: Kinematic::default(),
            goal: Goal::Hold,
            reached: true,
            jerk_ceiling: 0.0,
        };
        generator.hold(position);
        generator
    }

    /// The axis's maximum jerk: a re-target that cannot take the current acceleration out
    /// with its own (smaller) jerk before passing its velocity limit uses this one instead,
    /// so the axis never runs away from a command with gentler limits.
    pub fn set_jerk_ceiling(&mut self, jerk: f64) {
        self.jerk_ceiling = jerk;
    }

    /// The set-point of the last step.
    pub fn state(&self) -> Kinematic {
        self.state
    }

    /// Where the running profile ends (the position held when it holds).
    pub fn end_position(&self) -> f64 {
        if self.goal == Goal::Hold {
            return self.state.position;
        }
        let (mut p, mut section) = (one(0.0), Some(0));
        self.trajectory.at_time(
            self.trajectory.get_duration(),
            &mut Some(&mut p),
            &mut None,
            &mut None,
            &mut None,
            &mut section,
        );
        p[0]
    }

    /// The current goal.
    pub fn goal(&self) -> Goal {
        self.goal
    }

    /// Stops generating and holds `position` at rest (the axis is disabled or its set-point
    /// follows the actual position).
    pub fn hold(&mut self, position: f64) {
        self.state = Kinematic {
            position,
            ..Kinematic::default()
        };
        self.goal = Goal::Hold;
        self.reached = true;
    }

    /// Takes over a set-point produced elsewhere (a coupling that ends) and holds it until
    /// the next goal; a following [`SetpointGenerator::run_at`] starts from its velocity and
    /// acceleration without a step.
    pub fn resume_from(&mut self, state: Kinematic) {
        self.state = state;
        self.goal = Goal::Hold;
        self.reached = true;
    }

    /// Re-targets to `target` with `limits`, starting from the current set-point. On an error
    /// nothing changes.
    pub fn move_to(&mut self, target: f64, limits: MoveLimits) -> Result<(), GeneratorError> {
        self.prepare(
            ControlInterface::Position,
            limits,
            target - self.state.position,
        );
        self.candidate_input.target_position = one(target);
        self.candidate_input.target_velocity = one(0.0);
        self.commit(Goal::Position(target))
    }

    /// Re-targets to a constant signed `velocity`. On an error nothing changes.
    pub fn run_at(&mut self, velocity: f64, limits: MoveLimits) -> Result<(), GeneratorError> {
        let limits = MoveLimits {
            velocity: limits.velocity.max(velocity.abs()),
            ..limits
        };
        self.prepare(ControlInterface::Velocity, limits, velocity);
        self.candidate_input.target_velocity = one(velocity);
        self.commit(Goal::Velocity(velocity))
    }

    /// Brakes to standstill with `deceleration` and `jerk` (MC_Halt, MC_Stop). On an error
    /// nothing changes.
    pub fn brake(&mut self, deceleration: f64, jerk: f64) -> Result<(), GeneratorError> {
        let limits = MoveLimits {
            velocity: self.state.velocity.abs().max(f64::MIN_POSITIVE),
            acceleration: deceleration,
            deceleration,
            jerk,
        };
        self.prepare(ControlInterface::Velocity, limits, self.state.velocity);
        self.candidate_input.target_velocity = one(0.0);
        self.commit(Goal::Velocity(0.0))
    }

    /// Fills the candidate input for a goal from the current set-point.
    fn prepare(&mut self, interface: ControlInterface, limits: MoveLimits, travel: f64) {
        let s = self.state;
        let input = &mut self.candidate_input;
        input.control_interface = interface;
        input.current_position = one(s.position);
        input.current_velocity = one(s.velocity);
        input.current_acceleration = one(s.acceleration);
        input.target_acceleration = one(0.0);
        input.max_velocity = one(limits.velocity);
        // Taking out an acceleration `a` with jerk `j` changes the velocity by a|a| / 2j
        // first; past the velocity limit that would run away, so use the axis's jerk.
        let velocity_after =
            s.velocity + s.acceleration * s.acceleration.abs() / (2.0 * limits.jerk);
        let jerk = if velocity_after.abs() > limits.velocity.max(s.velocity.abs()) {
            limits.jerk.max(self.jerk_ceiling)
        } else {
            limits.jerk
        };
        input.max_jerk = one(jerk);
        // Deceleration is the acceleration against the direction of travel.
        let (up, down) = if travel >= 0.0 {
            (limits.acceleration, limits.deceleration)
        } else {
            (limits.deceleration, limits.acceleration)
        };
        input.max_acceleration = one(up);
        input.min_acceleration = Some(one(-down));
    }

    /// Plans the candidate; when a profile is found it becomes the running one.
    fn commit(&mut self, goal: Goal) -> Result<(), GeneratorError> {
        self.calculate_with_retries()?;
        core::mem::swap(&mut self.input, &mut self.candidate_input);
        core::mem::swap(&mut self.trajectory, &mut self.candidate);
        self.time = 0.0;
        self.goal = goal;
        self.reached = false;
        Ok(())
    }

    /// One calculation; when the library finds no profile, a few slightly gentler variants of the
    /// limits (never higher ones) are tried before giving up. rsruckig 3.0.1 misses profiles
    /// on numerical knife edges (for instance 0 -> 25 with +5000/-4000 mm/s^2, or some
    /// re-targets at full deceleration) that a 0.1 % smaller limit solves.
    fn calculate_with_retries(&mut self) -> Result<(), GeneratorError> {
        const VARIANTS: [(f64, bool); 6] = [
            (1.0, false),
            (1.0, true),
            (0.999, false),
            (0.999, true),
            (0.99, false),
            (0.99, true),
        ];
        let input = &mut self.candidate_input;
        let up = input.max_acceleration[0];
        let down = input.min_acceleration.as_ref().map_or(up, |m| -m[0]);
        let velocity = input.max_velocity[0];
        for (scale, symmetric) in VARIANTS {
            let (u, d) = if symmetric {
                (up.min(down), up.min(down))
            } else {
                (up, down)
            };
            input.max_acceleration = one(u * scale);
            input.min_acceleration = Some(one(-d * scale));
            input.max_velocity = one(velocity * scale);
            if let Ok(result) = self.otg.calculate(input, &mut self.candidate) {
                if usable(&result) {
                    return Ok(());
                }
            }
        }
        Err(GeneratorError)
    }

    /// Advances one tick.
    pub fn step(&mut self) -> Progress {
        if self.goal == Goal::Hold {
            return Progress::Idle;
        }
        self.time += self.cycle_s;
        let (mut p, mut v, mut a, mut j) = (one(0.0), one(0.0), one(0.0), one(0.0));
        let mut section = Some(0);
        self.trajectory.at_time(
            self.time,
            &mut Some(&mut p),
            &mut Some(&mut v),
            &mut Some(&mut a),
            &mut Some(&mut j),
            &mut section,
        );
        self.state = Kinematic {
            position: p[0],
            velocity: v[0],
            acceleration: a[0],
            jerk: j[0],
        };
        let finished = self.time > self.trajectory.get_duration();
        if !finished {
            return Progress::Moving;
        }
        let first = !self.reached;
        self.reached = true;
        match self.goal {
            Goal::Position(target) => {
                // Land exactly: the profile ends on the target at rest.
                self.hold(target);
                Progress::Reached
            }
            Goal::Velocity(0.0) => {
                let position = self.state.position;
                self.hold(position);
                Progress::Reached
            }
            Goal::Velocity(v) => {
                // Cruise: constant velocity from here on, integrated exactly.
                self.state.acceleration = 0.0;
                self.state.jerk = 0.0;
                self.state.velocity = v;
                if first {
                    Progress::Reached
                } else {
                    Progress::AtVelocity
                }
            }
            Goal::Hold => Progress::Idle,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Velocity, acceleration, deceleration and jerk limits in this order.
    fn limits([velocity, acceleration, deceleration, jerk]: [f64; 4]) -> MoveLimits {
        MoveLimits {
            velocity,
            acceleration,
            deceleration,
            jerk,
        }
    }

    /// Steps `g` until it reports its goal reached (fails after `max` steps); the steps
    /// before that one.
    fn steps_to_reach(g: &mut SetpointGenerator, max: usize) -> usize {
        let mut n = 0;
        while g.step() != Progress::Reached {
            n += 1;
            assert!(n < max);
        }
        n
    }

    fn run(from: f64, to: f64, l: MoveLimits) -> Result<usize, GeneratorError> {
        let mut g = SetpointGenerator::new(0.001, from);
        g.move_to(to, l)?;
        Ok(steps_to_reach(&mut g, 100_000))
    }

    #[test]
    fn a_knife_edge_retarget_still_finds_a_profile() {
        let mut g = SetpointGenerator::new(0.001, 0.0);
        g.set_jerk_ceiling(200_000.0);
        let first = limits([
            460.74781648558354,
            5204.042272881033,
            8614.688363408739,
            184719.09022780522,
        ]);
        g.move_to(-77.90457864321381, first).unwrap();
        for _ in 0..218 {
            g.step();
        }
        let second = limits([
            722.222359667801,
            8430.952228104466,
            8127.029675668488,
            196414.45591088082,
        ]);
        g.move_to(-895.1502189081375, second).unwrap();
        steps_to_reach(&mut g, 10_000);
        assert_eq!(g.state().position, -895.1502189081375);
    }

    #[test]
    fn asymmetric_limits_that_trip_the_library_still_move() {
        let l = limits([500.0, 5000.0, 4000.0, 100_000.0]);
        for (a, b) in [
            (0.0, -15.0),
            (10.0, -15.0),
            (10.0, 0.0),
            (0.0, 25.0),
            (-15.0, 10.0),
            (0.0, -25.0),
            (0.0, -100.0),
        ] {
            assert!(run(a, b, l).is_ok(), "{a} -> {b}");
        }
    }
}
