//! Channels in-process on a heap image: interpolation, the dynamic CS with a master channel
//! (the seed's example 3 geometry), the PLC as master through `MC_CONTROL_DYN_CS_UNIT`, and
//! the refusals that put tracking into ERROR.

use tests::channel_rig as support;

use cnc_core::channel::{Controller, LoadedProgram, RunState, MAX_CHANNELS};
use hli::enums::{DynCsCommand, DynCsState};
use hli::views::{CncView, PlcView};
use hli::{Bool, ImageMemory};
use kinematics::frame::offset_frame;
use kinematics::PoseWords;
use support::*;

#[test]
fn a_linear_block_reaches_its_target_within_feed_and_limits() {
    let mut ctl = controller(vec![(
        cartesian("c"),
        "G1 X100 Y50 F6000\nG91 X-10 Z5\nG0 G90 X0 Y0 Z0\nM30\n",
    )]);
    let memory = image(1);
    let mut last = [0.0f64; 3];
    let mut max_speed: f64 = 0.0;
    let mut first_block_end = None;
    run_until(
        &mut ctl,
        &memory,
        20_000,
        |ctl, tick| {
            let p = ctl.channels()[0].programmed();
            let d =
                ((p[0] - last[0]).powi(2) + (p[1] - last[1]).powi(2) + (p[2] - last[2]).powi(2))
                    .sqrt();
            if first_block_end.is_none() {
                max_speed = max_speed.max(d / CYCLE);
                if (p[0] - 100.0).abs() < 1e-12 && (p[1] - 50.0).abs() < 1e-12 {
                    first_block_end = Some(tick);
                }
            }
            last = [p[0], p[1], p[2]];
        },
        |ctl| ctl.channels()[0].state() == RunState::Finished,
    );
    assert!(first_block_end.is_some(), "X100 Y50 was reached exactly");
    assert!(
        max_speed <= 100.0 + 1e-6,
        "feed 6000 mm/min = 100 mm/s, ran {max_speed}"
    );
    assert!(max_speed > 99.0, "the block reached its feed: {max_speed}");
    let p = ctl.channels()[0].programmed();
    assert_eq!(&p[..3], &[0.0, 0.0, 0.0]);
}

/// Where example 3's slave stands relative to the master's tool (X=400 Y=700 C=-90).
fn slave_offset() -> nalgebra::Isometry3<f64> {
    offset_frame(
        &PoseWords {
            xyz: [400.0, 700.0, 0.0],
            abc: [0.0, 0.0, -90.0],
        },
        false,
    )
    .unwrap()
}

