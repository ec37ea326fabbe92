//! `cnc check`: parse, run and decode NC programs, report every problem as
//! `FILE:LINE:COL: error: MESSAGE`, optionally print the decoded motion blocks as JSON lines.

use cnc_core::nc::check::push_motion_json;
use cnc_core::nc::decode::{check_channel_axes, AxisLayout, DecoderSetup, ZeroVars};
use cnc_core::nc::interp::{check_set, SearchPath};
use cnc_core::nc::straight::check_straight;
use cnc_core::nc::{check_program, Decoded, DecoderState};
use std::io::Write as _;
use std::path::{Path, PathBuf};
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
    /// Folders `L name` searches after the calling program's own (repeatable).
    #[arg(long = "search", value_name = "DIR")]
    pub search: Vec<PathBuf>,
    /// A tool data record, `D=LENGTH` in mm (repeatable). With at least one, a D that is not
    /// given is an error; without any, every D takes length 0.
    #[arg(long = "tool", value_name = "D=LENGTH", value_parser = parse_tool)]
    pub tools: Vec<(u32, f64)>,
    /// NC program files.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
}

/// `D=LENGTH`: a D number of 1 or more and a finite length.
fn parse_tool(text: &str) -> Result<(u32, f64), String> {
    let (d, length) = text
        .split_once('=')
        .ok_or_else(|| format!("expected D=LENGTH, found \"{text}\""))?;
    let d: u32 = d
        .trim()
        .parse()
        .ok()
        .filter(|d| *d > 0)
        .ok_or_else(|| format!("D must be a whole number of 1 or more, found \"{d}\""))?;
    let length: f64 = length
        .trim()
        .parse()
        .ok()
        .filter(|l: &f64| l.is_finite())
        .ok_or_else(|| format!("LENGTH must be a finite number, found \"{length}\""))?;
    Ok((d, length))
}

/// Appends the motion blocks of `step` to `out` as JSON lines, writing `out` out when it has
/// grown (not once the reader has gone).
fn print_blocks(step: &[Decoded], axes: &[String], out: &mut String, reader_gone: &mut bool) {
    for d in step {
        if let Decoded::Motion(m) = d {
            push_motion_json(out, m, axes);
            out.push('\n');
        }
    }
    if out.len() > 1 << 16 && !*reader_gone {
        *reader_gone = !emit(out);
        out.clear();
    }
}

/// Writes `text` to stdout; `false` when the reader has gone (a closed pipe ends quietly).
fn emit(text: &str) -> bool {
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_all(text.as_bytes())
        .and_then(|()| stdout.flush())
        .is_ok()
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
    let search = SearchPath(args.search.clone());
    let mut failed = false;
    let mut out = String::new();
    for file in &args.files {
        let name = file.display().to_string();
        // The bytes become the text in place when they are UTF-8 (a copy would double the
        // file's share of the peak memory).
        let src = match std::fs::read(file) {
            Ok(bytes) => String::from_utf8(bytes)
                .unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned()),
            Err(e) => {
                eprintln!("{name}:1:1: error: cannot read the file: {e}");
                failed = true;
                continue;
            }
        };
        let setup = DecoderSetup {
            tools: args.tools.clone(),
            tools_unknown: args.tools.is_empty(),
            ..DecoderSetup::default()
        };
        // A straight program is checked as it is read (one window of its tree in memory), any
        // other whole, with the subroutine files it calls.
        // The whole check takes the text over; the straight one reads it again to print.
        let mut src = Some(src);
        let text = src.as_deref().unwrap_or("");
        let (diags, whole) = match check_straight(text, &axes, &setup, &ZeroVars, None) {
            Some(diags) => (diags, None),
            None => {
                let dir = file.parent().map(Path::to_path_buf);
                let (set, diags) = check_program(
                    &name,
                    src.take().unwrap_or_default(),
                    &axes,
                    &setup,
                    (dir.as_deref(), &search),
                    &ZeroVars,
                    None,
                );
                (diags, Some(set))
            }
        };
        for d in &diags {
            out.push_str(&d.render(&name));
            out.push('\n');
        }
        failed |= !diags.is_empty();
        if args.blocks && diags.is_empty() {
            // Run again, printing as it goes: a clean program's blocks are printed without
            // keeping them all (they take more memory than the program).
            let mut reader_gone = false;
            // The blocks' targets are per slot of the channel's layout.
            let slot_names = AxisLayout::new(&axes).names().to_vec();
            let mut print =
                |step: &[Decoded]| print_blocks(step, &slot_names, &mut out, &mut reader_gone);
            match &whole {
                None => {
                    let text = src.as_deref().unwrap_or("");
                    check_straight(text, &axes, &setup, &ZeroVars, Some(&mut print));
                }
                Some(set) => {
                    let mut decoder = DecoderState::new(&axes);
                    decoder.configure(&setup);
                    let budget = cnc_core::nc::decode::check_budget(set.block_count());
                    check_set(set, &mut decoder, &ZeroVars, budget, Some(&mut print));
                }
            }
            if reader_gone {
                return exit_code(failed);
            }
        }
    }
    emit(&out);
    exit_code(failed)
}

fn exit_code(failed: bool) -> ExitCode {
    if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
