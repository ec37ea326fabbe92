//! Command line of the PLC process, shared by the `plc` binary and `cnc plc` (which the
//! demo spawns, so that the single `cargo run -p cnc-app` builds everything it needs).

use crate::programs::turntable::{Turntable, Variant};
use crate::programs::RotaryTableMaster;
use crate::runtime::{PlcProgram, PlcRuntime};
use crate::timeline::Timeline;
use core::time::Duration;
use std::process::ExitCode;

/// The `plc` command line: run a PLC program, or a tool on a running CNC's image.
#[derive(Debug, Clone, clap::Parser)]
#[command(
    name = "plc",
    about = "PLC process attached to a CNC's HLI segment, and tools to read and write its image",
    args_conflicts_with_subcommands = true
)]
pub struct PlcCli {
    /// A tool instead of a PLC program.
    #[command(subcommand)]
    pub tool: Option<crate::tools::ToolCommand>,
    /// The PLC program to run.
    #[command(flatten)]
    pub run: PlcArgs,
}

/// How a PLC program is hosted: which CNC, watchdog, task period, real-time options. Shared
/// by the `plc` binary and PLC programs in users' crates ([`host`]).
#[derive(Debug, Clone, clap::Args)]
pub struct HostArgs {
    /// CNC instance to attach to.
    #[arg(long, default_value = crate::tools::DEFAULT_INSTANCE)]
    pub instance: String,
    /// Watchdog: CNC cycles (the cycle the CNC announces in the header) without a CNC
    /// heartbeat before the CNC counts as lost; a CNC process that is gone is noticed two
    /// cycles after its last tick. In lockstep and before the first tick the CNC has 10 s.
    #[arg(long, default_value_t = crate::watchdog::DEFAULT_WATCHDOG_CYCLES,
          value_parser = clap::value_parser!(u32).range(1..))]
    pub watchdog_cycles: u32,
    /// Task cycle as a multiple of the NC tick: run the program every N ticks (the heartbeat
    /// still follows every tick, so lockstep works with any N).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub period_ticks: u64,
    /// Stop after this many cycles.
    #[arg(long)]
    pub max_cycles: Option<u64>,
    /// Real-time options of the PLC's cycle.
    #[command(flatten)]
    pub realtime: crate::realtime::RealtimeOptions,
}

/// Arguments of the PLC process.
#[derive(Debug, Clone, clap::Args)]
pub struct PlcArgs {
    /// Where and how the program runs.
    #[command(flatten)]
    pub host: HostArgs,
    /// Built-in program: `rotary-table` (PLC as dynamic-CS master of channel 0),
    /// `turntable-hybrid`, `turntable-plc-only`, `cam-conveyor`, `fifo-stream`, `saw-cut` or
    /// `demo-machine` (the machine of `cnc demo`).
    #[arg(long, default_value = "rotary-table")]
    pub program: String,
    /// Run this timeline (TOML, see `plc_shim::timeline`) instead of a built-in program.
    #[arg(long)]
    pub timeline: Option<std::path::PathBuf>,
    /// The CNC cycle the timeline's `at_tick` counts ticks of (ms, 0.05..=100; `cnc run`
    /// passes its scenario's `cycle_ms`): a CNC running another cycle has them scaled to the
    /// same time. Without it `at_tick` counts the CNC's ticks, whatever their cycle.
    #[arg(long, requires = "timeline", value_parser = cycle_ms)]
    pub timeline_cycle_ms: Option<f64>,
    /// Run these Structured Text files (every PROGRAM in them, each cycle) instead of a
    /// built-in program (docs/plc-st.md).
    #[arg(long, num_args = 1.., conflicts_with = "timeline")]
    pub st: Vec<std::path::PathBuf>,
    /// Position file of `fifo-stream` (CSV, or binary `.fifo`; see `plc_shim::fifo_file`).
    #[arg(long)]
    pub file: Option<std::path::PathBuf>,
    /// FIFO group of `fifo-stream`.
    #[arg(long, default_value_t = 0)]
    pub fifo_group: u32,
    /// Override `fifo-stream` sets before the start, percent.
    #[arg(long)]
    pub fifo_override: Option<f64>,
    /// Cuts `saw-cut` (and the saw of `demo-machine`) makes.
    #[arg(long, default_value_t = 20)]
    pub saw_cuts: usize,
    /// Piece length of `saw-cut` and `demo-machine`, mm.
    #[arg(long, default_value_t = 500.0)]
    pub saw_length: f64,
    /// Conveyor speed of `saw-cut` and `demo-machine`, mm/s.
    #[arg(long, default_value_t = 200.0)]
    pub saw_speed: f64,
    /// Table speed of `rotary-table`, degree per cycle.
    #[arg(long, default_value_t = 0.01)]
    pub deg_per_cycle: f64,
}

