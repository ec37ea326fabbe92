//! The flying saw's calls (seed 001, chapter 12): MC_GearInVelo and MC_GearInPos in one
//! coupling call, MC_GearOut, and MC_ReadFlyingSawCharacteristics in three parts (the 31
//! values do not fit one frame; the organisation fields come last). Every call addresses the slave axis as `target` (its `gpAx`
//! index); the master is an axis index in the body. The slave's progress is read from its
//! axis image: `coupling_state_r` 2 (velocity) or 3 (position) and `nAxisState` 11/12/13.

use crate::enums::{hli_enum, wire_enum};
use crate::wire::ACYCLIC_BODY_SIZE;
use bytemuck::{Pod, Zeroable};

hli_enum! {
    /// Why the flying saw refused a coupling or ended one (seed 001, chapter 13 and the
    /// `SyncMode` checks of chapter 5). The seed refers to the controller's general error
    /// list for the numbers; these are ours. A violated check is reported as `Limit`
    /// unless `GEARINSYNC_OPMASK_DETAILEDERRORCODES` asks for the check's own code.
    SawError: u32, "SawError" {
        /// The master is not an axis of the machine, or is the slave itself.
        NoSuchMaster = 0x4400,
        /// The master stands and the slave moves: no coupling is possible (chapter 13).
        MasterAtRest = 0x4401,
        /// Gear ratio 0 (numerator 0 or denominator 0).
        RatioZero = 0x4402,
        /// A negative velocity, acceleration, deceleration or jerk.
        NegativeLimit = 0x4403,
        /// The master sync position is not ahead of the master in its direction of travel.
        MasterSyncNotAhead = 0x4404,
        /// The slave sync position is not ahead of the slave (ratio > 0) or behind it
        /// (ratio < 0).
        SlaveSyncNotAhead = 0x4405,
        /// The internal motion-function table 256 - slave axis ID is used by a cam.
        TableInUse = 0x4406,
        /// The time-based profile exists for MC_GearInVelo only.
        TimeBasedPosition = 0x4407,
        /// Unknown bits in the check or operation mask, or an unknown sync mode.
        Mode = 0x4408,
        /// A value that is not finite, or a profile that would not be.
        NotFinite = 0x4409,
        /// A check of the sync mode failed (the check's own code with DETAILEDERRORCODES).
        Limit = 0x440A,
        /// MC_GearOut for an axis the saw does not drive, or a characteristics read for an
        /// axis the saw never planned for.
        NotCoupled = 0x440B,
        /// Position sync with a master standing still.
        MasterStands = 0x440C,
        /// Check MINPOS: the slave would pass its lower software limit.
        CheckMinPos = 0x4410,
        /// Check MAXPOS: the slave would pass its upper software limit.
        CheckMaxPos = 0x4411,
        /// Check MAXVELO: the slave would exceed the velocity limit.
        CheckMaxVelo = 0x4412,
        /// Check MAXACC: the slave would exceed the acceleration limit.
        CheckMaxAcc = 0x4413,
        /// Check MAXDEC: the slave would exceed the deceleration limit.
        CheckMaxDec = 0x4414,
        /// Check MAXJERK: the slave would exceed the jerk limit.
        CheckMaxJerk = 0x4415,
        /// Check OVERSHOOTPOS: the slave would pass its sync position.
        CheckOvershootPos = 0x4416,
        /// Check UNDERSHOOTPOS: the slave would move back behind its start position.
        CheckUndershootPos = 0x4417,
        /// Check OVERSHOOTVELO: the slave velocity would pass beyond both its start and its
        /// sync velocity.
        CheckOvershootVelo = 0x4418,
        /// Check UNDERSHOOTVELO: the slave velocity would fall below both its start and its
        /// sync velocity.
        CheckUndershootVelo = 0x4419,
        /// Check OVERSHOOTVELOZERO: the slave velocity would rise above 0.
        CheckOvershootVeloZero = 0x441A,
        /// Check UNDERSHOOTVELOZERO: the slave velocity would fall below 0.
        CheckUndershootVeloZero = 0x441B,
    }
}

