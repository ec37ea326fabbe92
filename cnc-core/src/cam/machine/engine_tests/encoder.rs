//! A multi-table slave on an encoder master (issue 37 item 2): CamTableCoupleAxesMultiTables
//! with `master_source` actual follows the master's encoder, noise and all, not its set-point.

use super::*;
use crate::axis::config::DriveLink;
use crate::axis::sim_drive::{DriveModel, SimDriveConfig};
use hli::calls::axis::AxisCommandCall;

/// A wheel on a slow drive (PT1, 40 ms) whose encoder reads with noise, a feeder, and table 5:
/// a straight line of slope 1/2 from 0 to 1000.
fn wheel_and_feeder() -> Harness {
    let mut wheel = AxisConfig::linear("Wheel", 1);
    wheel.soft_limits = Some([-1e4, 1e4]);
    let pt1 = DriveModel::Pt1 {
        t1_ms: 40.0,
        dead_time_ticks: 0,
    };
    let sim = pt1.simulated(0.0).expect("a simulated drive");
    wheel.drive = DriveLink::Simulated(SimDriveConfig {
        encoder_noise: 0.00003,
        ..sim
    });
    let mut feeder = AxisConfig::linear("Feeder", 2);
    feeder.soft_limits = Some([-1e4, 1e4]);
    let line = r#"{ "kind": "table", "id": 5, "table_type": "non_equidistant",
        "rows": [[0, 0], [1000, 500]] }"#;
    powered(vec![wheel, feeder], &[], vec![cam_table(line.as_bytes())])
}

fn couple(run: &mut Harness, master_source: u32) {
    assert_eq!(call(run, SLAVE as u32, multi_couple(5, master_source)), 0);
}

/// Runs the wheel at 100 mm/s and halts it; every tick, `follows` gets the feeder's set-point,
/// the wheel's encoder position and its set-point position.
fn run_wheel(run: &mut Harness, mut follows: impl FnMut(f64, f64, f64)) {
    let go = AxisCommandCall::move_velocity(1, [100.0, 1000.0, 1000.0, 1e5]);
    assert_eq!(run.call(MASTER as u32, &go).unwrap().error_id, 0);
    for tick in 0..2500 {
        if tick == 1500 {
            let halt = AxisCommandCall::halt(1000.0, 1e5);
            assert_eq!(run.call(MASTER as u32, &halt).unwrap().error_id, 0);
        }
        run.step();
        let encoder = run.machine.axes().master(MASTER, true).unwrap();
        follows(
            set(run, SLAVE).position,
            encoder.position,
            set(run, MASTER).position,
        );
    }
}

#[test]
fn a_multi_table_slave_follows_an_encoder_master() {
    let mut run = wheel_and_feeder();
    run.step();
    couple(&mut run, 1);
    let start = set(&run, SLAVE).position;
    let mut lag = 0.0f64;
    run_wheel(&mut run, |feeder, encoder, setpoint| {
        // feeder = start + (encoder - where it was) / 2, to rounding, whatever the noise.
        assert!(
            (feeder - start - 0.5 * encoder).abs() < 1e-9,
            "{feeder} {encoder}"
        );
        lag = lag.max((setpoint - encoder).abs());
    });
    // The encoder was not the set-point: the drive lags it by millimetres.
    assert!(lag > 1.0, "{lag}");
    // A coupling to the set-point (the default) follows that instead.
    let mut run = wheel_and_feeder();
    run.step();
    couple(&mut run, 0);
    run_wheel(&mut run, |feeder, _, setpoint| {
        assert!(
            (feeder - start - 0.5 * setpoint).abs() < 1e-9,
            "{feeder} {setpoint}"
        );
    });
    // An unknown source is refused.
    let mut run = wheel_and_feeder();
    run.step();
    assert_eq!(
        call(&mut run, SLAVE as u32, multi_couple(5, 2)),
        CamCouplingError::UnknownMode.raw()
    );
}
