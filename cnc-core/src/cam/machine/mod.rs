//! The cam engine: slave axes coupled to a master axis through a cam profile (seed 000,
//! chapters 4.3 to 4.5 and 5.1.1 to 5.1.6). Each tick, for every coupled slave, it takes the
//! master's set-point of this tick, applies queued online changes of the cam's points, a due
//! switch or rescaling, and hands the slave its set-point through the coupling law
//! ([`crate::cam::coupling::CamLaw`]); the axis stage does the rest (limits, following
//! error, drive).
//!
//! Commands arrive as acyclic calls between ticks: MC_CamTableSelect (per table: cyclic; its
//! absolute flags are checked, MC_CamIn's start mode decides), MC_CamIn / MC_CamInExt (couple, or with Ext switch cams),
//! MC_CamOut (the slave goes on at its velocity as a free axis) and MC_CamScaling; and the
//! data: motion-function points written (a change under the table's online-change mode, or
//! a new function) and read, position tables written, each in chunks that change nothing
//! until the last one is checked whole. A refused call leaves every axis and table as it was.
//!
//! A first coupling with a waiting activation mode couples the slave at once but holds it
//! (`nAxisState` 11, pre-phase) until the master reaches the activation; then the slave
//! follows the cam (13, synchronous) and jumps to the cam's position if it does not stand
//! there, as the seed says (5.1.4).
//!
//! Here: the engine's state, its tick (multi-table slaves, online point changes, then every
//! cam slave: activation, rescaling, switch, hand-over) and the calls' dispatch. The calls
//! live beside it: `config` (the `[[cam_table]]` tables it starts with, its build),
//! `couplings` (couple, switch, decouple, scale, the multi-table slave),
//! `data` (points and rows in chunks, online-change mode, table delete) and `reads`
//! (MC_CamRead's answers).

mod config;
mod couplings;
mod data;
mod reads;

pub use config::{CamTableError, ENGINE};

use crate::axis::{AxisSet, Lease};
use crate::cam::coupling::{CamLaw, CouplingError, Scaling};
use crate::cam::multi_table::{MultiTableLaw, TableWeight};
use crate::cam::online::{ActivationMode, CamStore, MasterNow};
use crate::cam::{CamProfile, ProfileCursor, TableErrorCode};
use crate::machine::engine::{Balance, Call, Engine, EngineIo, Resource};
use crate::setpoint::Kinematic;
use data::{PointsTransfer, RowsTransfer};
use hli::calls::cam::CamCouplingError;
use hli::calls::cam::{
    CamReply, CamScalingMode, CamStartMode, CAM_KEEP_MASTER_OFFSET, CAM_KEEP_MASTER_SCALING,
    CAM_KEEP_SLAVE_OFFSET, CAM_KEEP_SLAVE_SCALING,
};
use hli::calls::{reply, CallKind, CallSpec, ErrorCode, HandlerResult};
use hli::enums::AxisState;

/// Table IDs run 1..=255.
const TABLE_SLOTS: usize = 256;

/// MC_CamTableSelect's settings of a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Select {
    periodic: bool,
    /// MasterAbsolute and SlaveAbsolute: a side selected absolute may not be coupled relative
    /// (MC_CamIn's StartMode governs; a contradiction is refused).
    absolute: (bool, bool),
}

/// A change a coupling waits for (each kind in its own slot: a scaling does not drop a
/// queued switch, nor the reverse).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Queued {
    /// A switch to another cam (MC_CamInExt while coupled).
    Switch {
        table: u32,
        scaling: Scaling,
        modes: (CamScalingMode, CamScalingMode),
        start: CamStartMode,
        activation: ActivationMode,
    },
    /// A rescaling (MC_CamScaling): the values asked for, and the keep bits of the ones
    /// that stay as the coupling has them when it applies (after a switch, too).
    Scale {
        requested: Scaling,
        keep: u32,
        modes: (CamScalingMode, CamScalingMode),
        activation: ActivationMode,
    },
}

