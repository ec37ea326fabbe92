//! `cnc demo`: the seed's application examples 3 and 4 end to end, in real-time mode, from
//! the scenarios embedded in the binary (no files needed):
//!
//! 1. example 3: a master robot carries the workpiece, two slave robots track its frame and
//!    hold their tools on it;
//! 2. example 4 (PLC-only variant): a robot machines a workpiece on a turning table; a spawned
//!    PLC process switches the tracking on and off through the transition when the NC program
//!    asks with M100/M101, and commands the table angle every cycle.
//!
//! Each run prints per channel the tracking switching log and the largest tracking error, the
//! M-function handshakes completed, the tick compute time and start lateness (p50/p99/max) and
//! what the PLC did; the traces go to the folder `--out` names.

use crate::app::scenario::runner::{run, RunOptions};
use crate::app::scenario::{Scenario, ScenarioError};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `cnc demo`.
#[derive(Debug, Clone, clap::Args)]
pub struct DemoArgs {
    /// Ticks per example (default: until its programs end).
    #[arg(long)]
    pub ticks: Option<u64>,
    /// Folder for the trace CSVs.
    #[arg(long, default_value = "out/demo")]
    pub out: PathBuf,
    /// Instance name prefix (default: demo-<pid>).
    #[arg(long)]
    pub instance: Option<String>,
    /// Lockstep instead of real time (reproducible traces).
    #[arg(long)]
    pub lockstep: bool,
    /// Real-time options of the CNC's tick loop.
    #[command(flatten)]
    pub realtime: plc_shim::realtime::RealtimeOptions,
}

/// A scenario built into the binary: its name and its files (scenario first).
struct Embedded {
    name: &'static str,
    files: &'static [(&'static str, &'static str)],
}

macro_rules! embed {
    ($dir:literal: $($file:literal),+) => {
        &[$(($file, include_str!(concat!("../../../scenarios/", $dir, "/", $file)))),+]
    };
}

const EXAMPLES: [Embedded; 2] = [
    Embedded {
        name: "example3-moving-workpiece",
        files: embed!("example3-moving-workpiece":
            "scenario.toml", "master.nc", "slave-left.nc", "slave-right.nc"),
    },
    Embedded {
        name: "example4-turntable-plc",
        files: embed!("example4-turntable-plc": "scenario.toml", "robot.nc", "plc.toml"),
    },
];

impl Embedded {
    fn scenario(&self) -> Result<Scenario, ScenarioError> {
        let (main, text) = self.files[0];
        let name = format!("{}/{main}", self.name);
        Scenario::parse(&name, text, |relative| {
            self.files
                .iter()
                .find(|(file, _)| *file == relative)
                .map(|(file, text)| {
                    (
                        PathBuf::from(format!("{}/{file}", self.name)),
                        text.to_string(),
                    )
                })
                .ok_or_else(|| ScenarioError::Read {
                    file: relative.to_string(),
                    message: "not embedded in the demo".into(),
                })
        })
    }
}

/// Runs the demo.
pub fn main(args: DemoArgs) -> ExitCode {
    let prefix = args
        .instance
        .clone()
        .unwrap_or_else(|| format!("demo-{}", std::process::id()));
    let mut failed = false;
    let mut stopped = None;
    hli::signals::capture();
    for (i, example) in EXAMPLES.iter().enumerate() {
        if stopped.is_some() {
            break;
        }
        println!(
            "== {} ({} mode)",
            example.name,
            if args.lockstep {
                "lockstep"
            } else {
                "real-time"
            }
        );
        let scenario = match example.scenario() {
            Ok(s) => s,
            Err(e) => {
                eprintln!("cnc demo: {e}");
                return ExitCode::from(1);
            }
        };
        let options = RunOptions {
            ticks: args.ticks,
            lockstep: args.lockstep,
            instance: format!("{prefix}-{i}"),
            scratch: args.out.clone(),
            plc_watchdog_ticks: None,
            realtime: args.realtime.clone(),
        };
        match run(&scenario, &options) {
            Ok(report) => {
                print!("{}", report.render(false));
                // A stop (signal, lost PLC) ends the demo after this example's trace.
                stopped = report.stop.as_ref().map(|c| c.exit_code());
                failed |= report
                    .channels
                    .iter()
                    .any(|c| c.outcome.starts_with("error"));
                let path = args.out.join(format!("{}.csv", example.name));
                match report.trace.save(&path) {
                    Ok(()) => println!("trace: {}", path.display()),
                    Err(e) => {
                        eprintln!("cnc demo: {e}");
                        failed = true;
                    }
                }
            }
            Err(e) => {
                eprintln!("cnc demo: {}: {e}", example.name);
                failed = true;
            }
        }
    }
    let folder = std::fs::canonicalize(&args.out).unwrap_or(args.out);
    println!("traces written to {}", folder.display());
    if let Some(code) = stopped {
        ExitCode::from(code)
    } else if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
