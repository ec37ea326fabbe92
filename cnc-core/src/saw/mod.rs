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
//! `crate::machine::saw` runs the phase in the machine tick.

pub mod follow;
pub mod plan;
pub mod profile;
pub mod shape;

pub use follow::Follower;
pub use plan::{diagonal_ratio, gear_ratio, plan, rollback_stop, Plan, SawRequest, SyncOn};
pub use profile::{Charac, Domain, Profile, Shape};
pub use shape::Limits;
