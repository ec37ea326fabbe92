//! `cnc hli-demo`, the HLI exercise: the CNC process creates the HLI segment, spawns a real PLC
//! process and runs a real-time tick loop (absolute deadlines) in which both sides exchange
//! the control units of the specification: the PLC acts as master of channel 0's dynamic
//! coordinate system (a rotary table, the seed's example 4 in its PLC-only form), switches
//! tracking on through the transition, the CNC consumes every command, reports state and
//! request data back, announces M functions that the PLC acknowledges, and answers acyclic
//! calls. The CNC's part of the tracking is a plain ramp here so that every handshake and the
//! axis commands are exercised without channels; `cnc demo` runs the real channels.

use crate::axis::{AxisConfig, AxisSet};
use crate::scenario::runner::{wait_for_attach, wait_for_exit, wait_for_first_cycle};
use crate::stats::Percentiles;
use hli::enums::{DynCsCommand, DynCsState};
use hli::layout::{HliAxis, HliAxisLrState, HliCoordinateSystemInt, HliMFunctionRequest};
use hli::rpc::{handle_read_axis_state, AcyclicServer, CallKind};
use hli::segment::CncSegment;
use hli::views::CncView;
use hli::PlaceExt;
use std::io::Write as _;
use std::path::PathBuf;
use std::process::{Child, Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

/// Arguments of `cnc hli-demo`.
#[derive(Debug, Clone, clap::Args)]
pub struct DemoArgs {
    /// Ticks to run.
    #[arg(long, default_value_t = 3000)]
    pub ticks: u64,
    /// Tick period in microseconds.
    #[arg(long, default_value_t = 1000)]
    pub cycle_us: u64,
    /// Folder for the trace CSV.
    #[arg(long, default_value = "out/hli-demo")]
    pub out: PathBuf,
    /// Instance name (default: demo-<pid>).
    #[arg(long)]
    pub instance: Option<String>,
    /// Announce an M function every N ticks.
    #[arg(long, default_value_t = 500)]
    pub m_every: u64,
}

/// One row of the trace, recorded into a pre-allocated buffer.
#[derive(Debug, Clone, Copy, Default)]
struct TraceRow {
    tick: u64,
    time_ns: u64,
    commanded_c: i32,
    table_axis: i32,
    display_c: i32,
    state: u32,
}

/// Counters of the run.
#[derive(Debug, Default)]
struct Counters {
    commands: u64,
    commands_while_disabled: u64,
    requests_published: u64,
    requests_not_taken: u64,
    transitions: u64,
    m_announced: u64,
    m_acked: u64,
    m_stale_acks: u64,
    acyclic_answered: u64,
    violations: u64,
}

/// The CNC side of tracking in this demo: a linear in/out ramp over the filter ticks.
#[derive(Debug)]
struct TrackingRamp {
    state: DynCsState,
    progress: u32,
    filter: u32,
}

impl TrackingRamp {
    fn weight(&self) -> f64 {
        match self.state {
            DynCsState::Active => 1.0,
            DynCsState::Activating => f64::from(self.progress) / f64::from(self.filter.max(1)),
            DynCsState::Deactivating => {
                1.0 - f64::from(self.progress) / f64::from(self.filter.max(1))
            }
            DynCsState::Inactive | DynCsState::Error => 0.0,
        }
    }

    fn command(&mut self, command: DynCsCommand, filter: u32) {
        self.state = match (self.state, command) {
            (DynCsState::Inactive, DynCsCommand::Activate) => DynCsState::Activating,
            (DynCsState::Active, DynCsCommand::Deactivate) => DynCsState::Deactivating,
            _ => DynCsState::Error, // e.g. switching on while on
        };
        self.progress = 0;
        self.filter = filter;
    }

    fn step(&mut self) {
        if matches!(
            self.state,
            DynCsState::Activating | DynCsState::Deactivating
        ) {
            self.progress += 1;
            if self.progress >= self.filter {
                self.state = match self.state {
                    DynCsState::Activating => DynCsState::Active,
                    _ => DynCsState::Inactive,
                };
            }
        }
    }
}

fn spawn_plc(instance: &str) -> std::io::Result<Child> {
    Command::new(std::env::current_exe()?)
        .args(["plc", "--instance", instance, "--program", "rotary-table"])
        .stdout(Stdio::piped())
        .stdin(Stdio::null())
        .spawn()
}

/// Runs the demo; prints the summary and returns the exit code.
pub fn main(args: DemoArgs) -> ExitCode {
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("cnc hli-demo: {message}");
            ExitCode::from(1)
        }
    }
}

