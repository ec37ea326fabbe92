//! The cam engine in the machine tick: the conveyor scenario end to end in-process (the PLC's
//! cam blocks through the acyclic service), the coupling law checked tick by tick against
//! the master's set-points, the activation modes, switching with automatic offsets, and
//! every refusal with its code while the axis keeps doing what it did.

use cnc_app::scenario::{InProcess, Scenario};
use cnc_core::cam::coupling::{CamLaw, Scaling};
use cnc_core::cam::{CamProfile, ProfileCursor};
use cnc_core::setpoint::Kinematic;
use hli::calls::cam::CamStartMode;
use hli::calls::cam::{CamInCall, CamOutCall, CamReply, CamScalingCall, CamTableSelectCall};
use hli::calls::{AcyclicCall, CallKind};
use hli::enums::{AxisError, AxisState, CamCouplingError, CouplingState};
use hli::views::CncView;
use hli::wire::{encode_body, AcyclicRequest};
use std::path::PathBuf;

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
    let law = CamLaw::new(
        &original,
        Scaling::default(),
        CamStartMode::Absolute,
        true,
        0.0,
        0.0,
    );
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
    let law = CamLaw::new(
        &profile,
        Scaling::default(),
        CamStartMode::Absolute,
        true,
        0.0,
        0.0,
    );
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
    // To the stroke table at cam position 200 (the next time round: the master is past it),
    // where the two cams differ by about 13: both offsets automatic, so neither the master's
    // place in the cycle nor the slave jumps.
    let switch = CamInCall {
        extended: 1,
        activation_mode: 1,
        activation_position: 200.0,
        master_scaling_mode: 1,
        slave_scaling_mode: 1,
        interpolation: 2,
        ..cam_in(2)
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

#[test]
fn a_table_of_100000_rows_arrives_in_chunks_and_a_coupling_runs_on_it() {
    let mut run = machine("");
    run.step(0.001);
    let total = 100_000;
    let rows: Vec<[f64; 2]> = (0..total)
        .map(|i| {
            [
                i as f64 * 0.0036,
                5.0 * (i as f64 / (total - 1) as f64 * std::f64::consts::TAU).sin(),
            ]
        })
        .collect();
    let chunks: Vec<&[[f64; 2]]> = rows.chunks(hli::calls::cam::CAM_ROWS_PER_CALL).collect();
    for (k, chunk) in chunks.iter().enumerate() {
        let first = k * hli::calls::cam::CAM_ROWS_PER_CALL;
        let last = k + 1 == chunks.len();
        let reply = dispatch_raw(&mut run, 5, &rows_chunk(chunk, first, total, last));
        let reply: CamReply = bytemuck::pod_read_unaligned(&reply);
        assert_eq!(reply.error_id, 0, "chunk {k}");
        if k % 1000 == 0 {
            // The machine ticks on between chunks: the upload never holds a tick up.
            run.step(0.001);
        }
    }
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(5)), 0);
    run_master(&mut run, 360.0);
    for _ in 0..3000 {
        run.step(0.001);
        assert!(run.machine.axes().axis(SLAVE).unwrap().error().is_none());
    }
    // The slave follows the uploaded wave (period 360, amplitude 5).
    let m = set(&run, MASTER).position;
    let expected = 5.0 * ((m.rem_euclid(360.0)) / 360.0 * std::f64::consts::TAU).sin();
    assert!(
        (set(&run, SLAVE).position - expected).abs() < 1e-3,
        "{} vs {expected}",
        set(&run, SLAVE).position
    );
    // A coupled table is not replaced.
    let one = rows_chunk(&rows[..13], 0, 13, true);
    let reply: CamReply = bytemuck::pod_read_unaligned(&dispatch_raw(&mut run, 5, &one));
    assert_eq!(reply.error_id, CamCouplingError::TableInUse.raw());
}

