//! The FIFO engine (seed 002): groups of single axes driven by rows the PLC streams in.
//!
//! A standing, enabled axis joins a group at a column (FiFoGroupIntegrate) and is coupled to
//! the group from then on: it holds its position and refuses PTP commands until the group
//! is dissolved (FiFoGroupDisintegrate). Rows arrive in blocks between ticks, each queued
//! whole or refused whole ([`crate::fifo::RowRing`]); FiFoStart checks that the group is
//! complete, standing, and that the first row is where the axes stand; then each tick the
//! generator ([`crate::fifo::FifoGenerator`]) advances by `tick x override` and hands every
//! axis its set-point. FiFoStop pulls the override to 0 (PT-2 or at once); when it is there
//! the job ends, the rows left are dropped and the group is Idle with its axes standing.
//!
//! If an axis of a running group faults (following error, drive, power), the job ends: the
//! group goes to Error, its other axes leave the group and stop with their own
//! deceleration (MC_Halt), and the PLC reads `AxisFault` in `gpFifo[i]^error_id_r`.
//!
//! Every tick the engine publishes each group's state, fill level, override and counters in
//! `gpFifo[i]^`. Neither the tick nor a call allocates: ring, generator and member slots
//! are sized when the engine is built.

use crate::axis::{AxisSet, Coupling, Lease};
use crate::fifo::{
    BlockError, FifoGenerator, FifoParams, OverrideFilter, OverrideType, ParamError, RowRing,
};
use crate::machine::engine::{Balance, Bulk, Call, Engine, EngineIo};
use crate::machine::engines::{
    config_of, section, Config, ConfigInput, EngineDef, EngineSetup, SetupError,
};
use crate::setpoint::Kinematic;
use hli::calls::axis::AxisCommandCall;
use hli::calls::fifo::FifoError;
use hli::calls::fifo::{
    FifoIntegrateCall, FifoOverrideCall, FifoOverrideType, FifoParametersCall, FifoReply,
};
use hli::calls::{decode_body, reply, CallKind, CallSpec, ErrorCode, HandlerResult};
use hli::enums::{AxisState, CouplingState, FifoGroupState};
use hli::layout::{
    HliFifoGroupState, FIFO_FLAG_AT_END, FIFO_FLAG_OVERRIDE_SETTLED, FIFO_FLAG_UNDERRUN,
    FIFO_OVERRIDE_FULL, HLI_MAX_FIFO_GROUPS,
};
use hli::wire::{AcyclicRequest, BulkHeader};
use hli::PlaceExt;

/// Why the engine cannot be built.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum FifoConfigError {
    /// More groups than the image holds.
    #[error("{0} FIFO groups: the image holds {HLI_MAX_FIFO_GROUPS}")]
    TooManyGroups(usize),
    /// A group's parameters.
    #[error("FIFO group {group}: {error}")]
    Params {
        /// The group index.
        group: usize,
        /// What is wrong.
        error: ParamError,
    },
}

/// One group.
#[derive(Debug)]
struct Group {
    params: FifoParams,
    /// Axis index per column (group position - 1).
    members: Vec<Option<Lease>>,
    ring: RowRing,
    generator: FifoGenerator,
    ovr: OverrideFilter,
    state: FifoGroupState,
    error: Option<FifoError>,
    flags: u32,
    rows_written: u64,
    underrun_ticks: u32,
    /// Rows taken, passed by the generator, and dropped (overwritten, or left when a job
    /// ended, the row a finished job stands on included): [`Balance`].
    balance: Balance,
    /// The override target before FiFoStop, in effect again once the stop has ended the job.
    before_stop: f64,
}

const MEMBER: Coupling = Coupling {
    kind: CouplingState::Fifo,
    master: -1,
    phase: AxisState::SlaveSynchronous,
};

/// Whether every slot holds a member whose coupling is still the group's.
fn complete(members: &[Option<Lease>], axes: &AxisSet) -> bool {
    members.iter().all(|m| m.is_some_and(|l| axes.holds(l)))
}

