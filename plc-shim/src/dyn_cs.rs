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

use crate::motion::BlockOutputs;
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

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TransitionPhase {
    Idle,
    /// Waiting for the command word to be free.
    Sending,
    /// Sent; waiting for the CNC to take it and reach the goal.
    Following,
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
    pub out: BlockOutputs,
    /// Commands the CNC was given.
    pub sent: u64,
    latched: HliDynCsTransition,
    latched_on: bool,
    phase: TransitionPhase,
    /// The state left the start state after the CNC took the command.
    moved: bool,
    /// `dyn_cs_result.taken_count_r` before the command was sent: a new count is the CNC's
    /// answer to it.
    taken_before: u32,
    execute_before: bool,
    show_once: bool,
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
            out: BlockOutputs::default(),
            sent: 0,
            latched: bytemuck::Zeroable::zeroed(),
            latched_on: true,
            phase: TransitionPhase::Idle,
            moved: false,
            taken_before: 0,
            execute_before: false,
            show_once: false,
        }
    }
}

impl McDynCsTransition {
    /// One cycle on channel `channel`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, channel: usize) {
        let rising = self.execute && !self.execute_before;
        self.execute_before = self.execute;
        if rising {
            self.latched = HliDynCsTransition {
                command: 0,
                filter_max_ticks: self.filter_max_ticks,
                option: self.option.raw(),
                f_wait: Bool::from(self.wait),
                f_set_zero: Bool::from(self.set_zero),
                f_kin_base: Bool::from(self.kin_base),
                f_rot_trans: Bool::from(self.rot_trans),
                kinematic_base_cs: self.kinematic_base_cs,
            };
            self.latched_on = self.on;
            self.out = BlockOutputs::default();
            self.phase = TransitionPhase::Sending;
            self.moved = false;
            self.show_once = false;
        }
        // Execute low while the command runs: its result, when it comes (possibly in this
        // very cycle), is shown for one cycle.
        if !self.execute && self.phase != TransitionPhase::Idle {
            self.show_once = true;
        }
        if self.phase != TransitionPhase::Idle {
            self.step(io, channel);
        }
        if !self.execute && self.phase == TransitionPhase::Idle {
            if self.show_once {
                self.show_once = false;
            } else {
                self.out = BlockOutputs::default();
            }
        }
    }

    fn step(&mut self, io: &mut PlcIo<'_>, channel: usize) {
        let Some(ch) = io.gp_ch(channel) else {
            return self.finish_with_error(DynCsBlockError::NoChannel);
        };
        if self.phase == TransitionPhase::Sending {
            let command = if self.latched_on {
                DynCsCommand::Activate
            } else {
                DynCsCommand::Deactivate
            };
            self.taken_before = ch.dyn_cs_result().taken_count_r;
            match ch.dyn_cs_transition().try_send(command, &self.latched) {
                Ok(()) => {
                    self.sent += 1;
                    self.phase = TransitionPhase::Following;
                }
                Err(SendError::Busy) => {}
                Err(SendError::Violation(_)) => {
                    return self.finish_with_error(DynCsBlockError::Protocol)
                }
            }
            self.out.busy = true;
            return;
        }
        // The CNC's answer: refused (with its reason) or carried out, and the states passed
        // since, so a state that lasted less than a PLC cycle still counts.
        let result = ch.dyn_cs_result();
        let taken = result.taken_count_r != self.taken_before;
        if taken && result.error_id_r != 0 {
            return self.finish_with_code(result.error_id_r);
        }
        let (goal, opposite) = if self.latched_on {
            (DynCsState::Active, DynCsState::Inactive)
        } else {
            (DynCsState::Inactive, DynCsState::Active)
        };
        let seen = |s: DynCsState| taken && result.states_seen_r & s.seen_bit() != 0;
        self.out = BlockOutputs {
            busy: true,
            active: taken,
            ..BlockOutputs::default()
        };
        match ch.dyn_cs_state() {
            Err(_) => self.finish_with_error(DynCsBlockError::InvalidState),
            _ if seen(DynCsState::Error) => self.finish_with_error(DynCsBlockError::Tracking),
            Ok(DynCsState::Error) if taken => self.finish_with_error(DynCsBlockError::Tracking),
            _ if seen(goal) => {
                self.out = BlockOutputs {
                    done: true,
                    ..BlockOutputs::default()
                };
                self.phase = TransitionPhase::Idle;
            }
            // Back in the start state after it had left it: something switched the other way.
            Ok(state) if taken && state == opposite && self.moved => {
                self.out = BlockOutputs {
                    command_aborted: true,
                    ..BlockOutputs::default()
                };
                self.phase = TransitionPhase::Idle;
            }
            Ok(state) => self.moved |= taken && state != opposite,
        }
    }

    fn finish_with_error(&mut self, why: DynCsBlockError) {
        self.finish_with_code(why.code());
    }

    /// Error with `error_id`: one of [`DynCsBlockError`] or the CNC's refusal
    /// (`hli::enums::DynCsTransitionError`).
    fn finish_with_code(&mut self, error_id: u32) {
        self.out = BlockOutputs {
            error: true,
            error_id,
            ..BlockOutputs::default()
        };
        self.phase = TransitionPhase::Idle;
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
