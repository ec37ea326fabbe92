//! `plc-shuttle`: the shuttle program as its own PLC process.
//!
//! ```text
//! cargo run -p plc-shuttle -- --instance cnc-demo --axis 0 --far 400 --strokes 5
//! ```

#![forbid(unsafe_code)]

use clap::Parser;
use plc_shuttle::Shuttle;
use std::process::ExitCode;

/// The shuttle's own arguments beside the runtime's (`--instance`, `--period-ticks`, ...).
#[derive(Debug, Parser)]
#[command(name = "plc-shuttle", about = "A shuttle axis between two stations")]
struct Args {
    /// The shuttle's axis (index in gpAx).
    #[arg(long, default_value_t = 0)]
    axis: u32,
    /// Home station, mm.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    home: f64,
    /// Far station, mm.
    #[arg(long, default_value_t = 300.0, allow_negative_numbers = true)]
    far: f64,
    /// Round trips.
    #[arg(long, default_value_t = 3)]
    strokes: u32,
    /// Velocity, mm/s.
    #[arg(long, default_value_t = 200.0)]
    velocity: f64,
    #[command(flatten)]
    host: plc_shim::cli::HostArgs,
}

fn main() -> ExitCode {
    let args = Args::parse();
    if !(args.home.is_finite() && args.far.is_finite()) {
        eprintln!("plc-shuttle: --home and --far must be finite");
        return ExitCode::from(2);
    }
    if !(args.velocity.is_finite() && args.velocity > 0.0) {
        eprintln!("plc-shuttle: --velocity {}: a speed > 0", args.velocity);
        return ExitCode::from(2);
    }
    let mut program = Shuttle::new(args.axis, args.home, args.far, args.strokes, args.velocity);
    plc_shim::cli::host(&mut program, &args.host)
}
