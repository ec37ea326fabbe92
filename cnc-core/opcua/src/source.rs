//! Where the served values come from: an image in memory (tests), or a CNC instance's
//! segment, attached read-mostly like `plc watch` and attached again when a new CNC of the
//! same instance has started.

use hli::enums::SegmentState;
use hli::segment::{AttachError, PlcSegment};
use hli::ImageMemory;
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

/// Whether `segment`'s CNC still serves it.
fn ready(segment: &PlcSegment) -> bool {
    segment.cnc_state() == Ok(SegmentState::Ready)
}

/// A CNC instance's segment, attached again after its CNC was replaced.
pub struct Instance {
    name: String,
    current: RwLock<Arc<PlcSegment>>,
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
        Ok(Instance {
            name: name.to_owned(),
            current: RwLock::new(Arc::new(PlcSegment::inspect(name)?)),
        })
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
    pub fn refresh(&self, was_ready: bool) -> Change {
        if ready(&self.segment()) {
            return Change::Same;
        }
        match PlcSegment::inspect(&self.name) {
            Ok(fresh) if ready(&fresh) => {
                *self.current.write().unwrap_or_else(|e| e.into_inner()) = Arc::new(fresh);
                Change::Back
            }
            _ if was_ready => Change::Gone,
            _ => Change::Same,
        }
    }
}

impl ImageSource for Instance {
    fn with_image(&self, f: &mut dyn FnMut(&ImageMemory)) -> bool {
        let segment = self.segment();
        if !ready(&segment) {
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
