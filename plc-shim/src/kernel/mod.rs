//! The one state machine of every Execute-driven block (motion, probe, dynamic CS, cam,
//! compatibility, FIFO, flying saw): the Execute edge, the call on its way, the timeout, the
//! following of an accepted command, and the PLCopen output rules. A block adds only its call
//! and, where it has them, its extra outputs and how it follows an accepted command.
//!
//! ```text
//!   Idle --rising Execute--> Sent --answer: accepted--> Following --ended--> Idle
//!                             |  \--answer: done/refused, or no answer in time--> Idle
//!   (a rising Execute in Sent or Following starts over: the old command is not reported)
//! ```
//!
//! The rules, the same for every family (docs/plc.md, "The block kernel"):
//! * a rising Execute sends the call and clears the outputs, also while the block is Busy:
//!   the new command supersedes the old one, whose result is no longer reported (PLCopen:
//!   no feedback for the previous action);
//! * Busy from the rising edge until the command ends; Done, CommandAborted and Error are
//!   exclusive and end it;
//! * an answer that takes more than `timeout_cycles` PLC cycles (tTimeout; default
//!   [`DEFAULT_TIMEOUT_CYCLES`], about the seeds' one second) ends the command with
//!   [`ERROR_NO_ANSWER`]; so does a call that cannot be sent, and, at once, every command
//!   running or starting while the link to the CNC is not operational
//!   ([`crate::runtime::Link`]);
//! * the outputs of an ended command hold while Execute stays TRUE and clear in the cycle
//!   Execute is seen FALSE; a command that ends while Execute is already FALSE (a short
//!   pulse) shows its result for exactly one cycle.

use crate::runtime::{Link, PlcIo};
use hli::calls::{AcyclicCall, CallError};
use hli_transport::rpc::{PendingCall, PendingRows};

/// Error id of a block whose call was not answered (lost, not sent, or not in time).
pub const ERROR_NO_ANSWER: u32 = 0x745;

/// PLC cycles a block waits for the CNC's answer by default (1 s at a 1 ms cycle).
pub const DEFAULT_TIMEOUT_CYCLES: u64 = 1000;

/// The outputs of every block: PLCopen's, the continuous blocks' InVelocity/InSync/StartSync,
/// and a family's extra (a FIFO reply, a recorded probe position; `()` for most).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Outputs<X = ()> {
    /// The command reached its goal (a one-shot call: the CNC took it).
    pub done: bool,
    /// The command has not ended yet.
    pub busy: bool,
    /// The command owns the axis (accepted and not ended).
    pub active: bool,
    /// A newer command, a fault or a stop ended this one.
    pub command_aborted: bool,
    /// The command failed; see `error_id`.
    pub error: bool,
    /// Why: the CNC's code (a block's, an axis's, an acyclic refusal) or [`ERROR_NO_ANSWER`].
    pub error_id: u32,
    /// MC_MoveVelocity: the commanded velocity is reached.
    pub in_velocity: bool,
    /// Couplings (cam, gear): the slave follows its master.
    pub in_sync: bool,
    /// Flying saw couplings: the CNC accepted the coupling (kept until the outputs clear).
    pub start_sync: bool,
    /// The family's extra outputs.
    pub extra: X,
}

impl<X: Default> Outputs<X> {
    /// Sent or running, nothing else.
    pub fn busy() -> Self {
        Outputs {
            busy: true,
            ..Outputs::default()
        }
    }

    /// Done, with `extra`.
    pub fn done(extra: X) -> Self {
        Outputs {
            done: true,
            extra,
            ..Outputs::default()
        }
    }

    /// Error `code`.
    pub fn failed(code: u32) -> Self {
        Outputs::failed_with(code, X::default())
    }

    /// Error `code`, with `extra`.
    pub fn failed_with(code: u32, extra: X) -> Self {
        Outputs {
            error: true,
            error_id: code,
            extra,
            ..Outputs::default()
        }
    }