/// `ST_SyncMode` bits: the checks (chapter 5, values as the seed gives them) and the
/// operation masks.
pub mod sync_mask {
    /// Slave position >= its lower software limit.
    pub const MINPOS: u32 = 0x0000_0001;
    /// Slave position <= its upper software limit.
    pub const MAXPOS: u32 = 0x0000_0002;
    /// |slave velocity| <= the velocity limit.
    pub const MAXVELO: u32 = 0x0000_0004;
    /// Slave acceleration (speeding up) <= the acceleration limit.
    pub const MAXACC: u32 = 0x0000_0008;
    /// Slave deceleration (slowing down) <= the deceleration limit.
    pub const MAXDEC: u32 = 0x0000_0010;
    /// |slave jerk| <= the jerk limit.
    pub const MAXJERK: u32 = 0x0000_0020;
    /// The slave position does not pass beyond its sync position.
    pub const OVERSHOOTPOS: u32 = 0x0000_0100;
    /// The slave position does not go back behind its start position.
    pub const UNDERSHOOTPOS: u32 = 0x0000_0200;
    /// The slave velocity stays at or below the larger of start and sync velocity.
    pub const OVERSHOOTVELO: u32 = 0x0000_0400;
    /// The slave velocity stays at or above the smaller of start and sync velocity.
    pub const UNDERSHOOTVELO: u32 = 0x0000_0800;
    /// The slave velocity does not rise above 0.
    pub const OVERSHOOTVELOZERO: u32 = 0x0000_1000;
    /// The slave velocity does not fall below 0.
    pub const UNDERSHOOTVELOZERO: u32 = 0x0000_2000;
    /// Every check bit.
    pub const CHECKS: u32 = 0x0000_3F3F;
    /// Rollback lock: the slave stops when the master runs back over the coupling position.
    pub const ROLLBACKLOCK: u32 = 0x0001_0000;
    /// On rollback the slave stops within one tick instead of along a 5th-order polynomial.
    pub const INSTANTSTOPONROLLBACK: u32 = 0x0002_0000;
    /// Prefer a phase of constant velocity: P5-P1-P5 at the given acceleration and
    /// deceleration.
    pub const PREFERCONSTVELO: u32 = 0x0010_0000;
    /// The master's acceleration at coupling is taken as 0.
    pub const IGNOREMASTERACC: u32 = 0x0020_0000;
    /// The slave's acceleration at coupling is taken as 0 (ours: the seed names the bit
    /// without a value).
    pub const IGNORESLAVEACC: u32 = 0x0040_0000;
    /// A failed check reports its own code instead of the general one (ours, as above).
    pub const DETAILEDERRORCODES: u32 = 0x0080_0000;
    /// Every operation bit.
    pub const OPERATIONS: u32 = 0x00F3_0000;
}

wire_enum! {
    /// `E_GearInSyncMode` ([`SawGearInCall::sync_mode`]).
    SawSyncMode {
        /// 0: the slave profile is a function of the master position.
        PositionBased = 0 => "position_based",
        /// 1: a time-based slave profile that keeps all slave limits (velocity sync only).
        TimeBased = 1 => "time_based",
    }
}

wire_enum! {
    /// [`SawGearInCall::target`]: what the slave synchronises on.
    SawSyncTarget {
        /// 0: velocity (MC_GearInVelo).
        Velocity = 0 => "velocity",
        /// 1: position (MC_GearInPos).
        Position = 1 => "position",
    }
}

