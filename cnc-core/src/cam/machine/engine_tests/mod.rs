//! The cam engine in the machine tick, on the in-library machine harness
//! ([`crate::harness::Harness`]): the coupling law checked tick by tick against the master's
//! set-points, the activation modes, switching with automatic offsets, and every refusal with
//! its code while the axis keeps doing what it did. Each machine is the one a scenario of
//! these axes and cam tables makes, built here in Rust: single axes powered before the first
//! tick, the engines in the engine set's order (a gear where a test has one, the cams, the
//! saw), calls straight to the machine. The PLC's cam blocks (timelines, scenarios with a
//! PLC) are tested in the application.
//!
//! * `data`: table data in chunks, points, reads, a transfer cut by a stop;
//! * `modes`: actual-value masters, scaling activation modes, coupling starts, online point
//!   changes;
//! * `manual_gaps`: gaps of the camming audit closed through the machine;
//! * `selection`: MC_CamTableSelect's absolute and relative, MC_CamScaling with activation
//!   OFF;
//! * `superimposed`: MC_MoveSuperimposed on a cam slave;
//! * `recovery`: MC_CamInfo after an emergency stop and a fault;
//! * `encoder`: a multi-table slave on an encoder master.

mod data;
mod encoder;
mod manual_gaps;
mod modes;
mod recovery;
mod selection;
mod superimposed;

use crate::axis::config::AxisConfig;
use crate::cam::coupling::{CamLaw, Scaling};
use crate::cam::machine::CamEngine;
use crate::cam::online::CamStore;
use crate::cam::{CamProfile, ProfileCursor};
use crate::gear::{GearEngine, GearSpec};
use crate::harness::Harness;
use crate::machine::Engine;
use crate::saw::machine::SawEngine;
use crate::setpoint::Kinematic;
use hli::calls::cam::CamCouplingError;
use hli::calls::cam::CamStartMode;
use hli::calls::cam::{CamInCall, CamOutCall, CamReply, CamScalingCall, CamTableSelectCall};
use hli::calls::AcyclicCall;
use hli::enums::{AxisError, AxisState, CouplingState};

/// The tick of every machine here (a scenario's `cycle_ms = 1.0`).
const TICK: f64 = 0.001;
const MASTER: usize = 0;
const SLAVE: usize = 1;

/// A JSON cam file's table as `[[cam_table]]` reads it: its profile under the file's ID.
fn cam_table(json: &[u8]) -> (u32, CamProfile) {
    let cam = crate::cam::file::parse(json, Default::default()).unwrap();
    (cam.id.expect("the file gives its ID"), cam.profile)
}

/// The repository's cam file `name` (`scenarios/cams`) as a table.
fn cam_file(name: &str) -> (u32, CamProfile) {
    let path = tests::cli::repo_root().join("scenarios/cams").join(name);
    cam_table(&std::fs::read(path).unwrap())
}

fn seed_cam() -> CamProfile {
    cam_file("seed_example.json").1
}

/// A machine of `axes`, every one powered before the first tick, with the engines a scenario
/// of them makes, in their tick order: the gear engine of `gears` (none without), the cam
/// engine holding `tables`, the saw engine. Not ticked yet.
fn powered(axes: Vec<AxisConfig>, gears: &[GearSpec], tables: Vec<(u32, CamProfile)>) -> Harness {
    let n = axes.len();
    let mut store = CamStore::new();
    for (id, profile) in tables {
        store.insert(id, profile).unwrap();
    }
    let mut engines: Vec<Box<dyn Engine>> = Vec::new();
    if !gears.is_empty() {
        engines.push(Box::new(GearEngine::new(gears, n).unwrap()));
    }
    engines.push(Box::new(CamEngine::new(store, n)));
    engines.push(Box::new(SawEngine::new(n, TICK)));
    let mut run = Harness::new(TICK, axes, engines).unwrap();
    run.power_all();
    run
}

/// The conveyor (ID 1: rotary, 720 degrees/s, 3600 /s^2 both ways, 36000 /s^3), the lifter
/// (ID 2: software limits -100..200, a following-error limit of 50) and "Other" (ID 3), both
/// linear with the defaults otherwise.
fn conveyor_axes() -> Vec<AxisConfig> {
    let mut conveyor = AxisConfig::rotary("Conveyor", 1);
    conveyor.dynamics.velocity = 720.0;
    conveyor.dynamics.acceleration = 3600.0;
    conveyor.dynamics.deceleration = 3600.0;
    conveyor.dynamics.jerk = 36000.0;
    let mut lifter = AxisConfig::linear("Lifter", 2);
    lifter.soft_limits = Some([-100.0, 200.0]);
    lifter.following_error_limit = 50.0;
    vec![conveyor, lifter, AxisConfig::linear("Other", 3)]
}

