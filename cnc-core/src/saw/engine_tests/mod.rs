//! The flying-saw engine in the machine tick, on the in-library machine harness
//! ([`crate::harness::Harness`]): single axes powered before the first tick and the engines a
//! machine of single axes gets (the cams, then the saw; the gear engine before them where a
//! test couples a gear), with calls straight to the machine.
//!
//! * `engine`: position sync to the tick, MC_GearOut, the rollback cases, refusals, the
//!   internal table rule, the characteristic values, the diagonal saw, the time-based phase;
//! * `superimposed`: MC_MoveSuperimposed on a synchronous saw;
//! * `manual_machine`: limits not given taken from the axis's machine data, the slave states
//!   in the image;
//! * `encoder`: the acceleration threshold of an encoder master at coupling.

mod encoder;
mod engine;
mod manual_machine;
mod superimposed;

use crate::axis::config::AxisConfig;
use crate::harness::Harness;
use crate::setpoint::Kinematic;
use hli::calls::axis::AxisCommandCall;
use hli::calls::saw::{SawGearInCall, SawSyncTarget};

const TICK: f64 = 0.001;
const MASTER: usize = 0;
const SAW: usize = 1;

/// An axis of the saw tests' machines: linear, wide software limits, 3000 mm/s, 20000
/// mm/s^2 both ways, 1e7 mm/s^3 and a following-error limit of 1e4 mm, on the ideal
/// simulated drive.
fn saw_axis(name: &str, id: u32) -> AxisConfig {
    let mut c = AxisConfig::linear(name, id);
    c.soft_limits = Some([-1e7, 1e7]);
    c.dynamics.velocity = 3000.0;
    c.dynamics.acceleration = 20000.0;
    c.dynamics.deceleration = 20000.0;
    c.dynamics.jerk = 1e7;
    c.following_error_limit = 1e4;
    c
}

/// `run` with every axis powered (before the first tick) after its first tick.
fn started(mut run: Harness) -> Harness {
    run.power_all();
    run.step();
    run
}

/// The saw engine tests' machine: Master (ID 1) and Saw (ID 2) with the standard engines,
/// after its first tick.
fn machine() -> Harness {
    let axes = vec![saw_axis("Master", 1), saw_axis("Saw", 2)];
    started(Harness::standard(TICK, axes).unwrap())
}

/// A command to `axis`; its ErrorID.
fn command(run: &mut Harness, axis: usize, c: AxisCommandCall) -> u32 {
    run.call(axis as u32, &c).unwrap().error_id
}

/// Axis `axis`'s set-point.
fn set(run: &Harness, axis: usize) -> Kinematic {
    run.setpoint(axis)
}

/// Axis `axis`'s `nAxisState` in the image.
fn phase(run: &Harness, axis: usize) -> i32 {
    run.plc_view().axis_state(axis).unwrap().axis_state_r
}

/// MC_GearInVelo to the master with `ratio` and SyncMode `mask`.
fn velocity_call(ratio: f64, mask: u32) -> SawGearInCall {
    SawGearInCall {
        master: MASTER as u32,
        target: SawSyncTarget::Velocity.raw(),
        ratio_numerator: ratio,
        ratio_denominator: 1,
        mask,
        acceleration: 2500.0,
        deceleration: 2500.0,
        jerk: 5000.0,
        ..SawGearInCall::default()
    }
}
