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

use super::engine::{Engine, EngineIo};
use crate::axis::{AxisSet, Coupling};
use crate::cam::coupling::{
    check_couple, check_not_passed, check_scaling, check_switch, Activation, CamLaw, CouplingError,
    Scaling, ScalingMode, StartMode,
};
use crate::cam::multi_table::{MultiTableError, MultiTableLaw, TableSpec, TableWeight};
use crate::cam::online::{ActivationMode, CamStore, MasterNow};
use crate::cam::{
    CamProfile, Interpolation, MotionFunction, MotionFunctionPoint, PositionTable, ProfileCursor,
    TableErrorCode, TableType,
};
use crate::setpoint::Kinematic;
use hli::calls::{
    decode_body, reply, CallKind, CamInCall, CamMultiCoupleCall, CamMultiTableCall,
    CamOnlineModeCall, CamOutCall, CamPointsReadCall, CamPointsReply, CamPointsWriteCall,
    CamReadCall, CamReply, CamRowsWriteCall, CamScalingCall, CamTableDeleteCall,
    CamTableSelectCall, CamTableWeightCall, CamValuesReply, ErrorCode, HandlerResult,
    McMotionFunctionPoint, CAM_CHUNK_FIRST, CAM_CHUNK_LAST, CAM_KEEP_MASTER_OFFSET,
    CAM_KEEP_MASTER_SCALING, CAM_KEEP_SLAVE_OFFSET, CAM_KEEP_SLAVE_SCALING,
    CAM_MULTI_ENABLE_CORRECTION, CAM_MULTI_STOP_CYCLIC, CAM_POINTS_CREATE, CAM_POINTS_PER_CALL,
    CAM_READ_CHARACTERISTICS, CAM_READ_INFO, CAM_READ_ROWS, CAM_READ_SLAVE_DYNAMICS,
    CAM_READ_VALUES, CAM_ROWS_DECLARE, CAM_ROWS_PER_CALL, CAM_VALUES_PER_REPLY,
};
use hli::enums::{AxisError, AxisState, CamCouplingError, CouplingState};
use hli::wire::AcyclicRequest;

/// Table IDs run 1..=255.
const TABLE_SLOTS: usize = 256;

/// MC_CamTableSelect's settings of a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Select {
    periodic: bool,
}

/// A change a coupling waits for (each kind in its own slot: a scaling does not drop a
/// queued switch, nor the reverse).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Queued {
    /// A switch to another cam (MC_CamInExt while coupled).
    Switch {
        table: u32,
        scaling: Scaling,
        modes: (ScalingMode, ScalingMode),
        start: StartMode,
        activation: ActivationMode,
    },
    /// A rescaling (MC_CamScaling): the values asked for, and the keep bits of the ones
    /// that stay as the coupling has them when it applies (after a switch, too).
    Scale {
        requested: Scaling,
        keep: u32,
        modes: (ScalingMode, ScalingMode),
        activation: ActivationMode,
    },
}

