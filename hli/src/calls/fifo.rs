//! The FIFO group's calls (seed 002, chapter 7): the one-frame commands over the acyclic
//! service (`FiFoGetDimension`, `FiFoGroupIntegrate`, `FiFoGroupDisintegrate`, `FiFoStart`,
//! `FiFoStop`, `FiFoSetChannelOverride`, and the parameters a PLC may set), and the row
//! blocks of `FiFoWrite`/`FiFoOverwrite`, which travel in the bulk slots of the call mailbox
//! (`hli_transport::rpc::mailbox`): a header plus up to 8192 `f64` the PLC writes in place into shared
//! memory, answered with the same [`FifoReply`].
//!
//! Every call addresses its group by index (`target`, 0-based, `gpFifo[target]^`); axes are
//! addressed by their `gpAx` index as in the other calls; group positions count from 1 as in
//! the seed.

use crate::calls::CallKind;
use crate::enums::{hli_enum, wire_enum};
use crate::wire::BulkHeader;
use bytemuck::{Pod, Zeroable};

hli_enum! {
    /// Why the FIFO engine refused a call or ended a job (seed 002 gives no numbers: these
    /// are ours). A refused call leaves the queued rows and the group as they were.
    FifoError: u32, "FifoError" {
        /// The group index is not a configured FIFO group.
        NoSuchGroup = 0x4300,
        /// The axis is not an axis of the machine (channel axes are refused as coupled: they
        /// belong to their channel).
        NoSuchAxis = 0x4301,
        /// The group position is outside 1..=N.
        GroupPosition = 0x4302,
        /// Another axis holds that group position.
        PositionTaken = 0x4303,
        /// The axis is in a FIFO group already.
        AxisInGroup = 0x4304,
        /// The axis is coupled to another engine (cam, gear, saw).
        AxisCoupled = 0x4305,
        /// The axis moves: only a standing axis joins a group.
        AxisMoving = 0x4306,
        /// FiFoStart with fewer than N axes integrated.
        GroupIncomplete = 0x4307,
        /// FiFoStart on an empty FIFO.
        Empty = 0x4308,
        /// FiFoStart: the first row is not where the axes stand.
        StartMismatch = 0x4309,
        /// The group runs: integrate, disintegrate, start and parameters wait for Idle.
        Running = 0x430A,
        /// The block does not fit the free rows; nothing was queued (offer it again).
        Full = 0x430B,
        /// The block's column count is not the group's dimension N.
        Columns = 0x430C,
        /// A value of the block is NaN or infinite (its row and column in the reply).
        NonFinite = 0x430D,
        /// A block without rows, or larger than one block holds.
        BlockSize = 0x430E,
        /// FiFoStop was given: no override change and no rows until the job has ended.
        Stopping = 0x430F,
        /// An override above 100 %.
        Override = 0x4310,
        /// A parameter out of range (T_f <= 0, T0 <= 0, an unknown override type).
        Parameter = 0x4311,
        /// An axis of the running group faulted (following error, drive); the job ended.
        AxisFault = 0x4312,
    }
}

/// Values (rows x columns) one row block may carry: 64 KiB of `f64`, the buffer size of the
/// seed's sample program.
pub const FIFO_BLOCK_VALUES: usize = crate::wire::BULK_MAX_VALUES;

/// Axes a FIFO group may have.
pub const FIFO_MAX_DIMENSION: u32 = 16;

/// Rows a FIFO may hold.
pub const FIFO_MAX_ROWS: u32 = 1 << 20;

wire_enum! {
    /// [`FifoParametersCall::override_type`]: how the override follows a new value.
    FifoOverrideType {
        /// 0: the override changes at once.
        Instant = 0 => "instant",
        /// 1: the override follows a PT-2 lag (damping 1.001).
        Pt2 = 1 => "pt2",
    }
}

/// The reply to every FIFO call and row block: 0 when accepted, else a raw
/// [`FifoError`] or [`crate::enums::AxisError`]; and the FIFO's state after it.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct FifoReply {
    /// 0 when accepted.
    pub error_id: u32,
    /// Raw [`crate::enums::FifoGroupState`] after the call.
    pub group_state: i32,
    /// Rows queued after the call.
    pub entries: u32,
    /// Rows a block may bring now.
    pub free: u32,
    /// Dimension N (FiFoGetDimension: iNoOfAxes).
    pub dimension: u32,
    /// Length Z (FiFoGetDimension: iNoOfFifoEntries).
    pub capacity: u32,
    /// A refused block: the row (0-based) of the first bad value; rows accepted otherwise.
    pub row: u32,
    /// A refused block: the column of the first bad value.
    pub column: u32,
}

/// FiFoGetDimension.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct FifoDimensionCall {
    /// Reserved, 0.
    pub reserved: u32,
}

