//! `cnc run`: the CNC process of a scenario. It creates the HLI segment, spawns the PLC
//! process (a timeline or a built-in program) and ticks the channels, in one of two modes:
//!
//! * **real-time**: tick N starts at the absolute deadline `start + N * cycle` on
//!   CLOCK_MONOTONIC; the PLC runs its cycles as the CNC's "tick done" events wake it;
//! * **lockstep**: tick N starts only once the PLC has run its cycle after tick N-1, so both
//!   sides see each other's writes at fixed ticks and identical runs give bit-identical
//!   traces (the trace time is then the nominal `N * cycle`).
//!
//! ```text
//! create segment ─► spawn plc ─► wait attach ─► for each tick:
//!   [real-time: sleep to deadline | lockstep: wait PLC heartbeat == N]
//!   channels tick ─► heartbeat ─► trace sample ─► answer acyclic calls ─► notify "tick done"
//! ```

use super::file::{Scenario, ScenarioError};
use super::machine::{build, Machine};
use super::trace::Trace;
use crate::stats::Percentiles;
use cnc_core::channel::diagnosis::log_message;
use cnc_os::monotonic;
use core::time::Duration;
use hli_transport::events::{EventLink, Side};
use hli_transport::rpc::AcyclicServer;
use hli_transport::segment::CncSegment;
use spawn::spawn_plc;
use std::path::{Path, PathBuf};
use std::process::{Child, ExitCode};
use tick_loop::{Bounds, Ending, Measured, TickLoop};

mod cycle_guard;
pub mod latency;
mod restart;
mod spawn;
mod tick_loop;

/// Ticks run when neither `--ticks` nor the scenario says: until every channel is idle, at
/// most this many of 1 ms (at another cycle, as many as last as long: 120 s).
pub const DEFAULT_TICK_LIMIT: u64 = 120_000;
/// How long lockstep waits for one PLC cycle before it gives up.
const PLC_CYCLE_WATCHDOG: Duration = Duration::from_secs(10);

/// Arguments of `cnc run`.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// The scenario (TOML).
    pub scenario: PathBuf,
    /// Write the trace CSV here.
    #[arg(long)]
    pub trace: Option<PathBuf>,
    /// Write where the tick time went (every part's p50/p99/max, the overruns, the ten
    /// worst ticks with their parts) to this file (markdown).
    #[arg(long)]
    pub latency_report: Option<PathBuf>,
    /// Run exactly N ticks (channels that finish earlier stay idle).
    #[arg(long)]
    pub ticks: Option<u64>,
    /// The tick cycle in ms, over the scenario's `cycle_ms` (0.05..=100). The scenario keeps
    /// its times: its `ticks` and its timeline's `at_tick` are scaled to the new cycle, and
    /// the PLC task keeps its `[plc] period_ms` (refused when that is not a whole number of
    /// the new cycle).
    #[arg(long)]
    pub cycle_ms: Option<f64>,
    /// Lockstep mode: tick N waits for the PLC's cycle; runs are reproducible bit for bit.
    #[arg(long)]
    pub lockstep: bool,
    /// Instance name of the segment (default: run-<pid>).
    #[arg(long)]
    pub instance: Option<String>,
    /// Print the dynamic-CS diagnosis tables (history and switching log) at the end.
    #[arg(long)]
    pub diagnosis: bool,
    /// Keep every channel's dynamic-CS listing after the run for `cnc diag dyncs` (in
    /// $TMPDIR/cncplc-diag/instance-INSTANCE; `cnc demo` always keeps them).
    #[arg(long)]
    pub keep_diagnosis: bool,
    /// Where `#TRACK CS ON [LOG_FILE=..]` files with a relative name are written.
    #[arg(long, default_value = ".")]
    pub log_dir: PathBuf,
    /// Ticks without a PLC cycle before the CNC declares the PLC lost and stops the machine
    /// (default: the scenario's `plc_watchdog_ticks`, else 100 ms' worth).
    #[arg(long)]
    pub plc_watchdog_ticks: Option<u64>,
    /// A lost PLC stops the machine, but the run goes on and takes a new PLC process on the
    /// same instance (`plc --instance I ...`): the CNC stays up while the PLC restarts. The
    /// run then ends at its tick count or on a signal, not when the channels are idle
    /// (real-time mode only).
    #[arg(long, conflicts_with = "lockstep")]
    pub plc_restart: bool,
    /// Real-time options of the tick loop (over the scenario's `[realtime]`).
    #[command(flatten)]
    pub realtime: plc_shim::realtime::RealtimeOptions,
    /// An OPC UA server beside the run.
    #[command(flatten)]
    pub opcua: crate::opcua::OpcuaArgs,
}

