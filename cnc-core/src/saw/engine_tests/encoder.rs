//! The flying saw on an encoder master (seed 001, chapter 3): the acceleration threshold at
//! coupling, with IGNOREMASTERACC beside it. (The extruder case of `scenarios/saw-encoder`, a
//! scenario file with its PLC timeline, stays with the application's tests.)

use super::{started, SAW, TICK};
use crate::axis::config::{AxisConfig, DriveLink};
use crate::axis::sim_drive::{DriveModel, SimDriveConfig};
use crate::harness::Harness;
use crate::setpoint::Kinematic;
use hli::calls::axis::AxisCommandCall;
use hli::calls::saw::{sync_mask as m, SawCharacCall, SawGearInCall, SawSyncTarget};

const STRIP: usize = 0;

fn encoder(run: &Harness, axis: usize) -> Kinematic {
    run.machine.axes().master(axis, true).unwrap()
}

/// An axis of the strip machine: linear, software limits +-1e6 mm, 3000 mm/s, 20000 mm/s^2
/// both ways and 1e7 mm/s^3.
fn strip_axis(name: &str, id: u32) -> AxisConfig {
    let mut c = AxisConfig::linear(name, id);
    c.soft_limits = Some([-1e6, 1e6]);
    c.dynamics.velocity = 3000.0;
    c.dynamics.acceleration = 20000.0;
    c.dynamics.deceleration = 20000.0;
    c.dynamics.jerk = 1e7;
    c
}

/// A machine of a strip on a slow drive whose encoder reads with noise `noise` (units), and a
/// saw; the strip at 200 mm/s, the saw at 100 mm/s.
fn strip_at_speed(noise: f64) -> Harness {
    let mut strip = strip_axis("Strip", 1);
    let pt1 = DriveModel::Pt1 {
        t1_ms: 40.0,
        dead_time_ticks: 0,
    };
    strip.drive = DriveLink::Simulated(SimDriveConfig {
        encoder_noise: noise,
        ..pt1.simulated(0.0).unwrap()
    });
    let axes = vec![strip, strip_axis("Saw", 2)];
    let mut run = started(Harness::standard(TICK, axes).unwrap());
    let go = AxisCommandCall::move_velocity(1, [200.0, 2000.0, 2000.0, 1e5]);
    assert_eq!(run.call(STRIP as u32, &go).unwrap().error_id, 0);
    // The saw moving too: a master's acceleration then shapes the slave's start.
    let slow = AxisCommandCall::move_velocity(1, [100.0, 2000.0, 2000.0, 1e5]);
    assert_eq!(run.call(SAW as u32, &slow).unwrap().error_id, 0);
    run.steps(1000);
    run
}

/// Couples the saw to the strip's encoder when `pick` likes the encoder's acceleration (the
/// watchdog: 2,000 ticks), with check and operation bits `mask`; the number of points of the
/// planned phase (the organisation field NumberOfRows: 2 for a lone fifth-order polynomial,
/// 3 once a straight piece joins it).
fn points_of_the_plan(run: &mut Harness, mask: u32, pick: impl Fn(f64) -> bool) -> u32 {
    let mut picked = false;
    for _ in 0..2000 {
        if pick(encoder(run, STRIP).acceleration) {
            picked = true;
            break;
        }
        run.step();
    }
    assert!(picked, "no tick with such an acceleration");
    let m0 = encoder(run, STRIP).position;
    let call = SawGearInCall {
        master: STRIP as u32,
        master_source: 1,
        target: SawSyncTarget::Position.raw(),
        master_sync_position: m0 + 1000.0,
        slave_sync_position: 600.0,
        ratio_numerator: 1.0,
        ratio_denominator: 1,
        mask,
        ..SawGearInCall::default()
    };
    assert_eq!(run.call(SAW as u32, &call).unwrap().error_id, 0);
    let org = run.call(SAW as u32, &SawCharacCall { part: 2 }).unwrap();
    org.values[1] as u32
}

/// Below 2 x 0.1 um / (1 ms)^2 = 200 mm/s^2 the encoder's acceleration counts as none at
/// coupling, and the planner joins a straight piece to its polynomial (step 1); a real
/// acceleration above it is kept and leaves the lone polynomial. IGNOREMASTERACC drops any.
#[test]
fn an_encoder_acceleration_below_the_threshold_counts_as_none_at_coupling() {
    let quantised = |a: f64| a != 0.0 && a.abs() < 200.0;
    let mut run = strip_at_speed(0.00003);
    assert_eq!(points_of_the_plan(&mut run, 0, quantised), 3);
    // A noisier encoder: above the threshold the acceleration stands, unless ignored.
    let beyond = |a: f64| a.abs() > 250.0;
    let mut run = strip_at_speed(0.0003);
    assert_eq!(points_of_the_plan(&mut run, 0, beyond), 2);
    let mut run = strip_at_speed(0.0003);
    assert_eq!(points_of_the_plan(&mut run, m::IGNOREMASTERACC, beyond), 3);
}
