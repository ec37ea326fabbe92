//! `plc call BLOCK [KEY=VALUE ...]`: one block of the library, by the name and with the inputs
//! a timeline gives it, run against a running CNC until it ends; for commissioning (an axis
//! moved, a cam coupled, a FIFO group started without writing a program).
//!
//! The call is a one-step timeline (`[[step]] call = { block = .., instance = "call", .. }`),
//! so the block and its inputs are checked exactly as a scenario's are. The tool attaches as
//! `plc get` does (without claiming the PLC slot) and opens its own call client beside a PLC
//! that may run; it runs the block once per CNC tick until one of Done, Error,
//! CommandAborted, InSync, InVelocity or Status (MC_Power) rises, then prints the block's report (its output
//! edges and what it read). A channel block, whose control unit has one writer (the PLC), is
//! refused while a PLC is attached unless `--force`.
//!
//! Exit codes: 0 done (Done, InSync, InVelocity or Status), 1 no CNC, 2 bad input, 3 no end within
//! `--max-cycles` or the CNC went away, 4 the block ended in Error or CommandAborted (or was
//! refused for a running PLC).

use crate::runtime::{Link, PlcIo};
use crate::timeline::Timeline;
use crate::tools::{ToolError, DEFAULT_INSTANCE};
use hli::views::PlcView;
use hli_transport::rpc::AcyclicClient;
use hli_transport::segment::PlcSegment;
use std::process::ExitCode;
use std::time::Duration;

/// `plc call`.
#[derive(Debug, Clone, clap::Args)]
pub struct CallArgs {
    /// The block, by its library name (MC_Power, MC_MoveAbsolute, MC_CamIn, FiFoStart ...).
    pub block: String,
    /// Its inputs as a timeline names them, KEY=VALUE with TOML values (`axis=0`,
    /// `position=100.0`, `start_mode="absolute"`, `rows=[[0.0,0.0],[90.0,10.0]]`).
    pub inputs: Vec<String>,
    /// CNC ticks to run the block before giving up.
    #[arg(long, default_value_t = 10_000)]
    pub max_cycles: u64,
    /// Run a channel block even while a PLC is attached.
    #[arg(long)]
    pub force: bool,
    /// CNC instance.
    #[arg(long, default_value = DEFAULT_INSTANCE)]
    pub instance: String,
}

/// How a call ended, with its exit code and text.
struct Ended(u8, String);

/// Runs `plc call`; prints the block's report and returns the exit code.
pub fn main(args: &CallArgs) -> ExitCode {
    match run(args) {
        Ok(report) => {
            print!("{report}");
            ExitCode::SUCCESS
        }
        Err(Ended(code, text)) => {
            eprintln!("plc call: {text}");
            ExitCode::from(code)
        }
    }
}

/// The one-step timeline of the call, checked.
fn timeline(args: &CallArgs) -> Result<Timeline, Ended> {
    let bad = |text: String| Ended(2, text);
    let mut call = format!("block = {:?}, instance = \"call\"", args.block);
    for input in &args.inputs {
        let (key, value) = input
            .split_once('=')
            .ok_or_else(|| bad(format!("`{input}`: give inputs as KEY=VALUE")))?;
        let (key, value) = (key.trim(), value.trim());
        let word = |c: char| c.is_ascii_alphanumeric() || c == '_';
        if key.is_empty() || !key.chars().all(word) || key == "block" || key == "instance" {
            return Err(bad(format!("`{key}` is no input name")));
        }
        toml::from_str::<toml::Table>(&format!("v = {value}")).map_err(|_| {
            bad(format!(
                "`{key}` = `{value}` is no value (numbers, true/false, \"text\", [..])"
            ))
        })?;
        call.push_str(&format!(", {key} = {value}"));
    }
    Timeline::parse("plc call", &format!("[[step]]\ncall = {{ {call} }}\n"))
        .map_err(|e| bad(e.to_string()))
}

fn run(args: &CallArgs) -> Result<String, Ended> {
    let mut timeline = timeline(args)?;
    let tool = |e: ToolError| Ended(e.exit_code(), e.to_string());
    let segment = PlcSegment::inspect(&args.instance).map_err(|e| tool(ToolError::from(e)))?;
    if let (Some(pid), true, false) = (
        segment.attached_plc(),
        timeline.block_channels().next().is_some(),
        args.force,
    ) {
        return Err(Ended(
            4,
            format!("a PLC (pid {pid}) operates this CNC and owns the channel control unit; call the block from it, or pass --force"),
        ));
    }
    let mut client = AcyclicClient::open(&args.instance)
        .map_err(|e| Ended(1, format!("the CNC's call mailbox: {e}")))?;
    let mut last_tick = segment.cnc_heartbeat();
    let mut cycle = 0;
    let mut waited = 0u64;
    while cycle < args.max_cycles {
        if !segment.cnc_process_alive() {
            return Err(Ended(
                3,
                format!("the CNC went away\n{}", timeline.summary()),
            ));
        }
        let tick = segment.cnc_heartbeat();
        if tick == last_tick {
            // A CNC that ticks no more (stopped, or a stalled machine) is no answer either.
            waited += 1;
            if waited > 5_000 {
                return Err(Ended(
                    3,
                    format!("the CNC does not tick\n{}", timeline.summary()),
                ));
            }
            std::thread::sleep(Duration::from_micros(200));
            continue;
        }
        (last_tick, waited) = (tick, 0);
        let mut io = PlcIo {
            view: PlcView::new(segment.memory()),
            memory: segment.memory(),
            acyclic: &mut client,
            cycle,
            link: Link::Operational,
        };
        timeline.cycle_io(&mut io);
        cycle += 1;
        if let Some(outcome) = outcome(&timeline.summary()) {
            return outcome;
        }
    }
    Err(Ended(
        3,
        format!(
            "no end within {} ticks\n{}",
            args.max_cycles,
            timeline.summary()
        ),
    ))
}

