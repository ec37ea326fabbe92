//! Online modification of motion-function points (seed 3.5, 5.1.9 to 5.1.12) as data
//! operations: a write is checked against the function it will change and queued whole, or
//! refused whole; the queue says when it is due under its activation mode. Nothing here
//! knows axes: the cam engine feeds the master positions in and swaps the function when a
//! change is due.

use super::error::CamError;
use super::motion_function::{MotionFunction, MotionFunctionPoint};
use super::CamProfile;
use hli::calls::cam::CamActivationMode;

/// `MC_CamActivationMode`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ActivationMode {
    /// 0: in the next tick.
    Instantaneous,
    /// 1: when the master's position within the cam passes this value.
    AtMasterCamPos(f64),
    /// 2: when the master axis passes this absolute position.
    AtMasterAxisPos(f64),
    /// 3: at the next cycle boundary of a cyclic cam.
    NextCycle,
    /// 5: as soon as the slave is in a segment the change leaves untouched.
    AsSoonAsPossible,
    /// 6: changes are not taken.
    Off,
}

impl ActivationMode {
    /// From the raw mode and its position. 4 (`NEXTCYCLEONCE`, "not yet implemented" in the
    /// seed) and 7 (`DELETEQUEUEDDATA`, an action, not a mode) are refused here.
    pub fn from_raw(raw: u32, position: f64) -> Result<ActivationMode, CamError> {
        Ok(match CamActivationMode::from_raw(raw) {
            Some(CamActivationMode::Instantaneous) => ActivationMode::Instantaneous,
            Some(CamActivationMode::AtMasterCamPos) => ActivationMode::AtMasterCamPos(position),
            Some(CamActivationMode::AtMasterAxisPos) => ActivationMode::AtMasterAxisPos(position),
            Some(CamActivationMode::NextCycle) => ActivationMode::NextCycle,
            Some(CamActivationMode::AsSoonAsPossible) => ActivationMode::AsSoonAsPossible,
            Some(CamActivationMode::Off) => ActivationMode::Off,
            Some(CamActivationMode::NextCycleOnce | CamActivationMode::DeleteQueuedData) | None => {
                return Err(CamError::ActivationMode { mode: raw })
            }
        })
    }

    /// The raw mode number and its position (0 for the modes without one).
    pub fn raw(self) -> (u32, f64) {
        let (mode, position) = match self {
            ActivationMode::Instantaneous => (CamActivationMode::Instantaneous, 0.0),
            ActivationMode::AtMasterCamPos(p) => (CamActivationMode::AtMasterCamPos, p),
            ActivationMode::AtMasterAxisPos(p) => (CamActivationMode::AtMasterAxisPos, p),
            ActivationMode::NextCycle => (CamActivationMode::NextCycle, 0.0),
            ActivationMode::AsSoonAsPossible => (CamActivationMode::AsSoonAsPossible, 0.0),
            ActivationMode::Off => (CamActivationMode::Off, 0.0),
        };
        (mode.raw(), position)
    }

    /// Whether an axis-position activation lies behind the master in its direction of
    /// travel (rising when it stands): it would never come. Other modes never pass.
    pub fn passed(self, now: MasterNow) -> bool {
        let ActivationMode::AtMasterAxisPos(position) = self else {
            return false;
        };
        let (before, at) = now.axis;
        if at < before {
            at <= position
        } else {
            at >= position
        }
    }

    /// Whether the master's move in `now` reaches this activation (AsSoonAsPossible depends
    /// on the change and is decided by the queue; Off never comes).
    pub fn due(self, now: MasterNow) -> bool {
        let crossed = |(before, after): (f64, f64), at: f64| {
            (before < at && at <= after) || (after <= at && at < before)
        };
        match self {
            ActivationMode::Instantaneous => true,
            ActivationMode::AtMasterAxisPos(p) => crossed(now.axis, p),
            ActivationMode::AtMasterCamPos(p) if now.cycle_changed => {
                // Across the wrap: passed at the end of the old cycle or the start of the new,
                // in the direction the master axis moves.
                if now.axis.1 >= now.axis.0 {
                    p > now.cam.0 || p <= now.cam.1
                } else {
                    p < now.cam.0 || p >= now.cam.1
                }
            }
            ActivationMode::AtMasterCamPos(p) => crossed(now.cam, p),
            ActivationMode::NextCycle => now.cycle_changed,
            ActivationMode::AsSoonAsPossible | ActivationMode::Off => false,
        }
    }
}

/// The master's position in the tick a queued change is checked in.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MasterNow {
    /// Absolute master axis position: (one tick before, now).
    pub axis: (f64, f64),
    /// Master position within the cam: (one tick before, now).
    pub cam: (f64, f64),
    /// Whether a cam cycle boundary was crossed since the last tick.
    pub cycle_changed: bool,
    /// A linear cam's range edge crossed since the last tick: where it lies on the master
    /// axis, and whether it is the end (crossed forward) or the start (crossed backward). A
    /// switch or rescaling due at it is anchored there, not one tick's travel past it.
    pub edge: Option<EdgeCrossing>,
}

