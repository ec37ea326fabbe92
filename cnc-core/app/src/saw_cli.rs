//! `cnc saw plan`: plans a flying-saw synchronisation from given master and slave states,
//! prints its characteristic values as JSON (the `MC_FlyingSawCharacValues` field names)
//! and, with `--trace`, runs it tick by tick with the master at constant velocity.
//!
//! ```text
//! cnc saw plan --mode position --master-position -500 --master-velocity 500
//!              --slave-position -250 --slave-velocity 250 --ratio 1
//!              --master-sync 1000 --slave-sync 1000
//!              --velocity 3000 --acceleration 2500 --deceleration 2500 --jerk 5000
//!              [--sync-mode position-based|time-based] [--check MAXACC,MAXJERK]
//!              [--op ROLLBACKLOCK] [--cycle 0.001 --duration 4 --trace out.csv]
//! ```
//!
//! Exit 0 with the JSON, 1 with the error code when the command is refused, 2 on bad
//! arguments or a trace that cannot be written.

use cnc_core::nc::json::number;
use cnc_core::saw::{self, Follower, Limits, SawRequest, SyncOn};
use cnc_core::setpoint::Kinematic;
use hli::calls::saw::sync_mask as m;
use hli::calls::saw::SawError;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// `cnc saw ...`.
#[derive(Debug, Clone, clap::Subcommand)]
pub enum SawCommand {
    /// Plan a synchronisation: characteristic values as JSON, optionally a trace.
    Plan(PlanArgs),
}

/// Velocity or position sync.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Mode {
    /// MC_GearInVelo.
    Velocity,
    /// MC_GearInPos.
    Position,
}

/// `E_GearInSyncMode`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SyncModeArg {
    /// Slave profile over the master position.
    PositionBased,
    /// Slave profile over time (velocity sync only).
    TimeBased,
}

/// `cnc saw plan`.
#[derive(Debug, Clone, clap::Args)]
pub struct PlanArgs {
    /// Velocity or position sync.
    #[arg(long)]
    mode: Mode,
    /// Master position at coupling.
    #[arg(long, allow_hyphen_values = true)]
    master_position: f64,
    /// Master velocity at coupling (constant afterwards).
    #[arg(long, allow_hyphen_values = true)]
    master_velocity: f64,
    /// Master acceleration at coupling (used for the plan; the trace runs the master at
    /// constant velocity).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.0)]
    master_acceleration: f64,
    /// Slave position at coupling.
    #[arg(long, allow_hyphen_values = true)]
    slave_position: f64,
    /// Slave velocity at coupling.
    #[arg(long, allow_hyphen_values = true)]
    slave_velocity: f64,
    /// Slave acceleration at coupling.
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.0)]
    slave_acceleration: f64,
    /// Coupling factor (negative reverses the slave).
    #[arg(long, allow_hyphen_values = true)]
    ratio: f64,
    /// Master sync position (position sync).
    #[arg(long, allow_hyphen_values = true)]
    master_sync: Option<f64>,
    /// Slave sync position (position sync).
    #[arg(long, allow_hyphen_values = true)]
    slave_sync: Option<f64>,
    /// Velocity limit of the synchronising phase.
    #[arg(long, allow_hyphen_values = true)]
    velocity: f64,
    /// Acceleration limit.
    #[arg(long, allow_hyphen_values = true)]
    acceleration: f64,
    /// Deceleration limit.
    #[arg(long, allow_hyphen_values = true)]
    deceleration: f64,
    /// Jerk limit.
    #[arg(long, allow_hyphen_values = true)]
    jerk: f64,
    /// Slave profile over the master position or over time.
    #[arg(long, value_enum, default_value = "position-based")]
    sync_mode: SyncModeArg,
    /// Checks, comma-separated: MINPOS, MAXPOS, MAXVELO, MAXACC, MAXDEC, MAXJERK,
    /// OVERSHOOTPOS, UNDERSHOOTPOS, OVERSHOOTVELO, UNDERSHOOTVELO, OVERSHOOTVELOZERO,
    /// UNDERSHOOTVELOZERO (or a number).
    #[arg(long, default_value = "")]
    check: String,
    /// Operation bits, comma-separated: ROLLBACKLOCK, INSTANTSTOPONROLLBACK,
    /// PREFERCONSTVELO, IGNOREMASTERACC, IGNORESLAVEACC, DETAILEDERRORCODES (or a number).
    #[arg(long, default_value = "")]
    op: String,
    /// Software limits of the slave `MIN,MAX` for MINPOS/MAXPOS.
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',', num_args = 2)]
    soft_limits: Option<Vec<f64>>,
    /// Tick of the trace, s.
    #[arg(long, default_value_t = 0.001)]
    cycle: f64,
    /// Length of the trace, s (default: the phase and 10 % more).
    #[arg(long)]
    duration: Option<f64>,
    /// Trace CSV: time, master and slave set-points, `nAxisState`.
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Draw the traced positions and velocities as SVG (`cnc plot` of the trace).
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// The names of the check and operation bits.
pub const MASK_NAMES: [(&str, u32); 18] = [
    ("MINPOS", m::MINPOS),
    ("MAXPOS", m::MAXPOS),
    ("MAXVELO", m::MAXVELO),
    ("MAXACC", m::MAXACC),
    ("MAXDEC", m::MAXDEC),
    ("MAXJERK", m::MAXJERK),
    ("OVERSHOOTPOS", m::OVERSHOOTPOS),
    ("UNDERSHOOTPOS", m::UNDERSHOOTPOS),
    ("OVERSHOOTVELO", m::OVERSHOOTVELO),
    ("UNDERSHOOTVELO", m::UNDERSHOOTVELO),
    ("OVERSHOOTVELOZERO", m::OVERSHOOTVELOZERO),
    ("UNDERSHOOTVELOZERO", m::UNDERSHOOTVELOZERO),
    ("ROLLBACKLOCK", m::ROLLBACKLOCK),
    ("INSTANTSTOPONROLLBACK", m::INSTANTSTOPONROLLBACK),
    ("PREFERCONSTVELO", m::PREFERCONSTVELO),
    ("IGNOREMASTERACC", m::IGNOREMASTERACC),
    ("IGNORESLAVEACC", m::IGNORESLAVEACC),
    ("DETAILEDERRORCODES", m::DETAILEDERRORCODES),
];