/// A cycle in ms: finite, 0.05..=100 (the CNC's range).
fn cycle_ms(text: &str) -> Result<f64, String> {
    let ms: f64 = text.parse().map_err(|e| format!("{e}"))?;
    if ms.is_finite() && (0.05..=100.0).contains(&ms) {
        Ok(ms)
    } else {
        Err(format!("{ms} ms: must lie in 0.05..=100"))
    }
}

/// Names of the built-in programs.
pub const BUILT_IN_PROGRAMS: &[&str] = &[
    "rotary-table",
    "turntable-hybrid",
    "turntable-plc-only",
    "cam-conveyor",
    "fifo-stream",
    "saw-cut",
    "demo-machine",
];

/// The built-in programs with a flying saw (they take `--saw-cuts`, `--saw-length`,
/// `--saw-speed`).
pub const SAW_PROGRAMS: &[&str] = &["saw-cut", "demo-machine"];

/// Runs a tool, or the PLC process (exit code 0 when the CNC closed in order).
pub fn main(cli: PlcCli) -> ExitCode {
    match cli.tool {
        Some(tool) => crate::tools::main(tool),
        None => run(cli.run),
    }
}

/// Runs the PLC process; exit code 0 when the CNC closed in order.
pub fn run(args: PlcArgs) -> ExitCode {
    if !args.st.is_empty() {
        let loaded =
            crate::st::StProgram::load(&args.st, args.host.period_ticks).and_then(|mut p| {
                // Its variables for `plc get|set|watch` (removed again when the PLC ends).
                p.publish_on(&args.host.instance)?;
                Ok(p)
            });
        return match loaded {
            Ok(mut program) => host(&mut program, &args.host),
            Err(e) => {
                eprint!("{e}");
                ExitCode::from(2)
            }
        };
    }
    let mut program: Box<dyn PlcProgram> = match &args.timeline {
        Some(path) => match Timeline::load(path) {
            Ok(mut t) => {
                if let Some(ms) = args.timeline_cycle_ms {
                    t.count_ticks_of((ms * 1e6).round() as u64);
                }
                Box::new(t)
            }
            Err(e) => {
                eprintln!("plc: {e}");
                return ExitCode::from(2);
            }
        },
        None => match built_in(&args) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("plc: {e}");
                return ExitCode::from(2);
            }
        },
    };
    host(program.as_mut(), &args.host)
}

/// The built-in program `args.program` with its arguments (the PLC process runs it; an
/// in-process run of a scenario runs it in the CNC's process).
pub fn built_in(args: &PlcArgs) -> Result<Box<dyn PlcProgram>, String> {
    if !args.st.is_empty() {
        let program = crate::st::StProgram::load(&args.st, args.host.period_ticks)?;
        return Ok(Box::new(program));
    }
    Ok(match args.program.as_str() {
        "rotary-table" => Box::new(RotaryTableMaster::new(0, args.deg_per_cycle, 200)),
        "turntable-hybrid" => Box::new(Turntable::new(Variant::Hybrid)),
        "turntable-plc-only" => Box::new(Turntable::new(Variant::PlcOnly)),
        "cam-conveyor" => Box::new(crate::programs::cam_conveyor::CamConveyor::new()),
        "fifo-stream" => Box::new(fifo_stream(args).map_err(|e| format!("fifo-stream: {e}"))?),
        "saw-cut" => Box::new(crate::programs::saw_cut::SawCut::new(
            args.saw_cuts,
            args.saw_length,
            args.saw_speed,
        )),
        "demo-machine" => Box::new(crate::programs::demo_machine::DemoMachine::new(
            args.saw_cuts,
            args.saw_length,
            args.saw_speed,
        )),
        other => {
            return Err(format!(
                "unknown program {other:?} (known: {BUILT_IN_PROGRAMS:?})"
            ))
        }
    })
}

/// The built-in program of a scenario's `[plc] program` and its arguments, as the PLC
/// process would parse them.
pub fn built_in_from(name: &str, extra: &[String]) -> Result<Box<dyn PlcProgram>, String> {
    use clap::Parser;
    let argv = ["plc", "--program", name]
        .into_iter()
        .map(str::to_string)
        .chain(extra.iter().cloned());
    let cli = PlcCli::try_parse_from(argv).map_err(|e| e.to_string())?;
    built_in(&cli.run)
}

