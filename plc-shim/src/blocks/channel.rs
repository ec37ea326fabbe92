//! The PLC operates a channel through its control unit (`gpCh[i]^channel_control`): one block
//! per command, PLCopen-style (Execute, Done, Busy, Active, CommandAborted, Error, ErrorID), on
//! the block kernel, and [`ReadChannelState`] for what an operator panel shows.
//!
//! A command is written when `command_semaphore_rw` is free, with an id of this process; the
//! block follows `state_r` while it echoes that id: Busy while the channel carries the command
//! out (a program loading, a stop decelerating), Done or Error with the channel's code
//! (`ChannelCommandError`). Another command taken on the same channel ends the block with
//! CommandAborted (one command unit per channel, as one axis takes one motion command).

use crate::blocks::plain;
use crate::kernel::{Accept, InFlight, Kernel, Outputs, Polled, Step, Waited};
use crate::runtime::PlcIo;
use crate::timeline::registry::{
    input, BlockSpec, InputSpec, Kind, StForm, Target, TimelineBlock, Value,
};
use hli::enums::{ChannelCommand, ChannelCommandState, ChannelMode, ChannelState};
use hli::handshake::SendError;
use hli::layout::{HliChannelCommand, HliChannelControlState, PROGRAM_NAME_LEN};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;

/// Why a channel block reports an error of its own (the channel's refusals are its codes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum ChannelBlockError {
    /// The channel is not configured on this CNC.
    NoChannel = 0x4A81,
    /// The command semaphore held garbage.
    Protocol = 0x4A82,
    /// `state_r` holds a value that is no command state.
    InvalidState = 0x4A83,
}

impl ChannelBlockError {
    /// The ErrorID.
    pub fn code(self) -> u32 {
        self as u32
    }
}

/// The next command id of this process: distinct across processes (the pid in the high bits)
/// and never 0.
fn next_command_id() -> u32 {
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    (std::process::id() << 16) ^ n.wrapping_add(1)
}

/// A command on its way: written when the semaphore allows, answered when `state_r` echoes
/// its id.
struct CommandSend {
    channel: usize,
    command: HliChannelCommand,
    written: bool,
    /// Polls that found the command taken (semaphore FALSE) but another id answered.
    taken_elsewhere: u8,
}

/// What the channel said of the command: its state and code.
type Answer = (ChannelCommandState, u32);

/// The answer with the command's id (the block follows that id).
type Reply = (Answer, u32);

/// The state block read whole: two reads that agree (the CNC writes it leaf by leaf), so a new
/// id is never seen with the previous command's answer.
pub fn stable_state(ch: &hli::views::PlcChannel<'_>) -> HliChannelControlState {
    let mut last = ch.channel_control_state();
    for _ in 0..8 {
        let again = ch.channel_control_state();
        if bytemuck::bytes_of(&again) == bytemuck::bytes_of(&last) {
            return again;
        }
        last = again;
    }
    last
}

fn answer_of(io: &PlcIo<'_>, channel: usize, id: u32) -> Option<Result<Answer, u32>> {
    let Some(ch) = io.gp_ch(channel) else {
        return Some(Err(ChannelBlockError::NoChannel.code()));
    };
    let state = stable_state(&ch);
    if state.command_id != id {
        return None;
    }
    Some(match ChannelCommandState::decode(state.command_state) {
        Ok(ChannelCommandState::None) | Err(_) => Err(ChannelBlockError::InvalidState.code()),
        Ok(s) => Ok((s, state.command_error)),
    })
}

impl InFlight for CommandSend {
    type Reply = Reply;
    type Buffer = ();

