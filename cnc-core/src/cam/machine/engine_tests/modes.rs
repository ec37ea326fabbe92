//! Actual-value masters, scaling activation modes, coupling starts and online point changes.

use super::*;
use hli::calls::cam::CAM_START_AS_SELECTED;

#[test]
fn a_slave_may_follow_the_masters_actual_position() {
    let mut run = machine();
    run.step();
    let actual = CamInCall {
        master_source: 1,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, SLAVE as u32, actual), 0);
    run_master(&mut run, 360.0);
    let law = seed_law(false);
    let profile = seed_cam();
    let mut differs = 0;
    for _ in 0..300 {
        run.step();
        let master = run.axis(MASTER);
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
        let mut run = machine();
        run.step();
        select_cyclic(&mut run, 1);
        assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
        run_master(&mut run, 360.0);
        for _ in 0..400 {
            run.step();
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
        let law = seed_law(true);
        let profile = seed_cam();
        let mut last = set(&run, SLAVE).position;
        let mut switched_at = None;
        for _ in 0..1500 {
            run.step();
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
        let mut run = machine();
        run.step();
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
                assert!(run.axis(SLAVE).coupling().is_none());
                continue;
            }
            Ok(from) => {
                assert_eq!(reply, 0, "mode {mode}");
                run_master(&mut run, 360.0);
                let mut started = None;
                for _ in 0..1500 {
                    run.step();
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
    let mut run = machine();
    run.step();
    let rows: Vec<[f64; 2]> = (0..26).map(|i| [i as f64, 0.5 * i as f64]).collect();
    // A transfer left half-done (the PLC re-triggered its block) ...
    assert_eq!(
        rows_answer(&mut run, 7, &rows_chunk(&rows[..13], 0, 26, false)),
        0
    );
    // ... does not block the next one, which starts over.
    let whole: Vec<[f64; 2]> = (0..13).map(|i| [i as f64 * 10.0, 1.0]).collect();
    assert_eq!(
        rows_answer(&mut run, 7, &rows_chunk(&whole, 0, 13, true)),
        0
    );
    let (v, _) = read_all(
        &mut run,
        7,
        hli::calls::cam::CamReadCall {
            what: hli::calls::cam::CamReadKind::Rows.raw(),
            ..Default::default()
        },
    );
    assert_eq!(v.len(), 26);
    assert_eq!((v[2], v[3]), (10.0, 1.0));
}

#[test]
fn a_slave_coupled_later_starts_in_the_base_cycle() {
    let mut run = machine();
    run.step();
    let rows: Vec<[f64; 2]> = (0..=36)
        .map(|i| [i as f64 * 10.0, i as f64 * 10.0 / 36.0])
        .collect();
    for (k, chunk) in rows.chunks(hli::calls::cam::CAM_ROWS_PER_CALL).enumerate() {
        let first = k * hli::calls::cam::CAM_ROWS_PER_CALL;
        let call = rows_chunk(chunk, first, rows.len(), first + chunk.len() == rows.len());
        let reply = answer(&mut run, 9, &call);
        assert_eq!(reply.error_id, 0);
    }
    run_master(&mut run, 360.0);
    for _ in 0..1500 {
        run.step();
    }
    // The master is more than a turn on; coupled now, the slave takes the cam's value at
    // the master's place in its turn, without the strokes of the turns before (seed 5.1.4).
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(9)), 0);
    run.step();
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
    use hli::calls::cam::CamOnlineModeCall;
    let mut run = machine();
    run.step();
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
        run.step();
    }
    let mode = CamOnlineModeCall {
        activation_mode: 5,
        ..Default::default()
    };
    let reply = answer(&mut run, 1, &mode);
    assert_eq!(reply.error_id, 0);
    // Point 4 (the fall's start, 240) from 40 to 30: the segments from 30 to 340 change (the
    // rise's end slope too), so both slaves are clear of them only while the lifter is
    // between 340 and 10 degrees.
    assert_eq!(write_point_4(&mut run), 0);
    let mut last = [set(&run, SLAVE).position, set(&run, 2).position];
    let mut top = [0.0f64; 2];
    for tick in 0..2000 {
        run.step();
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

/// MC_CamTableSelect's MasterAbsolute/SlaveAbsolute choose absolute or relative (seed 000
/// 5.1.1: FALSE is relative); MC_CamIn's StartMode 0 ("as selected", the block's default)
/// takes that choice, and an explicit StartMode that says otherwise is refused (0x4262) with
/// the axis untouched, both ways. A table never selected takes whatever MC_CamIn says.
#[test]
fn a_start_mode_that_contradicts_the_table_selection_is_refused() {
    let mut run = machine();
    run.step();
    select_cyclic(&mut run, 1);
    let contradiction = CamCouplingError::ModeCombination.raw();
    for mode in [2, 3, 4] {
        let c = CamInCall {
            start_mode: mode,
            ..cam_in(1)
        };
        assert_eq!(
            call(&mut run, SLAVE as u32, c),
            contradiction,
            "start mode {mode}"
        );
        assert!(run.axis(SLAVE).coupling().is_none());
    }
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
    assert_eq!(call(&mut run, SLAVE as u32, CamOutCall::default()), 0);
    // Slave selected absolute, master FALSE (relative): that start mode, or 0, only.
    let select = CamTableSelectCall {
        periodic: 1,
        master_absolute: 0,
        slave_absolute: 1,
        reserved: 0,
    };
    assert_eq!(call(&mut run, 2, select), 0);
    let mode = |m: u32| CamInCall {
        start_mode: m,
        ..cam_in(2)
    };
    for refused in [
        CamStartMode::Absolute,
        CamStartMode::Relative,
        CamStartMode::MasterAbsSlaveRel,
    ] {
        assert_eq!(
            call(&mut run, SLAVE as u32, mode(refused.raw())),
            contradiction,
            "{refused:?}"
        );
    }
    for taken in [CamStartMode::MasterRelSlaveAbs.raw(), CAM_START_AS_SELECTED] {
        assert_eq!(call(&mut run, SLAVE as u32, mode(taken)), 0, "{taken}");
        assert_eq!(call(&mut run, SLAVE as u32, CamOutCall::default()), 0);
    }
    // A table never selected: MC_CamIn's start mode alone governs.
    let mut fresh = machine();
    fresh.step();
    assert_eq!(
        call(&mut fresh, SLAVE as u32, mode(CamStartMode::Relative.raw())),
        0
    );
}

/// DeleteQueuedData on a pending MC_CamInExt switch: the queued switch to the stroke table is
/// dropped (MC_CamInfo shows nothing queued), and when the master passes the activation
/// position the slave stays on the seed cam, on its law tick by tick.
#[test]
fn delete_queued_data_drops_a_pending_switch_and_the_slave_stays_on_its_cam() {
    use hli::calls::cam::{CamReadCall, CamReadKind};
    let mut run = switchable_at_speed();
    assert_eq!(call(&mut run, SLAVE as u32, switch_to_stroke_at_200()), 0);
    let queued = |run: &mut Harness| {
        let info = CamReadCall {
            what: CamReadKind::Info.raw(),
            ..Default::default()
        };
        let v = read_all(run, SLAVE as u32, info).0;
        (v[34], v[35])
    };
    assert_eq!(queued(&mut run), (1.0, 2.0), "the switch to table 2 queued");
    let delete = CamInCall {
        extended: 1,
        activation_mode: 7,
        ..cam_in(2)
    };
    assert_eq!(call(&mut run, SLAVE as u32, delete), 0);
    assert_eq!(queued(&mut run).0, 0.0, "nothing queued any more");
    let profile = seed_cam();
    let law = seed_law(true);
    // More than a whole turn: past cam position 200 at least once.
    for tick in 0..1500 {
        run.step();
        let expected = law_at(&law, &profile, set(&run, MASTER)).position;
        assert!(
            (set(&run, SLAVE).position - expected).abs() < 1e-9,
            "tick {tick}: still the seed cam"
        );
    }
}

/// MC_CamOut at speed: the slave leaves the cam with the velocity it had and goes on at it
/// as a free axis (no stop, no jump), as the seed's decoupling does.
#[test]
fn cam_out_at_speed_leaves_the_slave_moving_at_its_velocity() {
    let mut run = machine();
    run.step();
    select_cyclic(&mut run, 2);
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(2)), 0);
    run_master(&mut run, 360.0);
    // The stroke table climbs from 0 to 16 over the first half turn: at 90 the slave moves.
    while set(&run, MASTER).position < 90.0 {
        run.step();
    }
    let before = set(&run, SLAVE);
    assert!(before.velocity > 10.0, "moving: {}", before.velocity);
    assert_eq!(call(&mut run, SLAVE as u32, CamOutCall::default()), 0);
    run.step();
    let after = set(&run, SLAVE);
    assert!(run.axis(SLAVE).coupling().is_none());
    assert!(
        (after.velocity - before.velocity).abs() < 0.01 * before.velocity.abs(),
        "{} then {}",
        before.velocity,
        after.velocity
    );
    let step = after.position - before.position;
    assert!(
        (step - before.velocity * 0.001).abs() < 1e-3,
        "no jump: {step}"
    );
    for _ in 0..100 {
        run.step();
    }
    let later = set(&run, SLAVE);
    assert!((later.velocity - before.velocity).abs() < 0.01 * before.velocity.abs());
}

