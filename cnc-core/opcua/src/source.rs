//! Where the served values come from: an image in memory (tests), or a CNC instance's
//! segment, attached read-mostly like `plc watch` and attached again when a new CNC of the
//! same instance has started.

use hli::enums::SegmentState;
use hli::ImageMemory;
use hli_transport::segment::{AttachError, PlcSegment};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, RwLock};

/// An image the server reads (and, for configured leaves, writes).
pub trait ImageSource: Send + Sync + 'static {
    /// Calls `f` with the image while a CNC serves it; `false` (and `f` not called) when
    /// none does.
    fn with_image(&self, f: &mut dyn FnMut(&ImageMemory)) -> bool;

    /// As [`ImageSource::with_image`], for a write: a source that can tell whether its CNC
    /// process still runs looks now (writes are rare; reads rely on the periodic look).
    fn with_image_to_write(&self, f: &mut dyn FnMut(&ImageMemory)) -> bool {
        self.with_image(f)
    }
}

impl ImageSource for ImageMemory {
    fn with_image(&self, f: &mut dyn FnMut(&ImageMemory)) -> bool {
        f(self);
        true
    }
}

/// Whether `segment`'s CNC still serves it (cheap: one atomic load).
fn ready(segment: &PlcSegment) -> bool {
    segment.cnc_state() == Ok(SegmentState::Ready)
}

/// Whether `segment` is Ready and its CNC process was seen at attach and still runs (a
/// `/proc` read). A segment whose CNC died before the attach is not served; neither is one
/// whose CNC runs in another PID namespace (its process cannot be seen from here).
fn serving(segment: &PlcSegment) -> bool {
    ready(segment) && segment.cnc_known_alive()
}

/// A segment and whether its CNC process still ran at the last look: kept together, so a
/// reader never pairs a new segment's flag with the old segment.
struct Attached {
    segment: PlcSegment,
    alive: AtomicBool,
}

impl Attached {
    fn new(segment: PlcSegment) -> Arc<Attached> {
        Arc::new(Attached {
            alive: AtomicBool::new(serving(&segment)),
            segment,
        })
    }

    /// The image while its CNC serves it: Ready, and alive at the last look.
    fn image(&self) -> Option<&ImageMemory> {
        let up = ready(&self.segment) && self.alive.load(Ordering::Acquire);
        up.then(|| self.segment.memory())
    }
}

/// A CNC instance's segment, attached again after its CNC was replaced.
pub struct Instance {
    name: String,
    current: RwLock<Arc<Attached>>,
}

/// What [`Instance::refresh`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Change {
    /// Nothing changed.
    Same,
    /// The CNC closed its segment, or its process ended.
    Gone,
    /// A new CNC of the instance serves a new segment, now attached.
    Back,
}

impl Instance {
    /// Attaches to the segment of `name` (refused when there is none).
    pub fn attach(name: &str) -> Result<Instance, AttachError> {
        Ok(Instance {
            name: name.to_owned(),
            current: RwLock::new(Attached::new(PlcSegment::inspect(name)?)),
        })
    }

    /// Whether the attached segment's CNC serves it (as the last look found).
    pub fn serves(&self) -> bool {
        self.attached().image().is_some()
    }

    /// The instance's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    fn attached(&self) -> Arc<Attached> {
        Arc::clone(&self.current.read().unwrap_or_else(|e| e.into_inner()))
    }

    /// Looks whether the attached CNC is gone and, if so, whether a new one serves the
    /// instance: then attaches to it. `was_ready` is what the previous call saw (so a CNC
    /// gone is reported once).
    /// Its CNC counts as gone when it closed the segment or when its process no longer runs
    /// (a crash or a kill leaves the segment marked Ready): a `/proc` read, here and not on
    /// every value.
    pub fn refresh(&self, was_ready: bool) -> Change {
        let attached = self.attached();
        if serving(&attached.segment) {
            return Change::Same;
        }
        attached.alive.store(false, Ordering::Release);
        match PlcSegment::inspect(&self.name) {
            Ok(fresh) if serving(&fresh) => {
                *self.current.write().unwrap_or_else(|e| e.into_inner()) = Attached::new(fresh);
                Change::Back
            }
            Ok(_) | Err(AttachError::NotFound { .. }) | Err(AttachError::NotReady { .. })
                if was_ready =>
            {
                Change::Gone
            }
            Err(e) if was_ready => {
                crate::say!("instance {}: {e}", self.name);
                Change::Gone
            }
            _ => Change::Same,
        }
    }
}

impl ImageSource for Instance {
    fn with_image(&self, f: &mut dyn FnMut(&ImageMemory)) -> bool {
        let attached = self.attached();
        let Some(image) = attached.image() else {
            return false;
        };
        f(image);
        true
    }

    fn with_image_to_write(&self, f: &mut dyn FnMut(&ImageMemory)) -> bool {
        let attached = self.attached();
        if !attached.segment.cnc_known_alive() {
            attached.alive.store(false, Ordering::Release);
            return false;
        }
        self.with_image(f)
    }
}

/// A segment served by its CNC, never attached again (a test's or a run's own segment).
impl ImageSource for PlcSegment {
    fn with_image(&self, f: &mut dyn FnMut(&ImageMemory)) -> bool {
        if !ready(self) {
            return false;
        }
        f(self.memory());
        true
    }
}
