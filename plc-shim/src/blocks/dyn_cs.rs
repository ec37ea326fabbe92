//! The PLC's blocks for a dynamic coordinate system it masters (seed 003, the PLC as master
//! of `MC_CONTROL_DYN_CS_UNIT`) and for the M-function handshake that lets an NC program ask
//! the PLC for something:
//!
//! * [`DynCsMaster`]: takes over the unit (`enable_w`) and writes the master frame through
//!   `command_w` whenever its semaphore allows, reading back `request_r` and the state;
//! * [`McDynCsTransition`]: switches the tracking on or off through `transition_w` with its
//!   parameters, an Execute block with PLCopen outputs (Done once the CNC reports ACTIVE or
//!   INACTIVE);
//! * [`MFunctionHandshake`]: takes each M function the channel announces and acknowledges it
//!   when the program says so.
//!
//! None of them allocates or blocks; each is called once per cycle.

use crate::kernel::{Accept, InFlight, Kernel, Outputs, Polled, Step, Waited};
use crate::runtime::PlcIo;
use hli::enums::{DynCsCommand, DynCsOption, DynCsState};
use hli::handshake::SendError;
use hli::layout::{
    HliCoordinateSystemInt, HliDynCsTransition, HliMFunctionAck, HliMFunctionRequest,
};
use hli::Bool;

/// Why a dynamic-CS or M-function block reports an error (its ErrorID).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum DynCsBlockError {
    /// The channel is not configured on this CNC.
    NoChannel = 0x4801,
    /// `state_r` holds a value that is no tracking state.
    InvalidState = 0x4802,
    /// The tracking went to ERROR.
    Tracking = 0x4803,
    /// A semaphore or command word held garbage (the other side broke the protocol).
    Protocol = 0x4804,
}

impl DynCsBlockError {
    /// The ErrorID.
    pub fn code(self) -> u32 {
        self as u32
    }
}

/// The master of a channel's dynamic CS: owns the unit while `enable` is TRUE and, while
/// `send` is TRUE, writes `frame` whenever the CNC has taken the previous one.
#[derive(Debug)]
pub struct DynCsMaster {
    /// Input: take over the unit.
    pub enable: bool,
    /// Input: write `frame` when the semaphore allows.
    pub send: bool,
    /// Input: the master frame (0.1 um, 0.0001 degree).
    pub frame: HliCoordinateSystemInt,
    /// Output: the tracking state the CNC reports.
    pub state: Option<DynCsState>,
    /// Output: frames the CNC was given.
    pub frames_sent: u64,
    /// Output: cycles a frame waited because the previous one was not taken.
    pub frames_waiting: u64,
    /// Output: the last frame the CNC requested through `request_r` (the channel's own
    /// master position, for a PLC that follows the NC's frame).
    pub request: Option<HliCoordinateSystemInt>,
    /// Output: requests read.
    pub requests_read: u64,
    /// Output: an error is shown.
    pub error: bool,
    /// Output: its ErrorID ([`DynCsBlockError`]).
    pub error_id: u32,
}

impl Default for DynCsMaster {
    fn default() -> Self {
        Self {
            enable: false,
            send: false,
            frame: bytemuck::Zeroable::zeroed(),
            state: None,
            frames_sent: 0,
            frames_waiting: 0,
            request: None,
            requests_read: 0,
            error: false,
            error_id: 0,
        }
    }
}

impl DynCsMaster {
    /// One cycle on channel `channel`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, channel: usize) {
        let Some(ch) = io.gp_ch(channel) else {
            return self.fail(DynCsBlockError::NoChannel);
        };
        self.error = false;
        self.error_id = 0;
        ch.set_dyn_cs_enabled(self.enable);
        match ch.dyn_cs_state() {
            Ok(state) => self.state = Some(state),
            Err(_) => {
                self.state = None;
                return self.fail(DynCsBlockError::InvalidState);
            }
        }
        if self.enable && self.send {
            match ch.dyn_cs_command().try_send(&self.frame) {
                Ok(()) => self.frames_sent += 1,
                Err(SendError::Busy) => self.frames_waiting += 1,
                Err(SendError::Violation(_)) => return self.fail(DynCsBlockError::Protocol),
            }
        }
        match ch.dyn_cs_request().try_take() {
            Ok(Some(frame)) => {
                self.request = Some(frame);
                self.requests_read += 1;
            }
            Ok(None) => {}
            Err(_) => self.fail(DynCsBlockError::Protocol),
        }
    }

    fn fail(&mut self, why: DynCsBlockError) {
        self.error = true;
        self.error_id = why.code();
    }
}