/// Seed 000 4.5, example 1 as written: on a cam that rests at the start of its cycle (the
/// seed cam rests at 0 from 0 to 30), MC_CamScaling with MasterOffset 0, SlaveOffset 0,
/// MasterScaling 1, SlaveScaling 0, MasterScalingMode Off, SlaveScalingMode UserDefined and
/// ActivationMode NextCycle stills the slave from the next cycle on, the coupling kept; the
/// same call with SlaveScaling 1.0 brings the motion back at the cycle after.
#[test]
fn the_seeds_example_1_stills_the_slave_at_the_next_cycle_and_brings_it_back() {
    let mut run = machine();
    run.step();
    select_cyclic(&mut run, 1);
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
    run_master(&mut run, 360.0);
    let profile = seed_cam();
    let law = seed_law(true);
    let example = |slave_scaling: f64| CamScalingCall {
        activation_mode: 3,
        master_scaling_mode: 2,
        slave_scaling_mode: 0,
        master_offset: 0.0,
        slave_offset: 0.0,
        master_scaling: 1.0,
        slave_scaling,
        ..CamScalingCall::default()
    };
    // Mid cycle: sent; the slave follows its law up to the cycle's end.
    while set(&run, MASTER).position < 200.0 {
        run.step();
    }
    assert_eq!(call(&mut run, SLAVE as u32, example(0.0)), 0);
    let follows = |run: &Harness| {
        (set(run, SLAVE).position - law_at(&law, &profile, set(run, MASTER)).position).abs() < 1e-9
    };
    while set(&run, MASTER).position < 359.0 {
        run.step();
        assert!(follows(&run));
    }
    // The next cycle: the slave stands at the rest value 0, coupled.
    while set(&run, MASTER).position < 380.0 {
        run.step();
    }
    let mut moved: f64 = 0.0;
    while set(&run, MASTER).position < 700.0 {
        run.step();
        let s = set(&run, SLAVE);
        moved = moved.max(s.position.abs()).max(s.velocity.abs());
        assert_eq!(
            run.axis(SLAVE).coupling().map(|c| c.kind),
            Some(CouplingState::Cam)
        );
    }
    assert_eq!(moved, 0.0, "stilled for the whole cycle");
    // SlaveScaling 1.0: the motion comes back at the next cycle, on the law again.
    assert_eq!(call(&mut run, SLAVE as u32, example(1.0)), 0);
    while set(&run, MASTER).position < 740.0 {
        run.step();
    }
    let mut back = false;
    while set(&run, MASTER).position < 1000.0 {
        run.step();
        assert!(
            follows(&run),
            "on its law at {}",
            set(&run, MASTER).position
        );
        back |= set(&run, SLAVE).position > 1.0;
    }
    assert!(back, "the slave moves again");
}