    fn poll(&mut self, io: &mut PlcIo<'_>, _: &mut ()) -> Polled<Reply> {
        let Some(ch) = io.gp_ch(self.channel) else {
            return Polled::Answer(Err(ChannelBlockError::NoChannel.code()));
        };
        if !self.written {
            return match ch.channel_command().try_send(&self.command) {
                Ok(()) => {
                    self.written = true;
                    Polled::Progress
                }
                Err(SendError::Busy) => Polled::Waiting,
                Err(SendError::Violation(_)) => {
                    Polled::Answer(Err(ChannelBlockError::Protocol.code()))
                }
            };
        }
        let id = self.command.command_id;
        match answer_of(io, self.channel, id) {
            Some(answer) => Polled::Answer(answer.map(|a| (a, id))),
            // Taken, and another command's answer shows, in two polls one after the other
            // (the CNC writes the answer in the tick it takes a command): another command
            // replaced this one before its answer was seen. Followed, it ends CommandAborted.
            None if ch.channel_command().is_free() == Ok(true) => {
                self.taken_elsewhere += 1;
                if self.taken_elsewhere >= 2 {
                    Polled::Answer(Ok(((ChannelCommandState::Busy, 0), id)))
                } else {
                    Polled::Waiting
                }
            }
            None => Polled::Waiting,
        }
    }
}

/// A command the channel took and carries out.
struct Following {
    channel: usize,
    id: u32,
}

fn accept((answer, id): Reply, channel: usize) -> Accept<Following, ()> {
    match answer {
        (ChannelCommandState::Busy, _) => Accept::Follow(
            Following { channel, id },
            Outputs {
                active: true,
                ..Outputs::busy()
            },
        ),
        (ChannelCommandState::Refused, code) => Accept::Failed(code, ()),
        _ => Accept::Done(()),
    }
}

fn follow(f: &mut Following, io: &mut PlcIo<'_>, _: Waited) -> Step<()> {
    match answer_of(io, f.channel, f.id) {
        None => Step::Ended(Outputs::aborted()),
        Some(Err(code)) => Step::Ended(Outputs::failed(code)),
        Some(Ok((ChannelCommandState::Busy, _))) => Step::Running(Outputs {
            active: true,
            ..Outputs::busy()
        }),
        Some(Ok((ChannelCommandState::Refused, code))) => Step::Ended(Outputs::failed(code)),
        Some(Ok(_)) => Step::Ended(Outputs::done(())),
    }
}

/// One command block: which command, and its inputs (a program's name and start line for
/// SELECT, a value for SINGLE_BLOCK and MODE).
#[derive(Debug)]
pub struct ChannelCommandBlock {
    /// The command this block sends.
    pub command: ChannelCommand,
    /// Input: a rising edge sends the command.
    pub execute: bool,
    /// Input (SELECT): the program's file name in the channel's folder, NUL-padded.
    pub program: [u8; PROGRAM_NAME_LEN],
    /// Input (SELECT): the source line to start at (0: the first block).
    pub start_line: u32,
    /// Input (SINGLE_BLOCK: 1 on, 0 off; MODE: a `ChannelMode`).
    pub value: i32,
    /// Outputs of the last call.
    pub out: Outputs,
    kernel: Kernel<CommandSend, Following>,
}

impl ChannelCommandBlock {
    /// A block sending `command`.
    pub fn new(command: ChannelCommand) -> Self {
        Self {
            command,
            execute: false,
            program: [0; PROGRAM_NAME_LEN],
            start_line: 0,
            value: 0,
            out: Outputs::default(),
            kernel: Kernel::default(),
        }
    }

    /// Sets the program input from text (cut at 63 bytes: the CNC refuses a name that fills
    /// the room).
    pub fn set_program(&mut self, name: &str) {
        self.program = hli::layout::nul_padded(name);
    }

    /// One cycle on channel `channel`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, channel: usize) {
        let (kind, start_line, value, program) =
            (self.command, self.start_line, self.value, self.program);
        // The id is drawn when a rising edge sends the command, never in other cycles.
        let send = |_: &mut PlcIo<'_>| {
            Ok(CommandSend {
                channel,
                command: HliChannelCommand {
                    command_id: next_command_id(),
                    command: kind.raw(),
                    start_line: start_line.min(i32::MAX as u32) as i32,
                    value,
                    program,
                },
                written: false,
                taken_elsewhere: 0,
            })
        };
        self.out = self.kernel.cycle(
            io,
            self.execute,
            send,
            |reply| accept(reply, channel),
            follow,
        );
    }

    timeout_input!(kernel);
}

