//! The universal flying saw's synchronising phase (seed 001): pure computation, no axes.
//!
//! A slave in any state (position, velocity, acceleration) is brought onto a moving master so
//! that it then runs at `ratio x master velocity`: as fast as the limits allow (velocity
//! sync, MC_GearInVelo) or exactly at given master and slave positions (position sync,
//! MC_GearInPos). The phase is a short list of polynomials: 5th-order ones (`P5`), straight
//! pieces (`P1`) and their combinations, chosen by the optimisation steps of chapter 7, over
//! the master's travel (position-based) or over time (time-based, jerk-limited). The
//! characteristic values describe it for a master at constant velocity; the checks of the
//! sync mode refuse a phase that breaks a limit.
//!
//! * `shape`: the pieces and the time a velocity change needs to keep the limits;
//! * `profile`: a phase, its evaluation in the tick and its characteristic values;
//! * `plan`: refusals, optimisation steps and checks;
//! * `follow`: a planned phase run tick by tick, rollback included.
//!
//! `machine` (beside it) runs the phase in the machine tick.

pub mod follow;
pub mod machine;
pub mod plan;
pub mod profile;
pub mod shape;

pub use follow::Follower;
pub use plan::{diagonal_ratio, gear_ratio, plan, rollback_stop, Plan, SawRequest, SyncOn};
pub use profile::{Charac, Domain, Profile, Shape};
pub use shape::Limits;

use crate::setpoint::Kinematic;

/// An encoder master's values at coupling (seed 001, chapter 3, for a master that is an
/// encoder axis): an acceleration whose magnitude is below `2 x units_per_increment /
/// cycle_s^2`, what the quantisation of one increment makes of the second difference of the
/// readings, counts as none, so the planner's optimisations (which need a master without
/// acceleration) stay open. A larger one is kept: a master that really accelerates.
pub fn encoder_master(m: Kinematic, units_per_increment: f64, cycle_s: f64) -> Kinematic {
    let threshold = 2.0 * units_per_increment / (cycle_s * cycle_s);
    match m.acceleration.abs() < threshold {
        true => Kinematic {
            acceleration: 0.0,
            ..m
        },
        false => m,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_encoder_master_below_the_threshold_has_no_acceleration() {
        // 0.1 um increments at 1 ms: 2 x 1e-4 mm / 1e-6 s^2 = 200 mm/s^2.
        let at = |a: f64| {
            let m = Kinematic {
                position: 5.0,
                velocity: 300.0,
                acceleration: a,
                jerk: 0.0,
            };
            encoder_master(m, 1e-4, 1e-3)
        };
        assert_eq!(at(199.0).acceleration, 0.0);
        assert_eq!(at(-199.0).acceleration, 0.0);
        assert_eq!(at(201.0).acceleration, 201.0);
        assert_eq!(at(-350.0).acceleration, -350.0);
        assert_eq!((at(150.0).position, at(150.0).velocity), (5.0, 300.0));
    }
}

#[cfg(test)]
mod engine_tests;
