//! The CNC tick of twelve tracking robots (interpreter in an endless loop, interpolation,
//! kinematic transformation both ways, dynamic CS, HLI outputs, axis images) allocates nothing
//! once the programs run.

use cnc_app::scenario::fleet::{running, running_with, Moves};

use crate::counting_alloc;
use counting_alloc::allocations;

#[test]
fn twelve_tracking_robots_tick_without_allocating() {
    // Start-up: programs begin, tracking switches on, the loops run once.
    let mut run = running(12, 3000).unwrap();
    let before = allocations();
    for _ in 0..5000 {
        run.machine.tick(&run.memory);
    }
    let made = allocations() - before;
    assert_eq!(made, 0, "{made} allocations in 5000 ticks of 12 channels");
    // The robots moved: the loops ran through the measured ticks.
    assert!(run
        .machine
        .controller()
        .channels()
        .iter()
        .all(|c| c.is_moving()));
}

/// The same fleet going round a triangle in continuous path: decoding ahead, corner curves,
/// the backward sweep, the joint caps under #TRAFO and every piece's profile allocate nothing.
#[test]
fn twelve_robots_in_continuous_path_tick_without_allocating() {
    let mut run = running_with(12, None, Moves::TriangleContour, 3000).unwrap();
    let before = allocations();
    for _ in 0..5000 {
        run.machine.tick(&run.memory);
    }
    let made = allocations() - before;
    assert_eq!(made, 0, "{made} allocations in 5000 ticks of 12 channels");
    let channels = run.machine.controller().channels();
    assert!(channels.iter().all(|c| c.is_moving()));
    // The loops ran through several corners in the measured ticks.
    assert!(channels.iter().all(|c| c.blocks_executed() > 6));
}

/// A robot that switches tracking on and off, with every option, in an endless loop: the
/// blocks are decoded in the tick, so decoding a `#TRACK CS`, `#CS`, `G92` or synchronisation
/// block must not allocate either.
const SWITCHING: &str = "%switching
#TRAFO [45]
$WHILE 1
#TRACK CS ON [ID=0 FILTER=20 WAIT KIN_BASE RELATIVE X=1 Y=2 Z=3 A=0.1 B=0.2 C=0.3 LOG_FILE=\"switching.log\"]
G1 X640 Y10 Z530 F3000
#TRACK CS OFF [WAIT]
#TRACK CS ON [ID=0 SET_ZERO FILTER=0 OPTION=1 ROT_TRANS SIMU]
#TRACK CS ABS
G1 X630 Y-10 Z530 F3000
#TRACK CS OFF [FILTER=5 WAIT]
G92 X0 Y0 Z0
#SIGNAL SYN [ID1 COUNT1]
#WAIT SYN [ID1]
#FLUSH WAIT
#CS ON [10, 0, 0, 0, 0, 5]
G1 X635 Y0 Z530 F3000
#CS OFF
$ENDWHILE
";

#[test]
fn switching_tracking_on_and_off_decodes_without_allocating() {
    use cnc_app::scenario::file::Scenario;
    use cnc_app::scenario::machine::InProcess;
    use hli::enums::DynCsState;
    let toml = "cycle_ms = 1.0\n[[channel]]\nname = \"switcher\"\n\
        axes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\n\
        kinematics = { id = 45, preset = \"kr6r900sixx\" }\n\
        start = [0.0, -60.0, 90.0, 0.0, 60.0, 0.0]\nprogram = \"switching.nc\"\n";
    let scenario = Scenario::parse("switching", toml, |file| {
        Ok((std::path::PathBuf::from(file), SWITCHING.to_string()))
    })
    .unwrap();
    let mut run = InProcess::new(&scenario, 0).unwrap();
    cnc_app::scenario::fleet::plc_setup(&hli::views::PlcView::new(&run.memory));
    // One pass of the loop first (the first pass may size buffers).
    for _ in 0..3000 {
        run.machine.tick(&run.memory);
    }
    let before = allocations();
    let mut switched = 0;
    let mut last = DynCsState::Inactive;
    for _ in 0..6000 {
        run.machine.tick(&run.memory);
        let state = run.machine.controller().channels()[0].tracker().state();
        if state != last {
            switched += 1;
            last = state;
        }
    }
    let made = allocations() - before;
    let channel = &run.machine.controller().channels()[0];
    assert!(channel.error().is_none(), "{:?}", channel.error());
    assert!(switched >= 8, "only {switched} state changes in 6000 ticks");
    assert_eq!(made, 0, "{made} allocations in 6000 ticks of switching");
}