/// ReadChannelState: what the channel shows, every cycle while Enable is TRUE.
#[derive(Debug, Default)]
pub struct ReadChannelState {
    /// Input: read.
    pub enable: bool,
    /// Output: the values are valid.
    pub valid: bool,
    /// Output: the channel's state.
    pub state: Option<ChannelState>,
    /// Output: its mode.
    pub mode: Option<ChannelMode>,
    /// Output: `ChannelSignal` bits.
    pub signals: u32,
    /// Output: the source line executing.
    pub block_nr: i32,
    /// Output: the channel's error, 0 when none.
    pub error_id: u32,
    /// Output: programs that ran to their end.
    pub programs_ended: u32,
    /// Output: an error of the block (no channel, a state that is none).
    pub error: bool,
    /// Output: its ErrorID.
    pub error_id_block: u32,
}

impl ReadChannelState {
    /// One cycle on channel `channel`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, channel: usize) {
        (self.valid, self.error, self.error_id_block) = (false, false, 0);
        if !self.enable {
            return;
        }
        let Some(ch) = io.gp_ch(channel) else {
            (self.error, self.error_id_block) = (true, ChannelBlockError::NoChannel.code());
            return;
        };
        let s = stable_state(&ch);
        match (ChannelState::decode(s.state), ChannelMode::decode(s.mode)) {
            (Ok(state), Ok(mode)) => {
                (self.state, self.mode) = (Some(state), Some(mode));
                self.signals = s.signals;
                self.block_nr = s.block_nr;
                self.error_id = s.error_id;
                self.programs_ended = s.programs_ended;
                self.valid = true;
            }
            _ => (self.error, self.error_id_block) = (true, ChannelBlockError::InvalidState.code()),
        }
    }
}

impl TimelineBlock for ChannelCommandBlock {
    timeline_timeout!();
    /// `program`: 1 to 63 characters, printable ASCII (the CNC checks the name as a path).
    fn set_text(&mut self, key: &str, text: &[u8]) -> bool {
        let fits = (1..PROGRAM_NAME_LEN).contains(&text.len());
        if key != "program" || !fits || !text.iter().all(|b| b.is_ascii_graphic() || *b == b' ') {
            return false;
        }
        self.program = [0; PROGRAM_NAME_LEN];
        self.program[..text.len()].copy_from_slice(text);
        true
    }
    fn set(&mut self, key: &str, value: &Value) {
        match (key, value) {
            ("program", v) => {
                if let Some(name) = v.custom::<String>() {
                    self.set_program(&name);
                }
            }
            ("start_line", Value::Int(v)) => self.start_line = *v as u32,
            ("enable", Value::Bool(v)) => self.value = i32::from(*v),
            ("mode", Value::Int(v)) => self.value = *v as i32,
            _ => {}
        }
    }
    fn execute(&mut self) -> Option<&mut bool> {
        Some(&mut self.execute)
    }
    fn cycle(&mut self, io: &mut PlcIo<'_>, channel: u32) -> (Outputs, bool) {
        self.call(io, channel as usize);
        plain(self.out)
    }
}

impl TimelineBlock for ReadChannelState {
    fn set(&mut self, key: &str, value: &Value) {
        if let ("enable", Value::Bool(v)) = (key, value) {
            self.enable = *v;
        }
    }
    fn execute(&mut self) -> Option<&mut bool> {
        None
    }
    fn cycle(&mut self, io: &mut PlcIo<'_>, channel: u32) -> (Outputs, bool) {
        self.call(io, channel as usize);
        let out = Outputs {
            done: self.valid,
            error: self.error,
            error_id: self.error_id_block,
            ..Outputs::default()
        };
        (out, false)
    }
    /// The channel's state in Structured Text, while Valid (Done).
    fn results(&self) -> Option<&'static crate::timeline::registry::Results> {
        Some(&CHANNEL_STATE)
    }
    fn result_values(&self, out: &mut [f64]) -> usize {
        let Some(state) = self.state else {
            return 0;
        };
        let values = [
            f64::from(state.raw()),
            f64::from(self.block_nr),
            f64::from(self.programs_ended),
            f64::from(self.error_id),
            f64::from(self.signals),
        ];
        let n = values.len().min(out.len());
        out[..n].copy_from_slice(&values[..n]);
        n
    }
    fn read(&self) -> Option<Vec<f64>> {
        let state = self.state?;
        Some(vec![
            f64::from(state.raw()),
            f64::from(self.block_nr),
            f64::from(self.programs_ended),
            f64::from(self.error_id),
            f64::from(self.signals),
        ])
    }
}