    /// The same outputs without the family's extra.
    pub fn without_extra(self) -> Outputs {
        Outputs {
            done: self.done,
            busy: self.busy,
            active: self.active,
            command_aborted: self.command_aborted,
            error: self.error,
            error_id: self.error_id,
            in_velocity: self.in_velocity,
            in_sync: self.in_sync,
            start_sync: self.start_sync,
            extra: (),
        }
    }

    /// CommandAborted.
    pub fn aborted() -> Self {
        Outputs {
            command_aborted: true,
            ..Outputs::default()
        }
    }
}

/// The code a block reports for a call that failed in transport or was refused.
pub fn call_error_code(error: &CallError) -> u32 {
    match error {
        CallError::Refused { code } => code.raw(),
        _ => ERROR_NO_ANSWER,
    }
}

/// Sends `call` to `target` on the acyclic service: the call on its way, or the code of a call
/// that could not be sent ([`call_error_code`]). What most blocks' `send` does.
pub fn send<C: AcyclicCall>(
    io: &mut PlcIo<'_>,
    target: u32,
    call: &C,
) -> Result<PendingCall<C>, u32> {
    io.acyclic
        .start(target, call)
        .map_err(|e| call_error_code(&e))
}

/// What a call on its way gave this cycle.
pub enum Polled<R> {
    /// Still on its way.
    Waiting,
    /// A multi-call transfer made progress (a chunk was taken): the timeout starts over.
    Progress,
    /// The answer, or the code of the failure.
    Answer(Result<R, u32>),
}

/// Something on its way to the CNC: one call, or a transfer of several.
pub trait InFlight {
    /// What the CNC answers.
    type Reply;
    /// Where a transfer of several parts puts what it reads (a block's output array, owned
    /// by the block); `()` for the rest.
    type Buffer: ?Sized;
    /// One cycle's look at it (a transfer sends its next part here).
    fn poll(&mut self, io: &mut PlcIo<'_>, buffer: &mut Self::Buffer) -> Polled<Self::Reply>;
}

fn polled<R>(result: Option<Result<R, CallError>>) -> Polled<R> {
    match result {
        None => Polled::Waiting,
        Some(result) => Polled::Answer(result.map_err(|e| call_error_code(&e))),
    }
}

impl<C: AcyclicCall> InFlight for PendingCall<C> {
    type Reply = C::Reply;
    type Buffer = ();
    fn poll(&mut self, _: &mut PlcIo<'_>, _: &mut ()) -> Polled<C::Reply> {
        polled(PendingCall::poll(self))
    }
}

/// A bulk call on its way (its values written straight into shared memory), answered with
/// the reply body `R` of its kind.
pub struct PendingBulk<R> {
    pending: PendingRows,
    reply: core::marker::PhantomData<fn() -> R>,
}

impl<R> PendingBulk<R> {
    /// `pending`, whose answer is an `R`.
    pub fn new(pending: PendingRows) -> Self {
        PendingBulk {
            pending,
            reply: core::marker::PhantomData,
        }
    }
}

impl<R> core::fmt::Debug for PendingBulk<R> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("PendingBulk")
    }
}

impl<R: bytemuck::Pod> InFlight for PendingBulk<R> {
    type Reply = R;
    type Buffer = ();
    fn poll(&mut self, _: &mut PlcIo<'_>, _: &mut ()) -> Polled<R> {
        polled(self.pending.poll::<R>())
    }
}

/// What a block makes of the CNC's answer.
pub enum Accept<F, X> {
    /// The command is over: Done with these extras.
    Done(X),
    /// The command runs on (a motion, a coupling): follow it with this state, showing these
    /// outputs meanwhile.
    Follow(F, Outputs<X>),
    /// Refused with this code.
    Failed(u32, X),
}

/// What following an accepted command gave this cycle.
pub enum Step<X> {
    /// It runs on, with these outputs.
    Running(Outputs<X>),
    /// It ended, with these outputs (they now hold).
    Ended(Outputs<X>),
}

/// How long the command has been followed, and the block's timeout.
#[derive(Debug, Clone, Copy)]
pub struct Waited {
    /// PLC cycles since the CNC accepted it (0 in the cycle of the answer).
    pub cycles: u64,
    /// The block's timeout in cycles.
    pub timeout: u64,
}

