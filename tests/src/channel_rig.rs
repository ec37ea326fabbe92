//! Channels on a heap image for the channel tests: channel configurations, a controller
//! running given programs, a watchdog loop, and the PLC's dynamic-CS payloads.

use cnc_core::channel::{Channel, ChannelConfig, Controller, LoadedProgram, RunState};
use hli::image::heap_image;
use hli::layout::{HliCoordinateSystemInt, HliDynCsTransition};
use hli::views::CncView;
use hli::{Bool, ImageMemory};

/// The CNC cycle of the channel tests, 1 ms.
pub const CYCLE: f64 = 0.001;
/// The joint angles a [`robot`] starts at (degrees).
pub const ROBOT_HOME: [f64; 6] = [0.0, -60.0, 90.0, 0.0, 60.0, 0.0];

/// A KR6 R900 sixx robot channel (kinematic 45) with stiff axes, at [`ROBOT_HOME`].
pub fn robot(name: &str) -> ChannelConfig {
    let mut c = stiff(ChannelConfig::new(name, &["X", "Y", "Z", "A", "B", "C"]));
    c.kinematics.id = 45;
    c.kinematics.preset = Some("kr6r900sixx".into());
    c.start = ROBOT_HOME.to_vec();
    c
}

/// A Cartesian channel with the six axes X..C, stiff.
pub fn cartesian(name: &str) -> ChannelConfig {
    stiff(ChannelConfig::new(name, &["X", "Y", "Z", "A", "B", "C"]))
}

/// Axes that take any step the tests' tracked motion asks of them (frame steps without a
/// filter, soft couplings of 20 mm in 0.1 s): the tests built on these helpers are about the
/// dynamic CS, not the axes' limits. The path keeps the channel's `limits`; the tests of the
/// guard (`tracking_safety.rs`) configure real axis limits.
pub fn stiff(mut c: ChannelConfig) -> ChannelConfig {
    let axis = cnc_core::channel::path::AxisLimits {
        velocity: 1e6,
        acceleration: 1e9,
        jerk: 1e12,
    };
    c.axis_limits = vec![axis; c.axes.len()];
    c
}

/// The text of seed `file` when `../shared/seeds/` is there (it is not in a fresh clone: the
/// tests that read it are extra cross-checks and say they skipped).
pub fn seed_text(file: &str) -> Option<String> {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/seeds")
        .join(file);
    if !path.exists() {
        println!("skipped: ../shared/seeds not present");
        return None;
    }
    Some(
        std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("reading {}: {e}", path.display())),
    )
}

/// The tool table of `nc.tools` from TOML rows (`{ d = 1, length = 100.0 }, ...`).
pub fn tools(rows: &str) -> Vec<cnc_core::channel::config::ToolEntry> {
    let table: toml::Table = toml::from_str(&format!("tools = [{rows}]")).unwrap();
    table["tools"].clone().try_into().unwrap()
}

/// Channels in the given order, each running its program (checked with the channel's own
/// machine data: zero offsets, tool table).
pub fn controller(configs: Vec<(ChannelConfig, &str)>) -> Controller {
    let mut channels = Vec::new();
    for (i, (config, src)) in configs.into_iter().enumerate() {
        let program = LoadedProgram::load_with(
            &config.name,
            src,
            &config.axes,
            &config.nc.setup(),
            None,
            &cnc_core::nc::interp::SearchPath::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let mut channel = Channel::new(i, config, CYCLE).unwrap();
        channel.start(program).unwrap();
        channels.push(channel);
    }
    Controller::new(channels).unwrap()
}

/// A heap image of `channels` channels and 8 axes.
pub fn image(channels: usize) -> ImageMemory {
    heap_image(channels as u32, 8)
}

/// Runs until `done` or the watchdog of `limit` ticks trips (then fails).
pub fn run_until(
    ctl: &mut Controller,
    memory: &ImageMemory,
    limit: u32,
    mut each: impl FnMut(&Controller, u32),
    done: impl Fn(&Controller) -> bool,
) -> u32 {
    let view = CncView::new(memory);
    for tick in 0..limit {
        ctl.tick(&view);
        for c in ctl.channels() {
            assert_ne!(
                c.state(),
                RunState::Error,
                "channel {} stopped: {:?}",
                c.config().name,
                c.error()
            );
        }
        each(ctl, tick);
        if done(ctl) {
            return tick;
        }
    }
    panic!("watchdog: not done after {limit} ticks");
}

/// A frame commanded by the PLC: a translation in 0.1 um, no rotation.
pub fn cs(translation: [i32; 3]) -> HliCoordinateSystemInt {
    HliCoordinateSystemInt {
        translation,
        fill_up_2: 0,
        rotation: [0; 3],
        fill_up_1: 0,
    }
}

/// A PLC transition's parameters: a filter, f_wait, no other flag, no offset (the command
/// word is written by `try_send`).
pub fn transition(filter_max_ticks: u32, f_wait: Bool) -> HliDynCsTransition {
    HliDynCsTransition {
        command: 0,
        filter_max_ticks,
        option: 0,
        f_wait,
        f_set_zero: Bool::FALSE,
        f_kin_base: Bool::FALSE,
        f_rot_trans: Bool::FALSE,
        kinematic_base_cs: cs([0; 3]),
    }
}

/// The PLC as master of channel 0: `enable_w` TRUE and a first frame at `translation`.
pub fn enable_plc_master(memory: &ImageMemory, translation: [i32; 3]) {
    let plc = hli::views::PlcView::new(memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    plc.dyn_cs_command(0)
        .unwrap()
        .try_send(&cs(translation))
        .unwrap();
}

/// Ticks until channel 0 finished (the watchdog of [`run_until`] fails a run that does not).
pub fn run_to_end(ctl: &mut Controller, memory: &ImageMemory, limit: u32) {
    run_until(
        ctl,
        memory,
        limit,
        |_, _| {},
        |c| c.channels()[0].state() == RunState::Finished,
    );
}
