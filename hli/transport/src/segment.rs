//! The shared segment: one POSIX shared-memory object per CNC instance, created by the CNC and
//! opened read-write by the PLC, through iceoryx2's own shared-memory layer
//! (`iceoryx2-bb-posix`). Owner-only permissions.
//!
//! ```text
//!  CNC start ──create exclusive──┬─ ok ───────────────────────────────► header Initialising
//!                                └─ exists ─ owner process alive? ─ yes ─► Err(InUse)
//!                                                       │ no (crashed)
//!                                                       └─ remove, create ─► (stale replaced)
//!  header complete ─► Ready ─► PLC may attach (magic, version, hash, size checked)
//!  CNC drop ─► Closed, object unlinked
//! ```

use core::mem::offset_of;
use hli::desc::PlaceExt;
use hli::enums::SegmentState;
use hli::layout::{HliImage, HliSegmentHeader, HLI_MAX_AXES, HLI_MAX_CHANNELS};
use hli::raw::{ImageMemory, Place};
use iceoryx2_bb_posix::shared_memory::{
    AccessMode, CreationMode, Permission, SharedMemory, SharedMemoryBuilder,
    SharedMemoryCreationError,
};
use iceoryx2_bb_system_types::file_name::{FileName, SemanticString};
use std::sync::atomic::{AtomicU64, Ordering};

mod announce;
mod liveness;
mod process;
mod reset;
pub use hli::image::guard::{
    CncTiming, HeaderFault, HeaderField, FLAG_LOCKSTEP, MAX_CYCLE_NS, MIN_CYCLE_NS,
};
use hli::image::{guard, write_plc_defaults};
pub use hli::image::{
    heap_image, initial_header, LayoutIdentity, HEADER_SIZE, IMAGE_SIZE, LAYOUT_VERSION,
    SEGMENT_MAGIC,
};
pub use liveness::{HeartbeatWatch, PeerLiveness};
pub(crate) use process::process_start_stamp;
use process::{check_owner, start_stamp_at, stat_path};

/// Why a segment could not be created.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CreateError {
    /// The instance name is not usable as a shared-memory name.
    #[error("invalid instance name {name:?}: use 1..=48 characters of [A-Za-z0-9_.-]")]
    InvalidName {
        /// The name given.
        name: String,
    },
    /// Channel or axis count above the image's capacity.
    #[error("{what} count {requested} exceeds the image capacity {capacity}")]
    TooMany {
        /// "channel" or "axis".
        what: &'static str,
        /// Requested count.
        requested: u32,
        /// Capacity.
        capacity: u32,
    },
    /// A live CNC already owns this instance.
    #[error("segment {name} is owned by the running CNC process {pid}")]
    InUse {
        /// Segment name.
        name: String,
        /// The owner's process id.
        pid: u32,
    },
    /// The operating system refused.
    #[error("creating segment {name} failed: {reason}")]
    Os {
        /// Segment name.
        name: String,
        /// iceoryx2's error.
        reason: String,
    },
}