/// How to run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Exactly this many ticks, or until idle (at most [`DEFAULT_TICK_LIMIT`]).
    pub ticks: Option<u64>,
    /// Lockstep instead of real-time.
    pub lockstep: bool,
    /// Segment instance name.
    pub instance: String,
    /// Where a timeline that exists only in memory is written for the PLC process.
    pub scratch: PathBuf,
    /// See [`RunArgs::plc_watchdog_ticks`].
    pub plc_watchdog_ticks: Option<u64>,
    /// See [`RunArgs::plc_restart`].
    pub plc_restart: bool,
    /// Real-time options of the tick loop (over the scenario's).
    pub realtime: plc_shim::realtime::RealtimeOptions,
    /// Where `LOG_FILE`s are written while the run goes on (`None`: only at the end, by the
    /// caller).
    pub log_dir: Option<PathBuf>,
    /// `--opcua [PORT]`: an OPC UA server on the run's instance from the segment's start to
    /// the last tick.
    pub opcua: crate::opcua::OpcuaArgs,
}

/// Why a run stopped before its end.
#[derive(Debug, Clone, PartialEq)]
pub enum StopCause {
    /// The PLC stopped cycling.
    PlcLost {
        /// The tick the CNC noticed it.
        tick: u64,
        /// What happened to the PLC process.
        detail: String,
    },
    /// A CNC-owned header field of the segment changed: someone wrote where only the CNC
    /// writes.
    SegmentCorrupt {
        /// The tick the CNC noticed it.
        tick: u64,
        /// Which field, what the CNC wrote, what it found.
        fault: hli_transport::segment::HeaderFault,
    },
    /// Real time: the mean work of the last 64 ticks reached the cycle (`--cycle-ms` below
    /// what the machine's ticks need).
    CycleTooShort {
        /// The tick it was noticed at.
        tick: u64,
        /// The ticks' mean work, ns.
        work_ns: u64,
        /// The cycle, ns.
        cycle_ns: u64,
    },
    /// SIGINT or SIGTERM.
    Signal {
        /// The tick it was noticed at.
        tick: u64,
        /// Which.
        signal: hli_transport::signals::Termination,
    },
}

impl StopCause {
    /// The exit code `cnc run` ends with: 4 for a lost PLC, 5 for a corrupted segment
    /// header, 6 for a cycle shorter than the ticks' work, 128 + signal for a signal.
    pub fn exit_code(&self) -> u8 {
        match self {
            StopCause::PlcLost { .. } => 4,
            StopCause::SegmentCorrupt { .. } => 5,
            StopCause::CycleTooShort { .. } => 6,
            StopCause::Signal { signal, .. } => signal.exit_code(),
        }
    }

    /// The one line logged when the stop begins.
    pub fn message(&self) -> String {
        match self {
            StopCause::PlcLost { tick, detail } => {
                format!("PLC lost at tick {tick}: {detail}; stopping the machine")
            }
            StopCause::SegmentCorrupt { tick, fault } => {
                format!("{fault} (noticed at tick {tick}); stopping the machine")
            }
            StopCause::CycleTooShort {
                tick,
                work_ns,
                cycle_ns,
            } => format!(
                "the cycle of {:.1} us is shorter than this machine's ticks need: their work was {:.1} us on average over the last 64 ticks (noticed at tick {tick}); stopping the machine (give a longer cycle: --cycle-ms or the scenario's cycle_ms)",
                *cycle_ns as f64 * 1e-3,
                *work_ns as f64 * 1e-3
            ),
            StopCause::Signal { tick, signal } => {
                format!("{} at tick {tick}: stopping the machine", signal.name())
            }
        }
    }
}

/// Default of `plc_watchdog_ticks`.
pub const DEFAULT_PLC_WATCHDOG_TICKS: u64 = 100;
/// Longest controlled stop before the run ends anyway, seconds of ticks.
const STOP_LIMIT_S: f64 = 10.0;

