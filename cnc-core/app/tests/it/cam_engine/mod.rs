//! The cam engine in the machine tick: the conveyor scenario end to end in-process (the PLC's
//! cam blocks through the acyclic service), the coupling law checked tick by tick against
//! the master's set-points, the activation modes, switching with automatic offsets, and
//! every refusal with its code while the axis keeps doing what it did.

use cnc_app::scenario::{InProcess, Scenario};
use cnc_core::cam::coupling::{CamLaw, Scaling};
use cnc_core::cam::{CamProfile, ProfileCursor};
use cnc_core::setpoint::Kinematic;
use hli::calls::cam::CamCouplingError;
use hli::calls::cam::CamStartMode;
use hli::calls::cam::{CamInCall, CamOutCall, CamReply, CamScalingCall, CamTableSelectCall};
use hli::calls::{AcyclicCall, CallKind};
use hli::enums::{AxisError, AxisState, CouplingState};
use hli::views::CncView;
use hli::wire::{encode_body, AcyclicRequest};
use std::path::PathBuf;

mod data;
mod encoder;
mod manual_gaps;
mod modes;
mod recovery;
mod selection;
mod superimposed;

const MASTER: usize = 0;
const SLAVE: usize = 1;

fn scenarios() -> PathBuf {
    tests::cli::repo_root().join("scenarios")
}

fn seed_cam() -> CamProfile {
    let text = std::fs::read(scenarios().join("cams/seed_example.json")).unwrap();
    cnc_core::cam::file::parse(&text, Default::default())
        .unwrap()
        .profile
}

/// A machine with a conveyor and a lifter, tables 1 (the seed's motion function) and 2
/// (the stroke table), no PLC: the tests call the engine themselves.
fn machine(extra: &str) -> InProcess {
    let toml = format!(
        "cycle_ms = 1.0\nticks = 10\n\
         [[axis]]\nname = \"Conveyor\"\nkind = \"rotary\"\npower = true\nvelocity = 720.0\n\
         acceleration = 3600.0\ndeceleration = 3600.0\njerk = 36000.0\n\
         [[axis]]\nname = \"Lifter\"\npower = true\nsoft_limits = [-100.0, 200.0]\n\
         following_error_limit = 50.0\n\
         [[axis]]\nname = \"Other\"\npower = true\n\
         [[cam_table]]\nfile = \"seed_example.json\"\n\
         [[cam_table]]\nfile = \"stroke_table.json\"\n{extra}"
    );
    let s = Scenario::parse("cams.toml", &toml, |f| {
        let path = scenarios().join("cams").join(f);
        Ok((path.clone(), std::fs::read_to_string(path).unwrap()))
    })
    .unwrap();
    InProcess::new(&s, 0).unwrap()
}