fn ppm(value: f64) -> u32 {
    (value * f64::from(FIFO_OVERRIDE_FULL)).round() as u32
}

impl Group {
    fn new(params: FifoParams, tick_s: f64) -> Group {
        Group {
            members: vec![None; params.dimension],
            ring: RowRing::new(params.dimension, params.rows),
            generator: FifoGenerator::new(params.dimension, tick_s, params.fifo_cycle_s),
            ovr: OverrideFilter::new(params.override_type, tick_s),
            state: FifoGroupState::Idle,
            error: None,
            flags: 0,
            rows_written: 0,
            underrun_ticks: 0,
            balance: Balance::default(),
            before_stop: 1.0,
            params,
        }
    }

    fn running(&self) -> bool {
        matches!(
            self.state,
            FifoGroupState::Running | FifoGroupState::Stopping
        )
    }

    fn reply(&self, error: Option<u32>) -> FifoReply {
        FifoReply {
            error_id: error.unwrap_or(0),
            group_state: self.state.raw(),
            entries: self.ring.len() as u32,
            free: self.ring.free() as u32,
            dimension: self.params.dimension as u32,
            capacity: self.params.rows as u32,
            row: 0,
            column: 0,
        }
    }

    fn refuse(&self, error: FifoError) -> FifoReply {
        self.reply(Some(error.raw()))
    }

    /// The job is over (stopped, ended by a fault or a machine stop): no rows, counters for
    /// the next job, and the override a stop pulled to 0 back at its value before the stop.
    fn end_job(&mut self, state: FifoGroupState) {
        if self.state == FifoGroupState::Stopping {
            self.ovr.reset(self.before_stop);
        }
        self.balance.dropped = self.balance.dropped.saturating_add(self.ring.len() as u64);
        self.ring.clear();
        self.generator.start(&self.ring);
        self.state = state;
        self.rows_written = 0;
        self.underrun_ticks = 0;
        self.flags = 0;
    }

    fn image(&self) -> HliFifoGroupState {
        let mut flags = self.flags;
        if self.ovr.settled() {
            flags |= FIFO_FLAG_OVERRIDE_SETTLED;
        }
        HliFifoGroupState {
            group_state_r: self.state.raw(),
            dimension_r: self.params.dimension as u32,
            axis_count_r: self.members.iter().flatten().count() as u32,
            capacity_r: self.params.rows as u32,
            entries_r: self.ring.len() as u32,
            free_r: self.ring.free() as u32,
            error_id_r: self.error.map_or(0, FifoError::raw),
            flags_r: flags,
            override_r: ppm(self.ovr.value()),
            override_target_r: ppm(self.ovr.target()),
            rows_written_r: self.rows_written,
            rows_consumed_r: self.generator.rows_passed(),
            underrun_ticks_r: self.underrun_ticks,
            fill_up_1: 0,
            job_time_r: if self.running() {
                self.generator.job_time()
            } else {
                0.0
            },
        }
    }

    /// Every member leaves the group (decoupled where still ours), `halt`ing with its own
    /// deceleration when asked.
    fn release(&mut self, axes: &mut AxisSet, halt: bool) {
        for lease in self.members.iter_mut().filter_map(Option::take) {
            if !axes.release(lease) {
                continue;
            }
            let Some(a) = axes.axis_mut(lease.axis()) else {
                continue;
            };
            if halt {
                let d = a.config().dynamics;
                // MC_Halt, not MC_Stop: the axis must not stay locked for the PLC that
                // regroups it. Refused only by an axis that stands already.
                let _ = a.command(&AxisCommandCall::halt(d.deceleration, d.jerk));
            }
        }
    }

    /// A member faulted while the group ran: the job ends, the others stop on their own.
    fn fault(&mut self, axes: &mut AxisSet) {
        self.release(axes, true);
        self.error = Some(FifoError::AxisFault);
        self.end_job(FifoGroupState::Error);
    }