/// The whole machine tick: a channel looping moves on PT2 drives, a gear engine driving a
/// single axis from it, a second single axis moving under MC_MoveVelocity-like commands, and
/// a PLC timeline cycling against the same image.
#[test]
fn the_machine_tick_with_single_axes_an_engine_and_a_plc_allocates_nothing() {
    use cnc_app::scenario::file::Scenario;
    use cnc_app::scenario::machine::InProcess;
    use hli::calls::axis::AxisCommandCall;
    let toml = "cycle_ms = 1.0\n[[channel]]\nname = \"portal\"\n\
        axes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprogram = \"loop.nc\"\n\
        drive = { model = \"pt2\", frequency_hz = 80.0, damping = 0.9 }\n\
        [[axis]]\nname = \"Follower\"\npower = true\n\
        [[axis]]\nname = \"Spindle\"\nkind = \"rotary\"\npower = true\n\
        drive = { model = \"pt1\", t1_ms = 2.0 }\n\
        [[gear]]\nmaster = \"portal.X\"\nslave = \"Follower\"\nratio = -0.5\n\
        [plc]\ntimeline = \"plc.toml\"\n";
    let program = "%loop\n$WHILE 1\nG1 X200 Y20 F12000\nG1 X0 Y0 F12000\n$ENDWHILE\n";
    let timeline = "[[step]]\nrepeat = true\nwhen = \"gpAx[0]^lr_state.command_velocity_r > 0\"\n\
        set = { \"gpCh[0]^channel_mc_control.dyn_cs.enable_w\" = false }\n";
    let s = Scenario::parse("alloc.toml", toml, |f| {
        let text = if f == "loop.nc" { program } else { timeline };
        Ok((std::path::PathBuf::from(f), text.to_string()))
    })
    .unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    for _ in 0..500 {
        run.step(s.cycle_s);
    }
    let spindle = run.machine.channel_axes() + 1;
    let call = AxisCommandCall::move_velocity(1, [90.0, 900.0, 900.0, 9000.0]);
    run.machine
        .axes_mut()
        .axis_mut(spindle)
        .unwrap()
        .command(&call)
        .expect("the spindle runs");
    for _ in 0..500 {
        run.step(s.cycle_s);
    }
    // The PLC also holds the feed and changes the override now and then: each change
    // re-targets the path's generator, which must not allocate either.
    let (mut held_ticks, mut changes) = (0, 0);
    let before = allocations();
    for i in 0..5000u32 {
        if i % 150 == 0 {
            let hold = (i / 150) % 3 == 1;
            let feed = if (i / 150) % 2 == 0 { 700 } else { 1300 };
            let value = hli::views::PathOverride {
                feed_permille: feed,
                rapid_permille: 1000,
                feed_hold: hold,
            };
            hli::views::PlcView::new(&run.memory)
                .set_path_override(0, value)
                .unwrap();
            changes += 1;
        }
        run.step(s.cycle_s);
        let plc = hli::views::PlcView::new(&run.memory);
        held_ticks += u32::from(plc.feed_override_applied(0).unwrap() == 0);
    }
    let made = allocations() - before;
    assert_eq!(
        made, 0,
        "{made} allocations in 5000 machine ticks and PLC cycles"
    );
    assert!(changes > 30 && held_ticks > 1000, "{changes} {held_ticks}");
    // Everything moved in the measured ticks.
    let axes = run.machine.axes();
    let follower = axes.axis(run.machine.channel_axes()).unwrap();
    assert!(follower.coupling().is_some() && follower.error().is_none());
    assert!(axes.axis(spindle).unwrap().setpoint().velocity > 89.0);
    assert!(run.timeline.as_ref().unwrap().records()[0].fired > 1000);
}

/// Runs `program` on a six-axis Cartesian channel: 200 ticks to start, then counts the
/// allocations of the 3000 ticks in which the program fails (the error kept as values, the
/// guard latching and holding the axes). Returns the error and the allocations.
fn fail_in_the_tick(program: &str) -> (cnc_core::channel::ChannelError, usize) {
    use cnc_app::scenario::file::Scenario;
    use cnc_app::scenario::machine::InProcess;
    use cnc_core::channel::RunState;
    let toml = "cycle_ms = 1.0\n[[channel]]\nname = \"failing\"\n\
        axes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprogram = \"fail.nc\"\n";
    let program = program.to_string();
    let scenario = Scenario::parse("failing", toml, |file| {
        Ok((std::path::PathBuf::from(file), program.clone()))
    })
    .expect("the program passes the check at load");
    let mut run = InProcess::new(&scenario, 0).unwrap();
    for _ in 0..200 {
        run.machine.tick(&run.memory);
    }
    let running = run.machine.controller().channels()[0].state();
    assert_eq!(
        running,
        RunState::Running,
        "the program runs before it fails"
    );
    let before = allocations();
    for _ in 0..3000 {
        run.machine.tick(&run.memory);
    }
    let made = allocations() - before;
    let channel = &run.machine.controller().channels()[0];
    assert_eq!(channel.state(), RunState::Error);
    (*channel.error().expect("the channel failed"), made)
}