/// FiFoGroupIntegrate: a standing single axis joins the group at a position.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct FifoIntegrateCall {
    /// The axis, its `gpAx` index.
    pub axis: u32,
    /// Its column in the rows, 1..=N.
    pub group_position: u32,
}

/// FiFoGroupDisintegrate: every axis leaves the group and is a free PTP axis again.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct FifoDisintegrateCall {
    /// Reserved, 0.
    pub reserved: u32,
}

/// FiFoStart.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct FifoStartCall {
    /// Reserved, 0.
    pub reserved: u32,
}

/// FiFoStop: the override goes to 0 (with the group's override type); then the job ends,
/// the rows still queued are dropped and the group is Idle with its axes standing.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct FifoStopCall {
    /// Reserved, 0.
    pub reserved: u32,
}

/// FiFoSetChannelOverride.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct FifoOverrideCall {
    /// Override, ppm (1,000,000 = 100 %; at most 100 %).
    pub override_ppm: u32,
}

/// The group's parameters a PLC may set while the group is not running (the rest, N and Z,
/// is configuration).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct FifoParametersCall {
    /// FIFO cycle T_f, s (> 0).
    pub fifo_cycle_s: f64,
    /// PT-2 time constant T0, s (> 0; used by [`FifoOverrideType::Pt2`]).
    pub pt2_t0_s: f64,
    /// Raw [`FifoOverrideType`].
    pub override_type: u32,
    /// Reserved, 0.
    pub reserved: u32,
}

/// FiFoWrite as a bulk call: its rows travel as the payload of the bulk service under a
/// [`BulkHeader`] (target: the group, columns: the group's N, rows), not in a frame; this
/// body is only the call's declaration ([`rows_header`] makes the header).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct FifoWriteRowsCall {
    /// Reserved, 0.
    pub reserved: u32,
}

/// FiFoOverwrite as a bulk call (replaces the rows queued behind the pair in use), as
/// [`FifoWriteRowsCall`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct FifoOverwriteRowsCall {
    /// Reserved, 0.
    pub reserved: u32,
}

/// The bulk header of a row block of `rows x columns` values for `group`: FiFoOverwrite
/// when `overwrite`, else FiFoWrite.
pub fn rows_header(group: u32, columns: u32, rows: u32, overwrite: bool) -> BulkHeader {
    let kind = match overwrite {
        true => CallKind::FIFO_OVERWRITE_ROWS,
        false => CallKind::FIFO_WRITE_ROWS,
    };
    BulkHeader {
        kind: kind.raw(),
        target: group,
        columns,
        rows,
    }
}

calls! { family "fifo";
    /// [`FifoDimensionCall`]: FiFoGetDimension.
    FIFO_DIMENSION = 30: FifoDimensionCall -> FifoReply, read_only;
    /// [`FifoIntegrateCall`]: FiFoGroupIntegrate.
    FIFO_INTEGRATE = 31: FifoIntegrateCall -> FifoReply, command;
    /// [`FifoDisintegrateCall`]: FiFoGroupDisintegrate.
    FIFO_DISINTEGRATE = 32: FifoDisintegrateCall -> FifoReply, command;
    /// [`FifoStartCall`]: FiFoStart.
    FIFO_START = 33: FifoStartCall -> FifoReply, command;
    /// [`FifoStopCall`]: FiFoStop.
    FIFO_STOP = 34: FifoStopCall -> FifoReply, command;
    /// [`FifoOverrideCall`]: FiFoSetChannelOverride.
    FIFO_OVERRIDE = 35: FifoOverrideCall -> FifoReply, command;
    /// [`FifoParametersCall`]: the group's parameters a PLC may set.
    FIFO_PARAMETERS = 36: FifoParametersCall -> FifoReply, command;
    /// [`FifoWriteRowsCall`]: FiFoWrite, a bulk call (its rows in shared memory).
    FIFO_WRITE_ROWS = 37: FifoWriteRowsCall -> FifoReply, bulk;
    /// [`FifoOverwriteRowsCall`]: FiFoOverwrite, a bulk call.
    FIFO_OVERWRITE_ROWS = 38: FifoOverwriteRowsCall -> FifoReply, bulk;
}

const _: () = assert!(core::mem::size_of::<FifoReply>() == 32);

#[cfg(test)]
mod tests {
    use super::FifoOverrideType;

    #[test]
    fn the_override_types_keep_their_numbers() {
        assert_eq!(
            FifoOverrideType::from_name("instant").map(FifoOverrideType::raw),
            Some(0)
        );
        assert_eq!(
            FifoOverrideType::from_name("PT2").map(FifoOverrideType::raw),
            Some(1)
        );
        assert_eq!(FifoOverrideType::from_raw(2), None);
    }
}