/// MC_GearInVelo / MC_GearInPos for the slave given as `target`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct SawGearInCall {
    /// The master, its `gpAx` index.
    pub master: u32,
    /// Raw [`SawSyncTarget`].
    pub target: u32,
    /// Raw [`SawSyncMode`].
    pub sync_mode: u32,
    /// Check and operation bits ([`sync_mask`]).
    pub mask: u32,
    /// RatioDenominator (0 is refused).
    pub ratio_denominator: u32,
    /// 0: the master's set-point; 1: its actual values (an encoder master: at coupling, an
    /// acceleration below 2 x its scaling / cycle^2 counts as none, seed 001 chapter 3).
    pub master_source: u32,
    /// RatioNumerator (may be negative; 0 is refused).
    pub ratio_numerator: f64,
    /// MasterSyncPosition (position sync).
    pub master_sync_position: f64,
    /// SlaveSyncPosition (position sync).
    pub slave_sync_position: f64,
    /// Velocity limit of the synchronising phase; 0: the axis's own.
    pub velocity: f64,
    /// Acceleration limit; 0: the axis's own.
    pub acceleration: f64,
    /// Deceleration limit; 0: the axis's own.
    pub deceleration: f64,
    /// Jerk limit; 0: the axis's own.
    pub jerk: f64,
}

/// MC_GearOut for the slave given as `target`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct SawGearOutCall {
    /// Reserved, 0.
    pub reserved: u32,
}

/// The reply to the coupling and decoupling calls: 0 when accepted, else a raw
/// [`SawError`] or [`crate::enums::AxisError`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct SawReply {
    /// 0 when accepted.
    pub error_id: u32,
    /// An accepted coupling's command id in the slave's command book (0 otherwise): the
    /// block follows it there, so a new coupling of the slave by another block aborts it.
    pub command_id: u32,
}

/// Values of `MC_FlyingSawCharacValues` one part carries.
pub const SAW_CHARAC_PART: usize = 16;

/// Parts of MC_ReadFlyingSawCharacteristics: two for the 31 values, one for the organisation.
pub const SAW_CHARAC_PARTS: u32 = 3;

/// MC_ReadFlyingSawCharacteristics, one part: fields `16 * part + 1 ..` of the structure
/// (part 0: fields 1-16, part 1: fields 17-31), and part 2: the five organisation fields
/// ([`crate::calls::cam::TableOrganisation`], the reserved block left out).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct SawCharacCall {
    /// 0, 1 or 2 ([`SAW_CHARAC_PARTS`]).
    pub part: u32,
}

/// One part of the characteristic values of the last synchronising phase planned for the
/// slave.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct SawCharacReply {
    /// 0 when answered.
    pub error_id: u32,
    /// The part.
    pub part: u32,
    /// The number of the plan the values belong to (a read whose parts differ here read
    /// across a new command and starts again).
    pub plan: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// The values, in the structure's order; unused places 0.
    pub values: [f64; SAW_CHARAC_PART],
}

calls! { family "saw";
    /// [`SawGearInCall`]: MC_GearInVelo / MC_GearInPos.
    SAW_GEAR_IN = 40: SawGearInCall -> SawReply, command;
    /// [`SawGearOutCall`]: MC_GearOut.
    SAW_GEAR_OUT = 41: SawGearOutCall -> SawReply, command;
    /// [`SawCharacCall`]: MC_ReadFlyingSawCharacteristics, one part.
    SAW_CHARAC = 42: SawCharacCall -> SawCharacReply, read_only;
}

const _: () = assert!(core::mem::size_of::<SawGearInCall>() == 80);
const _: () = assert!(core::mem::size_of::<SawCharacReply>() == 144);
const _: () = assert!(core::mem::size_of::<SawCharacReply>() <= ACYCLIC_BODY_SIZE);
const _: () = assert!(sync_mask::CHECKS & sync_mask::OPERATIONS == 0);

#[cfg(test)]
mod tests {
    use super::{SawSyncMode, SawSyncTarget};

    #[test]
    fn the_sync_selectors_keep_their_numbers() {
        assert_eq!(SawSyncMode::PositionBased.raw(), 0);
        assert_eq!(
            SawSyncMode::from_name("time_based"),
            Some(SawSyncMode::TimeBased)
        );
        assert_eq!(SawSyncMode::TimeBased.raw(), 1);
        assert_eq!(SawSyncTarget::Velocity.raw(), 0);
        assert_eq!(SawSyncTarget::from_raw(1), Some(SawSyncTarget::Position));
        assert_eq!(SawSyncTarget::from_raw(2), None);
    }
}
