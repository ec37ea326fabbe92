//! The dynamic CS against the manual's own numbers (seed 003): the switching log and the
//! diagnosis history of its diagnosis chapter, the FILTER (default 200, the switch-off taking
//! the switch-on's filter, a smoothing ramp without velocity steps), FREEZE and the soft
//! take-over, the soft release out of ERROR, and the PLC requests that are refused or not
//! redirected without ever blocking a later switch-on.

use tests::channel_rig as support;

use cnc_core::channel::dyn_cs::{smooth_ramp, TrackEvent};
use cnc_core::channel::{Controller, RunState};
use hli::enums::{DynCsCommand, DynCsState};
use hli::views::{CncView, PlcView};
use hli::Bool;
use support::*;

/// Ticks of the tracker's log events that match `pick`, in order.
fn ticks_of(ctl: &Controller, pick: impl Fn(&TrackEvent) -> bool) -> Vec<u64> {
    ctl.channels()[0]
        .tracker()
        .log()
        .filter(|(_, e)| pick(e))
        .map(|(t, _)| *t)
        .collect()
}

/// The log part of a diagnosis: its header line and its lines after `-----`.
fn log_part(diagnosis: &str) -> (String, Vec<String>) {
    let log = &diagnosis[diagnosis.find("BAHN LOGGING").unwrap()..];
    let header = log.lines().nth(2).unwrap().to_string();
    let lines = log
        .lines()
        .skip_while(|l| *l != "-----")
        .skip(1)
        .map(str::to_string)
        .collect();
    (header, lines)
}

