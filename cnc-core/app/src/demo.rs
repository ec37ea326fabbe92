//! `cnc demo`: the main job. One machine with every engine of the runtime, embedded in the
//! binary (`scenarios/demo`, no files needed), runs in real time with a spawned PLC process:
//!
//! * application example 3 of seed 003: a master robot carries the workpiece, two slave
//!   robots track its frame and hold their tools on it (channels 0 to 2);
//! * application example 4, PLC-only variant: a robot machines a workpiece on a turntable the
//!   PLC drives; the PLC switches the tracking on M100 / M101 (channel 3);
//! * a cam slave (a lifter) on a rotary conveyor: coupled, rescaled and changed online;
//! * a flying saw cutting the material on its conveyor into equal pieces.
//!
//! The report gives per channel the NC blocks run, the tracking state changes and the
//! largest tracking error; the M-function handshakes; the tick compute time and start
//! lateness (p50/p99/max); the PLC task's timing and overruns and what each station did. The
//! trace (CSV) and its plots (SVG) go to the folder `--out` names, which the report prints.

use crate::demo_plots;
use crate::scenario::runner::{run, RunOptions, RunReport};
use crate::scenario::{Scenario, ScenarioError};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `cnc demo`.
#[derive(Debug, Clone, clap::Args)]
pub struct DemoArgs {
    /// Run exactly N ticks (default: the machine's full cycle, 14.5 s).
    #[arg(long)]
    pub ticks: Option<u64>,
    /// The tick cycle in ms (0.05..=100; default the machine's 1 ms). The machine keeps its
    /// times: its full cycle is still 14.5 s (58,000 ticks at 0.25 ms), the PLC runs every
    /// tick, and what its programs wait for they wait in time.
    #[arg(long)]
    pub cycle_ms: Option<f64>,
    /// Folder for the trace CSV and the plots.
    #[arg(long, default_value = "out/demo")]
    pub out: PathBuf,
    /// Instance name of the HLI segment (`plc get/set/watch` and `cnc diag` find the demo
    /// under the default).
    #[arg(long, default_value = plc_shim::tools::DEFAULT_INSTANCE)]
    pub instance: String,
    /// Lockstep instead of real time (reproducible traces).
    #[arg(long)]
    pub lockstep: bool,
    /// The PLC program in Structured Text (`scenarios/demo/plc.st`, embedded) instead of the
    /// Rust one: the same machine, the same lockstep trace.
    #[arg(long)]
    pub st: bool,
    /// Real-time options of the CNC's tick loop.
    #[command(flatten)]
    pub realtime: plc_shim::realtime::RealtimeOptions,
    /// An OPC UA server beside the demo.
    #[command(flatten)]
    pub opcua: crate::opcua::OpcuaArgs,
}

/// The machine's name: its folder under `scenarios/` and the trace's file name.
const NAME: &str = "demo";

/// The demo's files, scenario first, each under the name the scenario gives it.
macro_rules! embed {
    ($($file:literal),+) => {
        &[$(($file, include_str!(concat!("../../../scenarios/demo/", $file)))),+]
    };
}

const FILES: &[(&str, &str)] = embed!(
    "scenario.toml",
    "master.nc",
    "slave-left.nc",
    "slave-right.nc",
    "robot.nc",
    "seed_example.json",
    "plc.st"
);

/// The `[plc]` lines of the embedded scenario that name the Rust program, and their ST twin.
const RUST_PLC: &str = "program = \"demo-machine\"\nsaw_cuts = 5\n";
const ST_PLC: &str = "st = [\"plc.st\"]\n";

/// The embedded machine.
pub fn scenario() -> Result<Scenario, ScenarioError> {
    scenario_with("")
}

