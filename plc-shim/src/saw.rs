//! The flying-saw blocks of seed 001 chapter 12 for the PLC program: MC_GearInVelo,
//! MC_GearInPos, MC_GearOut and MC_ReadFlyingSawCharacteristics. Each sends its call to the
//! slave's axis index on the rising Execute edge without waiting; an edge while Busy is
//! ignored (the call on its way keeps its answer), and no answer within `timeout_cycles` PLC
//! cycles is an Error with [`ERROR_NO_ANSWER`] (the call may still have been executed).
//!
//! MC_GearInVelo / MC_GearInPos: once the CNC accepts the coupling, StartSync is TRUE and the
//! block follows the slave's axis image. InSync when the slave is coupled the block's way
//! (`coupling_state_r` 2 for velocity, 3 for position, to the block's master) and synchronous
//! (`nAxisState` 13); Busy = Active until InSync, CommandAborted or Error (the seed: Active is
//! Busy for now). CommandAborted when that coupling goes away (MC_GearOut, MC_Stop, or a new
//! coupling of the other kind or to another master); Error with the axis's `error_id_r` when
//! the slave faults. After InSync the block keeps following while Execute stays TRUE: InSync
//! shows whether the slave is synchronous now (a rollback stop lowers it until the slave is
//! synchronous again; Busy stays FALSE, the command ended at the first InSync), and a coupling
//! that goes away later is CommandAborted. Limits of what the image can tell: a new coupling
//! of the same kind to the same master made by another instance looks like this block's own.
//!
//! The outputs clear one cycle after Execute is low and the block is not Busy; a block that is
//! InSync then stops following.

use crate::cam::rose;
use crate::fifo::DEFAULT_TIMEOUT_CYCLES;
use crate::motion::ERROR_NO_ANSWER;
use crate::runtime::PlcIo;
use hli::calls::saw::{
    SawCharacCall, SawGearInCall, SawGearOutCall, SawSyncMode, SawSyncTarget, SAW_CHARAC_PART,
};
use hli::calls::{AcyclicCall, CallError};
use hli::enums::{AxisState, CouplingState};
use hli::layout::HliAxisLrState;
use hli::rpc::PendingCall;

/// Version of this block library (like the FIFO library's version function).
pub fn saw_library_version() -> &'static str {
    concat!("cncplc-saw ", env!("CARGO_PKG_VERSION"))
}

/// Fields 1-31 of `MC_FlyingSawCharacValues`, in the structure's order (the CNC sends them
/// in this order, 16 per part).
pub const CHARAC_FIELDS: [&str; 31] = [
    "fMasterVeloNom",
    "fMasterPosStart",
    "fSlavePosStart",
    "fSlaveVeloStart",
    "fSlaveAccStart",
    "fSlaveJerkStart",
    "fMasterPosEnd",
    "fSlavePosEnd",
    "fSlaveVeloEnd",
    "fSlaveAccEnd",
    "fSlaveJerkEnd",
    "fMPosAtSPosMin",
    "fSlavePosMin",
    "fMPosAtSVeloMin",
    "fSlaveVeloMin",
    "fMPosAtSAccMin",
    "fSlaveAccMin",
    "fSVeloAtSAccMin",
    "fSlaveJerkMin",
    "fSlaveDynMomMin",
    "fMPosAtSPosMax",
    "fSlavePosMax",
    "fMPosAtSVeloMax",
    "fSlaveVeloMax",
    "fMPosAtSAccMax",
    "fSlaveAccMax",
    "fSVeloAtSAccMax",
    "fSlaveJerkMax",
    "fSlaveDynMomMax",
    "fSlaveVeloMean",
    "fSlaveAccEff",
];

/// `ST_SyncMode`: the profile kind and the check and operation flags as one bit mask
/// ([`hli::calls::saw::sync_mask`]); the CNC refuses bits it does not know.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SyncMode {
    /// GEARINSYNCMODE_TIMEBASED (MC_GearInVelo only) rather than position-based.
    pub time_based: bool,
    /// Check and operation bits.
    pub mask: u32,
}