/// A linear cam's range edge the master crossed (see [`MasterNow::edge`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeCrossing {
    /// The edge's master axis position.
    pub axis: f64,
    /// The end of the range (else its start).
    pub end: bool,
}

impl MasterNow {
    /// A master standing at one position (axis and cam alike).
    pub fn standing(at: f64) -> MasterNow {
        MasterNow {
            axis: (at, at),
            cam: (at, at),
            cycle_changed: false,
            edge: None,
        }
    }
}

/// What a write did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WriteOutcome {
    /// Checked and queued; it applies when due.
    Queued,
    /// The mode is Off: the write was not taken (the seed ignores changes in this mode).
    Ignored,
}

#[derive(Debug, Clone, PartialEq)]
struct Pending {
    function: MotionFunction,
    changed: Vec<(f64, f64)>,
    mode: ActivationMode,
}

/// The online-change state of one cam table.
#[derive(Debug, Clone, PartialEq)]
pub struct OnlineChangeQueue {
    mode: ActivationMode,
    pending: Option<Pending>,
}

impl Default for OnlineChangeQueue {
    fn default() -> Self {
        OnlineChangeQueue {
            mode: ActivationMode::Instantaneous,
            pending: None,
        }
    }
}

impl OnlineChangeQueue {
    /// `MC_SetCamOnlineChangeMode`: the rule for writes from now on.
    pub fn set_mode(&mut self, mode: ActivationMode) {
        self.mode = mode;
    }

    /// The rule for writes.
    pub fn mode(&self) -> ActivationMode {
        self.mode
    }

    /// `MC_CAMACTIVATION_DELETEQUEUEDDATA`: drops what is queued; the running cam is untouched.
    pub fn delete_queued(&mut self) {
        self.pending = None;
    }

    /// Whether a change is queued (the seed's `AxisCamDataQueued`).
    pub fn is_queued(&self) -> bool {
        self.pending.is_some()
    }

    /// The activation mode of the queued change, if one is queued.
    pub fn pending_mode(&self) -> Option<ActivationMode> {
        self.pending.as_ref().map(|p| p.mode)
    }

    /// Whether the master in `now` stands in a segment the queued change touches (what
    /// AsSoonAsPossible waits out; false when nothing is queued).
    pub fn touches(&self, now: MasterNow) -> bool {
        self.changed_ranges()
            .iter()
            .any(|(a, b)| now.cam.1 >= *a && now.cam.1 <= *b)
    }

    /// Master ranges of the segments the queued change touches.
    pub fn changed_ranges(&self) -> &[(f64, f64)] {
        self.pending.as_ref().map_or(&[], |p| &p.changed)
    }

    /// `MC_WriteMotionFunction(Point)`: points `first..` replaced, on top of anything already
    /// queued. The whole result is checked; on `Err` the queue is as it was.
    pub fn write(
        &mut self,
        current: &MotionFunction,
        first: u32,
        points: &[MotionFunctionPoint],
        now: MasterNow,
    ) -> Result<WriteOutcome, CamError> {
        if self.mode == ActivationMode::Off {
            return Ok(WriteOutcome::Ignored);
        }
        if let ActivationMode::AtMasterAxisPos(position) = self.mode {
            if self.mode.passed(now) {
                return Err(CamError::ActivationPassed {
                    position,
                    master: now.axis.1,
                });
            }
        }
        let base = self.pending.as_ref().map_or(current, |p| &p.function);
        let function = base.with_points_written(first, points)?;
        let changed = changed_ranges(current, &function);
        self.pending = Some(Pending {
            function,
            changed,
            mode: self.mode,
        });
        Ok(WriteOutcome::Queued)
    }

    /// The queued change if it is due now (and then no longer queued): the new function and
    /// the ranges it changed (handed out whole, so a cyclic caller frees nothing).
    pub fn take_due(&mut self, now: MasterNow) -> Option<(MotionFunction, Vec<(f64, f64)>)> {
        let pending = self.pending.as_ref()?;
        let due = match pending.mode {
            ActivationMode::AsSoonAsPossible => !pending
                .changed
                .iter()
                .any(|(a, b)| now.cam.1 >= *a && now.cam.1 <= *b),
            mode => mode.due(now),
        };
        if due {
            self.pending.take().map(|p| (p.function, p.changed))
        } else {
            None
        }
    }
}