/// One coupled slave.
#[derive(Debug)]
struct Slave {
    /// The slave's coupling.
    lease: Lease,
    master: usize,
    table: u32,
    /// The table interpolated as the coupling asked, when that differs from the stored one.
    own: Option<CamProfile>,
    /// The same for the cam a queued switch goes to.
    switch_own: Option<CamProfile>,
    law: CamLaw,
    cursor: ProfileCursor,
    /// False while a first coupling waits for its activation.
    active: bool,
    /// Coupled with MC_CamInExt: may switch cams.
    extended: bool,
    /// The first coupling's activation, while it waits (the slave holds).
    waiting: Option<ActivationMode>,
    /// A queued switch (`Queued::Switch`).
    switch: Option<Queued>,
    /// A queued rescaling (`Queued::Scale`).
    scale: Option<Queued>,
    /// The master's set-point of the last tick.
    master_before: f64,
    /// Where the slave holds while it waits.
    hold: f64,
    /// Master and slave set-points when the coupling became active (or was made).
    coupled_at: (f64, f64),
    /// Follows the master's actual position rather than its set-point.
    follow_actual: bool,
}

/// The scaling a rescaling gives: the values asked for, except those of a side whose mode is
/// Off and those the keep bits name, which stay as `current` has them.
fn merged_scaling(
    current: Scaling,
    requested: Scaling,
    keep: u32,
    (master_mode, slave_mode): (CamScalingMode, CamScalingMode),
) -> Scaling {
    let take = |bit: u32, on: bool| on && keep & bit == 0;
    let master_on = master_mode != CamScalingMode::Off;
    let slave_on = slave_mode != CamScalingMode::Off;
    Scaling {
        master_offset: if take(CAM_KEEP_MASTER_OFFSET, master_on) {
            requested.master_offset
        } else {
            current.master_offset
        },
        master_scaling: if take(CAM_KEEP_MASTER_SCALING, master_on) {
            requested.master_scaling
        } else {
            current.master_scaling
        },
        slave_offset: if take(CAM_KEEP_SLAVE_OFFSET, slave_on) {
            requested.slave_offset
        } else {
            current.slave_offset
        },
        slave_scaling: if take(CAM_KEEP_SLAVE_SCALING, slave_on) {
            requested.slave_scaling
        } else {
            current.slave_scaling
        },
    }
}

/// Whether couplings through `table` run cyclic: MC_CamTableSelect's choice, else the
/// table's own flag (a motion function: linear).
fn periodic_of(selects: &[Option<Select>], table: u32, profile: &CamProfile) -> bool {
    match selects.get(table as usize).copied().flatten() {
        Some(select) => select.periodic,
        None => match profile {
            CamProfile::Table(t) => t.periodic(),
            CamProfile::MotionFunction(_) => false,
        },
    }
}

/// What of the master a slave follows: its set-point (the seed's rule) or its actual
/// position, velocity and acceleration ([`AxisSet::master`]).
fn master_of(axes: &AxisSet, master: usize, actual: bool) -> Option<Kinematic> {
    axes.master(master, actual)
}

/// A multi-table slave (chapter 4.6).
#[derive(Debug)]
struct MultiSlave {
    /// The slave's coupling.
    lease: Lease,
    master: usize,
    /// Follows the master's actual values (an encoder master).
    follow_actual: bool,
    law: MultiTableLaw,
}