/// Why attaching to a segment failed. Every mismatch names the CNC's and the PLC's value.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum AttachError {
    /// The instance name is not usable as a shared-memory name.
    #[error("invalid instance name {name:?}: use 1..=48 characters of [A-Za-z0-9_.-]")]
    InvalidName {
        /// The name given.
        name: String,
    },
    /// No segment of that name.
    #[error("no segment {name}: is the CNC running?")]
    NotFound {
        /// Segment name.
        name: String,
    },
    /// The object belongs to another user: its CNC is not ours to attach to.
    #[error("segment {name} belongs to user {owner}, not to this process's user {me}")]
    ForeignOwner {
        /// Segment name.
        name: String,
        /// The file's owner.
        owner: u32,
        /// This process's effective user.
        me: u32,
    },
    /// The object is smaller than the layout needs.
    #[error("segment {name} is truncated: {found} bytes, the layout needs {expected}")]
    Truncated {
        /// Segment name.
        name: String,
        /// Bytes this build needs.
        expected: u64,
        /// Bytes found.
        found: u64,
    },
    /// Not an HLI segment.
    #[error("segment {name} has magic 0x{cnc:016X}, expected 0x{plc:016X}")]
    BadMagic {
        /// Segment name.
        name: String,
        /// Found in the segment.
        cnc: u64,
        /// Expected by this build.
        plc: u64,
    },
    /// Layout version differs.
    #[error("layout version mismatch: CNC has {cnc}, PLC has {plc}")]
    VersionMismatch {
        /// The segment's.
        cnc: u32,
        /// This build's.
        plc: u32,
    },
    /// Layout hash differs (the structs differ).
    #[error("layout hash mismatch: CNC has 0x{cnc:016X}, PLC has 0x{plc:016X}")]
    LayoutMismatch {
        /// The segment's.
        cnc: u64,
        /// This build's.
        plc: u64,
    },
    /// Image size differs.
    #[error("image size mismatch: CNC has {cnc} bytes, PLC has {plc} bytes")]
    SizeMismatch {
        /// The segment's.
        cnc: u64,
        /// This build's.
        plc: u64,
    },
    /// Header counts outside the capacity.
    #[error("segment header claims {channels} channels / {axes} axes (capacity 12 / 32)")]
    InvalidCounts {
        /// Claimed channels.
        channels: u32,
        /// Claimed axes.
        axes: u32,
    },
    /// The header announces a cycle or flags this build does not know.
    #[error("segment header announces a CNC cycle of {cycle_ns} ns with flags 0x{flags:X} (cycle 1 us..1 s, flags 0x1)")]
    InvalidTiming {
        /// Announced cycle, ns.
        cycle_ns: u32,
        /// Announced flags.
        flags: u32,
    },
    /// The CNC has not finished creating the segment, or has shut down.
    #[error("segment {name} is not ready (state {state})")]
    NotReady {
        /// Segment name.
        name: String,
        /// Raw state.
        state: u32,
    },
    /// The operating system refused.
    #[error("opening segment {name} failed: {reason}")]
    Os {
        /// Segment name.
        name: String,
        /// iceoryx2's error.
        reason: String,
    },
}

/// The shared-memory object name of an instance.
pub fn segment_name(instance: &str) -> Option<String> {
    instance_ok(instance, 48).then(|| format!("cncplc_{instance}.hli"))
}

/// Whether `instance` is 1..=`longest` characters of `[A-Za-z0-9_.-]` (a shared-memory name).
pub(crate) fn instance_ok(instance: &str, longest: usize) -> bool {
    (1..=longest).contains(&instance.len())
        && instance
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"_.-".contains(&b))
}

fn file_name(name: &str) -> FileName {
    FileName::new(name.as_bytes()).expect("segment_name yields a valid file name")
}

/// A zeroed shared-memory object of `size` bytes, owner-only, created as `mode` says.
fn create_object(
    fname: &FileName,
    mode: CreationMode,
    size: usize,
) -> Result<SharedMemory, SharedMemoryCreationError> {
    SharedMemoryBuilder::new(fname)
        .is_memory_locked(false)
        .creation_mode(mode)
        .size(size)
        .permission(Permission::OWNER_READ_WRITE)
        .zero_memory(true)
        .create()
}

/// What both sides of a segment ([`CncSegment`], [`PlcSegment`]) have over their mapping
/// (`memory`) and its `name`: `Debug` by the name, the whole image, the header, the raw memory;
/// `beat` counts the side's own heartbeat counter of the header (a CNC tick, a PLC cycle),
/// and a reader named after the other side's counter loads that one.
macro_rules! segment_side {
    ($side:ident, beats $own:ident, watches $peer:ident) => {
        impl core::fmt::Debug for $side {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.debug_struct(stringify!($side))
                    .field("name", &self.name)
                    .finish()
            }
        }

        impl $side {
            /// The segment's shared-memory name.
            pub fn name(&self) -> &str {
                &self.name
            }

            /// The whole image.
            pub fn image(&self) -> Place<'_, HliImage> {
                self.memory.place(0)
            }

            /// The header.
            pub fn header(&self) -> Place<'_, HliSegmentHeader> {
                self.memory.place(0)
            }

            /// The raw memory (symbol-table access, snapshots).
            pub fn memory(&self) -> &ImageMemory {
                &self.memory
            }

            /// Marks one more tick (CNC) or cycle (PLC) of this side; returns the new
            /// heartbeat. The count is this side's own: what the segment holds is written,
            /// not taken back.
            pub fn beat(&self) -> u64 {
                let beats = self.beats.fetch_add(1, Ordering::Relaxed).wrapping_add(1);
                self.header()
                    .field::<u64>(offset_of!(HliSegmentHeader, $own))
                    .store_release(beats);
                beats
            }

            /// This side's heartbeats so far.
            pub fn beats(&self) -> u64 {
                self.beats.load(Ordering::Relaxed)
            }

            /// The other side's heartbeat.
            pub fn $peer(&self) -> u64 {
                self.header()
                    .field::<u64>(offset_of!(HliSegmentHeader, $peer))
                    .load_acquire()
            }
        }
    };
}

