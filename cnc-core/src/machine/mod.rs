//! One machine, one tick: the channels, every axis (channel axes and single axes in one
//! `AxisSet`) and the engines, run in fixed stages once per CNC cycle.
//!
//! ```text
//! tick N:
//!   1 PLC units    each channel's units read into plain values (dyn-CS enable, command and
//!                  transition; the M-function acknowledge it awaits)
//!   2 channels     masters before followers, on those values only
//!   3 hand-over    each channel's set-points to its coupled axes (Axis::drive_coupled)
//!   4 axes sense   every axis reads its encoder and drive inputs; free axes run their
//!                  generators, so engines see this tick's set-points of their masters
//!   5 engines      gears, cams and FIFO groups (the flying saw next) drive their coupled axes
//!   6 axes act     every axis: following error, controller, drive; the only writer of the
//!                  axis blocks gpAx[k]^
//!   7 CNC units    each channel's display values, state, requests and interface; heartbeat;
//!                  tracking error measured on the actual axis positions
//! between ticks:  acyclic calls (`dispatch`): routed by kind to the engine that declares it, else the axis layer
//! ```
//!
//! The engines live in their own folders (`crate::gear`, `crate::cam::machine`,
//! `crate::fifo::machine`, `crate::saw::machine`); `engines::STANDARD` lists them.
//!
//! The machine is library code: it knows no PLC program and no process. `cnc run`, the demo,
//! the in-process runs, the benchmark and the no-allocation tests all drive this one `tick`.

mod channel_axes;
pub mod engine;
pub mod engines;

pub use channel_axes::ChannelAxes;
pub use engine::{Bulk, Call, Engine, EngineIo, Others, Resource, RouteConflict, Routes};

use crate::axis::config::AxisConfig;
use crate::axis::set::AxisSetError;
use crate::axis::AxisSet;
use crate::channel::plc_io::Violations;
use crate::channel::{diag_wire, Channel, ChannelConfig, Controller, ControllerError, RunState};
use hli::access::Leaf;
use hli::calls::axis::{AxisCommandCall, AxisCommandReply};
use hli::calls::{decode_body, reply, AcyclicCall, CallKind, ErrorCode, HandlerResult};
use hli::enums::{AxisError, DynCsState};
use hli::layout::HLI_MAX_AXES;
use hli::views::{handle_read_axis_state, CncView};
use hli::wire::{AcyclicRequest, BulkHeader};
use hli::ImageMemory;
use nalgebra::Isometry3;

/// The reason a channel ends with when one of its axes faulted.
pub const STOP_REASON_AXIS: &str = "machine stop: a channel axis faulted (see its error_id_r)";

/// Why a machine cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MachineError {
    /// The channels.
    #[error(transparent)]
    Channels(#[from] ControllerError),
    /// The axes.
    #[error(transparent)]
    Axes(#[from] AxisSetError),
    /// Two engines declare the same call kind.
    #[error(transparent)]
    Routes(#[from] RouteConflict),
    /// A channel whose axes do not fit into the image behind the channels before it.
    #[error(
        "channel {channel}: axes: its {count} axes would take axis images {} to {}, \
         the image holds {HLI_MAX_AXES}",
        first + 1,
        first + count
    )]
    ChannelAxesDoNotFit {
        /// The channel's name.
        channel: String,
        /// The first axis image it would take (0-based).
        first: usize,
        /// Its axes.
        count: usize,
    },
    /// Single axes that do not fit behind the channel axes.
    #[error(
        "{channel_axes} channel axes and {single} single axes: the image holds {HLI_MAX_AXES}"
    )]
    TooManyAxes {
        /// Axis images the channels take.
        channel_axes: usize,
        /// Single axes configured.
        single: usize,
    },
}

/// Channel by channel, each channel's axes take the next axis images (a channel with
/// `axis_images = false` none): refused for the first channel whose axes do not fit.
pub fn check_channel_images<'a>(
    configs: impl IntoIterator<Item = &'a ChannelConfig>,
) -> Result<(), MachineError> {
    let mut first = 0;
    for c in configs.into_iter().filter(|c| c.axis_images) {
        let count = c.axes.len();
        if first + count > HLI_MAX_AXES {
            return Err(MachineError::ChannelAxesDoNotFit {
                channel: c.name.clone(),
                first,
                count,
            });
        }
        first += count;
    }
    Ok(())
}