/// One coupled slave.
#[derive(Debug)]
struct Slave {
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
    (master_mode, slave_mode): (ScalingMode, ScalingMode),
) -> Scaling {
    let take = |bit: u32, on: bool| on && keep & bit == 0;
    let master_on = master_mode != ScalingMode::Off;
    let slave_on = slave_mode != ScalingMode::Off;
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

/// Couples axis `slave` to `master` as a cam slave in `phase`; the axis layer's refusal code.
fn couple_cam(
    axes: &mut AxisSet,
    slave: usize,
    master: usize,
    phase: AxisState,
) -> Result<(), u32> {
    let axis = axes
        .axis_mut(slave)
        .ok_or(CamCouplingError::NotCamCoupled.raw())?;
    axis.couple(Coupling {
        kind: CouplingState::Cam,
        master: master as i32,
        phase,
    })
    .map_err(AxisError::raw)
}

/// What of the master a slave follows: its set-point (the seed's rule) or its actual
/// position and velocity.
fn master_of(axes: &AxisSet, master: usize, actual: bool) -> Option<Kinematic> {
    let a = axes.axis(master)?;
    Some(if actual {
        Kinematic {
            position: a.actual(),
            velocity: a.actual_velocity(),
            ..Kinematic::default()
        }
    } else {
        a.setpoint()
    })
}

/// Points of a transfer received so far.
#[derive(Debug)]
struct PointsTransfer {
    first: u32,
    total: u32,
    create: bool,
    points: Vec<MotionFunctionPoint>,
}

/// Rows of a table transfer received so far.
#[derive(Debug)]
struct RowsTransfer {
    total: u32,
    table_type: u32,
    interpolation: u32,
    periodic: u32,
    rows: Vec<[f64; 2]>,
}

/// A multi-table slave (chapter 4.6).
#[derive(Debug)]
struct MultiSlave {
    master: usize,
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
    online_scaling: Vec<(ScalingMode, ScalingMode)>,
    points_in: Vec<Option<PointsTransfer>>,
    rows_in: Vec<Option<RowsTransfer>>,
    /// Tables declared (CamTableCreate) for rows that follow: type, interpolation, cyclic,
    /// rows.
    declared: Vec<Option<(u32, u32, u32, u32)>>,
    slaves: Vec<Option<Slave>>,
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
            online_scaling: vec![(ScalingMode::UserDefined, ScalingMode::UserDefined); TABLE_SLOTS],
            points_in: (0..TABLE_SLOTS).map(|_| None).collect(),
            rows_in: (0..TABLE_SLOTS).map(|_| None).collect(),
            declared: vec![None; TABLE_SLOTS],
            slaves: (0..axes).map(|_| None).collect(),
            // Room for every retirement between two calls: each slave lost (two profiles), a
            // switch per slave, a point change per table in use.
            retired: Vec::with_capacity(4 * axes + 8),
            retired_changes: Vec::with_capacity(2 * axes + 8),
        }
    }

    fn select_periodic(&self, table: u32, profile: &CamProfile) -> bool {
        periodic_of(&self.selects, table, profile)
    }

    fn table_select(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let call: CamTableSelectCall = decode_body(request)?;
        let id = request.target;
        if self.store.get(id).is_err() {
            return code(TABLE_INVALID);
        }
        if call.periodic > 1 || call.master_absolute > 1 || call.slave_absolute > 1 {
            return code(CamCouplingError::UnknownMode.raw());
        }
        self.selects[id as usize] = Some(Select {
            periodic: call.periodic == 1,
        });
        accepted()
    }

    /// The profile a coupling uses: the stored one, or a copy interpolated as requested.
    fn profile_for(&self, table: u32, interpolation: u32) -> Result<Option<CamProfile>, u32> {
        let profile = self.store.get(table).map_err(|_| TABLE_INVALID)?;
        let CamProfile::Table(t) = profile else {
            // Motion functions carry their own laws: the interpolation does not apply.
            return Ok(None);
        };
        let wanted = match interpolation {
            0 => Interpolation::Linear,
            1 => Interpolation::FourPoint,
            2 => Interpolation::Spline,
            _ => return Err(CamCouplingError::UnknownMode.raw()),
        };
        if wanted == t.interpolation() {
            return Ok(None);
        }
        let rows: Vec<[f64; 2]> = t.rows().collect();
        PositionTable::new(&rows, t.table_type(), wanted, t.periodic())
            .map(|t| Some(CamProfile::Table(t)))
            .map_err(|e| e.code() as u32)
    }

    fn cam_in(&mut self, request: &AcyclicRequest, axes: &mut AxisSet) -> HandlerResult {
        let call: CamInCall = decode_body(request)?;
        let slave = request.target as usize;
        let master = call.master as usize;
        if slave >= axes.len() {
            return Err(ErrorCode::InvalidTarget);
        }
        if master >= axes.len() {
            return code(CamCouplingError::NoSuchMaster.raw());
        }
        if master == slave {
            return code(CamCouplingError::MasterIsSlave.raw());
        }
        let (Some(start), Some(activation), Some(master_mode), Some(slave_mode)) = (
            StartMode::from_raw(call.start_mode),
            Activation::from_raw(call.activation_mode, call.activation_position),
            ScalingMode::from_raw(call.master_scaling_mode),
            ScalingMode::from_raw(call.slave_scaling_mode),
        ) else {
            return code(CamCouplingError::UnknownMode.raw());
        };
        if call.extended > 1 || call.master_source > 1 || !call.activation_position.is_finite() {
            return code(CamCouplingError::BadParameter.raw());
        }
        let scaling = Scaling {
            master_offset: call.master_offset,
            slave_offset: call.slave_offset,
            master_scaling: call.master_scaling,
            slave_scaling: call.slave_scaling,
        };
        if let Err(e) = scaling.check() {
            return code(coupling_code(e));
        }
        let own = match self.profile_for(call.table_id, call.interpolation) {
            Ok(own) => own,
            Err(e) => return code(e),
        };
        let follow_actual = call.master_source == 1;
        let Some(master_set) = master_of(axes, master, follow_actual) else {
            return code(CamCouplingError::NoSuchMaster.raw());
        };
        let master_auto = master_mode == ScalingMode::AutoOffset;
        // The master's direction of travel decides whether an axis position lies behind it.
        let now = MasterNow {
            axis: (
                master_set.position - master_set.velocity,
                master_set.position,
            ),
            ..MasterNow::default()
        };
        let Some(axis) = axes.axis(slave) else {
            return Err(ErrorCode::InvalidTarget);
        };
        let coupled = axis.coupling();
        let ours = self.slaves[slave].as_ref();
        match (coupled, ours) {
            // Coupled through a cam already: a switch (MC_CamInExt both times) or a refusal.
            (Some(c), Some(current)) if c.kind == CouplingState::Cam => {
                if !(current.extended && call.extended == 1) {
                    return code(CamCouplingError::NotSwitchable.raw());
                }
                if !current.active {
                    return code(CamCouplingError::CouplingPending.raw());
                }
                if current.master != master {
                    return code(CamCouplingError::NoSuchMaster.raw());
                }
                if let Err(e) = check_switch(activation, start, master_auto)
                    .and_then(|()| check_not_passed(activation, now))
                {
                    return code(coupling_code(e));
                }
                let current = self.slaves[slave].as_mut().expect("checked above");
                if activation == Activation::DeleteQueuedData {
                    if current.switch.take().is_some() {
                        if let Some(old) = current.switch_own.take() {
                            self.retired.push(old);
                        }
                    }
                    return accepted();
                }
                if let Some(old) = core::mem::replace(&mut current.switch_own, own) {
                    self.retired.push(old);
                }
                let current = self.slaves[slave].as_mut().expect("checked above");
                current.switch = Some(Queued::Switch {
                    table: call.table_id,
                    scaling,
                    modes: (master_mode, slave_mode),
                    start,
                    activation: activation.timing().expect("checked: a timed mode"),
                });
                accepted()
            }
            (Some(_), _) => code(AxisError::Coupled.raw()),
            (None, _) => {
                // Whatever the engine still held for this axis is stale: the axis layer
                // dropped the coupling (a fault, power off).
                self.multis[slave] = None;
                if let Err(e) = check_couple(activation, start, master_auto)
                    .and_then(|()| check_not_passed(activation, now))
                {
                    return code(coupling_code(e));
                }
                let profile = match &own {
                    Some(p) => p,
                    None => self
                        .store
                        .get(call.table_id)
                        .map_err(|_| ErrorCode::InvalidData)?,
                };
                let periodic = self.select_periodic(call.table_id, profile);
                let hold = axis.setpoint().position;
                let law = CamLaw::new(profile, scaling, start, periodic, master_set.position, hold);
                if let Err(e) = couple_cam(axes, slave, master, AxisState::SlavePrephase) {
                    return code(e);
                }
                let Some(axis) = axes.axis_mut(slave) else {
                    return Err(ErrorCode::InvalidTarget);
                };
                axis.drive_coupled(
                    Kinematic {
                        position: hold,
                        ..Kinematic::default()
                    },
                    AxisState::SlavePrephase,
                );
                let timing = activation.timing().expect("checked: a timed mode");
                self.slaves[slave] = Some(Slave {
                    master,
                    table: call.table_id,
                    own,
                    switch_own: None,
                    law,
                    cursor: ProfileCursor::default(),
                    active: false,
                    extended: call.extended == 1,
                    waiting: Some(timing),
                    switch: None,
                    scale: None,
                    master_before: master_set.position,
                    hold,
                    coupled_at: (master_set.position, hold),
                    follow_actual,
                });
                accepted()
            }
        }
    }

    /// Whether a coupling uses table `id` or switches to it.
    fn in_use(&self, id: u32) -> bool {
        self.slaves.iter().flatten().any(|s| {
            s.table == id || matches!(s.switch, Some(Queued::Switch { table, .. }) if table == id)
        }) || self
            .multis
            .iter()
            .flatten()
            .any(|m| m.law.tables().any(|t| t == id))
    }

    fn table_weight(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let call: CamTableWeightCall = decode_body(request)?;
        let id = request.target;
        if !(1..=255).contains(&id) {
            return code(TABLE_INVALID);
        }
        let w = TableWeight {
            weight: call.weight,
            master_offset: call.master_offset,
            master_slope: call.master_slope,
            slave_offset: call.slave_offset,
            slave_slope: call.slave_slope,
            range_low: call.range_low,
            range_high: call.range_high,
        };
        if w.check().is_err() {
            return code(CamCouplingError::BadParameter.raw());
        }
        // The seed: weights are set before a table becomes active, not while it is.
        if self
            .multis
            .iter()
            .flatten()
            .any(|m| m.law.tables().any(|t| t == id))
        {
            return code(CamCouplingError::TableInUse.raw());
        }
        self.weights[id as usize] = w;
        accepted()
    }

    fn multi_couple(&mut self, request: &AcyclicRequest, axes: &mut AxisSet) -> HandlerResult {
        let call: CamMultiCoupleCall = decode_body(request)?;
        let slave = request.target as usize;
        if slave >= axes.len() {
            return Err(ErrorCode::InvalidTarget);
        }
        if call.on == 0 {
            if self.multis[slave].take().is_none() {
                return code(CamCouplingError::NotCamCoupled.raw());
            }
            if let Some(axis) = axes.axis_mut(slave) {
                axis.decouple();
            }
            return accepted();
        }
        let master = call.master as usize;
        if master >= axes.len() {
            return code(CamCouplingError::NoSuchMaster.raw());
        }
        if master == slave {
            return code(CamCouplingError::MasterIsSlave.raw());
        }
        let (n, profiles) = (call.tables as usize, call.profiles as usize);
        if !(1..=8).contains(&n) || !(1..=n).contains(&profiles) {
            return code(CamCouplingError::UnknownMode.raw());
        }
        let mut specs = Vec::with_capacity(n);
        for (k, &id) in call.table_ids[..n].iter().enumerate() {
            let Ok(cam) = self.store.get(id) else {
                return code(TABLE_INVALID);
            };
            // Multi-table slaves run on position tables (seed 4.6.2).
            if matches!(cam, CamProfile::MotionFunction(_)) {
                return code(TableErrorCode::McTableTypeInvalid as u32);
            }
            specs.push(TableSpec {
                table: id,
                profile: k < profiles,
                periodic: self.select_periodic(id, cam),
                weight: self.weights[id as usize],
                cam,
            });
        }
        let Some(m) = axes.axis(master).map(|a| a.setpoint()) else {
            return code(CamCouplingError::NoSuchMaster.raw());
        };
        let slave_at = axes.axis(slave).map_or(0.0, |a| a.setpoint().position);
        let law = match MultiTableLaw::new(&specs, m.position, slave_at) {
            Ok(law) => law,
            Err(MultiTableError::Parameter { .. }) => {
                return code(CamCouplingError::BadParameter.raw())
            }
            Err(_) => return code(CamCouplingError::UnknownMode.raw()),
        };
        if let Err(e) = couple_cam(axes, slave, master, AxisState::SlaveSynchronous) {
            return code(e);
        }
        if let Some(stale) = self.slaves[slave].take() {
            self.retired.extend(stale.own);
            self.retired.extend(stale.switch_own);
        }
        self.multis[slave] = Some(MultiSlave { master, law });
        accepted()
    }

    fn multi_table(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let call: CamMultiTableCall = decode_body(request)?;
        let Some(m) = self
            .multis
            .get_mut(request.target as usize)
            .and_then(Option::as_mut)
        else {
            return code(CamCouplingError::NotCamCoupled.raw());
        };
        let done = match call.op {
            CAM_MULTI_ENABLE_CORRECTION => {
                if call.flags & 1 != 0 && !call.position.is_finite() {
                    return code(CamCouplingError::BadParameter.raw());
                }
                let at = (call.flags & 1 != 0).then_some(call.position);
                m.law.enable_correction(call.table, at)
            }
            CAM_MULTI_STOP_CYCLIC => m.law.stop_cyclic(call.table),
            _ => return code(CamCouplingError::UnknownMode.raw()),
        };
        match done {
            Ok(()) => accepted(),
            Err(_) => code(TABLE_INVALID),
        }
    }

    /// The master's motion over the last tick in the cam of a coupling that uses table `id`
    /// (standing at 0 when none does): what an online change's activation is checked against.
    fn master_now_of(&self, id: u32, axes: &AxisSet) -> MasterNow {
        for s in self.slaves.iter().flatten().filter(|s| s.table == id) {
            if let Some(m) = master_of(axes, s.master, s.follow_actual) {
                // Between ticks the master's direction comes from its velocity.
                return s.law.master_now(m.position - m.velocity * 1e-3, m.position);
            }
        }
        MasterNow::standing(0.0)
    }

    fn points_write(&mut self, request: &AcyclicRequest, axes: &AxisSet) -> HandlerResult {
        let call: CamPointsWriteCall = decode_body(request)?;
        let id = request.target;
        if !(1..=255).contains(&id) {
            return code(TABLE_INVALID);
        }
        let slot = id as usize;
        let count = call.count as usize;
        if count == 0 || count > CAM_POINTS_PER_CALL || call.total == 0 {
            self.points_in[slot] = None;
            return code(TableErrorCode::NumPointsInvalid as u32);
        }
        let create = call.flags & CAM_POINTS_CREATE != 0;
        if call.flags & CAM_CHUNK_FIRST != 0 {
            // A new transfer: whatever an earlier one left unfinished goes.
            if create && self.in_use(id) {
                self.points_in[slot] = None;
                return code(CamCouplingError::TableInUse.raw());
            }
            self.points_in[slot] = Some(PointsTransfer {
                first: call.first,
                total: call.total,
                create,
                points: Vec::with_capacity(call.total.min(1 << 16) as usize),
            });
        }
        let Some(transfer) = self.points_in[slot].as_mut() else {
            return code(CamCouplingError::ChunkOutOfOrder.raw());
        };
        let continues = transfer.total == call.total
            && transfer.create == create
            && call.first == transfer.first + transfer.points.len() as u32
            && transfer.points.len() + count <= call.total as usize;
        if !continues {
            self.points_in[slot] = None;
            return code(CamCouplingError::ChunkOutOfOrder.raw());
        }
        transfer
            .points
            .extend(call.points[..count].iter().map(point_from_plc));
        if call.flags & CAM_CHUNK_LAST == 0 {
            return accepted();
        }
        let transfer = self.points_in[slot].take().expect("filled above");
        if transfer.points.len() != transfer.total as usize {
            return code(CamCouplingError::ChunkOutOfOrder.raw());
        }
        if transfer.create {
            if self.in_use(id) {
                return code(CamCouplingError::TableInUse.raw());
            }
            return match MotionFunction::new(&transfer.points) {
                Ok(f) => {
                    let _ = self.store.insert(id, CamProfile::MotionFunction(f));
                    self.selects[slot] = None;
                    accepted()
                }
                Err(e) => code(e.code() as u32),
            };
        }
        let now = self.master_now_of(id, axes);
        match self
            .store
            .write_points(id, transfer.first, &transfer.points, now)
        {
            Ok(_) => {
                // A table no coupling uses takes an instantaneous change here (the ticks
                // apply changes to coupled tables); a positional one waits for a coupling.
                if !self.in_use(id) {
                    if let Ok(Some(replaced)) = self.store.apply_due(id, now) {
                        drop(replaced);
                    }
                }
                accepted()
            }
            Err(e) => code(e.code() as u32),
        }
    }

    fn points_read(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let call: CamPointsReadCall = decode_body(request)?;
        let refuse = |e: u32| {
            reply(&CamPointsReply {
                error_id: e,
                ..CamPointsReply::default()
            })
        };
        let function = match self.store.get(request.target) {
            Ok(CamProfile::MotionFunction(f)) => f,
            Ok(_) => return refuse(TableErrorCode::McTableTypeInvalid as u32),
            Err(_) => return refuse(TABLE_INVALID),
        };
        let all = function.points();
        let total = all.len() as u32;
        if call.first == 0 || call.first > total {
            return refuse(TableErrorCode::PointIdInvalid as u32);
        }
        let wanted = match call.count as usize {
            0 => CAM_POINTS_PER_CALL,
            n => n.min(CAM_POINTS_PER_CALL),
        };
        let from = call.first as usize - 1;
        let chunk = &all[from..(from + wanted).min(all.len())];
        let mut out = CamPointsReply {
            count: chunk.len() as u32,
            total,
            ..CamPointsReply::default()
        };
        for (o, p) in out.points.iter_mut().zip(chunk) {
            *o = point_to_plc(p);
        }
        reply(&out)
    }

    fn online_mode(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let call: CamOnlineModeCall = decode_body(request)?;
        let id = request.target;
        let (Some(master_mode), Some(slave_mode)) = (
            ScalingMode::from_raw(call.master_scaling_mode),
            ScalingMode::from_raw(call.slave_scaling_mode),
        ) else {
            return code(CamCouplingError::UnknownMode.raw());
        };
        if !call.activation_position.is_finite() {
            return code(CamCouplingError::BadParameter.raw());
        }
        let Ok(queue) = self.store.queue_mut(id) else {
            return code(TABLE_INVALID);
        };
        if call.activation_mode == 7 {
            queue.delete_queued();
            return accepted();
        }
        match ActivationMode::from_raw(call.activation_mode, call.activation_position) {
            Ok(mode) => queue.set_mode(mode),
            Err(_) => return code(CamCouplingError::ModeCombination.raw()),
        }
        self.online_scaling[id as usize] = (master_mode, slave_mode);
        accepted()
    }

    fn rows_write(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let mut call: CamRowsWriteCall = decode_body(request)?;
        let id = request.target;
        if !(1..=255).contains(&id) {
            return code(TABLE_INVALID);
        }
        let slot = id as usize;
        if call.flags & CAM_ROWS_DECLARE != 0 {
            // CamTableCreate: the table's type and size, for the rows that follow.
            if call.count != 0 || call.total < 2 {
                return code(TableErrorCode::NumRowsInvalid as u32);
            }
            if !matches!(call.table_type, 10 | 11) {
                return code(TableErrorCode::McTableTypeInvalid as u32);
            }
            self.declared[slot] = Some((
                call.table_type,
                call.interpolation,
                call.periodic,
                call.total,
            ));
            self.rows_in[slot] = None;
            return accepted();
        }
        if call.table_type == 0 {
            // Rows for a declared table (CamTableWriteData).
            let Some((table_type, interpolation, periodic, total)) = self.declared[slot] else {
                return code(TableErrorCode::McTableTypeInvalid as u32);
            };
            if call.total > total {
                return code(TableErrorCode::NumRowsInvalid as u32);
            }
            call.table_type = table_type;
            call.interpolation = interpolation;
            call.periodic = periodic;
        }
        let count = call.count as usize;
        if count == 0 || count > CAM_ROWS_PER_CALL || call.total == 0 {
            self.rows_in[slot] = None;
            return code(TableErrorCode::NumRowsInvalid as u32);
        }
        if call.flags & CAM_CHUNK_FIRST != 0 {
            // A new transfer, refused at once for a table in use.
            if self.in_use(id) {
                self.rows_in[slot] = None;
                return code(CamCouplingError::TableInUse.raw());
            }
            self.rows_in[slot] = Some(RowsTransfer {
                total: call.total,
                table_type: call.table_type,
                interpolation: call.interpolation,
                periodic: call.periodic,
                rows: Vec::with_capacity(call.total.min(1 << 20) as usize),
            });
        }
        let Some(transfer) = self.rows_in[slot].as_mut() else {
            return code(CamCouplingError::ChunkOutOfOrder.raw());
        };
        let continues = transfer.total == call.total
            && transfer.table_type == call.table_type
            && transfer.interpolation == call.interpolation
            && transfer.periodic == call.periodic
            && call.first_row as usize == transfer.rows.len()
            && transfer.rows.len() + count <= call.total as usize;
        if !continues {
            self.rows_in[slot] = None;
            return code(CamCouplingError::ChunkOutOfOrder.raw());
        }
        transfer.rows.extend_from_slice(&call.rows[..count]);
        if call.flags & CAM_CHUNK_LAST == 0 {
            return accepted();
        }
        let transfer = self.rows_in[slot].take().expect("filled above");
        if transfer.rows.len() != transfer.total as usize {
            return code(CamCouplingError::ChunkOutOfOrder.raw());
        }
        let table_type = match transfer.table_type {
            10 => TableType::Equidistant,
            11 => TableType::NonEquidistant,
            _ => return code(TableErrorCode::McTableTypeInvalid as u32),
        };
        let interpolation = match transfer.interpolation {
            0 => Interpolation::Linear,
            1 => Interpolation::FourPoint,
            2 => Interpolation::Spline,
            _ => return code(CamCouplingError::UnknownMode.raw()),
        };
        if transfer.periodic > 1 {
            return code(CamCouplingError::UnknownMode.raw());
        }
        if self.in_use(id) {
            return code(CamCouplingError::TableInUse.raw());
        }
        match PositionTable::new(
            &transfer.rows,
            table_type,
            interpolation,
            transfer.periodic == 1,
        ) {
            Ok(t) => {
                let _ = self.store.insert(id, CamProfile::Table(t));
                self.selects[slot] = None;
                accepted()
            }
            Err(e) => code(e.code() as u32),
        }
    }

    fn read(&self, request: &AcyclicRequest, axes: &AxisSet) -> HandlerResult {
        let call: CamReadCall = decode_body(request)?;
        let id = request.target;
        let profile = |id: u32| self.store.get(id).map_err(|_| TABLE_INVALID);
        let finite = |v: f64| {
            v.is_finite()
                .then_some(v)
                .ok_or(CamCouplingError::BadParameter.raw())
        };
        let skip = call.part as usize * CAM_VALUES_PER_REPLY;
        let mut columns = 1u32;
        // A values read makes only the part asked for; the others make all and are cut here.
        let mut made_from = 0;
        let answer: Result<(Vec<f64>, usize), u32> = match call.what {
            CAM_READ_SLAVE_DYNAMICS => profile(id).and_then(|p| {
                let x = finite(call.a)?;
                let (lo, hi) = p.master_range();
                let s = p.eval(
                    x.clamp(lo.min(hi), lo.max(hi)),
                    &mut ProfileCursor::default(),
                );
                // What each table type gives (seed 5.1.7): motion functions all three,
                // equidistant tables position and velocity, others position.
                let v = match p {
                    CamProfile::MotionFunction(_) => [s.position, s.velocity, s.acceleration],
                    CamProfile::Table(t) if t.table_type() == TableType::Equidistant => {
                        [s.position, s.velocity, 0.0]
                    }
                    CamProfile::Table(_) => [s.position, 0.0, 0.0],
                };
                Ok((v.to_vec(), 3))
            }),
            CAM_READ_CHARACTERISTICS => profile(id).map(|p| {
                let values: Vec<f64> = crate::cam::CharacValues::normed(p)
                    .fields()
                    .iter()
                    .map(|(_, v)| *v)
                    .collect();
                let n = values.len();
                (values, n)
            }),
            CAM_READ_VALUES => profile(id).and_then(|p| {
                let (from, to, step) = (finite(call.a)?, finite(call.b)?, finite(call.c)?);
                if call.mask == 0 || call.mask > 15 {
                    return Err(crate::cam::CamError::ValueMask { mask: call.mask }.code() as u32);
                }
                let rows = crate::cam::charac::sample_count(from, to, step, 1 << 20)
                    .map_err(|e| e.code() as u32)?;
                columns = 1 + call.mask.count_ones();
                let cols = columns as usize;
                let total = rows * cols;
                // Only the rows of the part asked for are evaluated.
                let mut values = Vec::with_capacity(CAM_VALUES_PER_REPLY);
                let mut cursor = ProfileCursor::default();
                let mut row_cache: Option<(usize, [f64; 5])> = None;
                for i in skip..(skip + CAM_VALUES_PER_REPLY).min(total) {
                    let (row, col) = (i / cols, i % cols);
                    let cells = match row_cache {
                        Some((r, c)) if r == row => c,
                        _ => {
                            let x = from + step * row as f64;
                            let s = p.eval(x, &mut cursor);
                            let mut c = [x, 0.0, 0.0, 0.0, 0.0];
                            let mut k = 1;
                            for (bit, v) in [s.position, s.velocity, s.acceleration, s.jerk]
                                .iter()
                                .enumerate()
                            {
                                if call.mask & (1 << bit) != 0 {
                                    c[k] = *v;
                                    k += 1;
                                }
                            }
                            row_cache = Some((row, c));
                            c
                        }
                    };
                    values.push(cells[col]);
                }
                made_from = skip;
                Ok((values, total))
            }),
            CAM_READ_ROWS => match profile(id) {
                Ok(CamProfile::Table(t)) => {
                    let total = t.len() * 2;
                    columns = 2;
                    made_from = skip;
                    // Only the rows of this part.
                    let values: Vec<f64> = (skip..(skip + CAM_VALUES_PER_REPLY).min(total))
                        .filter_map(|i| t.row_at(i / 2).map(|r| r[i % 2]))
                        .collect();
                    Ok((values, total))
                }
                Ok(_) => Err(TableErrorCode::McTableTypeInvalid as u32),
                Err(e) => Err(e),
            },
            CAM_READ_INFO => self.info(id as usize, &call, axes).map(|v| {
                let n = v.len();
                (v, n)
            }),
            _ => Err(CamCouplingError::UnknownMode.raw()),
        };
        let (values, total) = match answer {
            Ok(v) => v,
            Err(e) => {
                return reply(&CamValuesReply {
                    error_id: e,
                    ..CamValuesReply::default()
                })
            }
        };
        let mut out = CamValuesReply {
            total: total as u32,
            columns,
            ..CamValuesReply::default()
        };
        for (o, v) in out
            .values
            .iter_mut()
            .zip(values.iter().skip(skip - made_from.min(skip)))
        {
            *o = *v;
            out.count += 1;
        }
        reply(&out)
    }

    /// The 40 values of MC_CamInfoData for slave `slave`, at the master's set-point or at
    /// `call.a`.
    fn info(&self, slave: usize, call: &CamReadCall, axes: &AxisSet) -> Result<Vec<f64>, u32> {
        let Some(s) = self.slaves.get(slave).and_then(Option::as_ref) else {
            return Err(CamCouplingError::NotCamCoupled.raw());
        };
        let stored = self.store.get(s.table).map_err(|_| TABLE_INVALID)?;
        let profile = s.own.as_ref().unwrap_or(stored);
        let master_now = axes
            .axis(s.master)
            .map_or(s.master_before, |a| a.setpoint().position);
        let at = if call.flags & 1 != 0 {
            if !call.a.is_finite() {
                return Err(CamCouplingError::BadParameter.raw());
            }
            call.a
        } else {
            master_now
        };
        let standing = Kinematic {
            position: at,
            ..Kinematic::default()
        };
        let (slave_set, cam) = s
            .law
            .slave(profile, &mut ProfileCursor::default(), &standing);
        let (first, period) = s.law.range();
        let first_slave = profile.eval(first, &mut ProfileCursor::default()).position;
        let (rows, columns, interpolation) = match profile {
            CamProfile::MotionFunction(f) => (f.points().len(), 1, 0),
            CamProfile::Table(t) => (
                t.len(),
                2,
                match t.interpolation() {
                    Interpolation::Linear => 0,
                    Interpolation::FourPoint => 1,
                    Interpolation::Spline => 2,
                },
            ),
        };
        let sc = s.law.scaling;
        let flag = |b: bool| f64::from(u8::from(b));
        let raw_cam = (slave_set.position - s.law.slave_origin - sc.slave_offset)
            / if sc.slave_scaling != 0.0 {
                sc.slave_scaling
            } else {
                1.0
            };
        let (scale_q, scale_mode, scale_modes) = match s.scale {
            Some(Queued::Scale {
                activation, modes, ..
            }) => (true, activation.raw(), modes),
            _ => (
                false,
                (0, 0.0),
                (ScalingMode::UserDefined, ScalingMode::UserDefined),
            ),
        };
        let queue_mode = self
            .store
            .queue(s.table)
            .map(|q| (q.is_queued(), q.mode().raw()))
            .unwrap_or((false, (0, 0.0)));
        let online = self.online_scaling[s.table as usize];
        let (switch_q, switch_id, switch_mode, switch_modes) = match s.switch {
            Some(Queued::Switch {
                table,
                activation,
                modes,
                ..
            }) => (true, table, activation.raw(), modes),
            _ => (
                false,
                0,
                (0, 0.0),
                (ScalingMode::UserDefined, ScalingMode::UserDefined),
            ),
        };
        Ok(vec![
            f64::from(s.table),
            f64::from(profile.table_type_raw()),
            flag(s.law.periodic),
            f64::from(interpolation),
            rows as f64,
            f64::from(columns),
            first,
            first_slave,
            period,
            s.law.stroke(),
            s.coupled_at.0,
            s.coupled_at.1,
            flag(!s.law.start.master_relative()),
            flag(!s.law.start.slave_relative()),
            sc.master_offset,
            sc.slave_offset,
            sc.master_scaling,
            sc.slave_scaling,
            sc.slave_scaling * s.law.stroke() * s.law.cycles_since_coupling(at) as f64,
            0.0,
            at,
            slave_set.position,
            cam.x,
            raw_cam,
            flag(scale_q),
            f64::from(scale_mode.0),
            scale_mode.1,
            f64::from(scale_modes.0.raw()),
            f64::from(scale_modes.1.raw()),
            flag(queue_mode.0),
            f64::from(queue_mode.1 .0),
            queue_mode.1 .1,
            f64::from(online.0.raw()),
            f64::from(online.1.raw()),
            flag(switch_q),
            f64::from(switch_id),
            f64::from(switch_mode.0),
            switch_mode.1,
            f64::from(switch_modes.0.raw()),
            f64::from(switch_modes.1.raw()),
        ])
    }

    fn table_delete(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let _: CamTableDeleteCall = decode_body(request)?;
        let id = request.target;
        if self.store.get(id).is_err() {
            return code(TABLE_INVALID);
        }
        if self.in_use(id) {
            return code(CamCouplingError::TableInUse.raw());
        }
        if let Ok(old) = self.store.remove(id) {
            drop(old);
        }
        let slot = id as usize;
        self.selects[slot] = None;
        self.declared[slot] = None;
        self.weights[slot] = TableWeight::default();
        accepted()
    }

    fn cam_out(&mut self, request: &AcyclicRequest, axes: &mut AxisSet) -> HandlerResult {
        let _: CamOutCall = decode_body(request)?;
        let slave = request.target as usize;
        if slave >= axes.len() {
            return Err(ErrorCode::InvalidTarget);
        }
        let cam_coupled = axes
            .axis(slave)
            .and_then(|a| a.coupling())
            .is_some_and(|c| c.kind == CouplingState::Cam);
        if cam_coupled && self.multis[slave].take().is_some() {
            if let Some(axis) = axes.axis_mut(slave) {
                axis.decouple();
            }
            return accepted();
        }
        let Some(state) = self.slaves[slave].take().filter(|_| cam_coupled) else {
            return code(CamCouplingError::NotCamCoupled.raw());
        };
        if let Some(axis) = axes.axis_mut(slave) {
            axis.decouple();
        }
        drop(state);
        accepted()
    }

    fn cam_scaling(&mut self, request: &AcyclicRequest, axes: &AxisSet) -> HandlerResult {
        let call: CamScalingCall = decode_body(request)?;
        let slave = request.target as usize;
        if slave >= axes.len() {
            return Err(ErrorCode::InvalidTarget);
        }
        let (Some(activation), Some(master_mode), Some(slave_mode)) = (
            Activation::from_raw(call.activation_mode, call.activation_position),
            ScalingMode::from_raw(call.master_scaling_mode),
            ScalingMode::from_raw(call.slave_scaling_mode),
        ) else {
            return code(CamCouplingError::UnknownMode.raw());
        };
        let Some(state) = self.slaves[slave].as_mut() else {
            return code(CamCouplingError::NotCamCoupled.raw());
        };
        if !state.active {
            return code(CamCouplingError::CouplingPending.raw());
        }
        if let Err(e) = check_scaling(
            activation,
            state.law.start,
            master_mode == ScalingMode::AutoOffset,
        ) {
            return code(coupling_code(e));
        }
        if activation == Activation::Off {
            return accepted();
        }
        // Only the values that take part must be usable (the keep bits of the compatibility
        // blocks leave single values as they are); they merge again when it applies.
        let requested = Scaling {
            master_offset: call.master_offset,
            slave_offset: call.slave_offset,
            master_scaling: call.master_scaling,
            slave_scaling: call.slave_scaling,
        };
        let scaling = merged_scaling(
            state.law.scaling,
            requested,
            call.reserved,
            (master_mode, slave_mode),
        );
        if let Err(e) = scaling.check() {
            return code(coupling_code(e));
        }
        if !call.activation_position.is_finite() {
            return code(CamCouplingError::BadParameter.raw());
        }
        let master = axes.axis(state.master).map(|a| a.setpoint());
        let Some(master) = master else {
            return code(CamCouplingError::NoSuchMaster.raw());
        };
        let now = MasterNow {
            axis: (master.position - master.velocity, master.position),
            ..MasterNow::default()
        };
        if let Err(e) = check_not_passed(activation, now) {
            return code(coupling_code(e));
        }
        state.scale = Some(Queued::Scale {
            requested: Scaling {
                master_offset: call.master_offset,
                slave_offset: call.slave_offset,
                master_scaling: call.master_scaling,
                slave_scaling: call.slave_scaling,
            },
            keep: call.reserved,
            modes: (master_mode, slave_mode),
            activation: activation.timing().expect("checked: a timed mode"),
        });
        accepted()
    }
}