/// A previous owner's segment that was found dead and replaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StaleSegment {
    /// The dead owner's process id (0 when the header was unreadable).
    pub pid: u32,
}

/// The CNC's side of a segment: creates it, owns it, removes it when dropped.
pub struct CncSegment {
    memory: ImageMemory,
    name: String,
    replaced: Option<StaleSegment>,
    /// The header as written at creation (Ready): what every check compares against.
    expected: HliSegmentHeader,
    beats: AtomicU64,
}

segment_side!(CncSegment, beats cnc_heartbeat, watches plc_heartbeat);

impl CncSegment {
    /// Creates the segment of `instance` for `channels` channels and `axes` axes, announcing
    /// the default timing (real time, 1 ms). A segment left behind by a crashed CNC is
    /// replaced; one whose owner is alive is refused.
    pub fn create(instance: &str, channels: u32, axes: u32) -> Result<Self, CreateError> {
        Self::create_with(instance, channels, axes, CncTiming::default())
    }

    /// [`CncSegment::create`] announcing `timing` to the PLC.
    pub fn create_with(
        instance: &str,
        channels: u32,
        axes: u32,
        timing: CncTiming,
    ) -> Result<Self, CreateError> {
        let name = segment_name(instance).ok_or_else(|| CreateError::InvalidName {
            name: instance.to_string(),
        })?;
        for (what, requested, capacity) in [
            ("channel", channels, HLI_MAX_CHANNELS),
            ("axis", axes, HLI_MAX_AXES),
        ] {
            if requested as usize > capacity {
                return Err(CreateError::TooMany {
                    what,
                    requested,
                    capacity: capacity as u32,
                });
            }
        }
        let fname = file_name(&name);
        let mut replaced = None;
        let shm = match Self::create_exclusive(&fname) {
            Ok(shm) => shm,
            Err(SharedMemoryCreationError::AlreadyExist) => {
                let stale = Self::inspect_existing(&fname, &name)?;
                SharedMemory::remove(&fname).map_err(|e| CreateError::Os {
                    name: name.clone(),
                    reason: format!("removing stale segment: {e:?}"),
                })?;
                replaced = Some(stale);
                Self::create_exclusive(&fname).map_err(|e| CreateError::Os {
                    name: name.clone(),
                    reason: format!("{e:?}"),
                })?
            }
            Err(e) => {
                return Err(CreateError::Os {
                    name,
                    reason: format!("{e:?}"),
                })
            }
        };
        let mut segment = Self {
            memory: crate::raw::shared(shm),
            name,
            replaced,
            expected: bytemuck::Zeroable::zeroed(),
            beats: AtomicU64::new(0),
        };
        segment.expected = segment.write_header(channels, axes, timing);
        Ok(segment)
    }

    fn create_exclusive(fname: &FileName) -> Result<SharedMemory, SharedMemoryCreationError> {
        create_object(fname, CreationMode::CreateExclusive, IMAGE_SIZE)
    }

    /// Decides whether an existing object may be replaced: only when no live CNC owns it.
    fn inspect_existing(fname: &FileName, name: &str) -> Result<StaleSegment, CreateError> {
        let Ok(shm) = SharedMemoryBuilder::new(fname)
            .is_memory_locked(false)
            .open_existing(AccessMode::ReadWrite)
        else {
            return Ok(StaleSegment { pid: 0 });
        };
        if shm.size() < HEADER_SIZE {
            return Ok(StaleSegment { pid: 0 });
        }
        let memory = crate::raw::shared(shm);
        let header: HliSegmentHeader = memory.place::<HliSegmentHeader>(0).read();
        drop(memory); // unmaps; an opened (not created) object is not unlinked
        let owner_alive = header.magic == SEGMENT_MAGIC
            && header.segment_state != SegmentState::Closed.raw()
            && process_start_stamp(header.cnc_pid) == Some(header.cnc_start_stamp);
        if owner_alive {
            return Err(CreateError::InUse {
                name: name.to_string(),
                pid: header.cnc_pid,
            });
        }
        Ok(StaleSegment {
            pid: header.cnc_pid,
        })
    }

