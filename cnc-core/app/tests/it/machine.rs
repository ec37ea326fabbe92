//! The machine tick: channel axes on the axis layer, single axes and an engine (gears) in one
//! tick; scenario `[[axis]]` and `[[gear]]` tables, refused with file, key and reason.

use cnc_app::scenario::{InProcess, Scenario, ScenarioError};
use hli::enums::CouplingState;
use hli::layout::{HliAxis, HliAxisLrState};
use hli::views::CncView;
use hli::PlaceExt;
use std::path::PathBuf;

/// Channel axes take images 0..6; the single axis follows.
const FEED: usize = 6;

const PROGRAM: &str = "%conveyor\nG1 X100 F6000\nG1 X40 F3000\nM30\n";

fn scenario(extra: &str) -> Result<Scenario, ScenarioError> {
    let toml = format!(
        "cycle_ms = 1.0\n[[channel]]\nname = \"conveyor\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprogram = \"c.nc\"\n\
         drive = {{ model = \"pt1\", t1_ms = 2.0 }}\n{extra}"
    );
    Scenario::parse("machine.toml", &toml, |f| {
        Ok((PathBuf::from(f), PROGRAM.to_string()))
    })
}

fn lr(memory: &hli::ImageMemory, axis: usize) -> HliAxisLrState {
    CncView::new(memory)
        .axis(axis)
        .unwrap()
        .field::<HliAxisLrState>(core::mem::offset_of!(HliAxis, lr_state))
        .read()
}

const GEARED: &str =
    "[[axis]]\nname = \"Feed\"\npower = true\nstart = 5.0\nsoft_limits = [-500.0, 500.0]\n\
    drive = { model = \"pt2\", frequency_hz = 60.0, damping = 0.9 }\n\
    [[gear]]\nmaster = \"conveyor.X\"\nslave = \"Feed\"\nratio = -2.0\n";

#[test]
fn a_gear_slave_follows_a_channel_axis_through_simulated_drives() {
    let s = scenario(GEARED).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let mut max_fe: f64 = 0.0;
    let mut ticks = 0;
    let mut last: Option<(f64, f64, bool)> = None;
    while !run.machine.idle() || ticks < 3000 {
        run.step(s.cycle_s);
        ticks += 1;
        assert!(ticks < 20_000, "watchdog: the program did not end");
        let feed = run.machine.axes().axis(FEED).unwrap();
        assert!(feed.error().is_none(), "{:?}", feed.error());
        max_fe = max_fe.max(feed.following_error().abs());
        // Once coupled, the slave's set-point moves by -2 times the master's, tick by tick.
        let m = run.machine.axes().axis(0).unwrap().setpoint().position;
        let f = feed.setpoint().position;
        if let Some((m0, f0, coupled)) = last {
            if coupled {
                assert!(((f - f0) + 2.0 * (m - m0)).abs() < 1e-9, "tick {ticks}");
            }
        }
        last = Some((m, f, feed.coupling().is_some()));
    }
    // The conveyor stands at X40, so the slave at 5 - 80; both drives settled on it.
    let conveyor = run.machine.axes().axis(0).unwrap();
    let feed = run.machine.axes().axis(FEED).unwrap();
    assert!(
        (conveyor.actual() - 40.0).abs() < 1e-3,
        "{}",
        conveyor.actual()
    );
    assert!((feed.actual() + 75.0).abs() < 1e-3, "{}", feed.actual());
    // The drives lag: a following error shows while moving (ideal drives show none).
    assert!(max_fe > 0.01, "max following error {max_fe}");
    let image = lr(&run.memory, FEED);
    assert_eq!(image.coupling_state_r, CouplingState::GearVelocity.raw());
    assert_eq!(image.master_axis_r, 0);
    assert_eq!(
        lr(&run.memory, 0).coupling_state_r,
        CouplingState::Channel.raw()
    );
}

