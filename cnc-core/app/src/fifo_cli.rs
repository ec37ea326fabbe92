//! `cnc fifo run`: a position file through a FIFO group of the machine library (the FIFO
//! engine on ideal simulated axes), the rows written in blocks as the FIFO frees them, as a
//! PLC would, and the set-points traced tick by tick.
//!
//! ```text
//! cnc fifo run --rows contour.csv --tf 0.002 --cycle 0.001 [--override 80] [--pt2 0.04]
//!              [--fifo-rows 1000] [--trace out.csv]
//! ```
//!
//! The trace has `time,fill,override` (override in percent), then per axis N
//! `aN_position,aN_velocity,aN_acceleration,aN_direction` (direction +1, -1 or 0).

use cnc_core::axis::config::AxisConfig;
use cnc_core::axis::sim_drive::SimDriveConfig;
use cnc_core::axis::DriveLink;
use cnc_core::fifo::machine::FifoEngine;
use cnc_core::fifo::{FifoParams, OverrideType};
use cnc_core::machine::{Machine, MachineSetup};
use hli::calls::fifo::{
    rows_header, FifoIntegrateCall, FifoOverrideCall, FifoReply, FifoStartCall, FifoWriteRowsCall,
    FIFO_BLOCK_VALUES,
};
use hli::calls::{decode_reply, AcyclicCall};
use hli::enums::FifoGroupState;
use hli::layout::HliFifoGroupState;
use hli::layout::{FIFO_FLAG_AT_END, FIFO_FLAG_UNDERRUN, FIFO_OVERRIDE_FULL};
use hli::views::{CncView, PlcView};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// `cnc fifo ...`.
#[derive(Debug, Clone, clap::Subcommand)]
pub enum FifoCommand {
    /// Run a position file through a FIFO group and trace the set-points.
    Run(FifoRunArgs),
}

/// `cnc fifo run`.
#[derive(Debug, Clone, clap::Args)]
pub struct FifoRunArgs {
    /// Position file: CSV, one row per FIFO entry, one column per axis, an optional header
    /// line (or binary `.fifo`).
    #[arg(long)]
    rows: PathBuf,
    /// FIFO cycle T_f, seconds.
    #[arg(long)]
    tf: f64,
    /// NC tick, seconds.
    #[arg(long)]
    cycle: f64,
    /// Override, percent (0 < override <= 100).
    #[arg(long = "override", default_value_t = 100.0)]
    override_percent: f64,
    /// PT-2 override with time constant T0, seconds (default: instant).
    #[arg(long)]
    pt2: Option<f64>,
    /// FIFO length Z, rows.
    #[arg(long, default_value_t = 1000)]
    fifo_rows: usize,
    /// Trace CSV.
    #[arg(long)]
    trace: Option<PathBuf>,
}

/// Exit code of a run whose rows end in motion: the group held the last row with an
/// underrun (the axes stopped with a velocity step), the trace written.
pub const EXIT_ENDS_IN_MOTION: u8 = 3;

/// Runs `cnc fifo`: exit 0, 1 when the group refused the file or a parameter, 2 when the file
/// cannot be read, 3 ([`EXIT_ENDS_IN_MOTION`]) when the rows end in motion.
pub fn main(command: FifoCommand) -> ExitCode {
    let FifoCommand::Run(args) = command;
    match run(&args) {
        Ok((summary, None)) => {
            println!("{summary}");
            ExitCode::SUCCESS
        }
        Ok((summary, Some(end))) => {
            println!("{summary}");
            eprintln!(
                "cnc fifo: the rows end in motion: the FIFO ran dry at tick {} and the group holds the last row (underrun); velocity step {:.6} units/s on axis {}",
                end.tick, end.step, end.axis
            );
            ExitCode::from(EXIT_ENDS_IN_MOTION)
        }
        Err(Failure::File(e)) => {
            eprintln!("cnc fifo: {e}");
            ExitCode::from(2)
        }
        Err(Failure::Refused(e)) => {
            eprintln!("cnc fifo: {e}");
            ExitCode::from(1)
        }
    }
}