/// One channel at the end of a run.
#[derive(Debug, Clone)]
pub struct ChannelReport {
    /// Name.
    pub name: String,
    /// Final run state and, on error, the line and reason.
    pub outcome: String,
    /// Tracking switching log: tick and event.
    pub tracking: Vec<(u64, String)>,
    /// See [`Machine::max_tracking_error`].
    pub max_tracking_error_mm: f64,
    /// M-function handshakes completed.
    pub m_functions_acked: u64,
    /// NC blocks run.
    pub blocks: u64,
    /// Programs that ran to their end (several when the PLC started the channel again).
    pub programs_ended: u32,
    /// Dynamic-CS state changes (switching on, active, switching off, inactive, error).
    pub state_changes: u64,
    /// The diagnosis tables.
    pub diagnosis: String,
    /// `#TRACK CS ON [LOG_FILE=..]`: where the program asked the diagnosis to go.
    pub log_file: Option<String>,
}

/// Why a run did not happen or did not finish.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The scenario's channels were refused before anything started.
    #[error(transparent)]
    Refused(#[from] ScenarioError),
    /// The segment, the PLC process or the lockstep handshake failed.
    #[error("{0}")]
    Process(String),
}

/// What a run did.
#[derive(Debug)]
pub struct RunReport {
    /// Ticks run.
    pub ticks: u64,
    /// Compute time of a tick, ns.
    pub tick_ns: Percentiles,
    /// The tick's parts, the overruns and the worst ticks.
    pub latency: latency::Latency,
    /// How late a tick started after its deadline (real-time mode), ns.
    pub late_ns: Percentiles,
    /// Per channel.
    pub channels: Vec<ChannelReport>,
    /// Acyclic calls answered.
    pub acyclic_answered: u64,
    /// What the PLC process printed.
    pub plc_output: String,
    /// The trace.
    pub trace: Trace,
    /// Why the run stopped early, if it did.
    pub stop: Option<StopCause>,
    /// Ticks from the stop until every channel and axis stood still (None: not within the
    /// stop limit).
    pub rest_after: Option<u64>,
    /// Real-time options in force in the tick loop.
    pub realtime: Vec<String>,
    /// Axes in error at the end: held where their fault stopped them, not braked.
    pub held_by_fault: Vec<String>,
    /// `--plc-restart`: new PLCs that took over after a loss.
    pub plc_restarts: u64,
    /// What the CNC refused of the PLC's writes and calls, by class.
    pub violations: cnc_core::channel::plc_io::Violations,
    /// `--plc-restart`: the run ended while no PLC ran.
    pub ended_without_plc: bool,
}

/// `cnc run`.
pub fn main(args: RunArgs) -> ExitCode {
    let mut scenario = match Scenario::load(&args.scenario) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("cnc run: {e}");
            return ExitCode::from(2);
        }
    };
    if let Some(ms) = args.cycle_ms {
        if let Err(e) = scenario.set_cycle_ms(ms) {
            eprintln!("cnc run: --cycle-ms {ms}: {e}");
            return ExitCode::from(2);
        }
    }
    let instance = args
        .instance
        .clone()
        .unwrap_or_else(|| format!("run-{}", std::process::id()));
    let options = RunOptions {
        ticks: args.ticks,
        lockstep: args.lockstep,
        scratch: std::env::temp_dir(),
        instance,
        plc_watchdog_ticks: args.plc_watchdog_ticks,
        plc_restart: args.plc_restart,
        realtime: args.realtime.clone(),
        log_dir: Some(args.log_dir.clone()),
        opcua: args.opcua.clone(),
    };
    hli_transport::signals::capture();
    match run(&scenario, &options) {
        Ok(report) => {
            print!("{}", report.render(args.diagnosis));
            if args.keep_diagnosis {
                keep_diagnosis("cnc run", &options.instance, &report);
            }
            if let Some(path) = &args.latency_report {
                if let Err(e) = std::fs::write(path, report.latency.full()) {
                    eprintln!("cnc run: latency report {}: {e}", path.display());
                    return ExitCode::from(1);
                }
                println!("latency report: {}", path.display());
            }
            if let Some(path) = &args.trace {
                if let Err(e) = report.trace.save(path) {
                    eprintln!("cnc run: trace: {e}");
                    return ExitCode::from(1);
                }
                println!("trace: {}", path.display());
            }
            match report.write_log_files(&args.log_dir) {
                Ok(files) => {
                    for file in files {
                        println!("dynamic-CS log: {}", file.display());
                    }
                }
                Err(e) => {
                    eprintln!("cnc run: LOG_FILE: {e}");
                    return ExitCode::from(1);
                }
            }
            if let Some(cause) = &report.stop {
                ExitCode::from(cause.exit_code())
            } else if report.ended_without_plc {
                ExitCode::from(4)
            } else if report
                .channels
                .iter()
                .any(|c| c.outcome.starts_with("error"))
            {
                ExitCode::from(3)
            } else {
                ExitCode::SUCCESS
            }
        }
        Err(e) => {
            eprintln!("cnc run: {e}");
            // A refused scenario is a usage error, found before any process started.
            ExitCode::from(if matches!(e, RunError::Refused(_)) {
                2
            } else {
                1
            })
        }
    }
}