    fn tick(&mut self, axes: &mut AxisSet) {
        if !self.running() {
            // Members stand where they are; one that lost its coupling (power off, fault,
            // reset) has left the group.
            for slot in &mut self.members {
                let Some(lease) = *slot else { continue };
                let Some(a) = axes.axis(lease.axis()).filter(|_| axes.holds(lease)) else {
                    *slot = None;
                    continue;
                };
                let hold = Kinematic {
                    position: a.setpoint().position,
                    ..Kinematic::default()
                };
                axes.drive(lease, hold, AxisState::SlaveSynchronous);
            }
            return;
        }
        if !complete(&self.members, axes) {
            self.fault(axes);
            return;
        }
        let ov = self.ovr.step();
        let queued = self.ring.len();
        let status = self.generator.step(&mut self.ring, ov);
        let passed = queued.saturating_sub(self.ring.len()) as u64;
        self.balance.done = self.balance.done.saturating_add(passed);
        for (c, lease) in self.members.iter().enumerate() {
            let Some(lease) = *lease else {
                continue;
            };
            let set = Kinematic {
                position: self.generator.position()[c],
                velocity: self.generator.velocity()[c],
                acceleration: self.generator.acceleration()[c],
                jerk: 0.0,
            };
            axes.drive(lease, set, AxisState::SlaveSynchronous);
        }
        self.flags = 0;
        if status.underrun {
            self.flags |= FIFO_FLAG_UNDERRUN;
            self.underrun_ticks = self.underrun_ticks.saturating_add(1);
        }
        if status.at_end {
            self.flags |= FIFO_FLAG_AT_END;
        }
        if self.state == FifoGroupState::Stopping && self.ovr.settled() && ov == 0.0 {
            self.end_job(FifoGroupState::Idle);
        }
    }

    fn integrate(&mut self, call: FifoIntegrateCall, axes: &mut AxisSet) -> FifoReply {
        if self.running() {
            return self.refuse(FifoError::Running);
        }
        let column = call.group_position as usize;
        if !(1..=self.params.dimension).contains(&column) {
            return self.refuse(FifoError::GroupPosition);
        }
        let axis = call.axis as usize;
        let Some(a) = axes.axis(axis) else {
            return self.refuse(FifoError::NoSuchAxis);
        };
        match a.coupling().map(|c| c.kind) {
            Some(CouplingState::Fifo) => return self.refuse(FifoError::AxisInGroup),
            Some(_) => return self.refuse(FifoError::AxisCoupled),
            None => {}
        }
        if self.members[column - 1].is_some() {
            return self.refuse(FifoError::PositionTaken);
        }
        // Standing, and no command about to move it (coupling would abort it silently).
        if a.setpoint().velocity != 0.0 || a.book().active().is_some() {
            return self.refuse(FifoError::AxisMoving);
        }
        let lease = match axes.couple(axis, MEMBER) {
            Ok(lease) => lease,
            Err(e) => return self.reply(Some(e.raw())),
        };
        self.members[column - 1] = Some(lease);
        if self.state == FifoGroupState::Error {
            self.error = None;
            self.state = FifoGroupState::Idle;
        }
        self.reply(None)
    }

    /// Drops `axis` from the member slots (it belongs to another group now).
    fn forget(&mut self, axis: usize) {
        for slot in &mut self.members {
            if slot.is_some_and(|l| l.axis() == axis) {
                *slot = None;
            }
        }
    }

    fn disintegrate(&mut self, axes: &mut AxisSet) -> FifoReply {
        if self.running() {
            return self.refuse(FifoError::Running);
        }
        self.release(axes, false);
        // The group is dissolved: rows queued for its axes go with it.
        self.error = None;
        self.end_job(FifoGroupState::Idle);
        self.reply(None)
    }

