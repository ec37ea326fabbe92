//! The seam every motion engine plugs into (cams, FIFO groups, flying saw, gears): a tick
//! with the HLI view and the axis set, the acyclic calls it owns, and its reaction to a fault.
//!
//! An engine never writes an axis block itself. It couples the axes it drives
//! (`Axis::couple`) and hands each of them its set-point for the tick (`Axis::drive_coupled`);
//! the axis stage then runs limits, following-error monitoring, the position controller and
//! the drive, and is the only writer of `gpAx[k]^`.

use crate::axis::AxisSet;
use hli::calls::fifo::{FifoReply, FifoRowsHeader};
use hli::calls::{CallKind, HandlerResult};
use hli::views::CncView;
use hli::wire::AcyclicRequest;

/// What an engine sees in its tick.
pub struct EngineIo<'a, 'm> {
    /// The CNC side of the image (the engine's own HLI unit lives here).
    pub view: &'a CncView<'m>,
    /// Every axis of the machine: channel axes first, then single axes.
    pub axes: &'a mut AxisSet,
    /// Ticks done before this one.
    pub tick: u64,
}

/// A motion engine in the machine tick.
pub trait Engine: std::fmt::Debug + Send {
    /// A short name for reports.
    fn name(&self) -> &'static str;

    /// One tick, between the axes' sense (inputs read, free axes' generators stepped: a
    /// master's set-point is this tick's) and act (following error, controller, outputs).
    /// An engine may couple an axis here (`Axis::couple`, then `drive_coupled`); a decoupled
    /// axis steps its own generator this tick (`Axis::decouple`). Must not allocate, lock or
    /// do IO.
    fn tick(&mut self, io: &mut EngineIo<'_, '_>);

    /// An acyclic call this engine owns, answered; `None` when the call is not its own.
    fn handle(
        &mut self,
        kind: CallKind,
        request: &AcyclicRequest,
        axes: &mut AxisSet,
    ) -> Option<HandlerResult> {
        let _ = (kind, request, axes);
        None
    }

    /// A FIFO row block (the bulk data of the row service) this engine owns, answered;
    /// `None` when it is not its own.
    fn handle_rows(&mut self, header: &FifoRowsHeader, values: &[f64]) -> Option<FifoReply> {
        let _ = (header, values);
        None
    }

    /// Whether this engine holds motion-function table `id` (the flying saw refuses a slave
    /// whose internal table, 256 - slave axis ID, a cam uses).
    fn holds_table(&self, id: u32) -> bool {
        let _ = id;
        false
    }

    /// The machine stops on a fault (lost PLC, signal): release every coupled axis so that
    /// each stops with its own deceleration.
    fn reset(&mut self, axes: &mut AxisSet);
}
