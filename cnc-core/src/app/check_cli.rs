//! `cnc check`: parse and decode NC programs, report every problem as
//! `FILE:LINE:COL: error: MESSAGE`, optionally print the decoded motion blocks as JSON lines.

use crate::app::json::number;
use crate::nc::decode::{check_channel_axes, ZeroVars};
use crate::nc::{decode_program, parse, Decoded, Diagnostic};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `cnc check`.
#[derive(Debug, Clone, clap::Args)]
pub struct CheckArgs {
    /// The channel's axis names, comma separated.
    #[arg(long, default_value = "X,Y,Z,A,B,C", value_delimiter = ',')]
    pub axes: Vec<String>,
    /// Also print each decoded motion block as a JSON line.
    #[arg(long)]
    pub blocks: bool,
    /// NC program files.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
}

/// Checks one program text; returns its diagnostics (sorted) and the decoded stream.
pub fn check_source(src: &str, axes: &[String]) -> (Vec<Diagnostic>, Vec<Decoded>) {
    let (program, mut diags) = parse(src);
    let (decoded, semantic) = decode_program(&program, src, axes, &ZeroVars);
    diags.extend(semantic);
    diags.sort_by_key(|d| (d.line, d.col));
    diags.dedup();
    (diags, decoded)
}

/// A decoded motion block as the JSON line `--blocks` prints.
pub fn motion_json(block: &crate::nc::MotionBlock, axes: &[String]) -> String {
    let target: Vec<String> = axes
        .iter()
        .zip(block.target.iter())
        .map(|(name, v)| format!("\"{name}\":{}", number(*v)))
        .collect();
    format!(
        "{{\"line\":{},\"motion\":\"{}\",\"feed\":{},\"target\":{{{}}}}}",
        block.line,
        block.motion.name(),
        number(block.feed),
        target.join(",")
    )
}

/// Runs `cnc check`.
pub fn main(args: CheckArgs) -> ExitCode {
    let axes: Vec<String> = args
        .axes
        .iter()
        .map(|a| a.trim().to_ascii_uppercase())
        .collect();
    if let Err(message) = check_channel_axes(&axes) {
        eprintln!("error: --axes: {message}");
        return ExitCode::from(2);
    }
    let mut failed = false;
    let mut out = String::new();
    for file in &args.files {
        let name = file.display().to_string();
        let src = match std::fs::read(file) {
            Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
            Err(e) => {
                eprintln!("{name}:1:1: error: cannot read the file: {e}");
                failed = true;
                continue;
            }
        };
        let (diags, decoded) = check_source(&src, &axes);
        for d in &diags {
            out.push_str(&d.render(&name));
            out.push('\n');
        }
        failed |= !diags.is_empty();
        if args.blocks && diags.is_empty() {
            for d in &decoded {
                if let Decoded::Motion(m) = d {
                    out.push_str(&motion_json(m, &axes));
                    out.push('\n');
                }
            }
        }
    }
    print!("{out}");
    if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