/// What a machine is built from.
#[derive(Debug)]
pub struct MachineSetup {
    /// The channels, programs started or not.
    pub channels: Vec<Channel>,
    /// Single axes, behind the channel axes in the axis set and the image.
    pub axes: Vec<AxisConfig>,
    /// Engines, ticked in this order.
    pub engines: Vec<Box<dyn Engine>>,
    /// Tick, s.
    pub cycle_s: f64,
}

/// Channels, axes and engines of one CNC.
#[derive(Debug)]
pub struct Machine {
    controller: Controller,
    axes: AxisSet,
    links: Vec<ChannelAxes>,
    single_axes: usize,
    engines: Vec<Box<dyn Engine>>,
    routes: Routes,
    heartbeat: Leaf,
    /// Heartbeats written before the first tick (a real-time start announces ticks before the
    /// loop): tick N writes `heartbeat_base + N + 1`.
    heartbeat_base: u64,
    ticks: u64,
    commanded: Vec<Isometry3<f64>>,
    max_tracking_error: Vec<f64>,
    stopped: bool,
    /// Acyclic calls refused.
    refused_calls: u64,
}

impl Machine {
    /// Builds the machine: channel axes take the first axis images (channel by channel; a
    /// channel whose axes do not fit is refused), single axes follow.
    pub fn new(setup: MachineSetup) -> Result<Machine, MachineError> {
        let MachineSetup {
            channels,
            axes,
            engines,
            cycle_s,
        } = setup;
        check_channel_images(channels.iter().map(Channel::config))?;
        let mut configs = Vec::new();
        let mut links = Vec::with_capacity(channels.len());
        for channel in &channels {
            let config = channel.config();
            let slots: &[usize] = match config.axis_images {
                true => channel.layout().slots(),
                false => &[],
            };
            let n = slots.len();
            links.push(ChannelAxes::new(
                configs.len(),
                slots,
                channel.set_points(),
                cycle_s,
            ));
            for i in 0..n {
                let id = configs.len() as u32 + 1;
                configs.push(channel_axes::axis_config(config, i, id));
            }
        }
        let channel_axes = configs.len();
        if channel_axes + axes.len() > HLI_MAX_AXES {
            return Err(MachineError::TooManyAxes {
                channel_axes,
                single: axes.len(),
            });
        }
        let single_axes = axes.len();
        configs.extend(axes);
        let mut axis_set = AxisSet::new(configs, cycle_s)?;
        for link in &mut links {
            link.couple(&mut axis_set);
        }
        let n = channels.len();
        let routes = Routes::new(&engines)?;
        Ok(Machine {
            controller: Controller::new(channels)?,
            axes: axis_set,
            links,
            single_axes,
            engines,
            routes,
            heartbeat: Leaf::resolve("header.cnc_heartbeat").expect("the header has a heartbeat"),
            heartbeat_base: 0,
            refused_calls: 0,
            ticks: 0,
            commanded: vec![Isometry3::identity(); n],
            max_tracking_error: vec![0.0; n],
            stopped: false,
        })
    }

    /// One tick of the whole machine (see the module docs for the stages). Does not allocate.
    pub fn tick(&mut self, memory: &ImageMemory) {
        let view = CncView::new(memory);
        if self.ticks == 0 {
            self.axes.prime(&view);
        }
        // 1 PLC units
        self.controller.read_plc(&view);
        // 2 channels
        self.controller.tick_channels();
        self.reset_channel_axes();
        // 3 hand-over
        for (channel, link) in self.controller.channels().iter().zip(self.links.iter_mut()) {
            link.drive(
                &mut self.axes,
                channel.set_points(),
                channel.set_point_rates(),
            );
        }
        // 4 axes sense
        self.axes.sense(&view);
        // 5 engines
        for engine in &mut self.engines {
            engine.tick(&mut EngineIo {
                view: &view,
                axes: &mut self.axes,
                tick: self.ticks,
            });
        }
        // 6 axes act
        self.axes.act(&view);
        // A channel whose axis faulted (following error, I/O) has lost it: it stops.
        for (c, link) in self.links.iter().enumerate() {
            if link.faulted(&self.axes) {
                if let Some(channel) = self.controller.channel_mut(c) {
                    channel.stop(STOP_REASON_AXIS);
                }
            }
        }
        // 7 CNC units
        self.controller.write_plc(&view);
        // The machine's own count, never read back from the segment.
        memory
            .place::<u64>(self.heartbeat.offset)
            .store_release(self.heartbeat_base + self.ticks + 1);
        self.measure_tracking();
        self.ticks += 1;
    }

