//! What the CNC announces in its header for tools only (the OPC UA server's source
//! timestamps and machine figures): the CNC never reads it back.

use super::CncSegment;
use core::mem::offset_of;
use hli::layout::HliSegmentHeader;

impl CncSegment {
    /// Announces when heartbeat 0 was due, wall clock in ns since the Unix epoch
    /// ([`HliSegmentHeader::cnc_epoch_ns`]).
    pub fn publish_epoch(&self, epoch_ns: u64) {
        self.header()
            .field::<u64>(offset_of!(HliSegmentHeader, cnc_epoch_ns))
            .store_release(epoch_ns);
    }

    /// Announces the ticks' start lateness so far: p99 and max, ns (saturated to `u32`).
    pub fn publish_lateness(&self, p99_ns: u64, max_ns: u64) {
        let header = self.header();
        for (offset, ns) in [
            (offset_of!(HliSegmentHeader, cnc_late_p99_ns), p99_ns),
            (offset_of!(HliSegmentHeader, cnc_late_max_ns), max_ns),
        ] {
            header
                .field::<u32>(offset)
                .store_release(u32::try_from(ns).unwrap_or(u32::MAX));
        }
    }
}