/// Leaves the channels' dynamic-CS listings for `cnc diag dyncs` and says where (a failure
/// is reported and does not fail the run: the report is already out).
pub fn keep_diagnosis(tool: &str, instance: &str, report: &RunReport) {
    if report.channels.is_empty() {
        return;
    }
    match crate::diag_cli::keep_finished(instance, &report.channels) {
        Ok(dir) => println!(
            "dynamic-CS diagnosis: `cnc diag dyncs --instance {instance} --channel N` ({})",
            dir.display()
        ),
        Err(e) => eprintln!("{tool}: diagnosis not kept: {e}"),
    }
}

/// Runs `scenario` as a CNC process with a spawned PLC process.
pub fn run(scenario: &Scenario, options: &RunOptions) -> Result<RunReport, RunError> {
    let mut machine = build(scenario)?;
    run_machine(scenario, &mut machine, options).map_err(RunError::Process)
}

fn run_machine(
    scenario: &Scenario,
    machine: &mut Machine,
    options: &RunOptions,
) -> Result<RunReport, String> {
    let mut link = PlcLink::open(scenario, machine, options)?;
    let opcua = crate::opcua::Beside::start(&options.instance, &options.opcua)?;
    // After spawning: the PLC must not inherit the CNC's scheduling and CPU.
    let realtime = spawn::cnc_realtime(scenario, options).apply("cnc run");
    let bounds = Bounds::of(scenario, options)?;
    let measured = Measured::new(scenario, bounds.rows);
    // Real time: the heartbeat watchdogs start with the loop, so the PLC must be cycling by
    // then, and nothing slow may come between its first cycle and tick 0 (the PLC counts the
    // CNC's silence in cycles once it has seen it tick).
    if let (false, Some(child)) = (options.lockstep, link.child.as_mut()) {
        wait_for_first_cycle(&link.segment, &link.events, child)?;
    }
    // The PLC's client exists now: its segment is mapped here, not in tick 0's calls.
    // A warm-up only: a connection that fails now is tried again by every poll.
    if let Err(e) = link.server.connect() {
        eprintln!("cnc run: acyclic service: connecting before tick 0: {e}");
    }
    let (mut measured, mut ending) =
        TickLoop::new(scenario, options, machine, &mut link, &bounds, measured).run();
    drop(opcua); // stops the server (also when an error above returns early)
    let ticks = machine.ticks();
    let mut plc_output = String::new();
    for child in ending.lost_plcs.drain(..) {
        plc_output.push_str(&wait_for_exit(child)?);
    }
    plc_output.push_str(&link.close(options, &ending, ticks, &bounds)?);
    let cycle_ns = (scenario.cycle_s * 1e9).round() as u64;
    let latency = latency::Latency::of(&measured, cycle_ns, !options.lockstep);
    Ok(RunReport {
        ticks,
        tick_ns: Percentiles::of(&mut measured.tick_ns),
        latency,
        late_ns: if options.lockstep {
            Percentiles::default()
        } else {
            Percentiles::of(&mut measured.late_ns)
        },
        channels: channel_reports(machine),
        acyclic_answered: measured.acyclic_answered,
        plc_output,
        trace: measured.trace,
        stop: ending.stop.map(|(cause, _)| cause),
        rest_after: ending.rest_after,
        realtime,
        plc_restarts: ending.restarts,
        violations: machine.plc_violations(),
        ended_without_plc: ending.without_plc,
        held_by_fault: machine
            .held_by_fault()
            .map(|(name, error)| format!("{name} ({error:?})"))
            .collect(),
    })
}