    /// A channel that carried out a RESET in its tick gets its axes reset and coupled again;
    /// it takes their positions over, so nothing jumps. Allocates nothing.
    fn reset_channel_axes(&mut self) {
        for (c, link) in self.links.iter_mut().enumerate() {
            let Some(channel) = self.controller.channel_mut(c) else {
                continue;
            };
            if !channel.take_axis_reset() {
                continue;
            }
            let reset = link.reset(&mut self.axes);
            let actual = link.actual(&self.axes, channel.set_points());
            channel.adopt_positions(&actual, reset.unwrap_or_else(|m| m));
            if reset.is_err() {
                channel.axis_reset_failed();
            }
        }
    }

    /// Between ticks: what the channels' control units asked for that allocates (loading and
    /// checking a selected program, starting one). Never called in a tick; `cnc run`, the
    /// in-process runs and the demo call it after each tick. Returns how many were served.
    pub fn serve_channels(&mut self) -> usize {
        self.controller.serve_channels(None)
    }

    /// [`Machine::serve_channels`] with programs loaded on `loader`'s thread (the real-time
    /// loop: a file is never read between two ticks).
    pub fn serve_channels_with(&mut self, loader: &crate::channel::folder::Loader) -> usize {
        self.controller.serve_channels(Some(loader))
    }

    /// The tool point the actual joints realise against the commanded point of the tick the
    /// drives were asked to reach (the previous one: an actual position belongs to the
    /// previous set-point).
    fn measure_tracking(&mut self) {
        for (c, channel) in self.controller.channels().iter().enumerate() {
            let link = &self.links[c];
            if channel.tracker().state() == DynCsState::Active && self.ticks > 0 {
                let actual = link.actual(&self.axes, channel.set_points());
                if let Some(realised) = channel.realised_tool(&actual) {
                    let e =
                        (realised.translation.vector - self.commanded[c].translation.vector).norm();
                    self.max_tracking_error[c] = self.max_tracking_error[c].max(e);
                }
            }
            self.commanded[c] = *channel.pose_out();
        }
    }

    /// Answers one acyclic call: the engine that declares its kind, else the machine's own
    /// (the axis layer, the probes, the channels' diagnosis). Commands to a
    /// channel's axes are refused (`Coupled`): the channel owns them. A refusal is counted
    /// ([`Machine::plc_violations`]).
    pub fn dispatch(
        &mut self,
        view: &CncView<'_>,
        kind: CallKind,
        request: &AcyclicRequest,
    ) -> HandlerResult {
        let answer = self.answer(view, kind, request);
        self.count_refusal(&answer);
        answer
    }

    fn count_refusal(&mut self, answer: &HandlerResult) {
        if answer.is_err() {
            self.refused_calls = self.refused_calls.saturating_add(1);
        }
    }