#[test]
fn chunks_out_of_order_and_bad_tables_are_refused_whole() {
    let mut run = machine("");
    run.step(0.001);
    let rows: Vec<[f64; 2]> = (0..26).map(|i| [i as f64, 0.0]).collect();
    let first = rows_chunk(&rows[..13], 0, 26, false);
    let skipped = rows_chunk(&rows[..13], 20, 26, true);
    let answer = |run: &mut InProcess, c: &hli::calls::cam::CamRowsWriteCall| {
        bytemuck::pod_read_unaligned::<CamReply>(&dispatch_raw(run, 7, c)).error_id
    };
    assert_eq!(answer(&mut run, &first), 0);
    assert_eq!(
        answer(&mut run, &skipped),
        CamCouplingError::ChunkOutOfOrder.raw()
    );
    // Nothing was stored: table 7 does not exist.
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(7)), 0x4B32);
    // A table whose masters do not rise: refused with the table code, nothing stored.
    let mut bad = rows.clone();
    bad[5][0] = 1.0;
    assert_eq!(answer(&mut run, &rows_chunk(&bad[..13], 0, 26, false)), 0);
    let reply = answer(&mut run, &rows_chunk(&bad[13..], 13, 26, true));
    assert!((0x4B30..=0x4B38).contains(&reply), "{reply:#x}");
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(7)), 0x4B32);
}