    /// Writes the header (Initialising), the PLC defaults, then Ready; returns the header as
    /// it stands at Ready.
    fn write_header(&self, channels: u32, axes: u32, timing: CncTiming) -> HliSegmentHeader {
        let pid = std::process::id();
        let header = self.header();
        let mut written = initial_header(
            channels,
            axes,
            SegmentState::Initialising,
            process_start_stamp(pid).unwrap_or(0),
            timing,
        );
        header.write(&written);
        // Before Ready: a PLC that attaches never sees the zeroed values.
        write_plc_defaults(&self.memory, channels);
        header
            .field::<u32>(offset_of!(HliSegmentHeader, segment_state))
            .store_release(SegmentState::Ready.raw());
        written.segment_state = SegmentState::Ready.raw();
        written
    }

    /// Compares the CNC-owned header with what this CNC wrote: identity, state (Ready) and
    /// `heartbeat`, the last heartbeat the CNC wrote. Reads a few words; no system call.
    pub fn check_header(&self, heartbeat: u64) -> Result<(), HeaderFault> {
        let found: HliSegmentHeader = self.header().read();
        guard::compare_identity(&self.expected, &found)?;
        guard::check_state(found.segment_state, &[SegmentState::Ready])?;
        if found.cnc_heartbeat != heartbeat {
            return Err(HeaderFault {
                field: HeaderField::CncHeartbeat,
                expected: heartbeat,
                found: found.cnc_heartbeat,
            });
        }
        Ok(())
    }

    /// The timing this CNC announced.
    pub fn timing(&self) -> CncTiming {
        CncTiming::of(&self.expected).unwrap_or_default()
    }

    /// The stale segment this one replaced, if any.
    pub fn replaced_stale(&self) -> Option<StaleSegment> {
        self.replaced
    }

    /// Size of the mapping in bytes.
    pub fn mapped_size(&self) -> usize {
        self.memory.len()
    }
}

impl CncSegment {
    /// Marks the segment closed (the PLC stops); the object stays until the segment is
    /// dropped.
    pub fn mark_closed(&self) {
        self.header()
            .field::<u32>(offset_of!(HliSegmentHeader, segment_state))
            .store_release(SegmentState::Closed.raw());
    }
}

impl Drop for CncSegment {
    fn drop(&mut self) {
        self.mark_closed();
        // `memory` owns the object and unlinks it when dropped.
    }
}

/// Detaching: a PLC that leaves takes its pid out of the header (if no other PLC has claimed
/// the segment since), so the CNC sees no PLC attached rather than one that hangs. The
/// mapping itself is unmapped by `memory`; the segment stays with the CNC.
impl Drop for PlcSegment {
    fn drop(&mut self) {
        if self.claimed {
            let pid = self
                .header()
                .field::<u32>(offset_of!(HliSegmentHeader, plc_pid));
            if pid.load() == std::process::id() {
                pid.store_release(0);
            }
        }
    }
}

/// The PLC's side: an attached segment, validated against this build's layout.
pub struct PlcSegment {
    memory: ImageMemory,
    name: String,
    channels: u32,
    axes: u32,
    /// This process wrote its pid into the header (a PLC, not a tool).
    claimed: bool,
    /// The header as found at attach: what every check compares against.
    seen: HliSegmentHeader,
    /// `/proc/<cnc_pid>/stat` of the CNC named at attach.
    cnc_stat: String,
    /// Whether the CNC's process could be seen at attach (its start time read and matching):
    /// else (another pid namespace, an unknown start time) its liveness is not judged.
    cnc_visible: bool,
    timing: CncTiming,
    beats: AtomicU64,
}

segment_side!(PlcSegment, beats plc_heartbeat, watches cnc_heartbeat);

impl PlcSegment {
    /// Attaches to the segment of `instance`, which must match this build's layout.
    pub fn attach(instance: &str) -> Result<Self, AttachError> {
        Self::attach_expecting(instance, LayoutIdentity::current())
    }

