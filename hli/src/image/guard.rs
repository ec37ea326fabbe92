//! The header's integrity: both sides keep their own copy of what the CNC wrote into the
//! header when it created the segment and compare the segment against it, the CNC after every
//! tick, the PLC after every wake-up. A field that changed was written by someone who must
//! not: the machine stops, and neither side takes it for an orderly close.
//!
//! A fault is a small `Copy` value (field, expected and found value), rendered to text only
//! when it is reported, outside the cycle.

use crate::enums::SegmentState;
use crate::layout::HliSegmentHeader;

/// Bit of [`HliSegmentHeader::cnc_flags`]: the CNC runs in lockstep with its PLC.
pub const FLAG_LOCKSTEP: u32 = 1;

/// Shortest CNC cycle a header may announce, ns.
pub const MIN_CYCLE_NS: u32 = 1_000;
/// Longest CNC cycle a header may announce, ns.
pub const MAX_CYCLE_NS: u32 = 1_000_000_000;

/// How the CNC ticks, announced in the header for the PLC's watchdog.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CncTiming {
    /// The cycle, ns ([`MIN_CYCLE_NS`]..=[`MAX_CYCLE_NS`]).
    pub cycle_ns: u32,
    /// Lockstep: ticks follow the PLC's cycles, not a clock.
    pub lockstep: bool,
}

impl Default for CncTiming {
    /// A real-time CNC at 1 ms.
    fn default() -> Self {
        Self {
            cycle_ns: 1_000_000,
            lockstep: false,
        }
    }
}

impl CncTiming {
    /// A CNC in lockstep with its PLC at a nominal 1 ms.
    pub fn lockstep() -> Self {
        Self {
            lockstep: true,
            ..Self::default()
        }
    }

    /// The cycle as a duration.
    pub fn cycle(&self) -> core::time::Duration {
        core::time::Duration::from_nanos(u64::from(self.cycle_ns))
    }

    /// The header's `cnc_flags` for this timing.
    pub fn flags(&self) -> u32 {
        if self.lockstep {
            FLAG_LOCKSTEP
        } else {
            0
        }
    }

    /// The timing a header announces, `None` when the cycle is out of range or unknown flags
    /// are set.
    pub fn of(header: &HliSegmentHeader) -> Option<Self> {
        let cycle_ok = (MIN_CYCLE_NS..=MAX_CYCLE_NS).contains(&header.cnc_cycle_ns);
        let flags_ok = header.cnc_flags & !FLAG_LOCKSTEP == 0;
        (cycle_ok && flags_ok).then_some(Self {
            cycle_ns: header.cnc_cycle_ns,
            lockstep: header.cnc_flags & FLAG_LOCKSTEP != 0,
        })
    }
}

/// A CNC-owned header field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeaderField {
    /// `magic`.
    Magic,
    /// `layout_version`.
    LayoutVersion,
    /// `header_size`.
    HeaderSize,
    /// `layout_hash`.
    LayoutHash,
    /// `image_size`.
    ImageSize,
    /// `channel_count`.
    ChannelCount,
    /// `axis_count`.
    AxisCount,
    /// `cnc_pid`.
    CncPid,
    /// `segment_state`.
    SegmentState,
    /// `cnc_start_stamp`.
    CncStartStamp,
    /// `cnc_cycle_ns`.
    CncCycle,
    /// `cnc_flags`.
    CncFlags,
    /// `cnc_heartbeat` (checked by the CNC, which knows the value it wrote).
    CncHeartbeat,
}

impl HeaderField {
    /// The field's ST path.
    pub fn path(self) -> &'static str {
        match self {
            HeaderField::Magic => "header.magic",
            HeaderField::LayoutVersion => "header.layout_version",
            HeaderField::HeaderSize => "header.header_size",
            HeaderField::LayoutHash => "header.layout_hash",
            HeaderField::ImageSize => "header.image_size",
            HeaderField::ChannelCount => "header.channel_count",
            HeaderField::AxisCount => "header.axis_count",
            HeaderField::CncPid => "header.cnc_pid",
            HeaderField::SegmentState => "header.segment_state",
            HeaderField::CncStartStamp => "header.cnc_start_stamp",
            HeaderField::CncCycle => "header.cnc_cycle_ns",
            HeaderField::CncFlags => "header.cnc_flags",
            HeaderField::CncHeartbeat => "header.cnc_heartbeat",
        }
    }
}

/// A CNC-owned header field found changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeaderFault {
    /// Which.
    pub field: HeaderField,
    /// What the CNC wrote.
    pub expected: u64,
    /// What the segment holds now.
    pub found: u64,
}

impl core::fmt::Display for HeaderFault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "segment header corrupted: {} is 0x{:X} where the CNC wrote 0x{:X}",
            self.field.path(),
            self.found,
            self.expected
        )
    }
}