/// A division by zero in a block the check at load cannot reach: the `$IF` reads a machine
/// value, and on its own the block's P1 has no value yet. At run time the channel reaches it
/// after a move and fails in the tick.
#[test]
fn a_division_by_zero_at_run_time_fails_the_channel_without_allocating() {
    use cnc_core::channel::ChannelFault;
    use cnc_core::nc::decode::DecodeError;
    use cnc_core::nc::eval::EvalError;
    use cnc_core::nc::interp::ProgramFault;
    let program =
        "%fail\nP1 = 0\nG1 X100 F6000\n$IF V.G.TRACK_CS.X < 1\nP2 = 10 / P1\n$ENDIF\nM30\n";
    let (error, made) = fail_in_the_tick(program);
    assert_eq!(
        error.fault,
        ChannelFault::Program(ProgramFault::Decode(DecodeError::Eval(
            EvalError::DivisionByZero
        )))
    );
    assert_eq!(error.to_string(), "division by zero");
    assert_eq!(error.line, 5, "the line of the failing block");
    assert_eq!(made, 0, "{made} allocations while the channel failed");
}

/// A variable read before it is assigned, in a motion block reached only at run time.
#[test]
fn an_unassigned_variable_at_run_time_fails_the_channel_without_allocating() {
    let program = "%fail\nG1 X100 F6000\n$IF V.G.TRACK_CS.X < 1\nG1 X=V.P.DEPTH\n$ENDIF\nM30\n";
    let (error, made) = fail_in_the_tick(program);
    assert_eq!(
        error.to_string(),
        "variable \"V.P.DEPTH\" is read before it is assigned"
    );
    assert_eq!(error.line, 4, "the line of the failing block");
    assert_eq!(made, 0, "{made} allocations while the channel failed");
}

/// `#TRACK CS ON` to a channel the controller does not have: refused when the block runs
/// (the check at load does not know the controller), the tracking goes to ERROR.
#[test]
fn a_tracking_refused_at_run_time_fails_the_channel_without_allocating() {
    let program = "%fail\nG1 X100 F6000\n#TRACK CS ON [CH=5]\nM30\n";
    let (error, made) = fail_in_the_tick(program);
    assert_eq!(error.id, hli::enums::ChannelErrorId::Tracking);
    assert!(error.to_string().starts_with("#TRACK CS ON: "), "{error}");
    assert_eq!(error.line, 3, "the line of the failing block");
    assert_eq!(made, 0, "{made} allocations while the channel failed");
}

/// The PLC's channel commands, taken in the tick, on a tracking robot among others: feed hold
/// and resume, single block, stop (tracking switched off softly), reset, start, mode and the
/// refusals allocate nothing in the tick; loading and starting a program happen between ticks
/// (`serve_channels`, not counted).
#[test]
fn channel_commands_are_taken_in_the_tick_without_allocating() {
    use hli::enums::{ChannelCommand as C, ChannelCommandState};
    use hli::layout::HliChannelCommand;
    use hli::views::PlcView;
    let mut run = running(2, 3000).unwrap();
    let commands = [
        (C::FeedHold, 0),
        (C::Resume, 0),
        (C::SingleBlock, 1),
        (C::SingleBlock, 0),
        (C::Stop, 0),
        (C::Mode, 1),
        (C::Start, 0),
        (C::Mode, 0),
        (C::Reset, 0),
        (C::Start, 0),
        (C::Select, 0),
    ];
    let mut made = 0;
    for (k, (command, value)) in commands.into_iter().enumerate() {
        let id = k as u32 + 1;
        let c = HliChannelCommand {
            command_id: id,
            command: command.raw(),
            start_line: 0,
            value,
            program: [0; 64],
        };
        let plc = PlcView::new(&run.memory);
        plc.gp_ch(1)
            .unwrap()
            .channel_command()
            .try_send(&c)
            .unwrap();
        for _ in 0..1500 {
            let before = allocations();
            run.machine.tick(&run.memory);
            made += allocations() - before;
            run.machine.serve_channels();
        }
        let s = PlcView::new(&run.memory)
            .gp_ch(1)
            .unwrap()
            .channel_control_state();
        assert_eq!(s.command_id, id, "{command:?} taken");
        assert_ne!(
            s.command_state,
            ChannelCommandState::Busy.raw(),
            "{command:?} answered"
        );
    }
    assert_eq!(
        made, 0,
        "{made} allocations in the ticks that took the commands"
    );
}
