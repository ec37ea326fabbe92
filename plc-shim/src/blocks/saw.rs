//! The flying-saw blocks of seed 001 chapter 12 for the PLC program: MC_GearInVelo,
//! MC_GearInPos, MC_GearOut and MC_ReadFlyingSawCharacteristics, on the block kernel
//! ([`crate::kernel`]: its Execute, timeout and output rules). Each sends its call to the
//! slave's axis index on the rising Execute edge without waiting; no answer within the
//! timeout is an Error with [`ERROR_NO_ANSWER`] (the call may still have been executed).
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
//! that goes away later is CommandAborted. The block also follows its coupling's command id
//! in the slave's command book (the reply carries it): a new coupling of the slave by another
//! instance, even of the same kind to the same master (which looks like this block's own in
//! the image), aborts it there, and the block shows CommandAborted.
//!
//! With Execute low the block follows on until the coupling ends, and shows that end for one
//! cycle (the kernel's rule for every block).
//!
//! A timeline calls them by their names ([`TIMELINE`]) with the seed's input names
//! ([`inputs`]).

use crate::kernel::{
    call_error_code, done_unless, no_follow, send, Accept, InFlight, Kernel, Outputs, Polled, Step,
    Waited, ERROR_NO_ANSWER,
};
use crate::runtime::PlcIo;
use crate::timeline::registry::{BlockSpec, InputSpec, Target, TimelineBlock, Value};
use hli::calls::cam::TableOrganisation;
use hli::calls::saw::{
    SawCharacCall, SawGearInCall, SawGearOutCall, SawSyncMode, SawSyncTarget, SAW_CHARAC_PART,
    SAW_CHARAC_PARTS,
};
use hli::command_book::{view_command, CommandView};
use hli::enums::{AxisState, CouplingState};
use hli::layout::{HliAxis, HliAxisCommandState, HliAxisLrState};
use hli::PlaceExt;
use hli_transport::rpc::PendingCall;

pub mod inputs;

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
    /// Check bits (`GearInSync_CheckMask_*`).
    pub check_mask: u32,
    /// Operation bits (`GearInSync_OpMask_*`).
    pub op_mask: u32,
}

impl SyncMode {
    /// Check and operation bits as the one mask the call carries.
    pub fn mask(self) -> u32 {
        self.check_mask | self.op_mask
    }

    /// The raw `E_GearInSyncMode`.
    pub fn raw_mode(self) -> u32 {
        if self.time_based {
            SawSyncMode::TimeBased.raw()
        } else {
            SawSyncMode::PositionBased.raw()
        }
    }
}

fn failed(error_id: u32) -> Outputs {
    Outputs::failed(error_id)
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

/// What a coupling block keeps while it follows its accepted coupling: the master it asked
/// for, whether the image has shown the coupling, and whether it was synchronous once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct GearFollow {
    master: u32,
    /// The coupling's command id in the slave's command book (0: a CNC that gives none).
    command_id: u32,
    seen: bool,
    synced: bool,
}

/// Accepted: StartSync, Busy = Active.
const STARTED: Outputs = Outputs {
    start_sync: true,
    busy: true,
    active: true,
    done: false,
    command_aborted: false,
    error: false,
    error_id: 0,
    in_velocity: false,
    in_sync: false,
    extra: (),
};

