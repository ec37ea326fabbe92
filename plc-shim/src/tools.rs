//! `plc get`, `plc set`, `plc watch`: single leaves of a running CNC's image by ST path (the
//! paths of `cnc hli symbols`), from a shell, beside the PLC process; and the variables of a
//! Structured Text PLC by name (`MAIN.fbCam.Busy`, `st::vars`), which its PLC writes for a
//! tool before its next cycle (a value the variable's type cannot hold is refused).
//!
//! A tool attaches like a PLC (same layout checks) but does not claim the segment: the CNC
//! keeps supervising its PLC. Writes follow the handshake protocol of the control units, so a
//! tool cannot tear a datum the other side owns:
//!
//! | leaf                                   | written when                | value        |
//! |----------------------------------------|-----------------------------|--------------|
//! | CNC-owned (`*_r`, states)              | never                       |              |
//! | payload of a PLC→CNC unit (`X_w.*`)    | its `X_semaphore_rw` FALSE  | any in range |
//! | `X_semaphore_rw` of a PLC→CNC unit     | it is FALSE                 | TRUE only    |
//! | `X_semaphore_rw` of a CNC→PLC unit     | it is TRUE                  | FALSE only   |
//! | `transition_w.*` parameters            | `transition_w.command` is 0 | any in range |
//! | `transition_w.command`                 | it is 0                     | not 0        |
//! | other PLC-owned leaves (`enable_w`)    | always                      | any in range |
//!
//! `plc set` takes PATH VALUE pairs, checks all of them (each against the state the earlier
//! pairs leave) and writes only if every one passes, in the order given: payload first, then
//! its semaphore publishes it. Exit codes: 0 done, 1 no CNC to attach to, 2 bad input
//! (unknown path, value of the wrong type or range), 4 refused by the protocol.

use crate::st::vars::Variables;
use core::time::Duration;
use hli::access::{AccessError, Leaf, Value};
use hli::enums::SegmentState;
use hli::protocol::Refused;
pub use hli::protocol::{show, Refusal, Write};
use hli::ImageMemory;
use hli_transport::segment::{AttachError, PlcSegment};
use plc_st::types::Elem;
use std::process::ExitCode;

/// Instance `cnc demo` runs as, and the tools' default.
pub const DEFAULT_INSTANCE: &str = "cnc-demo";

/// The tool commands of the `plc` binary.
#[derive(Debug, Clone, clap::Subcommand)]
pub enum ToolCommand {
    /// Print leaves of a running CNC's image: `PATH = VALUE` per line.
    Get {
        /// ST paths (see `cnc hli symbols`).
        #[arg(required = true)]
        paths: Vec<String>,
        /// CNC instance.
        #[arg(long, default_value = DEFAULT_INSTANCE)]
        instance: String,
    },
    /// Write leaves by the handshake protocol: PATH VALUE [PATH VALUE ...], all or nothing.
    Set {
        /// PATH VALUE pairs; values are numbers, TRUE or FALSE.
        #[arg(required = true, num_args = 2.., allow_negative_numbers = true)]
        pairs: Vec<String>,
        /// CNC instance.
        #[arg(long, default_value = DEFAULT_INSTANCE)]
        instance: String,
    },
    /// Print leaves every interval until the CNC ends (or `--count` lines).
    Watch {
        /// ST paths.
        #[arg(required = true)]
        paths: Vec<String>,
        /// Interval, ms.
        #[arg(long, default_value_t = 100)]
        interval: u64,
        /// Stop after this many lines.
        #[arg(long)]
        count: Option<u64>,
        /// CNC instance.
        #[arg(long, default_value = DEFAULT_INSTANCE)]
        instance: String,
    },
    /// Operate a channel through its control unit: select, start, stop, hold, resume, reset,
    /// single block, mode; or print its state.
    Channel(crate::channel_tool::ChannelArgs),
    /// Run one block of the library (by its name and timeline inputs) against a running CNC
    /// until it ends: for commissioning.
    Call(crate::call_tool::CallArgs),
    /// Print the block library as Structured Text: AXIS_REF, the modes' and flags' constants
    /// under the manuals' names, one FUNCTION_BLOCK per block; then the blocks ST cannot
    /// call yet (in a comment).
    Library,
    /// Check Structured Text files as `plc --st` would load them: every diagnostic with
    /// FILE:LINE:COL (exit 2 if there is one).
    Check {
        /// The files, one program.
        #[arg(required = true)]
        files: Vec<std::path::PathBuf>,
    },
}