/// A comma-separated list of bit names (with or without the `GEARINSYNC_CHECKMASK_` /
/// `GEARINSYNC_OPMASK_` prefix) or a number, each allowed only from `allowed`.
pub fn parse_mask(text: &str, allowed: u32) -> Result<u32, String> {
    let mut mask = 0;
    for word in text.split(',').map(str::trim).filter(|w| !w.is_empty()) {
        let upper = word.to_ascii_uppercase();
        let name = upper
            .trim_start_matches("GEARINSYNC_CHECKMASK_")
            .trim_start_matches("GEARINSYNC_OPMASK_");
        let bit = match MASK_NAMES.iter().find(|(n, _)| *n == name) {
            Some((_, bit)) => *bit,
            None => parse_number(word).ok_or_else(|| format!("{word}: not a bit name"))?,
        };
        if bit & !allowed != 0 {
            return Err(format!("{word}: not one of these bits"));
        }
        mask |= bit;
    }
    Ok(mask)
}

fn parse_number(word: &str) -> Option<u32> {
    match word.strip_prefix("0x").or_else(|| word.strip_prefix("0X")) {
        Some(hex) => u32::from_str_radix(hex, 16).ok(),
        None => word.parse().ok(),
    }
}

/// Runs `cnc saw`.
pub fn main(command: SawCommand) -> ExitCode {
    let SawCommand::Plan(args) = command;
    match plan(&args) {
        Ok(json) => {
            println!("{json}");
            ExitCode::SUCCESS
        }
        Err(Failure::Refused(e)) => {
            eprintln!("cnc saw plan: refused with 0x{:X} {e:?}", e.raw());
            println!("{{\"error_id\": {}, \"error\": \"{e:?}\"}}", e.raw());
            ExitCode::from(1)
        }
        Err(Failure::Usage(e)) => {
            eprintln!("cnc saw plan: {e}");
            ExitCode::from(2)
        }
    }
}

enum Failure {
    Refused(SawError),
    Usage(String),
}