#[test]
fn points_read_back_and_a_refused_write_leaves_the_function() {
    use hli::calls::cam::{
        CamPointsReadCall, CamPointsReply, CamPointsWriteCall, McMotionFunctionPoint,
    };
    let mut run = machine("");
    run.step(0.001);
    let read = |run: &mut InProcess, first: u32| -> CamPointsReply {
        bytemuck::pod_read_unaligned(&dispatch_raw(
            run,
            1,
            &CamPointsReadCall { first, count: 0 },
        ))
    };
    let r = read(&mut run, 1);
    assert_eq!((r.error_id, r.count, r.total), (0, 4, 6));
    assert_eq!(r.points[3].master_pos, 240.0);
    assert_eq!(r.points[3].slave_pos, 40.0);
    let r = read(&mut run, 5);
    assert_eq!((r.count, r.points[1].master_pos), (2, 360.0));
    assert_eq!(read(&mut run, 7).error_id, 0x4B33);
    // A point whose master position breaks the monotonic order: refused whole.
    let mut p4: McMotionFunctionPoint = read(&mut run, 4).points[0];
    p4.master_pos = 400.0;
    let mut points = [McMotionFunctionPoint::default(); 4];
    points[0] = p4;
    let write = CamPointsWriteCall {
        first: 4,
        count: 1,
        flags: hli::calls::cam::CAM_CHUNK_FIRST | hli::calls::cam::CAM_CHUNK_LAST,
        total: 1,
        points,
    };
    let reply: CamReply = bytemuck::pod_read_unaligned(&dispatch_raw(&mut run, 1, &write));
    assert!(
        (0x4B30..=0x4B38).contains(&reply.error_id),
        "{:#x}",
        reply.error_id
    );
    run.step(0.001);
    assert_eq!(read(&mut run, 4).points[0].master_pos, 240.0);
    // A good one applies (instantaneous mode, nothing coupled).
    points[0].master_pos = 250.0;
    let write = CamPointsWriteCall { points, ..write };
    let reply: CamReply = bytemuck::pod_read_unaligned(&dispatch_raw(&mut run, 1, &write));
    assert_eq!(reply.error_id, 0);
    run.step(0.001);
    assert_eq!(read(&mut run, 4).points[0].master_pos, 250.0);
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

#[test]
fn reads_give_dynamics_characteristics_value_tables_and_the_coupling_info() {
    use hli::calls::cam::{
        CamReadCall, CAM_READ_CHARACTERISTICS, CAM_READ_INFO, CAM_READ_SLAVE_DYNAMICS,
        CAM_READ_VALUES,
    };
    let mut run = machine("");
    run.step(0.001);
    let seed = seed_cam();
    // Slave dynamics of the motion function: position, velocity, acceleration of the raw cam.
    let (v, _) = read_all(
        &mut run,
        1,
        CamReadCall {
            what: CAM_READ_SLAVE_DYNAMICS,
            a: 90.0,
            ..Default::default()
        },
    );
    let s = seed.eval(90.0, &mut ProfileCursor::default());
    assert_eq!(v, vec![s.position, s.velocity, s.acceleration]);
    // An equidistant table gives no acceleration (seed 5.1.7).
    let (v, _) = read_all(
        &mut run,
        2,
        CamReadCall {
            what: CAM_READ_SLAVE_DYNAMICS,
            a: 100.0,
            ..Default::default()
        },
    );
    assert_eq!(v[2], 0.0);
    assert!(v[1] != 0.0);
    // Characteristics: the 31 values of MC_TableCharacValues, in two parts.
    let (v, _) = read_all(
        &mut run,
        1,
        CamReadCall {
            what: CAM_READ_CHARACTERISTICS,
            ..Default::default()
        },
    );
    let expected: Vec<f64> = cnc_core::cam::CharacValues::normed(&seed)
        .fields()
        .iter()
        .map(|(_, v)| *v)
        .collect();
    assert_eq!(v, expected);
    // A value table of position and velocity from 0 to 360 in steps of 10: 37 rows of 3.
    let (v, columns) = read_all(
        &mut run,
        1,
        CamReadCall {
            what: CAM_READ_VALUES,
            mask: 3,
            a: 0.0,
            b: 360.0,
            c: 10.0,
            ..Default::default()
        },
    );
    assert_eq!((v.len(), columns), (111, 3));
    for row in v.chunks(3) {
        let s = seed.eval(row[0], &mut ProfileCursor::default());
        assert_eq!([row[1], row[2]], [s.position, s.velocity], "at {}", row[0]);
    }
    // The coupling info of a scaled coupling, at a master position given.
    let scaled = CamInCall {
        slave_scaling: 2.0,
        slave_offset: 1.0,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, SLAVE as u32, scaled), 0);
    run.step(0.001);
    let (v, _) = read_all(
        &mut run,
        SLAVE as u32,
        CamReadCall {
            what: CAM_READ_INFO,
            flags: 1,
            a: 90.0,
            ..Default::default()
        },
    );
    assert_eq!(v.len(), 40);
    assert_eq!(v[0], 1.0, "table");
    assert_eq!(v[1], 22.0, "a motion function");
    assert_eq!((v[4], v[5]), (6.0, 1.0), "points, columns");
    assert_eq!((v[6], v[8]), (0.0, 360.0), "master start, period");
    assert_eq!((v[15], v[17]), (1.0, 2.0), "slave offset, scaling");
    assert_eq!(v[20], 90.0, "at the master position given");
    assert_eq!(
        v[21],
        1.0 + 2.0 * s_at(&seed, 90.0),
        "slave set-point there"
    );
    assert_eq!(v[22], 90.0, "cam master coordinate");
    // Not coupled: refused.
    let reply: hli::calls::cam::CamValuesReply = bytemuck::pod_read_unaligned(&dispatch_raw(
        &mut run,
        2,
        &CamReadCall {
            what: CAM_READ_INFO,
            ..Default::default()
        },
    ));
    assert_eq!(reply.error_id, CamCouplingError::NotCamCoupled.raw());
}

fn s_at(p: &CamProfile, x: f64) -> f64 {
    p.eval(x, &mut ProfileCursor::default()).position
}

/// The numbers of a read block in the PLC's report.
fn read_values(report: &str, instance: &str) -> Vec<f64> {
    let mut lines = report.lines();
    lines
        .find(|l| l.starts_with(&format!("block {instance} ")))
        .unwrap_or_else(|| panic!("no block {instance}\n{report}"));
    let line = lines.next().unwrap_or("");
    let (_, values) = line
        .split_once(": ")
        .unwrap_or_else(|| panic!("{instance}: {line}"));
    values
        .split(", ")
        .filter(|v| *v != "...")
        .map(|v| v.parse().unwrap())
        .collect()
}

