//! The touch-probe blocks: MC_TouchProbe arms a probe of an axis on its Execute edge and
//! reports the recorded position; MC_AbortTrigger disarms it. The arming is followed in the
//! axis image (`gpAx[i]^drive_state.probe_r[k]`) under the arm id the CNC's reply carries, so
//! a later arming (by another block) shows as CommandAborted here.

use crate::motion::ERROR_NO_ANSWER;
use crate::runtime::PlcIo;
use hli::calls::probe::{ProbeAbortCall, ProbeArmCall, ProbeReply};
use hli::calls::CallError;
use hli::enums::{ProbeEdge, ProbeState};
use hli::layout::{HliAxis, HliAxisDriveState, HliAxisProbe};
use hli::rpc::PendingCall;
use hli::PlaceExt;

/// Outputs of the probe blocks.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ProbeOutputs {
    /// MC_TouchProbe: a position was recorded; MC_AbortTrigger: the probe is disarmed.
    pub done: bool,
    /// Waiting for the CNC's answer or (MC_TouchProbe) for the edge.
    pub busy: bool,
    /// The arming was ended by MC_AbortTrigger or replaced by a newer one.
    pub command_aborted: bool,
    /// Refused or lost; see `error_id`.
    pub error: bool,
    /// An axis error code, an acyclic error code, or [`ERROR_NO_ANSWER`].
    pub error_id: u32,
    /// MC_TouchProbe: the recorded position, axis units.
    pub recorded_position: f64,
}

fn failed(code: u32) -> ProbeOutputs {
    ProbeOutputs {
        error: true,
        error_id: code,
        ..ProbeOutputs::default()
    }
}

fn reply_outcome(result: Result<ProbeReply, CallError>) -> Result<u32, ProbeOutputs> {
    match result {
        Ok(reply) if reply.error_id != 0 => Err(failed(reply.error_id)),
        Ok(reply) => Ok(reply.arm_id),
        Err(CallError::Refused { code }) => Err(failed(code.raw())),
        Err(_) => Err(failed(ERROR_NO_ANSWER)),
    }
}

/// The probe's block in the image, if the axis exists.
fn probe_image(io: &PlcIo<'_>, axis: u32, probe: u32) -> Option<HliAxisProbe> {
    let state: HliAxisDriveState = io
        .view
        .axis(axis as usize)
        .ok()?
        .field::<HliAxisDriveState>(core::mem::offset_of!(HliAxis, drive_state))
        .read();
    state.probe_r.get(probe.checked_sub(1)? as usize).copied()
}

enum Phase<C: hli::calls::AcyclicCall> {
    Idle,
    Sent(PendingCall<C>),
    /// The CNC took the call: the arming's id.
    Accepted(u32),
}

/// The Execute edge and the call in flight, shared by both blocks.
struct Core<C: hli::calls::AcyclicCall> {
    execute_before: bool,
    phase: Phase<C>,
}

impl<C: hli::calls::AcyclicCall> Default for Core<C> {
    fn default() -> Self {
        Self {
            execute_before: false,
            phase: Phase::Idle,
        }
    }
}

/// What one cycle's Execute did.
struct Edges {
    fell: bool,
    was_running: bool,
}

impl<C: hli::calls::AcyclicCall<Reply = ProbeReply>> Core<C> {
    /// Takes this cycle's Execute; on its rising edge sends `call` (outputs reset, or the
    /// transport's error).
    fn begin(
        &mut self,
        io: &mut PlcIo<'_>,
        axis: u32,
        execute: bool,
        call: impl FnOnce() -> C,
        out: &mut ProbeOutputs,
    ) -> Edges {
        let edges = Edges {
            fell: !execute && self.execute_before,
            was_running: !matches!(self.phase, Phase::Idle),
        };
        let rising = execute && !self.execute_before;
        self.execute_before = execute;
        if rising {
            *out = ProbeOutputs::default();
            self.phase = match io.acyclic.start(axis, &call()) {
                Ok(pending) => Phase::Sent(pending),
                Err(_) => {
                    *out = failed(ERROR_NO_ANSWER);
                    Phase::Idle
                }
            };
        }
        edges
    }

    /// Polls a call in flight: `Some(Ok(id))` once accepted, `Some(Err(outputs))` when
    /// refused or lost (the call is over), `None` while waiting (Busy) or with nothing sent.
    fn poll(&mut self, out: &mut ProbeOutputs) -> Option<Result<u32, ProbeOutputs>> {
        let Phase::Sent(pending) = &self.phase else {
            return None;
        };
        let Some(result) = pending.poll() else {
            out.busy = true;
            return None;
        };
        let outcome = reply_outcome(result);
        self.phase = match outcome {
            Ok(id) => Phase::Accepted(id),
            Err(_) => Phase::Idle,
        };
        Some(outcome)
    }