impl SyncMode {
    /// The raw `E_GearInSyncMode`.
    pub fn raw_mode(self) -> u32 {
        if self.time_based {
            SawSyncMode::TimeBased.raw()
        } else {
            SawSyncMode::PositionBased.raw()
        }
    }
}

/// Outputs of a flying-saw block (the one-shot blocks use Done, the couplings StartSync,
/// InSync, Active and CommandAborted).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SawOutputs {
    /// MC_GearOut / the read: the CNC answered.
    pub done: bool,
    /// The CNC accepted the coupling (kept until the outputs clear).
    pub start_sync: bool,
    /// The slave is coupled and synchronous.
    pub in_sync: bool,
    /// Sent and not finished.
    pub busy: bool,
    /// The coupling is being made (= Busy, as the seed says).
    pub active: bool,
    /// The coupling ended without this block.
    pub command_aborted: bool,
    /// Refused or failed; see `error_id`.
    pub error: bool,
    /// The CNC's code, the axis's error, or [`ERROR_NO_ANSWER`].
    pub error_id: u32,
}

impl SawOutputs {
    const NONE: SawOutputs = SawOutputs {
        done: false,
        start_sync: false,
        in_sync: false,
        busy: false,
        active: false,
        command_aborted: false,
        error: false,
        error_id: 0,
    };
    const BUSY: SawOutputs = SawOutputs {
        busy: true,
        active: true,
        ..SawOutputs::NONE
    };
    const STARTED: SawOutputs = SawOutputs {
        start_sync: true,
        ..SawOutputs::BUSY
    };
    const DONE: SawOutputs = SawOutputs {
        done: true,
        ..SawOutputs::NONE
    };
}

fn failed(error_id: u32) -> SawOutputs {
    SawOutputs {
        error: true,
        error_id,
        ..SawOutputs::default()
    }
}

/// What a call on its way gave this cycle.
#[derive(Debug, PartialEq)]
enum Answer<R> {
    Waiting,
    Reply(R),
    /// Refused by the transport layer, lost, or not answered in time: the block's code.
    Failed(u32),
}

fn answer<R>(result: Option<Result<R, CallError>>, waited: u64, timeout: u64) -> Answer<R> {
    match result {
        None if waited > timeout => Answer::Failed(ERROR_NO_ANSWER),
        None => Answer::Waiting,
        Some(Ok(reply)) => Answer::Reply(reply),
        Some(Err(CallError::Refused { code })) => Answer::Failed(code.raw()),
        Some(Err(_)) => Answer::Failed(ERROR_NO_ANSWER),
    }
}

/// What the slave's image says about the coupling a block made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Image {
    Faulted(u32),
    Ours { synchronous: bool },
    Other,
}

fn read_image(state: Option<HliAxisLrState>, kind: CouplingState, master: u32) -> Image {
    match state {
        Some(s) if s.error_id_r != 0 => Image::Faulted(s.error_id_r),
        Some(s)
            if s.coupling_state_r == kind.raw()
                && i64::from(s.master_axis_r) == i64::from(master) =>
        {
            Image::Ours {
                synchronous: s.axis_state_r == AxisState::SlaveSynchronous.raw(),
            }
        }
        _ => Image::Other,
    }
}

enum GearPhase {
    Idle,
    Sent {
        call: PendingCall<SawGearInCall>,
        since: u64,
        master: u32,
    },
    /// Accepted in cycle `since`; `seen` once the image showed the coupling, `synced` once it
    /// was synchronous.
    Following {
        master: u32,
        since: u64,
        seen: bool,
        synced: bool,
    },
}

/// The Execute edge, the call and the following of the slave, shared by MC_GearInVelo and
/// MC_GearInPos.
struct GearInCore {
    kind: CouplingState,
    timeout_cycles: u64,
    execute_before: bool,
    phase: GearPhase,
    out: SawOutputs,
}

impl GearInCore {
    fn new(kind: CouplingState) -> GearInCore {
        GearInCore {
            kind,
            timeout_cycles: DEFAULT_TIMEOUT_CYCLES,
            execute_before: false,
            phase: GearPhase::Idle,
            out: SawOutputs::default(),
        }
    }