#[test]
fn the_data_scenario_loads_reads_and_writes_through_the_blocks() {
    let s = Scenario::load(&scenarios().join("cam-data/scenario.toml")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let mut followed = 0;
    for _ in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        if phase(&run, SLAVE) == AxisState::SlaveSynchronous {
            // The uploaded zigzag (0, 10, 0, -10, 0 every 90 degrees), linear, cyclic.
            let m = set(&run, MASTER).position.rem_euclid(360.0);
            let expected = match m {
                x if x < 90.0 => x / 9.0,
                x if x < 270.0 => 10.0 - (x - 90.0) / 9.0,
                x => -10.0 + (x - 270.0) / 9.0,
            };
            assert!(
                (set(&run, SLAVE).position - expected).abs() < 1e-9,
                "at {m}"
            );
            followed += 1;
        }
    }
    assert!(followed > 1000);
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    let seed = seed_cam();
    let s90 = seed.eval(90.0, &mut ProfileCursor::default());
    assert_eq!(
        read_values(&report, "dynamics"),
        vec![s90.position, s90.velocity, s90.acceleration]
    );
    // Positions every 45 degrees: 9 rows of master and slave (the first 12 numbers shown).
    let values = read_values(&report, "values");
    for row in values.chunks(2) {
        assert_eq!(
            row[1],
            seed.eval(row[0], &mut ProfileCursor::default()).position
        );
    }
    // Point 4 after MC_WriteMotionFunction: index, master, slave.
    assert_eq!(read_values(&report, "point4"), vec![4.0, 240.0, 30.0]);
    // MC_CamInfo: table 3, equidistant (10), cyclic, linear, 5 rows of 2 columns.
    assert_eq!(
        read_values(&report, "info")[..6],
        [3.0, 10.0, 1.0, 0.0, 5.0, 2.0]
    );
    assert!(run.machine.axes().axis(SLAVE).unwrap().coupling().is_none());
}

#[test]
fn the_multi_table_scenario_runs_start_work_correction_and_stop_tables() {
    let s = Scenario::load(&scenarios().join("cam-multi-table/scenario.toml")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    // By hand: the start table 0.2 per unit to 100; the work table 0.4 per unit from 20;
    // the correction bump (+0.2 per unit for 10, back for 10) from 350; the work table ends
    // at its boundary at 500 (the stop came at about 489) and the stop table adds 0.2 per
    // unit for 50 units from 180; then the feeder stands at 190.
    let bump = |d: f64| match d {
        d if (0.0..10.0).contains(&d) => 0.2 * d,
        d if (10.0..20.0).contains(&d) => 2.0 - 0.2 * (d - 10.0),
        _ => 0.0,
    };
    let expected = |pm: f64| match pm {
        pm if pm < 100.0 => 0.2 * pm,
        pm if pm < 500.0 => 20.0 + 0.4 * (pm - 100.0) + bump(pm - 350.0),
        pm if pm < 550.0 => 180.0 + 0.2 * (pm - 500.0),
        _ => 190.0,
    };
    let mut coupled_ticks = 0;
    for _ in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let feeder = run.machine.axes().axis(SLAVE).unwrap();
        if feeder.coupling().map(|c| c.kind) != Some(CouplingState::Cam) {
            continue;
        }
        coupled_ticks += 1;
        let pm = set(&run, MASTER).position;
        let f = set(&run, SLAVE).position;
        assert!(
            (f - expected(pm)).abs() < 1e-9,
            "line {pm}: feeder {f}, expected {}",
            expected(pm)
        );
    }
    assert!(coupled_ticks > 7000, "{coupled_ticks}");
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    assert!(run.machine.axes().axis(SLAVE).unwrap().coupling().is_none());
    assert_eq!(set(&run, SLAVE).position, 190.0);
}