/// ReadChannelState's outputs in Structured Text: the channel's state (a `ChannelState`),
/// the block it runs, the programs that ended, its error and its signals.
const CHANNEL_STATE: crate::timeline::registry::Results = crate::timeline::registry::Results {
    outputs: &[
        ("State", "DINT"),
        ("BlockNr", "DINT"),
        ("ProgramsEnded", "UDINT"),
        ("ChannelErrorID", "UDINT"),
        ("Signals", "DWORD"),
    ],
    declaration: "",
    type_name: "",
};

/// A program name input: a plain file name as a TOML string.
fn parse_program(value: &toml::Value) -> Result<Value, String> {
    let name = value
        .as_str()
        .ok_or("`program` must be a string (a file name)")?;
    if name.is_empty() || name.len() >= PROGRAM_NAME_LEN {
        return Err(format!(
            "`program` {name:?}: 1 to {} bytes",
            PROGRAM_NAME_LEN - 1
        ));
    }
    Ok(Value::Custom(Arc::new(name.to_string())))
}

const PROGRAM: InputSpec = input(
    "program",
    Kind::Parsed {
        parse: parse_program,
        example: "\"part.nc\"",
    },
)
.st_form(StForm::Text {
    name: "ProgramName",
    len: PROGRAM_NAME_LEN as u32 - 1,
});

const fn on_channel(
    name: &'static str,
    execute: bool,
    inputs: &'static [InputSpec],
    make: fn(Option<usize>) -> Box<dyn TimelineBlock>,
) -> BlockSpec {
    BlockSpec {
        name,
        target: Target::Channel,
        execute,
        inputs,
        make,
        style: crate::timeline::registry::StStyle::PlcOpen,
    }
}

macro_rules! command_block {
    ($command:ident) => {
        |_| Box::new(ChannelCommandBlock::new(ChannelCommand::$command))
    };
}