/// Cam couplings of a machine.
#[derive(Debug)]
pub struct CamEngine {
    /// Per table: its weight and scaling in a multi-table slave (CamTableSetWeight).
    weights: Vec<TableWeight>,
    /// Multi-table slaves by axis.
    multis: Vec<Option<MultiSlave>>,
    store: CamStore,
    selects: Vec<Option<Select>>,
    /// Per table: how a point change that applies treats the master and slave offsets.
    online_scaling: Vec<(CamScalingMode, CamScalingMode)>,
    points_in: Vec<Option<PointsTransfer>>,
    rows_in: Vec<Option<RowsTransfer>>,
    /// Points and rows of transfers: taken, stored, dropped ([`Engine::balance`]).
    data_balance: Balance,
    /// Tables declared (CamTableCreate) for rows that follow: type, interpolation, cyclic,
    /// rows.
    declared: Vec<Option<(u32, u32, u32, u32)>>,
    slaves: Vec<Option<Slave>>,
    /// Per axis: the last valid coupling of a slave that lost it without MC_CamOut (a fault,
    /// an emergency stop, power off), which MC_CamInfo still reads (seed 000 5.1.15: the
    /// recovery after an emergency stop); dropped by the next MC_CamIn or MC_CamOut.
    lost: Vec<Option<Slave>>,
    /// Profiles replaced or released in a tick, freed between ticks (no free in the tick).
    retired: Vec<CamProfile>,
    /// Motion functions a point change replaced, with their change records, freed alike.
    retired_changes: Vec<crate::cam::online::Replaced>,
}

/// A refusal as the code the block reports.
fn code(e: u32) -> HandlerResult {
    reply(&CamReply {
        error_id: e,
        reserved: 0,
    })
}

fn accepted() -> HandlerResult {
    code(0)
}

fn coupling_code(e: CouplingError) -> u32 {
    match e {
        CouplingError::Parameter { .. } => CamCouplingError::BadParameter.raw(),
        CouplingError::Combination { .. } => CamCouplingError::ModeCombination.raw(),
        CouplingError::Passed { .. } => CamCouplingError::ActivationPassed.raw(),
    }
}

const TABLE_INVALID: u32 = TableErrorCode::CamTableIdInvalid as u32;

impl CamEngine {
    /// An engine for a machine of `axes` axes with the tables of `store`.
    pub fn new(store: CamStore, axes: usize) -> CamEngine {
        CamEngine {
            weights: vec![TableWeight::default(); TABLE_SLOTS],
            multis: (0..axes).map(|_| None).collect(),
            store,
            selects: vec![None; TABLE_SLOTS],
            online_scaling: vec![
                (CamScalingMode::UserDefined, CamScalingMode::UserDefined);
                TABLE_SLOTS
            ],
            points_in: (0..TABLE_SLOTS).map(|_| None).collect(),
            rows_in: (0..TABLE_SLOTS).map(|_| None).collect(),
            data_balance: Balance::default(),
            declared: vec![None; TABLE_SLOTS],
            slaves: (0..axes).map(|_| None).collect(),
            lost: (0..axes).map(|_| None).collect(),
            // Room for every retirement between two calls: each slave lost (two profiles), a
            // switch per slave, a point change per table in use.
            retired: Vec::with_capacity(4 * axes + 8),
            retired_changes: Vec::with_capacity(2 * axes + 8),
        }
    }

    /// Keeps slave `i`'s coupling, lost without MC_CamOut, for MC_CamInfo: a move, no
    /// allocation (an older lost coupling of the axis, if any, is retired).
    fn keep_lost(&mut self, i: usize, gone: Slave) {
        if let Some(old) = self.lost[i].replace(gone) {
            self.retired.extend(old.own);
            self.retired.extend(old.switch_own);
        }
    }

    fn select_periodic(&self, table: u32, profile: &CamProfile) -> bool {
        periodic_of(&self.selects, table, profile)
    }

    /// Whether a coupling uses table `id` or switches to it. A coupling lost to a fault
    /// counts until it is decoupled: MC_CamInfo still reads it from its table.
    fn in_use(&self, id: u32) -> bool {
        let uses = |s: &Slave| {
            s.table == id || matches!(s.switch, Some(Queued::Switch { table, .. }) if table == id)
        };
        self.slaves.iter().chain(&self.lost).flatten().any(uses)
            || self
                .multis
                .iter()
                .flatten()
                .any(|m| m.law.tables().any(|t| t == id))
    }