/// The PLC side of a run: the segment, the events, the acyclic service and the PLC process
/// (none when the scenario has no PLC).
struct PlcLink {
    segment: CncSegment,
    events: EventLink,
    server: AcyclicServer,
    child: Option<Child>,
}

impl PlcLink {
    /// Creates the segment and the services and spawns the PLC; returns once it attached
    /// (real time: once it runs its cycles).
    fn open(
        scenario: &Scenario,
        machine: &Machine,
        options: &RunOptions,
    ) -> Result<PlcLink, String> {
        let timing = hli_transport::segment::CncTiming {
            cycle_ns: (scenario.cycle_s * 1e9).round().clamp(
                f64::from(hli_transport::segment::MIN_CYCLE_NS),
                f64::from(hli_transport::segment::MAX_CYCLE_NS),
            ) as u32,
            lockstep: options.lockstep,
        };
        // The calls' mailbox first: a PLC that finds the segment Ready finds the mailbox.
        let server = AcyclicServer::open(&options.instance).map_err(|e| e.to_string())?;
        let segment = CncSegment::create_with(
            &options.instance,
            scenario.channels.len() as u32,
            machine.axis_images() as u32,
            timing,
        )
        .map_err(|e| e.to_string())?;
        let events = EventLink::open(&options.instance, Side::Cnc).map_err(|e| e.to_string())?;
        let mut child = spawn_plc(scenario, options)?;
        if let Some(child) = child.as_mut() {
            wait_for_attach(&segment, child)?;
        }
        Ok(PlcLink {
            segment,
            events,
            server,
            child,
        })
    }

    /// After the last tick (`ticks` run): closes the segment, so the PLC stops, and returns
    /// what the PLC printed.
    fn close(
        mut self,
        options: &RunOptions,
        ending: &Ending,
        ticks: u64,
        bounds: &Bounds,
    ) -> Result<String, String> {
        // Lockstep: the PLC's cycle after the last tick belongs to the run as every other one
        // (it sees the final state) before the segment closes.
        if options.lockstep && ending.stop.is_none() && !ending.forced {
            if let Some(child) = self.child.as_mut() {
                if let Err(PlcWait::Lost(detail)) = wait_for_plc_cycle(
                    &self.segment,
                    &self.events,
                    child,
                    ticks,
                    bounds.watchdog,
                    bounds.period,
                ) {
                    eprintln!("cnc run: the PLC's last cycle did not come: {detail}");
                }
            }
        }
        drop(self.segment); // marks the segment closed: the PLC stops
        match self.child {
            Some(mut child) => {
                let untrusted = matches!(
                    ending.stop,
                    Some((
                        StopCause::PlcLost { .. } | StopCause::SegmentCorrupt { .. },
                        _
                    ))
                );
                if ending.forced || untrusted {
                    // A lost PLC may be hung, one that wrote over the header may be anything:
                    // neither can be relied on to see the segment close.
                    let _ = child.kill();
                }
                wait_for_exit(child)
            }
            None => Ok(String::new()),
        }
    }
}

/// The per-channel part of the report.
pub fn channel_reports(machine: &Machine) -> Vec<ChannelReport> {
    machine
        .controller()
        .channels()
        .iter()
        .zip(machine.max_tracking_error())
        .map(|(c, &err)| ChannelReport {
            name: c.config().name.clone(),
            outcome: match c.error() {
                Some(e) => format!("error at line {}: {}", e.line, e.message()),
                None => format!("{:?}", c.state()).to_lowercase(),
            },
            tracking: c
                .tracker()
                .log()
                .filter_map(|(tick, event)| Some((*tick, log_message(*tick, event)?)))
                .collect(),
            max_tracking_error_mm: err,
            m_functions_acked: c.m_functions_acked(),
            blocks: c.blocks_executed(),
            programs_ended: c.programs_ended(),
            state_changes: c.tracker().state_changes(),
            diagnosis: c.dyn_cs_diagnosis(),
            log_file: c.log_file().map(str::to_string),
        })
        .collect()
}