/// The embedded machine with its robots' programs as the manual has them: without the lines
/// that switch continuous path on (`#CONTOUR MODE`, `G261`, `G260` and their comment). The
/// benchmarks compare the two.
pub fn scenario_exact_stop() -> Result<Scenario, ScenarioError> {
    let (main, text) = FILES[0];
    Scenario::parse(&format!("{NAME}/{main}"), text, |relative| {
        FILES
            .iter()
            .find(|(file, _)| *file == relative)
            .map(|(file, text)| {
                let kept: String = text
                    .lines()
                    .filter(|l| !continuous_path_line(l))
                    .map(|l| format!("{l}\n"))
                    .collect();
                (PathBuf::from(format!("{NAME}/{file}")), kept)
            })
            .ok_or_else(|| ScenarioError::Read {
                file: relative.to_string(),
                message: "not embedded in the demo".into(),
            })
    })
}

/// A line the demo adds to the manual's programs for continuous path.
pub fn continuous_path_line(line: &str) -> bool {
    line.starts_with("; continuous path (the demo's addition")
        || line.starts_with("#CONTOUR MODE")
        || line == "G261"
        || line == "G260"
}

/// The embedded machine with its PLC program in Structured Text (`plc.st`), written into
/// `dir` for the PLC process to load.
pub fn scenario_st(dir: &Path) -> Result<Scenario, ScenarioError> {
    let (main, text) = FILES[0];
    if !text.contains(RUST_PLC) {
        return Err(ScenarioError::Read {
            file: format!("{NAME}/{main}"),
            message: format!("its [plc] table no longer reads {RUST_PLC:?}"),
        });
    }
    let program = dir.join("plc.st");
    let written = std::fs::create_dir_all(dir)
        .and_then(|()| std::fs::write(&program, embedded("plc.st").unwrap_or_default()));
    written.map_err(|e| ScenarioError::Read {
        file: program.display().to_string(),
        message: e.to_string(),
    })?;
    let mut s = parse_embedded(&text.replace(RUST_PLC, ST_PLC), Some(&program))?;
    s.name = format!("{NAME}/{main} (PLC in Structured Text)");
    Ok(s)
}

/// The embedded file `name`.
fn embedded(name: &str) -> Option<&'static str> {
    FILES.iter().find(|(f, _)| *f == name).map(|(_, t)| *t)
}

/// The embedded machine with `extra` appended to its scenario file (more axes, a FIFO group:
/// the tests that load the whole machine further).
pub fn scenario_with(extra: &str) -> Result<Scenario, ScenarioError> {
    parse_embedded(&format!("{}\n{extra}", FILES[0].1), None)
}

/// The embedded machine from the scenario text `text`, its other files embedded; the ST
/// program, if it has one, at `st` on disk.
fn parse_embedded(text: &str, st: Option<&Path>) -> Result<Scenario, ScenarioError> {
    let main = FILES[0].0;
    Scenario::parse(&format!("{NAME}/{main}"), text, |relative| {
        FILES
            .iter()
            .find(|(file, _)| *file == relative)
            .map(|(file, text)| match (st, *file) {
                (Some(path), "plc.st") => (path.to_path_buf(), text.to_string()),
                _ => (PathBuf::from(format!("{NAME}/{file}")), text.to_string()),
            })
            .ok_or_else(|| ScenarioError::Read {
                file: relative.to_string(),
                message: "not embedded in the demo".into(),
            })
    })
}