    /// Online changes of the motion functions coupled slaves run on, under each table's
    /// mode. A change is timed by the first slave on its table (the lowest axis); with
    /// AsSoonAsPossible it waits until no slave on the table stands in a segment it touches.
    /// Every slave on the table then takes it at once, each law rebuilt with the table's
    /// scaling modes (offsets keep the master's place and the slave's position when they say
    /// so); a slave still waiting for its activation only takes the new geometry.
    fn apply_point_changes(&mut self, axes: &AxisSet) {
        for i in 0..self.slaves.len() {
            let Some(s) = self.slaves[i].as_ref() else {
                continue;
            };
            let table = s.table;
            let queued = self.store.queue(table).is_ok_and(|q| q.is_queued());
            if s.own.is_some() || !queued {
                continue;
            }
            let Some(master) = master_of(axes, s.master, s.follow_actual) else {
                continue;
            };
            let now = s.law.master_now(s.master_before, master.position);
            if let Ok(queue) = self.store.queue(table) {
                if queue.pending_mode() == Some(ActivationMode::AsSoonAsPossible) {
                    let touched = self.slaves.iter().flatten().any(|o| {
                        o.table == table
                            && o.own.is_none()
                            && master_of(axes, o.master, o.follow_actual).is_some_and(|m| {
                                queue.touches(o.law.master_now(o.master_before, m.position))
                            })
                    });
                    if touched {
                        continue;
                    }
                }
            }
            let Ok(Some(old)) = self.store.apply_due(table, now) else {
                continue;
            };
            let Ok(new) = self.store.get(table) else {
                continue;
            };
            let modes = self.online_scaling[table as usize];
            for other in self.slaves.iter_mut().flatten() {
                if other.table != table || other.own.is_some() {
                    continue;
                }
                other.cursor = ProfileCursor::default();
                if !other.active {
                    other.law.take_geometry(new);
                    continue;
                }
                let Some(m) = master_of(axes, other.master, other.follow_actual) else {
                    continue;
                };
                let (before, _) = other
                    .law
                    .slave(&old.profile, &mut ProfileCursor::default(), &m);
                let law = other.law;
                other.law = law.rescaled(
                    new,
                    law.scaling,
                    modes,
                    law.start,
                    law.periodic,
                    m.position,
                    before.position,
                    false,
                    None,
                );
                other.cursor = ProfileCursor::default();
            }
            self.retired_changes.push(old);
        }
    }
}

impl CamEngine {
    /// The multi-table slaves' set-points; a slave that lost its coupling or its master is
    /// dropped.
    fn tick_multis(&mut self, axes: &mut AxisSet) {
        for i in 0..self.multis.len() {
            let Some(multi) = self.multis[i].as_mut() else {
                continue;
            };
            let still = axes.holds(multi.lease);
            let master = master_of(axes, multi.master, multi.follow_actual);
            let (true, Some(master)) = (still, master) else {
                self.multis[i] = None;
                continue;
            };
            let set = multi.law.slave(&self.store, &master);
            axes.drive(multi.lease, set, AxisState::SlaveSynchronous);
        }
    }

