//! The integration tests of the kinematics in one binary, one module per topic: one linked test
//! binary instead of one per file keeps the build short on a small CI machine.

#[path = "../../../tests/support/counting_alloc.rs"]
mod counting_alloc;
mod no_alloc;
mod opw_cross_check;
mod other_kinematics;
mod robot45;
mod tracking;