/// Attaches to the CNC `args` names and runs `program` until the CNC ends, is lost, a signal
/// arrives or the cycle limit is reached; prints the end, the task statistics and the
/// program's summary. Exit codes: 0 the CNC closed (or the limit), 1 no CNC or a service
/// failed, 3 the CNC was lost, 5 the segment header was corrupted, 6 another PLC took over,
/// 128 + signal number on SIGINT/SIGTERM.
///
/// A PLC program in a user's crate is a type implementing [`PlcProgram`] and a `main` that
/// parses [`HostArgs`] (flattened into its own arguments) and calls this (see
/// `examples/plc-shuttle`).
pub fn host(program: &mut dyn PlcProgram, args: &HostArgs) -> ExitCode {
    let mut runtime = match PlcRuntime::attach(
        &args.instance,
        args.watchdog_cycles,
        Duration::from_millis(10),
    ) {
        Ok(runtime) => runtime,
        Err(e) => {
            cnc_os::stdio::line_err(&format!("plc: {e}"));
            return ExitCode::from(1);
        }
    };
    let realtime = args.realtime.apply("plc");
    if !realtime.is_empty() {
        cnc_os::stdio::line_out(&format!("plc: real-time {}", realtime.join(", ")));
    }
    runtime.set_period_ticks(args.period_ticks);
    runtime.set_wake(args.realtime.wake.unwrap_or_default());
    hli_transport::signals::capture();
    match runtime.run(program, args.max_cycles) {
        Ok(summary) => {
            cnc_os::stdio::line_out(&report(&summary, program));
            runtime.detach();
            let (code, why) = ending(&summary.end);
            if let Some(why) = why {
                cnc_os::stdio::line_err(&format!("plc: {why}"));
            }
            ExitCode::from(code)
        }
        Err(e) => {
            cnc_os::stdio::line_err(&format!("plc: {e}"));
            ExitCode::from(1)
        }
    }
}

/// The run's report: cycles, how it ended, the task's timing and the program's summary.
fn report(summary: &crate::runtime::RunSummary, program: &dyn PlcProgram) -> String {
    let w = &summary.wake_to_done;
    format!(
        "plc: {} cycles, ended by {:?}\nplc: task {}\n\
         plc: wake-up to done {} cycles, p50 {:.0} us p99 {:.0} us max {:.1} us\n{}{}{}",
        summary.cycles(),
        summary.end,
        summary.stats,
        w.cycles,
        w.quantile_us(0.5),
        w.quantile_us(0.99),
        w.max_ns as f64 / 1e3,
        due_to_woken(&summary.due_to_woken),
        summary.worst.render(),
        program.summary()
    )
}

/// The line of the ticks' due time to the PLC woken (real time), or nothing.
fn due_to_woken(d: &crate::runtime::CycleStats) -> String {
    if d.cycles == 0 {
        return String::new();
    }
    format!(
        "plc: tick due to woken {} cycles, p50 {:.0} us p99 {:.0} us max {:.1} us\n",
        d.cycles,
        d.quantile_us(0.5),
        d.quantile_us(0.99),
        d.max_ns as f64 / 1e3
    )
}

/// The exit code of a run that ended with `end`, and what to say about it.
fn ending(end: &crate::runtime::RunEnd) -> (u8, Option<String>) {
    use crate::runtime::RunEnd;
    match end {
        RunEnd::CncLost(loss) => (
            3,
            Some(format!(
                "CNC lost: {loss}; the last cycle ran not operational"
            )),
        ),
        RunEnd::SegmentCorrupt(fault) => (
            5,
            Some(format!("{fault}; the last cycle ran not operational")),
        ),
        RunEnd::Replaced(pid) => (
            6,
            Some(format!("PLC process {pid} took over the segment; stopping")),
        ),
        RunEnd::Signal(signal) => (
            signal.exit_code(),
            Some(format!("stopped by {}", signal.name())),
        ),
        RunEnd::ProgramHalted => (
            7,
            Some("the program stopped on a fault (above); the CNC stops as for a lost PLC".into()),
        ),
        _ => (0, None),
    }
}

fn fifo_stream(args: &PlcArgs) -> Result<crate::programs::fifo_stream::FifoStream, String> {
    let file = args
        .file
        .as_ref()
        .ok_or("needs --file (the position file)")?;
    let mut p = crate::programs::fifo_stream::FifoStream::new(file, args.fifo_group)
        .map_err(|e| e.to_string())?;
    if let Some(percent) = args.fifo_override {
        if !(0.0..=100.0).contains(&percent) {
            return Err(format!("--fifo-override {percent}: 0 to 100 percent"));
        }
        p.override_ppm = Some((percent * 1e4).round() as u32);
    }
    Ok(p)
}
