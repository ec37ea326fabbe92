//! MC_CamInfo after an emergency stop (seed 000 5.1.15): the coupling's last valid state stays
//! readable, and the recovery the seed describes runs with it: both axes back to where the
//! coupling last stood, coupled again with the offsets and the slave strokes accounted for,
//! and the slave then follows the very curve it followed before the stop.

use super::*;
use hli::calls::axis::AxisCommandCall;
use hli::calls::cam::{CamReadCall, CamReadKind};

/// A periodic table that climbs 20 per master period of 360 (its stroke), linear.
const STROKE_TABLE: &str = r#"{ "kind": "table", "id": 3, "table_type": "equidistant",
  "periodic": true, "interpolation": "linear",
  "rows": [[0, 0], [90, 5], [180, 10], [270, 15], [360, 20]] }"#;

/// A linear axis `name` (ID `id`) of these machines: software limits -1e5..`max`, 2000 /s,
/// 4000 /s^2 both ways, 1e6 /s^3.
fn recovery_axis(name: &str, id: u32, max: f64) -> AxisConfig {
    let mut c = AxisConfig::linear(name, id);
    c.soft_limits = Some([-1e5, max]);
    c.dynamics.velocity = 2000.0;
    c.dynamics.acceleration = 4000.0;
    c.dynamics.deceleration = 4000.0;
    c.dynamics.jerk = 1e6;
    c
}

/// A linear master and a slave (its software limit at `slave_max`), the stroke table as
/// table 3.
fn machine_to(slave_max: f64) -> Harness {
    let axes = vec![
        recovery_axis("Master", 1, 1e5),
        recovery_axis("Slave", 2, slave_max),
    ];
    powered(axes, &[], vec![cam_table(STROKE_TABLE.as_bytes())])
}

pub(super) fn machine() -> Harness {
    machine_to(1e5)
}

fn command(run: &mut Harness, axis: usize, c: AxisCommandCall) {
    let reply = run.call(axis as u32, &c).unwrap();
    assert_eq!(reply.error_id, 0, "axis {axis}: {c:?}");
}

/// MC_CamInfo of the slave (at `at` when given): its 40 values, or the refusal's code.
pub(super) fn cam_info(run: &mut Harness, at: Option<f64>) -> Result<Vec<f64>, u32> {
    let call = CamReadCall {
        what: CamReadKind::Info.raw(),
        flags: u32::from(at.is_some()),
        a: at.unwrap_or(0.0),
        ..Default::default()
    };
    let first = answer(run, SLAVE as u32, &call);
    if first.error_id != 0 {
        return Err(first.error_id);
    }
    Ok(read_all(run, SLAVE as u32, call).0)
}

fn tick_until(run: &mut Harness, what: &str, done: impl Fn(&Harness) -> bool) {
    for _ in 0..20_000 {
        run.step();
        if done(run) {
            return;
        }
    }
    panic!("{what}: not within 20 s");
}