enum Failure {
    File(String),
    Refused(String),
}

fn call<C: AcyclicCall<Reply = FifoReply>>(
    machine: &mut Machine,
    view: &CncView<'_>,
    body: C,
) -> u32 {
    machine
        .call(view, 0, &body)
        .map_or_else(|code| code.raw(), |reply| reply.error_id)
}

fn refused(what: &str, code: u32) -> Failure {
    let name = hli::calls::fifo::FifoError::decode(code)
        .map(|e| format!("{e:?}"))
        .or_else(|_| hli::enums::AxisError::decode(code).map(|e| format!("{e:?}")))
        .unwrap_or_default();
    Failure::Refused(format!("{what}: refused with 0x{code:X} {name}"))
}

/// A job whose rows ended in motion: the tick the FIFO ran dry, the largest velocity step of
/// the hold and its axis.
struct MotionEnd {
    tick: u64,
    axis: usize,
    step: f64,
}

/// How the job ended: its ticks, the group's underrun ticks, and whether in motion.
struct JobEnd {
    ticks: u64,
    underrun_ticks: u32,
    in_motion: Option<MotionEnd>,
}

fn run(args: &FifoRunArgs) -> Result<(String, Option<MotionEnd>), Failure> {
    let (n, rows) = plc_shim::fifo_file::RowReader::open(&args.rows)
        .and_then(|r| r.read_all())
        .map_err(|e| Failure::File(e.to_string()))?;
    check_args(args)?;
    let mut machine = build_machine(args, n, &rows)?;
    let memory = hli::image::heap_image(0, n as u32);
    machine.tick(&memory);
    let view = CncView::new(&memory);
    integrate(&mut machine, &view, args, n)?;
    let mut feed = RowFeed {
        rows: &rows,
        n,
        total: rows.len() / n,
        written: 0,
    };
    feed.write(&mut machine, args.fifo_rows)?;
    let code = call(&mut machine, &view, FifoStartCall::default());
    if code != 0 {
        return Err(refused("FiFoStart", code));
    }
    let mut trace = trace_header(n);
    let ended = run_job(args, &mut machine, &memory, &mut feed, &mut trace);
    // The trace is written however the job ended: it shows why.
    if let Some(path) = &args.trace {
        std::fs::File::create(path)
            .and_then(|mut f| f.write_all(trace.as_bytes()))
            .map_err(|e| Failure::File(format!("{}: {e}", path.display())))?;
    }
    let JobEnd {
        ticks,
        underrun_ticks,
        in_motion,
    } = ended?;
    let last: Vec<String> = (0..n)
        .map(|i| {
            let p = machine
                .axes()
                .axis(i)
                .map_or(0.0, |a| a.setpoint().position);
            // + 0.0 turns -0 into 0.
            format!("{:.4}", p + 0.0)
        })
        .collect();
    let summary = format!(
        "fifo: {} rows x {n} axes, T_f {} s, tick {} s, override {} %: {ticks} ticks ({:.3} s), {underrun_ticks} underrun ticks, end at [{}]",
        feed.total,
        args.tf,
        args.cycle,
        args.override_percent,
        ticks as f64 * args.cycle,
        last.join(", ")
    );
    Ok((summary, in_motion))
}

/// The override and the tick, checked.
fn check_args(args: &FifoRunArgs) -> Result<(), Failure> {
    if !(args.override_percent > 0.0 && args.override_percent <= 100.0) {
        return Err(Failure::Refused(format!(
            "--override {}: above 0 (0 % never ends), at most 100",
            args.override_percent
        )));
    }
    if !(args.cycle.is_finite() && args.cycle > 0.0) {
        return Err(Failure::Refused(format!(
            "--cycle {}: a time > 0",
            args.cycle
        )));
    }
    Ok(())
}

