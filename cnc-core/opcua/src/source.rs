//! Where the served values come from: an image in memory (tests), or a CNC instance's
//! segment, attached read-mostly like `plc watch` and attached again when a new CNC of the
//! same instance has started.

use hli::enums::SegmentState;
use hli::segment::{AttachError, PlcSegment};
use hli::ImageMemory;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, RwLock};

/// An image the server reads (and, for configured leaves, writes).
pub trait ImageSource: Send + Sync + 'static {
    /// Calls `f` with the image while a CNC serves it; `false` (and `f` not called) when
    /// none does.
    fn with_image(&self, f: &mut dyn FnMut(&ImageMemory)) -> bool;
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
/// `/proc` read). A segment whose CNC died before the attach is not served.
fn serving(segment: &PlcSegment) -> bool {
    ready(segment) && segment.cnc_known_alive()
}

/// A CNC instance's segment, attached again after its CNC was replaced.
pub struct Instance {
    name: String,
    current: RwLock<Arc<PlcSegment>>,
    /// Whether the attached segment's CNC process still ran at the last [`Instance::refresh`]
    /// (a killed CNC leaves its segment marked Ready).
    alive: AtomicBool,
}

/// What [`Instance::refresh`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Change {
    /// Nothing changed.
    Same,
    /// The CNC closed its segment.
    Gone,
    /// A new CNC of the instance serves a new segment, now attached.
    Back,
}

impl Instance {
    /// Attaches to the running CNC of `name` (refused when none runs).
    pub fn attach(name: &str) -> Result<Instance, AttachError> {
        let segment = PlcSegment::inspect(name)?;
        Ok(Instance {
            name: name.to_owned(),
            alive: AtomicBool::new(serving(&segment)),
            current: RwLock::new(Arc::new(segment)),
        })
    }

    /// Whether the attached segment's CNC serves it (as the last look found).
    pub fn serves(&self) -> bool {
        self.alive.load(Ordering::Acquire)
    }

    /// The instance's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The segment attached now.
    pub fn segment(&self) -> Arc<PlcSegment> {
        Arc::clone(&self.current.read().unwrap_or_else(|e| e.into_inner()))
    }

    /// Looks whether the attached CNC is gone and, if so, whether a new one serves the
    /// instance: then attaches to it. `was_ready` is what the previous call saw (so a CNC
    /// gone is reported once).
    /// Its CNC counts as gone when it closed the segment or when its process no longer runs
    /// (a crash or a kill leaves the segment marked Ready): a `/proc` read, here and not on
    /// every value.
    pub fn refresh(&self, was_ready: bool) -> Change {
        let segment = self.segment();
        if serving(&segment) {
            return Change::Same;
        }
        self.alive.store(false, Ordering::Release);
        match PlcSegment::inspect(&self.name) {
            Ok(fresh) if serving(&fresh) => {
                *self.current.write().unwrap_or_else(|e| e.into_inner()) = Arc::new(fresh);
                self.alive.store(true, Ordering::Release);
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
        let segment = self.segment();
        if !ready(&segment) || !self.alive.load(Ordering::Acquire) {
            return false;
        }
        f(segment.memory());
        true
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