#[test]
fn the_compatibility_blocks_make_read_couple_rescale_and_delete() {
    let s = Scenario::load(&scenarios().join("cam-compat/scenario.toml")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    // The generated zigzag, linear: +-9 per turn, doubled, shifted by 0.5 from tick 1500.
    let zigzag = |m: f64| {
        let m = m.rem_euclid(360.0);
        match m {
            m if m < 90.0 => m / 10.0,
            m if m < 270.0 => 9.0 - (m - 90.0) / 10.0,
            m => -9.0 + (m - 270.0) / 10.0,
        }
    };
    let mut checked = 0;
    for tick in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let coupled = run.machine.axes().axis(SLAVE).unwrap().coupling().is_some();
        if coupled && (1600..3000).contains(&tick) {
            let m = set(&run, MASTER).position;
            let expected = 0.5 + 2.0 * zigzag(m);
            assert!(
                (set(&run, SLAVE).position - expected).abs() < 1e-9,
                "tick {tick}, drum {m}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 1400);
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    assert_eq!(
        read_values(&report, "read"),
        vec![0.0, 0.0, 40.0, 4.0, 100.0, 5.0]
    );
    // Non-equidistant: the slave position only (seed 5.1.7).
    assert_eq!(read_values(&report, "slavepos"), vec![2.0, 0.0, 0.0]);
    for (done, kind) in [
        ("release", "CamTableCoupleAxes"),
        ("delete21", "CamTableDelete"),
        ("delete22", "CamTableDelete"),
    ] {
        assert!(
            report.contains(&format!("block {done} ({kind} on gpAx[1]): Done")),
            "{report}"
        );
    }
    assert!(run.machine.axes().axis(SLAVE).unwrap().coupling().is_none());
}

#[test]
fn a_slave_may_follow_the_masters_actual_position() {
    let mut run = machine("");
    run.step(0.001);
    let actual = CamInCall {
        master_source: 1,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, SLAVE as u32, actual), 0);
    run_master(&mut run, 360.0);
    let law = CamLaw::new(
        &seed_cam(),
        Scaling::default(),
        CamStartMode::Absolute,
        false,
        0.0,
        0.0,
    );
    let profile = seed_cam();
    let mut differs = 0;
    for _ in 0..300 {
        run.step(0.001);
        let master = run.machine.axes().axis(MASTER).unwrap();
        let on_actual = law_at(
            &law,
            &profile,
            Kinematic {
                position: master.actual(),
                ..Kinematic::default()
            },
        );
        assert!((set(&run, SLAVE).position - on_actual.position).abs() < 1e-9);
        let on_set = law_at(&law, &profile, master.setpoint());
        differs += usize::from((on_set.position - on_actual.position).abs() > 1e-6);
    }
    assert!(
        differs > 100,
        "the actual position lags the set-point: {differs}"
    );
    let bad = CamInCall {
        master_source: 2,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, 2, bad), CamCouplingError::BadParameter.raw());
}

#[test]
fn every_scaling_activation_mode_takes_effect_where_it_says_without_a_jump() {
    use hli::calls::cam::CamScalingCall;
    // (mode, position, the master position from which the new scaling must show)
    let cases = [
        (0u32, 0.0, 0.0),
        (1, 200.0, 200.0),
        (2, 560.0, 560.0),
        (3, 0.0, 360.0),
    ];
    for (mode, position, from) in cases {
        let mut run = machine("");
        run.step(0.001);
        select_cyclic(&mut run, 1);
        assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
        run_master(&mut run, 360.0);
        for _ in 0..400 {
            run.step(0.001);
        }
        let m0 = set(&run, MASTER).position;
        // Slave scaling 0.5 with slave auto-offset: no jump at the activation.
        let scaling = CamScalingCall {
            activation_mode: mode,
            activation_position: position,
            master_scaling_mode: 2,
            slave_scaling_mode: 1,
            master_scaling: 1.0,
            slave_scaling: 0.5,
            ..CamScalingCall::default()
        };
        assert_eq!(call(&mut run, SLAVE as u32, scaling), 0, "mode {mode}");
        let law = CamLaw::new(
            &seed_cam(),
            Scaling::default(),
            CamStartMode::Absolute,
            true,
            0.0,
            0.0,
        );
        let profile = seed_cam();
        let mut last = set(&run, SLAVE).position;
        let mut switched_at = None;
        for _ in 0..1500 {
            run.step(0.001);
            let m = set(&run, MASTER);
            let p = set(&run, SLAVE).position;
            assert!(
                (p - last).abs() < 0.35,
                "mode {mode}: jump {} at {}",
                p - last,
                m.position
            );
            last = p;
            let full = law_at(&law, &profile, m).position;
            if switched_at.is_none() && (p - full).abs() > 1e-9 {
                switched_at = Some(m.position);
            }
        }
        let at = switched_at.unwrap_or_else(|| panic!("mode {mode} never took effect"));
        // The master was at m0 when the command came; the change shows from `from` on (within
        // the cam's flat stretches it cannot show earlier than it is seen).
        // AtMasterCamPos: the first time after the command that the master's place in the
        // cam is `position` (in absolute master terms).
        let due = match mode {
            0 => m0,
            1 => m0 + (position - m0.rem_euclid(360.0)).rem_euclid(360.0),
            _ => from,
        };
        assert!(
            at >= due - 1e-9,
            "mode {mode}: took effect at {at}, due at {due}"
        );
        assert!(
            at < due + 60.0,
            "mode {mode}: took effect at {at}, due at {due}"
        );
    }
}

#[test]
fn couplings_by_cam_position_and_next_cycle_start_where_they_say() {
    // (activation mode, position, start mode, expected: Ok(master position of the start) or
    // Err(code))
    let relative = CamCouplingError::ModeCombination.raw();
    let cases: [(u32, f64, u32, Result<f64, u32>); 4] = [
        (1, 100.0, 1, Ok(100.0)),
        (3, 0.0, 1, Ok(360.0)),
        (1, 100.0, 2, Err(relative)),
        (3, 0.0, 4, Err(relative)),
    ];
    for (mode, position, start, expected) in cases {
        let mut run = machine("");
        run.step(0.001);
        select_cyclic(&mut run, 1);
        let coupling = CamInCall {
            extended: 1,
            activation_mode: mode,
            activation_position: position,
            start_mode: start,
            ..cam_in(1)
        };
        let reply = call(&mut run, SLAVE as u32, coupling);
        match expected {
            Err(code) => {
                assert_eq!(reply, code, "mode {mode} start {start}");
                assert!(run.machine.axes().axis(SLAVE).unwrap().coupling().is_none());
                continue;
            }
            Ok(from) => {
                assert_eq!(reply, 0, "mode {mode}");
                run_master(&mut run, 360.0);
                let mut started = None;
                for _ in 0..1500 {
                    run.step(0.001);
                    if phase(&run, SLAVE) == AxisState::SlaveSynchronous {
                        started.get_or_insert(set(&run, MASTER).position);
                    } else {
                        assert_eq!(set(&run, SLAVE).position, 0.0, "holds while waiting");
                    }
                }
                let at = started.unwrap_or_else(|| panic!("mode {mode} never started"));
                assert!(
                    (from..from + 0.5).contains(&at),
                    "mode {mode}: started at {at}"
                );
            }
        }
    }
}

#[test]
fn a_first_chunk_drops_an_unfinished_transfer() {
    let mut run = machine("");
    run.step(0.001);
    let answer = |run: &mut InProcess, c: &hli::calls::cam::CamRowsWriteCall| {
        bytemuck::pod_read_unaligned::<CamReply>(&dispatch_raw(run, 7, c)).error_id
    };
    let rows: Vec<[f64; 2]> = (0..26).map(|i| [i as f64, 0.5 * i as f64]).collect();
    // A transfer left half-done (the PLC re-triggered its block) ...
    assert_eq!(answer(&mut run, &rows_chunk(&rows[..13], 0, 26, false)), 0);
    // ... does not block the next one, which starts over.
    let whole: Vec<[f64; 2]> = (0..13).map(|i| [i as f64 * 10.0, 1.0]).collect();
    assert_eq!(answer(&mut run, &rows_chunk(&whole, 0, 13, true)), 0);
    let (v, _) = read_all(
        &mut run,
        7,
        hli::calls::cam::CamReadCall {
            what: hli::calls::cam::CAM_READ_ROWS,
            ..Default::default()
        },
    );
    assert_eq!(v.len(), 26);
    assert_eq!((v[2], v[3]), (10.0, 1.0));
}

#[test]
fn a_slave_coupled_later_starts_in_the_base_cycle() {
    let mut run = machine("");
    run.step(0.001);
    let rows: Vec<[f64; 2]> = (0..=36)
        .map(|i| [i as f64 * 10.0, i as f64 * 10.0 / 36.0])
        .collect();
    for (k, chunk) in rows.chunks(hli::calls::cam::CAM_ROWS_PER_CALL).enumerate() {
        let first = k * hli::calls::cam::CAM_ROWS_PER_CALL;
        let call = rows_chunk(chunk, first, rows.len(), first + chunk.len() == rows.len());
        let reply: CamReply = bytemuck::pod_read_unaligned(&dispatch_raw(&mut run, 9, &call));
        assert_eq!(reply.error_id, 0);
    }
    run_master(&mut run, 360.0);
    for _ in 0..1500 {
        run.step(0.001);
    }
    // The master is more than a turn on; coupled now, the slave takes the cam's value at
    // the master's place in its turn, without the strokes of the turns before (seed 5.1.4).
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(9)), 0);
    run.step(0.001);
    let m = set(&run, MASTER).position;
    assert!(m > 400.0, "{m}");
    let expected = m.rem_euclid(360.0) / 36.0;
    assert!(
        (set(&run, SLAVE).position - expected).abs() < 1e-9,
        "slave {} at master {m}, expected {expected}",
        set(&run, SLAVE).position
    );
}