    fn start(&mut self, axes: &AxisSet) -> FifoReply {
        if self.running() {
            return self.refuse(FifoError::Running);
        }
        if self.state == FifoGroupState::Error {
            return self.refuse(FifoError::AxisFault);
        }
        if !complete(&self.members, axes) {
            return self.refuse(FifoError::GroupIncomplete);
        }
        let Some(first) = self.ring.row(0) else {
            return self.refuse(FifoError::Empty);
        };
        for (c, axis) in self.members.iter().enumerate() {
            let Some(a) = axis.and_then(|l| axes.axis(l.axis())) else {
                continue;
            };
            let set = a.setpoint();
            if set.velocity != 0.0 {
                return self.refuse(FifoError::AxisMoving);
            }
            if (first[c] - set.position).abs() > a.config().in_target_window {
                let mut r = self.refuse(FifoError::StartMismatch);
                r.column = c as u32;
                return r;
            }
        }
        self.generator.start(&self.ring);
        // An override set before the start is in effect from the first tick.
        self.ovr.reset(self.ovr.target());
        self.state = FifoGroupState::Running;
        self.flags = 0;
        self.underrun_ticks = 0;
        self.reply(None)
    }

    fn stop(&mut self) -> FifoReply {
        if self.state == FifoGroupState::Running {
            self.before_stop = self.ovr.target();
            self.ovr.set_target(0.0);
            self.state = FifoGroupState::Stopping;
        } else if self.state == FifoGroupState::Stopping {
        } else if self.state != FifoGroupState::Error {
            self.end_job(FifoGroupState::Idle);
        }
        self.reply(None)
    }

    fn set_override(&mut self, call: FifoOverrideCall) -> FifoReply {
        if self.state == FifoGroupState::Stopping {
            return self.refuse(FifoError::Stopping);
        }
        if call.override_ppm > FIFO_OVERRIDE_FULL {
            return self.refuse(FifoError::Override);
        }
        let value = f64::from(call.override_ppm) / f64::from(FIFO_OVERRIDE_FULL);
        if self.running() {
            self.ovr.set_target(value);
        } else {
            self.ovr.reset(value);
        }
        self.reply(None)
    }

    fn set_parameters(&mut self, call: FifoParametersCall, tick_s: f64) -> FifoReply {
        if self.running() {
            return self.refuse(FifoError::Running);
        }
        let kind = match FifoOverrideType::from_raw(call.override_type) {
            Some(FifoOverrideType::Instant) => OverrideType::Instant,
            Some(FifoOverrideType::Pt2) => OverrideType::Pt2 {
                t0_s: call.pt2_t0_s,
            },
            None => return self.refuse(FifoError::Parameter),
        };
        let Ok(params) = FifoParams::new(
            self.params.dimension,
            self.params.rows,
            call.fifo_cycle_s,
            kind,
        ) else {
            return self.refuse(FifoError::Parameter);
        };
        self.params = params;
        self.generator.set_fifo_cycle(params.fifo_cycle_s);
        let value = self.ovr.target();
        self.ovr = OverrideFilter::new(kind, tick_s);
        self.ovr.reset(value);
        self.reply(None)
    }

    /// A row block: FiFoOverwrite when `overwrite`, else FiFoWrite.
    fn write(&mut self, header: &BulkHeader, values: &[f64], overwrite: bool) -> FifoReply {
        match self.state {
            FifoGroupState::Stopping => return self.refuse(FifoError::Stopping),
            FifoGroupState::Error => return self.refuse(FifoError::AxisFault),
            _ => {}
        }
        if header.columns as usize != self.params.dimension {
            return self.refuse(FifoError::Columns);
        }
        let before = self.ring.len();
        let (result, keep) = if overwrite {
            // A running group keeps the pair it interpolates between.
            let keep = if self.running() { before.min(2) } else { 0 };
            (self.ring.replace_after(keep, values), keep)
        } else {
            (self.ring.push_block(values), before)
        };
        match result {
            Ok(rows) => {
                let b = &mut self.balance;
                b.taken = b.taken.saturating_add(rows as u64);
                b.dropped = b.dropped.saturating_add((before - keep) as u64);
                // Written counts the rows of the job: the replaced ones are no longer part.
                self.rows_written = self.rows_written + rows as u64 - (before - keep) as u64;
                if self.state == FifoGroupState::Idle {
                    self.state = FifoGroupState::Filling;
                }
                let mut r = self.reply(None);
                r.row = rows as u32;
                r
            }
            Err(BlockError::Full { .. }) => self.refuse(FifoError::Full),
            Err(BlockError::Columns { .. }) => self.refuse(FifoError::Columns),
            Err(BlockError::Empty) => self.refuse(FifoError::BlockSize),
            Err(BlockError::NonFinite { row, column, .. }) => {
                let mut r = self.refuse(FifoError::NonFinite);
                r.row = row as u32;
                r.column = column as u32;
                r
            }
        }
    }

