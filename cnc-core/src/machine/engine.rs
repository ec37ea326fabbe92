//! The seam every motion engine plugs into (cams, FIFO groups, flying saw, gears): a tick
//! with the HLI view and the axis set, the acyclic calls it declares and answers, the bulk
//! service, the shared resources it holds, and its reaction to a fault.
//!
//! An engine never writes an axis block itself. It couples the axes it drives
//! ([`AxisSet::couple`], which gives a [`crate::axis::Lease`]) and hands each of them its
//! set-point for the tick ([`AxisSet::drive`] with that lease); the axis stage then runs
//! limits, following-error monitoring, the position controller and the drive, and is the
//! only writer of `gpAx[k]^`.
//!
//! The machine routes a call by the table the engines declare ([`Engine::calls`]): it names
//! no engine and no family. A new engine is its pure module, one file here with its `Engine`
//! impl, one calls file in `hli::calls`, and one line where the engine set is built.

use crate::axis::AxisSet;
use hli::calls::{CallKind, CallSpec, ErrorCode, HandlerResult};
use hli::views::CncView;
use hli::wire::{AcyclicRequest, BulkHeader};

/// What an engine sees in its tick.
pub struct EngineIo<'a, 'm> {
    /// The CNC side of the image (the engine's own HLI unit lives here).
    pub view: &'a CncView<'m>,
    /// Every axis of the machine: channel axes first, then single axes.
    pub axes: &'a mut AxisSet,
    /// Ticks done before this one.
    pub tick: u64,
}

/// Something engines share and one may hold, asked for by another before it takes it: a
/// kind named by the wire vocabulary that owns it (`hli::calls::<family>`), and a number.
/// The seam names no engine and no kind: an engine answers [`Engine::holds`] for the kinds
/// it knows (for example the flying saw plans its slave's motion in the motion table 256 -
/// the slave's axis ID, seed 001 chapter 13, which a cam must not be using).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Resource {
    /// The kind (`hli::calls::cam::MOTION_TABLE`, ...).
    pub kind: &'static str,
    /// Which one of the kind.
    pub id: u32,
}

/// The engines other than the one answering a call.
pub struct Others<'a> {
    before: &'a mut [Box<dyn Engine>],
    after: &'a mut [Box<dyn Engine>],
}

impl<'a> Others<'a> {
    /// The engines around `engines[i]`.
    pub fn split(engines: &'a mut [Box<dyn Engine>], i: usize) -> (&'a mut dyn Engine, Self) {
        let (before, rest) = engines.split_at_mut(i);
        let (me, after) = rest.split_first_mut().expect("an engine at i");
        (me.as_mut(), Others { before, after })
    }

    /// Whether one of them holds `resource`.
    pub fn hold(&self, resource: Resource) -> bool {
        self.before
            .iter()
            .chain(self.after.iter())
            .any(|e| e.holds(resource))
    }

    /// Asks the engine whose coupling holds slave `axis` to let it go
    /// ([`Engine::release_slave`]): whether one did.
    pub fn release_slave(&mut self, axis: usize, axes: &mut AxisSet) -> bool {
        self.before
            .iter_mut()
            .chain(self.after.iter_mut())
            .any(|e| e.release_slave(axis, axes))
    }
}

/// A call for an engine: its kind and frame, the axes, and the other engines to ask about
/// shared resources.
pub struct Call<'a> {
    /// The call kind (one of the engine's [`Engine::calls`]).
    pub kind: CallKind,
    /// The frame.
    pub request: &'a AcyclicRequest,
    /// Every axis of the machine.
    pub axes: &'a mut AxisSet,
    /// The other engines.
    pub others: Others<'a>,
}

/// A bulk call for an engine: its kind, its header and its numbers (read in place from shared
/// memory; the transport has checked that `values` holds `rows x columns`).
pub struct Bulk<'a> {
    /// The call kind (one of the engine's bulk [`Engine::calls`]).
    pub kind: CallKind,
    /// Target and shape.
    pub header: &'a BulkHeader,
    /// The numbers, row after row.
    pub values: &'a [f64],
}

/// Where the data an engine took from the PLC went, counted in its units (a FIFO row, a cam
/// table's row or point): each unit taken is done (executed, stored), dropped (an overwrite,
/// a stop, a refused or cut transfer) or still pending, so `taken = done + dropped + pending`
/// at every moment. Counters saturate.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Balance {
    /// Units taken in.
    pub taken: u64,
    /// Units that did what they came for.
    pub done: u64,
    /// Units thrown away.
    pub dropped: u64,
    /// Units still held.
    pub pending: u64,
}

impl Balance {
    /// Whether every unit taken is accounted for.
    pub fn holds(&self) -> bool {
        let out = self
            .done
            .saturating_add(self.dropped)
            .saturating_add(self.pending);
        self.taken == out
    }
}

/// A motion engine in the machine tick.
pub trait Engine: std::fmt::Debug + Send {
    /// A short name for reports.
    fn name(&self) -> &'static str;