#[test]
fn a_point_change_as_soon_as_possible_waits_for_every_slave_on_the_table() {
    use hli::calls::cam::{CamOnlineModeCall, CamPointsWriteCall, McMotionFunctionPoint};
    let mut run = machine("");
    run.step(0.001);
    select_cyclic(&mut run, 1);
    // Two slaves on table 1: the lifter, and the third axis 20 degrees ahead.
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
    let ahead = CamInCall {
        master_offset: 20.0,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, 2, ahead), 0);
    run_master(&mut run, 360.0);
    for _ in 0..500 {
        run.step(0.001);
    }
    let mode = CamOnlineModeCall {
        activation_mode: 5,
        ..Default::default()
    };
    let reply: CamReply = bytemuck::pod_read_unaligned(&dispatch_raw(&mut run, 1, &mode));
    assert_eq!(reply.error_id, 0);
    // Point 4 (the fall's start, 240) from 40 to 30: the segments from 30 to 340 change (the
    // rise's end slope too), so both slaves are clear of them only while the lifter is
    // between 340 and 10 degrees.
    let mut points = [McMotionFunctionPoint::default(); 4];
    points[0] = McMotionFunctionPoint {
        point_index: 4,
        function_type: 15,
        point_type: 2,
        rel_index_next_point: 1,
        master_pos: 240.0,
        slave_pos: 30.0,
        ..Default::default()
    };
    let write = CamPointsWriteCall {
        first: 4,
        count: 1,
        flags: hli::calls::cam::CAM_CHUNK_FIRST | hli::calls::cam::CAM_CHUNK_LAST,
        total: 1,
        points,
    };
    let reply: CamReply = bytemuck::pod_read_unaligned(&dispatch_raw(&mut run, 1, &write));
    assert_eq!(reply.error_id, 0);
    let mut last = [set(&run, SLAVE).position, set(&run, 2).position];
    let mut top = [0.0f64; 2];
    for tick in 0..2000 {
        run.step(0.001);
        for (k, axis) in [SLAVE, 2].into_iter().enumerate() {
            let p = set(&run, axis).position;
            assert!(
                (p - last[k]).abs() < 0.35,
                "axis {axis} jumped {} at tick {tick}",
                p - last[k]
            );
            last[k] = p;
            if tick >= 1000 {
                top[k] = top[k].max(p);
            }
        }
    }
    // The change came (the tops are now about 31, no longer about 42) without a jump.
    for t in top {
        assert!(t > 25.0 && t < 35.0, "top {t}");
    }
}