fn call<C: AcyclicCall<Reply = CamReply>>(run: &mut InProcess, target: u32, body: C) -> u32 {
    let (body, body_len) = encode_body(&body);
    let request = AcyclicRequest {
        invoke_id: 1,
        kind: C::KIND.raw(),
        target,
        body_len,
        body,
    };
    let view = CncView::new(&run.memory);
    let (reply, len) = run
        .machine
        .dispatch(&view, C::KIND, &request)
        .expect("answered");
    let reply: CamReply = bytemuck::pod_read_unaligned(&reply[..len as usize]);
    reply.error_id
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
fn select_cyclic(run: &mut InProcess, table: u32) {
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

fn run_master(run: &mut InProcess, velocity: f64) {
    let command =
        hli::calls::axis::AxisCommandCall::move_velocity(1, [velocity, 3600.0, 3600.0, 36000.0]);
    let (body, body_len) = encode_body(&command);
    let request = AcyclicRequest {
        invoke_id: 2,
        kind: CallKind::AXIS_COMMAND.raw(),
        target: MASTER as u32,
        body_len,
        body,
    };
    let view = CncView::new(&run.memory);
    run.machine
        .dispatch(&view, CallKind::AXIS_COMMAND, &request)
        .unwrap();
}

fn set(run: &InProcess, axis: usize) -> Kinematic {
    run.machine.axes().axis(axis).unwrap().setpoint()
}

fn phase(run: &InProcess, axis: usize) -> AxisState {
    run.machine
        .axes()
        .axis(axis)
        .unwrap()
        .motion_state(set(run, axis))
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
fn switchable_at_speed() -> InProcess {
    let mut run = machine("");
    run.step(0.001);
    select_cyclic(&mut run, 1);
    let ext = CamInCall {
        extended: 1,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, SLAVE as u32, ext), 0);
    run_master(&mut run, 360.0);
    for _ in 0..700 {
        run.step(0.001);
    }
    run
}

/// The zigzag of the compatibility scenario's table 22 (+-9 per turn, linear) at master `m`.
fn zigzag(m: f64) -> f64 {
    let m = m.rem_euclid(360.0);
    match m {
        m if m < 90.0 => m / 10.0,
        m if m < 270.0 => 9.0 - (m - 90.0) / 10.0,
        m => -9.0 + (m - 270.0) / 10.0,
    }
}

/// The seed cam's point 4 (the fall's start at master 240) at slave position `slave`.
pub(crate) fn seed_point_4(slave: f64) -> hli::calls::cam::McMotionFunctionPoint {
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

/// MC_WriteMotionFunctionPoint's call of one point, in one chunk.
pub(crate) fn one_point_write(
    point: hli::calls::cam::McMotionFunctionPoint,
) -> hli::calls::cam::CamPointsWriteCall {
    let mut points = [hli::calls::cam::McMotionFunctionPoint::default(); 4];
    points[0] = point;
    hli::calls::cam::CamPointsWriteCall {
        first: point.point_index,
        count: 1,
        flags: hli::calls::cam::CAM_CHUNK_FIRST | hli::calls::cam::CAM_CHUNK_LAST,
        total: 1,
        points,
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

/// The first steps of a timeline on the seed cam: table 1 selected cyclic and absolute, the
/// lifter (axis 1) coupled to the conveyor (axis 0), and the conveyor run at 360 degree/s.
const COUPLED_AND_RUNNING: &str = r#"
[[step]]
at_tick = 2
call = { block = "MC_CamTableSelect", instance = "select", axis = 1, table = 1, periodic = true, master_absolute = true, slave_absolute = true }
[[step]]
wait = "select.Done"
call = { block = "MC_CamIn", instance = "cam", axis = 1, master = 0, table = 1, start_mode = "absolute" }
[[step]]
wait = "cam.InSync"
call = { block = "MC_MoveVelocity", instance = "run", axis = 0, velocity = 360.0, direction = 1, acceleration = 3600.0, deceleration = 3600.0, jerk = 36000.0 }
"#;

/// The line of block `instance` in a timeline's report.
fn block_line(report: &str, instance: &str) -> String {
    let start = format!("block {instance} ");
    let line = report.lines().find(|l| l.starts_with(&start));
    line.unwrap_or_else(|| panic!("no block {instance}\n{report}"))
        .to_string()
}

/// A scenario `toml` whose `plc.toml` is `timeline` and whose other files are the cam
/// examples (`scenarios/cams`).
fn with_timeline(name: &str, toml: &str, timeline: &str) -> Scenario {
    with_timeline_result(name, toml, timeline).unwrap()
}

/// [`with_timeline`], or why the scenario is refused.
fn with_timeline_result(name: &str, toml: &str, timeline: &str) -> Result<Scenario, String> {
    Scenario::parse(name, toml, |f| {
        if f == "plc.toml" {
            return Ok((PathBuf::from(f), timeline.to_string()));
        }
        let path = scenarios().join("cams").join(f);
        Ok((path.clone(), std::fs::read_to_string(path).unwrap()))
    })
    .map_err(|e| e.to_string())
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

#[test]
fn the_conveyor_scenario_follows_the_law_scales_changes_a_point_and_decouples() {
    let s = Scenario::load(&scenarios().join("cam-conveyor/scenario.toml")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let original = seed_cam();
    let changed = changed_cam(&original);
    let law = seed_law(true);
    // The three phases: scaling 1 with the original cam, 0.5 with it, 0.5 with the changed
    // one. Each switch happens where the laws before and after agree (the rest at the cycle
    // start), so the phase a tick belongs to is the first that explains it from the last.
    let phases = [(1.0, &original), (0.5, &original), (0.5, &changed)];
    let mut phase = 0;
    let mut entered = [None; 3];
    let mut synced_ticks = 0;
    let mut last: Option<f64> = None;
    let mut max_step: f64 = 0.0;
    for tick in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let slave = set(&run, SLAVE);
        if let Some(p) = last {
            max_step = max_step.max((slave.position - p).abs());
        }
        last = Some(slave.position);
        if run.machine.axes().axis(SLAVE).unwrap().coupling().is_none()
            || self::phase(&run, SLAVE) != AxisState::SlaveSynchronous
        {
            continue;
        }
        synced_ticks += 1;
        let master = set(&run, MASTER);
        let fits = |(ss, profile): (f64, &CamProfile)| {
            let expected = law_at(&law, profile, master);
            (slave.position - ss * expected.position).abs() < 1e-9
                && (slave.velocity - ss * expected.velocity).abs() < 1e-6
        };
        while !fits(phases[phase]) {
            phase += 1;
            assert!(
                phase < 3,
                "tick {tick}: slave {slave:?} for master {master:?} fits no phase"
            );
            entered[phase] = Some((tick, law.locate(master.position)));
        }
    }
    assert!(synced_ticks > 3000, "synchronous for {synced_ticks} ticks");
    // Both changes took effect after they were sent (1700, 2602), each in the cam's first 30
    // degrees of a new turn (where it rests and the phases agree, they cannot be told apart).
    for (k, sent) in [(1, 1700), (2, 2602)] {
        let (tick, at) = entered[k].unwrap_or_else(|| panic!("phase {k} never came"));
        assert!(tick > sent, "phase {k} at tick {tick}");
        assert!(at.local <= 30.5, "phase {k} at {} degrees", at.local);
    }
    let (t1, a1) = entered[1].unwrap();
    let (t2, a2) = entered[2].unwrap();
    assert!(t2 > t1 && a2.cycle > a1.cycle);
    // No jump anywhere: at most one tick's travel at the cam's top speed.
    assert!(max_step < 0.35, "largest step {max_step} mm");
    // Decoupled in a rest phase: free, at rest, where the cam left it.
    let lifter = run.machine.axes().axis(SLAVE).unwrap();
    assert!(lifter.coupling().is_none());
    assert_eq!(set(&run, SLAVE).velocity, 0.0);
    assert!(lifter.error().is_none());
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(report.contains("InSync"), "{report}");
    assert!(
        report.contains("block out (MC_CamOut on gpAx[1]): Done"),
        "{report}"
    );
    assert!(
        report.contains("block point (MC_WriteMotionFunctionPoint on gpAx[1]): Done"),
        "{report}"
    );
}

#[test]
fn refusals_carry_their_code_and_leave_the_axes_alone() {
    let mut run = machine("[[gear]]\nmaster = \"Conveyor\"\nslave = \"Other\"\nratio = 1.0\n");
    for _ in 0..5 {
        run.step(0.001);
    }
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
        run.step(0.001);
        assert!(run.machine.axes().axis(SLAVE).unwrap().coupling().is_none());
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
    run.step(0.001);
    assert_eq!(
        call(&mut run, SLAVE as u32, bad_scaling),
        CamCouplingError::ModeCombination.raw()
    );
    // The gear slave (axis 2) kept following its master through all of this.
    assert_eq!(
        run.machine
            .axes()
            .axis(2)
            .unwrap()
            .coupling()
            .map(|c| c.kind),
        Some(CouplingState::GearVelocity)
    );
}

#[test]
fn an_axis_position_activation_holds_the_slave_until_the_master_passes_it() {
    let mut run = machine("");
    run.step(0.001);
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
        run.step(0.001);
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
        run.step(0.001);
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
    let mut run = machine("");
    run.step(0.001);
    // A cyclic table with a stroke: 0..360 -> 0..10, linear, loaded over the acyclic service.
    let rows: Vec<[f64; 2]> = (0..=36)
        .map(|i| [i as f64 * 10.0, i as f64 * 10.0 / 36.0])
        .collect();
    for (k, chunk) in rows.chunks(hli::calls::cam::CAM_ROWS_PER_CALL).enumerate() {
        let first = k * hli::calls::cam::CAM_ROWS_PER_CALL;
        let last = first + chunk.len() == rows.len();
        let call = rows_chunk(chunk, first, rows.len(), last);
        let reply: CamReply = bytemuck::pod_read_unaligned(&dispatch_raw(&mut run, 9, &call));
        assert_eq!(reply.error_id, 0);
    }
    // The slave climbs past the Lifter's limit of 200: the other axis (limits +-1000).
    const SLAVE: usize = 2;
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(9)), 0);
    run_master(&mut run, 720.0);
    for _ in 0..45_000 {
        run.step(0.001);
    }
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
        run.machine
            .axes()
            .axis(SLAVE)
            .unwrap()
            .coupling()
            .map(|c| c.kind),
        Some(CouplingState::Cam)
    );
}

fn dispatch_raw<C: AcyclicCall>(run: &mut InProcess, target: u32, body: &C) -> Vec<u8> {
    let (body, body_len) = encode_body(body);
    let request = AcyclicRequest {
        invoke_id: 3,
        kind: C::KIND.raw(),
        target,
        body_len,
        body,
    };
    let view = CncView::new(&run.memory);
    let (reply, len) = run.machine.dispatch(&view, C::KIND, &request).unwrap();
    reply[..len as usize].to_vec()
}

/// The error id a rows chunk for table `id` is answered with (0: taken).
fn rows_answer(run: &mut InProcess, id: u32, chunk: &hli::calls::cam::CamRowsWriteCall) -> u32 {
    bytemuck::pod_read_unaligned::<CamReply>(&dispatch_raw(run, id, chunk)).error_id
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
fn read_all(
    run: &mut InProcess,
    target: u32,
    call: hli::calls::cam::CamReadCall,
) -> (Vec<f64>, u32) {
    let mut values = Vec::new();
    let mut columns = 1;
    for part in 0.. {
        let reply: hli::calls::cam::CamValuesReply = bytemuck::pod_read_unaligned(&dispatch_raw(
            run,
            target,
            &hli::calls::cam::CamReadCall { part, ..call },
        ));
        assert_eq!(reply.error_id, 0, "part {part}");
        values.extend_from_slice(&reply.values[..reply.count as usize]);
        columns = reply.columns;
        if values.len() >= reply.total as usize {
            break;
        }
    }
    (values, columns)
}