/// Runs the demo.
pub fn main(args: DemoArgs) -> ExitCode {
    let mut scenario = match if args.st {
        scenario_st(&args.out)
    } else {
        scenario()
    } {
        Ok(s) => s,
        Err(e) => {
            eprintln!("cnc demo: {e}");
            return ExitCode::from(1);
        }
    };
    if let Some(ms) = args.cycle_ms {
        if let Err(e) = scenario.set_cycle_ms(ms) {
            eprintln!("cnc demo: --cycle-ms {ms}: {e}");
            return ExitCode::from(2);
        }
    }
    println!(
        "== cnc demo: 4 robot channels, a cam station, a flying saw and a PLC process{} ({} mode, instance {})",
        if args.st { " in Structured Text" } else { "" },
        if args.lockstep { "lockstep" } else { "real-time" },
        args.instance
    );
    let options = RunOptions {
        ticks: args.ticks,
        lockstep: args.lockstep,
        instance: args.instance.clone(),
        scratch: args.out.clone(),
        plc_watchdog_ticks: None,
        plc_restart: false,
        realtime: args.realtime.clone(),
        // The demo's programs name no LOG_FILE; its listings are kept for `cnc diag`.
        log_dir: None,
        opcua: args.opcua.clone(),
    };
    hli_transport::signals::capture();
    let report = match run(&scenario, &options) {
        Ok(report) => report,
        Err(e) => {
            eprintln!("cnc demo: {e}");
            return ExitCode::from(1);
        }
    };
    print!("{}", report.render(false));
    print!("{}", summary(&report));
    crate::scenario::runner::keep_diagnosis("cnc demo", &args.instance, &report);
    let written = write_outputs(&report, &args.out);
    let mut failed = report
        .channels
        .iter()
        .any(|c| c.outcome.starts_with("error"));
    match written {
        Ok(files) => {
            let folder = std::fs::canonicalize(&args.out).unwrap_or(args.out.clone());
            println!("written to {}: {}", folder.display(), files.join(", "));
        }
        Err(e) => {
            eprintln!("cnc demo: {e}");
            failed = true;
        }
    }
    match &report.stop {
        Some(cause) => ExitCode::from(cause.exit_code()),
        None if failed => ExitCode::from(1),
        None => ExitCode::SUCCESS,
    }
}

/// The closing lines: the figures a reader looks for first, one per line.
fn summary(report: &RunReport) -> String {
    let mut out = String::from("== summary\n");
    for c in &report.channels {
        out.push_str(&format!(
            "{:<12} {:<10} blocks {:>3}  tracking state changes {:>2}  M handshakes {}  max tracking error {:.6} mm\n",
            c.name, c.outcome, c.blocks, c.state_changes, c.m_functions_acked, c.max_tracking_error_mm
        ));
    }
    let handshakes: u64 = report.channels.iter().map(|c| c.m_functions_acked).sum();
    out.push_str(&format!(
        "M-function handshakes {handshakes}; acyclic calls answered {}\n",
        report.acyclic_answered
    ));
    let us = |ns: u64| ns as f64 / 1000.0;
    out.push_str(&format!(
        "CNC tick ({} ticks): compute p50 {:.1} us, p99 {:.1} us, max {:.1} us; start lateness p50 {:.1} us, p99 {:.1} us, max {:.1} us\n",
        report.ticks,
        us(report.tick_ns.p50),
        us(report.tick_ns.p99),
        us(report.tick_ns.max),
        us(report.late_ns.p50),
        us(report.late_ns.p99),
        us(report.late_ns.max),
    ));
    match report
        .plc_output
        .lines()
        .find_map(|l| l.strip_prefix("plc: task "))
    {
        Some(task) => out.push_str(&format!("PLC task: {task}\n")),
        None => out.push_str("PLC task: no statistics (the PLC did not end in order)\n"),
    }
    if let Some(wake) = report
        .plc_output
        .lines()
        .find_map(|l| l.strip_prefix("plc: wake-up to done "))
    {
        out.push_str(&format!("PLC wake-up to done: {wake}\n"));
    }
    out
}

/// Writes the trace and its plots into `dir`; returns the file names.
fn write_outputs(report: &RunReport, dir: &Path) -> Result<Vec<String>, String> {
    let csv_name = format!("{NAME}.csv");
    let csv = dir.join(&csv_name);
    report.trace.save(&csv)?;
    let latency = dir.join("latency.md");
    std::fs::write(&latency, report.latency.full())
        .map_err(|e| format!("{}: {e}", latency.display()))?;
    let mut files = vec![csv_name, "latency.md".to_string()];
    files.extend(demo_plots::draw(&csv, dir).map_err(|e| e.to_string())?);
    Ok(files)
}