fn run(args: &DemoArgs) -> Result<(), String> {
    let instance = args
        .instance
        .clone()
        .unwrap_or_else(|| format!("demo-{}", std::process::id()));
    let segment = CncSegment::create(&instance, 1, 1).map_err(|e| e.to_string())?;
    if let Some(stale) = segment.replaced_stale() {
        println!("replaced a stale segment of crashed CNC pid {}", stale.pid);
    }
    let events = hli::events::EventLink::open(&instance, hli::events::Side::Cnc)
        .map_err(|e| e.to_string())?;
    let server = AcyclicServer::open(&instance).map_err(|e| e.to_string())?;
    let mut child = spawn_plc(&instance).map_err(|e| format!("spawning the PLC: {e}"))?;
    println!(
        "cnc: segment {} ({} bytes), PLC process {} spawned",
        segment.name(),
        segment.mapped_size(),
        child.id()
    );
    wait_for_attach(&segment, &mut child)?;
    wait_for_first_cycle(&segment, &events, &mut child)?;

    let view = CncView::new(segment.memory());
    let mut command_rx = view.dyn_cs_command(0).map_err(|e| e.to_string())?;
    let request_tx = view.dyn_cs_request(0).map_err(|e| e.to_string())?;
    let mut transition_rx = view.dyn_cs_transition(0).map_err(|e| e.to_string())?;
    let m_tx = view.m_function_request(0).map_err(|e| e.to_string())?;
    let mut ack_rx = view.m_function_ack(0).map_err(|e| e.to_string())?;
    let lr_state = view
        .axis(0)
        .map_err(|e| e.to_string())?
        .field::<HliAxisLrState>(core::mem::offset_of!(HliAxis, lr_state));
    // The rotary table: a real axis (simulated drive) that the PLC powers and turns.
    let mut axes = AxisSet::new(
        vec![AxisConfig::rotary("C", 1)],
        args.cycle_us.max(1) as f64 * 1e-6,
    )
    .map_err(|e| e.to_string())?;
    axes.prime(&view);

    let ticks = args.ticks as usize;
    let mut trace = vec![TraceRow::default(); ticks];
    let mut tick_ns = vec![0u64; ticks];
    let mut late_ns = vec![0u64; ticks];
    let mut state_changes: Vec<(u64, DynCsState)> = Vec::with_capacity(64);
    let mut ack_latency_ticks: Vec<u64> =
        Vec::with_capacity(ticks / args.m_every.max(1) as usize + 1);
    let mut counters = Counters::default();
    let mut ramp = TrackingRamp {
        state: DynCsState::Inactive,
        progress: 0,
        filter: 0,
    };
    let mut applied: HliCoordinateSystemInt = bytemuck::Zeroable::zeroed();
    let mut outstanding_m: Option<(u32, u64)> = None;
    let period = Duration::from_micros(args.cycle_us.max(1));
    let start = Instant::now();

    for tick in 0..args.ticks {
        // Real-time mode: sleep to the absolute deadline of this tick.
        let deadline = start + period * (tick as u32);
        let now = Instant::now();
        if deadline > now {
            std::thread::sleep(deadline - now);
        }
        let t0 = Instant::now();
        late_ns[tick as usize] = t0.saturating_duration_since(deadline).as_nanos() as u64;
        segment.beat();

        let before = ramp.state;
        match transition_rx.try_take() {
            Ok(Some((command, params))) => {
                counters.transitions += 1;
                ramp.command(command, params.filter_max_ticks);
            }
            Ok(None) => {}
            Err(_) => counters.violations += 1,
        }
        ramp.step();
        if ramp.state != before && state_changes.len() < state_changes.capacity() {
            state_changes.push((tick, ramp.state));
        }
        let _ = view.set_dyn_cs_state(0, ramp.state);

        let enabled = matches!(view.dyn_cs_enabled(0), Ok(Ok(true)));
        match command_rx.try_take() {
            Ok(Some(cs)) if enabled => {
                applied = cs;
                counters.commands += 1;
            }
            Ok(Some(_)) => counters.commands_while_disabled += 1,
            Ok(None) => {}
            Err(_) => counters.violations += 1,
        }
        match request_tx.try_send(&applied) {
            Ok(()) => counters.requests_published += 1,
            Err(_) => counters.requests_not_taken += 1,
        }

        // The table axis turns under the PLC's commands; the display shows the tracked share.
        axes.tick(&view);
        let table = lr_state.read();
        let commanded_c = applied.rotation[2];
        let display_c = (f64::from(commanded_c) * ramp.weight()).round() as i32;

        if args.m_every > 0 && tick % args.m_every == args.m_every - 1 && outstanding_m.is_none() {
            let id = (counters.m_announced + 1) as u32;
            let request = HliMFunctionRequest {
                m_code: 100 + (id as i32 % 2),
                block_nr: id as i32 * 10,
                request_id: id,
            };
            if m_tx.try_send(&request).is_ok() {
                counters.m_announced += 1;
                outstanding_m = Some((id, tick));
            }
        }
        match ack_rx.try_take() {
            Ok(Some(ack)) => match outstanding_m {
                Some((id, since)) if ack.request_id == id => {
                    counters.m_acked += 1;
                    if ack_latency_ticks.len() < ack_latency_ticks.capacity() {
                        ack_latency_ticks.push(tick - since);
                    }
                    outstanding_m = None;
                }
                _ => counters.m_stale_acks += 1,
            },
            Ok(None) => {}
            Err(_) => counters.violations += 1,
        }

        counters.acyclic_answered += server
            .poll(|kind, request| match kind {
                CallKind::ReadAxisState => handle_read_axis_state(&view, request),
                CallKind::AxisCommand => axes.handle_command(request),
            })
            .unwrap_or(0) as u64;

        trace[tick as usize] = TraceRow {
            tick,
            time_ns: t0.duration_since(start).as_nanos() as u64,
            commanded_c,
            table_axis: table.current_position_acs_r,
            display_c,
            state: ramp.state.raw(),
        };
        let _ = events.notify();
        tick_ns[tick as usize] = t0.elapsed().as_nanos() as u64;
    }

    counters.violations += command_rx.stats().violations() + transition_rx.stats().violations();
    let table = lr_state.read();
    drop(segment); // marks the segment closed: the PLC stops
    let plc_output = wait_for_exit(child)?;

    let trace_path = write_trace(&args.out, &trace)?;
    let tick = Percentiles::of(&mut tick_ns);
    let late = Percentiles::of(&mut late_ns);
    let ack = Percentiles::of(&mut ack_latency_ticks);
    println!("channel 0 tracking state changes (tick: state):");
    for (tick, state) in &state_changes {
        println!("  {tick}: {state:?}");
    }
    println!(
        "handshakes: dyn-CS commands consumed {}, ignored while not enabled {}, requests published {} (PLC had not read {}), transitions {}, M functions announced {} / acknowledged {} (stale acks {}), acyclic calls answered {}, protocol violations {}",
        counters.commands,
        counters.commands_while_disabled,
        counters.requests_published,
        counters.requests_not_taken,
        counters.transitions,
        counters.m_announced,
        counters.m_acked,
        counters.m_stale_acks,
        counters.acyclic_answered,
        counters.violations
    );
    println!(
        "M-function acknowledge latency: p50 {} ticks, p99 {} ticks, max {} ticks",
        ack.p50, ack.p99, ack.max
    );
    println!(
        "tick duration: p50 {} ns, p99 {} ns, max {} ns; wake-up lateness: p50 {} ns, p99 {} ns, max {} ns ({} ticks of {} us)",
        tick.p50, tick.p99, tick.max, late.p50, late.p99, late.max, args.ticks, args.cycle_us
    );
    println!(
        "table axis C: at {:.4} deg, {:.1} deg/s, nAxisState {}, error 0x{:X}",
        hli::units::deg_from_hli(table.current_position_acs_r),
        hli::units::deg_from_hli(table.current_velocity_r),
        table.axis_state_r,
        table.error_id_r
    );
    print!("{plc_output}");
    println!("trace: {}", trace_path.display());
    Ok(())
}

fn write_trace(dir: &PathBuf, rows: &[TraceRow]) -> Result<PathBuf, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("creating {}: {e}", dir.display()))?;
    let path = dir.join("trace.csv");
    let file = std::fs::File::create(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = std::io::BufWriter::new(file);
    let header = "tick,time,gpCh[0]^channel_mc_control.dyn_cs.command_w.rotation[2],gpAx[0]^lr_state.current_position_acs_r,display_c,gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state";
    writeln!(out, "{header}").map_err(|e| e.to_string())?;
    for r in rows {
        writeln!(
            out,
            "{},{:.6},{},{},{},{}",
            r.tick,
            r.time_ns as f64 * 1e-9,
            r.commanded_c,
            r.table_axis,
            r.display_c,
            r.state as i32
        )
        .map_err(|e| e.to_string())?;
    }
    out.flush().map_err(|e| e.to_string())?;
    Ok(std::fs::canonicalize(&path).unwrap_or(path))
}
