//! `plc channel ACTION --channel N`: a channel command from a shell, through the channel
//! control unit of a running CNC (`gpCh[N]^channel_control`), the way a PLC block sends it.
//! The tool attaches without claiming the PLC slot, writes the command when its semaphore is
//! free, waits for the channel's answer and prints it; `state` prints the state block.
//!
//! The unit has one writer, the PLC: while a PLC is attached the tool refuses to send (its
//! command and the PLC's could mix) unless `--force`; `state` always works.
//!
//! Exit codes: 0 done, 1 no CNC to attach to, 2 bad input (no such channel, a name that does
//! not fit), 3 no answer in time, 4 refused by the channel (the code and its text printed) or
//! because a PLC is attached.

use crate::tools::ToolError;
use core::time::Duration;
use hli::enums::{
    ChannelCommand, ChannelCommandError, ChannelCommandState, ChannelMode, ChannelSignal,
    ChannelState,
};
use hli::handshake::SendError;
use hli::layout::{nul_padded, nul_padded_str, HliChannelCommand, HliChannelControlState};
use hli::views::{PlcChannel, PlcView};
use std::process::ExitCode;

/// What `plc channel` does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Action {
    /// SELECT the program `--program` (with `--start-line`).
    Select,
    /// START the selected program (with `--program`: SELECT it first), or go on from a hold.
    Start,
    /// STOP: decelerate on the path and end the program.
    Stop,
    /// FEED_HOLD: decelerate on the path and hold.
    Hold,
    /// RESUME after a feed hold.
    Resume,
    /// RESET: end the program, clear the errors (decelerates first).
    Reset,
    /// SINGLE_BLOCK on (`--value 1`) or off (`--value 0`).
    SingleBlock,
    /// MODE: `--value 0` automatic, `--value 1` manual.
    Mode,
    /// Print the state block.
    State,
}

/// The arguments of `plc channel`.
#[derive(Debug, Clone, clap::Args)]
pub struct ChannelArgs {
    /// What to do.
    pub action: Action,
    /// The channel (its gpCh index, 0-based).
    #[arg(long, default_value_t = 0)]
    pub channel: usize,
    /// SELECT / START: the program's file name in the channel's program folder.
    #[arg(long)]
    pub program: Option<String>,
    /// SELECT: the source line to start at (0: the first block).
    #[arg(long, default_value_t = 0)]
    pub start_line: u32,
    /// SINGLE_BLOCK (1 on, 0 off) and MODE (0 automatic, 1 manual).
    #[arg(long, default_value_t = 1)]
    pub value: i32,
    /// How long to wait for the channel's answer, ms (a stop waits for rest).
    #[arg(long, default_value_t = 10_000)]
    pub timeout_ms: u64,
    /// Send even while a PLC is attached (its commands and the tool's could mix: the unit
    /// has one writer, the PLC).
    #[arg(long)]
    pub force: bool,
    /// CNC instance.
    #[arg(long, default_value = crate::tools::DEFAULT_INSTANCE)]
    pub instance: String,
}

/// How a command ended.
#[derive(Debug)]
enum Failure {
    Tool(ToolError),
    BadInput(String),
    NoAnswer(String),
    Refused(String),
}

impl From<ToolError> for Failure {
    fn from(e: ToolError) -> Self {
        Failure::Tool(e)
    }
}

/// Runs `plc channel`; prints what happened and returns the exit code.
pub fn main(args: &ChannelArgs) -> ExitCode {
    match run(args) {
        Ok(lines) => {
            for line in lines {
                println!("{line}");
            }
            ExitCode::SUCCESS
        }
        Err(failure) => {
            let (code, text) = match failure {
                Failure::Tool(e) => (e.exit_code(), e.to_string()),
                Failure::BadInput(t) => (2, t),
                Failure::NoAnswer(t) => (3, t),
                Failure::Refused(t) => (4, t),
            };
            eprintln!("plc channel: {text}");
            ExitCode::from(code)
        }
    }
}

