//! The PLC process a run spawns: the scenario's timeline, program or ST files, its task
//! period, its watchdog and real-time options as flags.

use super::RunOptions;
use crate::scenario::file::{PlcSetup, Scenario};
use plc_shim::realtime::RealtimeOptions;
use std::path::Path;
use std::process::{Child, Command, Stdio};

/// Spawns the scenario's PLC (`cnc plc ...`); `None` when it has none.
pub(super) fn spawn_plc(
    scenario: &Scenario,
    options: &RunOptions,
) -> Result<Option<Child>, String> {
    let mut command = Command::new(std::env::current_exe().map_err(|e| e.to_string())?);
    command.args(["plc", "--instance", &options.instance]);
    match &scenario.plc {
        PlcSetup::None => return Ok(None),
        PlcSetup::Timeline { path, text, .. } => {
            let file = if path.is_file() {
                path.clone()
            } else {
                // Embedded scenario: hand the PLC process a copy on disk.
                let file = options
                    .scratch
                    .join(format!("{}-timeline.toml", options.instance));
                write_file(&file, text)?;
                file
            };
            command.arg("--timeline").arg(file);
            // Its at_tick count ticks of the file's cycle, whatever the run's.
            command
                .arg("--timeline-cycle-ms")
                .arg(format!("{}", scenario.file_cycle_s * 1e3));
        }
        PlcSetup::Program(p, args) => {
            command.args(["--program", p]).args(args);
        }
    }
    let period = scenario.plc_period_ticks();
    if period > 1 {
        command.args(["--period-ticks", &period.to_string()]);
    }
    // The PLC's watchdog on the CNC keeps its default time (40 cycles of 1 ms) at any cycle.
    let default = plc_shim::watchdog::DEFAULT_WATCHDOG_CYCLES;
    let cycles = (f64::from(default) * 1e-3 / scenario.cycle_s)
        .round()
        .max(1.0) as u32;
    if cycles != default {
        command.args(["--watchdog-cycles", &cycles.to_string()]);
    }
    // The scenario's `[realtime_plc]`, else what the CNC's own options imply for its PLC; the
    // wake path is always the CNC's (both ends must use the same).
    let cnc = cnc_realtime(scenario, options);
    let mut plc = scenario.realtime_plc.over(&cnc.for_plc());
    plc.wake = cnc.wake;
    command.args(plc.to_args());
    command
        .stdout(Stdio::piped())
        .stdin(Stdio::null())
        .spawn()
        .map(Some)
        .map_err(|e| format!("spawning the PLC: {e}"))
}

/// The CNC's real-time options: the flags over the scenario's `[realtime]` (the one place
/// the CNC's tick loop, its report and the PLC it spawns take them from).
pub(super) fn cnc_realtime(scenario: &Scenario, options: &RunOptions) -> RealtimeOptions {
    options.realtime.over(&scenario.realtime)
}

fn write_file(path: &Path, text: &str) -> Result<(), String> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}
