//! FIFO axis groups as pure computation (seed 002): the group's parameters, the FIFO of
//! rows, the override (instant or PT-2) and the set-point generator that walks the rows in
//! time. No axes, no image, no calls: `machine` (beside it) puts these on the engine seam.
//!
//! Row `k` of a job holds every axis's position at job time `k x T_f`. Each tick the job
//! time advances by `tick x override`; the generator interpolates linearly between the pair
//! of rows around it (fine interpolation when `T_f > tick`, coarse when smaller: rows it
//! steps over are passed, not executed) and derives velocity and acceleration from the
//! differences of its own set-points, so they integrate exactly back to the positions.

pub mod generator;
pub mod machine;
pub mod override_filter;
pub mod params;
pub mod ring;

pub use generator::{FifoGenerator, GeneratorStatus};
pub use override_filter::{OverrideFilter, OverrideType};
pub use params::{FifoParams, ParamError};
pub use ring::{BlockError, RowRing};

#[cfg(test)]
mod engine_tests;
