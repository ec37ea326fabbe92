//! The channel control unit (`gpCh[i]^channel_control`) as a PLC drives it: select from the
//! program folder, start, stop, feed hold and resume, reset, single block and mode, every
//! refusal with its code, and the interplay with tracking, `#WAIT SYN` and M functions.

use tests::channel_rig as support;

use cnc_core::channel::folder::ProgramFolder;
use cnc_core::channel::{Channel, ChannelConfig, Controller, LoadedProgram};
use hli::enums::{
    ChannelCommand, ChannelCommandError as E, ChannelCommandState, ChannelErrorId, ChannelMode,
    ChannelSignal, ChannelState, DynCsState,
};
use hli::layout::{nul_padded, nul_padded_str, HliChannelCommand, HliChannelControlState};
use hli::views::{CncView, PlcView};
use hli::ImageMemory;
use std::path::PathBuf;
use support::*;

const PART: &str = "G1 X100 F6000\nG1 Y50\nG1 X0\nG1 Y0\nM30\n";

/// A program folder of its own for one test.
fn folder(files: &[(&str, &str)]) -> PathBuf {
    static N: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let n = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("cnc-channel-control-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir
}

/// Channels on a heap image, driven like a PLC does: a command posted, the machine's tick, the
/// work between ticks.
struct Rig {
    ctl: Controller,
    memory: ImageMemory,
    next_id: u32,
    ticks: u32,
}

impl Rig {
    /// Channels with `configs`, each selecting (not starting) its program if it has one, all
    /// with the program folder `dir`.
    fn new(configs: Vec<(ChannelConfig, Option<&str>)>, dir: Option<&PathBuf>) -> Rig {
        let mut channels = Vec::new();
        for (i, (config, src)) in configs.into_iter().enumerate() {
            let mut channel = Channel::new(i, config.clone(), CYCLE).unwrap();
            if let Some(src) = src {
                let program =
                    LoadedProgram::load(&format!("{}.nc", config.name), src, &config.axes);
                channel.select(program.unwrap_or_else(|e| panic!("{e}")));
            }
            if let Some(dir) = dir {
                channel.set_program_folder(ProgramFolder {
                    dir: dir.clone(),
                    setup: config.nc.setup(),
                    search: Default::default(),
                });
            }
            channels.push(channel);
        }
        let n = channels.len();
        Rig {
            ctl: Controller::new(channels).unwrap(),
            memory: image(n),
            next_id: 0,
            ticks: 0,
        }
    }

    fn tick(&mut self) {
        self.ctl.tick(&CncView::new(&self.memory));
        self.ctl.serve_channels(None);
        self.ticks += 1;
    }

    /// Posts a command to `channel` (the semaphore must be free) and returns its id.
    fn post(
        &mut self,
        channel: usize,
        command: ChannelCommand,
        edit: impl Fn(&mut HliChannelCommand),
    ) -> u32 {
        self.next_id += 1;
        let mut c = HliChannelCommand {
            command_id: self.next_id,
            command: command.raw(),
            start_line: 0,
            value: 0,
            program: [0; 64],
        };
        edit(&mut c);
        let plc = PlcView::new(&self.memory);
        plc.gp_ch(channel)
            .unwrap()
            .channel_command()
            .try_send(&c)
            .unwrap();
        self.next_id
    }

    fn state_block(&self, channel: usize) -> HliChannelControlState {
        PlcView::new(&self.memory)
            .gp_ch(channel)
            .unwrap()
            .channel_control_state()
    }

    fn state(&self, channel: usize) -> ChannelState {
        ChannelState::decode(self.state_block(channel).state).unwrap()
    }

    /// Posts `command` and ticks until the channel answers it with Done or Refused (watchdog:
    /// `limit` ticks); returns the refusal code (None: done).
    fn command(
        &mut self,
        channel: usize,
        command: ChannelCommand,
        edit: impl Fn(&mut HliChannelCommand),
        limit: u32,
    ) -> Option<E> {
        let id = self.post(channel, command, edit);
        for _ in 0..limit {
            self.tick();
            let s = self.state_block(channel);
            assert_eq!(s.command_id, id, "the channel took the command in its tick");
            match ChannelCommandState::decode(s.command_state).unwrap() {
                ChannelCommandState::Done => return None,
                ChannelCommandState::Refused => return Some(E::decode(s.command_error).unwrap()),
                _ => {}
            }
        }
        panic!("watchdog: {command:?} not answered in {limit} ticks");
    }

    fn run_ticks(&mut self, n: u32, mut each: impl FnMut(&Rig)) {
        for _ in 0..n {
            self.tick();
            each(self);
        }
    }

    fn x(&self, channel: usize) -> f64 {
        self.ctl.channels()[channel].set_points()[0]
    }
}

fn plain(_: &mut HliChannelCommand) {}

fn select(name: &'static str, line: i32) -> impl Fn(&mut HliChannelCommand) {
    move |c| {
        c.program = nul_padded(name);
        c.start_line = line;
    }
}

#[test]
fn a_selected_program_waits_for_start_and_runs_three_times() {
    let mut rig = Rig::new(vec![(cartesian("c"), Some(PART))], None);
    rig.run_ticks(50, |r| assert_eq!(r.state(0), ChannelState::Selected));
    assert_eq!(rig.x(0), 0.0, "nothing moves before START");
    assert_eq!(nul_padded_str(&rig.state_block(0).program), Some("c.nc"));
    for part in 1..=3 {
        assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
        assert_eq!(rig.state(0), ChannelState::Running);
        let mut top = 0.0f64;
        while rig.state(0) != ChannelState::Selected {
            rig.tick();
            top = top.max(rig.x(0));
            assert!(rig.ticks < 50_000, "watchdog");
        }
        assert_eq!(top, 100.0, "part {part} ran its path");
        let s = rig.state_block(0);
        assert_eq!(s.programs_ended, part);
        assert_ne!(s.signals & ChannelSignal::ProgramEnd.raw(), 0);
    }
}

#[test]
fn start_while_running_and_commands_without_program_are_refused_and_change_nothing() {
    let mut rig = Rig::new(vec![(cartesian("c"), None)], None);
    assert_eq!(
        rig.command(0, ChannelCommand::Start, plain, 5),
        Some(E::NoProgram)
    );
    assert_eq!(
        rig.command(0, ChannelCommand::FeedHold, plain, 5),
        Some(E::NotRunning)
    );
    assert_eq!(
        rig.command(0, ChannelCommand::Select, select("a.nc", 0), 5),
        Some(E::NoProgramFolder)
    );
    assert_eq!(
        rig.command(0, ChannelCommand::SingleBlock, |c| c.value = 7, 5),
        Some(E::BadValue)
    );
    assert_eq!(
        rig.command(0, ChannelCommand::Mode, |c| c.value = 9, 5),
        Some(E::BadValue)
    );
    // A command word that is no command.
    let id = rig.post(0, ChannelCommand::Start, |c| c.command = 77);
    rig.tick();
    let s = rig.state_block(0);
    assert_eq!(
        (s.command_id, s.command_error),
        (id, E::UnknownCommand.raw())
    );
    assert_eq!(rig.state(0), ChannelState::Idle);

    let mut rig = Rig::new(vec![(cartesian("c"), Some(PART))], None);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(100, |_| {});
    let x = rig.x(0);
    assert_eq!(
        rig.command(0, ChannelCommand::Start, plain, 5),
        Some(E::Running)
    );
    assert_eq!(
        rig.command(0, ChannelCommand::Mode, |c| c.value = 1, 5),
        Some(E::Running)
    );
    assert_eq!(rig.state(0), ChannelState::Running);
    assert!(rig.x(0) > x, "the program went on");
}

#[test]
fn select_loads_from_the_folder_and_refuses_what_is_missing_or_fails_its_check() {
    let part = "G1 X100 F6000\nG1 Y50 F6000\nG1 X0 F6000\nM30\n";
    let dir = folder(&[("part.nc", part), ("bad.nc", "G1 X10 F100\nG1 Q=\nM30\n")]);
    let mut rig = Rig::new(vec![(cartesian("c"), None)], Some(&dir));
    assert_eq!(
        rig.command(0, ChannelCommand::Select, select("nope.nc", 0), 5),
        Some(E::ProgramNotFound)
    );
    assert_eq!(
        rig.command(0, ChannelCommand::Select, select("../part.nc", 0), 5),
        Some(E::BadName)
    );
    assert_eq!(
        rig.command(0, ChannelCommand::Select, select("bad.nc", 0), 5),
        Some(E::ProgramInvalid)
    );
    let message = rig.state_block(0).message;
    let text = nul_padded_str(&message).unwrap();
    assert!(
        text.contains("bad.nc:2:"),
        "FILE:LINE:COL of the first diagnostic: {text}"
    );
    assert_eq!(rig.state(0), ChannelState::Idle, "nothing half-done");
    assert_eq!(
        rig.command(0, ChannelCommand::Select, select("part.nc", 2), 5),
        None
    );
    assert_eq!(rig.state(0), ChannelState::Selected);
    assert_eq!(nul_padded_str(&rig.state_block(0).program), Some("part.nc"));
    // Started at line 2 (G1 Y50): X never leaves 0, Y goes to 50.
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(5_000, |r| assert_eq!(r.x(0), 0.0));
    assert_eq!(rig.state(0), ChannelState::Selected);
    assert_eq!(rig.ctl.channels()[0].set_points()[1], 50.0);
    assert_eq!(
        rig.command(0, ChannelCommand::Select, select("part.nc", 99), 5),
        Some(E::StartLineNotFound)
    );
}

#[test]
fn feed_hold_decelerates_on_the_path_and_start_goes_on_from_there() {
    let mut rig = Rig::new(vec![(cartesian("c"), Some(PART))], None);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(300, |_| {});
    let id = rig.post(0, ChannelCommand::FeedHold, plain);
    let mut last = rig.x(0);
    let mut v_last = f64::INFINITY;
    loop {
        rig.tick();
        let v = (rig.x(0) - last) / CYCLE;
        assert!(
            v <= v_last + 1e-9 && v >= 0.0,
            "decelerates along the path, never back"
        );
        (last, v_last) = (rig.x(0), v);
        let s = rig.state_block(0);
        assert_eq!(s.command_id, id);
        assert_eq!(rig.state(0), ChannelState::Holding);
        if s.command_state == ChannelCommandState::Done.raw() {
            break;
        }
        assert!(rig.ticks < 2_000, "watchdog");
    }
    let held = rig.x(0);
    assert!(
        held < 99.0,
        "held on the path, before the block's end: {held}"
    );
    rig.run_ticks(500, |r| {
        assert_eq!(r.x(0), held);
        assert_eq!(r.state(0), ChannelState::Holding);
    });
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(50, |_| {});
    assert!(rig.x(0) > held, "the path went on from where it held");
    assert_eq!(rig.state(0), ChannelState::Running);
}

#[test]
fn stop_ends_the_program_at_rest_and_it_stays_selected() {
    let mut rig = Rig::new(vec![(cartesian("c"), Some(PART))], None);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(400, |_| {});
    assert_eq!(rig.command(0, ChannelCommand::Stop, plain, 2_000), None);
    let x = rig.x(0);
    assert!(x > 0.0 && x < 100.0, "stopped on the path");
    assert_eq!(rig.state(0), ChannelState::Selected);
    rig.run_ticks(100, |r| assert_eq!(r.x(0), x));
    assert_eq!(rig.state_block(0).programs_ended, 0, "stopped, not ended");
    // A new start runs the program from its beginning, from where the axes stand.
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    assert_eq!(rig.state(0), ChannelState::Running);
}

#[test]
fn single_block_waits_for_start_after_each_block() {
    let mut rig = Rig::new(vec![(cartesian("c"), Some(PART))], None);
    assert_eq!(
        rig.command(0, ChannelCommand::SingleBlock, |c| c.value = 1, 5),
        None
    );
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    let mut stops = 0;
    while rig.state(0) != ChannelState::Selected {
        rig.tick();
        if rig.state(0) == ChannelState::Holding {
            let s = rig.state_block(0);
            assert_ne!(s.signals & ChannelSignal::SingleBlockStop.raw(), 0);
            stops += 1;
            let at = rig.x(0);
            rig.run_ticks(20, |r| assert_eq!(r.x(0), at));
            assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
        }
        assert!(rig.ticks < 50_000, "watchdog");
    }
    assert_eq!(stops, 4, "one stop after each of the four motion blocks");
}

#[test]
fn manual_mode_refuses_start() {
    let mut rig = Rig::new(vec![(cartesian("c"), Some(PART))], None);
    assert_eq!(
        rig.command(
            0,
            ChannelCommand::Mode,
            |c| c.value = ChannelMode::Manual.raw(),
            5
        ),
        None
    );
    assert_eq!(rig.state_block(0).mode, ChannelMode::Manual.raw());
    assert_eq!(
        rig.command(0, ChannelCommand::Start, plain, 5),
        Some(E::NotAutomatic)
    );
    assert_eq!(
        rig.command(0, ChannelCommand::Mode, |c| c.value = 0, 5),
        None
    );
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
}

/// A program that fails (its own channel as tracking master) leaves the channel in ERROR with
/// the tracker refusing; RESET clears both and the part runs again.
#[test]
fn reset_clears_the_error_and_a_moving_channel_decelerates_first() {
    let failing = "G1 X20 F6000\n#TRACK CS ON [ID=1]\nG1 X40\nM30\n";
    let mut rig = Rig::new(vec![(cartesian("c"), Some(failing))], None);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(2_000, |_| {});
    assert_eq!(rig.state(0), ChannelState::Error);
    assert_eq!(rig.state_block(0).error_id, ChannelErrorId::Tracking.raw());
    let message = rig.state_block(0).message;
    let text = nul_padded_str(&message).unwrap();
    assert!(
        text.starts_with("line 2: #TRACK CS ON"),
        "the error's text: {text}"
    );
    assert_eq!(
        rig.command(0, ChannelCommand::Start, plain, 5),
        Some(E::InError)
    );
    assert_eq!(rig.command(0, ChannelCommand::Reset, plain, 5), None);
    assert_eq!(rig.state(0), ChannelState::Selected);
    assert_eq!(rig.state_block(0).error_id, 0);

    // RESET at speed: decelerates on the path, then resets.
    let mut rig = Rig::new(vec![(cartesian("c"), Some(PART))], None);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(400, |_| {});
    let id = rig.post(0, ChannelCommand::Reset, plain);
    let mut last = rig.x(0);
    let mut v_last = f64::INFINITY;
    let mut stopping = 0;
    loop {
        rig.tick();
        let v = (rig.x(0) - last) / CYCLE;
        assert!(v <= v_last + 1e-9, "no jump, only deceleration");
        (last, v_last) = (rig.x(0), v);
        let s = rig.state_block(0);
        assert_eq!(s.command_id, id);
        if s.command_state == ChannelCommandState::Done.raw() {
            break;
        }
        assert_eq!(rig.state(0), ChannelState::Stopping);
        stopping += 1;
        assert!(rig.ticks < 3_000, "watchdog");
    }
    assert!(
        stopping > 10,
        "it took the deceleration's time: {stopping} ticks"
    );
    assert_ne!(
        rig.state_block(0).states_seen & ChannelState::Stopping.seen_bit(),
        0
    );
}

mod interplay;

/// STOP during a continuous path: the path brakes on the contour within the channel's limits
/// and rests on it (within the corner deviation of the programmed zigzag); the program stays
/// selected.
#[test]
fn stop_brakes_a_continuous_path_on_the_contour() {
    let mut program = String::from("#CONTOUR MODE [DEV PATH_DEV=0.02]\nG261 G1 F9000\n");
    for k in 1..=200 {
        program.push_str(&format!("X{k} Y{}\n", if k % 2 == 1 { 0.2 } else { 0.0 }));
    }
    program.push_str("M30\n");
    let config = cartesian("c");
    let limits = config.limits;
    let mut rig = Rig::new(vec![(config, Some(&program))], None);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(300, |_| {});
    let id = rig.post(0, ChannelCommand::Stop, plain);
    let mut trace = Vec::new();
    for _ in 0..5_000 {
        rig.tick();
        let c = &rig.ctl.channels()[0];
        trace.push([c.set_points()[0], c.set_points()[1]]);
        let s = rig.state_block(0);
        if s.command_id == id
            && ChannelCommandState::decode(s.command_state).unwrap() == ChannelCommandState::Done
        {
            break;
        }
    }
    assert_eq!(rig.state(0), ChannelState::Selected);
    for w in trace.windows(3) {
        for ((p0, p1), p2) in w[0].iter().zip(&w[1]).zip(&w[2]) {
            let v = (p2 - p1) / CYCLE;
            let a = (p2 - 2.0 * p1 + p0) / (CYCLE * CYCLE);
            assert!(v.abs() <= limits.velocity * 1.000001, "velocity {v}");
            assert!(
                a.abs() <= limits.acceleration * 1.000001,
                "acceleration {a}"
            );
        }
    }
    let [x, y] = *trace.last().unwrap();
    assert!(x > 1.0 && x < 199.0, "stopped on the way: {x}");
    // The zigzag's corners at the whole millimetres: y = 0.2 at odd ones, 0 at even ones.
    let corner = |k: f64| [k, if k as i64 % 2 == 1 { 0.2 } else { 0.0 }];
    let to_segment = |a: [f64; 2], b: [f64; 2]| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let t = (((x - a[0]) * dx + (y - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
        (x - a[0] - t * dx).hypot(y - a[1] - t * dy)
    };
    let k = x.floor();
    let off = to_segment(corner(k - 1.0), corner(k))
        .min(to_segment(corner(k), corner(k + 1.0)))
        .min(to_segment(corner(k + 1.0), corner(k + 2.0)));
    assert!(off <= 0.02 + 1e-9, "off the path by {off} at {x} {y}");
    rig.run_ticks(100, |r| assert_eq!(r.x(0), x, "at rest"));
}