/// One cycle of following an accepted coupling through the slave's image.
fn follow_gear(f: &mut GearFollow, image: Image, book: CommandView, waited: Waited) -> Step<()> {
    // The CNC answers between two ticks: the image read in the reply's own cycle may still be
    // the tick before the coupling (an earlier coupling of the slave included).
    if waited.cycles == 0 {
        return Step::Running(STARTED);
    }
    // Replaced in the book: a new coupling of the slave (by any block, also one that looks
    // like ours in the image), or the coupling's end.
    if f.command_id != 0 && matches!(book, CommandView::Aborted | CommandView::Unknown) {
        return Step::Ended(Outputs {
            start_sync: true,
            command_aborted: true,
            ..Outputs::default()
        });
    }
    match image {
        Image::Faulted(code) => Step::Ended(Outputs {
            start_sync: true,
            ..failed(code)
        }),
        Image::Ours { synchronous } => {
            f.seen = true;
            f.synced |= synchronous;
            let busy = !f.synced;
            Step::Running(Outputs {
                start_sync: true,
                in_sync: synchronous,
                busy,
                active: busy,
                ..Outputs::default()
            })
        }
        // Gone after it was seen; or never shown at all within the timeout (ended between
        // two PLC cycles).
        Image::Other if f.seen || waited.cycles > waited.timeout => Step::Ended(Outputs {
            start_sync: true,
            command_aborted: true,
            ..Outputs::default()
        }),
        Image::Other => Step::Running(STARTED),
    }
}

/// The block kernel as MC_GearInVelo and MC_GearInPos use it.
struct GearInCore {
    kind: CouplingState,
    kernel: Kernel<PendingCall<SawGearInCall>, GearFollow>,
}

impl GearInCore {
    fn new(kind: CouplingState) -> GearInCore {
        GearInCore {
            kind,
            kernel: Kernel::active_while_sent(),
        }
    }

    fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        execute: bool,
        slave: u32,
        call: SawGearInCall,
    ) -> Outputs {
        let kind = self.kind;
        self.kernel.cycle(
            io,
            execute,
            |io| send(io, slave, &call),
            |reply| match reply.error_id {
                0 => Accept::Follow(
                    GearFollow {
                        master: call.master,
                        command_id: reply.command_id,
                        seen: false,
                        synced: false,
                    },
                    STARTED,
                ),
                code => Accept::Failed(code, ()),
            },
            |f, io, waited| {
                let image = read_image(io.view.axis_state(slave as usize).ok(), kind, f.master);
                let book = io
                    .view
                    .axis(slave as usize)
                    .map(|place| {
                        let book: HliAxisCommandState = place
                            .field::<HliAxisCommandState>(core::mem::offset_of!(
                                HliAxis,
                                command_state
                            ))
                            .read();
                        view_command(&book, f.command_id)
                    })
                    .unwrap_or(CommandView::Unknown);
                follow_gear(f, image, book, waited)
            },
        )
    }
}

impl core::fmt::Debug for GearInCore {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.kernel.fmt(f)
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
    /// Follow the master's actual values (an encoder master) rather than its set-point; our
    /// input, as MC_CamIn's `master_source` (the seed knows the encoder master as an axis
    /// type).
    pub master_actual: bool,
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
            master_actual: false,
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
            mask: self.sync_mode.mask(),
            ratio_denominator: self.ratio_denominator,
            master_source: u32::from(self.master_actual),
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
    pub out: Outputs,
    core: GearInCore,
}

impl Default for McGearInVelo {
    fn default() -> Self {
        McGearInVelo {
            execute: false,
            inputs: GearInInputs::default(),
            master: 0,
            slave: 0,
            out: Outputs::default(),
            core: GearInCore::new(CouplingState::GearVelocity),
        }
    }
}

impl McGearInVelo {
    timeout_input!(core.kernel);

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
    pub out: Outputs,
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
            out: Outputs::default(),
            core: GearInCore::new(CouplingState::GearPosition),
        }
    }
}

impl McGearInPos {
    timeout_input!(core.kernel);

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let positions = [self.master_sync_position, self.slave_sync_position];
        let call = self
            .inputs
            .call(self.master, SawSyncTarget::Position.raw(), positions);
        self.out = self.core.cycle(io, self.execute, self.slave, call);
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
    pub out: Outputs,
    kernel: Kernel<PendingCall<SawGearOutCall>>,
}

impl McGearOut {
    timeout_input!(kernel);

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let slave = self.slave;
        self.out = self.kernel.cycle(
            io,
            self.execute,
            |io| send(io, slave, &SawGearOutCall::default()),
            |reply| done_unless(reply.error_id),
            no_follow,
        );
    }
}

