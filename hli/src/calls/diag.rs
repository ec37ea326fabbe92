//! The dynamic-CS diagnosis read while the CNC runs: one history entry or one log event per
//! call, addressed by its sequence number, for the channel given as `target` (its `gpCh`
//! index). A tool reads the history and the log entry by entry (chunked: a call body holds
//! one entry) and renders the listing itself, so the CNC answers from its rings without
//! formatting or allocating in its cycle.
//!
//! Sequence numbers count every entry the channel ever recorded; the CNC keeps the last
//! `kept` of them. Every reply names the window (`recorded`, `kept`): a reader asks for
//! sequence 0, gets the oldest kept entry (the reply's `sequence` says which) and reads on
//! from there. A sequence not recorded yet gets a reply with `present` 0; a channel that
//! does not exist is refused with `InvalidTarget`.

use bytemuck::{Pod, Zeroable};

/// Read history entry `sequence` (or the oldest kept one, if it is older).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct DynCsHistoryReadCall {
    /// Sequence number wanted.
    pub sequence: u64,
}

/// Read log event `sequence` (or the oldest kept one, if it is older).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct DynCsLogReadCall {
    /// Sequence number wanted.
    pub sequence: u64,
}

/// Where a reply's entry lies: its sequence number and the window the CNC keeps.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct DiagWindow {
    /// Sequence number of the entry in this reply (`recorded` when there is none yet).
    pub sequence: u64,
    /// Entries recorded so far: the next one gets this number.
    pub recorded: u64,
    /// Entries the CNC keeps (the last `kept` of `recorded`).
    pub kept: u32,
    /// 1 when the reply holds an entry, 0 when the channel has none at or after `sequence`.
    pub present: u32,
}

/// One history entry: what went into and out of the dynamic CS in one tick (HLI units:
/// 0.1 um, 0.0001 degree).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct DynCsHistoryReply {
    /// Which entry.
    pub window: DiagWindow,
    /// The tick.
    pub tick: u64,
    /// Raw `HLI_DYN_CS_STATE`.
    pub state: i32,
    /// Reserved, 0.
    pub reserved: u32,
    /// Pose X..C before the dynamic CS.
    pub input: [i64; 6],
    /// Compensation translation.
    pub translation: [i64; 3],
    /// Compensation rotation (Z-Y-X).
    pub rotation: [i64; 3],
    /// Pose X..C after the dynamic CS.
    pub output: [i64; 6],
}

/// Log event kinds ([`DynCsLogReply::kind`]).
pub mod log_kind {
    /// Switched on.
    pub const ON: u32 = 1;
    /// The values of a switch-on.
    pub const ON_VALUES: u32 = 2;
    /// Coupled completely.
    pub const ACTIVE: u32 = 3;
    /// Switched off.
    pub const OFF: u32 = 4;
    /// Released completely.
    pub const INACTIVE: u32 = 5;
    /// The master froze.
    pub const MASTER_FROZEN: u32 = 6;
    /// The master resumed.
    pub const MASTER_RESUMED: u32 = 7;
    /// An error (state ERROR).
    pub const ERROR: u32 = 8;
    /// A PLC request refused.
    pub const REFUSED: u32 = 9;
    /// A program (re)started: `flags` bit 0 set on its second line.
    pub const RESTART: u32 = 10;
    /// The axes began to catch up with a step (`flags` FINISHED: landed); `frame[0]` the
    /// lag in mm, `frame[1]` in degrees.
    pub const CATCH_UP: u32 = 11;
}

/// [`DynCsLogReply::flags`] bits.
pub mod log_flags {
    /// WAIT.
    pub const WAIT: u32 = 1;
    /// RELATIVE.
    pub const RELATIVE: u32 = 2;
    /// SIMU.
    pub const SIMU: u32 = 4;
    /// The restart finished.
    pub const FINISHED: u32 = 8;
}

/// One log event, its fields as the kind uses them.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct DynCsLogReply {
    /// Which entry.
    pub window: DiagWindow,
    /// The tick.
    pub tick: u64,
    /// [`log_kind`].
    pub kind: u32,
    /// Master: 0 the PLC, n channel n (1-based, as `CH=n`).
    pub source: u32,
    /// Filter ticks.
    pub filter_ticks: u32,
    /// [`log_flags`].
    pub flags: u32,
    /// ERROR / REFUSED: the error's code (the CNC's numbering, see its `TrackError`).
    pub error: u32,
    /// ERROR / REFUSED: the error's value (a channel number, a parameter's code).
    pub error_value: u32,
    /// Positions X..C before the dynamic CS.
    pub axes: [i64; 6],
    /// Master frame or applied compensation X..C (mm, degree).
    pub frame: [f64; 6],
}

calls! { family "diag";
    /// [`DynCsHistoryReadCall`]: one entry of a channel's dynamic-CS history.
    DYN_CS_HISTORY_READ = 60: DynCsHistoryReadCall -> DynCsHistoryReply, read_only;
    /// [`DynCsLogReadCall`]: one event of a channel's dynamic-CS log.
    DYN_CS_LOG_READ = 61: DynCsLogReadCall -> DynCsLogReply, read_only;
}

const _: () = assert!(core::mem::size_of::<DynCsHistoryReply>() == 184);
const _: () = assert!(core::mem::size_of::<DynCsLogReply>() == 152);
const _: () = assert!(core::mem::size_of::<DynCsLogReply>() <= crate::wire::ACYCLIC_BODY_SIZE);
const _: () = assert!(core::mem::size_of::<DynCsHistoryReply>() <= crate::wire::ACYCLIC_BODY_SIZE);