    fn busy(&self) -> bool {
        match self.phase {
            GearPhase::Idle => false,
            GearPhase::Sent { .. } => true,
            GearPhase::Following { synced, .. } => !synced,
        }
    }

    /// A rising edge while not Busy: the block sends now (outputs cleared).
    fn edge(&mut self, execute: bool) -> bool {
        let send = rose(&mut self.execute_before, execute) && !self.busy();
        if send {
            self.out = SawOutputs::default();
            self.phase = GearPhase::Idle;
        }
        send
    }

    fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        execute: bool,
        slave: u32,
        call: SawGearInCall,
    ) -> SawOutputs {
        if self.edge(execute) {
            self.phase = match io.acyclic.start(slave, &call) {
                Ok(pending) => GearPhase::Sent {
                    call: pending,
                    since: io.cycle,
                    master: call.master,
                },
                Err(_) => {
                    self.out = failed(ERROR_NO_ANSWER);
                    GearPhase::Idle
                }
            };
        }
        self.poll_reply(io.cycle);
        if let GearPhase::Following { master, .. } = self.phase {
            let image = read_image(io.view.axis_state(slave as usize).ok(), self.kind, master);
            self.follow(image, io.cycle);
        }
        self.finish(execute)
    }

    fn poll_reply(&mut self, cycle: u64) {
        let GearPhase::Sent {
            call,
            since,
            master,
        } = &self.phase
        else {
            return;
        };
        let (since, master) = (*since, *master);
        match answer(
            call.poll(),
            cycle.saturating_sub(since),
            self.timeout_cycles,
        ) {
            Answer::Waiting => self.out = SawOutputs::BUSY,
            Answer::Reply(reply) if reply.error_id != 0 => {
                self.out = failed(reply.error_id);
                self.phase = GearPhase::Idle;
            }
            Answer::Reply(_) => {
                self.out = SawOutputs::STARTED;
                self.phase = GearPhase::Following {
                    master,
                    since: cycle,
                    seen: false,
                    synced: false,
                };
            }
            Answer::Failed(code) => {
                self.out = failed(code);
                self.phase = GearPhase::Idle;
            }
        }
    }

    fn follow(&mut self, image: Image, cycle: u64) {
        let GearPhase::Following {
            since,
            seen,
            synced,
            ..
        } = &mut self.phase
        else {
            return;
        };
        // The CNC answers between two ticks: the image read in the reply's own cycle may
        // still be the tick before the coupling (an earlier coupling of the slave included).
        if cycle <= *since {
            return;
        }
        let waited = cycle - *since;
        let ended = SawOutputs {
            start_sync: true,
            command_aborted: true,
            ..SawOutputs::default()
        };
        match image {
            Image::Faulted(code) => {
                self.out = SawOutputs {
                    start_sync: true,
                    ..failed(code)
                };
                self.phase = GearPhase::Idle;
            }
            Image::Ours { synchronous } => {
                *seen = true;
                *synced |= synchronous;
                let busy = !*synced;
                self.out = SawOutputs {
                    start_sync: true,
                    in_sync: synchronous,
                    busy,
                    active: busy,
                    ..SawOutputs::default()
                };
            }
            // Gone after it was seen; or never shown at all within the timeout (ended
            // between two PLC cycles).
            Image::Other if *seen || waited > self.timeout_cycles => {
                self.out = ended;
                self.phase = GearPhase::Idle;
            }
            Image::Other => {}
        }
    }

    /// The outputs of this cycle; Execute low and not Busy: they clear after being shown.
    fn finish(&mut self, execute: bool) -> SawOutputs {
        let shown = self.out;
        if !execute && !self.busy() {
            self.out = SawOutputs::default();
            self.phase = GearPhase::Idle;
        }
        shown
    }
}

impl core::fmt::Debug for GearInCore {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("GearInCore")
            .field("out", &self.out)
            .finish()
    }
}