/// The read of the characteristic values in its parts: part 0 first; a part of another plan
/// than part 0 (a new command came between) starts the read over.
struct CharacRead {
    slave: u32,
    pending: PendingCall<SawCharacCall>,
    part: u32,
    plan: u32,
    /// Three parts of 16: the 31 values, then the organisation fields from place 32 on.
    scratch: [f64; 48],
}

impl CharacRead {
    fn start(io: &mut PlcIo<'_>, slave: u32) -> Result<CharacRead, u32> {
        Ok(CharacRead {
            slave,
            pending: Self::send(io, slave, 0)?,
            part: 0,
            plan: 0,
            scratch: [0.0; 48],
        })
    }

    fn send(io: &mut PlcIo<'_>, slave: u32, part: u32) -> Result<PendingCall<SawCharacCall>, u32> {
        send(io, slave, &SawCharacCall { part })
    }

    fn next(&mut self, io: &mut PlcIo<'_>, part: u32) -> Polled<[f64; 48]> {
        match Self::send(io, self.slave, part) {
            Ok(pending) => {
                self.pending = pending;
                self.part = part;
                Polled::Progress
            }
            Err(code) => Polled::Answer(Err(code)),
        }
    }
}

impl InFlight for CharacRead {
    type Reply = [f64; 48];
    type Buffer = ();

    fn poll(&mut self, io: &mut PlcIo<'_>, _: &mut ()) -> Polled<[f64; 48]> {
        let reply = match self.pending.poll() {
            None => return Polled::Waiting,
            Some(Err(e)) => return Polled::Answer(Err(call_error_code(&e))),
            Some(Ok(reply)) => reply,
        };
        if reply.error_id != 0 {
            return Polled::Answer(Err(reply.error_id));
        }
        if reply.part != self.part {
            // An answer to another question: as if none came.
            return Polled::Answer(Err(ERROR_NO_ANSWER));
        }
        if self.part > 0 && reply.plan != self.plan {
            return self.next(io, 0);
        }
        self.plan = reply.plan;
        let from = self.part as usize * SAW_CHARAC_PART;
        for (slot, v) in self.scratch[from..].iter_mut().zip(reply.values) {
            *slot = v;
        }
        if self.part + 1 >= SAW_CHARAC_PARTS {
            Polled::Answer(Ok(self.scratch))
        } else {
            self.next(io, self.part + 1)
        }
    }
}

/// MC_ReadFlyingSawCharacteristics: the characteristic values of the synchronising phase last
/// planned for the slave, in three calls (fields 1-16, 17-31, then the organisation fields).
/// `values` and `organisation` (the seed's CamTableCharac) are written whole when every part
/// is in, so they never mix two reads.
#[derive(Debug, Default)]
pub struct McReadFlyingSawCharacteristics {
    /// Input: a rising edge starts the read.
    pub execute: bool,
    /// In/out: the slave axis index.
    pub slave: u32,
    /// Outputs of the last cycle.
    pub out: Outputs,
    /// In/out: fields 1-31 of `MC_FlyingSawCharacValues` ([`CHARAC_FIELDS`]).
    pub values: [f64; 31],
    /// In/out: the organisation fields (CamTableID 256 - the slave's axis ID, the points of
    /// the phase's motion function, 1 column, TableType 22, not periodic).
    pub organisation: TableOrganisation,
    kernel: Kernel<CharacRead>,
}

impl core::fmt::Debug for CharacRead {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("CharacRead")
            .field("part", &self.part)
            .finish()
    }
}

impl McReadFlyingSawCharacteristics {
    timeout_input!(kernel);

    /// The values with their field names, in the structure's order.
    pub fn characteristics(&self) -> impl Iterator<Item = (&'static str, f64)> + '_ {
        CHARAC_FIELDS
            .iter()
            .copied()
            .zip(self.values.iter().copied())
    }

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let slave = self.slave;
        let (values, organisation) = (&mut self.values, &mut self.organisation);
        self.out = self.kernel.cycle(
            io,
            self.execute,
            |io| CharacRead::start(io, slave),
            |read| {
                let org = TableOrganisation::from_values(&read[32..37]);
                let Some(org) = org else {
                    // Fields that are no organisation: as if no answer came.
                    return Accept::Failed(ERROR_NO_ANSWER, ());
                };
                values.copy_from_slice(&read[..31]);
                *organisation = org;
                Accept::Done(())
            },
            no_follow,
        );
    }
}