/// The identity fields of the header: everything the CNC writes once at creation.
fn identity(h: &HliSegmentHeader) -> [(HeaderField, u64); 11] {
    [
        (HeaderField::Magic, h.magic),
        (HeaderField::LayoutVersion, h.layout_version.into()),
        (HeaderField::HeaderSize, h.header_size.into()),
        (HeaderField::LayoutHash, h.layout_hash),
        (HeaderField::ImageSize, h.image_size),
        (HeaderField::ChannelCount, h.channel_count.into()),
        (HeaderField::AxisCount, h.axis_count.into()),
        (HeaderField::CncPid, h.cnc_pid.into()),
        (HeaderField::CncStartStamp, h.cnc_start_stamp),
        (HeaderField::CncCycle, h.cnc_cycle_ns.into()),
        (HeaderField::CncFlags, h.cnc_flags.into()),
    ]
}

/// The first identity field of `found` that differs from `expected`.
pub fn compare_identity(
    expected: &HliSegmentHeader,
    found: &HliSegmentHeader,
) -> Result<(), HeaderFault> {
    for ((field, want), (_, got)) in identity(expected).into_iter().zip(identity(found)) {
        if want != got {
            return Err(HeaderFault {
                field,
                expected: want,
                found: got,
            });
        }
    }
    Ok(())
}

/// The segment state of `found` where it is one the other side may write next to `expected`
/// (the CNC only ever writes Ready, then Closed).
pub fn check_state(found: u32, allowed: &[SegmentState]) -> Result<SegmentState, HeaderFault> {
    match SegmentState::decode(found) {
        Ok(state) if allowed.contains(&state) => Ok(state),
        _ => Err(HeaderFault {
            field: HeaderField::SegmentState,
            expected: u64::from(SegmentState::Ready.raw()),
            found: u64::from(found),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> HliSegmentHeader {
        super::super::initial_header(2, 3, SegmentState::Ready, 77, CncTiming::lockstep())
    }

    #[test]
    fn every_identity_field_is_compared() {
        let expected = header();
        assert_eq!(compare_identity(&expected, &expected), Ok(()));
        let n = identity(&expected).len();
        for i in 0..n {
            let mut found = expected;
            let (field, value) = identity(&expected)[i];
            set(&mut found, field, value ^ 1);
            let fault = compare_identity(&expected, &found).unwrap_err();
            assert_eq!(fault.field, field);
            assert_eq!((fault.expected, fault.found), (value, value ^ 1));
        }
    }

    fn set(h: &mut HliSegmentHeader, field: HeaderField, v: u64) {
        match field {
            HeaderField::Magic => h.magic = v,
            HeaderField::LayoutVersion => h.layout_version = v as u32,
            HeaderField::HeaderSize => h.header_size = v as u32,
            HeaderField::LayoutHash => h.layout_hash = v,
            HeaderField::ImageSize => h.image_size = v,
            HeaderField::ChannelCount => h.channel_count = v as u32,
            HeaderField::AxisCount => h.axis_count = v as u32,
            HeaderField::CncPid => h.cnc_pid = v as u32,
            HeaderField::CncStartStamp => h.cnc_start_stamp = v,
            HeaderField::CncCycle => h.cnc_cycle_ns = v as u32,
            HeaderField::CncFlags => h.cnc_flags = v as u32,
            HeaderField::SegmentState | HeaderField::CncHeartbeat => unreachable!(),
        }
    }

    #[test]
    fn states_outside_the_allowed_ones_are_faults() {
        let both = [SegmentState::Ready, SegmentState::Closed];
        assert_eq!(check_state(1, &both), Ok(SegmentState::Ready));
        assert_eq!(check_state(2, &both), Ok(SegmentState::Closed));
        for raw in [0, 3, u32::MAX] {
            let fault = check_state(raw, &both).unwrap_err();
            assert_eq!(fault.field, HeaderField::SegmentState);
            assert_eq!(fault.found, u64::from(raw));
        }
        assert!(check_state(2, &[SegmentState::Ready]).is_err());
    }

    #[test]
    fn timing_is_validated() {
        let mut h = header();
        assert_eq!(CncTiming::of(&h), Some(CncTiming::lockstep()));
        h.cnc_cycle_ns = 0;
        assert_eq!(CncTiming::of(&h), None);
        h = header();
        h.cnc_flags = 0x80;
        assert_eq!(CncTiming::of(&h), None);
        let fault = HeaderFault {
            field: HeaderField::Magic,
            expected: 1,
            found: 0xFF,
        };
        assert_eq!(
            fault.to_string(),
            "segment header corrupted: header.magic is 0xFF where the CNC wrote 0x1"
        );
    }
}
