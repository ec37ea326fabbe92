//! `cnc cam eval|charac|plot`: a cam file (JSON motion function or table, or the binary table
//! format) evaluated, characterised or drawn from the command line.

use cnc_core::cam::file::{self, BinaryOptions, LoadError};
use cnc_core::cam::{CamProfile, CharacValues, ProfileCursor, Sample};
use cnc_core::nc::json::number as num;
use hli::calls::cam::CamInterpolation;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Options for reading a binary table (JSON files say this themselves).
#[derive(Debug, Clone, clap::Args)]
pub struct BinaryArgs {
    /// Interpolation of a binary table: linear, 4point or spline.
    #[arg(long, default_value = "linear", value_parser = parse_interpolation)]
    interpolation: CamInterpolation,
    /// A binary table continues cyclically (master period, slave stroke).
    #[arg(long)]
    periodic: bool,
}

fn parse_interpolation(s: &str) -> Result<CamInterpolation, String> {
    match s {
        "linear" => Ok(CamInterpolation::Linear),
        "4point" => Ok(CamInterpolation::FourPoint),
        "spline" => Ok(CamInterpolation::Spline),
        _ => Err(format!("{s:?}: linear, 4point or spline")),
    }
}

/// `cnc cam ...`.
#[derive(Debug, Clone, clap::Subcommand)]
pub enum CamCommand {
    /// Print `master,position,velocity,acceleration,jerk` (CSV) of the raw cam.
    Eval {
        /// Cam file.
        file: PathBuf,
        /// First master position.
        #[arg(long, allow_negative_numbers = true)]
        from: f64,
        /// Last master position.
        #[arg(long, allow_negative_numbers = true)]
        to: f64,
        /// Master step (its sign must lead from --from to --to).
        #[arg(long, allow_negative_numbers = true)]
        step: f64,
        /// How to read a binary table.
        #[command(flatten)]
        binary: BinaryArgs,
    },
    /// Print the characteristic values (MC_TableCharacValues field names) as JSON.
    Charac {
        /// Cam file.
        file: PathBuf,
        /// Constant master velocity the dynamic values refer to (default 1: normed).
        #[arg(long, default_value_t = 1.0)]
        master_velocity: f64,
        /// How to read a binary table.
        #[command(flatten)]
        binary: BinaryArgs,
    },
    /// Draw position, velocity and acceleration over the master as SVG.
    Plot {
        /// Cam file.
        file: PathBuf,
        /// Output SVG.
        #[arg(short = 'o', long)]
        out: PathBuf,
        /// Samples drawn.
        #[arg(long, default_value_t = 2000)]
        samples: usize,
        /// How to read a binary table.
        #[command(flatten)]
        binary: BinaryArgs,
    },
}

/// Runs `cnc cam`: exit 0, 1 for a refused file or request, 2 for a file that cannot be read.
pub fn main(command: CamCommand) -> ExitCode {
    match run(&command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::Pipe) => ExitCode::SUCCESS,
        Err(CliError::Message(code, text)) => {
            eprintln!("cnc cam: {text}");
            ExitCode::from(code)
        }
    }
}

enum CliError {
    Pipe,
    Message(u8, String),
}

impl From<std::io::Error> for CliError {
    fn from(e: std::io::Error) -> Self {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            CliError::Pipe
        } else {
            CliError::Message(2, e.to_string())
        }
    }
}

fn load(path: &Path, binary: &BinaryArgs) -> Result<CamProfile, CliError> {
    let options = BinaryOptions {
        interpolation: binary.interpolation,
        periodic: binary.periodic,
    };
    file::load(path, options)
        .map(|f| f.profile)
        .map_err(|e| match e {
            LoadError::Cam(_) => CliError::Message(1, format!("{}: {e}", path.display())),
            other => CliError::Message(2, format!("{}: {other}", path.display())),
        })
}

fn run(command: &CamCommand) -> Result<(), CliError> {
    match command {
        CamCommand::Eval {
            file,
            from,
            to,
            step,
            binary,
        } => {
            let profile = load(file, binary)?;
            // Streamed: the command line may ask for more rows than a PLC value table holds.
            let rows = cnc_core::cam::charac::sample_count(*from, *to, *step, 1_000_000_000)
                .map_err(|e| {
                    let code = e.code();
                    CliError::Message(
                        1,
                        format!("error {:#06X} ({}): {e}", code as u32, code.name()),
                    )
                })?;
            let mut out = std::io::BufWriter::new(std::io::stdout().lock());
            writeln!(out, "master,position,velocity,acceleration,jerk")?;
            let mut cursor = ProfileCursor::default();
            for i in 0..rows {
                let x = from + step * i as f64;
                let s = profile.eval(x, &mut cursor);
                writeln!(
                    out,
                    "{},{},{},{},{}",
                    num(x),
                    num(s.position),
                    num(s.velocity),
                    num(s.acceleration),
                    num(s.jerk)
                )?;
            }
            out.flush()?;
            Ok(())
        }
        CamCommand::Charac {
            file,
            master_velocity,
            binary,
        } => {
            let profile = load(file, binary)?;
            let Some(values) = CharacValues::normed(&profile).rescaled(*master_velocity) else {
                return Err(CliError::Message(
                    1,
                    format!("--master-velocity {master_velocity}: a finite velocity other than 0"),
                ));
            };
            let body: Vec<String> = values
                .fields()
                .iter()
                .map(|(name, value)| format!("\"{name}\":{}", num(*value)))
                .collect();
            let mut out = std::io::stdout().lock();
            writeln!(out, "{{{}}}", body.join(","))?;
            Ok(())
        }
        CamCommand::Plot {
            file,
            out,
            samples,
            binary,
        } => {
            let profile = load(file, binary)?;
            plot(&profile, out, (*samples).clamp(2, 1_000_000))
                .map_err(|e| CliError::Message(2, format!("{}: {e}", out.display())))
        }
    }
}

/// Position, velocity and acceleration over the master, stacked, as SVG (through
/// [`crate::plot`], like every plot of the tools).
pub fn plot(profile: &CamProfile, out: &Path, samples: usize) -> Result<(), String> {
    use crate::plot::{Figure, Series, Unit};
    let (m0, m1) = profile.master_range();
    let (lo, hi) = (m0.min(m1), m0.max(m1));
    let mut cursor = ProfileCursor::default();
    let points: Vec<(f64, Sample)> = (0..samples)
        .map(|i| {
            let x = lo + (hi - lo) * i as f64 / (samples - 1) as f64;
            (x, profile.eval(x, &mut cursor))
        })
        .collect();
    type Curve = (&'static str, &'static str, fn(&Sample) -> f64);
    let curves: [Curve; 3] = [
        ("slave position", "slave position", |s| s.position),
        ("slave velocity", "per master unit", |s| s.velocity),
        ("slave acceleration", "per master unit²", |s| {
            s.acceleration
        }),
    ];
    let figure = Figure {
        title: "cam profile".into(),
        x_label: "master position".into(),
        series: curves
            .iter()
            .map(|(name, unit, get)| Series {
                name: (*name).into(),
                unit: Unit {
                    label: unit,
                    scale: 1.0,
                },
                points: points.iter().map(|(x, s)| (*x, get(s))).collect(),
            })
            .collect(),
    };
    figure.save_svg(out).map_err(|e| e.to_string())
}