/// A transition command on its way through the channel's `transition_w` unit: written as
/// soon as the command word is free, answered when `dyn_cs_result.taken_count_r` moves (with
/// the CNC's refusal code, or 0).
struct TransitionSend {
    channel: usize,
    command: DynCsCommand,
    latched: HliDynCsTransition,
    taken_before: u32,
    written: bool,
    counted: bool,
}

impl InFlight for TransitionSend {
    type Reply = u32;
    type Buffer = ();

    fn poll(&mut self, io: &mut PlcIo<'_>, _: &mut ()) -> Polled<u32> {
        let Some(ch) = io.gp_ch(self.channel) else {
            return Polled::Answer(Err(DynCsBlockError::NoChannel.code()));
        };
        if !self.written {
            self.taken_before = ch.dyn_cs_result().taken_count_r;
            return match ch.dyn_cs_transition().try_send(self.command, &self.latched) {
                Ok(()) => {
                    self.written = true;
                    Polled::Progress
                }
                Err(SendError::Busy) => Polled::Waiting,
                Err(SendError::Violation(_)) => {
                    Polled::Answer(Err(DynCsBlockError::Protocol.code()))
                }
            };
        }
        let result = ch.dyn_cs_result();
        if result.taken_count_r != self.taken_before {
            return Polled::Answer(Ok(result.error_id_r));
        }
        // Not taken yet; a state that is no tracking state ends the command at once.
        match ch.dyn_cs_state() {
            Ok(_) => Polled::Waiting,
            Err(_) => Polled::Answer(Err(DynCsBlockError::InvalidState.code())),
        }
    }
}

/// What the block keeps while it follows a taken command: its goal, and whether the state
/// left the start state.
struct TransitionFollow {
    on: bool,
    moved: bool,
}

/// One cycle of following a taken command in the channel's tracking state, with the states
/// passed since (a state that lasted less than a PLC cycle still counts).
fn follow_transition(f: &mut TransitionFollow, io: &PlcIo<'_>, channel: usize) -> Step<()> {
    let Some(ch) = io.gp_ch(channel) else {
        return Step::Ended(Outputs::failed(DynCsBlockError::NoChannel.code()));
    };
    let seen_bits = ch.dyn_cs_result().states_seen_r;
    let seen = |s: DynCsState| seen_bits & s.seen_bit() != 0;
    let (goal, opposite) = if f.on {
        (DynCsState::Active, DynCsState::Inactive)
    } else {
        (DynCsState::Inactive, DynCsState::Active)
    };
    let tracking = Outputs::failed(DynCsBlockError::Tracking.code());
    match ch.dyn_cs_state() {
        Err(_) => Step::Ended(Outputs::failed(DynCsBlockError::InvalidState.code())),
        _ if seen(DynCsState::Error) => Step::Ended(tracking),
        Ok(DynCsState::Error) => Step::Ended(tracking),
        _ if seen(goal) => Step::Ended(Outputs::done(())),
        // Back in the start state after it had left it: something switched the other way.
        Ok(state) if state == opposite && f.moved => Step::Ended(Outputs::aborted()),
        Ok(state) => {
            f.moved |= state != opposite;
            Step::Running(Outputs {
                active: true,
                ..Outputs::busy()
            })
        }
    }
}

/// MC_DynCsTransition (our name): switches the tracking ON or OFF through `transition_w`.
///
/// A rising edge of `execute` latches the inputs and writes the parameters and then the
/// command word as soon as the word is free (Busy meanwhile). The block is Active once the
/// CNC took the command and Done when the tracking state reaches ACTIVE (ON) or INACTIVE
/// (OFF). The opposite end state reached first shows CommandAborted; ERROR shows Error.
/// Outputs are held while `execute` stays TRUE, or shown for one cycle if it fell earlier.
/// A new rising edge while Busy starts the new command; the old one gives no more outputs
/// (PLCopen's rule for an instance re-triggered before it finished).
#[derive(Debug)]
pub struct McDynCsTransition {
    /// Input: a rising edge starts the command.
    pub execute: bool,
    /// Input: TRUE switches ON (+1), FALSE OFF (-1).
    pub on: bool,
    /// Input: filter length in ticks (FILTER=).
    pub filter_max_ticks: u32,
    /// Input: what is followed (OPTION=).
    pub option: DynCsOption,
    /// Input: WAIT.
    pub wait: bool,
    /// Input: SET_ZERO.
    pub set_zero: bool,
    /// Input: KIN_BASE.
    pub kin_base: bool,
    /// Input: ROT_TRANS.
    pub rot_trans: bool,
    /// Input: the static frame between the error point and the kinematic base (X.. C..).
    pub kinematic_base_cs: HliCoordinateSystemInt,
    /// Outputs of the last call.
    pub out: Outputs,
    /// Commands the CNC was given.
    pub sent: u64,
    kernel: Kernel<TransitionSend, TransitionFollow>,
}