/// A machine of `n` ideal axes standing on the first row, without software limits (the file
/// is the job), switched on, with one FIFO group of `n` columns.
fn build_machine(args: &FifoRunArgs, n: usize, rows: &[f64]) -> Result<Machine, Failure> {
    let kind = match args.pt2 {
        Some(t0_s) => OverrideType::Pt2 { t0_s },
        None => OverrideType::Instant,
    };
    let params = FifoParams::new(n, args.fifo_rows, args.tf, kind)
        .map_err(|e| Failure::Refused(e.to_string()))?;
    // Ideal axes standing on the first row, without software limits (the file is the job).
    let axes = (0..n)
        .map(|i| {
            let mut c = AxisConfig::linear(&format!("a{i}"), i as u32 + 1);
            c.soft_limits = None;
            c.following_error_limit = f64::MAX;
            c.drive = DriveLink::Simulated(SimDriveConfig {
                start_position: rows[i],
                ..SimDriveConfig::default()
            });
            c
        })
        .collect();
    let engine =
        FifoEngine::new(&[params], args.cycle).map_err(|e| Failure::Refused(e.to_string()))?;
    let mut machine = Machine::new(MachineSetup {
        channels: Vec::new(),
        axes,
        engines: vec![Box::new(engine)],
        cycle_s: args.cycle,
    })
    .map_err(|e| Failure::Refused(e.to_string()))?;
    for i in 0..n {
        if let Some(a) = machine.axes_mut().axis_mut(i) {
            a.switch_on()
                .map_err(|e| Failure::Refused(format!("{e:?}")))?;
        }
    }
    Ok(machine)
}

/// Every axis joins the group in its column, and the override is set.
fn integrate(
    machine: &mut Machine,
    view: &CncView<'_>,
    args: &FifoRunArgs,
    n: usize,
) -> Result<(), Failure> {
    for i in 0..n as u32 {
        let code = call(
            machine,
            view,
            FifoIntegrateCall {
                axis: i,
                group_position: i + 1,
            },
        );
        if code != 0 {
            return Err(refused("FiFoGroupIntegrate", code));
        }
    }
    let ppm = (args.override_percent / 100.0 * f64::from(FIFO_OVERRIDE_FULL)).round() as u32;
    let code = call(machine, view, FifoOverrideCall { override_ppm: ppm });
    if code != 0 {
        return Err(refused("FiFoSetChannelOverride", code));
    }
    Ok(())
}

/// The file's rows, written into the group in blocks as a PLC would.
struct RowFeed<'a> {
    /// Every row, `n` values each.
    rows: &'a [f64],
    n: usize,
    /// Rows in the file.
    total: usize,
    /// Rows written so far.
    written: usize,
}

impl RowFeed<'_> {
    /// Writes the next rows, at most `free` and one block.
    fn write(&mut self, machine: &mut Machine, free: usize) -> Result<(), Failure> {
        let n = self.n;
        let count = (self.total - self.written)
            .min(free)
            .min(FIFO_BLOCK_VALUES / n);
        if count == 0 {
            return Ok(());
        }
        let header = rows_header(0, n as u32, count as u32, false);
        let values = &self.rows[self.written * n..(self.written + count) * n];
        let reply = machine
            .dispatch_bulk(&header, values)
            .and_then(|(body, len)| decode_reply::<FifoWriteRowsCall>(&body, len))
            .map_err(|code| refused("FiFoWrite", code.raw()))?;
        if reply.error_id != 0 {
            return Err(refused("FiFoWrite", reply.error_id));
        }
        self.written += count;
        Ok(())
    }
}

/// The trace's header line.
fn trace_header(n: usize) -> String {
    let mut trace = String::from("time,fill,override");
    for i in 0..n {
        trace.push_str(&format!(
            ",a{i}_position,a{i}_velocity,a{i}_acceleration,a{i}_direction"
        ));
    }
    trace.push('\n');
    trace
}

