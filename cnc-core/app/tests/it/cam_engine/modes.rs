//! Actual-value masters, scaling activation modes, coupling starts and online point changes.

use super::*;
use hli::calls::cam::CAM_START_AS_SELECTED;

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
    let law = seed_law(false);
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
        let law = seed_law(true);
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
    use hli::calls::cam::CamOnlineModeCall;
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
    assert_eq!(write_point_4(&mut run), 0);
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

/// MC_CamTableSelect's MasterAbsolute/SlaveAbsolute choose absolute or relative (seed 000
/// 5.1.1: FALSE is relative); MC_CamIn's StartMode 0 ("as selected", the block's default)
/// takes that choice, and an explicit StartMode that says otherwise is refused (0x4262) with
/// the axis untouched, both ways. A table never selected takes whatever MC_CamIn says.
#[test]
fn a_start_mode_that_contradicts_the_table_selection_is_refused() {
    let mut run = machine("");
    run.step(0.001);
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
        assert!(run.machine.axes().axis(SLAVE).unwrap().coupling().is_none());
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
    let mut fresh = machine("");
    fresh.step(0.001);
    assert_eq!(
        call(&mut fresh, SLAVE as u32, mode(CamStartMode::Relative.raw())),
        0
    );
}

/// A table selected with MasterAbsolute and SlaveAbsolute FALSE couples relative with
/// MC_CamIn's default StartMode: the slave standing at 5 follows 5 + T(master), the seed
/// cam's law counted from where it stood.
#[test]
fn a_table_selected_relative_couples_relative() {
    let mut run = machine("");
    run.step(0.001);
    let command =
        hli::calls::axis::AxisCommandCall::move_absolute(5.0, [100.0, 1000.0, 1000.0, 10_000.0]);
    let view = CncView::new(&run.memory);
    run.machine.call(&view, SLAVE as u32, &command).unwrap();
    while set(&run, SLAVE).position != 5.0 || set(&run, SLAVE).velocity != 0.0 {
        run.step(0.001);
    }
    let select = CamTableSelectCall {
        periodic: 1,
        master_absolute: 0,
        slave_absolute: 0,
        reserved: 0,
    };
    assert_eq!(call(&mut run, 1, select), 0);
    let c = CamInCall {
        start_mode: CAM_START_AS_SELECTED,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, SLAVE as u32, c), 0);
    // Coupled in the next tick, with the master still at 0 (its origin).
    run.step(0.001);
    run_master(&mut run, 360.0);
    let (profile, law) = (seed_cam(), seed_law(true));
    let mut checked = 0;
    for _ in 0..1500 {
        run.step(0.001);
        let m = set(&run, MASTER);
        let expected = 5.0 + law_at(&law, &profile, m).position;
        let got = set(&run, SLAVE).position;
        assert!(
            (got - expected).abs() < 1e-9,
            "at {}: {got} vs {expected}",
            m.position
        );
        checked += u32::from(expected > 6.0);
    }
    assert!(checked > 100, "the cam moved the slave ({checked})");
}