/// A machine with a conveyor and a lifter, tables 1 (the seed's motion function) and 2
/// (the stroke table), no PLC: the tests call the engine themselves.
fn machine() -> Harness {
    machine_with_gears(&[])
}

/// [`machine`] with the gear engine of `gears` before the cams.
fn machine_with_gears(gears: &[GearSpec]) -> Harness {
    let tables = vec![cam_file("seed_example.json"), cam_file("stroke_table.json")];
    powered(conveyor_axes(), gears, tables)
}

/// A cam call's ErrorID.
fn call<C: AcyclicCall<Reply = CamReply>>(run: &mut Harness, target: u32, body: C) -> u32 {
    run.call(target, &body).expect("answered").error_id
}

/// The reply to `body` at `target`.
fn answer<C: AcyclicCall>(run: &mut Harness, target: u32, body: &C) -> C::Reply {
    run.call(target, body).unwrap()
}

/// CamTableCoupleAxesMultiTables of the slave to the master through profile table `table`
/// alone, following the master's set-point (`master_source` 0) or its encoder (1).
fn multi_couple(table: u32, master_source: u32) -> hli::calls::cam::CamMultiCoupleCall {
    let mut table_ids = [0; hli::calls::cam::CAM_MULTI_TABLES];
    table_ids[0] = table;
    hli::calls::cam::CamMultiCoupleCall {
        master: MASTER as u32,
        on: 1,
        tables: 1,
        profiles: 1,
        table_ids,
        master_source,
        reserved: 0,
    }
}

/// MC_CamTableSelect: couplings through `table` run cyclic, absolute.
fn select_cyclic(run: &mut Harness, table: u32) {
    let select = CamTableSelectCall {
        periodic: 1,
        master_absolute: 1,
        slave_absolute: 1,
        reserved: 0,
    };
    assert_eq!(call(run, table, select), 0);
}

fn cam_in(table: u32) -> CamInCall {
    CamInCall {
        master: MASTER as u32,
        table_id: table,
        start_mode: 1,
        master_scaling: 1.0,
        slave_scaling: 1.0,
        ..CamInCall::default()
    }
}

fn run_master(run: &mut Harness, velocity: f64) {
    let command =
        hli::calls::axis::AxisCommandCall::move_velocity(1, [velocity, 3600.0, 3600.0, 36000.0]);
    run.call(MASTER as u32, &command).unwrap();
}

fn set(run: &Harness, axis: usize) -> Kinematic {
    run.setpoint(axis)
}

fn phase(run: &Harness, axis: usize) -> AxisState {
    run.axis(axis).motion_state(set(run, axis))
}

/// MC_CamInExt switching the slave to the stroke table (2) when the master reaches cam
/// position 200, the rest as `cam_in`.
fn switch_to_stroke_at_200() -> CamInCall {
    CamInCall {
        extended: 1,
        activation_mode: 1,
        activation_position: 200.0,
        ..cam_in(2)
    }
}

/// The lifter coupled with MC_CamInExt to the seed cam (table 1, cyclic), the conveyor at
/// 360 degrees/s for 0.7 s: a coupling ready for a switch.
fn switchable_at_speed() -> Harness {
    let mut run = machine();
    run.step();
    select_cyclic(&mut run, 1);
    let ext = CamInCall {
        extended: 1,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, SLAVE as u32, ext), 0);
    run_master(&mut run, 360.0);
    run.steps(700);
    run
}

/// The seed cam's point 4 (the fall's start at master 240) at slave position `slave`.
fn seed_point_4(slave: f64) -> hli::calls::cam::McMotionFunctionPoint {
    hli::calls::cam::McMotionFunctionPoint {
        point_index: 4,
        function_type: 15,
        point_type: 2,
        rel_index_next_point: 1,
        master_pos: 240.0,
        slave_pos: slave,
        ..Default::default()
    }
}

/// The law of a slave coupled absolute, unscaled, to the seed cam at master 0, slave 0.
fn seed_law(periodic: bool) -> CamLaw {
    CamLaw::new(
        &seed_cam(),
        Scaling::default(),
        CamStartMode::Absolute,
        periodic,
        0.0,
        0.0,
    )
}

fn law_at(law: &CamLaw, profile: &CamProfile, master: Kinematic) -> Kinematic {
    law.slave(profile, &mut ProfileCursor::default(), &master).0
}

/// The seed cam with point 4 at 30 instead of 40, as the conveyor's PLC writes it.
fn changed_cam(profile: &CamProfile) -> CamProfile {
    let CamProfile::MotionFunction(f) = profile else {
        unreachable!("the seed cam is a motion function")
    };
    let mut p4 = f.points()[3];
    p4.slave = 30.0;
    CamProfile::MotionFunction(f.with_points_written(4, &[p4]).unwrap())
}

