//! Gaps of the camming audit (seed 000) closed through the machine: a cam slave's coupling
//! state in its image (#91), multi-table slaves and motion functions (#47) or cyclic
//! corrections (#42), MC_CamInfo (#70) and master auto-offset on a point change (#23).

use super::*;
use hli::calls::cam::{
    CamMultiTableCall, CamMultiTableOp, CamOnlineModeCall, CamPointsWriteCall, CamReadCall,
    CamReadKind, McMotionFunctionPoint, CAM_CHUNK_FIRST, CAM_CHUNK_LAST,
};
use hli::layout::HliAxisLrState;

/// Axis `axis`'s state in the image, as the PLC reads it.
fn image(run: &Harness, axis: usize) -> HliAxisLrState {
    run.plc_view().axis_state(axis).unwrap()
}

/// MC_CamInfo of slave `axis`: its 40 values.
fn info_of(run: &mut Harness, axis: usize) -> Vec<f64> {
    let call = CamReadCall {
        what: CamReadKind::Info.raw(),
        ..Default::default()
    };
    let (v, _) = read_all(run, axis as u32, call);
    assert_eq!(v.len(), 40);
    v
}

/// The coupling state of axis `axis` in its image.
fn coupled(run: &Harness, axis: usize) -> i32 {
    image(run, axis).coupling_state_r
}

/// Whether `got` is `want` (to 1e-9).
fn near(got: f64, want: f64) -> bool {
    (got - want).abs() < 1e-9
}

/// The raw slave position of `profile` at master `x`.
fn cam_at(profile: &CamProfile, x: f64) -> f64 {
    profile.eval(x, &mut ProfileCursor::default()).position
}

/// Rows every `step` of the master with these slave positions.
fn rows_every(step: f64, slaves: &[f64]) -> Vec<[f64; 2]> {
    let row = |(i, s): (usize, &f64)| [step * i as f64, *s];
    slaves.iter().enumerate().map(row).collect()
}

/// Seed 000 4.4 and the NC-PLC interface: a cam slave shows `coupling_state_r` 1 (Cam) and
/// its master in its image while coupled, 0 and -1 after MC_CamOut.
#[test]
fn a_cam_slave_shows_coupling_state_cam_in_its_image_until_cam_out() {
    let mut run = machine();
    run.step();
    assert_eq!(coupled(&run, SLAVE), 0);
    select_cyclic(&mut run, 1);
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
    run_master(&mut run, 360.0);
    for _ in 0..300 {
        run.step();
        let lr = image(&run, SLAVE);
        assert_eq!((lr.coupling_state_r, lr.master_axis_r), (1, MASTER as i32));
    }
    let lr = image(&run, SLAVE);
    assert_eq!(lr.axis_state_r, AxisState::SlaveSynchronous.raw());
    assert_eq!(coupled(&run, MASTER), 0, "the master is free");
    assert_eq!(call(&mut run, SLAVE as u32, CamOutCall::default()), 0);
    run.step();
    let lr = image(&run, SLAVE);
    assert_eq!((lr.coupling_state_r, lr.master_axis_r), (0, -1));
    assert_eq!(CouplingState::Cam.raw(), 1);
}

/// Seed 000 4.2 / 4.6.2: multi-table slaves run on position tables only. The seed's motion
/// function, as profile table or as correction, is refused with 0x4B35 (the slave stays
/// free); the position table alone couples, and the image shows a cam coupling.
#[test]
fn a_multi_table_coupling_refuses_a_motion_function_with_0x4b35() {
    let mut run = machine();
    run.step();
    let before = set(&run, SLAVE);
    assert_eq!(call(&mut run, SLAVE as u32, multi_couple(1, 0)), 0x4B35);
    let mut beside = multi_couple(2, 0);
    beside.tables = 2;
    beside.table_ids[1] = 1;
    assert_eq!(call(&mut run, SLAVE as u32, beside), 0x4B35);
    run.step();
    assert!(run.axis(SLAVE).coupling().is_none());
    assert_eq!(set(&run, SLAVE), before);
    assert_eq!(coupled(&run, SLAVE), 0);
    assert_eq!(call(&mut run, SLAVE as u32, multi_couple(2, 0)), 0);
    run.step();
    assert_eq!(coupled(&run, SLAVE), CouplingState::Cam.raw());
}