fn run(args: &ChannelArgs) -> Result<Vec<String>, Failure> {
    if let Some(p) = &args.program {
        if p.is_empty() || p.len() >= hli::layout::PROGRAM_NAME_LEN {
            return Err(Failure::BadInput(format!("--program {p:?}: 1 to 63 bytes")));
        }
    }
    let segment =
        hli_transport::segment::PlcSegment::inspect(&args.instance).map_err(ToolError::from)?;
    let view = PlcView::new(segment.memory());
    let ch = view.gp_ch(args.channel).ok_or_else(|| {
        Failure::BadInput(format!(
            "channel {} does not exist (the CNC has {})",
            args.channel,
            view.channel_count()
        ))
    })?;
    let mut lines = Vec::new();
    if let (Some(pid), false) = (
        segment.attached_plc(),
        args.action == Action::State || args.force,
    ) {
        return Err(Failure::Refused(format!(
            "a PLC (pid {pid}) operates this CNC and owns the channel control unit; send the command from it, or pass --force"
        )));
    }
    let command = match args.action {
        Action::State => return Ok(describe(&crate::blocks::channel::stable_state(&ch))),
        Action::Start if args.program.is_some() => {
            lines.push(send(&ch, ChannelCommand::Select, args)?);
            ChannelCommand::Start
        }
        Action::Select => ChannelCommand::Select,
        Action::Start => ChannelCommand::Start,
        Action::Stop => ChannelCommand::Stop,
        Action::Hold => ChannelCommand::FeedHold,
        Action::Resume => ChannelCommand::Resume,
        Action::Reset => ChannelCommand::Reset,
        Action::SingleBlock => ChannelCommand::SingleBlock,
        Action::Mode => ChannelCommand::Mode,
    };
    lines.push(send(&ch, command, args)?);
    Ok(lines)
}

/// Sends `kind` and waits for its answer (Done, or the refusal with its code and text).
fn send(ch: &PlcChannel<'_>, kind: ChannelCommand, args: &ChannelArgs) -> Result<String, Failure> {
    let id = (std::process::id() << 8) ^ kind.raw() as u32;
    let command = HliChannelCommand {
        command_id: id,
        command: kind.raw(),
        start_line: args.start_line.min(i32::MAX as u32) as i32,
        value: args.value,
        program: nul_padded(args.program.as_deref().unwrap_or("")),
    };
    let deadline = std::time::Instant::now() + Duration::from_millis(args.timeout_ms);
    let no_answer = |what: &str| Failure::NoAnswer(format!("{kind:?}: {what} within --timeout-ms"));
    loop {
        match ch.channel_command().try_send(&command) {
            Ok(()) => break,
            Err(SendError::Busy) if std::time::Instant::now() < deadline => {}
            Err(SendError::Busy) => return Err(no_answer("the unit was not free")),
            Err(SendError::Violation(v)) => return Err(Failure::Refused(format!("{kind:?}: {v}"))),
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    loop {
        let s = crate::blocks::channel::stable_state(ch);
        if s.command_id == id {
            match ChannelCommandState::decode(s.command_state) {
                Ok(ChannelCommandState::Done) => return Ok(format!("{kind:?}: done")),
                Ok(ChannelCommandState::Refused) => {
                    let code = ChannelCommandError::decode(s.command_error)
                        .map_or_else(|_| "unknown".to_string(), |e| format!("{e:?}"));
                    let text = nul_padded_str(&s.message).unwrap_or("");
                    return Err(Failure::Refused(format!(
                        "{kind:?} refused: 0x{:X} {code}{}{text}",
                        s.command_error,
                        if text.is_empty() { "" } else { ": " }
                    )));
                }
                _ => {}
            }
        }
        if std::time::Instant::now() >= deadline {
            return Err(no_answer("no answer"));
        }
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// The state block as `key = value` lines.
pub fn describe(s: &HliChannelControlState) -> Vec<String> {
    let state = ChannelState::decode(s.state).map_or_else(|e| e.to_string(), |v| format!("{v:?}"));
    let mode = ChannelMode::decode(s.mode).map_or_else(|e| e.to_string(), |v| format!("{v:?}"));
    let signals: Vec<String> = ChannelSignal::ALL
        .iter()
        .filter(|b| s.signals & b.raw() != 0)
        .map(|b| format!("{b:?}"))
        .collect();
    vec![
        format!("state = {state}"),
        format!("mode = {mode}"),
        format!("program = {}", nul_padded_str(&s.program).unwrap_or("?")),
        format!("block = {}", s.block_nr),
        format!("single_block = {:?}", s.single_block),
        format!("feed_hold = {:?}", s.feed_hold),
        format!("signals = {}", signals.join(" ")),
        format!("programs_ended = {}", s.programs_ended),
        format!("error_id = 0x{:X}", s.error_id),
        format!(
            "last command = {} state {} error 0x{:X} {}",
            s.command_id,
            s.command_state,
            s.command_error,
            nul_padded_str(&s.message).unwrap_or("")
        ),
    ]
}