    /// Each engine's name and where the data it took went ([`engine::Balance`]).
    pub fn balances(&self) -> impl Iterator<Item = (&'static str, engine::Balance)> + '_ {
        self.engines.iter().map(|e| (e.name(), e.balance()))
    }

    /// What the PLC's writes and calls the CNC refused so far, by class.
    pub fn plc_violations(&self) -> Violations {
        let mut all = *self.controller.violations();
        all.refused_calls = all.refused_calls.saturating_add(self.refused_calls);
        all
    }

    fn answer(
        &mut self,
        view: &CncView<'_>,
        kind: CallKind,
        request: &AcyclicRequest,
    ) -> HandlerResult {
        // A bulk kind's numbers come by the bulk service only ([`Machine::dispatch_bulk`]).
        if kind.is_bulk() {
            return Err(ErrorCode::ServiceNotSupported);
        }
        // A stopped machine takes no commands, only reads (a PLC must not undo the stop).
        if self.stopped && !kind.is_read_only() {
            return Err(ErrorCode::Busy);
        }
        if let Some(i) = self.routes.engine(kind) {
            let (engine, others) = Others::split(&mut self.engines, i);
            return engine.handle(Call {
                kind,
                request,
                axes: &mut self.axes,
                others,
            });
        }
        match kind {
            CallKind::READ_AXIS_STATE => handle_read_axis_state(view, request),
            CallKind::AXIS_COMMAND => {
                let target = request.target as usize;
                if target < self.channel_axes() {
                    return reply(&AxisCommandReply {
                        command_id: 0,
                        error_id: hli::enums::AxisError::Coupled.raw(),
                    });
                }
                if target >= self.axes.len() {
                    return Err(ErrorCode::InvalidTarget);
                }
                self.axes.handle_command(request)
            }
            CallKind::PROBE_ARM => self.axes.handle_probe(request, true),
            CallKind::PROBE_ABORT => self.axes.handle_probe(request, false),
            CallKind::DYN_CS_HISTORY_READ | CallKind::DYN_CS_LOG_READ => {
                let channel = self
                    .controller
                    .channels()
                    .get(request.target as usize)
                    .ok_or(ErrorCode::InvalidTarget)?;
                let tracker = channel.tracker();
                if kind == CallKind::DYN_CS_HISTORY_READ {
                    reply(&diag_wire::answer_history(tracker, &decode_body(request)?))
                } else {
                    reply(&diag_wire::answer_log(tracker, &decode_body(request)?))
                }
            }
            // A kind of an engine this machine does not have.
            _ => Err(ErrorCode::ServiceNotSupported),
        }
    }

    /// A typed acyclic call answered in this process (tools, tests, benches): the body
    /// encoded as the PLC would send it to `target`, dispatched, the reply decoded.
    pub fn call<C: AcyclicCall>(
        &mut self,
        view: &CncView<'_>,
        target: u32,
        body: &C,
    ) -> Result<C::Reply, ErrorCode> {
        let (body, body_len) = hli::wire::encode_body(body);
        let request = AcyclicRequest {
            invoke_id: 0,
            kind: C::KIND.raw(),
            target,
            body_len,
            body,
        };
        let (reply, len) = self.dispatch(view, C::KIND, &request)?;
        hli::calls::decode_reply::<C>(&reply, len)
    }

    /// Answers one bulk call: routed by the kind its header names, like [`Machine::dispatch`],
    /// to the engine that declares it (refused when none does or the kind is no bulk kind).
    /// A stopped machine takes none.
    pub fn dispatch_bulk(&mut self, header: &BulkHeader, values: &[f64]) -> HandlerResult {
        let answer = self.answer_bulk(header, values);
        self.count_refusal(&answer);
        answer
    }

    fn answer_bulk(&mut self, header: &BulkHeader, values: &[f64]) -> HandlerResult {
        let kind = CallKind::decode(header.kind)
            .filter(|k| k.is_bulk())
            .ok_or(ErrorCode::ServiceNotSupported)?;
        if self.stopped {
            return Err(ErrorCode::Busy);
        }
        let engine = self
            .routes
            .engine(kind)
            .ok_or(ErrorCode::ServiceNotSupported)?;
        self.engines[engine].handle_bulk(Bulk {
            kind,
            header,
            values,
        })
    }

    /// Brings the machine to a safe state (supervision, signals): every channel stops on
    /// its path with its deceleration and its tracking goes to ERROR holding the last frame;
    /// engines release their axes; every single axis stops with its own deceleration and
    /// jerk (MC_Stop, which keeps the axis locked). Ticks go on until `at_rest`.
    pub fn stop(&mut self, reason: &'static str) {
        self.stopped = true;
        for i in 0..self.controller.channels().len() {
            if let Some(c) = self.controller.channel_mut(i) {
                c.stop(reason);
                // The channel control unit takes no command until the machine is re-armed.
                c.set_machine_stopped(true);
            }
        }
        for engine in &mut self.engines {
            engine.reset(&mut self.axes);
        }
        for i in self.channel_axes()..self.axes.len() {
            if let Some(axis) = self.axes.axis_mut(i) {
                let d = axis.config().dynamics;
                // Refused only by an axis that is disabled or in error: it stands already.
                let _ = axis.command(&AxisCommandCall::stop(d.deceleration, d.jerk));
            }
        }
    }

    /// Disables every axis (MC_Power off), as a machine that lost its PLC may be configured
    /// to once at rest: the axes stand without torque until a PLC powers them again.
    pub fn disable_drives(&mut self) {
        for i in 0..self.axes.len() {
            if let Some(axis) = self.axes.axis_mut(i) {
                // Refused only by an axis that is off already.
                let _ = axis.command(&AxisCommandCall::power(false));
            }
        }
    }

    /// Takes commands again after a [`Machine::stop`] that reached rest (a new PLC took
    /// over): the single axes the stop locked are released and stand powered, as they were
    /// left; channels that ended stay ended. `false` (nothing done) while not at rest.
    pub fn rearm(&mut self) -> bool {
        if !self.at_rest() {
            return false;
        }
        self.stopped = false;
        for i in 0..self.controller.channels().len() {
            if let Some(c) = self.controller.channel_mut(i) {
                c.set_machine_stopped(false);
            }
        }
        for i in self.channel_axes()..self.axes.len() {
            if let Some(axis) = self.axes.axis_mut(i) {
                // Refused only by an axis that cannot take commands: nothing to release.
                let _ = axis.command(&AxisCommandCall::stop_release());
            }
        }
        true
    }

    /// Whether every channel and every axis has come to rest (set-point velocity 0). An
    /// axis in error counts as at rest: its set-point stood still at the fault and its drive
    /// is not trusted to arrive ([`Machine::held_by_fault`] names them).
    pub fn at_rest(&self) -> bool {
        let channels = self.controller.channels().iter().all(|c| !c.stopping());
        // Set-points at rest and the drives arrived (following error inside the window).
        let axes = (0..self.axes.len()).all(|i| {
            self.axes.axis(i).is_none_or(|a| {
                a.error().is_some()
                    || (a.setpoint().velocity == 0.0
                        && a.following_error().abs() <= a.config().in_target_window)
            })
        });
        channels && axes
    }

    /// The axes in error: each stands where its fault stopped its set-point (not braked) and
    /// its controller output is zero.
    pub fn held_by_fault(&self) -> impl Iterator<Item = (&str, AxisError)> + '_ {
        (0..self.axes.len()).filter_map(|i| {
            let a = self.axes.axis(i)?;
            Some((a.config().name.as_str(), a.error()?))
        })
    }