    /// The call kinds this engine answers: its family's table (`hli::calls::<family>::CALLS`)
    /// or part of it. The machine routes every call of these kinds to [`Engine::handle`]; two
    /// engines declaring one kind is an error when the machine is built.
    fn calls(&self) -> &'static [CallSpec] {
        &[]
    }

    /// One tick, between the axes' sense (inputs read, free axes' generators stepped: a
    /// master's set-point is this tick's) and act (following error, controller, outputs).
    /// An engine may couple an axis here ([`AxisSet::couple`], then [`AxisSet::drive`]); a
    /// released axis steps its own generator this tick. Must not allocate, lock or do IO.
    fn tick(&mut self, io: &mut EngineIo<'_, '_>);

    /// A call of one of the kinds of [`Engine::calls`], answered.
    fn handle(&mut self, call: Call<'_>) -> HandlerResult {
        let _ = call;
        Err(ErrorCode::ServiceNotSupported)
    }

    /// A bulk call of one of its kinds (numbers written straight into shared memory, not
    /// copied into a frame), answered like [`Engine::handle`].
    fn handle_bulk(&mut self, call: Bulk<'_>) -> HandlerResult {
        let _ = call;
        Err(ErrorCode::ServiceNotSupported)
    }

    /// Whether this engine holds `resource` now.
    fn holds(&self, resource: Resource) -> bool {
        let _ = resource;
        false
    }

    /// A decoupling block of another engine's family for slave `axis`, which that engine
    /// does not hold (MC_GearOut on a `[[gear]]` slave): the engine whose coupling holds the
    /// axis lets it go, as its own decoupling would (the slave goes on free at its velocity),
    /// and says so; the others answer `false`.
    fn release_slave(&mut self, axis: usize, axes: &mut AxisSet) -> bool {
        let _ = (axis, axes);
        false
    }

    /// The machine stops on a fault (lost PLC, signal): release every coupled axis so that
    /// each stops with its own deceleration.
    fn reset(&mut self, axes: &mut AxisSet);

    /// Where the data it took went ([`Balance`]); an engine that takes no data has none.
    fn balance(&self) -> Balance {
        Balance::default()
    }
}

/// Which engine answers which call kind: built once from the engines' [`Engine::calls`].
#[derive(Debug, Default)]
pub struct Routes {
    table: Vec<(CallKind, usize)>,
}

/// Two engines declare the same call kind.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("call kind {kind:?} is declared by the engines {first} and {second}")]
pub struct RouteConflict {
    /// The kind.
    pub kind: CallKind,
    /// The engine that declared it first.
    pub first: &'static str,
    /// The other one.
    pub second: &'static str,
}

impl Routes {
    /// The routes of `engines`.
    pub fn new(engines: &[Box<dyn Engine>]) -> Result<Routes, RouteConflict> {
        let mut table: Vec<(CallKind, usize)> = Vec::new();
        for (i, engine) in engines.iter().enumerate() {
            for spec in engine.calls() {
                if let Some(&(_, first)) = table.iter().find(|(k, _)| *k == spec.kind) {
                    return Err(RouteConflict {
                        kind: spec.kind,
                        first: engines[first].name(),
                        second: engine.name(),
                    });
                }
                table.push((spec.kind, i));
            }
        }
        Ok(Routes { table })
    }

    /// The engine that answers `kind`.
    pub fn engine(&self, kind: CallKind) -> Option<usize> {
        self.table.iter().find(|(k, _)| *k == kind).map(|&(_, i)| i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug)]
    struct Declares(&'static str, &'static [CallSpec]);

    impl Engine for Declares {
        fn name(&self) -> &'static str {
            self.0
        }
        fn calls(&self) -> &'static [CallSpec] {
            self.1
        }
        fn tick(&mut self, _: &mut EngineIo<'_, '_>) {}
        fn reset(&mut self, _: &mut AxisSet) {}
    }

    #[test]
    fn calls_route_to_the_engine_that_declares_them_and_only_one_may() {
        let engines: Vec<Box<dyn Engine>> = vec![
            Box::new(Declares("a", hli::calls::cam::CALLS)),
            Box::new(Declares("b", hli::calls::fifo::CALLS)),
        ];
        let routes = Routes::new(&engines).unwrap();
        assert_eq!(routes.engine(CallKind::CAM_IN), Some(0));
        assert_eq!(routes.engine(CallKind::FIFO_START), Some(1));
        assert_eq!(routes.engine(CallKind::AXIS_COMMAND), None);
        let twice: Vec<Box<dyn Engine>> = vec![
            Box::new(Declares("a", hli::calls::saw::CALLS)),
            Box::new(Declares("b", hli::calls::saw::CALLS)),
        ];
        let conflict = Routes::new(&twice).unwrap_err();
        assert_eq!((conflict.first, conflict.second), ("a", "b"));
    }
}