impl TimelineBlock for McGearInVelo {
    timeline_timeout!();
    fn set_master(&mut self, index: u32) -> bool {
        self.master = index;
        true
    }
    fn set(&mut self, key: &str, value: &Value) {
        inputs::set_velo(self, key, value);
    }
    execute_cycle!(as_slave, recorded);
}

impl TimelineBlock for McGearInPos {
    timeline_timeout!();
    fn set_master(&mut self, index: u32) -> bool {
        self.master = index;
        true
    }
    fn set(&mut self, key: &str, value: &Value) {
        inputs::set_pos(self, key, value);
    }
    execute_cycle!(as_slave, recorded);
}

impl TimelineBlock for McGearOut {
    timeline_timeout!();
    fn set(&mut self, _: &str, _: &Value) {}
    execute_cycle!(as_slave, recorded);
}

/// MC_ReadFlyingSawCharacteristics in a timeline: its values are reported once a read
/// finished.
#[derive(Debug, Default)]
struct CharacInstance {
    block: McReadFlyingSawCharacteristics,
    read: bool,
}

impl TimelineBlock for CharacInstance {
    timeline_timeout!(block);
    fn set(&mut self, _: &str, _: &Value) {}
    fn execute(&mut self) -> Option<&mut bool> {
        Some(&mut self.block.execute)
    }
    fn cycle(&mut self, io: &mut PlcIo<'_>, axis: u32) -> (Outputs, bool) {
        self.block.slave = axis;
        self.block.call(io);
        self.read |= self.block.out.done;
        recorded(self.block.out)
    }
    /// `CamTableCharac : MC_FlyingSawCharacValues` in Structured Text.
    fn results(&self) -> Option<&'static crate::timeline::registry::Results> {
        Some(&super::cam_results::FLYING_SAW_CHARAC)
    }
    fn result_values(&self, out: &mut [f64]) -> usize {
        let mut all = [0.0; 36];
        all[..31].copy_from_slice(&self.block.values);
        all[31..].copy_from_slice(&self.block.organisation.values());
        super::cam_results::characteristics(&all, out)
    }
    /// The 31 values in `MC_FlyingSawCharacValues` order ([`CHARAC_FIELDS`]), then the
    /// five organisation fields.
    fn read(&self) -> Option<Vec<f64>> {
        let org = self.block.organisation.values();
        self.read
            .then(|| self.block.values.iter().chain(&org).copied().collect())
    }
}

/// What a timeline records of a saw block's outputs: all but StartSync.
fn recorded(out: Outputs) -> (Outputs, bool) {
    let out = Outputs {
        start_sync: false,
        ..out
    };
    (out, false)
}

/// A flying-saw block a timeline calls, on its slave's axis (`Slave` or `axis`).
const fn saw_block(
    name: &'static str,
    inputs: &'static [InputSpec],
    make: fn(Option<usize>) -> Box<dyn TimelineBlock>,
) -> BlockSpec {
    BlockSpec::with_execute(name, Target::AxisNamed("Slave"), inputs, make)
}

/// The flying-saw blocks a timeline calls (their inputs: [`inputs`]).
pub const TIMELINE: &[BlockSpec] = &[
    saw_block("MC_GearInVelo", inputs::VELO, |_| {
        Box::<McGearInVelo>::default()
    }),
    saw_block("MC_GearInPos", inputs::POS, |_| {
        Box::<McGearInPos>::default()
    }),
    saw_block("MC_GearOut", &[], |_| Box::<McGearOut>::default()),
    saw_block("MC_ReadFlyingSawCharacteristics", &[], |_| {
        Box::<CharacInstance>::default()
    }),
];

#[cfg(test)]
mod tests;