#[test]
fn an_unpowered_gear_slave_stays_uncoupled() {
    let s = scenario(&GEARED.replace("power = true\n", "")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    for _ in 0..500 {
        run.step(s.cycle_s);
    }
    let feed = run.machine.axes().axis(FEED).unwrap();
    assert!(feed.coupling().is_none());
    assert_eq!(feed.actual(), 5.0);
}

#[test]
fn bad_axes_and_gears_are_refused_with_key_and_reason() {
    for (extra, expect) in [
        ("[[axis]]\nkind = \"linear\"\n", "missing field `name`"),
        ("[[axis]]\nname = \"A\"\nmodulo = 360.0\n", "\"A\": modulo"),
        ("[[axis]]\nname = \"A\"\nkind = \"rotary\"\nsoft_limits = [0.0, 1.0]\n", "\"A\": soft_limits"),
        ("[[axis]]\nname = \"A\"\nsoft_limits = [5.0, 1.0]\n", "minimum must lie below"),
        ("[[axis]]\nname = \"A\"\nvelocity = -1.0\n", "dynamics.velocity"),
        ("[[axis]]\nname = \"A\"\nspeed = 1.0\n", "unknown field `speed`"),
        ("[[axis]]\nname = \"A\"\n[[axis]]\nname = \"A\"\n", "given twice"),
        ("[[axis]]\nname = \"A\"\ndrive = { model = \"pt3\" }\n", "pt3"),
        ("[[axis]]\nname = \"A\"\n[[gear]]\nmaster = \"conveyor.Q\"\nslave = \"A\"\nratio = 1.0\n", "master \"conveyor.Q\": no such axis"),
        ("[[axis]]\nname = \"A\"\n[[gear]]\nmaster = \"A\"\nslave = \"A\"\nratio = 1.0\n", "its own master"),
        ("[[axis]]\nname = \"A\"\n[[gear]]\nmaster = \"conveyor.X\"\nslave = \"A\"\nratio = 0.0\n", "ratio 0"),
        // The engines' keys go to their engines, which name the key; a key nobody reads is
        // refused by name.
        ("[[axis]]\nname = \"A\"\n[[gear]]\nmaster = \"A\"\nslave = \"A\"\nratio = 1.0\nphase = 2\n", "[[gear]]: unknown field `phase`"),
        ("[[axis]]\nname = \"A\"\n[[gear]]\nmaster = \"A\"\nslave = \"A\"\nratio = \"one\"\n", "[[gear]]: invalid type"),
        ("[[axis]]\nname = \"A\"\n[[gears]]\nmaster = \"A\"\n", "unknown key `gears`"),
        ("[[axis]]\nname = \"A\"\n[[fifo_group]]\ndimension = 2\nrows = 8\nfifo_cycle_ms = 1.0\noverride = \"pt2\"\n", "[[fifo_group]] 0: override = \"pt2\" needs pt2_t0_ms"),
    ] {
        let e = scenario(extra).expect_err(extra).to_string();
        assert!(e.starts_with("machine.toml:"), "{e}");
        assert!(e.contains(expect), "{extra}: {e}");
    }
}

/// `track_lag_max` (mm, degree) of a channel: refused with the file, the channel and the key
/// unless positive and finite, and an unknown key of it too.
#[test]
fn a_bad_track_lag_max_is_refused_with_file_and_key() {
    for (value, expect) in [
        ("{ translation = -1.0 }", "track_lag_max.translation = -1"),
        ("{ rotation = 0.0 }", "track_lag_max.rotation = 0"),
        ("{ translation = nan }", "track_lag_max.translation = NaN"),
        ("{ distance = 1.0 }", "unknown field `distance`"),
    ] {
        let toml = format!(
            "cycle_ms = 1.0\n[[channel]]\nname = \"c\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\n\
             program = \"c.nc\"\ntrack_lag_max = {value}\n"
        );
        let e = Scenario::parse("lag.toml", &toml, |f| {
            Ok((PathBuf::from(f), "%c\nM30\n".to_string()))
        })
        .and_then(|s| InProcess::new(&s, 0).map(|_| s))
        .expect_err(value)
        .to_string();
        assert!(e.contains("lag.toml"), "{value}: {e}");
        assert!(e.contains(expect), "{value}: {e}");
    }
}

/// The start-up list's `configuration.channel[i].interpolator.dyn_cs_history_max` (P-STUP-00074)
/// is the channel's `interpolator = { dyn_cs_history_max = N }`: taken as given, 0 keeps no
/// history, beyond what is kept refused with the file, the channel and the key.
#[test]
fn the_history_size_is_the_start_up_key() {
    let toml = |n: &str| {
        format!(
            "cycle_ms = 1.0\n[[channel]]\nname = \"c\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\n\
             program = \"c.nc\"\ninterpolator = {{ dyn_cs_history_max = {n} }}\n"
        )
    };
    let program = "%c\n#TRACK CS ON [ID=0 FILTER=0]\n#TIME 0.1\nM30\n";
    let parse = |n: &str| {
        Scenario::parse("hist.toml", &toml(n), |f| {
            Ok((PathBuf::from(f), program.to_string()))
        })
    };
    let s = parse("1000").unwrap();
    assert_eq!(s.channels[0].interpolator.dyn_cs_history_max, 1000);
    let mut run = InProcess::new(&s, 0).unwrap();
    for _ in 0..50 {
        run.step(s.cycle_s);
    }
    assert!(
        run.machine.controller().channels()[0]
            .tracker()
            .history()
            .count()
            >= 40
    );
    let s = parse("0").unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    for _ in 0..50 {
        run.step(s.cycle_s);
    }
    assert_eq!(
        run.machine.controller().channels()[0]
            .tracker()
            .history()
            .count(),
        0
    );
    let e = parse("100001")
        .and_then(|s| InProcess::new(&s, 0).map(|_| ()))
        .expect_err("refused")
        .to_string();
    assert!(
        e.contains("hist.toml") && e.contains("dyn_cs_history_max"),
        "{e}"
    );
}

#[test]
fn a_channel_whose_axis_faults_stops_in_error() {
    // A slow drive (10 Hz) cannot follow fast moves: the following error passes the limit.
    let toml = "cycle_ms = 1.0\n[[channel]]\nname = \"c\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\n\
        program = \"c.nc\"\nlimits = { velocity = 1000.0, acceleration = 20000.0, jerk = 2000000.0 }\n\
        drive = { model = \"pt2\", frequency_hz = 2.0, damping = 0.3 }\n";
    let s = Scenario::parse("fault.toml", toml, |f| {
        Ok((
            PathBuf::from(f),
            "%c\nG0 X400\nG0 X0\nG0 X400\nM30\n".to_string(),
        ))
    })
    .unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    for _ in 0..5000 {
        run.step(s.cycle_s);
    }
    let c = &run.machine.controller().channels()[0];
    let error = c.error().expect("the channel ended in error").to_string();
    assert!(error.contains("a channel axis faulted"), "{error}");
    assert!(run.machine.axes().axis(0).unwrap().error().is_some());

    // The PLC's RESET: the axis is reset and coupled again where it stands, the channel takes
    // that position over (no step), and is ready for a new start.
    use hli::enums::{ChannelCommand, ChannelCommandState, ChannelState};
    let command = hli::layout::HliChannelCommand {
        command_id: 7,
        command: ChannelCommand::Reset.raw(),
        start_line: 0,
        value: 0,
        program: [0; 64],
    };
    let plc = hli::views::PlcView::new(&run.memory);
    plc.gp_ch(0)
        .unwrap()
        .channel_command()
        .try_send(&command)
        .unwrap();
    for _ in 0..3 {
        run.step(s.cycle_s);
    }
    let state = hli::views::PlcView::new(&run.memory)
        .gp_ch(0)
        .unwrap()
        .channel_control_state();
    assert_eq!(
        (state.command_id, state.command_state),
        (7, ChannelCommandState::Done.raw())
    );
    assert_eq!(state.state, ChannelState::Selected.raw());
    let axis = run.machine.axes().axis(0).unwrap();
    assert_eq!(axis.error(), None, "the axis was reset");
    let c = &run.machine.controller().channels()[0];
    assert!(
        (c.set_points()[0] - axis.actual()).abs() < 1e-9,
        "the channel stands where the axis stands"
    );
    let before = axis.actual();
    for _ in 0..200 {
        run.step(s.cycle_s);
    }
    let axis = run.machine.axes().axis(0).unwrap();
    assert!(
        (axis.actual() - before).abs() < 1e-6,
        "at rest and held: {before} -> {}",
        axis.actual()
    );
    assert_eq!(axis.error(), None);
}

#[test]
fn gears_drive_single_axes_only_and_names_stay_apart() {
    for (extra, expect) in [
        ("[[axis]]\nname = \"A\"\n[[gear]]\nmaster = \"A\"\nslave = \"conveyor.Y\"\nratio = 1.0\n", "a channel axis is driven by its channel"),
        ("[[axis]]\nname = \"conveyor.Q\"\n", "without '.'"),
    ] {
        let e = scenario(extra).expect_err(extra).to_string();
        assert!(e.contains(expect), "{extra}: {e}");
    }
    let e = Scenario::parse("axes.toml", "[[axis]]\nname = \"A\"\n", |_| unreachable!())
        .unwrap_err()
        .to_string();
    assert!(e.contains("needs `ticks`"), "{e}");
}

#[test]
fn a_stop_ends_a_waiting_channel_in_error_before_the_machine_counts_as_at_rest() {
    // The channel waits for an M-function acknowledge nobody gives.
    let toml = "cycle_ms = 1.0\n[[channel]]\nname = \"c\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprogram = \"c.nc\"\n";
    let s = Scenario::parse("wait.toml", toml, |f| {
        Ok((
            PathBuf::from(f),
            "%c\nG1 X1 F600\nM100\nG1 X2 F600\nM30\n".to_string(),
        ))
    })
    .unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    for _ in 0..1000 {
        run.step(s.cycle_s);
    }
    assert!(run.machine.controller().channels()[0].error().is_none());
    run.machine.stop("machine stop: test");
    // An acknowledge the PLC gives during the stop stays pending: a stopping channel takes
    // nothing from it.
    let plc = hli::views::PlcView::new(&run.memory);
    let request = plc
        .m_function_request(0)
        .unwrap()
        .try_take()
        .unwrap()
        .unwrap();
    let ack_free = |m: &hli::ImageMemory| {
        hli::views::PlcView::new(m)
            .m_function_ack(0)
            .unwrap()
            .is_free()
            .unwrap()
    };
    plc.m_function_ack(0)
        .unwrap()
        .try_send(&hli::layout::HliMFunctionAck {
            m_code: 100,
            request_id: request.request_id,
        })
        .unwrap();
    assert!(
        !run.machine.at_rest(),
        "the waiting channel has not ended yet"
    );
    run.step(s.cycle_s);
    let c = &run.machine.controller().channels()[0];
    assert_eq!(
        c.error().map(|e| e.to_string()).as_deref(),
        Some("machine stop: test")
    );
    assert!(run.machine.at_rest());
    assert!(run.machine.stopped());
    assert!(
        !ack_free(&run.memory),
        "the acknowledge was taken during the stop"
    );
    assert_eq!(
        run.machine.controller().channels()[0].m_functions_acked(),
        0
    );
}

#[test]
fn a_gear_on_a_single_axis_master_follows_it_in_the_same_tick() {
    // Master and slave are both single axes; the PLC moves the master with MC_MoveAbsolute.
    // Free axes run their generators before the engines, so the gear sees the master's
    // set-point of the same tick: no lag, in acceleration as at constant velocity.
    let toml = "cycle_ms = 1.0\nticks = 2000\n\
        [[axis]]\nname = \"Master\"\npower = true\n\
        [[axis]]\nname = \"Slave\"\npower = true\nstart = 3.0\n\
        [[gear]]\nmaster = \"Master\"\nslave = \"Slave\"\nratio = 0.5\n\
        [plc]\ntimeline = \"plc.toml\"\n";
    let timeline = "[[step]]\nat_tick = 10\ncall = { block = \"MC_MoveAbsolute\", instance = \"m\", axis = 0, \
        position = 200.0, velocity = 300.0, acceleration = 3000.0, deceleration = 3000.0, jerk = 30000.0 }\n";
    let s = Scenario::parse("single.toml", toml, |_| {
        Ok((PathBuf::from("plc.toml"), timeline.to_string()))
    })
    .unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let mut moved = 0;
    for _ in 0..2000 {
        run.step(s.cycle_s);
        let m = run.machine.axes().axis(0).unwrap().setpoint();
        let f = run.machine.axes().axis(1).unwrap().setpoint();
        assert!(
            (f.position - (3.0 + 0.5 * m.position)).abs() < 1e-9,
            "tick {}: slave {} for master {}",
            run.machine.ticks(),
            f.position,
            m.position
        );
        assert!((f.velocity - 0.5 * m.velocity).abs() < 1e-9);
        moved += usize::from(m.velocity != 0.0);
    }
    assert!(moved > 500, "the master moved for {moved} ticks");
    let master = run.machine.axes().axis(0).unwrap();
    assert!(
        (master.actual() - 200.0).abs() < 1e-3,
        "{}",
        master.actual()
    );
    let slave = run.machine.axes().axis(1).unwrap();
    assert!((slave.actual() - 103.0).abs() < 1e-3, "{}", slave.actual());
}

/// A tracking slave's axes are axes like any other: on simulated PT2 drives, the slave channel
/// (images 6..11) follows the master channel's X move through `#TRACK CS`, and its X axis
/// image shows it: the drive's velocity command (`nOutData1`, 10000 increments per mm/s) runs
/// up to the master's 50 mm/s, the encoder count (`nInData1`, 10000 per mm) is the axis's
/// actual position in the next tick, which lags its set-point (a following error) and settles on the master's
/// 50 mm.
#[test]
fn a_tracking_slave_drives_its_axis_images_through_simulated_drives() {
    let toml = "cycle_ms = 1.0\n\
        [[channel]]\nname = \"master\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprogram = \"m.nc\"\n\
        drive = { model = \"pt2\", frequency_hz = 60.0, damping = 0.9 }\n\
        [[channel]]\nname = \"slave\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprogram = \"s.nc\"\n\
        drive = { model = \"pt2\", frequency_hz = 60.0, damping = 0.9 }\n";
    let s = Scenario::parse("tracking.toml", toml, |f| {
        let text = if f == "m.nc" {
            "#CHANNEL INTERFACE ON [DYN_CS]\n#TIME 0.05\nG1 X50 F3000\n#TIME 0.5\nM30\n"
        } else {
            "#TRACK CS ON [CH=1 FILTER=0]\n#TIME 3\nM30\n"
        };
        Ok((PathBuf::from(f), text.to_string()))
    })
    .unwrap();
    const SLAVE_X: usize = 6;
    let mut run = InProcess::new(&s, 0).unwrap();
    let (mut max_command, mut min_command, mut max_fe, mut count) = (0i32, 0i32, 0.0f64, 0i32);
    for tick in 0..4000 {
        run.step(s.cycle_s);
        let channels = run.machine.controller().channels();
        for c in channels {
            assert!(c.error().is_none(), "{}: {:?}", c.config().name, c.error());
        }
        // Masters tick first: the slave's set-point is the master's X of the same tick.
        let master_x = channels[0].set_points()[0];
        assert!(
            (channels[1].set_points()[0] - master_x).abs() < 1e-9,
            "tick {tick}"
        );
        let axis = run.machine.axes().axis(SLAVE_X).unwrap();
        let image: HliAxis = CncView::new(&run.memory).axis(SLAVE_X).unwrap().read();
        // The axis read, at the start of this tick, the count the drive wrote in the last.
        assert_eq!(
            f64::from(count) / 10_000.0,
            axis.actual(),
            "tick {tick}: the encoder count is the actual position"
        );
        assert_eq!(image.lr_state.current_position_acs_r, count, "tick {tick}");
        count = image.enc_in.nInData1;
        max_command = max_command.max(image.drive_out.nOutData1);
        min_command = min_command.min(image.drive_out.nOutData1);
        max_fe = max_fe.max(axis.following_error().abs());
    }
    // F3000 is 50 mm/s: 500000 increments per second at the top.
    assert!(
        max_command > 450_000 && max_command < 700_000,
        "top velocity command {max_command}"
    );
    // Backwards only to take out the PT2 drive's small overshoot at the end.
    assert!(
        min_command > -max_command / 10,
        "{min_command} {max_command}"
    );
    assert!(max_fe > 0.01, "the drive lags: {max_fe}");
    let slave_x = run.machine.axes().axis(SLAVE_X).unwrap();
    assert!(
        (slave_x.actual() - 50.0).abs() < 1e-3,
        "{}",
        slave_x.actual()
    );
    assert_eq!(
        lr(&run.memory, SLAVE_X).coupling_state_r,
        CouplingState::Channel.raw()
    );
}

#[test]
fn a_gear_slave_whose_master_faults_brakes_with_its_own_deceleration() {
    // The channel's X faults (a 2 Hz drive cannot follow); its gear slave, moving at speed,
    // must not stop with it in one tick: it is let go with the motion it had and brakes
    // (MC_Stop) with its own deceleration and jerk.
    let toml = "cycle_ms = 1.0\n[[channel]]\nname = \"c\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\n\
        program = \"c.nc\"\nlimits = { velocity = 1000.0, acceleration = 20000.0, jerk = 2000000.0 }\n\
        drive = { model = \"pt2\", frequency_hz = 2.0, damping = 0.3 }\n\
        [[axis]]\nname = \"Feed\"\npower = true\nvelocity = 5000.0\nacceleration = 20000.0\n\
        deceleration = 2000.0\njerk = 2000000.0\n\
        [[gear]]\nmaster = \"c.X\"\nslave = \"Feed\"\nratio = 1.0\n";
    let s = Scenario::parse("orphan.toml", toml, |f| {
        Ok((PathBuf::from(f), "%c\nG0 X400\nG0 X0\nM30\n".to_string()))
    })
    .unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let feed = |run: &InProcess| run.machine.axes().axis(FEED).unwrap().setpoint();
    let mut fault_at = None;
    let mut at_fault = feed(&run);
    let mut last = feed(&run);
    for tick in 0..5000 {
        run.step(s.cycle_s);
        let now = feed(&run);
        if fault_at.is_none() && run.machine.axes().axis(0).unwrap().error().is_some() {
            fault_at = Some(tick);
            at_fault = last;
        }
        // The fault comes at the end of tick `at`; from the next tick on the slave moves
        // within its limits: acceleration at most 20000 mm/s², its change at most the jerk.
        if fault_at.is_some_and(|at| tick > at) {
            assert!(
                (now.velocity - last.velocity).abs() <= 20.0 + 1e-6,
                "tick {tick}: the slave's velocity jumped from {} to {}",
                last.velocity,
                now.velocity
            );
            assert!(
                now.acceleration.abs() <= 20_000.0 + 1e-6,
                "tick {tick}: {now:?}"
            );
            assert!(
                (now.acceleration - last.acceleration).abs() <= 2_000.0 + 1e-6,
                "tick {tick}: {last:?} -> {now:?}"
            );
        }
        last = now;
    }
    assert!(fault_at.is_some(), "the master never faulted");
    assert!(
        at_fault.velocity.abs() > 10.0,
        "the slave moved at the fault: {at_fault:?}"
    );
    let slave = run.machine.axes().axis(FEED).unwrap();
    assert_eq!(slave.error(), None, "the slave itself is sound");
    assert_eq!(slave.setpoint().velocity, 0.0, "and came to rest");
    assert!(
        run.machine.at_rest(),
        "the faulted master counts as held, not moving"
    );
    let held: Vec<_> = run
        .machine
        .held_by_fault()
        .map(|(n, _)| n.to_string())
        .collect();
    assert_eq!(held, ["c.X"]);
}

#[test]
fn garbage_over_simulated_drive_inputs_in_the_image_is_not_taken_back() {
    // A PLC that writes over the axis image's inputs of simulated drives (which the CNC
    // itself wrote there) changes nothing: the axes keep reading their drives' answers.
    use hli::layout::{NcDriveIn, NcEncoderIn};
    let s = scenario(GEARED).unwrap();
    let mut clean = InProcess::new(&s, 0).unwrap();
    let mut hammered = InProcess::new(&s, 0).unwrap();
    let mut noise = 0x9E37_79B9_7F4A_7C15u64;
    for _ in 0..3000 {
        clean.step(s.cycle_s);
        for axis in 0..=FEED {
            let place = CncView::new(&hammered.memory).axis(axis).unwrap();
            noise = noise.rotate_left(13) ^ 0xD1B5_4A32_D192_ED03;
            let mut enc: NcEncoderIn = bytemuck::Zeroable::zeroed();
            let mut drive: NcDriveIn = bytemuck::Zeroable::zeroed();
            bytemuck::bytes_of_mut(&mut enc).fill(noise as u8);
            bytemuck::bytes_of_mut(&mut drive).fill((noise >> 8) as u8);
            place
                .field::<NcEncoderIn>(core::mem::offset_of!(HliAxis, enc_in))
                .write(&enc);
            place
                .field::<NcDriveIn>(core::mem::offset_of!(HliAxis, drive_in))
                .write(&drive);
        }
        hammered.step(s.cycle_s);
        for axis in 0..=FEED {
            let (a, b) = (lr(&clean.memory, axis), lr(&hammered.memory, axis));
            assert_eq!(
                bytemuck::bytes_of(&a),
                bytemuck::bytes_of(&b),
                "axis {axis} at tick {}",
                clean.machine.ticks()
            );
        }
    }
    assert!(hammered.machine.held_by_fault().next().is_none());
}