    /// Cam slave `i` for this tick: its set-point from the master's, after a due activation,
    /// rescaling and switch; held while it waits, released when the law gives no finite
    /// set-point.
    fn tick_slave(&mut self, i: usize, axes: &mut AxisSet) {
        let Some(state) = self.slaves[i].as_mut() else {
            return;
        };
        // A slave that lost its coupling (fault, power off, another engine) is free again.
        let still = axes.holds(state.lease);
        let master = master_of(axes, state.master, state.follow_actual);
        let (true, Some(master)) = (still, master) else {
            if let Some(gone) = self.slaves[i].take() {
                self.keep_lost(i, gone);
            }
            return;
        };
        let now = state.law.master_now(state.master_before, master.position);
        let Ok(stored) = self.store.get(state.table) else {
            return;
        };
        let mut set = state.setpoint(stored, &master);
        if state.waiting.is_some_and(|t| t.due(now)) {
            set = state.activate(stored, &master);
        }
        set = state.rescale_if_due(stored, &master, now, set);
        let store = &self.store;
        set = state.switch_if_due(store, &self.selects, &mut self.retired, &master, now, set);
        // A law that cannot give a finite set-point (extreme scalings) releases the
        // slave rather than pass the number on.
        let finite = set.position.is_finite()
            && set.velocity.is_finite()
            && set.acceleration.is_finite()
            && set.jerk.is_finite();
        if !finite {
            axes.release(state.lease);
            return;
        }
        let (set, phase) = if state.active {
            (set, AxisState::SlaveSynchronous)
        } else {
            (
                Kinematic {
                    position: state.hold,
                    ..Kinematic::default()
                },
                AxisState::SlavePrephase,
            )
        };
        axes.drive(state.lease, set, phase);
        let queued = self.store.queue(state.table).is_ok_and(|q| q.is_queued());
        let bits = if queued {
            hli::enums::axis_status::CAM_DATA_QUEUED
        } else {
            0
        };
        axes.set_coupled_status(state.lease, bits);
        state.master_before = master.position;
    }
}

impl Slave {
    /// The set-point of the coupling as it stands, on its own copy of the table or the
    /// stored one.
    fn setpoint(&mut self, stored: &CamProfile, master: &Kinematic) -> Kinematic {
        let profile = self.own.as_ref().unwrap_or(stored);
        self.law.slave(profile, &mut self.cursor, master).0
    }

    /// A first coupling whose activation came becomes synchronous: relative sides start
    /// from here, the cycle counter too. The set-point of the new law.
    fn activate(&mut self, stored: &CamProfile, master: &Kinematic) -> Kinematic {
        let profile = self.own.as_ref().unwrap_or(stored);
        self.law = CamLaw::new(
            profile,
            self.law.scaling,
            self.law.start,
            self.law.periodic,
            master.position,
            self.hold,
        );
        self.active = true;
        self.waiting = None;
        self.coupled_at = (master.position, self.hold);
        self.law.slave(profile, &mut self.cursor, master).0
    }

    /// A queued rescaling whose activation came applies (an active coupling only); the
    /// set-point after it, else `set`.
    fn rescale_if_due(
        &mut self,
        stored: &CamProfile,
        master: &Kinematic,
        now: MasterNow,
        set: Kinematic,
    ) -> Kinematic {
        let Some(Queued::Scale {
            requested,
            keep,
            modes,
            activation,
        }) = self.scale.filter(|_| self.active)
        else {
            return set;
        };
        if !activation.due(now) {
            return set;
        }
        let profile = self.own.as_ref().unwrap_or(stored);
        let law = self.law;
        let scaling = merged_scaling(law.scaling, requested, keep, modes);
        self.law = law.rescaled(
            profile,
            scaling,
            modes,
            law.start,
            law.periodic,
            master.position,
            set.position,
            false,
            now.edge,
        );
        self.scale = None;
        self.law.slave(profile, &mut self.cursor, master).0
    }

    /// A queued switch whose activation came moves the coupling to the other cam (an
    /// active coupling only; the profile it leaves goes to `retired`); the set-point after
    /// it, else `set`.
    fn switch_if_due(
        &mut self,
        store: &CamStore,
        selects: &[Option<Select>],
        retired: &mut Vec<CamProfile>,
        master: &Kinematic,
        now: MasterNow,
        set: Kinematic,
    ) -> Kinematic {
        let Some(Queued::Switch {
            table,
            scaling,
            modes,
            start,
            activation,
        }) = self.switch.filter(|_| self.active)
        else {
            return set;
        };
        if !activation.due(now) {
            return set;
        }
        let mut set = set;
        let stored_next = store.get(table).ok();
        if let Some(next) = self.switch_own.as_ref().or(stored_next) {
            let periodic = periodic_of(selects, table, next);
            let law = self.law;
            self.law = law.rescaled(
                next,
                scaling,
                modes,
                start,
                periodic,
                master.position,
                set.position,
                true,
                now.edge,
            );
            self.table = table;
            self.cursor = ProfileCursor::default();
            set = self.law.slave(next, &mut self.cursor, master).0;
            // The switched-to cam's own copy becomes the coupling's.
            let next_own = self.switch_own.take();
            if let Some(old) = core::mem::replace(&mut self.own, next_own) {
                retired.push(old);
            }
        }
        self.switch = None;
        set
    }
}