/// A point change applied at once (Instantaneous) while the slave is in a segment it moves:
/// with the slave scaling mode AutoOffset the slave offset takes up the difference and the
/// slave does not jump, then follows the changed cam shifted by that offset; with
/// UserDefined the same change jumps (the contrast that shows the offset at work).
#[test]
fn an_online_point_change_with_slave_auto_offset_does_not_jump() {
    use hli::calls::cam::CamOnlineModeCall;
    let run_with = |slave_mode: u32| -> (f64, Vec<(f64, f64)>) {
        let mut run = machine();
        run.step();
        select_cyclic(&mut run, 1);
        assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
        run_master(&mut run, 360.0);
        // In the rise from 150 towards point 4 at 240.
        while set(&run, MASTER).position < 200.0 {
            run.step();
        }
        let mode = CamOnlineModeCall {
            activation_mode: 0,
            slave_scaling_mode: slave_mode,
            ..Default::default()
        };
        let reply = answer(&mut run, 1, &mode);
        assert_eq!(reply.error_id, 0);
        assert_eq!(write_point_4(&mut run), 0);
        let mut last = set(&run, SLAVE).position;
        let mut largest: f64 = 0.0;
        let mut samples = Vec::new();
        for _ in 0..300 {
            run.step();
            let p = set(&run, SLAVE).position;
            largest = largest.max((p - last).abs());
            last = p;
            samples.push((set(&run, MASTER).position, p));
        }
        (largest, samples)
    };
    let (auto_step, samples) = run_with(1);
    let (user_step, _) = run_with(0);
    // One tick's travel on the rise is under 0.35; the plain change jumps by about 2.
    assert!(auto_step < 0.35, "AutoOffset: largest step {auto_step}");
    assert!(user_step > 1.0, "UserDefined: largest step {user_step}");
    // After the change: the changed cam plus one constant offset.
    let changed = changed_cam(&seed_cam());
    let offsets: Vec<f64> = samples
        .iter()
        .map(|&(m, p)| {
            p - changed
                .eval(m.rem_euclid(360.0), &mut ProfileCursor::default())
                .position
        })
        .collect();
    let spread = offsets
        .iter()
        .fold(0.0f64, |w, o| w.max((o - offsets[0]).abs()));
    assert!(spread < 1e-9, "one offset: {offsets:?}");
    assert!(
        offsets[0].abs() > 0.1,
        "the offset took up the change: {}",
        offsets[0]
    );
}

/// MC_WriteMotionFunctionPoint of the seed cam's point 4 (the fall's start at 240) from 40 to
/// 30, as the conveyor's PLC writes it: the error id of the answer.
fn write_point_4(run: &mut Harness) -> u32 {
    let write = hli::calls::cam::CamPointsWriteCall::one(seed_point_4(30.0));
    call(run, 1, write)
}