    /// Execute low and nothing running: a result shows for the cycle Execute fell in (or the
    /// cycle it arrived in, if the call was still running), then clears.
    fn settle(&self, execute: bool, edges: Edges, out: &mut ProbeOutputs) {
        let idle = matches!(self.phase, Phase::Idle);
        let finished_now = edges.was_running && idle;
        if !execute && !edges.fell && !finished_now && idle {
            *out = ProbeOutputs::default();
        }
    }
}

/// MC_TouchProbe: on a rising Execute edge arms `probe` (1 or 2) of the axis for `edge`;
/// with `window_only` only an edge between `first_position` and `last_position` records.
/// Outputs hold while Execute stays TRUE and show for one cycle after it fell.
pub struct McTouchProbe {
    /// Input: a rising edge arms the probe.
    pub execute: bool,
    /// Input: probe number, 1 or 2.
    pub probe: u32,
    /// Input: the edge that records.
    pub edge: ProbeEdge,
    /// Input: only edges inside the window record.
    pub window_only: bool,
    /// Input: start of the window.
    pub first_position: f64,
    /// Input: end of the window.
    pub last_position: f64,
    /// Outputs of the last call.
    pub out: ProbeOutputs,
    core: Core<ProbeArmCall>,
}

impl Default for McTouchProbe {
    fn default() -> Self {
        Self {
            execute: false,
            probe: 1,
            edge: ProbeEdge::Positive,
            window_only: false,
            first_position: 0.0,
            last_position: 0.0,
            out: ProbeOutputs::default(),
            core: Core::default(),
        }
    }
}

impl McTouchProbe {
    /// One cycle for `axis`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, axis: u32) {
        let call = ProbeArmCall {
            probe: self.probe,
            edge: self.edge.raw(),
            window_only: u32::from(self.window_only),
            reserved: 0,
            first_position: self.first_position,
            last_position: self.last_position,
        };
        let edges = self
            .core
            .begin(io, axis, self.execute, || call, &mut self.out);
        if let Some(Err(out)) = self.core.poll(&mut self.out) {
            self.out = out;
        }
        if let Phase::Accepted(id) = self.core.phase {
            self.out = match probe_image(io, axis, self.probe) {
                Some(p) if p.arm_id_r != id => ProbeOutputs {
                    command_aborted: true,
                    ..ProbeOutputs::default()
                },
                Some(p) => match ProbeState::decode(p.state_r) {
                    Ok(ProbeState::Armed) => ProbeOutputs {
                        busy: true,
                        ..ProbeOutputs::default()
                    },
                    Ok(ProbeState::Recorded) => ProbeOutputs {
                        done: true,
                        recorded_position: p.recorded_position_r,
                        ..ProbeOutputs::default()
                    },
                    Ok(ProbeState::Aborted) if p.error_id_r != 0 => failed(p.error_id_r),
                    Ok(ProbeState::Aborted) | Ok(ProbeState::Idle) => ProbeOutputs {
                        command_aborted: true,
                        ..ProbeOutputs::default()
                    },
                    Err(_) => failed(hli::calls::ErrorCode::InvalidData.raw()),
                },
                None => failed(hli::calls::ErrorCode::InvalidTarget.raw()),
            };
            if !self.out.busy {
                self.core.phase = Phase::Idle;
            }
        }
        self.core.settle(self.execute, edges, &mut self.out);
    }
}

/// MC_AbortTrigger: on a rising Execute edge disarms `probe` of the axis.
pub struct McAbortTrigger {
    /// Input: a rising edge disarms.
    pub execute: bool,
    /// Input: probe number, 1 or 2.
    pub probe: u32,
    /// Outputs of the last call.
    pub out: ProbeOutputs,
    core: Core<ProbeAbortCall>,
}

impl Default for McAbortTrigger {
    fn default() -> Self {
        Self {
            execute: false,
            probe: 1,
            out: ProbeOutputs::default(),
            core: Core::default(),
        }
    }
}

impl McAbortTrigger {
    /// One cycle for `axis`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, axis: u32) {
        let call = ProbeAbortCall {
            probe: self.probe,
            reserved: 0,
        };
        let edges = self
            .core
            .begin(io, axis, self.execute, || call, &mut self.out);
        match self.core.poll(&mut self.out) {
            Some(Ok(_)) => {
                self.out = ProbeOutputs {
                    done: true,
                    ..ProbeOutputs::default()
                };
                self.core.phase = Phase::Idle;
            }
            Some(Err(out)) => self.out = out,
            None => {}
        }
        self.core.settle(self.execute, edges, &mut self.out);
    }
}