impl RunReport {
    /// Writes the diagnosis of every channel whose program named a `LOG_FILE` (relative names
    /// under `dir`; channels naming the same file share it, in channel order). Returns the
    /// files written.
    pub fn write_log_files(&self, dir: &Path) -> Result<Vec<PathBuf>, String> {
        let mut files: Vec<(PathBuf, String)> = Vec::new();
        for c in &self.channels {
            let Some(name) = &c.log_file else { continue };
            let path = dir.join(name);
            match files.iter_mut().find(|(p, _)| *p == path) {
                Some((_, text)) => text.push_str(&c.diagnosis),
                None => files.push((path, c.diagnosis.clone())),
            }
        }
        for (path, text) in &files {
            if let Some(parent) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(parent)
                    .map_err(|e| format!("{}: {e}", parent.display()))?;
            }
            std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
        }
        Ok(files.into_iter().map(|(p, _)| p).collect())
    }

    /// The summary printed at the end of a run.
    pub fn render(&self, diagnosis: bool) -> String {
        let mut out = String::new();
        for c in &self.channels {
            out.push_str(&format!(
                "channel {}: {}; programs ended {}; blocks {}; tracking state changes {}; M functions acknowledged {}; max tracking error (tool point of the actual joints vs the commanded one) {:.6} mm\n",
                c.name, c.outcome, c.programs_ended, c.blocks, c.state_changes, c.m_functions_acked, c.max_tracking_error_mm
            ));
            for (tick, event) in &c.tracking {
                out.push_str(&format!("  {tick} {}\n", event.replace('\n', "\n  ")));
            }
            if diagnosis && !c.tracking.is_empty() {
                out.push_str(&c.diagnosis);
            }
        }
        out.push_str(&self.latency.summary());
        out.push_str(&format!(
            "ticks {}; tick compute p50 {} ns, p99 {} ns, max {} ns; start lateness p50 {} ns, p99 {} ns, max {} ns; acyclic calls answered {}\n",
            self.ticks,
            self.tick_ns.p50,
            self.tick_ns.p99,
            self.tick_ns.max,
            self.late_ns.p50,
            self.late_ns.p99,
            self.late_ns.max,
            self.acyclic_answered
        ));
        if !self.realtime.is_empty() {
            out.push_str(&format!("real-time: {}\n", self.realtime.join(", ")));
        }
        if let Some(cause) = &self.stop {
            let rest = match self.rest_after {
                Some(n) => format!("machine at rest {n} ticks after the stop"),
                None => "machine NOT at rest when the stop limit ran out".into(),
            };
            out.push_str(&format!("stopped: {}; {rest}\n", cause.message()));
        }
        if self.violations.total() > 0 {
            let v = &self.violations;
            out.push_str(&format!(
                "refused from the PLC: semaphore garbage {}, torn payloads {}, transition command garbage {}, BOOL garbage {}, out of range {}, acyclic calls {}\n",
                v.semaphore_garbage, v.torn_payload, v.command_garbage, v.bool_garbage, v.out_of_range, v.refused_calls
            ));
        }
        if self.plc_restarts > 0 || self.ended_without_plc {
            out.push_str(&format!(
                "PLC restarts: {}{}\n",
                self.plc_restarts,
                if self.ended_without_plc {
                    "; the run ended while no PLC ran"
                } else {
                    ""
                }
            ));
        }
        if !self.held_by_fault.is_empty() {
            out.push_str(&format!(
                "axes in error, held where their fault stopped them (not braked, output 0): {}\n",
                self.held_by_fault.join(", ")
            ));
        }
        out.push_str(&self.plc_output);
        out
    }
}

/// Why lockstep stopped waiting for the PLC.
enum PlcWait {
    /// Exited, or no cycle within the watchdog.
    Lost(String),
}

/// The channel reason for a stop on a lost PLC.
const STOP_REASON_PLC: &str = "machine stop: PLC lost";
/// The channel reason for a stop on a corrupted segment header.
const STOP_REASON_SEGMENT: &str = "machine stop: segment header corrupted";
/// The channel reason for a stop on a cycle shorter than the ticks' work.
const STOP_REASON_CYCLE: &str = "machine stop: cycle shorter than the ticks' work";
/// The channel reason for a stop on SIGINT/SIGTERM.
const STOP_REASON_SIGNAL: &str = "machine stop: termination requested";