    /// Per channel, the largest distance (mm) in ACTIVE between the tool point the actual
    /// joint positions realise and the commanded point on the moving workpiece.
    pub fn max_tracking_error(&self) -> &[f64] {
        &self.max_tracking_error
    }

    /// Ticks done.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// Before the first tick: `beats` heartbeats were already written (ticks announced before
    /// the loop), so tick N writes `beats + N + 1`.
    pub fn start_heartbeat_at(&mut self, beats: u64) {
        self.heartbeat_base = beats;
    }

    /// The heartbeat the last tick wrote (the base before the first tick).
    pub fn heartbeat(&self) -> u64 {
        self.heartbeat_base + self.ticks
    }

    /// Axis images in use (at least 1).
    pub fn axis_images(&self) -> usize {
        self.axes.len().max(1)
    }

    /// Axis images the channels take (the single axes follow them).
    pub fn channel_axes(&self) -> usize {
        self.axes.len() - self.single_axes
    }

    /// First axis image of channel `index` (None: no such channel, or it drives none).
    pub fn first_axis(&self, index: usize) -> Option<usize> {
        let link = self.links.get(index)?;
        (link.count() > 0).then(|| link.first())
    }

    /// The channels.
    pub fn controller(&self) -> &Controller {
        &self.controller
    }

    /// Every axis.
    pub fn axes(&self) -> &AxisSet {
        &self.axes
    }

    /// Every axis, mutable (tests and tools).
    pub fn axes_mut(&mut self) -> &mut AxisSet {
        &mut self.axes
    }

    /// The engines.
    pub fn engines(&self) -> &[Box<dyn Engine>] {
        &self.engines
    }

    /// Whether `stop` was called.
    pub fn stopped(&self) -> bool {
        self.stopped
    }

    /// Whether no channel runs a program any more, and none of them is still coupling its
    /// dynamic CS in or out or braking after a failure.
    pub fn idle(&self) -> bool {
        self.controller
            .channels()
            .iter()
            .all(|c| c.state() != RunState::Running && !c.settling())
    }
}