enum Phase<P, F> {
    Idle,
    Sent { call: P, since: u64 },
    Following { state: F, since: u64 },
}

/// The block kernel: one per block instance. `P` is what goes to the CNC, `F` what a block
/// keeps while it follows an accepted command, `X` its extra outputs.
pub struct Kernel<P, F = (), X = ()> {
    timeout_cycles: u64,
    active_while_sent: bool,
    execute_before: bool,
    fell: bool,
    show_once: bool,
    phase: Phase<P, F>,
    out: Outputs<X>,
}

impl<P, F, X: Default> Default for Kernel<P, F, X> {
    fn default() -> Self {
        Kernel {
            timeout_cycles: DEFAULT_TIMEOUT_CYCLES,
            active_while_sent: false,
            execute_before: false,
            fell: false,
            show_once: false,
            phase: Phase::Idle,
            out: Outputs::default(),
        }
    }
}

impl<P, F, X: core::fmt::Debug> core::fmt::Debug for Kernel<P, F, X> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Kernel")
            .field("out", &self.out)
            .field("running", &!matches!(self.phase, Phase::Idle))
            .finish()
    }
}

impl<P: InFlight, F, X: Copy + Default> Kernel<P, F, X> {
    /// A kernel whose block is Active while its call is on its way (the flying saw's
    /// couplings, where Active = Busy).
    pub fn active_while_sent() -> Self {
        Kernel {
            active_while_sent: true,
            ..Kernel::default()
        }
    }

    /// Input tTimeout: cycles to wait for the CNC's answer.
    pub fn set_timeout_cycles(&mut self, cycles: u64) {
        self.timeout_cycles = cycles;
    }

    /// Whether Execute fell in the last cycle.
    pub fn fell(&self) -> bool {
        self.fell
    }

    /// The call on its way, if one is.
    pub fn in_flight_mut(&mut self) -> Option<&mut P> {
        match &mut self.phase {
            Phase::Sent { call, .. } => Some(call),
            _ => None,
        }
    }

    /// Whether a command is on its way or followed.
    pub fn running(&self) -> bool {
        !matches!(self.phase, Phase::Idle)
    }