/// Seed 000 4.6.1: correction tables are always linear. A table selected cyclic (climbing 20
/// over 360) as a correction runs through once and leaves exactly its last row's 20: nothing
/// of a next period in the tick it ends (the master overshoots there), nothing more after.
#[test]
fn a_cyclic_table_as_a_correction_runs_through_once_as_a_linear_one() {
    let mut run = machine();
    run.step();
    let flat = [[0.0, 0.0], [360.0, 0.0]];
    assert_eq!(rows_answer(&mut run, 8, &rows_chunk(&flat, 0, 2, true)), 0);
    let climb = rows_every(90.0, &[0.0, 5.0, 10.0, 15.0, 20.0]);
    assert_eq!(rows_answer(&mut run, 9, &rows_chunk(&climb, 0, 5, true)), 0);
    select_cyclic(&mut run, 9);
    let mut couple = multi_couple(8, 0);
    couple.tables = 2;
    couple.table_ids[1] = 9;
    assert_eq!(call(&mut run, SLAVE as u32, couple), 0);
    run_master(&mut run, 350.0);
    while set(&run, MASTER).position < 100.0 {
        run.step();
        assert_eq!(set(&run, SLAVE).position, 0.0, "the flat profile alone");
    }
    assert_eq!(coupled(&run, SLAVE), CouplingState::Cam.raw());
    let enable = CamMultiTableCall {
        op: CamMultiTableOp::EnableCorrection.raw(),
        table: 9,
        ..CamMultiTableCall::default()
    };
    assert_eq!(call(&mut run, SLAVE as u32, enable), 0);
    let start = set(&run, MASTER).position;
    let (mut ran, mut through, mut highest) = (false, false, f64::MIN);
    while set(&run, MASTER).position < start + 800.0 {
        run.step();
        let s = set(&run, SLAVE).position;
        highest = highest.max(s);
        ran |= s > 1.0 && s < 19.0;
        if through {
            assert!(near(s, 20.0), "after its end: {s}");
        }
        through |= near(s, 20.0);
    }
    assert!(ran && through, "ran {ran}, ended {through}");
    assert!(highest <= 20.0 + 1e-9, "beyond its last row: {highest}");
}

/// Seed 000 5.1.16.15: MC_CamInfo's pending fields (24-39) are 0 with nothing queued; with an
/// MC_CamScaling at cam position 300, an online change at axis position 700 and a switch at
/// cam position 200 they give each one's flag, mode, position, scaling modes. And 3, 9-13, 23.
#[test]
fn mc_cam_info_shows_queued_scaling_online_change_and_switch() {
    let mut run = machine();
    run.step();
    select_cyclic(&mut run, 1);
    let ext = CamInCall {
        extended: 1,
        slave_scaling: 2.0,
        slave_offset: 1.0,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, SLAVE as u32, ext), 0);
    run.step();
    run_master(&mut run, 360.0);
    while set(&run, MASTER).position < 90.0 {
        run.step();
    }
    let v = info_of(&mut run, SLAVE);
    assert_eq!(v[24..40], [0.0; 16], "nothing queued: {v:?}");
    // InterpolationType (a motion function's 0), RawSlaveStroke (the seed cam ends where it
    // starts), both axes at 0 when coupled, both sides absolute.
    assert_eq!(v[9..14], [0.0, 0.0, 0.0, 1.0, 1.0], "{v:?}");
    assert_eq!(v[3], 0.0);
    // ActualSlaveCamPos: the raw cam at the cam's master position, unscaled.
    let raw = cam_at(&seed_cam(), v[22]);
    assert!(raw > 1.0 && near(v[23], raw), "{v:?}");
    assert!(near(v[21], 1.0 + 2.0 * v[23]), "{v:?}");
    let scaling = CamScalingCall {
        activation_mode: 1,
        activation_position: 300.0,
        slave_scaling_mode: 1,
        master_scaling: 1.0,
        slave_scaling: 2.0,
        slave_offset: 1.0,
        ..CamScalingCall::default()
    };
    assert_eq!(call(&mut run, SLAVE as u32, scaling), 0);
    let online = CamOnlineModeCall {
        activation_mode: 2,
        master_scaling_mode: 2,
        slave_scaling_mode: 1,
        activation_position: 700.0,
        ..CamOnlineModeCall::default()
    };
    assert_eq!(call(&mut run, 1, online), 0);
    assert_eq!(
        call(
            &mut run,
            1,
            hli::calls::cam::CamPointsWriteCall::one(seed_point_4(30.0))
        ),
        0
    );
    let switch = CamInCall {
        master_scaling_mode: 1,
        slave_scaling_mode: 2,
        ..switch_to_stroke_at_200()
    };
    assert_eq!(call(&mut run, SLAVE as u32, switch), 0);
    let v = info_of(&mut run, SLAVE);
    // ScalingPending, ScalingActivationMode, -Pos, ScalingMasterScalingMode, -Slave...
    assert_eq!(v[24..29], [1.0, 1.0, 300.0, 0.0, 1.0], "{v:?}");
    // CamDataQueued, OnlineChangeActivationMode, -Pos, -MasterScalingMode, -Slave...
    assert_eq!(v[29..34], [1.0, 2.0, 700.0, 2.0, 1.0], "{v:?}");
    // CamTableQueued, CamExchangeCamTableID, -ActivationMode, -Pos, -Master/Slave...
    assert_eq!(v[34..40], [1.0, 2.0, 1.0, 200.0, 1.0, 2.0], "{v:?}");
}

