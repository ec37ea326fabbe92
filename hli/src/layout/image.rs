//! The whole image: segment header, channels, axes and FIFO groups.

use super::axis::HliAxis;
use super::channel::HliChannel;
use super::fifo::HliFifoGroupState;
use crate::hli_struct;

/// Channels the image holds.
pub const HLI_MAX_CHANNELS: usize = 12;
/// Axes the image holds.
pub const HLI_MAX_AXES: usize = 32;
/// FIFO axis groups the image holds.
pub const HLI_MAX_FIFO_GROUPS: usize = 8;

hli_struct! {
    /// Identity and liveness of a segment. The two heartbeats sit on their own cache lines so
    /// each side's increments do not disturb the other.
    ///
    /// ST path: `header`.
    #[st = "HLI_SEGMENT_HEADER", size = 192]
    pub struct HliSegmentHeader {
        /// [`crate::image::SEGMENT_MAGIC`].
        pub magic: u64 => [0, Cnc],
        /// [`crate::image::LAYOUT_VERSION`].
        pub layout_version: u32 => [8, Cnc],
        /// Size of this header in bytes.
        pub header_size: u32 => [12, Cnc],
        /// Hash of the symbol table (paths, offsets, sizes, types).
        pub layout_hash: u64 => [16, Cnc],
        /// Size of the whole image in bytes.
        pub image_size: u64 => [24, Cnc],
        /// Channels the CNC configured (at most 12).
        pub channel_count: u32 => [32, Cnc],
        /// Axes the CNC configured (at most 32).
        pub axis_count: u32 => [36, Cnc],
        /// Process id of the CNC that created the segment.
        pub cnc_pid: u32 => [40, Cnc],
        /// Raw [`crate::enums::SegmentState`].
        pub segment_state: u32 => [44, Cnc],
        /// Boot time of the CNC's process (ns since an arbitrary epoch) to tell pid reuse apart.
        pub cnc_start_stamp: u64 => [48, Cnc],
        /// The CNC's cycle in nanoseconds: the PLC's time base for noticing a silent CNC.
        pub cnc_cycle_ns: u32 => [56, Cnc],
        /// Bit 0: lockstep (the CNC ticks only after the PLC's cycle, so its ticks keep no
        /// clock and a silent CNC is given the lockstep patience).
        pub cnc_flags: u32 => [60, Cnc],
        /// Incremented by the CNC once per tick.
        pub cnc_heartbeat: u64 => [64, Cnc],
        /// Wall-clock time (ns since the Unix epoch) at which heartbeat 0 was due: the tick
        /// that wrote heartbeat N was due at `cnc_epoch_ns + N * cnc_cycle_ns` (lockstep: the
        /// machine's own time, not the clock's). 0 until the tick loop starts. For tools
        /// (the OPC UA server's source timestamps); the CNC never reads it.
        pub cnc_epoch_ns: u64 => [72, Cnc],
        /// 99th percentile of the ticks' start lateness so far, ns (real time; 0 in
        /// lockstep), refreshed every 1,024 ticks. For tools; the CNC never reads it.
        pub cnc_late_p99_ns: u32 => [80, Cnc],
        /// Largest tick start lateness so far, ns, refreshed with the p99.
        pub cnc_late_max_ns: u32 => [84, Cnc],
        /// Padding up to the next cache line.
        pub fill_up_2: [u64; 5] => [88, Cnc],
        /// Incremented by the PLC once per cycle.
        pub plc_heartbeat: u64 => [128, Plc],
        /// Process id of the attached PLC, 0 when none.
        pub plc_pid: u32 => [136, Plc],
        /// Padding.
        pub fill_up_3: u32 => [140, Plc],
        /// Padding up to the end of the cache line.
        pub fill_up_4: [u64; 6] => [144, Plc],
    }
}

hli_struct! {
    /// The complete HLI image as it lies in the shared segment.
    ///
    /// ST path: the image root (`header`, `gpCh[..]`, `gpAx[..]`, `gpFifo[..]`).
    #[st = "HLI_IMAGE", size = 24896]
    pub struct HliImage {
        /// Identity and heartbeats.
        pub header: HliSegmentHeader => [0, Parent],
        /// Channels, `gpCh[i]^`.
        pub gpCh: [HliChannel; HLI_MAX_CHANNELS] => [192, Parent],
        /// Axes, `gpAx[i]^`.
        pub gpAx: [HliAxis; HLI_MAX_AXES] => [13056, Parent],
        /// FIFO groups, `gpFifo[i]^`.
        pub gpFifo: [HliFifoGroupState; HLI_MAX_FIFO_GROUPS] => [24320, Parent],
    }
}