    /// [`Kernel::cycle`] for a transfer that reads into `buffer`.
    pub fn cycle_with(
        &mut self,
        io: &mut PlcIo<'_>,
        buffer: &mut P::Buffer,
        execute: bool,
        send: impl FnOnce(&mut PlcIo<'_>, &mut P::Buffer) -> Result<P, u32>,
        accept: impl FnOnce(P::Reply) -> Accept<F, X>,
        follow: impl FnOnce(&mut F, &mut PlcIo<'_>, Waited) -> Step<X>,
    ) -> Outputs<X> {
        if io.link == Link::NotOperational {
            return self.not_operational(execute);
        }
        let rising = execute && !self.execute_before;
        self.fell = !execute && self.execute_before;
        self.execute_before = execute;
        if rising {
            self.start(io, |io| send(io, buffer));
        }
        // Execute is low while the command runs: whatever it ends with, this cycle or later,
        // is shown for one cycle.
        if !execute && self.running() {
            self.show_once = true;
        }
        self.poll(io, buffer, accept);
        self.follow(io, follow);
        self.finish(execute)
    }

    /// The CNC is gone: a command on its way or followed ends with [`ERROR_NO_ANSWER`], and
    /// so does a rising Execute, at once (no call is sent, no timeout waited for).
    fn not_operational(&mut self, execute: bool) -> Outputs<X> {
        let rising = execute && !self.execute_before;
        self.fell = !execute && self.execute_before;
        self.execute_before = execute;
        if self.running() || rising {
            self.phase = Phase::Idle;
            self.show_once = !execute;
            self.out = Outputs::failed(ERROR_NO_ANSWER);
        }
        self.finish(execute)
    }

    fn start(&mut self, io: &mut PlcIo<'_>, send: impl FnOnce(&mut PlcIo<'_>) -> Result<P, u32>) {
        self.out = Outputs::default();
        self.show_once = false;
        self.phase = match send(io) {
            Ok(call) => Phase::Sent {
                call,
                since: io.cycle,
            },
            Err(code) => {
                self.out = Outputs::failed(code);
                Phase::Idle
            }
        };
    }

    fn poll(
        &mut self,
        io: &mut PlcIo<'_>,
        buffer: &mut P::Buffer,
        accept: impl FnOnce(P::Reply) -> Accept<F, X>,
    ) {
        let Phase::Sent { call, since } = &mut self.phase else {
            return;
        };
        let answer = match call.poll(io, buffer) {
            Polled::Waiting if io.cycle.saturating_sub(*since) > self.timeout_cycles => {
                Err(ERROR_NO_ANSWER)
            }
            Polled::Waiting => {
                self.out = self.sent_outputs();
                return;
            }
            Polled::Progress => {
                *since = io.cycle;
                self.out = self.sent_outputs();
                return;
            }
            Polled::Answer(answer) => answer,
        };
        let accepted = match answer {
            Ok(reply) => accept(reply),
            Err(code) => Accept::Failed(code, X::default()),
        };
        self.phase = match accepted {
            Accept::Done(extra) => {
                self.out = Outputs::done(extra);
                Phase::Idle
            }
            Accept::Failed(code, extra) => {
                self.out = Outputs::failed_with(code, extra);
                Phase::Idle
            }
            Accept::Follow(state, out) => {
                self.out = out;
                Phase::Following {
                    state,
                    since: io.cycle,
                }
            }
        };
    }

    fn sent_outputs(&self) -> Outputs<X> {
        Outputs {
            active: self.active_while_sent,
            ..Outputs::busy()
        }
    }

    fn follow(
        &mut self,
        io: &mut PlcIo<'_>,
        follow: impl FnOnce(&mut F, &mut PlcIo<'_>, Waited) -> Step<X>,
    ) {
        let Phase::Following { state, since } = &mut self.phase else {
            return;
        };
        let waited = Waited {
            cycles: io.cycle.saturating_sub(*since),
            timeout: self.timeout_cycles,
        };
        match follow(state, io, waited) {
            Step::Running(out) => self.out = out,
            Step::Ended(out) => {
                self.out = out;
                self.phase = Phase::Idle;
            }
        }
    }

    fn finish(&mut self, execute: bool) -> Outputs<X> {
        let running = self.running();
        if !execute && !running {
            // Execute is low and nothing runs: a result that arrived meanwhile shows once.
            if self.show_once {
                self.show_once = false;
                return self.out;
            }
            self.out = Outputs::default();
        }
        if !execute && running {
            self.show_once = true;
        }
        self.out
    }
}

impl<P: InFlight<Buffer = ()>, F, X: Copy + Default> Kernel<P, F, X> {
    /// One PLC cycle. On a rising `execute`, `send` puts the call on its way (or gives the
    /// code it failed with); `accept` judges the answer; `follow` watches an accepted
    /// command in the image. Returns the block's outputs for this cycle.
    pub fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        execute: bool,
        send: impl FnOnce(&mut PlcIo<'_>) -> Result<P, u32>,
        accept: impl FnOnce(P::Reply) -> Accept<F, X>,
        follow: impl FnOnce(&mut F, &mut PlcIo<'_>, Waited) -> Step<X>,
    ) -> Outputs<X> {
        self.cycle_with(io, &mut (), execute, |io, _| send(io), accept, follow)
    }
}

/// `accept` for a one-shot call whose reply carries an error id: Done, or Error with it.
pub fn done_unless<F>(error_id: u32) -> Accept<F, ()> {
    if error_id == 0 {
        Accept::Done(())
    } else {
        Accept::Failed(error_id, ())
    }
}

/// `follow` for a block that never follows (its `accept` never says Follow).
pub fn no_follow<F, X: Default>(_: &mut F, _: &mut PlcIo<'_>, _: Waited) -> Step<X> {
    Step::Ended(Outputs::default())
}

#[cfg(test)]
mod tests;