/// Lockstep: waits until the PLC has run its cycle after tick `tick - 1`; a PLC that exits
/// or runs no cycle for `watchdog` ticks' time (at least 10 s, so a loaded machine is not
/// mistaken for a dead PLC) is lost.
fn wait_for_plc_cycle(
    segment: &CncSegment,
    events: &EventLink,
    child: &mut Child,
    tick: u64,
    watchdog: u64,
    period: Duration,
) -> Result<(), PlcWait> {
    let patience = (period * watchdog.min(u64::from(u32::MAX)) as u32).max(PLC_CYCLE_WATCHDOG);
    let deadline = monotonic::now() + patience;
    while segment.plc_heartbeat() < tick {
        let _ = events.wait(Duration::from_millis(5));
        if let Ok(Some(status)) = child.try_wait() {
            return Err(PlcWait::Lost(format!("the PLC process exited ({status})")));
        }
        if monotonic::now() > deadline {
            return Err(PlcWait::Lost(format!(
                "no PLC cycle for {patience:?}, the process is alive (hung)"
            )));
        }
    }
    Ok(())
}

/// What became of the PLC process: exited (how), or alive without cycling.
fn describe_plc(
    child: &mut Child,
    exited: Option<std::process::ExitStatus>,
    silent: u64,
) -> String {
    match exited.or_else(|| child.try_wait().ok().flatten()) {
        Some(status) => format!("the PLC process exited ({status})"),
        None => format!("no PLC cycle for {silent} ticks, the process is alive (hung)"),
    }
}

/// Waits (bounded) until the PLC process has attached to the segment.
pub fn wait_for_attach(segment: &CncSegment, child: &mut Child) -> Result<(), String> {
    let watchdog = monotonic::now() + Duration::from_secs(20);
    let plc_pid = core::mem::offset_of!(hli::layout::HliSegmentHeader, plc_pid);
    loop {
        if segment.header().field::<u32>(plc_pid).load() != 0 {
            return Ok(());
        }
        if let Ok(Some(status)) = child.try_wait() {
            return Err(format!("the PLC process exited before attaching: {status}"));
        }
        if monotonic::now() > watchdog {
            let _ = child.kill();
            return Err("the PLC process did not attach within 20 s".into());
        }
        monotonic::sleep_until(monotonic::now() + Duration::from_millis(1));
    }
}

/// Real-time start: beats and announces ticks until the PLC has run its first cycle, so the
/// timed loop does not start while the PLC is still opening its services (attaching comes
/// before that, and under load the gap can be longer than a short run).
pub fn wait_for_first_cycle(
    segment: &CncSegment,
    events: &EventLink,
    child: &mut Child,
) -> Result<(), String> {
    let watchdog = monotonic::now() + Duration::from_secs(20);
    while segment.plc_heartbeat() == 0 {
        segment.beat();
        let _ = events.notify();
        if let Ok(Some(status)) = child.try_wait() {
            return Err(format!(
                "the PLC process exited before its first cycle: {status}"
            ));
        }
        if monotonic::now() > watchdog {
            let _ = child.kill();
            return Err("the PLC process did not run a cycle within 20 s of attaching".into());
        }
        let _ = events.wait(Duration::from_millis(1));
    }
    Ok(())
}

/// Waits (bounded) for the PLC process to stop and returns what it printed.
pub fn wait_for_exit(mut child: Child) -> Result<String, String> {
    let watchdog = monotonic::now() + Duration::from_secs(10);
    loop {
        match child.try_wait() {
            Ok(Some(_)) => break,
            Ok(None) if monotonic::now() > watchdog => {
                // Killed, and the run still reports: what the PLC printed is not worth the
                // CNC's report and trace.
                let _ = child.kill();
                let _ = child.wait();
                return Ok("plc: did not stop within 10 s of the CNC closing; killed\n".into());
            }
            Ok(None) => monotonic::sleep_until(monotonic::now() + Duration::from_millis(2)),
            Err(e) => return Err(e.to_string()),
        }
    }
    let mut text = String::new();
    if let Some(mut out) = child.stdout.take() {
        use std::io::Read;
        let _ = out.read_to_string(&mut text);
    }
    Ok(text)
}