#[test]
fn after_an_emergency_stop_cam_info_gives_the_last_valid_coupling_and_the_slave_is_recoupled_on_its_curve(
) {
    let mut run = machine();
    run.step();
    select_cyclic(&mut run, 3);
    let coupling = CamInCall {
        slave_scaling: 2.0,
        ..cam_in(3)
    };
    assert_eq!(call(&mut run, SLAVE as u32, coupling), 0);
    run_master(&mut run, 360.0);
    // 1.5 s: the master passes one period, the slave one stroke (2 x 20).
    for _ in 0..1500 {
        run.step();
    }
    let master_at_stop = set(&run, MASTER).position;
    assert!(
        master_at_stop > 360.0 && master_at_stop < 720.0,
        "{master_at_stop}"
    );
    // Emergency stop: every engine lets its axes go, the axes brake to rest.
    run.machine.stop("emergency stop (test)");
    tick_until(&mut run, "rest", |r| r.machine.at_rest());
    assert!(run.machine.rearm());
    assert!(run.axis(SLAVE).coupling().is_none());
    // The last valid state of the coupling.
    let v = cam_info(&mut run, None).expect("the last valid coupling after the stop");
    assert_eq!(v.len(), 40);
    assert_eq!((v[0], v[2]), (3.0, 1.0), "table 3, periodic");
    assert_eq!(
        (v[14], v[15], v[16], v[17]),
        (0.0, 0.0, 1.0, 2.0),
        "offsets, scalings"
    );
    assert_eq!(v[18], 40.0, "SumOfSlaveStrokes: one period of 2 x 20");
    assert!(
        (v[20] - master_at_stop).abs() < 1.0,
        "ActualMasterAxisPos {} at the stop {master_at_stop}",
        v[20]
    );
    let on_curve = |m: f64| 2.0 * (20.0 * (m / 360.0).floor() + 20.0 * (m % 360.0) / 360.0);
    assert!(
        (v[21] - on_curve(v[20])).abs() < 1e-9,
        "ActualSlaveAxisPos {}",
        v[21]
    );
    // Where the old coupling would have put the slave 100 further on.
    let ahead = cam_info(&mut run, Some(v[20] + 100.0)).unwrap()[21];
    // The recovery: both axes back to the coupling's last position, coupled again with the
    // strokes run so far added to the slave offset (a new coupling counts strokes from 0).
    let limits = [300.0, 3000.0, 3000.0, 1e6];
    command(
        &mut run,
        MASTER,
        AxisCommandCall::move_absolute(v[20], limits),
    );
    command(
        &mut run,
        SLAVE,
        AxisCommandCall::move_absolute(v[21], limits),
    );
    tick_until(&mut run, "back", |r| r.machine.at_rest());
    let again = CamInCall {
        master_offset: v[14],
        slave_offset: v[15] + v[18],
        master_scaling: v[16],
        slave_scaling: v[17],
        ..cam_in(3)
    };
    assert_eq!(call(&mut run, SLAVE as u32, again), 0);
    run.step();
    assert!(
        (set(&run, SLAVE).position - v[21]).abs() < 1e-9,
        "no jump at the coupling"
    );
    // A new coupling: the lost one is gone, its info is the new coupling's.
    assert_eq!(cam_info(&mut run, None).unwrap()[18], 0.0);
    command(
        &mut run,
        MASTER,
        AxisCommandCall::move_absolute(v[20] + 100.0, limits),
    );
    tick_until(&mut run, "ahead", |r| r.machine.at_rest());
    assert!(
        (set(&run, SLAVE).position - ahead).abs() < 1e-9,
        "the slave on the old curve: {} against {ahead}",
        set(&run, SLAVE).position
    );
    // Decoupled: nothing left to read.
    assert_eq!(call(&mut run, SLAVE as u32, CamOutCall::default()), 0);
    assert_eq!(
        cam_info(&mut run, None),
        Err(CamCouplingError::NotCamCoupled.raw())
    );
}

/// A slave that loses its coupling in the tick (here: a fault, its software limit reached
/// while coupled) keeps its last valid state for MC_CamInfo too, until MC_CamOut decouples
/// it (accepted once).
#[test]
fn a_slave_that_faults_while_coupled_keeps_its_last_valid_coupling_until_cam_out() {
    // The slave climbs 20 per period of 360: past 30 halfway through the second period.
    let mut run = machine_to(30.0);
    run.step();
    select_cyclic(&mut run, 3);
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(3)), 0);
    run_master(&mut run, 360.0);
    tick_until(&mut run, "the fault", |r| r.axis(SLAVE).error().is_some());
    run.step();
    assert!(run.axis(SLAVE).coupling().is_none());
    let v = cam_info(&mut run, None).expect("the last valid coupling");
    assert_eq!(v[18], 20.0, "one stroke of 20");
    // The coupling's last tick: the set-point that passed the limit (by one tick's 0.02).
    assert!(
        (v[21] - 30.0).abs() < 0.05,
        "the last slave position {}",
        v[21]
    );
    // Its table stays in use until then (the read rebuilds positions from it).
    let delete = |run: &mut Harness| {
        let d = hli::calls::cam::CamTableDeleteCall::default();
        call(run, 3, d)
    };
    assert_eq!(delete(&mut run), CamCouplingError::TableInUse.raw());
    // MC_CamOut decouples the lost coupling; then there is nothing to read or decouple.
    assert_eq!(call(&mut run, SLAVE as u32, CamOutCall::default()), 0);
    let refused = CamCouplingError::NotCamCoupled.raw();
    assert_eq!(cam_info(&mut run, None), Err(refused));
    assert_eq!(call(&mut run, SLAVE as u32, CamOutCall::default()), refused);
    assert_eq!(delete(&mut run), 0, "the table is free again");
}