/// The manual's diagnosis scenario on a Cartesian slave: the axis stands at X 0.32 mm (3200 in
/// 0.1 um); the PLC, master with enable_w TRUE, switches on with FILTER=1000 and f_wait, moves
/// its frame to (0.1, -0.1, 0) mm once the state is ACTIVE, and switches off with FILTER=1000.
/// Returns the diagnosis 100 ticks after the move, the one right after the switch-off, and the
/// tracker's tick of the switch-on and of the switch-off.
fn manual_diagnosis_run() -> (String, String, u64, u64) {
    let mut ctl = controller(vec![(cartesian("slave"), "G1 X0.32 F600\n#TIME 5\nM30\n")]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    let view = CncView::new(&memory);
    enable_plc_master(&memory, [0, 0, 0]);
    let mut moved_at = None;
    let mut while_active = None;
    for tick in 0..5000u32 {
        if tick == 200 {
            plc.dyn_cs_transition(0)
                .unwrap()
                .try_send(DynCsCommand::Activate, &transition(1000, Bool::TRUE))
                .unwrap();
        }
        let state = plc.dyn_cs_state(0).unwrap().unwrap();
        if state == DynCsState::Active && moved_at.is_none() {
            plc.dyn_cs_command(0)
                .unwrap()
                .try_send(&cs([1000, -1000, 0]))
                .unwrap();
            moved_at = Some(tick);
        }
        if moved_at.is_some_and(|m| tick == m + 100) {
            while_active = Some(ctl.channels()[0].dyn_cs_diagnosis());
            plc.dyn_cs_transition(0)
                .unwrap()
                .try_send(DynCsCommand::Deactivate, &transition(1000, Bool::FALSE))
                .unwrap();
        }
        ctl.tick(&view);
        let ch = &ctl.channels()[0];
        assert_ne!(ch.state(), RunState::Error, "{:?}", ch.error());
        if let Some(active) = &while_active {
            let on = ticks_of(&ctl, |e| matches!(e, TrackEvent::On { .. }))[0];
            let off = ticks_of(&ctl, |e| matches!(e, TrackEvent::Off { .. }))[0];
            return (active.clone(), ch.dyn_cs_diagnosis(), on, off);
        }
    }
    panic!("watchdog: the scenario did not reach its switch-off");
}

/// The switching log of the manual's diagnosis chapter, line for line: the level column, the
/// `BF 8 logging : 16/40 ... index 16` header (2 restart + 8 switch-on + 6 switch-off lines),
/// the switch-on's values one tick after the command, `is on` exactly FILTER ticks after it,
/// and the switch-off with its source, the axis positions and the dynamic CS it leaves.
#[test]
fn the_switching_log_reads_like_the_manuals_example() {
    let (_, diagnosis, on, off) = manual_diagnosis_run();
    let (header, lines) = log_part(&diagnosis);
    assert_eq!(header, "BF 8 logging : 16/40, level ffffffff, index 16");
    let d = "00000010";
    let expected: Vec<String> = [
        (0, "00000001", "BAHN restart... start"),
        (0, "00000001", "BAHN restart...finished"),
        (on, d, "dynCS: cmd=ON PLC=1 NO FILTER=1000 WAIT=1"),
        (on + 1, d, "dynCS: ON, axes positions"),
        (on + 1, d, "a[0..2](3200, 0, 0)"),
        (on + 1, d, "a[3..5](0, 0, 0)"),
        (on + 1, d, "dynCS: ON, VALUE"),
        (on + 1, d, "T(0, 0, 0)"),
        (on + 1, d, "R(0, 0, 0)"),
        (on + 1000, d, "dynCS: is on = DYN_CS_SYNC_ACTIVE"),
        (off, d, "dynCS: cmd=OFF PLC=1 NO FILTER=1000"),
        (off, d, "a[0..2](3200, 0, 0)"),
        (off, d, "a[3..5](0, 0, 0)"),
        (off, d, "dynCS: VALUE"),
        (off, d, "T(1000, -1000, 0)"),
        (off, d, "R(0, 0, 0)"),
    ]
    .iter()
    .map(|(t, level, m)| format!("{t} {level} {m}"))
    .collect();
    assert_eq!(lines, expected, "{diagnosis}");
}

/// The history of the manual's diagnosis chapter: the `max entries per PDU` line, 20 rows (the
/// default of P-STUP-00074), state 2, the input X 3200 plus the translation (1000, -1000, 0)
/// giving the output (4200, -1000, 0, 0, 0, 0); the first row shows the whole tick, the
/// following ones its last three digits, one tick apart.
#[test]
fn the_history_reproduces_the_manuals_sample_rows() {
    let (diagnosis, _, _, _) = manual_diagnosis_run();
    let mut lines = diagnosis.lines();
    assert_eq!(
        lines.next(),
        Some("BAHN : DYNAMIC CS, CHANNEL-NR.: 1"),
        "{diagnosis}"
    );
    assert_eq!(lines.next(), Some("====="));
    assert_eq!(lines.next(), Some("dynCs : max entries per PDU 15"));
    assert_eq!(
        lines.next(),
        Some("TIME STATE POSITION_IN CS_TRANSLATION CS_ROTATION POSITION_OUT")
    );
    let rows: Vec<&str> = lines.take_while(|l| !l.is_empty()).collect();
    assert_eq!(rows.len(), 20, "{diagnosis}");
    let first: u64 = rows[0].split(' ').next().unwrap().parse().unwrap();
    assert!(
        first > 1000,
        "the first row shows the whole tick: {}",
        rows[0]
    );
    for (n, row) in rows.iter().enumerate() {
        let (time, rest) = row.split_once(' ').unwrap();
        let expected_time = if n == 0 {
            first.to_string()
        } else {
            format!("{:03}", (first + n as u64) % 1000)
        };
        assert_eq!(time, expected_time, "row {}: {row}", n + 1);
        assert_eq!(
            rest,
            format!(
                "{}) 2 (3200,0,0,0,0,0) (1000,-1000,0) (0,0,0) (4200,-1000,0,0,0,0)",
                n + 1
            )
        );
    }
}

/// Runs `program` on a Cartesian slave while the PLC, enabled, stands its frame at
/// `translation` (0.1 um) and moves it `y_step` (0.1 um) in Y per tick; returns the controller
/// and the X and Y compensation (set-point minus programmed value, mm) before the first tick
/// and after each.
fn follow_plc(program: &str, translation: [i32; 3], y_step: i32) -> (Controller, Vec<[f64; 2]>) {
    let mut ctl = controller(vec![(cartesian("slave"), program)]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    let view = CncView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    // Entry n is the compensation after n ticks (the tracker's tick n).
    let mut compensation = vec![[0.0; 2]];
    let mut y = 0;
    for _ in 0..20_000 {
        let frame = cs([translation[0], translation[1] + y, translation[2]]);
        if plc.dyn_cs_command(0).unwrap().try_send(&frame).is_ok() {
            y += y_step;
        }
        ctl.tick(&view);
        let ch = &ctl.channels()[0];
        assert_ne!(ch.state(), RunState::Error, "{:?}", ch.error());
        let (set, programmed) = (ch.set_points(), ch.programmed());
        compensation.push([set[0] - programmed[0], set[1] - programmed[1]]);
        if ch.state() == RunState::Finished {
            return (ctl, compensation);
        }
    }
    panic!("watchdog: the program did not finish");
}

/// Ticks from the switch-on to ACTIVE and from the switch-off to INACTIVE.
fn filter_lengths(ctl: &Controller) -> (u64, u64) {
    let tick = |pick: fn(&TrackEvent) -> bool| ticks_of(ctl, pick)[0];
    let on = tick(|e| matches!(e, TrackEvent::On { .. }));
    let active = tick(|e| matches!(e, TrackEvent::Active));
    let off = tick(|e| matches!(e, TrackEvent::Off { .. }));
    let inactive = tick(|e| matches!(e, TrackEvent::Inactive));
    (active - on, inactive - off)
}

/// FILTER's default is 200 ticks; a switch-off without FILTER takes the switch-on's filter
/// (the manual's log shows the same FILTER on both); FILTER on the switch-off overrides it.
#[test]
fn the_filter_defaults_to_200_and_the_switch_off_takes_the_switch_on_filter() {
    let run = |program: &str| {
        let (ctl, _) = follow_plc(program, [100_000, 0, 0], 0);
        filter_lengths(&ctl)
    };
    assert_eq!(
        run("#TRACK CS ON [ID=0 WAIT]\n#TRACK CS OFF [WAIT]\nM30\n"),
        (200, 200)
    );
    assert_eq!(
        run("#TRACK CS ON [ID=0 FILTER=300 WAIT]\n#TRACK CS OFF [WAIT]\nM30\n"),
        (300, 300)
    );
    assert_eq!(
        run("#TRACK CS ON [ID=0 FILTER=300 WAIT]\n#TRACK CS OFF [FILTER=40 WAIT]\nM30\n"),
        (300, 40)
    );
    let (ctl, _) = follow_plc(
        "#TRACK CS ON [ID=0 FILTER=300 WAIT]\n#TRACK CS OFF [WAIT]\nM30\n",
        [100_000, 0, 0],
        0,
    );
    assert!(ctl.channels()[0]
        .dyn_cs_diagnosis()
        .contains("dynCS: cmd=OFF PLC=1 NO FILTER=300"));
}

/// The filter couples a 10 mm frame in over 200 ticks along the smoothing ramp: every tick's
/// compensation is the ramp's value, it starts from rest and arrives at rest (a linear ramp
/// would step by 0.05 mm per tick at once), and its velocity changes by little per tick. With
/// the master moving, the compensation arrives at the master's velocity without a step.
#[test]
fn the_filter_couples_in_along_a_smooth_ramp_without_velocity_steps() {
    let (_, comp) = follow_plc(
        "#TRACK CS ON [ID=0 WAIT]\n#TIME 0.1\nM30\n",
        [100_000, 0, 0],
        0,
    );
    let start = comp.iter().position(|c| c[0] != 0.0).unwrap();
    for k in 0..=200 {
        let expected = 10.0 * smooth_ramp(f64::from(k as u32 + 1) / 200.0);
        assert!(
            (comp[start + k][0] - expected).abs() < 1e-9,
            "tick {k}: {} vs {expected}",
            comp[start + k][0]
        );
    }
    let steps: Vec<f64> = comp.windows(2).map(|w| w[1][0] - w[0][0]).collect();
    let first = steps[start - 1];
    let last = steps[start + 198];
    // 10 * ramp(1/200) = 1.25e-5 mm, where a linear ramp steps by 0.05 mm at once.
    assert!(first < 2e-5 && last < 2e-5, "first {first}, last {last}");
    let largest = steps.iter().fold(0.0f64, |m, s| m.max(s.abs()));
    assert!(
        (largest - 10.0 / 200.0 * 15.0 / 8.0).abs() < 1e-4,
        "largest step {largest}"
    );
    let largest_change = steps
        .windows(2)
        .fold(0.0f64, |m, w| m.max((w[1] - w[0]).abs()));
    // The ramp's curvature is at most 10/sqrt(3) / N^2 of the distance per tick squared.
    assert!(
        largest_change < 10.0 * 5.78 / 200.0 / 200.0,
        "velocity change per tick {largest_change}"
    );

    // A master moving 1 um per tick in Y: at the end of the ramp the compensation moves with it.
    let (ctl, comp) = follow_plc("#TRACK CS ON [ID=0 WAIT]\n#TIME 0.1\nM30\n", [0, 0, 0], 10);
    let active = ticks_of(&ctl, |e| matches!(e, TrackEvent::Active))[0] as usize;
    let v = |t: usize| comp[t][1] - comp[t - 1][1];
    for t in active - 3..active + 20 {
        assert!(
            (v(t) - v(t - 1)).abs() < 2e-5,
            "tick {t}: velocity {} after {}",
            v(t),
            v(t - 1)
        );
    }
    assert!((v(active + 10) - 0.001).abs() < 1e-9);
}

/// FREEZE of the PLC master: enable_w FALSE holds the compensation exactly where it was while
/// frames the PLC writes meanwhile are not redirected (taken and counted, no fault); on resume
/// the slave takes the new frame over softly along the filter and follows it exactly after.
/// A resume while coupling in restarts the ramp from where the compensation stands.
#[test]
fn a_frozen_master_is_held_and_taken_over_softly_on_resume() {
    let mut ctl = controller(vec![(
        cartesian("slave"),
        "#TRACK CS ON [ID=0 FILTER=100]\n#TIME 2\nM30\n",
    )]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    let view = CncView::new(&memory);
    let send = |x: i32| plc.dyn_cs_command(0).unwrap().try_send(&cs([x, 0, 0]));
    let comp = |ctl: &Controller| {
        let ch = &ctl.channels()[0];
        ch.set_points()[0] - ch.programmed()[0]
    };
    plc.set_dyn_cs_enabled(0, true).unwrap();
    send(200_000).unwrap();
    // Coupling in: 20 mm; freeze at tick 50 of the ramp.
    for _ in 0..51 {
        ctl.tick(&view);
    }
    let at_freeze = comp(&ctl);
    assert!(at_freeze > 5.0 && at_freeze < 15.0, "{at_freeze}");
    plc.set_dyn_cs_enabled(0, false).unwrap();
    send(300_000).unwrap();
    for _ in 0..200 {
        ctl.tick(&view);
        assert_eq!(comp(&ctl), at_freeze, "held while frozen");
        assert_eq!(
            plc.dyn_cs_state(0).unwrap().unwrap(),
            DynCsState::Activating
        );
    }
    let tracker = ctl.channels()[0].tracker();
    assert_eq!(tracker.not_redirected_count(), 1);
    assert_eq!(tracker.refused_count(), 0);
    // Resume with a new frame (30 mm): a new ramp from where the compensation stands.
    plc.set_dyn_cs_enabled(0, true).unwrap();
    send(300_000).unwrap();
    let mut last = at_freeze;
    for k in 1..=100u32 {
        ctl.tick(&view);
        let expected = at_freeze + (30.0 - at_freeze) * smooth_ramp(f64::from(k) / 100.0);
        let now = comp(&ctl);
        assert!(
            (now - expected).abs() < 1e-9,
            "ramp tick {k}: {now} vs {expected}"
        );
        assert!(now - last <= (30.0 - at_freeze) / 100.0 * 15.0 / 8.0 + 1e-9);
        last = now;
    }
    assert_eq!(plc.dyn_cs_state(0).unwrap().unwrap(), DynCsState::Active);
    assert!((comp(&ctl) - 30.0).abs() < 1e-9);
    // A freeze while ACTIVE holds; the resume goes through ACTIVATING again.
    plc.set_dyn_cs_enabled(0, false).unwrap();
    for _ in 0..10 {
        ctl.tick(&view);
    }
    plc.set_dyn_cs_enabled(0, true).unwrap();
    send(250_000).unwrap();
    ctl.tick(&view);
    assert_eq!(
        plc.dyn_cs_state(0).unwrap().unwrap(),
        DynCsState::Activating
    );
    let now = comp(&ctl);
    let expected = 30.0 - 5.0 * smooth_ramp(0.01);
    assert!((now - expected).abs() < 1e-9, "{now} vs {expected}");
    let diagnosis = ctl.channels()[0].dyn_cs_diagnosis();
    assert_eq!(diagnosis.matches("master frozen, holding").count(), 2);
    assert_eq!(
        diagnosis.matches("master resumed, soft take-over").count(),
        2
    );
}

/// ERROR stops using the master: the slave's axes brake to rest and hold (here they stand
/// already, 20 mm compensated) while the master moves on. A switch-off clears ERROR without
/// moving them: the compensation they hold becomes part of the programmed position (the
/// manual describes ERROR only; the recovery is ours). A new switch-on then couples in softly
/// along its filter from where the axes stand.
#[test]
fn a_switch_off_clears_error_where_the_axes_stand_and_a_new_switch_on_couples_in_softly() {
    let mut ctl = controller(vec![(
        cartesian("slave"),
        "#TRACK CS ON [ID=0 FILTER=0]\n#TIME 0.005\n#TRACK CS ON [ID=0 FILTER=0]\nM30\n",
    )]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    let view = CncView::new(&memory);
    enable_plc_master(&memory, [200_000, 0, 0]);
    for _ in 0..20 {
        ctl.tick(&view);
    }
    let x = |ctl: &Controller| ctl.channels()[0].set_points()[0];
    assert_eq!(ctl.channels()[0].state(), RunState::Error);
    assert_eq!(plc.dyn_cs_state(0).unwrap().unwrap(), DynCsState::Error);
    // The master moves on; ERROR holds the axes at 20 mm.
    plc.dyn_cs_command(0)
        .unwrap()
        .try_send(&cs([250_000, 0, 0]))
        .unwrap();
    ctl.tick(&view);
    assert!((x(&ctl) - 20.0).abs() < 1e-12, "{}", x(&ctl));
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(DynCsCommand::Deactivate, &transition(100, Bool::FALSE))
        .unwrap();
    for _ in 0..102 {
        ctl.tick(&view);
        assert!((x(&ctl) - 20.0).abs() < 1e-12, "the axes do not move");
    }
    assert_eq!(plc.dyn_cs_state(0).unwrap().unwrap(), DynCsState::Inactive);
    assert!((ctl.channels()[0].programmed()[0] - 20.0).abs() < 1e-12);
    // A new switch-on from the PLC: the master's 25 mm come in along the filter.
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(DynCsCommand::Activate, &transition(100, Bool::FALSE))
        .unwrap();
    for k in 1..=100u32 {
        ctl.tick(&view);
        let expected = 20.0 + 25.0 * smooth_ramp(f64::from(k) / 100.0);
        assert!(
            (x(&ctl) - expected).abs() < 1e-9,
            "tick {k}: {} vs {expected}",
            x(&ctl)
        );
    }
    assert_eq!(plc.dyn_cs_state(0).unwrap().unwrap(), DynCsState::Active);
}

/// enable_w redirects the dynamic CS to the PLC. Without it a commanded frame goes nowhere (it
/// is taken, so the semaphore is free again, and counted) and a transition is refused: logged,
/// counted, the state left INACTIVE. Garbage and bad parameters are refused the same way. None
/// of it blocks the NC's later `#TRACK CS ON`, nor a later valid transition.
#[test]
fn refused_and_unredirected_plc_requests_never_block_a_later_switch_on() {
    let mut ctl = controller(vec![(
        cartesian("slave"),
        "#TIME 0.05\n#TRACK CS ON [ID=0 FILTER=0]\n#TIME 0.01\n#TRACK CS OFF [FILTER=0]\nM30\n",
    )]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    let view = CncView::new(&memory);
    // Not enabled: a frame and an ON transition.
    plc.dyn_cs_command(0)
        .unwrap()
        .try_send(&cs([100_000, 0, 0]))
        .unwrap();
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(DynCsCommand::Activate, &transition(0, Bool::FALSE))
        .unwrap();
    ctl.tick(&view);
    assert_eq!(plc.dyn_cs_state(0).unwrap().unwrap(), DynCsState::Inactive);
    assert!(
        plc.dyn_cs_command(0)
            .unwrap()
            .try_send(&cs([100_000, 0, 0]))
            .is_ok(),
        "the command semaphore is free again"
    );
    ctl.tick(&view);
    // Enabled, but an option of 7 and a garbage command word.
    plc.set_dyn_cs_enabled(0, true).unwrap();
    let mut bad = transition(0, Bool::FALSE);
    bad.option = 7;
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(DynCsCommand::Activate, &bad)
        .unwrap();
    ctl.tick(&view);
    // A flag byte that is neither FALSE nor TRUE.
    let mut flag = transition(0, Bool::FALSE);
    flag.f_kin_base = bytemuck::cast(7u8);
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(DynCsCommand::Activate, &flag)
        .unwrap();
    ctl.tick(&view);
    let command_word =
        hli::access::Leaf::resolve("gpCh[0]^channel_mc_control.dyn_cs.transition_w.command")
            .unwrap();
    command_word.write(&memory, hli::access::Value::Int(5));
    ctl.tick(&view);
    let tracker = ctl.channels()[0].tracker();
    assert_eq!(tracker.state(), DynCsState::Inactive);
    assert_eq!(tracker.not_redirected_count(), 2);
    assert_eq!(tracker.refused_count(), 4);
    let diagnosis = ctl.channels()[0].dyn_cs_diagnosis();
    for refusal in [
        "dynCS: refused: PLC transition while enable_w is FALSE",
        "dynCS: refused: invalid transition parameter: option must be 0 or 1",
        "dynCS: refused: invalid transition parameter: a flag byte is neither FALSE nor TRUE",
        "dynCS: refused: invalid transition parameter: command word is not -1, 0 or +1",
    ] {
        assert!(diagnosis.contains(refusal), "{refusal}\n{diagnosis}");
    }
    assert!(!diagnosis.contains("ERROR"), "{diagnosis}");
    // The NC's switch-on at 50 ms works and follows the PLC's frame, redirected now.
    plc.dyn_cs_command(0)
        .unwrap()
        .try_send(&cs([100_000, 0, 0]))
        .unwrap();
    let mut active = false;
    for _ in 0..200 {
        ctl.tick(&view);
        let ch = &ctl.channels()[0];
        assert_ne!(ch.state(), RunState::Error, "{:?}", ch.error());
        if ch.tracker().state() == DynCsState::Active {
            active = true;
            assert!((ch.set_points()[0] - ch.programmed()[0] - 10.0).abs() < 1e-12);
        }
    }
    assert!(active);
    assert_eq!(ctl.channels()[0].state(), RunState::Finished);
    // A valid transition after the refusals switches on too (ACTIVATING for its tick).
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(DynCsCommand::Activate, &transition(0, Bool::FALSE))
        .unwrap();
    ctl.tick(&view);
    assert_eq!(
        plc.dyn_cs_state(0).unwrap().unwrap(),
        DynCsState::Activating
    );
    ctl.tick(&view);
    assert_eq!(plc.dyn_cs_state(0).unwrap().unwrap(), DynCsState::Active);
    // A second +1 while on is refused; tracking stays ACTIVE.
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(DynCsCommand::Activate, &transition(0, Bool::FALSE))
        .unwrap();
    ctl.tick(&view);
    assert_eq!(plc.dyn_cs_state(0).unwrap().unwrap(), DynCsState::Active);
    let tracker = ctl.channels()[0].tracker();
    assert_eq!(tracker.refused_count(), 5);
    assert!(ctl.channels()[0]
        .dyn_cs_diagnosis()
        .contains("dynCS: refused: tracking is already on"));
}

/// Runs a master channel (channel 1) and a tracking slave (channel 2) until `done` or a
/// watchdog of 20000 ticks, checking every tick with `each`.
fn run_pair(
    ctl: &mut Controller,
    memory: &hli::ImageMemory,
    mut each: impl FnMut(&Controller, u32) -> bool,
) {
    let view = CncView::new(memory);
    for tick in 0..20_000u32 {
        ctl.tick(&view);
        if each(ctl, tick) {
            return;
        }
    }
    panic!("watchdog: not done after 20000 ticks");
}

/// A master channel's FREEZE by its interface: `#CHANNEL INTERFACE OFF [DYN_CS]` while its
/// slave is ACTIVE holds the slave exactly where it was (the master moves 20 mm meanwhile);
/// ON again is taken over softly, ACTIVATING along the slave's FILTER (the smoothing ramp's
/// 100 ticks, its last ACTIVE on the master's position). Logged once each.
#[test]
fn a_master_channel_that_switches_its_interface_off_and_on_is_held_and_taken_over_softly() {
    let master = "#CHANNEL INTERFACE ON [DYN_CS]\n#TIME 0.3\n#CHANNEL INTERFACE OFF [DYN_CS]\n\
                  G1 X20 F6000\n#TIME 0.1\n#CHANNEL INTERFACE ON [DYN_CS]\n#TIME 1\nM30\n";
    let slave = "#TRACK CS ON [CH=1 FILTER=100]\n#TIME 3\nM30\n";
    let mut ctl = controller(vec![
        (cartesian("master"), master),
        (cartesian("slave"), slave),
    ]);
    let memory = image(2);
    let x = |ctl: &Controller| ctl.channels()[1].set_points()[0];
    let state = |ctl: &Controller| ctl.channels()[1].tracker().state();
    // Coupled in on the master at rest, then the master freezes.
    let mut held = None;
    let mut resumed_at = None;
    let mut ramp = Vec::new();
    run_pair(&mut ctl, &memory, |ctl, tick| {
        let master_x = ctl.channels()[0].set_points()[0];
        match (held, resumed_at) {
            (None, _) if master_x > 0.0 => {
                assert_eq!(state(ctl), DynCsState::Active, "tick {tick}");
                held = Some(x(ctl));
            }
            (Some(h), None) if state(ctl) == DynCsState::Activating => {
                resumed_at = Some(tick);
                ramp.push(x(ctl) - h);
            }
            (Some(h), None) => assert_eq!(x(ctl), h, "held while frozen, tick {tick}"),
            (Some(h), Some(_)) if state(ctl) == DynCsState::Activating => ramp.push(x(ctl) - h),
            _ => {}
        }
        resumed_at.is_some() && state(ctl) == DynCsState::Active
    });
    let h = held.expect("the master moved");
    assert_eq!(h, 0.0);
    // The ramp's last tick (k = 100) lands on the master and is ACTIVE.
    assert_eq!(ramp.len(), 99, "ACTIVATING through the filter's ticks");
    for (k, v) in ramp.iter().enumerate() {
        let expected = 20.0 * smooth_ramp((k + 1) as f64 / 100.0);
        assert!(
            (v - expected).abs() < 1e-9,
            "ramp tick {k}: {v} vs {expected}"
        );
    }
    assert_eq!(x(&ctl), 20.0);
    let log: Vec<_> = ctl.channels()[1].tracker().log().map(|(_, e)| *e).collect();
    let count = |pick: fn(&TrackEvent) -> bool| log.iter().filter(|e| pick(e)).count();
    assert_eq!(count(|e| matches!(e, TrackEvent::MasterFrozen)), 1);
    assert_eq!(count(|e| matches!(e, TrackEvent::MasterResumed)), 1);
}

/// A master channel that fails: it brakes (its slave follows the braking frame) and freezes
/// at rest; the slave holds there without failing itself. After the master's reset a new
/// program of the master publishes again and the slave takes it over softly.
#[test]
fn a_failing_master_channel_freezes_its_slave_which_resumes_after_the_masters_reset() {
    let master = "#CHANNEL INTERFACE ON [DYN_CS]\nG1 X10 F6000\n#CS ON [1, 0, 0, 0, 0, 0]\nM30\n";
    let slave = "#TRACK CS ON [CH=1 FILTER=100]\n#TIME 10\nM30\n";
    let mut ctl = controller(vec![
        (cartesian("master"), master),
        (cartesian("slave"), slave),
    ]);
    let memory = image(2);
    let x = |ctl: &Controller| ctl.channels()[1].set_points()[0];
    run_pair(&mut ctl, &memory, |ctl, _| {
        ctl.channels()[0].state() == RunState::Error && !ctl.channels()[0].settling()
    });
    let view = CncView::new(&memory);
    let held = x(&ctl);
    assert!(
        (held - 10.0).abs() < 1e-9,
        "on the master's last frame: {held}"
    );
    for _ in 0..200 {
        ctl.tick(&view);
        let s = &ctl.channels()[1];
        assert_ne!(s.state(), RunState::Error, "{:?}", s.error());
        assert_eq!(x(&ctl), held, "held");
    }
    assert!(ctl.channels()[1]
        .tracker()
        .log()
        .any(|(_, e)| matches!(e, TrackEvent::MasterFrozen)));
    // The master is reset and runs again: the slave takes its frame over along the filter.
    let m = ctl.channel_mut(0).unwrap();
    m.reset().unwrap();
    let again = "#CHANNEL INTERFACE ON [DYN_CS]\nG1 X30 F6000\n#TIME 1\nM30\n";
    m.start(cnc_core::channel::LoadedProgram::load("m", again, &m.config().axes.clone()).unwrap())
        .unwrap();
    run_pair(&mut ctl, &memory, |ctl, _| {
        let s = &ctl.channels()[1];
        assert_ne!(s.state(), RunState::Error, "{:?}", s.error());
        ctl.channels()[0].state() == RunState::Finished && s.tracker().state() == DynCsState::Active
    });
    assert!((x(&ctl) - 30.0).abs() < 1e-9, "{}", x(&ctl));
    assert!(ctl.channels()[1]
        .tracker()
        .log()
        .any(|(_, e)| matches!(e, TrackEvent::MasterResumed)));
}