/// The inputs MC_GearInVelo and MC_GearInPos share.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GearInInputs {
    /// Gear ratio numerator (may be negative; a ratio of 0 is refused). With a denominator
    /// of 1 it may carry the whole ratio (0.25 for 1:4).
    pub ratio_numerator: f64,
    /// Gear ratio denominator (0 is refused).
    pub ratio_denominator: u32,
    /// Profile kind and flags.
    pub sync_mode: SyncMode,
    /// Slave velocity limit of the synchronising phase (0: the axis's own).
    pub velocity: f64,
    /// Acceleration limit (0: the axis's own).
    pub acceleration: f64,
    /// Deceleration limit (0: the axis's own).
    pub deceleration: f64,
    /// Jerk limit (0: the axis's own).
    pub jerk: f64,
}

impl Default for GearInInputs {
    /// Ratio 1:1, position-based, no flags, the axis's own limits.
    fn default() -> Self {
        GearInInputs {
            ratio_numerator: 1.0,
            ratio_denominator: 1,
            sync_mode: SyncMode::default(),
            velocity: 0.0,
            acceleration: 0.0,
            deceleration: 0.0,
            jerk: 0.0,
        }
    }
}

impl GearInInputs {
    /// The call that couples to `master`, synchronising `on` velocity or position (the sync
    /// positions matter for the latter only).
    fn call(&self, master: u32, on: u32, sync_positions: [f64; 2]) -> SawGearInCall {
        SawGearInCall {
            master,
            target: on,
            sync_mode: self.sync_mode.raw_mode(),
            mask: self.sync_mode.mask,
            ratio_denominator: self.ratio_denominator,
            reserved: 0,
            ratio_numerator: self.ratio_numerator,
            master_sync_position: sync_positions[0],
            slave_sync_position: sync_positions[1],
            velocity: self.velocity,
            acceleration: self.acceleration,
            deceleration: self.deceleration,
            jerk: self.jerk,
        }
    }
}

/// MC_GearInVelo: the slave synchronises on the master's velocity times the ratio.
#[derive(Debug)]
pub struct McGearInVelo {
    /// Input: a rising edge sends the coupling.
    pub execute: bool,
    /// Inputs: ratio, SyncMode and the limits.
    pub inputs: GearInInputs,
    /// In/out: the master axis index.
    pub master: u32,
    /// In/out: the slave axis index (the call's target).
    pub slave: u32,
    /// Outputs of the last cycle.
    pub out: SawOutputs,
    core: GearInCore,
}

impl Default for McGearInVelo {
    fn default() -> Self {
        McGearInVelo {
            execute: false,
            inputs: GearInInputs::default(),
            master: 0,
            slave: 0,
            out: SawOutputs::default(),
            core: GearInCore::new(CouplingState::GearVelocity),
        }
    }
}

impl McGearInVelo {
    /// Input: cycles to wait for the CNC's answer.
    pub fn set_timeout_cycles(&mut self, cycles: u64) {
        self.core.timeout_cycles = cycles;
    }

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let call = self
            .inputs
            .call(self.master, SawSyncTarget::Velocity.raw(), [0.0; 2]);
        self.out = self.core.cycle(io, self.execute, self.slave, call);
    }
}

/// MC_GearInPos: the slave reaches the synchronous velocity exactly when master and slave
/// pass their sync positions (the master must be moving).
#[derive(Debug)]
pub struct McGearInPos {
    /// Input: a rising edge sends the coupling.
    pub execute: bool,
    /// Inputs: ratio, SyncMode and the limits.
    pub inputs: GearInInputs,
    /// Input: the master's sync position.
    pub master_sync_position: f64,
    /// Input: the slave's sync position.
    pub slave_sync_position: f64,
    /// In/out: the master axis index.
    pub master: u32,
    /// In/out: the slave axis index (the call's target).
    pub slave: u32,
    /// Outputs of the last cycle.
    pub out: SawOutputs,
    core: GearInCore,
}

impl Default for McGearInPos {
    fn default() -> Self {
        McGearInPos {
            execute: false,
            inputs: GearInInputs::default(),
            master_sync_position: 0.0,
            slave_sync_position: 0.0,
            master: 0,
            slave: 0,
            out: SawOutputs::default(),
            core: GearInCore::new(CouplingState::GearPosition),
        }
    }
}