/// Why a tool did not do what it was asked.
#[derive(Debug, thiserror::Error)]
pub enum ToolError {
    /// No CNC to attach to (or one of another layout).
    #[error("{0}")]
    Attach(#[from] AttachError),
    /// An unknown path, or a value of the wrong type or range.
    #[error("{0}")]
    Access(#[from] AccessError),
    /// A value that is not a number, TRUE or FALSE.
    #[error("`{value}` for `{path}` is not a number, TRUE or FALSE")]
    NotAValue {
        /// The path.
        path: String,
        /// The text given.
        value: String,
    },
    /// PATH without a VALUE.
    #[error("`{0}` has no value: give PATH VALUE pairs")]
    MissingValue(String),
    /// An ST PLC's variables: none published, an unknown one, a value refused.
    #[error("{0}")]
    St(String),
    /// The protocol forbids this write now.
    #[error("`{path}`: {reason}")]
    Refused {
        /// The path.
        path: String,
        /// Why.
        reason: Refusal,
    },
}

impl From<Refused> for ToolError {
    fn from(r: Refused) -> Self {
        ToolError::Refused {
            path: r.path,
            reason: r.reason,
        }
    }
}

/// Checks `writes` against the image and the protocol ([`hli::protocol::check_protocol`]).
pub fn check_protocol(memory: &ImageMemory, writes: &[Write<'_>]) -> Result<(), ToolError> {
    Ok(hli::protocol::check_protocol(memory, writes)?)
}

impl ToolError {
    /// The exit code of this failure.
    pub fn exit_code(&self) -> u8 {
        match self {
            ToolError::Attach(_) => 1,
            ToolError::Refused { .. } => 4,
            _ => 2,
        }
    }
}

/// Parses a value for `leaf`: TRUE/FALSE, a decimal or `0x` hexadecimal integer, or a
/// number with a fraction or exponent.
fn parse_value(path: &str, text: &str, leaf: &Leaf) -> Result<Value, ToolError> {
    let bad = || ToolError::NotAValue {
        path: path.to_string(),
        value: text.to_string(),
    };
    let t = text.trim();
    let value = match t.to_ascii_uppercase().as_str() {
        "TRUE" => Value::Unsigned(1),
        "FALSE" => Value::Unsigned(0),
        upper => {
            if let Some(hex) = upper.strip_prefix("0X") {
                Value::Unsigned(u64::from_str_radix(hex, 16).map_err(|_| bad())?)
            } else if let Ok(i) = t.parse::<i64>() {
                Value::Int(i)
            } else if let Ok(u) = t.parse::<u64>() {
                Value::Unsigned(u)
            } else {
                Value::Real(t.parse::<f64>().map_err(|_| bad())?)
            }
        }
    };
    Ok(leaf.check(path, value)?)
}

/// Resolves the paths and parses the values of `pairs` (PATH VALUE ...); needs no CNC.
pub fn parse_pairs(pairs: &[String]) -> Result<Vec<Write<'_>>, ToolError> {
    pairs
        .chunks(2)
        .map(|pair| {
            let path = pair[0].as_str();
            let text = pair
                .get(1)
                .ok_or_else(|| ToolError::MissingValue(path.to_string()))?;
            let leaf = Leaf::resolve(path)?;
            let value = parse_value(path, text, &leaf)?;
            Ok(Write { path, leaf, value })
        })
        .collect()
}

fn attach(instance: &str) -> Result<PlcSegment, ToolError> {
    Ok(PlcSegment::inspect(instance)?)
}

/// `plc get`: the lines it prints (leaves of the image, variables of an ST PLC).
pub fn get(instance: &str, paths: &[String]) -> Result<Vec<String>, ToolError> {
    let (sources, vars) = sources(instance, paths)?;
    let segment = attach(instance)?;
    if let Some(Err(e)) = vars.as_ref().map(Variables::refresh) {
        // A PLC that does not cycle (a stalled lockstep run): the last copy, said so.
        eprintln!("plc get: {e}: the values of the last copy");
    }
    Ok(paths
        .iter()
        .zip(&sources)
        .map(|(p, s)| format!("{p} = {}", read(s, &segment, vars.as_ref())))
        .collect())
}

/// `plc set`: parses every pair (a typo is reported the same with or without a CNC), checks
/// them against the protocol, then writes them in order; returns the lines it prints.
pub fn set(instance: &str, pairs: &[String]) -> Result<Vec<String>, ToolError> {
    // No path of the image: the ST PLC's variables, if one publishes them.
    let image = |p: &[String]| Leaf::resolve(&p[0]).is_ok();
    if !pairs.chunks(2).any(image) {
        if let Ok(vars) = Variables::open(instance) {
            return set_st(&vars, pairs);
        }
    }
    let writes = parse_pairs(pairs)?;
    let segment = attach(instance)?;
    check_protocol(segment.memory(), &writes)?;
    Ok(writes
        .iter()
        .map(|w| {
            w.leaf.write(segment.memory(), w.value);
            format!("{} := {}", w.path, show(&w.leaf, w.value))
        })
        .collect())
}

/// Where a path of `plc get|watch` is: a leaf of the image, or a variable of the ST PLC
/// (`MAIN.fbCam.Busy`, published by `plc --st`).
enum Source {
    Image(Leaf),
    St(usize),
}

/// The sources of `paths`: a path the image does not know is looked for among the ST PLC's
/// variables (opened only then).
fn sources(
    instance: &str,
    paths: &[String],
) -> Result<(Vec<Source>, Option<Variables>), ToolError> {
    let mut vars: Option<Variables> = None;
    let mut out = Vec::with_capacity(paths.len());
    for p in paths {
        match Leaf::resolve(p) {
            Ok(leaf) => out.push(Source::Image(leaf)),
            Err(image_error) => {
                if vars.is_none() {
                    let opened = Variables::open(instance);
                    let why = |e: String| ToolError::St(format!("{image_error}; {e}"));
                    vars = Some(opened.map_err(why)?);
                }
                let index = vars.as_ref().and_then(|v| v.find(p));
                out.push(Source::St(index.ok_or(image_error)?));
            }
        }
    }
    Ok((out, vars))
}

/// The value of `source` as `plc get` prints it.
fn read(source: &Source, segment: &PlcSegment, vars: Option<&Variables>) -> String {
    match (source, vars) {
        (Source::Image(leaf), _) => show(leaf, leaf.read(segment.memory())),
        (Source::St(i), Some(v)) => {
            if let Some(text) = v.read_text(*i) {
                return text;
            }
            let value = v.read(*i);
            match v.symbol(*i).elem {
                Elem::Bool if value != 0.0 => "TRUE".into(),
                Elem::Bool => "FALSE".into(),
                _ => value.to_string(),
            }
        }
        (Source::St(_), None) => "?".into(),
    }
}

/// `plc set` of the ST PLC's variables: every pair's path resolved and value parsed first,
/// then each written through the PLC in the order given (a refused one stops the rest).
fn set_st(vars: &Variables, pairs: &[String]) -> Result<Vec<String>, ToolError> {
    let mut writes = Vec::new();
    for pair in pairs.chunks(2) {
        let path = pair[0].as_str();
        let text = pair
            .get(1)
            .ok_or_else(|| ToolError::MissingValue(path.to_string()))?;
        let index = vars
            .find(path)
            .ok_or_else(|| ToolError::St(format!("unknown variable `{path}` of the ST PLC")))?;
        if vars.symbol(index).text.is_some() {
            let why = format!("`{path}` is a STRING: `plc set` writes numbers and BOOLs only");
            return Err(ToolError::St(why));
        }
        let value = match text.trim().to_ascii_uppercase().as_str() {
            "TRUE" => 1.0,
            "FALSE" => 0.0,
            t => t.parse::<f64>().map_err(|_| ToolError::NotAValue {
                path: path.to_string(),
                value: text.to_string(),
            })?,
        };
        writes.push((path, index, value, text));
    }
    let mut lines = Vec::new();
    for (path, index, value, text) in writes {
        vars.write(index, value).map_err(ToolError::St)?;
        lines.push(format!("{path} := {}", text.trim()));
    }
    Ok(lines)
}

/// Runs a tool command; prints its output and returns the exit code.
pub fn main(command: ToolCommand) -> ExitCode {
    let result = match &command {
        ToolCommand::Channel(args) => return crate::channel_tool::main(args),
        ToolCommand::Call(args) => return crate::call_tool::main(args),
        ToolCommand::Library => {
            let lib = crate::st::library::Library::new();
            print!("{}", lib.text());
            for (block, input) in crate::st::library::unavailable() {
                println!("(* not in ST yet: {block}, for its input {input} *)");
            }
            for (block, input) in crate::st::library::left_out() {
                println!("(* {block}: input {input} is not in ST yet *)");
            }
            return ExitCode::SUCCESS;
        }
        ToolCommand::Check { files } => {
            return match crate::st::StProgram::load(files, 1) {
                Ok(p) => {
                    let (pous, methods) = p.pous();
                    let methods = match methods {
                        0 => String::new(),
                        n => format!(", {n} methods and actions"),
                    };
                    let s = if pous == 1 { "" } else { "s" };
                    let how = if p.program().is_native() {
                        "native code"
                    } else {
                        "operations (no native code for this machine)"
                    };
                    println!("{}: ok, {pous} POU{s}{methods}, as {how}", files.len());
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprint!("{e}");
                    ExitCode::from(2)
                }
            }
        }
        ToolCommand::Get { paths, instance } => get(instance, paths).map(print_lines),
        ToolCommand::Set { pairs, instance } => set(instance, pairs).map(print_lines),
        ToolCommand::Watch {
            paths,
            interval,
            count,
            instance,
        } => watch(
            instance,
            paths,
            Duration::from_millis((*interval).max(1)),
            *count,
        ),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("plc: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

fn print_lines(lines: Vec<String>) {
    for line in lines {
        println!("{line}");
    }
}

/// `plc watch`: a header line of the paths, then `TICK VALUE...` every interval until the
/// CNC closes its segment, a signal arrives or `count` lines are printed.
fn watch(
    instance: &str,
    paths: &[String],
    interval: Duration,
    count: Option<u64>,
) -> Result<(), ToolError> {
    use std::io::Write as _;
    let (sources, vars) = sources(instance, paths)?;
    let segment = attach(instance)?;
    hli_transport::signals::capture();
    let mut out = std::io::stdout().lock();
    let header = format!("cnc_tick {}", paths.join(" "));
    if writeln!(out, "{header}").is_err() {
        return Ok(());
    }
    let (mut printed, mut stale) = (0u64, false);
    while count.is_none_or(|c| printed < c) {
        if segment.cnc_state() != Ok(SegmentState::Ready) {
            eprintln!("plc watch: the CNC closed its segment");
            break;
        }
        if hli_transport::signals::take().is_some() {
            break;
        }
        if let Some(Err(e)) = vars.as_ref().map(Variables::refresh) {
            if !stale {
                eprintln!("plc watch: {e}: the values of the last copy until it cycles again");
            }
            stale = true;
        } else {
            stale = false;
        }
        let mut line = segment.cnc_heartbeat().to_string();
        for source in &sources {
            line.push(' ');
            line.push_str(&read(source, &segment, vars.as_ref()));
        }
        // A closed pipe (`plc watch ... | head`) ends the watch quietly.
        if writeln!(out, "{line}").and_then(|()| out.flush()).is_err() {
            break;
        }
        printed += 1;
        if count.is_none_or(|c| printed < c) {
            std::thread::sleep(interval);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use hli::image::heap_image;

    const SEM: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_semaphore_rw";
    const ROT: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_w.rotation[2]";
    const REQ_SEM: &str = "gpCh[0]^channel_mc_control.dyn_cs.request_semaphore_rw";
    const ENABLE: &str = "gpCh[0]^channel_mc_control.dyn_cs.enable_w";
    const T_CMD: &str = "gpCh[0]^channel_mc_control.dyn_cs.transition_w.command";
    const T_FILTER: &str = "gpCh[0]^channel_mc_control.dyn_cs.transition_w.filter_max_ticks";
    const STATE: &str = "gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state";

    fn pairs(p: &[&str]) -> Vec<String> {
        p.iter().map(|s| s.to_string()).collect()
    }

    /// Parses and checks `pairs` as `plc set` does, writing nothing.
    fn plan(memory: &ImageMemory, pairs: &[String]) -> Result<(), ToolError> {
        check_protocol(memory, &parse_pairs(pairs)?)
    }

    fn refusal(memory: &ImageMemory, p: &[&str]) -> Option<Refusal> {
        match plan(memory, &pairs(p)) {
            Err(ToolError::Refused { reason, .. }) => Some(reason),
            Ok(_) => None,
            Err(e) => panic!("{e}"),
        }
    }

    fn apply(memory: &ImageMemory, p: &[&str]) {
        let given = pairs(p);
        let writes = parse_pairs(&given).unwrap();
        check_protocol(memory, &writes).unwrap();
        for w in writes {
            w.leaf.write(memory, w.value);
        }
    }

    #[test]
    fn a_payload_is_written_only_while_its_semaphore_is_false() {
        let memory = heap_image(1, 1);
        apply(&memory, &[ROT, "900000", SEM, "TRUE"]);
        assert_eq!(
            Leaf::resolve(ROT).unwrap().read(&memory),
            Value::Int(900_000)
        );
        assert_eq!(refusal(&memory, &[ROT, "1"]), Some(Refusal::Pending));
        assert_eq!(refusal(&memory, &[SEM, "TRUE"]), Some(Refusal::PublishOnly));
        assert_eq!(
            refusal(&memory, &[SEM, "FALSE"]),
            Some(Refusal::PublishOnly)
        );
        // The order counts: the semaphore last publishes, first blocks the payload.
        let fresh = heap_image(1, 1);
        assert_eq!(
            refusal(&fresh, &[SEM, "TRUE", ROT, "1"]),
            Some(Refusal::Pending)
        );
        assert_eq!(refusal(&fresh, &[ROT, "1", SEM, "TRUE"]), None);
    }

    #[test]
    fn cnc_leaves_semaphores_and_commands_keep_their_direction() {
        let memory = heap_image(1, 1);
        assert_eq!(refusal(&memory, &[STATE, "2"]), Some(Refusal::CncOwned));
        assert_eq!(
            refusal(&memory, &[REQ_SEM, "TRUE"]),
            Some(Refusal::TakeOnly)
        );
        assert_eq!(
            refusal(&memory, &[REQ_SEM, "FALSE"]),
            Some(Refusal::TakeOnly)
        );
        Leaf::resolve(REQ_SEM)
            .unwrap()
            .write(&memory, Value::Unsigned(1));
        assert_eq!(refusal(&memory, &[REQ_SEM, "FALSE"]), None);
        assert_eq!(refusal(&memory, &[T_CMD, "0"]), Some(Refusal::CommandZero));
        apply(&memory, &[T_FILTER, "200", T_CMD, "1"]);
        assert_eq!(
            refusal(&memory, &[T_FILTER, "5"]),
            Some(Refusal::CommandPending)
        );
        assert_eq!(
            refusal(&memory, &[T_CMD, "2"]),
            Some(Refusal::CommandPending)
        );
        assert_eq!(refusal(&memory, &[ENABLE, "TRUE"]), None);
    }

    #[test]
    fn bad_values_are_refused_before_anything_is_written() {
        let memory = heap_image(1, 1);
        for (p, v) in [(ENABLE, "2"), (ROT, "0.5"), (ROT, "abc"), (ROT, "1e12")] {
            let e = plan(&memory, &pairs(&[ROT, "7", p, v])).unwrap_err();
            assert_eq!(e.exit_code(), 2, "{e}");
        }
        assert_eq!(Leaf::resolve(ROT).unwrap().read(&memory), Value::Int(0));
        let e = plan(&memory, &pairs(&["gpCh[0]^nope", "1"])).unwrap_err();
        assert!(e.to_string().contains("no symbol `gpCh[0]^nope`"), "{e}");
        assert!(matches!(
            plan(&memory, &pairs(&[ROT])),
            Err(ToolError::MissingValue(_))
        ));
    }
}