/// The seed's example 3 with our own programs: the master robot (channel 1) carries the
/// workpiece and publishes its tool frame; the slave (channel 2) stands at X=400 Y=700 C=-90
/// relative to it, tracks with SET_ZERO, puts its zero on the master's tool with `#CS` and holds
/// X0 Y0 Z0 there while the master moves.
#[test]
fn example_3_the_slave_tool_stays_on_the_moving_workpiece() {
    let master = "%master
#TRAFO [45]
#CHANNEL INTERFACE ON [DYN_CS]
#WAIT SYN [ID1]
G1 X680 Y40 Z560 F3000
G1 X600 Y-40 Z520 C170 F3000
G1 B10 F1200
#SIGNAL SYN [ID2 COUNT1]
M30
";
    let slave = "%slave
#TRAFO [45]
#CS ON [OFFS] [400, 700, 0, 0, 0, -90]
#TRACK CS ON [ID=1 SET_ZERO X=400 Y=700 C=-90 FILTER=0 WAIT]
#CS ON [V.G.TRACK_CS.X, V.G.TRACK_CS.Y, V.G.TRACK_CS.Z, V.G.TRACK_CS.A, -V.G.TRACK_CS.B, V.G.TRACK_CS.C]
G1 X0 Y0 Z0 A0 B0 C0 F3000
#SIGNAL SYN [ID1 COUNT1]
#WAIT SYN [ID2]
#TRACK CS OFF [FILTER=0]
#CS OFF
#CS OFF
M30
";
    let mut ctl = controller(vec![(robot("master"), master), (robot("slave"), slave)]);
    let memory = image(2);
    let offset = slave_offset();
    // The same offset turned 1 degree more about Z: the test must tell it apart.
    let off_by_a_degree = offset_frame(
        &PoseWords {
            xyz: [400.0, 700.0, 0.0],
            abc: [0.0, 0.0, -89.0],
        },
        false,
    )
    .unwrap();
    let mut worst_off_by_a_degree: f64 = 0.0;
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    let mut master_travel: f64 = 0.0;
    let mut last_master: Option<nalgebra::Vector3<f64>> = None;
    run_until(
        &mut ctl,
        &memory,
        60_000,
        |ctl, _| {
            let (m, s) = (&ctl.channels()[0], &ctl.channels()[1]);
            let master_tool = m.tool_pose();
            // Measure only while the slave holds the workpiece point (after its approach, before
            // the master signals the end).
            if s.tracker().state() == DynCsState::Active && !s.is_moving() && m.is_moving() {
                let slave_tool = s.tool_pose();
                let expected = offset * master_tool;
                let miss = (slave_tool.translation.vector - expected.translation.vector).norm();
                let turn = slave_tool.rotation.angle_to(&expected.rotation);
                worst = worst.max(miss);
                let wrong = off_by_a_degree * master_tool;
                worst_off_by_a_degree = worst_off_by_a_degree
                    .max((slave_tool.translation.vector - wrong.translation.vector).norm());
                assert!(turn < 1e-6, "orientation off by {turn} rad");
                checked += 1;
                if let Some(last) = last_master {
                    master_travel += (master_tool.translation.vector - last).norm();
                }
                last_master = Some(master_tool.translation.vector);
            }
        },
        |ctl| {
            ctl.channels()
                .iter()
                .all(|c| c.state() == RunState::Finished)
        },
    );
    assert!(checked > 1000, "the master moved for {checked} ticks");
    assert!(master_travel > 100.0, "the master moved {master_travel} mm");
    assert!(
        worst < 1e-3,
        "the slave's tool left the workpiece by {worst} mm"
    );
    // Against an offset 1 degree off, the same run misses by millimetres: the 1 um bound above
    // would catch it (about 806 mm from the slave's base, 1 degree is 14 mm).
    assert!(
        worst_off_by_a_degree > 1.0,
        "a 1 degree error in the offset went unseen: {worst_off_by_a_degree} mm"
    );
}

/// The states of a complete switch-on and switch-off, in order.
const SWITCHED_ON_AND_OFF: [DynCsState; 4] = [
    DynCsState::Activating,
    DynCsState::Active,
    DynCsState::Deactivating,
    DynCsState::Inactive,
];