/// How the block's report says it ended, if it did: `Ok(report)` for Done, InSync,
/// InVelocity or Status (MC_Power), exit 4 for Error or CommandAborted.
fn outcome(report: &str) -> Option<Result<String, Ended>> {
    let line = report.lines().find(|l| l.starts_with("block call "))?;
    // The outputs after "): ", each "Name tick (xN)": matched by name, never inside the
    // block's own name (MC_ReadStatus ...).
    let outputs = line.split_once("): ").map_or("", |(_, o)| o);
    let rose = |output: &str| {
        outputs
            .split(", ")
            .any(|item| item.split_whitespace().next() == Some(output))
    };
    if rose("Error") || rose("CommandAborted") {
        return Some(Err(Ended(4, report.trim_end().to_string())));
    }
    let ended = rose("Done") || rose("InSync") || rose("InVelocity") || rose("Status");
    ended.then(|| Ok(block_report(report)))
}

/// The block's lines of a timeline report (its edges and what it read).
fn block_report(report: &str) -> String {
    report
        .lines()
        .skip_while(|l| !l.starts_with("block call "))
        .take_while(|l| !l.starts_with("timeline step"))
        .map(|l| format!("{l}\n"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(block: &str, inputs: &[&str]) -> CallArgs {
        CallArgs {
            block: block.to_string(),
            inputs: inputs.iter().map(|s| s.to_string()).collect(),
            max_cycles: 10,
            force: false,
            instance: "none".to_string(),
        }
    }

    /// Bad input is refused before anything attaches: an unknown block, an input the block
    /// does not have, a malformed KEY=VALUE, a value that is no TOML value (exit 2 each).
    #[test]
    fn bad_input_is_refused_before_attaching() {
        for (block, inputs, needle) in [
            ("MC_Teleport", vec!["axis=0"], "MC_Teleport"),
            ("MC_MoveAbsolute", vec!["axis=0", "speed=3"], "speed"),
            ("MC_MoveAbsolute", vec!["axis"], "KEY=VALUE"),
            ("MC_MoveAbsolute", vec!["axis=zero"], "is no value"),
            ("MC_MoveAbsolute", vec!["block=1"], "no input name"),
        ] {
            let Err(Ended(code, text)) = timeline(&args(block, &inputs)) else {
                panic!("{block} {inputs:?} accepted");
            };
            assert_eq!(code, 2, "{text}");
            assert!(text.contains(needle), "{block} {inputs:?}: {text}");
        }
        assert!(timeline(&args("MC_MoveAbsolute", &["axis=0", "position=100.0"])).is_ok());
    }

    #[test]
    fn the_report_says_how_the_block_ended() {
        let report = "block call (MC_MoveAbsolute on gpAx[0]): Busy 2 (x1)\n";
        assert!(outcome(report).is_none());
        let powered = "block call (MC_Power on gpAx[0]): Status 3 (x1)\n";
        assert!(outcome(powered).unwrap().is_ok());
        let done = "block call (MC_MoveAbsolute on gpAx[0]): Busy 2 (x1), Done 90 (x1)\ntimeline step 1: fired\n";
        assert_eq!(
            outcome(done).unwrap().ok().unwrap(),
            "block call (MC_MoveAbsolute on gpAx[0]): Busy 2 (x1), Done 90 (x1)\n"
        );
        let failed =
            "block call (MC_MoveAbsolute on gpAx[0]): Busy 2 (x1), Error 3 (x1), ErrorID 0x4225\n";
        assert!(matches!(outcome(failed), Some(Err(Ended(4, _)))));
        // A block whose name ends like an output has not ended by its name.
        let named = "block call (FiFoGetStatus on gpFifo[0]): Busy 2 (x1)\n";
        assert!(outcome(named).is_none());
        let named_done = "block call (MC_ReadDone on gpAx[0]): Busy 2 (x1)\n";
        assert!(outcome(named_done).is_none());
    }
}