/// The error id a rows chunk for table `id` is answered with (0: taken).
fn rows_answer(run: &mut Harness, id: u32, chunk: &hli::calls::cam::CamRowsWriteCall) -> u32 {
    answer(run, id, chunk).error_id
}

fn rows_chunk(
    rows: &[[f64; 2]],
    first: usize,
    total: usize,
    last: bool,
) -> hli::calls::cam::CamRowsWriteCall {
    let mut call = hli::calls::cam::CamRowsWriteCall {
        first_row: first as u32,
        count: rows.len() as u32,
        flags: if last {
            hli::calls::cam::CAM_CHUNK_LAST
        } else {
            0
        } | if first == 0 {
            hli::calls::cam::CAM_CHUNK_FIRST
        } else {
            0
        },
        total: total as u32,
        table_type: 10,
        interpolation: 0,
        periodic: 1,
        ..Default::default()
    };
    call.rows[..rows.len()].copy_from_slice(rows);
    call
}

/// Every part of a read, joined.
fn read_all(run: &mut Harness, target: u32, call: hli::calls::cam::CamReadCall) -> (Vec<f64>, u32) {
    let mut values = Vec::new();
    let mut columns = 1;
    for part in 0.. {
        let reply = answer(run, target, &hli::calls::cam::CamReadCall { part, ..call });
        assert_eq!(reply.error_id, 0, "part {part}");
        values.extend_from_slice(&reply.values[..reply.count as usize]);
        columns = reply.columns;
        if values.len() >= reply.total as usize {
            break;
        }
    }
    (values, columns)
}

#[test]
fn refusals_carry_their_code_and_leave_the_axes_alone() {
    // [[gear]] master = "Conveyor", slave = "Other", ratio = 1.0
    let gear = GearSpec {
        master: MASTER,
        slave: 2,
        ratio: 1.0,
    };
    let mut run = machine_with_gears(&[gear]);
    run.steps(5);
    let before = set(&run, SLAVE);
    let nan = CamInCall {
        slave_scaling: f64::NAN,
        ..cam_in(1)
    };
    let relative_next_cycle = CamInCall {
        start_mode: 2,
        activation_mode: 3,
        extended: 1,
        ..cam_in(1)
    };
    let own_master = CamInCall {
        master: SLAVE as u32,
        ..cam_in(1)
    };
    let cases: [(u32, CamInCall, u32); 6] = [
        (SLAVE as u32, cam_in(9), 0x4B32),
        (
            SLAVE as u32,
            own_master,
            CamCouplingError::MasterIsSlave.raw(),
        ),
        (SLAVE as u32, nan, CamCouplingError::BadParameter.raw()),
        (
            SLAVE as u32,
            relative_next_cycle,
            CamCouplingError::ModeCombination.raw(),
        ),
        (2, cam_in(1), AxisError::Coupled.raw()),
        (
            SLAVE as u32,
            CamInCall {
                master: 7,
                ..cam_in(1)
            },
            CamCouplingError::NoSuchMaster.raw(),
        ),
    ];
    for (target, body, code) in cases {
        assert_eq!(call(&mut run, target, body), code, "{body:?}");
        run.step();
        assert!(run.axis(SLAVE).coupling().is_none());
        assert_eq!(set(&run, SLAVE), before);
    }
    assert_eq!(
        call(&mut run, SLAVE as u32, CamOutCall::default()),
        CamCouplingError::NotCamCoupled.raw()
    );
    let select = CamTableSelectCall {
        periodic: 1,
        master_absolute: 1,
        slave_absolute: 1,
        reserved: 0,
    };
    assert_eq!(call(&mut run, 44, select), 0x4B32);
    // Coupled with MC_CamIn: MC_CamInExt cannot switch it.
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
    let ext = CamInCall {
        extended: 1,
        ..cam_in(2)
    };
    assert_eq!(
        call(&mut run, SLAVE as u32, ext),
        CamCouplingError::NotSwitchable.raw()
    );
    // Before the coupling is active (its activation comes with the next tick) a scaling is
    // refused as pending; then a mode combination the seed forbids (an activation mode
    // scalings do not take) with its own code.
    let bad_scaling = CamScalingCall {
        activation_mode: 7,
        master_scaling: 1.0,
        slave_scaling: 1.0,
        ..CamScalingCall::default()
    };
    assert_eq!(
        call(&mut run, SLAVE as u32, bad_scaling),
        CamCouplingError::CouplingPending.raw()
    );
    run.step();
    assert_eq!(
        call(&mut run, SLAVE as u32, bad_scaling),
        CamCouplingError::ModeCombination.raw()
    );
    // The gear slave (axis 2) kept following its master through all of this.
    assert_eq!(
        run.axis(2).coupling().map(|c| c.kind),
        Some(CouplingState::GearVelocity)
    );
}