/// The set-point velocities of the first `n` axes.
fn velocities(machine: &Machine, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            machine
                .axes()
                .axis(i)
                .map_or(0.0, |a| a.setpoint().velocity)
        })
        .collect()
}

/// The largest velocity change from `before` to `after`, and its axis.
fn largest_step(before: &[f64], after: &[f64]) -> (usize, f64) {
    before
        .iter()
        .zip(after)
        .map(|(b, a)| (a - b).abs())
        .enumerate()
        .fold((0, 0.0), |w, (i, d)| if d > w.1 { (i, d) } else { w })
}

/// Ticks the machine until the job ends at rest, or in motion when every row is written and
/// the FIFO ran dry (the group holds the last row), refilling the FIFO and tracing each tick.
fn run_job(
    args: &FifoRunArgs,
    machine: &mut Machine,
    memory: &hli::ImageMemory,
    feed: &mut RowFeed<'_>,
    trace: &mut String,
) -> Result<JobEnd, Failure> {
    // Watchdog: twice the job's duration at the override, plus the PT-2's settling.
    let job = feed.total as f64 * args.tf / (args.override_percent / 100.0);
    let limit = (2.0 * job / args.cycle) as u64 + 100_000;
    let plc = PlcView::new(memory);
    let mut ticks = 0u64;
    let mut underrun_ticks;
    let mut before = velocities(machine, feed.n);
    loop {
        machine.tick(memory);
        ticks += 1;
        let s = plc
            .fifo_group(0)
            .map_err(|e| Failure::Refused(e.to_string()))?;
        underrun_ticks = s.underrun_ticks_r;
        if args.trace.is_some() {
            trace_row(trace, machine, &s, ticks as f64 * args.cycle, feed.n);
        }
        if s.group_state_r == FifoGroupState::Error.raw() {
            return Err(refused("the group", s.error_id_r));
        }
        let at_end = s.flags_r & FIFO_FLAG_AT_END != 0 && s.entries_r <= 1;
        if feed.written == feed.total && at_end {
            break;
        }
        let dry = s.flags_r & FIFO_FLAG_UNDERRUN != 0 && s.entries_r <= 1;
        if feed.written == feed.total && dry {
            let (axis, step) = largest_step(&before, &velocities(machine, feed.n));
            let in_motion = Some(MotionEnd {
                tick: ticks,
                axis,
                step,
            });
            return Ok(JobEnd {
                ticks,
                underrun_ticks,
                in_motion,
            });
        }
        before = velocities(machine, feed.n);
        // Whenever a quarter of the FIFO is free, as a PLC would refill it.
        if s.free_r as usize >= (args.fifo_rows / 4).max(1)
            || feed.total - feed.written <= s.free_r as usize
        {
            feed.write(machine, s.free_r as usize)?;
        }
        if ticks > limit {
            return Err(Failure::Refused(format!(
                "no end after {ticks} ticks (the rows do not come to rest?)"
            )));
        }
    }
    Ok(JobEnd {
        ticks,
        underrun_ticks,
        in_motion: None,
    })
}

/// One trace line at `time`: the group's fill and override, each axis's set-point and
/// direction.
fn trace_row(trace: &mut String, machine: &Machine, s: &HliFifoGroupState, time: f64, n: usize) {
    trace.push_str(&format!(
        "{:.6},{},{}",
        time,
        s.entries_r,
        f64::from(s.override_r) / 1e4
    ));
    for i in 0..n {
        let set = machine
            .axes()
            .axis(i)
            .map(|a| a.setpoint())
            .unwrap_or_default();
        let direction = if set.velocity > 0.0 {
            1
        } else if set.velocity < 0.0 {
            -1
        } else {
            0
        };
        trace.push_str(&format!(
            ",{},{},{},{direction}",
            set.position, set.velocity, set.acceleration
        ));
    }
    trace.push('\n');
}