/// The PLC as master: the program switches tracking on with `ID=0 FILTER=50`, the "PLC"
/// (this test, through its view) enables the unit and commands a moving translation. The
/// channel couples in softly (state ACTIVATING, per-tick step bounded by the filter), then
/// follows the commanded translation exactly (axis-specific, no transformation).
#[test]
fn plc_as_master_couples_in_softly_then_follows_exactly() {
    let mut ctl = controller(vec![(
        cartesian("slave"),
        "#TRACK CS ON [ID=0 FILTER=50 WAIT]\nG1 X10 F600\n#TRACK CS OFF [FILTER=50 WAIT]\nM30\n",
    )]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    // 20 mm in X at switch-on, then moving 1 um per tick in Y.
    plc.dyn_cs_command(0)
        .unwrap()
        .try_send(&cs([200_000, 0, 0]))
        .unwrap();
    let view = CncView::new(&memory);
    let mut states = Vec::new();
    let mut last_x = 0.0;
    let mut max_step: f64 = 0.0;
    let mut y_um = 0;
    for tick in 0..20_000u32 {
        if plc
            .dyn_cs_command(0)
            .unwrap()
            .try_send(&cs([200_000, y_um * 10, 0]))
            .is_ok()
        {
            y_um += 1;
        }
        ctl.tick(&view);
        let ch = &ctl.channels()[0];
        assert_ne!(ch.state(), RunState::Error, "{:?}", ch.error());
        let state = plc.dyn_cs_state(0).unwrap().unwrap();
        if states.last() != Some(&state) {
            states.push(state);
        }
        let set = ch.set_points();
        let programmed = ch.programmed();
        let x_comp = set[0] - programmed[0];
        max_step = max_step.max((x_comp - last_x).abs());
        last_x = x_comp;
        if state == DynCsState::Active {
            let y_comp = set[1] - programmed[1];
            // The command taken this tick is the one sent before it; follow it to 1 um.
            let commanded_y = f64::from((y_um - 1) * 10) / 10_000.0;
            assert!((x_comp - 20.0).abs() < 1e-9, "tick {tick}: x comp {x_comp}");
            assert!(
                (y_comp - commanded_y).abs() < 1e-3,
                "tick {tick}: y {y_comp} vs {commanded_y}"
            );
        }
        if ch.state() == RunState::Finished {
            break;
        }
    }
    assert_eq!(states, SWITCHED_ON_AND_OFF);
    // 20 mm over 50 ticks, the smoothing ramp's steepest slope 15/8 at the middle: at most
    // 0.75 mm in one tick; the Y motion adds 1 um per tick.
    assert!(
        max_step <= 20.0 / 50.0 * 15.0 / 8.0 + 1e-9,
        "largest per-tick step {max_step}"
    );
    assert!(max_step > 0.74);
    assert_eq!(ctl.channels()[0].state(), RunState::Finished);
    let diagnosis = ctl.channels()[0].dyn_cs_diagnosis();
    assert!(
        diagnosis.contains("dynCS: cmd=ON PLC=1 NO FILTER=50 WAIT=1"),
        "{diagnosis}"
    );
    assert!(
        diagnosis.contains("dynCS: is off = DYN_CS_SYNC_INACTIVE"),
        "{diagnosis}"
    );
    // 20 history entries by default (P-STUP-00074).
    let history = diagnosis
        .lines()
        .filter(|l| l.contains(") 3 (") || l.contains(") 2 ("))
        .count();
    assert_eq!(history, 20, "{diagnosis}");
}

/// A master channel that never publishes is waited for (ACTIVATING), not refused: the slave
/// does not move, takes no compensation, and its program goes on (no WAIT).
#[test]
fn tracking_a_channel_without_interface_waits_for_it() {
    let mut ctl = controller(vec![
        (cartesian("quiet"), "G1 X5 F600\nM30\n"),
        (cartesian("slave"), "#TRACK CS ON [CH=1]\nG1 X1 F600\nM30\n"),
    ]);
    let memory = image(2);
    let view = CncView::new(&memory);
    for _ in 0..2000 {
        ctl.tick(&view);
    }
    let (quiet, slave) = (&ctl.channels()[0], &ctl.channels()[1]);
    assert_eq!(quiet.state(), RunState::Finished);
    assert_eq!(slave.state(), RunState::Finished, "{:?}", slave.error());
    assert_eq!(slave.tracker().state(), DynCsState::Activating);
    assert_eq!(slave.set_points()[0], 1.0, "no compensation while waiting");
}

#[test]
fn switching_on_twice_is_an_error_and_keeps_the_setpoint() {
    let mut ctl = controller(vec![(
        cartesian("slave"),
        "#TRACK CS ON [ID=0 FILTER=0]\n#TRACK CS ON [ID=0 FILTER=0]\nG1 X1 F600\nM30\n",
    )]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    plc.dyn_cs_command(0)
        .unwrap()
        .try_send(&cs([10_000, 0, 0]))
        .unwrap();
    let view = CncView::new(&memory);
    for _ in 0..100 {
        ctl.tick(&view);
    }
    let ch = &ctl.channels()[0];
    assert_eq!(ch.state(), RunState::Error);
    assert!(ch.error().unwrap().to_string().contains("already on"));
    assert_eq!(ch.error().unwrap().line, 2);
    assert_eq!(ch.tracker().state(), DynCsState::Error);
}

/// One tick of a single-channel run with the PLC as master.
#[derive(Debug, Clone, Copy)]
struct PlcTrackingTick {
    state: DynCsState,
    /// Set-point minus programmed value, X and Y (mm).
    applied: [f64; 2],
    /// `position_dyncs_r` of X (mm).
    dyncs_x: f64,
    /// The PLC's Y translation the channel took this tick (mm).
    master_y: f64,
}

/// Runs `program` on a Cartesian channel while the PLC enables the unit, stands its frame at
/// X=20 mm and moves it 1 um per tick in Y; returns the channel and every tick.
fn track_plc(program: &str) -> (Controller, Vec<PlcTrackingTick>) {
    let mut ctl = controller(vec![(cartesian("slave"), program)]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    let dyncs_x =
        hli::access::Leaf::resolve("gpCh[0]^bahn_state.coord_r[0].position_dyncs_r").unwrap();
    let view = CncView::new(&memory);
    let mut ticks = Vec::new();
    let mut y_um = 0;
    for _ in 0..20_000u32 {
        let sent = plc
            .dyn_cs_command(0)
            .unwrap()
            .try_send(&cs([200_000, y_um * 10, 0]))
            .is_ok();
        let master_y = f64::from(y_um) / 1000.0;
        y_um += i32::from(sent);
        ctl.tick(&view);
        let ch = &ctl.channels()[0];
        assert_ne!(ch.state(), RunState::Error, "{:?}", ch.error());
        let (set, programmed) = (ch.set_points(), ch.programmed());
        ticks.push(PlcTrackingTick {
            state: plc.dyn_cs_state(0).unwrap().unwrap(),
            applied: [set[0] - programmed[0], set[1] - programmed[1]],
            dyncs_x: dyncs_x.read(&memory).as_f64() / 10_000.0,
            master_y,
        });
        if ch.state() == RunState::Finished {
            return (ctl, ticks);
        }
    }
    panic!("watchdog: the program did not finish in 20000 ticks");
}

/// RELATIVE: the displacement counts from the master frame at switch-on, so switching on
/// without a filter does not move the set-point, and the slave then follows only what the
/// master moved since. Without RELATIVE the same switch-on jumps onto the master's 20 mm.
#[test]
fn relative_tracking_follows_the_master_from_where_it_stood_at_switch_on() {
    let program = "G1 X5 F600\n#TRACK CS ON [ID=0 RELATIVE FILTER=0]\nG1 X10 F600\n\
                   #TRACK CS OFF [FILTER=0]\nM30\n";
    let (ctl, ticks) = track_plc(program);
    let on = ticks
        .iter()
        .position(|t| t.state != DynCsState::Inactive)
        .unwrap();
    let y0 = ticks[on].master_y;
    let mut active = 0;
    for t in ticks.iter().filter(|t| t.state == DynCsState::Active) {
        assert!(t.applied[0].abs() < 1e-9, "no X jump: {:?}", t);
        assert!(
            (t.applied[1] - (t.master_y - y0)).abs() < 1e-9,
            "Y follows the master's motion since switch-on: {:?} (y0 {y0})",
            t
        );
        active += 1;
    }
    assert!(active > 500, "tracked for {active} ticks");
    assert!(
        ticks.last().unwrap().applied[1] == 0.0,
        "switched off: compensation released"
    );
    // RELATIVE hands nothing to the program (that is SET_ZERO's job).
    assert_eq!(ctl.channels()[0].tracker().zero_values(), [0.0; 6]);
    let diagnosis = ctl.channels()[0].dyn_cs_diagnosis();
    assert!(
        diagnosis.contains("FILTER=0 WAIT=0 RELATIVE"),
        "{diagnosis}"
    );

    // The same switch-on without RELATIVE takes the master's absolute frame at once.
    let (_, absolute) = track_plc(&program.replace(" RELATIVE", ""));
    let first_active = absolute
        .iter()
        .find(|t| t.state == DynCsState::Active)
        .unwrap();
    assert!(
        (first_active.applied[0] - 20.0).abs() < 1e-9,
        "{first_active:?}"
    );
}

/// SIMU: tracking runs through its states and shows the tracked pose in `position_dyncs_r`
/// and the history, but the set-points stay on the programmed path.
#[test]
fn simulated_tracking_shows_the_compensation_without_moving_the_axes() {
    let (ctl, ticks) = track_plc(
        "#TRACK CS ON [ID=0 SIMU FILTER=10 WAIT]\nG1 X10 F600\n#TRACK CS OFF [FILTER=10 WAIT]\nM30\n",
    );
    let mut states: Vec<DynCsState> = Vec::new();
    for t in &ticks {
        if states.last() != Some(&t.state) {
            states.push(t.state);
        }
        assert_eq!(t.applied, [0.0, 0.0], "SIMU never moves the axes: {t:?}");
    }
    assert_eq!(states, SWITCHED_ON_AND_OFF);
    // While ACTIVE, the display shows the programmed X shifted by the master's 20 mm.
    let programmed_x_end = 10.0;
    let last_active = ticks
        .iter()
        .rev()
        .find(|t| t.state == DynCsState::Active)
        .unwrap();
    assert!(
        (last_active.dyncs_x - (programmed_x_end + 20.0)).abs() < 1e-3,
        "{last_active:?}"
    );
    let diagnosis = ctl.channels()[0].dyn_cs_diagnosis();
    assert!(diagnosis.contains(" SIMU\n"), "{diagnosis}");
    // The history's CS translation is the compensation the channel did not apply.
    assert!(diagnosis.contains("(200000,"), "{diagnosis}");
}

/// SIMU on a robot: the joints (and the real tool) stay on the untracked path.
#[test]
fn simulated_tracking_on_a_robot_keeps_the_joints_on_the_programmed_pose() {
    let program = |simu: &str| {
        format!("#TRAFO [45]\n#TRACK CS ON [ID=0 FILTER=0 {simu}]\nG1 X640 Y10 Z530 F3000\nM30\n")
    };
    let run = |src: &str| {
        let mut ctl = controller(vec![(robot("r"), src)]);
        let memory = image(1);
        let plc = PlcView::new(&memory);
        plc.set_dyn_cs_enabled(0, true).unwrap();
        plc.dyn_cs_command(0)
            .unwrap()
            .try_send(&cs([50_000, 0, 0]))
            .unwrap();
        run_until(
            &mut ctl,
            &memory,
            20_000,
            |_, _| {},
            |ctl| ctl.channels()[0].state() == RunState::Finished,
        );
        let ch = &ctl.channels()[0];
        (ch.set_points().to_vec(), ch.tool_pose().translation.vector)
    };
    let (plain_joints, plain_tool) =
        run(&program("").replace("#TRACK CS ON [ID=0 FILTER=0 ]\n", ""));
    let (simu_joints, simu_tool) = run(&program("SIMU"));
    let (_, tracked_tool) = run(&program(""));
    assert_eq!(simu_joints, plain_joints);
    assert!((simu_tool - plain_tool).norm() < 1e-9);
    assert!(
        ((tracked_tool - plain_tool).x - 5.0).abs() < 1e-6,
        "without SIMU the tool moves 5 mm: {:?}",
        tracked_tool - plain_tool
    );
}

/// LOG_FILE names the file the process writes the diagnosis to after the run; the channel
/// keeps the name (the tick does no IO). A LOG_FILE without a quoted name is refused at load.
#[test]
fn log_file_is_kept_for_the_process_and_needs_a_quoted_name() {
    let (ctl, _) = track_plc(
        "#TRACK CS ON [ID=0 FILTER=0 LOG_FILE=\"slave-dyncs.log\"]\nG1 X1 F600\n#TRACK CS OFF\nM30\n",
    );
    assert_eq!(ctl.channels()[0].log_file(), Some("slave-dyncs.log"));
    let axes: Vec<String> = ["X", "Y", "Z"].map(String::from).to_vec();
    for bad in ["LOG_FILE", "LOG_FILE=3", "LOG_FILE=\"  \""] {
        let src = format!("#TRACK CS ON [ID=0 {bad}]\nM30\n");
        let err = LoadedProgram::load("log.nc", &src, &axes).unwrap_err();
        assert!(err.to_string().starts_with("log.nc:1:"), "{bad}: {err}");
        assert!(err.to_string().contains("LOG_FILE"), "{bad}: {err}");
    }
}

#[test]
fn programs_with_errors_are_refused_at_load() {
    let axes: Vec<String> = ["X", "Y", "Z"].map(String::from).to_vec();
    let err = LoadedProgram::load("bad.nc", "G1 X1 F100\nG1 Q5\n", &axes).unwrap_err();
    assert!(err.to_string().starts_with("bad.nc:2:"), "{err}");
    assert_eq!(MAX_CHANNELS, 12);
}

#[test]
fn unmatched_control_statements_are_refused_at_load_where_they_stand() {
    let axes: Vec<String> = ["X", "Y", "Z"].map(String::from).to_vec();
    let err = LoadedProgram::load("flow.nc", "G1 X1 F100\n$IF 1\nX2\n$ENDWHILE\n", &axes)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("flow.nc:4:1: error: $ENDWHILE without a matching $WHILE"),
        "{err}"
    );
    assert!(
        err.contains("flow.nc:2:1: error: $IF without $ENDIF"),
        "{err}"
    );
}

#[test]
fn branches_and_loops_follow_the_jump_table_matched_at_load() {
    // $IF 0 takes the $ELSE branch; the $WHILE 0 body never runs; the nested $IF 1 inside the
    // taken branch runs its first part and skips its $ELSE.
    let program = "$IF 0\nG1 X10 F6000\n$ELSE\n$IF 1\nG1 X20 F6000\n$ELSE\nG1 X30 F6000\n$ENDIF\n\
                   $ENDIF\n$WHILE 0\nG1 Y99 F6000\n$ENDWHILE\nG1 Z5 F6000\nM30\n";
    let mut ctl = controller(vec![(cartesian("c"), program)]);
    let memory = image(1);
    let mut lines = std::collections::BTreeSet::new();
    run_until(
        &mut ctl,
        &memory,
        20_000,
        |c, _| {
            lines.insert(c.channels()[0].line());
        },
        |c| c.channels()[0].state() == RunState::Finished,
    );
    let p = ctl.channels()[0].programmed();
    assert_eq!([p[0], p[1], p[2]], [20.0, 0.0, 5.0]);
    // Lines 2 (X10), 7 (X30) and 11 (Y99) never ran; 5 (X20) and 13 (Z5) did.
    for skipped in [2, 7, 11] {
        assert!(!lines.contains(&skipped), "line {skipped} ran: {lines:?}");
    }
    assert!(lines.contains(&5) && lines.contains(&13), "{lines:?}");
}

#[test]
fn program_state_and_m_function_announcement_reach_the_plc_through_the_stages() {
    use hli::enums::ProgramState;
    use hli::layout::HliMFunctionAck;
    let mut ctl = controller(vec![(
        cartesian("c"),
        "G1 X5 F6000\nM100\nG1 X0 F6000\nM30\n",
    )]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    let state = |m: &ImageMemory| PlcView::new(m).program_state(0).unwrap().unwrap();
    let view = CncView::new(&memory);
    ctl.tick(&view);
    assert_eq!(state(&memory), ProgramState::Running);
    // Run until the announcement appears; the channel then waits and says so.
    let mut request = None;
    for _ in 0..10_000 {
        ctl.tick(&view);
        if let Some(r) = plc.m_function_request(0).unwrap().try_take().unwrap() {
            request = Some(r);
            break;
        }
    }
    let request = request.expect("M100 announced");
    assert_eq!((request.m_code, request.block_nr), (100, 2));
    for _ in 0..5 {
        ctl.tick(&view);
        assert_eq!(state(&memory), ProgramState::Waiting);
        assert_eq!(ctl.channels()[0].programmed()[0], 5.0);
    }
    // A stale acknowledge is consumed and ignored; the right one releases the channel.
    let ack = |id| {
        plc.m_function_ack(0)
            .unwrap()
            .try_send(&HliMFunctionAck {
                m_code: 100,
                request_id: id,
            })
            .unwrap()
    };
    ack(request.request_id + 7);
    ctl.tick(&view);
    assert_eq!(state(&memory), ProgramState::Waiting);
    ack(request.request_id);
    run_until(
        &mut ctl,
        &memory,
        10_000,
        |_, _| {},
        |c| c.channels()[0].state() == RunState::Finished,
    );
    ctl.tick(&view);
    assert_eq!(state(&memory), ProgramState::Finished);
    assert_eq!(ctl.channels()[0].m_functions_acked(), 1);
}

/// Example 3's set-up with an arc: the slave circles the workpiece point (radius 10 mm, in the
/// workpiece's own coordinates) while the master carries the workpiece; the slave's tool stays
/// on that circle on the moving workpiece.
#[test]
fn an_arc_under_track_cs_stays_on_its_circle_on_the_moving_workpiece() {
    let master = "%master
#TRAFO [45]
#CHANNEL INTERFACE ON [DYN_CS]
#WAIT SYN [ID1]
G1 X680 Y40 Z560 F1500
G1 X600 Y-40 Z520 F1500
#SIGNAL SYN [ID2 COUNT1]
M30
";
    let slave = "%slave
#TRAFO [45]
#CS ON [OFFS] [400, 700, 0, 0, 0, -90]
#TRACK CS ON [ID=1 SET_ZERO X=400 Y=700 C=-90 FILTER=0 WAIT]
#CS ON [V.G.TRACK_CS.X, V.G.TRACK_CS.Y, V.G.TRACK_CS.Z, V.G.TRACK_CS.A, -V.G.TRACK_CS.B, V.G.TRACK_CS.C]
G1 X10 Y0 Z0 A0 B0 C0 F3000
#SIGNAL SYN [ID1 COUNT1]
$WHILE 1
G3 X-10 Y0 I-10 J0 F3000
G3 X10 Y0 R10
$ENDWHILE
";
    let mut ctl = controller(vec![(robot("master"), master), (robot("slave"), slave)]);
    let memory = image(2);
    let offset = slave_offset();
    let (mut checked, mut worst, mut turned) = (0, 0.0f64, 0.0f64);
    run_until(
        &mut ctl,
        &memory,
        60_000,
        |ctl, _| {
            let (m, s) = (&ctl.channels()[0], &ctl.channels()[1]);
            if s.tracker().state() == DynCsState::Active && m.is_moving() && s.is_moving() {
                // The slave's tool in the workpiece's coordinates (the master's tool frame).
                let workpiece = offset * m.tool_pose();
                let local = workpiece.inverse() * s.tool_pose();
                let p = local.translation.vector;
                worst = worst.max((p.x.hypot(p.y) - 10.0).abs()).max(p.z.abs());
                turned = turned.max(-p.y);
                checked += 1;
            }
        },
        |ctl| ctl.channels()[0].state() == RunState::Finished,
    );
    assert!(
        checked > 1000,
        "{checked} ticks on the arc while the master moved"
    );
    assert!(turned > 9.9, "the arc went round: lowest y {}", -turned);
    assert!(
        worst < 1e-3,
        "off the circle on the workpiece by {worst} mm"
    );
}

/// `f_wait` of a PLC transition holds the channel's program like `WAIT` of `#TRACK CS`: the
/// block under way runs on, the next one starts only once the switching has finished.
#[test]
fn f_wait_of_a_plc_transition_holds_the_next_block_until_the_switching_is_done() {
    // (tick the state turned ACTIVE, tick the second block started)
    let run = |f_wait: Bool| -> (u32, u32) {
        let mut ctl = controller(vec![(cartesian("slave"), "G1 X1 F600\nG1 X2 F600\nM30\n")]);
        let memory = image(1);
        let plc = PlcView::new(&memory);
        plc.set_dyn_cs_enabled(0, true).unwrap();
        plc.dyn_cs_command(0)
            .unwrap()
            .try_send(&cs([0, 0, 0]))
            .unwrap();
        let params = transition(400, f_wait);
        plc.dyn_cs_transition(0)
            .unwrap()
            .try_send(DynCsCommand::Activate, &params)
            .unwrap();
        let view = CncView::new(&memory);
        let (mut active, mut second) = (None, None);
        for tick in 0..20_000u32 {
            ctl.tick(&view);
            let ch = &ctl.channels()[0];
            assert_ne!(ch.state(), RunState::Error, "{:?}", ch.error());
            if active.is_none() && plc.dyn_cs_state(0).unwrap().unwrap() == DynCsState::Active {
                active = Some(tick);
            }
            if second.is_none() && ch.programmed()[0] > 1.0 {
                second = Some(tick);
            }
            if let (Some(a), Some(b)) = (active, second) {
                return (a, b);
            }
        }
        panic!("watchdog: ACTIVE at {active:?}, second block at {second:?}");
    };
    let (active, second) = run(Bool::TRUE);
    // The first millimetre takes about 110 ticks, the switching 400: the second block waits.
    assert!(
        second > active,
        "second block at {second}, ACTIVE at {active}"
    );
    let (active, second) = run(Bool::FALSE);
    assert!(
        second < active,
        "without f_wait: second block at {second}, ACTIVE at {active}"
    );
}