/// DeleteQueuedData on a pending MC_CamInExt switch: the queued switch to the stroke table is
/// dropped (MC_CamInfo shows nothing queued), and when the master passes the activation
/// position the slave stays on the seed cam, on its law tick by tick.
#[test]
fn delete_queued_data_drops_a_pending_switch_and_the_slave_stays_on_its_cam() {
    use hli::calls::cam::{CamReadCall, CamReadKind};
    let mut run = switchable_at_speed();
    assert_eq!(call(&mut run, SLAVE as u32, switch_to_stroke_at_200()), 0);
    let queued = |run: &mut InProcess| {
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
        run.step(0.001);
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
    let mut run = machine("");
    run.step(0.001);
    select_cyclic(&mut run, 2);
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(2)), 0);
    run_master(&mut run, 360.0);
    // The stroke table climbs from 0 to 16 over the first half turn: at 90 the slave moves.
    while set(&run, MASTER).position < 90.0 {
        run.step(0.001);
    }
    let before = set(&run, SLAVE);
    assert!(before.velocity > 10.0, "moving: {}", before.velocity);
    assert_eq!(call(&mut run, SLAVE as u32, CamOutCall::default()), 0);
    run.step(0.001);
    let after = set(&run, SLAVE);
    assert!(run.machine.axes().axis(SLAVE).unwrap().coupling().is_none());
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
        run.step(0.001);
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
    let mut run = machine("");
    run.step(0.001);
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
        run.step(0.001);
    }
    assert_eq!(call(&mut run, SLAVE as u32, example(0.0)), 0);
    let follows = |run: &InProcess| {
        (set(run, SLAVE).position - law_at(&law, &profile, set(run, MASTER)).position).abs() < 1e-9
    };
    while set(&run, MASTER).position < 359.0 {
        run.step(0.001);
        assert!(follows(&run));
    }
    // The next cycle: the slave stands at the rest value 0, coupled.
    while set(&run, MASTER).position < 380.0 {
        run.step(0.001);
    }
    let mut moved: f64 = 0.0;
    while set(&run, MASTER).position < 700.0 {
        run.step(0.001);
        let s = set(&run, SLAVE);
        moved = moved.max(s.position.abs()).max(s.velocity.abs());
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
    assert_eq!(moved, 0.0, "stilled for the whole cycle");
    // SlaveScaling 1.0: the motion comes back at the next cycle, on the law again.
    assert_eq!(call(&mut run, SLAVE as u32, example(1.0)), 0);
    while set(&run, MASTER).position < 740.0 {
        run.step(0.001);
    }
    let mut back = false;
    while set(&run, MASTER).position < 1000.0 {
        run.step(0.001);
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
        let mut run = machine("");
        run.step(0.001);
        select_cyclic(&mut run, 1);
        assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
        run_master(&mut run, 360.0);
        // In the rise from 150 towards point 4 at 240.
        while set(&run, MASTER).position < 200.0 {
            run.step(0.001);
        }
        let mode = CamOnlineModeCall {
            activation_mode: 0,
            slave_scaling_mode: slave_mode,
            ..Default::default()
        };
        let reply: CamReply = bytemuck::pod_read_unaligned(&dispatch_raw(&mut run, 1, &mode));
        assert_eq!(reply.error_id, 0);
        assert_eq!(write_point_4(&mut run), 0);
        let mut last = set(&run, SLAVE).position;
        let mut largest: f64 = 0.0;
        let mut samples = Vec::new();
        for _ in 0..300 {
            run.step(0.001);
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

/// MC_CamScaling is Done when the scaling has been carried out (seed 000 5.1.6), not when the
/// CNC took it: sent mid-cycle with ActivationMode NextCycle, it stays Busy until the master
/// crosses the cycle boundary; the step waiting for its Done fires only then.
#[test]
fn cam_scaling_is_done_when_its_scaling_activates() {
    let scenario = "cycle_ms = 1.0\nticks = 2500\n\
        [[axis]]\nname = \"Conveyor\"\nkind = \"rotary\"\npower = true\nvelocity = 720.0\n\
        acceleration = 3600.0\ndeceleration = 3600.0\njerk = 36000.0\n\
        [[axis]]\nname = \"Lifter\"\npower = true\nsoft_limits = [-100.0, 200.0]\n\
        [[cam_table]]\nfile = \"seed_example.json\"\n[plc]\ntimeline = \"plc.toml\"\n";
    let timeline = r#"
[[step]]
at_tick = 2
call = { block = "MC_CamTableSelect", instance = "select", axis = 1, table = 1, periodic = true, master_absolute = true, slave_absolute = true }
[[step]]
wait = "select.Done"
call = { block = "MC_CamIn", instance = "cam", axis = 1, master = 0, table = 1, start_mode = "absolute" }
[[step]]
wait = "cam.InSync"
call = { block = "MC_MoveVelocity", instance = "run", axis = 0, velocity = 360.0, direction = 1, acceleration = 3600.0, deceleration = 3600.0, jerk = 36000.0 }
[[step]]
at_tick = 500
call = { block = "MC_CamScaling", instance = "scale", axis = 1, activation_mode = "next_cycle", slave_scaling_mode = "auto_offset", slave_scaling = 0.5 }
[[step]]
wait = "scale.Done"
call = { block = "MC_Halt", instance = "halt", axis = 0, deceleration = 3600.0, jerk = 36000.0 }
"#;
    let s = with_timeline("scaling-done.toml", scenario, timeline);
    let mut run = InProcess::new(&s, 0).unwrap();
    let mut crossed = None;
    let mut before: f64 = 0.0;
    for tick in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let m = set(&run, MASTER).position;
        if crossed.is_none() && tick > 500 && m.rem_euclid(360.0) < before.rem_euclid(360.0) {
            crossed = Some(tick);
        }
        before = m;
    }
    let crossed = crossed.expect("the master crossed a cycle boundary after tick 500");
    let records = run.timeline.as_ref().unwrap().records().to_vec();
    let sent = records[3].first_fired_at.expect("the scaling was sent");
    let done = records[4].first_fired_at.expect("the scaling became Done");
    assert!(
        sent >= 500 && sent + 100 < crossed,
        "sent at {sent}, boundary at {crossed}"
    );
    assert!(
        (crossed..crossed + 5).contains(&done),
        "Done at tick {done}, the boundary at {crossed}"
    );
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
}

/// MC_WriteMotionFunctionPoint of the seed cam's point 4 (the fall's start at 240) from 40 to
/// 30, as the conveyor's PLC writes it: the error id of the answer.
fn write_point_4(run: &mut InProcess) -> u32 {
    let write = one_point_write(seed_point_4(30.0));
    bytemuck::pod_read_unaligned::<CamReply>(&dispatch_raw(run, 1, &write)).error_id
}

/// MC_CamScaling with ActivationMode OFF carries no scaling out (seed 000 5.1.16.13): taken
/// (0) and nothing changes: the slave stays on its law, and a scaling queued before it (the
/// seed's example 1 at NextCycle) still comes at the next cycle as queued, not the OFF call's.
#[test]
fn a_scaling_with_activation_off_changes_nothing() {
    let mut run = machine("");
    run.step(0.001);
    select_cyclic(&mut run, 1);
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
    run_master(&mut run, 360.0);
    let profile = seed_cam();
    let law = seed_law(true);
    let scaling = |activation_mode: u32, slave_scaling: f64| CamScalingCall {
        activation_mode,
        master_scaling_mode: 2,
        slave_scaling_mode: 0,
        master_scaling: 1.0,
        slave_scaling,
        ..CamScalingCall::default()
    };
    while set(&run, MASTER).position < 200.0 {
        run.step(0.001);
    }
    assert_eq!(call(&mut run, SLAVE as u32, scaling(3, 0.0)), 0);
    assert_eq!(call(&mut run, SLAVE as u32, scaling(6, 3.0)), 0);
    while set(&run, MASTER).position < 359.0 {
        run.step(0.001);
        let expected = law_at(&law, &profile, set(&run, MASTER)).position;
        assert!((set(&run, SLAVE).position - expected).abs() < 1e-9);
    }
    while set(&run, MASTER).position < 380.0 {
        run.step(0.001);
    }
    let mut moved: f64 = 0.0;
    while set(&run, MASTER).position < 700.0 {
        run.step(0.001);
        moved = moved.max(set(&run, SLAVE).position.abs());
    }
    assert_eq!(
        moved, 0.0,
        "the queued SlaveScaling 0, not the OFF call's 3"
    );
}

/// The block: MC_CamScaling with ActivationMode "off" is Done as soon as the CNC took it,
/// while a NextCycle scaling queued before it waits for its cycle (and is Done then).
#[test]
fn mc_cam_scaling_off_is_done_at_once_beside_a_queued_scaling() {
    let timeline = r#"
[[step]]
at_tick = 2
call = { block = "CamTableGenerate", instance = "generate", axis = 1, table = 22, table_type = 2, rows = [[0.0, 0.0], [90.0, 9.0], [180.0, 0.0], [270.0, -9.0], [360.0, 0.0]] }
[[step]]
wait = "generate.Done"
call = { block = "CamTableCoupleAxesIpol", instance = "couple", axis = 1, master = 0, table = 22, interpolation = 0, master_absolute = true, slave_absolute = true }
[[step]]
wait = "couple.Done"
call = { block = "MC_MoveVelocity", instance = "turn", axis = 0, velocity = 180.0, direction = 1, acceleration = 1800.0, deceleration = 1800.0, jerk = 18000.0 }
[[step]]
at_tick = 600
call = { block = "MC_CamScaling", instance = "queued", axis = 1, activation_mode = "next_cycle", master_scaling_mode = "off", slave_scaling_mode = "user_defined", slave_scaling = 0.5 }
[[step]]
at_tick = 610
call = { block = "MC_CamScaling", instance = "off", axis = 1, activation_mode = "off", master_scaling_mode = "off", slave_scaling_mode = "user_defined", slave_scaling = 3.0 }
"#;
    let toml = "cycle_ms = 1.0\nticks = 3000\n\
        [[axis]]\nname = \"Drum\"\nkind = \"rotary\"\npower = true\n\
        [[axis]]\nname = \"Pusher\"\npower = true\nsoft_limits = [-50.0, 50.0]\n\
        following_error_limit = 5.0\n[plc]\ntimeline = \"plc.toml\"\n";
    let s = with_timeline("off.toml", toml, timeline);
    let run = InProcess::run_through(&s).unwrap();
    let summary = run.timeline.as_ref().unwrap().summary();
    let done_at = |name: &str| -> u64 {
        let line = summary
            .lines()
            .find(|l| l.starts_with(&format!("block {name} ")))
            .unwrap_or_else(|| panic!("{name}: {summary}"));
        let after = &line[line.find("Done ").unwrap_or_else(|| panic!("{line}")) + 5..];
        after.split_whitespace().next().unwrap().parse().unwrap()
    };
    let (off, queued) = (done_at("off"), done_at("queued"));
    assert!(off < 620, "done at once: {off}\n{summary}");
    assert!(
        queued > off + 100,
        "the queued one at its cycle: {queued}\n{summary}"
    );
    assert!(!summary.contains("ErrorID"), "{summary}");
}

/// MC_CamIn's InterpolationType overrides the table's for that coupling (seed 000 5.1.2): a
/// cyclic equidistant table stored linear, coupled once as it is and once with "spline", the
/// master moved to 45: the slave reads the linear 5.0, then the periodic spline's value there
/// (the kinematics of the table evaluated with the spline, by hand through `PositionTable`).
#[test]
fn mc_cam_in_interpolation_overrides_the_tables() {
    let rows = [
        [0.0, 0.0],
        [90.0, 10.0],
        [180.0, 0.0],
        [270.0, -10.0],
        [360.0, 0.0],
    ];
    let at_45 = |interpolation: &str| -> f64 {
        let timeline = format!(
            r#"
[[step]]
at_tick = 2
call = {{ block = "CamTableGenerate", instance = "generate", axis = 1, table = 22, table_type = 2, rows = [[0.0, 0.0], [90.0, 10.0], [180.0, 0.0], [270.0, -10.0], [360.0, 0.0]] }}
[[step]]
wait = "generate.Done"
call = {{ block = "MC_CamTableSelect", instance = "select", axis = 1, table = 22, periodic = true, master_absolute = true, slave_absolute = true }}
[[step]]
wait = "select.Done"
call = {{ block = "MC_CamIn", instance = "cam", axis = 1, master = 0, table = 22, start_mode = "absolute", interpolation = "{interpolation}" }}
[[step]]
wait = "cam.InSync"
call = {{ block = "MC_MoveAbsolute", instance = "go", axis = 0, position = 45.0, velocity = 90.0, acceleration = 900.0, deceleration = 900.0, jerk = 9000.0 }}
"#
        );
        let toml = "cycle_ms = 1.0\nticks = 3000\n\
            [[axis]]\nname = \"Drum\"\nkind = \"rotary\"\npower = true\n\
            [[axis]]\nname = \"Pusher\"\npower = true\nsoft_limits = [-50.0, 50.0]\n\
            following_error_limit = 5.0\n[plc]\ntimeline = \"plc.toml\"\n";
        let s = with_timeline("ipol.toml", toml, &timeline);
        let run = InProcess::run_through(&s).unwrap();
        let summary = run.timeline.as_ref().unwrap().summary();
        assert!(!summary.contains("ErrorID"), "{summary}");
        assert_eq!(set(&run, MASTER).position, 45.0);
        set(&run, SLAVE).position
    };
    assert!((at_45("linear") - 5.0).abs() < 1e-9);
    let spline = CamProfile::Table(
        cnc_core::cam::PositionTable::new(
            &rows,
            cnc_core::cam::TableType::Equidistant,
            hli::calls::cam::CamInterpolation::Spline,
            true,
        )
        .unwrap(),
    )
    .eval(45.0, &mut cnc_core::cam::ProfileCursor::default())
    .position;
    assert!(
        (spline - 5.0).abs() > 0.1,
        "the spline differs here: {spline}"
    );
    assert!((at_45("spline") - spline).abs() < 1e-9, "{spline}");
}

/// Reserve points (seed 000 3.1, 3.5): points laid in as IGNORE drop out of the cam, and are
/// switched on while it runs by writing another point type. The seed's six-point cam with
/// its points 3 and 4 as IGNORE keeps the slave at rest through the running cycle; written as
/// VELOCITY points at NextCycle (point 4 first: written alone, point 3's line would end in a
/// rest point), they apply at the cycle's end: in the next cycle the slave is
/// 20 at 150 and 40 at 240, as in the full cam, and nothing jumps at the wrap. From the first
/// write until then the slave's `AxisCamDataQueued` (its axis image's bit) is TRUE.
#[test]
fn reserve_points_switched_on_while_the_cam_runs_apply_at_the_next_cycle() {
    let json = std::fs::read_to_string(scenarios().join("cams/seed_example.json"))
        .unwrap()
        .replacen(
            "\"point_type\": \"VELOCITY\"",
            "\"point_type\": \"IGNORE\"",
            2,
        );
    assert_eq!(json.matches("IGNORE").count(), 2);
    let timeline = r#"
[[step]]
at_tick = 2
call = { block = "MC_CamTableSelect", instance = "select", axis = 1, table = 1, periodic = true, master_absolute = true, slave_absolute = true }
[[step]]
wait = "select.Done"
call = { block = "MC_CamIn", instance = "cam", axis = 1, master = 0, table = 1, start_mode = "absolute" }
[[step]]
wait = "cam.InSync"
call = { block = "MC_MoveVelocity", instance = "run", axis = 0, velocity = 360.0, direction = 1, acceleration = 3600.0, deceleration = 3600.0, jerk = 36000.0 }
[[step]]
at_tick = 500
call = { block = "MC_SetCamOnlineChangeMode", instance = "mode", axis = 1, table = 1, activation_mode = "next_cycle" }
[[step]]
wait = "mode.Done"
call = { block = "MC_WriteMotionFunctionPoint", instance = "p4", axis = 1, table = 1, point_index = 4, function_type = 15, point_type = 2, master_pos = 240.0, slave_pos = 40.0 }
[[step]]
wait = "p4.Done"
call = { block = "MC_WriteMotionFunctionPoint", instance = "p3", axis = 1, table = 1, point_index = 3, function_type = 1, point_type = 2, master_pos = 150.0, slave_pos = 20.0 }
"#;
    let toml = "cycle_ms = 1.0\nticks = 3000\n\
        [[axis]]\nname = \"Conveyor\"\nkind = \"rotary\"\npower = true\nvelocity = 720.0\n\
        acceleration = 3600.0\ndeceleration = 3600.0\njerk = 36000.0\n\
        [[axis]]\nname = \"Lifter\"\npower = true\nsoft_limits = [-10.0, 100.0]\n\
        [[cam_table]]\nfile = \"seed_example.json\"\n[plc]\ntimeline = \"plc.toml\"\n";
    let s = Scenario::parse("reserve.toml", toml, |f| {
        let text = match f {
            "plc.toml" => timeline.to_string(),
            "seed_example.json" => json.clone(),
            other => panic!("{other}"),
        };
        Ok((PathBuf::from(f), text))
    })
    .unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let (mut first_cycle_max, mut seen, mut last): (f64, Vec<(f64, f64)>, f64) = (0.0, vec![], 0.0);
    let mut queued_at = Vec::new();
    for tick in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let (m, p) = (set(&run, MASTER).position, set(&run, SLAVE).position);
        // AxisCamDataQueued: from the write until the change applies at the cycle's end.
        let view = hli::views::PlcView::new(&run.memory);
        if plc_shim::blocks::cam::axis_cam_data_queued(&view, SLAVE) {
            queued_at.push((tick, m));
        }
        assert!((p - last).abs() < 0.5, "no jump: {last} -> {p} at {m}");
        last = p;
        if m < 360.0 {
            first_cycle_max = first_cycle_max.max(p.abs());
        } else if m < 720.0 {
            seen.push((m, p));
        }
    }
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    assert_eq!(
        first_cycle_max, 0.0,
        "the reserves stay out in the running cycle"
    );
    let (first, last_queued) = (queued_at[0], *queued_at.last().unwrap());
    assert!(
        (503..=506).contains(&first.0),
        "queued from the write: {first:?}"
    );
    assert!(
        last_queued.1 < 360.0,
        "until the cycle's end: {last_queued:?}"
    );
    assert_eq!(
        queued_at.len() as u64,
        last_queued.0 - first.0 + 1,
        "without a gap"
    );
    let near = |x: f64| {
        seen.iter()
            .min_by(|a, b| (a.0 - x).abs().total_cmp(&(b.0 - x).abs()))
            .unwrap()
            .1
    };
    assert!((near(510.0) - 20.0).abs() < 0.5, "{}", near(510.0));
    assert!((near(600.0) - 40.0).abs() < 0.5, "{}", near(600.0));
}