impl MotionFunction {
    /// The function with points `first..first + points.len()` replaced (each written point's
    /// index must be its place), checked whole.
    pub fn with_points_written(
        &self,
        first: u32,
        points: &[MotionFunctionPoint],
    ) -> Result<MotionFunction, CamError> {
        let count = self.points().len() as u32;
        let last = first.saturating_add(points.len() as u32).saturating_sub(1);
        if first == 0 || points.is_empty() || last > count {
            return Err(CamError::WriteRange { first, last, count });
        }
        let mut all = self.points().to_vec();
        for (i, p) in points.iter().enumerate() {
            let at = first as usize - 1 + i;
            if p.index != first + i as u32 {
                return Err(CamError::PointIndex {
                    found: p.index,
                    expected: first + i as u32,
                });
            }
            all[at] = *p;
        }
        MotionFunction::new(&all)
    }
}

/// Master ranges (rising order) of the segments of `new` that are not segments of `old`
/// with the same range and the same pieces.
pub fn changed_ranges(old: &MotionFunction, new: &MotionFunction) -> Vec<(f64, f64)> {
    let pieces_of =
        |f: &MotionFunction, s: &super::motion_function::Segment| f.segment_pieces(s).to_vec();
    let mut out = Vec::new();
    for s in new.segments() {
        let same = old
            .segments()
            .iter()
            .any(|o| o.master == s.master && pieces_of(old, o) == pieces_of(new, s));
        if !same {
            let (a, b) = s.master;
            out.push((a.min(b), a.max(b)));
        }
    }
    out
}

/// What an applied change replaced: the old profile and the change's record.
#[derive(Debug)]
pub struct Replaced {
    /// The profile before the change.
    pub profile: CamProfile,
    /// The master ranges the change touched.
    pub changed: Vec<(f64, f64)>,
}

/// Cam tables by ID (1..=255), as the NC keeps them.
#[derive(Debug, Clone, Default)]
pub struct CamStore {
    tables: Vec<Option<(CamProfile, OnlineChangeQueue)>>,
}

fn slot(id: u32) -> Result<usize, CamError> {
    if (1..=255).contains(&id) {
        Ok(id as usize - 1)
    } else {
        Err(CamError::TableId { id })
    }
}

impl CamStore {
    /// An empty store.
    pub fn new() -> CamStore {
        CamStore {
            tables: vec![None; 255],
        }
    }

    /// Stores (or replaces) the profile under `id`.
    pub fn insert(&mut self, id: u32, profile: CamProfile) -> Result<(), CamError> {
        let i = slot(id)?;
        self.tables[i] = Some((profile, OnlineChangeQueue::default()));
        Ok(())
    }

    /// The online-change state of table `id`, to look at.
    pub fn queue(&self, id: u32) -> Result<&OnlineChangeQueue, CamError> {
        self.tables[slot(id)?]
            .as_ref()
            .map(|(_, q)| q)
            .ok_or(CamError::NoSuchTable { id })
    }

    /// The profile under `id`.
    pub fn get(&self, id: u32) -> Result<&CamProfile, CamError> {
        self.tables[slot(id)?]
            .as_ref()
            .map(|(p, _)| p)
            .ok_or(CamError::NoSuchTable { id })
    }

    /// Removes the profile under `id`.
    pub fn remove(&mut self, id: u32) -> Result<CamProfile, CamError> {
        let i = slot(id)?;
        self.tables[i]
            .take()
            .map(|(p, _)| p)
            .ok_or(CamError::NoSuchTable { id })
    }

    /// The online-change queue of table `id`.
    pub fn queue_mut(&mut self, id: u32) -> Result<&mut OnlineChangeQueue, CamError> {
        self.tables[slot(id)?]
            .as_mut()
            .map(|(_, q)| q)
            .ok_or(CamError::NoSuchTable { id })
    }

    /// A point write to table `id` under its online-change mode; a refused write leaves the
    /// table and its queue unchanged.
    pub fn write_points(
        &mut self,
        id: u32,
        first: u32,
        points: &[MotionFunctionPoint],
        now: MasterNow,
    ) -> Result<WriteOutcome, CamError> {
        let (profile, queue) = self.tables[slot(id)?]
            .as_mut()
            .ok_or(CamError::NoSuchTable { id })?;
        let CamProfile::MotionFunction(current) = profile else {
            return Err(CamError::NotMotionFunction { id });
        };
        queue.write(current, first, points, now)
    }

    /// Applies the queued change of table `id` if it is due; what it replaced when it was
    /// applied (handed back so that a cyclic caller can free it outside its cycle).
    pub fn apply_due(&mut self, id: u32, now: MasterNow) -> Result<Option<Replaced>, CamError> {
        let (profile, queue) = self.tables[slot(id)?]
            .as_mut()
            .ok_or(CamError::NoSuchTable { id })?;
        Ok(queue.take_due(now).map(|(f, changed)| Replaced {
            profile: core::mem::replace(profile, CamProfile::MotionFunction(f)),
            changed,
        }))
    }
}