fn plan(args: &PlanArgs) -> Result<String, Failure> {
    let on = match (args.mode, args.master_sync, args.slave_sync) {
        (Mode::Velocity, None, None) => SyncOn::Velocity,
        (Mode::Position, Some(master), Some(slave)) => SyncOn::Position { master, slave },
        (Mode::Velocity, _, _) => {
            return Err(Failure::Usage(
                "--master-sync/--slave-sync belong to --mode position".into(),
            ))
        }
        (Mode::Position, _, _) => {
            return Err(Failure::Usage(
                "--mode position needs --master-sync and --slave-sync".into(),
            ))
        }
    };
    let checks = parse_mask(&args.check, m::CHECKS).map_err(Failure::Usage)?;
    let ops = parse_mask(&args.op, m::OPERATIONS).map_err(Failure::Usage)?;
    let soft = match args.soft_limits.as_deref() {
        None => None,
        Some([lo, hi]) if lo < hi => Some([*lo, *hi]),
        Some(v) => {
            return Err(Failure::Usage(format!(
                "--soft-limits {v:?}: MIN,MAX with MIN < MAX"
            )))
        }
    };
    if !(args.cycle.is_finite() && args.cycle > 0.0) {
        return Err(Failure::Usage(format!(
            "--cycle {}: a time > 0",
            args.cycle
        )));
    }
    let request = SawRequest {
        on,
        time_based: args.sync_mode == SyncModeArg::TimeBased,
        mask: checks | ops,
        ratio: args.ratio,
        limits: Limits {
            velocity: args.velocity,
            acceleration: args.acceleration,
            deceleration: args.deceleration,
            jerk: args.jerk,
        },
    };
    let master = Kinematic {
        position: args.master_position,
        velocity: args.master_velocity,
        acceleration: args.master_acceleration,
        jerk: 0.0,
    };
    let slave = Kinematic {
        position: args.slave_position,
        velocity: args.slave_velocity,
        acceleration: args.slave_acceleration,
        jerk: 0.0,
    };
    let plan = saw::plan(&request, &master, &slave, soft).map_err(Failure::Refused)?;
    if args.trace.is_some() || args.plot.is_some() {
        let seconds = plan.charac.values.fMasterPosEnd - plan.charac.values.fMasterPosStart;
        let phase_s = match plan.profile.domain {
            saw::Domain::Master { .. } if master.velocity != 0.0 => {
                seconds.abs() / master.velocity.abs()
            }
            _ => plan.profile.length,
        };
        let duration = args.duration.unwrap_or(1.1 * phase_s + args.cycle);
        // A trace is written into memory first: at most ten million rows.
        if !(duration.is_finite() && duration > 0.0 && duration / args.cycle <= 1e7) {
            return Err(Failure::Usage(format!(
                "--duration {duration}: a time > 0 of at most 10,000,000 cycles"
            )));
        }
        let csv = trace(&request, &plan, &master, &slave, soft, args.cycle, duration);
        if let Some(path) = &args.trace {
            std::fs::File::create(path)
                .and_then(|mut f| f.write_all(csv.as_bytes()))
                .map_err(|e| Failure::Usage(format!("--trace {}: {e}", path.display())))?;
        }
        if let Some(path) = &args.plot {
            plot_trace(&csv, path).map_err(|e| Failure::Usage(format!("--plot {e}")))?;
        }
    }
    let fields = plan.charac.values.fields();
    let mut json = String::from("{\n");
    json.push_str(&format!("  \"shape\": \"{:?}\",\n", plan.profile.shape));
    for (i, (name, value)) in fields.iter().enumerate() {
        let comma = if i + 1 < fields.len() { "," } else { "" };
        json.push_str(&format!("  \"{name}\": {}{comma}\n", number(*value)));
    }
    json.push('}');
    Ok(json)
}

/// Master and slave positions and velocities over time, one panel each.
fn plot_trace(csv: &str, out: &std::path::Path) -> Result<(), crate::plot::PlotError> {
    use crate::plot::{Figure, Series, Table, Unit};
    let table = Table::parse("trace", csv)?;
    let time = table.column("time")?;
    let mut series = Vec::new();
    for (name, label) in [
        ("master_position", "position"),
        ("slave_position", "position"),
        ("master_velocity", "velocity /s"),
        ("slave_velocity", "velocity /s"),
    ] {
        series.push(Series {
            name: name.into(),
            unit: Unit { label, scale: 1.0 },
            points: time.iter().copied().zip(table.column(name)?).collect(),
        });
    }
    let figure = Figure {
        title: "flying saw: synchronisation".into(),
        x_label: "time [s]".into(),
        series,
    };
    figure.save_svg(out)
}

/// The phase tick by tick with the master at constant velocity from coupling on.
fn trace(
    request: &SawRequest,
    plan: &saw::Plan,
    master: &Kinematic,
    slave: &Kinematic,
    soft: Option<[f64; 2]>,
    cycle: f64,
    duration: f64,
) -> String {
    let mut follower = Follower::new(*request, plan, master, soft);
    let mut out = String::from(
        "time,master_position,master_velocity,slave_position,slave_velocity,slave_acceleration,axis_state\n",
    );
    let mut s = *slave;
    let ticks = (duration / cycle).ceil() as usize;
    for k in 0..=ticks {
        let t = k as f64 * cycle;
        let m = Kinematic {
            position: master.position + master.velocity * t,
            velocity: master.velocity,
            acceleration: 0.0,
            jerk: 0.0,
        };
        let dt = if k == 0 { 0.0 } else { cycle };
        let state = match follower.step(&m, s, dt) {
            Some((next, phase)) => {
                s = next;
                phase.raw()
            }
            None => 0,
        };
        out.push_str(&format!(
            "{},{},{},{},{},{},{state}\n",
            number(t),
            number(m.position),
            number(m.velocity),
            number(s.position),
            number(s.velocity),
            number(s.acceleration)
        ));
    }
    out
}
