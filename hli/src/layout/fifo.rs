//! Status of a FIFO axis group: `gpFifo[group_idx]^` (our own unit; seed 002 names the
//! values a PLC needs to keep a FIFO filled, not their layout).

use crate::hli_struct;

/// [`HliFifoGroupState::flags_r`]: the FIFO ran dry while the axes moved; they hold the last
/// row's positions until rows come (the group does not abort).
pub const FIFO_FLAG_UNDERRUN: u32 = 1;
/// [`HliFifoGroupState::flags_r`]: every queued row is executed and the content brought the
/// axes to rest (the normal end of a job).
pub const FIFO_FLAG_AT_END: u32 = 2;
/// [`HliFifoGroupState::flags_r`]: the override has reached its target (a PT-2 change has
/// decayed and been cut off).
pub const FIFO_FLAG_OVERRIDE_SETTLED: u32 = 4;

/// Override unit of the FIFO calls and this unit: parts per million (1,000,000 = 100 %).
pub const FIFO_OVERRIDE_FULL: u32 = 1_000_000;

hli_struct! {
    /// Status the CNC publishes for one FIFO axis group every tick.
    ///
    /// ST path: `gpFifo[i]^`.
    #[st = "HLI_FIFO_GROUP_STATE", size = 72]
    pub struct HliFifoGroupState {
        /// Raw [`crate::enums::FifoGroupState`].
        pub group_state_r: i32 => [0, Cnc],
        /// Configured dimension N (axes of the group).
        pub dimension_r: u32 => [4, Cnc],
        /// Axes integrated so far (a group starts with all N).
        pub axis_count_r: u32 => [8, Cnc],
        /// Configured length Z (rows the FIFO holds).
        pub capacity_r: u32 => [12, Cnc],
        /// Rows queued: the pair in use and every row behind it (the fill level).
        pub entries_r: u32 => [16, Cnc],
        /// Rows a write may bring now (`capacity_r - entries_r`).
        pub free_r: u32 => [20, Cnc],
        /// Raw [`crate::calls::fifo::FifoError`] of a fault that ended the job (an axis lost), 0
        /// when none.
        pub error_id_r: u32 => [24, Cnc],
        /// `FIFO_FLAG_*` bits.
        pub flags_r: u32 => [28, Cnc],
        /// Override in effect, ppm ([`FIFO_OVERRIDE_FULL`] = 100 %).
        pub override_r: u32 => [32, Cnc],
        /// Override the group moves towards, ppm.
        pub override_target_r: u32 => [36, Cnc],
        /// Rows accepted since the job began (the group left Idle).
        pub rows_written_r: u64 => [40, Cnc],
        /// Rows whose time has passed since the job began.
        pub rows_consumed_r: u64 => [48, Cnc],
        /// Ticks spent in underrun since the job began.
        pub underrun_ticks_r: u32 => [56, Cnc],
        /// Padding.
        pub fill_up_1: u32 => [60, Cnc],
        /// Job time on the FIFO's time base, s (row k is due at k x T_f).
        pub job_time_r: f64 => [64, Cnc],
    }
}