impl Engine for CamEngine {
    fn name(&self) -> &'static str {
        "cam"
    }

    fn balance(&self) -> Balance {
        Balance {
            pending: self.pending_units(),
            ..self.data_balance
        }
    }

    fn calls(&self) -> &'static [CallSpec] {
        hli::calls::cam::CALLS
    }

    fn holds(&self, resource: Resource) -> bool {
        resource.kind == hli::calls::cam::MOTION_TABLE && self.store.get(resource.id).is_ok()
    }

    fn tick(&mut self, io: &mut EngineIo<'_, '_>) {
        self.tick_multis(io.axes);
        self.apply_point_changes(io.axes);
        for i in 0..self.slaves.len() {
            self.tick_slave(i, io.axes);
        }
    }

    fn handle(&mut self, call: Call<'_>) -> HandlerResult {
        let Call {
            kind,
            request,
            axes,
            others,
        } = call;
        // Between ticks: free what the ticks retired.
        self.retired.clear();
        self.retired_changes.clear();
        // Table data written into a table another engine plans in (the flying saw's table
        // 256 - the slave's axis ID while it drives that slave, seed 001 chapter 13): refused.
        let writes_table = matches!(kind, CallKind::CAM_POINTS_WRITE | CallKind::CAM_ROWS_WRITE);
        let table = Resource {
            kind: hli::calls::cam::MOTION_TABLE,
            id: request.target,
        };
        if writes_table && others.hold(table) {
            return code(CamCouplingError::TableInUse.raw());
        }
        match kind {
            CallKind::CAM_TABLE_SELECT => self.table_select(request),
            CallKind::CAM_IN => self.cam_in(request, axes),
            CallKind::CAM_OUT => self.cam_out(request, axes),
            CallKind::CAM_SCALING => self.cam_scaling(request, axes),
            CallKind::CAM_POINTS_WRITE => self.points_write(request, axes),
            CallKind::CAM_POINTS_READ => self.points_read(request),
            CallKind::CAM_ONLINE_MODE => self.online_mode(request),
            CallKind::CAM_ROWS_WRITE => self.rows_write(request),
            CallKind::CAM_READ => self.read(request, axes),
            CallKind::CAM_TABLE_WEIGHT => self.table_weight(request),
            CallKind::CAM_MULTI_COUPLE => self.multi_couple(request, axes),
            CallKind::CAM_MULTI_TABLE => self.multi_table(request),
            CallKind::CAM_TABLE_DELETE => self.table_delete(request),
            _ => Err(ErrorCode::ServiceNotSupported),
        }
    }

    fn reset(&mut self, axes: &mut AxisSet) {
        // A transfer cut by the stop (its PLC lost between two chunks) is dropped: a new PLC
        // that sent the missing chunks must not complete a table half of which is the old
        // PLC's. Nothing was stored from it.
        for slot in 0..TABLE_SLOTS {
            self.drop_points(slot);
            self.drop_rows(slot);
        }
        // Only its own couplings (another engine may hold an axis since).
        for multi in self.multis.iter_mut().filter_map(Option::take) {
            axes.release(multi.lease);
        }
        for i in 0..self.slaves.len() {
            if let Some(state) = self.slaves[i].take() {
                axes.release(state.lease);
                self.keep_lost(i, state);
            }
        }
    }
}

#[cfg(test)]
mod engine_tests;