#[test]
fn an_axis_position_activation_holds_the_slave_until_the_master_passes_it() {
    let mut run = machine();
    run.step();
    select_cyclic(&mut run, 1);
    let at_axis = CamInCall {
        activation_mode: 2,
        activation_position: 100.0,
        extended: 1,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, SLAVE as u32, at_axis), 0);
    run_master(&mut run, 360.0);
    let profile = seed_cam();
    let law = seed_law(true);
    let mut started = None;
    for tick in 0..2000 {
        run.step();
        let m = set(&run, MASTER);
        let synchronous = phase(&run, SLAVE) == AxisState::SlaveSynchronous;
        if !synchronous {
            assert_eq!(phase(&run, SLAVE), AxisState::SlavePrephase, "tick {tick}");
            assert!(m.position < 100.0 + 1e-9, "still waiting at {}", m.position);
            assert_eq!(set(&run, SLAVE).position, 0.0);
        } else {
            started.get_or_insert(m.position);
            let expected = law_at(&law, &profile, m).position;
            assert!((set(&run, SLAVE).position - expected).abs() < 1e-9);
        }
    }
    let start = started.expect("the coupling became active");
    assert!(
        (100.0..100.5).contains(&start),
        "active from master {start}"
    );
    // Passed already: refused, the coupling as it was.
    let passed = CamInCall {
        activation_mode: 2,
        activation_position: 10.0,
        extended: 1,
        ..cam_in(1)
    };
    assert_eq!(
        call(&mut run, 2, passed),
        CamCouplingError::ActivationPassed.raw()
    );
}

#[test]
fn switching_cams_mid_cycle_with_auto_offsets_keeps_the_slave_continuous() {
    let mut run = switchable_at_speed();
    // To the stroke table at cam position 200 (the next time round: the master is past it),
    // where the two cams differ by about 13: both offsets automatic, so neither the master's
    // place in the cycle nor the slave jumps.
    let switch = CamInCall {
        master_scaling_mode: 1,
        slave_scaling_mode: 1,
        interpolation: 2,
        ..switch_to_stroke_at_200()
    };
    assert_eq!(call(&mut run, SLAVE as u32, switch), 0);
    let mut last = set(&run, SLAVE).position;
    let mut max_step: f64 = 0.0;
    let mut positions = Vec::new();
    for _ in 0..2500 {
        run.step();
        let p = set(&run, SLAVE).position;
        max_step = max_step.max((p - last).abs());
        last = p;
        positions.push(p);
        assert_eq!(phase(&run, SLAVE), AxisState::SlaveSynchronous);
    }
    assert!(max_step < 0.35, "largest step {max_step}");
    // After the switch (within 900 ticks) the slave runs the stroke table's 0..16 profile,
    // shifted by the slave offset that kept it in place: over more than a whole turn.
    let tail = &positions[1000..];
    let (lo, hi) = tail
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(*p), b.max(*p)));
    assert!((hi - lo - 16.0).abs() < 0.1, "range {lo}..{hi}");
    assert!(
        lo.abs() > 1.0,
        "an offset kept the slave in place: {lo}..{hi}"
    );
}

#[test]
fn the_machine_tick_with_a_coupled_cam_slave_keeps_its_cycle_count_over_many_turns() {
    let mut run = machine();
    run.step();
    // A cyclic table with a stroke: 0..360 -> 0..10, linear, loaded over the acyclic service.
    let rows: Vec<[f64; 2]> = (0..=36)
        .map(|i| [i as f64 * 10.0, i as f64 * 10.0 / 36.0])
        .collect();
    for (k, chunk) in rows.chunks(hli::calls::cam::CAM_ROWS_PER_CALL).enumerate() {
        let first = k * hli::calls::cam::CAM_ROWS_PER_CALL;
        let last = first + chunk.len() == rows.len();
        let call = rows_chunk(chunk, first, rows.len(), last);
        let reply = answer(&mut run, 9, &call);
        assert_eq!(reply.error_id, 0);
    }
    // The slave climbs past the Lifter's limit of 200: the other axis (limits +-1000).
    const SLAVE: usize = 2;
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(9)), 0);
    run_master(&mut run, 720.0);
    run.steps(45_000);
    // 45 s at 720 deg/s: about 90 turns. The slave climbed 10 per turn from the coupling
    // (at the master's 0), exactly: the cycle counter neither lost nor gained a turn.
    let m = set(&run, MASTER);
    assert!(m.position > 360.0 * 85.0, "{}", m.position);
    let expected = m.position / 36.0;
    assert!(
        (set(&run, SLAVE).position - expected).abs() < 1e-6,
        "slave {} expected {expected}",
        set(&run, SLAVE).position
    );
    assert_eq!(
        run.axis(SLAVE).coupling().map(|c| c.kind),
        Some(CouplingState::Cam)
    );
}