impl CamEngine {
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
                );
                other.cursor = ProfileCursor::default();
            }
            self.retired_changes.push(old);
        }
    }
}

impl Engine for CamEngine {
    fn name(&self) -> &'static str {
        "cam"
    }

    fn holds_table(&self, id: u32) -> bool {
        self.store.get(id).is_ok()
    }

    fn tick(&mut self, io: &mut EngineIo<'_, '_>) {
        for i in 0..self.multis.len() {
            let Some(multi) = self.multis[i].as_mut() else {
                continue;
            };
            let still = io
                .axes
                .axis(i)
                .and_then(|a| a.coupling())
                .is_some_and(|c| c.kind == CouplingState::Cam);
            let master = io.axes.axis(multi.master).map(|a| a.setpoint());
            let (true, Some(master)) = (still, master) else {
                self.multis[i] = None;
                continue;
            };
            let set = multi.law.slave(&self.store, &master);
            if let Some(axis) = io.axes.axis_mut(i) {
                axis.drive_coupled(set, AxisState::SlaveSynchronous);
            }
        }
        self.apply_point_changes(io.axes);
        for i in 0..self.slaves.len() {
            let Some(state) = self.slaves[i].as_mut() else {
                continue;
            };
            // A slave that lost its coupling (fault, power off) is free again.
            let still = io
                .axes
                .axis(i)
                .and_then(|a| a.coupling())
                .is_some_and(|c| c.kind == CouplingState::Cam);
            let master = master_of(io.axes, state.master, state.follow_actual);
            let (true, Some(master)) = (still, master) else {
                if let Some(gone) = self.slaves[i].take() {
                    self.retired.extend(gone.own);
                    self.retired.extend(gone.switch_own);
                }
                continue;
            };
            let now = state.law.master_now(state.master_before, master.position);
            let Ok(stored) = self.store.get(state.table) else {
                continue;
            };
            let profile = state.own.as_ref().unwrap_or(stored);
            let (mut set, _) = state.law.slave(profile, &mut state.cursor, &master);
            if state.waiting.is_some_and(|t| t.due(now)) {
                // Relative sides start from here; the cycle counter too.
                state.law = CamLaw::new(
                    profile,
                    state.law.scaling,
                    state.law.start,
                    state.law.periodic,
                    master.position,
                    state.hold,
                );
                state.active = true;
                state.waiting = None;
                state.coupled_at = (master.position, state.hold);
                set = state.law.slave(profile, &mut state.cursor, &master).0;
            }
            if let Some(Queued::Scale {
                requested,
                keep,
                modes,
                activation,
            }) = state.scale.filter(|_| state.active)
            {
                if activation.due(now) {
                    let law = state.law;
                    let scaling = merged_scaling(law.scaling, requested, keep, modes);
                    state.law = law.rescaled(
                        profile,
                        scaling,
                        modes,
                        law.start,
                        law.periodic,
                        master.position,
                        set.position,
                        false,
                    );
                    state.scale = None;
                    set = state.law.slave(profile, &mut state.cursor, &master).0;
                }
            }
            if let Some(Queued::Switch {
                table,
                scaling,
                modes,
                start,
                activation,
            }) = state.switch.filter(|_| state.active)
            {
                if activation.due(now) {
                    let stored_next = self.store.get(table).ok();
                    if let Some(next) = state.switch_own.as_ref().or(stored_next) {
                        let periodic = periodic_of(&self.selects, table, next);
                        let law = state.law;
                        state.law = law.rescaled(
                            next,
                            scaling,
                            modes,
                            start,
                            periodic,
                            master.position,
                            set.position,
                            true,
                        );
                        state.table = table;
                        state.cursor = ProfileCursor::default();
                        set = state.law.slave(next, &mut state.cursor, &master).0;
                        // The switched-to cam's own copy becomes the coupling's.
                        let next_own = state.switch_own.take();
                        if let Some(old) = core::mem::replace(&mut state.own, next_own) {
                            self.retired.push(old);
                        }
                    }
                    state.switch = None;
                }
            }
            // A law that cannot give a finite set-point (extreme scalings) releases the
            // slave rather than pass the number on.
            let finite = set.position.is_finite()
                && set.velocity.is_finite()
                && set.acceleration.is_finite()
                && set.jerk.is_finite();
            if !finite {
                if let Some(axis) = io.axes.axis_mut(i) {
                    axis.decouple();
                }
                continue;
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
            if let Some(axis) = io.axes.axis_mut(i) {
                axis.drive_coupled(set, phase);
            }
            state.master_before = master.position;
        }
    }

    fn handle(
        &mut self,
        kind: CallKind,
        request: &AcyclicRequest,
        axes: &mut AxisSet,
    ) -> Option<HandlerResult> {
        // Between ticks: free what the ticks retired.
        self.retired.clear();
        self.retired_changes.clear();
        Some(match kind {
            CallKind::CamTableSelect => self.table_select(request),
            CallKind::CamIn => self.cam_in(request, axes),
            CallKind::CamOut => self.cam_out(request, axes),
            CallKind::CamScaling => self.cam_scaling(request, axes),
            CallKind::CamPointsWrite => self.points_write(request, axes),
            CallKind::CamPointsRead => self.points_read(request),
            CallKind::CamOnlineMode => self.online_mode(request),
            CallKind::CamRowsWrite => self.rows_write(request),
            CallKind::CamRead => self.read(request, axes),
            CallKind::CamTableWeight => self.table_weight(request),
            CallKind::CamMultiCouple => self.multi_couple(request, axes),
            CallKind::CamMultiTable => self.multi_table(request),
            CallKind::CamTableDelete => self.table_delete(request),
            _ => return None,
        })
    }

    fn reset(&mut self, axes: &mut AxisSet) {
        for (i, slot) in self.multis.iter_mut().enumerate() {
            if slot.take().is_some() {
                if let Some(axis) = axes.axis_mut(i) {
                    axis.decouple();
                }
            }
        }
        for (i, slot) in self.slaves.iter_mut().enumerate() {
            if let Some(state) = slot.take() {
                if let Some(axis) = axes.axis_mut(i) {
                    axis.decouple();
                }
                self.retired.extend(state.own);
                self.retired.extend(state.switch_own);
            }
        }
    }
}

fn point_from_plc(p: &McMotionFunctionPoint) -> MotionFunctionPoint {
    MotionFunctionPoint {
        index: p.point_index,
        function: p.function_type,
        point_type: p.point_type,
        rel_index_next: i64::from(p.rel_index_next_point),
        master: p.master_pos,
        slave: p.slave_pos,
        velocity: p.slave_velo,
        acceleration: p.slave_acc,
        jerk: p.slave_jerk,
    }
}

fn point_to_plc(p: &MotionFunctionPoint) -> McMotionFunctionPoint {
    McMotionFunctionPoint {
        point_index: p.index,
        function_type: p.function,
        point_type: p.point_type,
        rel_index_next_point: u32::try_from(p.rel_index_next.max(0)).unwrap_or(u32::MAX),
        master_pos: p.master,
        slave_pos: p.slave,
        slave_velo: p.velocity,
        slave_acc: p.acceleration,
        slave_jerk: p.jerk,
    }
}
