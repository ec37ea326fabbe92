//! Status of a FIFO axis group: `gpFifo[group_idx]^`.

use crate::hli_struct;

hli_struct! {
    /// Status the CNC publishes for one FIFO axis group every tick.
    ///
    /// ST path: `gpFifo[i]^`.
    #[st = "HLI_FIFO_GROUP_STATE", size = 40]
    pub struct HliFifoGroupState {
        /// Raw [`crate::enums::FifoGroupState`].
        pub group_state_r: i32 => [0, Cnc],
        /// Axes in the group.
        pub axis_count_r: u32 => [4, Cnc],
        /// Rows currently buffered.
        pub entries_r: u32 => [8, Cnc],
        /// Buffer capacity in rows.
        pub capacity_r: u32 => [12, Cnc],
        /// Free rows.
        pub free_r: u32 => [16, Cnc],
        /// Error code, 0 when none.
        pub error_id_r: u32 => [20, Cnc],
        /// Rows consumed since the group was started.
        pub rows_consumed_r: u64 => [24, Cnc],
        /// Override in effect, 0.1 %.
        pub override_r: u32 => [32, Cnc],
        /// Padding.
        pub fill_up_1: i32 => [36, Cnc],
    }
}