impl McGearInPos {
    /// Input: cycles to wait for the CNC's answer.
    pub fn set_timeout_cycles(&mut self, cycles: u64) {
        self.core.timeout_cycles = cycles;
    }

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let positions = [self.master_sync_position, self.slave_sync_position];
        let call = self
            .inputs
            .call(self.master, SawSyncTarget::Position.raw(), positions);
        self.out = self.core.cycle(io, self.execute, self.slave, call);
    }
}

/// Execute edge, one call on its way (with the cycle it left in) and the outputs: the
/// one-shot blocks' share.
struct Request<C: AcyclicCall> {
    timeout_cycles: u64,
    execute_before: bool,
    pending: Option<(PendingCall<C>, u64)>,
    out: SawOutputs,
}

impl<C: AcyclicCall> Default for Request<C> {
    fn default() -> Self {
        Request {
            timeout_cycles: DEFAULT_TIMEOUT_CYCLES,
            execute_before: false,
            pending: None,
            out: SawOutputs::default(),
        }
    }
}

impl<C: AcyclicCall> Request<C> {
    fn edge(&mut self, execute: bool) -> bool {
        let send = rose(&mut self.execute_before, execute) && self.pending.is_none();
        if send {
            self.out = SawOutputs::default();
        }
        send
    }

    fn send(&mut self, io: &mut PlcIo<'_>, target: u32, call: &C) {
        match io.acyclic.start(target, call) {
            Ok(p) => {
                self.pending = Some((p, io.cycle));
                self.out = SawOutputs {
                    active: false,
                    ..SawOutputs::BUSY
                };
            }
            Err(_) => self.out = failed(ERROR_NO_ANSWER),
        }
    }

    /// The answer once it is in (the reply, or the code of a failure); `None` while waiting
    /// or when nothing is on its way.
    fn take_answer(&mut self, cycle: u64) -> Option<Result<C::Reply, u32>> {
        let (pending, since) = self.pending.as_ref()?;
        let waited = cycle.saturating_sub(*since);
        let got = match answer(pending.poll(), waited, self.timeout_cycles) {
            Answer::Waiting => return None,
            Answer::Reply(reply) => Ok(reply),
            Answer::Failed(code) => Err(code),
        };
        self.pending = None;
        Some(got)
    }

    fn finish(&mut self, execute: bool) -> SawOutputs {
        let shown = self.out;
        if !execute && self.pending.is_none() {
            self.out = SawOutputs::default();
        }
        shown
    }
}

impl<C: AcyclicCall> core::fmt::Debug for Request<C> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Request").field("out", &self.out).finish()
    }
}

/// MC_GearOut: the slave leaves the coupling and keeps its velocity as a free axis (stop it
/// with MC_Stop or MC_Halt). Done when the CNC has decoupled it.
#[derive(Debug, Default)]
pub struct McGearOut {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// In/out: the slave axis index.
    pub slave: u32,
    /// Outputs of the last cycle.
    pub out: SawOutputs,
    request: Request<SawGearOutCall>,
}

impl McGearOut {
    /// Input: cycles to wait for the CNC's answer.
    pub fn set_timeout_cycles(&mut self, cycles: u64) {
        self.request.timeout_cycles = cycles;
    }

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        if self.request.edge(self.execute) {
            self.request
                .send(io, self.slave, &SawGearOutCall::default());
        }
        match self.request.take_answer(io.cycle) {
            None => {}
            Some(Ok(reply)) if reply.error_id != 0 => self.request.out = failed(reply.error_id),
            Some(Ok(_)) => self.request.out = SawOutputs::DONE,
            Some(Err(code)) => self.request.out = failed(code),
        }
        self.out = self.request.finish(self.execute);
    }
}

/// MC_ReadFlyingSawCharacteristics: the characteristic values of the synchronising phase last
/// planned for the slave, in two calls (fields 1-16, then 17-31). `values` (the seed's
/// CamTableCharac) is written whole when both parts are in, so it never mixes two reads.
#[derive(Debug, Default)]
pub struct McReadFlyingSawCharacteristics {
    /// Input: a rising edge starts the read.
    pub execute: bool,
    /// In/out: the slave axis index.
    pub slave: u32,
    /// Outputs of the last cycle.
    pub out: SawOutputs,
    /// In/out: fields 1-31 of `MC_FlyingSawCharacValues` ([`CHARAC_FIELDS`]).
    pub values: [f64; 31],
    request: Request<SawCharacCall>,
    part: u32,
    /// The plan part 0 belonged to.
    plan: u32,
    scratch: [f64; 31],
}