    /// Attaches expecting `expected` (a PLC built against another layout passes its own).
    pub fn attach_expecting(instance: &str, expected: LayoutIdentity) -> Result<Self, AttachError> {
        Self::open(instance, expected, true)
    }

    /// Attaches as a tool beside the PLC (`plc get/set/watch`): the same checks, but the
    /// header keeps naming the PLC process, which the CNC supervises.
    pub fn inspect(instance: &str) -> Result<Self, AttachError> {
        Self::open(instance, LayoutIdentity::current(), false)
    }

    fn open(instance: &str, expected: LayoutIdentity, claim: bool) -> Result<Self, AttachError> {
        let name = segment_name(instance).ok_or_else(|| AttachError::InvalidName {
            name: instance.to_string(),
        })?;
        let shm = match SharedMemoryBuilder::new(&file_name(&name))
            .is_memory_locked(false)
            .open_existing(AccessMode::ReadWrite)
        {
            Ok(shm) => shm,
            Err(SharedMemoryCreationError::DoesNotExist) => {
                return Err(AttachError::NotFound { name })
            }
            Err(e) => {
                return Err(AttachError::Os {
                    name,
                    reason: format!("{e:?}"),
                })
            }
        };
        check_owner(&name)?;
        let found = shm.size() as u64;
        if found < HEADER_SIZE as u64 {
            return Err(AttachError::Truncated {
                name,
                expected: expected.size,
                found,
            });
        }
        let memory = crate::raw::shared(shm);
        let header = memory.place::<HliSegmentHeader>(0);
        let state = header
            .field::<u32>(offset_of!(HliSegmentHeader, segment_state))
            .load_acquire();
        let h: HliSegmentHeader = header.read();
        if h.magic != SEGMENT_MAGIC {
            return Err(AttachError::BadMagic {
                name,
                cnc: h.magic,
                plc: SEGMENT_MAGIC,
            });
        }
        if state != SegmentState::Ready.raw() {
            return Err(AttachError::NotReady { name, state });
        }
        if h.layout_version != expected.version {
            return Err(AttachError::VersionMismatch {
                cnc: h.layout_version,
                plc: expected.version,
            });
        }
        if h.image_size != expected.size {
            return Err(AttachError::SizeMismatch {
                cnc: h.image_size,
                plc: expected.size,
            });
        }
        if h.layout_hash != expected.hash {
            return Err(AttachError::LayoutMismatch {
                cnc: h.layout_hash,
                plc: expected.hash,
            });
        }
        if found < expected.size || expected.size < IMAGE_SIZE as u64 {
            return Err(AttachError::Truncated {
                name,
                expected: expected.size,
                found,
            });
        }
        if h.channel_count as usize > HLI_MAX_CHANNELS || h.axis_count as usize > HLI_MAX_AXES {
            return Err(AttachError::InvalidCounts {
                channels: h.channel_count,
                axes: h.axis_count,
            });
        }
        let timing = CncTiming::of(&h).ok_or(AttachError::InvalidTiming {
            cycle_ns: h.cnc_cycle_ns,
            flags: h.cnc_flags,
        })?;
        if claim {
            header
                .field::<u32>(offset_of!(HliSegmentHeader, plc_pid))
                .store(std::process::id());
        }
        Ok(Self {
            memory,
            name,
            channels: h.channel_count,
            axes: h.axis_count,
            claimed: claim,
            seen: h,
            cnc_stat: stat_path(h.cnc_pid),
            cnc_visible: h.cnc_start_stamp != 0
                && start_stamp_at(&stat_path(h.cnc_pid)) == Some(h.cnc_start_stamp),
            timing,
            beats: AtomicU64::new(h.plc_heartbeat),
        })
    }

    /// Channels the CNC configured.
    pub fn channel_count(&self) -> u32 {
        self.channels
    }

    /// Axes the CNC configured.
    pub fn axis_count(&self) -> u32 {
        self.axes
    }

    /// The CNC's segment state (`Closed` after an orderly shutdown).
    pub fn cnc_state(&self) -> Result<SegmentState, hli::enums::InvalidValue> {
        SegmentState::decode(
            self.header()
                .field::<u32>(offset_of!(HliSegmentHeader, segment_state))
                .load_acquire(),
        )
    }

