//! The image's identity and its header as a CNC of this build writes it: the magic, the
//! layout version and size, the header's integrity checks ([`guard`]), and a heap-backed
//! image with a valid header for in-process runs and tests ([`heap_image`]). The shared
//! segment that holds an image between two processes is the transport's
//! (`hli_transport::segment`).

use crate::desc::PlaceExt;
use crate::enums::SegmentState;
use crate::layout::{HliImage, HliSegmentHeader};
use crate::raw::ImageMemory;
use crate::symbols::SymbolTable;
use core::mem::size_of;
use guard::CncTiming;

pub mod guard;

/// "HLI-SEG1" as a little-endian u64.
pub const SEGMENT_MAGIC: u64 = u64::from_le_bytes(*b"HLI-SEG1");
/// Bumped whenever the meaning of the image changes without its layout changing.
pub const LAYOUT_VERSION: u32 = 3;
/// Size of the image in bytes.
pub const IMAGE_SIZE: usize = size_of::<HliImage>();
/// Size of the header in bytes.
pub const HEADER_SIZE: usize = size_of::<HliSegmentHeader>();

/// What a peer expects the segment to be; both sides compare theirs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LayoutIdentity {
    /// [`LAYOUT_VERSION`].
    pub version: u32,
    /// [`SymbolTable::layout_hash`].
    pub hash: u64,
    /// Image size in bytes.
    pub size: u64,
}

impl LayoutIdentity {
    /// The identity of this build.
    pub fn current() -> Self {
        Self {
            version: LAYOUT_VERSION,
            hash: SymbolTable::global().layout_hash(),
            size: IMAGE_SIZE as u64,
        }
    }
}

/// The header a CNC of this build writes when it creates an image.
pub fn initial_header(
    channels: u32,
    axes: u32,
    state: SegmentState,
    start_stamp: u64,
    timing: CncTiming,
) -> HliSegmentHeader {
    let identity = LayoutIdentity::current();
    HliSegmentHeader {
        magic: SEGMENT_MAGIC,
        layout_version: identity.version,
        header_size: HEADER_SIZE as u32,
        layout_hash: identity.hash,
        image_size: identity.size,
        channel_count: channels,
        axis_count: axes,
        cnc_pid: std::process::id(),
        segment_state: state.raw(),
        cnc_start_stamp: start_stamp,
        cnc_cycle_ns: timing.cycle_ns,
        cnc_flags: timing.flags(),
        ..bytemuck::Zeroable::zeroed()
    }
}

/// The word the PLC sleeps on for a tick with `--rt-wake futex`, and the CNC wakes: the low
/// 32 bits of the CNC's heartbeat (changed by every tick), in the image at the heartbeat's own
/// offset on a little-endian machine.
pub fn cnc_heartbeat_word(memory: &ImageMemory) -> &core::sync::atomic::AtomicU32 {
    memory
        .place::<u32>(core::mem::offset_of!(HliSegmentHeader, cnc_heartbeat))
        .atomic()
}

#[cfg(not(target_endian = "little"))]
compile_error!("the heartbeat's low word is at its offset on a little-endian machine only");

/// A heap-backed image with a valid header, for in-process mode and unit tests.
pub fn heap_image(channels: u32, axes: u32) -> ImageMemory {
    let memory = ImageMemory::heap(IMAGE_SIZE);
    memory.place::<HliSegmentHeader>(0).write(&initial_header(
        channels,
        axes,
        SegmentState::Ready,
        0,
        CncTiming::default(),
    ));
    write_plc_defaults(&memory, channels);
    memory
}

/// The PLC-written values whose zero would not be a safe default: each channel's override
/// starts at 100 % ([`crate::views::DEFAULT_PATH_OVERRIDE`]).
pub fn write_plc_defaults(memory: &ImageMemory, channels: u32) {
    let view = crate::views::PlcView::new(memory);
    for channel in 0..channels as usize {
        let _ = view.set_path_override(channel, crate::views::DEFAULT_PATH_OVERRIDE);
    }
}

const _: () = assert!(IMAGE_SIZE.is_multiple_of(8));