impl McReadFlyingSawCharacteristics {
    /// Input: cycles to wait for each part.
    pub fn set_timeout_cycles(&mut self, cycles: u64) {
        self.request.timeout_cycles = cycles;
    }

    /// The values with their field names, in the structure's order.
    pub fn characteristics(&self) -> impl Iterator<Item = (&'static str, f64)> + '_ {
        CHARAC_FIELDS
            .iter()
            .copied()
            .zip(self.values.iter().copied())
    }

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        if self.request.edge(self.execute) {
            self.part = 0;
            self.scratch = [0.0; 31];
            self.request
                .send(io, self.slave, &SawCharacCall { part: 0 });
        }
        match self.request.take_answer(io.cycle) {
            None => {}
            Some(Ok(reply)) if reply.error_id != 0 => self.request.out = failed(reply.error_id),
            // An answer to another question: as if none came.
            Some(Ok(reply)) if reply.part != self.part => {
                self.request.out = failed(ERROR_NO_ANSWER)
            }
            // Part 1 of another plan than part 0 (a new command came between): read again.
            Some(Ok(reply)) if self.part > 0 && reply.plan != self.plan => {
                self.part = 0;
                self.request
                    .send(io, self.slave, &SawCharacCall { part: 0 });
            }
            Some(Ok(reply)) => {
                self.plan = reply.plan;
                let from = self.part as usize * SAW_CHARAC_PART;
                for (slot, v) in self.scratch[from..].iter_mut().zip(reply.values) {
                    *slot = v;
                }
                if from + SAW_CHARAC_PART >= CHARAC_FIELDS.len() {
                    self.values = self.scratch;
                    self.request.out = SawOutputs::DONE;
                } else {
                    self.part += 1;
                    let call = SawCharacCall { part: self.part };
                    self.request.send(io, self.slave, &call);
                }
            }
            Some(Err(code)) => self.request.out = failed(code),
        }
        self.out = self.request.finish(self.execute);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hli::calls::saw::{SawCharacReply, SawReply};
    use hli::calls::{decode_body, reply, CallKind, ErrorCode};
    use hli::layout::HliAxis;
    use hli::rpc::{AcyclicClient, AcyclicServer};
    use hli::views::{CncView, PlcView};
    use hli::PlaceExt;

    #[test]
    fn the_library_names_its_version() {
        let v = saw_library_version();
        assert_eq!(v, concat!("cncplc-saw ", env!("CARGO_PKG_VERSION")));
        assert!(v.len() <= 20, "fits a STRING(20)");
    }

    #[test]
    fn answers_time_out_after_the_timeout_and_refusals_keep_their_code() {
        assert_eq!(answer::<u32>(None, 5, 5), Answer::Waiting);
        assert_eq!(answer::<u32>(None, 6, 5), Answer::Failed(ERROR_NO_ANSWER));
        let refused = Some(Err::<u32, _>(CallError::Refused {
            code: ErrorCode::InvalidTarget,
        }));
        let code = ErrorCode::InvalidTarget.raw();
        assert_eq!(answer(refused, 0, 5), Answer::Failed(code));
        let lost = Some(Err::<u32, _>(CallError::Transport("gone".into())));
        assert_eq!(answer(lost, 0, 5), Answer::Failed(ERROR_NO_ANSWER));
        assert_eq!(answer(Some(Ok(7u32)), 99, 5), Answer::Reply(7));
    }

    fn state(coupling: CouplingState, master: i32, axis: AxisState, error: u32) -> HliAxisLrState {
        HliAxisLrState {
            axis_state_r: axis.raw(),
            coupling_state_r: coupling.raw(),
            master_axis_r: master,
            error_id_r: error,
            ..bytemuck::Zeroable::zeroed()
        }
    }

    #[test]
    fn the_image_is_ours_only_for_our_kind_and_master() {
        let pos = CouplingState::GearPosition;
        let sync = AxisState::SlaveSynchronous;
        let image = |s| read_image(Some(s), pos, 2);
        assert_eq!(
            image(state(pos, 2, sync, 0)),
            Image::Ours { synchronous: true }
        );
        let synchronizing = AxisState::SlaveSynchronizing;
        assert_eq!(
            image(state(pos, 2, synchronizing, 0)),
            Image::Ours { synchronous: false }
        );
        let velocity = CouplingState::GearVelocity;
        assert_eq!(image(state(velocity, 2, sync, 0)), Image::Other);
        assert_eq!(image(state(pos, 3, sync, 0)), Image::Other);
        assert_eq!(image(state(pos, 2, sync, 0x4711)), Image::Faulted(0x4711));
        assert_eq!(read_image(None, pos, 2), Image::Other);
    }

    /// A core that had its coupling accepted in cycle 10.
    fn accepted() -> GearInCore {
        let mut fsm = GearInCore::new(CouplingState::GearPosition);
        fsm.execute_before = true;
        fsm.out = SawOutputs::STARTED;
        fsm.phase = GearPhase::Following {
            master: 0,
            since: 10,
            seen: false,
            synced: false,
        };
        fsm
    }

    #[test]
    fn a_coupling_is_busy_until_in_sync_then_aborted_when_it_goes_away() {
        let mut fsm = accepted();
        let ours = |synchronous| Image::Ours { synchronous };
        fsm.follow(ours(true), 10); // the reply's own cycle: its image may be older
        assert_eq!(fsm.finish(true), SawOutputs::STARTED);
        fsm.follow(Image::Other, 11); // not shown yet
        assert_eq!(fsm.finish(true), SawOutputs::STARTED);
        fsm.follow(ours(false), 12);
        assert_eq!(fsm.finish(true), SawOutputs::STARTED);
        assert!(
            !fsm.edge(false) && !fsm.edge(true),
            "an edge while Busy is ignored"
        );
        fsm.follow(ours(true), 13);
        let out = fsm.finish(true);
        assert!(
            out.in_sync && out.start_sync && !out.busy && !out.active,
            "{out:?}"
        );
        fsm.follow(ours(false), 14); // a rollback stop: still coupled
        let out = fsm.finish(true);
        assert!(!out.in_sync && !out.busy && !out.command_aborted, "{out:?}");
        fsm.follow(Image::Other, 15); // MC_GearOut, or another coupling
        let out = fsm.finish(false);
        assert!(out.command_aborted && !out.busy, "shown once: {out:?}");
        assert_eq!(fsm.finish(false), SawOutputs::default(), "then cleared");
    }

    #[test]
    fn faults_unseen_couplings_and_a_low_execute_end_the_following() {
        let mut fsm = accepted();
        fsm.follow(Image::Faulted(0x4711), 11);
        let out = fsm.finish(true);
        assert!(out.error && out.error_id == 0x4711 && !out.busy, "{out:?}");

        let mut fsm = accepted();
        fsm.timeout_cycles = 3;
        fsm.follow(Image::Other, 13);
        assert!(fsm.finish(true).busy, "still waiting for the image");
        fsm.follow(Image::Other, 14);
        assert!(
            fsm.finish(true).command_aborted,
            "never shown: ended unseen"
        );

        let mut fsm = accepted();
        fsm.follow(Image::Ours { synchronous: true }, 11);
        assert!(
            fsm.finish(false).in_sync,
            "InSync shown once with Execute low"
        );
        assert!(matches!(fsm.phase, GearPhase::Idle));
        assert_eq!(fsm.finish(false), SawOutputs::default());
        assert!(!fsm.edge(false) && fsm.edge(true), "a new edge sends again");
    }

    fn io<'a>(
        memory: &'a hli::ImageMemory,
        client: &'a mut AcyclicClient,
        cycle: u64,
    ) -> PlcIo<'a> {
        PlcIo {
            view: PlcView::new(memory),
            memory,
            acyclic: client,
            cycle,
        }
    }

    fn show(memory: &hli::ImageMemory, coupling: CouplingState, master: i32, axis: AxisState) {
        CncView::new(memory)
            .axis(1)
            .unwrap()
            .field::<HliAxisLrState>(core::mem::offset_of!(HliAxis, lr_state))
            .write(&state(coupling, master, axis, 0));
    }

    /// The blocks against a stand-in CNC in this thread: the coupling call, the slave's image
    /// written by hand, MC_GearOut, and the read in two parts.
    #[test]
    fn blocks_against_a_stand_in_cnc() {
        hli::init_logging();
        let instance = format!("saw-blocks-{}", std::process::id());
        let server = AcyclicServer::open(&instance).unwrap();
        let mut client = AcyclicClient::open(&instance).unwrap();
        let memory = hli::segment::heap_image(0, 2);
        let mut cycle = 0;
        let mut run = |call: &mut dyn FnMut(&mut PlcIo<'_>) -> bool| loop {
            cycle += 1;
            assert!(cycle < 100_000, "watchdog: no answer");
            if call(&mut io(&memory, &mut client, cycle)) {
                break;
            }
            std::thread::yield_now();
        };
        let pos = CouplingState::GearPosition;

        let mut gear = McGearInPos {
            execute: true,
            master: 0,
            slave: 1,
            master_sync_position: 100.0,
            ..McGearInPos::default()
        };
        run(&mut |io| {
            gear.call(io);
            true
        });
        let answered = server.poll(|kind, request| {
            assert_eq!((kind, request.target), (CallKind::SAW_GEAR_IN, 1));
            let call: SawGearInCall = decode_body(request)?;
            assert_eq!(
                (call.target, call.master_sync_position),
                (SawSyncTarget::Position.raw(), 100.0)
            );
            reply(&SawReply::default())
        });
        assert_eq!(answered.unwrap(), 1);
        run(&mut |io| {
            gear.call(io);
            gear.out.start_sync
        });
        assert!(gear.out.busy && gear.out.active, "{:?}", gear.out);
        for (axis, in_sync) in [
            (AxisState::SlaveSynchronizing, false),
            (AxisState::SlaveSynchronous, true),
        ] {
            show(&memory, pos, 0, axis);
            run(&mut |io| {
                gear.call(io);
                true
            });
            assert_eq!((gear.out.in_sync, gear.out.busy), (in_sync, !in_sync));
        }

        let mut gear_out = McGearOut {
            execute: true,
            slave: 1,
            ..McGearOut::default()
        };
        run(&mut |io| {
            gear_out.call(io);
            true
        });
        let answered = server.poll(|kind, _| {
            assert_eq!(kind, CallKind::SAW_GEAR_OUT);
            reply(&SawReply::default())
        });
        assert_eq!(answered.unwrap(), 1);
        run(&mut |io| {
            gear_out.call(io);
            !gear_out.out.busy
        });
        assert!(gear_out.out.done, "{:?}", gear_out.out);
        show(&memory, CouplingState::Uncoupled, -1, AxisState::Inactive);
        run(&mut |io| {
            gear.call(io);
            true
        });
        assert!(
            gear.out.command_aborted && !gear.out.in_sync,
            "{:?}",
            gear.out
        );

        let mut read = McReadFlyingSawCharacteristics {
            execute: true,
            slave: 1,
            ..McReadFlyingSawCharacteristics::default()
        };
        run(&mut |io| {
            read.call(io);
            server
                .poll(|_, request| {
                    let call: SawCharacCall = decode_body(request)?;
                    let mut values = [0.0; SAW_CHARAC_PART];
                    for (i, v) in values.iter_mut().enumerate() {
                        *v = (call.part as usize * SAW_CHARAC_PART + i + 1) as f64;
                    }
                    let part = call.part;
                    reply(&SawCharacReply {
                        error_id: 0,
                        part,
                        plan: 1,
                        reserved: 0,
                        values,
                    })
                })
                .unwrap();
            !read.out.busy
        });
        assert!(read.out.done, "{:?}", read.out);
        let got: Vec<(&str, f64)> = read.characteristics().collect();
        assert_eq!(got.len(), 31);
        assert_eq!(got[0], ("fMasterVeloNom", 1.0));
        assert_eq!(got[16], ("fSlaveAccMin", 17.0));
        assert_eq!(got[30], ("fSlaveAccEff", 31.0));
    }
}