    /// The machine stops: the job ends, every member leaves the group (the machine then
    /// stops each axis with its own deceleration).
    fn reset(&mut self, axes: &mut AxisSet) {
        self.release(axes, false);
        self.error = None;
        self.end_job(FifoGroupState::Idle);
    }
}

/// The FIFO groups of a machine.
#[derive(Debug)]
pub struct FifoEngine {
    groups: Vec<Group>,
    tick_s: f64,
}

/// The FIFO engine in the engine set ([`crate::machine::engines::STANDARD`]).
pub const ENGINE: EngineDef = EngineDef {
    name: "fifo",
    sections: &["fifo_group"],
    configure,
    build,
};

/// One `[[fifo_group]]` table: `gpFifo[i]^` in file order.
///
/// ```toml
/// [[fifo_group]]
/// dimension = 2         # N axes
/// rows = 64             # Z rows
/// fifo_cycle_ms = 2.0   # T_f
/// override = "pt2"      # or "instant" (the default)
/// pt2_t0_ms = 20.0      # T0 of the PT-2 (with "pt2" only)
/// ```
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct FifoGroupFile {
    dimension: usize,
    rows: usize,
    fifo_cycle_ms: f64,
    #[serde(default = "instant", rename = "override")]
    override_type: String,
    pt2_t0_ms: Option<f64>,
}

fn instant() -> String {
    "instant".into()
}

/// The FIFO groups' parameters, checked: an error names the group and what is wrong.
fn configure(input: &ConfigInput<'_>) -> Result<Config, SetupError> {
    let files: Vec<FifoGroupFile> = section(input.sections, "fifo_group")?;
    if files.len() > HLI_MAX_FIFO_GROUPS {
        let n = files.len();
        return Err(format!("{n} [[fifo_group]]: the image holds {HLI_MAX_FIFO_GROUPS}").into());
    }
    let mut groups = Vec::with_capacity(files.len());
    for (i, f) in files.iter().enumerate() {
        let kind = match (f.override_type.as_str(), f.pt2_t0_ms) {
            ("instant", None) => OverrideType::Instant,
            ("pt2", Some(t0)) => OverrideType::Pt2 { t0_s: t0 * 1e-3 },
            ("pt2", None) => {
                return Err(
                    format!("[[fifo_group]] {i}: override = \"pt2\" needs pt2_t0_ms").into(),
                )
            }
            ("instant", Some(_)) => {
                let e = format!("[[fifo_group]] {i}: pt2_t0_ms belongs to override = \"pt2\"");
                return Err(e.into());
            }
            (other, _) => {
                let e = format!("[[fifo_group]] {i}: override = {other:?}: \"instant\" or \"pt2\"");
                return Err(e.into());
            }
        };
        let params = FifoParams::new(f.dimension, f.rows, f.fifo_cycle_ms * 1e-3, kind)
            .map_err(|e| format!("[[fifo_group]] {i}: {e}"))?;
        groups.push(params);
    }
    Ok(std::sync::Arc::new(groups))
}

/// The FIFO groups of a machine, if it has any.
fn build(setup: &EngineSetup, config: &Config) -> Result<Option<Box<dyn Engine>>, SetupError> {
    let groups: &Vec<FifoParams> = config_of(config)?;
    if groups.is_empty() {
        return Ok(None);
    }
    Ok(Some(Box::new(FifoEngine::new(groups, setup.cycle_s)?)))
}