    /// Whether the CNC process that created the segment (as the header said at attach) still
    /// runs. Reads `/proc`: a system call, for the PLC's wait, not for its cycle.
    /// A CNC that could not be seen at attach counts as alive (its silence still counts).
    pub fn cnc_process_alive(&self) -> bool {
        !self.cnc_visible || start_stamp_at(&self.cnc_stat) == Some(self.seen.cnc_start_stamp)
    }

    /// Whether the CNC was seen running at attach and still runs (a tool that must not serve
    /// a dead CNC's image: a killed CNC leaves its segment marked Ready).
    pub fn cnc_known_alive(&self) -> bool {
        self.cnc_visible && self.cnc_process_alive()
    }

    /// The CNC's timing, as announced at attach.
    pub fn cnc_timing(&self) -> CncTiming {
        self.timing
    }

    /// The pid of the PLC that claimed the segment, while that process lives (a tool sees
    /// whether a PLC operates the CNC). `None` when no PLC is attached.
    pub fn attached_plc(&self) -> Option<u32> {
        let pid = self
            .header()
            .field::<u32>(offset_of!(HliSegmentHeader, plc_pid))
            .load_acquire();
        (pid != 0 && std::path::Path::new(&format!("/proc/{pid}")).exists()).then_some(pid)
    }

    /// The pid of another PLC that claimed the segment since this one did (a new PLC the
    /// CNC took after it lost this one): this one must stop writing. `None` for a tool.
    pub fn replaced_by(&self) -> Option<u32> {
        if !self.claimed {
            return None;
        }
        let pid = self
            .header()
            .field::<u32>(offset_of!(HliSegmentHeader, plc_pid))
            .load_acquire();
        (pid != std::process::id()).then_some(pid)
    }

    /// Compares the CNC-owned header with what it was at attach: the identity must be
    /// unchanged and the state Ready or Closed. Returns the state. Reads a few words.
    pub fn check_header(&self) -> Result<SegmentState, HeaderFault> {
        let found: HliSegmentHeader = self.header().read();
        guard::compare_identity(&self.seen, &found)?;
        guard::check_state(
            found.segment_state,
            &[SegmentState::Ready, SegmentState::Closed],
        )
    }
}

/// The shared-memory object name of an instance's ST variables (`plc --st` publishes them
/// for `plc get|set|watch`).
pub fn st_object_name(instance: &str) -> Option<String> {
    instance_ok(instance, 48).then(|| format!("cncplc_{instance}.st"))
}

/// Opens the existing shared-memory object `name` read-write (not owned: dropping it unmaps
/// and leaves the object to its owner).
pub fn open_raw_object(name: &str) -> Result<ImageMemory, AttachError> {
    let fname = FileName::new(name.as_bytes()).map_err(|_| AttachError::NotFound {
        name: name.to_string(),
    })?;
    SharedMemoryBuilder::new(&fname)
        .is_memory_locked(false)
        .open_existing(AccessMode::ReadWrite)
        .map(crate::raw::shared)
        .map_err(|_| AttachError::NotFound {
            name: name.to_string(),
        })
}

/// Creates a zeroed shared-memory object of `size` bytes under the full object `name`
/// (see [`segment_name`]), owned by the result (removed when it is dropped); one of the same
/// name left behind is replaced. For the ST variables' object, and for tests and tools that
/// need what a foreign or broken program would leave behind (truncated objects, wrong
/// magic).
pub fn create_raw_object(name: &str, size: usize) -> Result<ImageMemory, CreateError> {
    let fname = FileName::new(name.as_bytes()).map_err(|_| CreateError::InvalidName {
        name: name.to_string(),
    })?;
    create_object(&fname, CreationMode::PurgeAndCreate, size)
        .map(crate::raw::shared)
        .map_err(|e| CreateError::Os {
            name: name.to_string(),
            reason: format!("{e:?}"),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_checked() {
        assert_eq!(segment_name("demo-1").as_deref(), Some("cncplc_demo-1.hli"));
        assert!(segment_name("").is_none());
        assert!(segment_name("a/b").is_none());
        assert!(segment_name(&"x".repeat(49)).is_none());
    }

    #[test]
    fn own_process_has_a_start_stamp() {
        assert!(process_start_stamp(std::process::id()).is_some());
        assert!(process_start_stamp(u32::MAX).is_none());
    }
}