/// The channel blocks a timeline calls (`channel = gpCh index`).
pub const TIMELINE: &[BlockSpec] = &[
    on_channel(
        "ChannelSelectProgram",
        true,
        &[
            PROGRAM,
            input("start_line", Kind::Range(0, i32::MAX as i64)),
        ],
        command_block!(Select),
    ),
    on_channel("ChannelStart", true, &[], command_block!(Start)),
    on_channel("ChannelStop", true, &[], command_block!(Stop)),
    on_channel("ChannelFeedHold", true, &[], command_block!(FeedHold)),
    on_channel("ChannelResume", true, &[], command_block!(Resume)),
    on_channel("ChannelReset", true, &[], command_block!(Reset)),
    on_channel(
        "ChannelSingleBlock",
        true,
        &[input("enable", Kind::Bool)],
        command_block!(SingleBlock),
    ),
    on_channel(
        "ChannelMode",
        true,
        &[input(
            "mode",
            Kind::OneOf(&[("\"automatic\"", 0), ("\"manual\"", 1)]),
        )],
        command_block!(Mode),
    ),
    on_channel(
        "ReadChannelState",
        false,
        &[input("enable", Kind::Bool)],
        |_| Box::<ReadChannelState>::default(),
    ),
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runtime::Link;
    use hli::views::{CncView, PlcView};
    use hli_transport::rpc::{AcyclicClient, AcyclicServer};

    /// One cycle of `block` on `channel` of a one-channel image, the link in state `link`.
    fn cycle(
        memory: &hli::ImageMemory,
        client: &mut AcyclicClient,
        block: &mut ChannelCommandBlock,
        channel: usize,
        link: Link,
    ) -> Outputs {
        let mut io = PlcIo {
            view: PlcView::new(memory),
            memory,
            acyclic: client,
            cycle: 0,
            link,
        };
        block.call(&mut io, channel);
        block.out
    }

    /// The CNC's side: takes the command and answers it in the state block.
    fn answer(memory: &hli::ImageMemory, state: ChannelCommandState) -> u32 {
        let cnc = CncView::new(memory);
        let taken = cnc.channel_command(0).unwrap().try_take().unwrap();
        let plc = PlcView::new(memory);
        let mut s = plc.gp_ch(0).unwrap().channel_control_state();
        if let Some(c) = taken {
            s.command_id = c.command_id;
        }
        s.command_state = state.raw();
        cnc.write_channel_control_state(0, &s).unwrap();
        s.command_id
    }

    #[test]
    fn a_command_follows_the_channel_and_ends_done_aborted_or_with_an_error() {
        let instance = format!("channel-blocks-{}", std::process::id());
        let _server = AcyclicServer::open(&instance).unwrap();
        let mut client = AcyclicClient::open(&instance).unwrap();
        let memory = hli::image::heap_image(1, 0);
        let mut stop = ChannelCommandBlock::new(ChannelCommand::Stop);
        stop.execute = true;
        // Written, then Busy while the channel stops, then Done.
        assert!(cycle(&memory, &mut client, &mut stop, 0, Link::Operational).busy);
        answer(&memory, ChannelCommandState::Busy);
        let out = cycle(&memory, &mut client, &mut stop, 0, Link::Operational);
        assert!(out.busy && out.active);
        answer(&memory, ChannelCommandState::Done);
        assert!(cycle(&memory, &mut client, &mut stop, 0, Link::Operational).done);

        // Another command taken on the channel: CommandAborted.
        let mut hold = ChannelCommandBlock::new(ChannelCommand::FeedHold);
        hold.execute = true;
        cycle(&memory, &mut client, &mut hold, 0, Link::Operational);
        answer(&memory, ChannelCommandState::Busy);
        cycle(&memory, &mut client, &mut hold, 0, Link::Operational);
        let cnc = CncView::new(&memory);
        let mut s = PlcView::new(&memory)
            .gp_ch(0)
            .unwrap()
            .channel_control_state();
        s.command_id = s.command_id.wrapping_add(1);
        cnc.write_channel_control_state(0, &s).unwrap();
        assert!(cycle(&memory, &mut client, &mut hold, 0, Link::Operational).command_aborted);

        // Taken, but another command's answer shows before this one's was seen: aborted.
        let mut resume = ChannelCommandBlock::new(ChannelCommand::Resume);
        resume.execute = true;
        cycle(&memory, &mut client, &mut resume, 0, Link::Operational);
        let cnc = CncView::new(&memory);
        cnc.channel_command(0).unwrap().try_take().unwrap().unwrap();
        let mut s = PlcView::new(&memory)
            .gp_ch(0)
            .unwrap()
            .channel_control_state();
        s.command_id = s.command_id.wrapping_add(17);
        s.command_state = ChannelCommandState::Done.raw();
        cnc.write_channel_control_state(0, &s).unwrap();
        let mut aborted = false;
        for _ in 0..4 {
            aborted |=
                cycle(&memory, &mut client, &mut resume, 0, Link::Operational).command_aborted;
        }
        assert!(
            aborted,
            "a command replaced before its answer ends CommandAborted"
        );

        // No such channel; no CNC.
        let mut start = ChannelCommandBlock::new(ChannelCommand::Start);
        start.execute = true;
        let out = cycle(&memory, &mut client, &mut start, 3, Link::Operational);
        assert_eq!(
            (out.error, out.error_id),
            (true, ChannelBlockError::NoChannel.code())
        );
        let mut start = ChannelCommandBlock::new(ChannelCommand::Start);
        start.execute = true;
        let out = cycle(&memory, &mut client, &mut start, 0, Link::NotOperational);
        assert_eq!(
            (out.error, out.error_id),
            (true, crate::kernel::ERROR_NO_ANSWER)
        );
    }
}