impl FifoEngine {
    /// Groups `gpFifo[0..]` with these parameters, for a tick of `tick_s`.
    pub fn new(groups: &[FifoParams], tick_s: f64) -> Result<FifoEngine, FifoConfigError> {
        if groups.len() > HLI_MAX_FIFO_GROUPS {
            return Err(FifoConfigError::TooManyGroups(groups.len()));
        }
        for (group, p) in groups.iter().enumerate() {
            FifoParams::new(p.dimension, p.rows, p.fifo_cycle_s, p.override_type)
                .map_err(|error| FifoConfigError::Params { group, error })?;
        }
        Ok(FifoEngine {
            groups: groups.iter().map(|&p| Group::new(p, tick_s)).collect(),
            tick_s,
        })
    }

    fn call(&mut self, kind: CallKind, request: &AcyclicRequest, axes: &mut AxisSet) -> FifoReply {
        let tick_s = self.tick_s;
        let Some(group) = self.groups.get_mut(request.target as usize) else {
            return FifoReply {
                error_id: FifoError::NoSuchGroup.raw(),
                ..FifoReply::default()
            };
        };
        match kind {
            CallKind::FIFO_INTEGRATE => match decode_body::<FifoIntegrateCall>(request) {
                Ok(call) => {
                    let axis = call.axis as usize;
                    let reply = group.integrate(call, axes);
                    if reply.error_id == 0 {
                        // An axis that left another group between its ticks (fault, power
                        // off) is that group's no more: it faults there if it ran.
                        let target = request.target as usize;
                        for (g, other) in self.groups.iter_mut().enumerate() {
                            if g != target {
                                other.forget(axis);
                            }
                        }
                    }
                    reply
                }
                Err(_) => group.refuse(FifoError::Parameter),
            },
            CallKind::FIFO_DISINTEGRATE => group.disintegrate(axes),
            CallKind::FIFO_START => group.start(axes),
            CallKind::FIFO_STOP => group.stop(),
            CallKind::FIFO_OVERRIDE => match decode_body(request) {
                Ok(call) => group.set_override(call),
                Err(_) => group.refuse(FifoError::Parameter),
            },
            CallKind::FIFO_PARAMETERS => match decode_body(request) {
                Ok(call) => group.set_parameters(call, tick_s),
                Err(_) => group.refuse(FifoError::Parameter),
            },
            // FiFoGetDimension, and nothing else reaches here.
            _ => group.reply(None),
        }
    }
}

impl Engine for FifoEngine {
    fn name(&self) -> &'static str {
        "fifo"
    }

    fn balance(&self) -> Balance {
        let mut sum = Balance::default();
        for g in &self.groups {
            sum.taken = sum.taken.saturating_add(g.balance.taken);
            sum.done = sum.done.saturating_add(g.balance.done);
            sum.dropped = sum.dropped.saturating_add(g.balance.dropped);
            sum.pending = sum.pending.saturating_add(g.ring.len() as u64);
        }
        sum
    }

    fn tick(&mut self, io: &mut EngineIo<'_, '_>) {
        for (i, group) in self.groups.iter_mut().enumerate() {
            group.tick(io.axes);
            if let Ok(place) = io.view.fifo_group(i) {
                place.write(&group.image());
            }
        }
    }

    fn calls(&self) -> &'static [CallSpec] {
        hli::calls::fifo::CALLS
    }

    fn handle(&mut self, call: Call<'_>) -> HandlerResult {
        reply(&self.call(call.kind, call.request, call.axes))
    }

    fn handle_bulk(&mut self, call: Bulk<'_>) -> HandlerResult {
        let overwrite = match call.kind {
            CallKind::FIFO_WRITE_ROWS => false,
            CallKind::FIFO_OVERWRITE_ROWS => true,
            // The other kinds come in a frame.
            _ => return Err(ErrorCode::ServiceNotSupported),
        };
        reply(&match self.groups.get_mut(call.header.target as usize) {
            Some(group) => group.write(call.header, call.values, overwrite),
            None => FifoReply {
                error_id: FifoError::NoSuchGroup.raw(),
                ..FifoReply::default()
            },
        })
    }

    fn reset(&mut self, axes: &mut AxisSet) {
        for group in &mut self.groups {
            group.reset(axes);
        }
    }
}