/// Seed 000 5.1.12 / 5.1.16.14: master AutoOffset on a point change. The seed cam's masters
/// doubled (period 720), written at once with the master at about 100: the master keeps its
/// share of the cycle (cam position about 200, an offset of about 100) and the slave goes on
/// without a jump on the stretched cam (without the offset it would jump by more than 1).
#[test]
fn a_point_change_with_master_auto_offset_keeps_the_masters_share_of_the_cycle() {
    let mut run = machine();
    run.step();
    select_cyclic(&mut run, 1);
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
    let online = CamOnlineModeCall {
        master_scaling_mode: 1,
        ..CamOnlineModeCall::default()
    };
    assert_eq!(call(&mut run, 1, online), 0);
    run_master(&mut run, 360.0);
    while set(&run, MASTER).position < 100.0 {
        run.step();
    }
    // The seed's points (index, function, type, master, slave) with the masters doubled.
    let seed = [
        (1, 1, 1, 0.0, 0.0),
        (2, 15, 1, 30.0, 0.0),
        (3, 1, 2, 150.0, 20.0),
        (4, 15, 2, 240.0, 40.0),
        (5, 1, 1, 340.0, 0.0),
        (6, 1, 1, 360.0, 0.0),
    ];
    let stretched: Vec<McMotionFunctionPoint> = seed
        .iter()
        .map(
            |&(point_index, function_type, point_type, m, s)| McMotionFunctionPoint {
                point_index,
                function_type,
                point_type,
                master_pos: 2.0 * m,
                slave_pos: s,
                ..McMotionFunctionPoint::default()
            },
        )
        .collect();
    let old = seed_cam();
    let new_at = |x: f64| cam_at(&old, x.rem_euclid(720.0) / 2.0);
    let at_write = set(&run, MASTER).position;
    let mut last = set(&run, SLAVE).position;
    assert!(near(last, cam_at(&old, at_write)));
    let jump = (new_at(at_write) - cam_at(&old, at_write)).abs();
    assert!(jump > 1.0, "the test needs a jump to avoid: {jump}");
    // MC_WriteMotionFunction of the six points, in two chunks.
    for (chunk, flags) in [
        (&stretched[..4], CAM_CHUNK_FIRST),
        (&stretched[4..], CAM_CHUNK_LAST),
    ] {
        let mut body = CamPointsWriteCall {
            first: chunk[0].point_index,
            count: chunk.len() as u32,
            flags,
            total: 6,
            ..CamPointsWriteCall::default()
        };
        body.points[..chunk.len()].copy_from_slice(chunk);
        assert_eq!(call(&mut run, 1, body), 0);
    }
    run.step();
    let v = info_of(&mut run, SLAVE);
    let mo = v[14];
    assert!(mo >= at_write && mo < at_write + 1.0, "MasterOffset {mo}");
    assert_eq!(v[8], 720.0, "RawMasterPeriod of the stretched cam");
    let mut max_step: f64 = 0.0;
    for tick in 0..1500 {
        if tick > 0 {
            run.step();
        }
        let (m, p) = (set(&run, MASTER).position, set(&run, SLAVE).position);
        max_step = max_step.max((p - last).abs());
        last = p;
        let expected = new_at(m + mo);
        assert!(near(p, expected), "tick {tick}, master {m}: {p}");
    }
    assert!(max_step < 0.35, "no jump: largest step {max_step}");
    assert!(run.axis(SLAVE).error().is_none());
}