impl Default for McDynCsTransition {
    fn default() -> Self {
        Self {
            execute: false,
            on: true,
            filter_max_ticks: 0,
            option: DynCsOption::TranslationAndRotation,
            wait: false,
            set_zero: false,
            kin_base: false,
            rot_trans: false,
            kinematic_base_cs: bytemuck::Zeroable::zeroed(),
            out: Outputs::default(),
            sent: 0,
            kernel: Kernel::default(),
        }
    }
}

impl McDynCsTransition {
    /// One cycle on channel `channel`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, channel: usize) {
        let on = self.on;
        let latched = HliDynCsTransition {
            command: 0,
            filter_max_ticks: self.filter_max_ticks,
            option: self.option.raw(),
            f_wait: Bool::from(self.wait),
            f_set_zero: Bool::from(self.set_zero),
            f_kin_base: Bool::from(self.kin_base),
            f_rot_trans: Bool::from(self.rot_trans),
            kinematic_base_cs: self.kinematic_base_cs,
        };
        let command = if on {
            DynCsCommand::Activate
        } else {
            DynCsCommand::Deactivate
        };
        let send = |_: &mut PlcIo<'_>| {
            Ok(TransitionSend {
                channel,
                command,
                latched,
                taken_before: 0,
                written: false,
                counted: false,
            })
        };
        let accept = |error_id: u32| match error_id {
            0 => Accept::Follow(TransitionFollow { on, moved: false }, Outputs::busy()),
            code => Accept::Failed(code, ()),
        };
        let follow = |f: &mut TransitionFollow, io: &mut PlcIo<'_>, _: Waited| {
            follow_transition(f, io, channel)
        };
        self.out = self.kernel.cycle(io, self.execute, send, accept, follow);
        if let Some(send) = self.kernel.in_flight_mut() {
            if send.written && !send.counted {
                send.counted = true;
                self.sent += 1;
            }
        }
    }
}

/// The M-function handshake of a channel: takes the announcement (`request_r`) as soon as it
/// comes, shows it as `pending` until the program acknowledges it with [`Self::acknowledge`];
/// the acknowledge is written as soon as its semaphore allows (the channel waits for it).
#[derive(Debug, Default)]
pub struct MFunctionHandshake {
    /// Output: the M function waiting for its acknowledge.
    pub pending: Option<HliMFunctionRequest>,
    /// Output: M functions taken.
    pub received: u64,
    /// Output: M functions acknowledged.
    pub acknowledged: u64,
    /// Output: an error is shown.
    pub error: bool,
    /// Output: its ErrorID ([`DynCsBlockError`]).
    pub error_id: u32,
    ack: Option<HliMFunctionAck>,
}

impl MFunctionHandshake {
    /// One cycle on channel `channel`: sends an acknowledge asked for earlier, then takes a
    /// new announcement if none is pending.
    pub fn call(&mut self, io: &mut PlcIo<'_>, channel: usize) {
        let Some(ch) = io.gp_ch(channel) else {
            self.error = true;
            self.error_id = DynCsBlockError::NoChannel.code();
            return;
        };
        self.error = false;
        self.error_id = 0;
        self.flush(&ch);
        if self.pending.is_none() && self.ack.is_none() {
            match ch.m_function_request().try_take() {
                Ok(Some(request)) => {
                    self.pending = Some(request);
                    self.received += 1;
                }
                Ok(None) => {}
                Err(_) => {
                    self.error = true;
                    self.error_id = DynCsBlockError::Protocol.code();
                }
            }
        }
    }

    /// The pending M function's code, if any.
    pub fn m_code(&self) -> Option<i32> {
        self.pending.map(|r| r.m_code)
    }

    /// Acknowledges the pending M function (this cycle if the semaphore allows, else as soon
    /// as it does). Without a pending one, nothing happens.
    pub fn acknowledge(&mut self, io: &mut PlcIo<'_>, channel: usize) {
        if let Some(request) = self.pending.take() {
            self.ack = Some(HliMFunctionAck {
                m_code: request.m_code,
                request_id: request.request_id,
            });
            if let Some(ch) = io.gp_ch(channel) {
                self.flush(&ch);
            }
        }
    }

    fn flush(&mut self, ch: &hli::views::PlcChannel<'_>) {
        if let Some(ack) = self.ack {
            match ch.m_function_ack().try_send(&ack) {
                Ok(()) => {
                    self.ack = None;
                    self.acknowledged += 1;
                }
                Err(SendError::Busy) => {}
                Err(SendError::Violation(_)) => {
                    self.error = true;
                    self.error_id = DynCsBlockError::Protocol.code();
                }
            }
        }
    }
}
