//! The coupling calls: MC_CamTableSelect, MC_CamIn / MC_CamInExt (a first coupling, or a
//! queued switch of cams), MC_CamOut, MC_CamScaling, and the multi-table slave's
//! CamTableSetWeight, coupling and table operations. Each checks the whole request before it
//! changes anything; the tick (`super`) applies what they queue.

use super::{
    accepted, code, coupling_code, master_of, merged_scaling, CamEngine, MultiSlave, Queued,
    Select, Slave, TABLE_INVALID,
};
use crate::axis::{AxisSet, Coupling, Lease};
use crate::cam::coupling::{
    check_couple, check_not_passed, check_scaling, check_switch, Activation, CamLaw, Scaling,
};
use crate::cam::multi_table::{
    check_weight, MultiTableError, MultiTableLaw, TableSpec, TableWeight,
};
use crate::cam::online::MasterNow;
use crate::cam::{CamProfile, PositionTable, ProfileCursor, TableErrorCode};
use crate::setpoint::Kinematic;
use hli::calls::cam::CamCouplingError;
use hli::calls::cam::{
    CamInCall, CamInterpolation, CamMultiCoupleCall, CamMultiTableCall, CamMultiTableOp,
    CamOutCall, CamScalingCall, CamScalingMode, CamStartMode, CamTableSelectCall,
};
use hli::calls::{decode_body, ErrorCode, HandlerResult};
use hli::enums::{AxisError, AxisState, CouplingState};
use hli::wire::AcyclicRequest;

/// Couples axis `slave` to `master` as a cam slave in `phase`; the axis layer's refusal code.
fn couple_cam(
    axes: &mut AxisSet,
    slave: usize,
    master: usize,
    phase: AxisState,
) -> Result<Lease, u32> {
    if axes.axis(slave).is_none() {
        return Err(CamCouplingError::NotCamCoupled.raw());
    }
    let coupling = Coupling {
        kind: CouplingState::Cam,
        master: master as i32,
        phase,
    };
    axes.couple(slave, coupling).map_err(AxisError::raw)
}

/// MC_CamIn's request, checked: what a switch or a first coupling is made of.
struct CamInAsk {
    master: usize,
    start: CamStartMode,
    activation: Activation,
    /// Master and slave scaling modes.
    modes: (CamScalingMode, CamScalingMode),
    scaling: Scaling,
    /// The table interpolated as asked, when that differs from the stored one.
    own: Option<CamProfile>,
    follow_actual: bool,
    /// The master's set-point (or actual position) now.
    master_set: Kinematic,
    /// The master's motion, for an activation already passed.
    now: MasterNow,
}

impl CamInAsk {
    /// The master side takes its offset from the coupling (AutoOffset).
    fn master_auto(&self) -> bool {
        self.modes.0 == CamScalingMode::AutoOffset
    }
}

impl CamEngine {
    pub(super) fn table_select(&mut self, request: &AcyclicRequest) -> HandlerResult {
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
            absolute: (call.master_absolute == 1, call.slave_absolute == 1),
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
        let Some(wanted) = CamInterpolation::from_raw(interpolation) else {
            return Err(CamCouplingError::UnknownMode.raw());
        };
        if wanted == t.interpolation() {
            return Ok(None);
        }
        let rows: Vec<[f64; 2]> = t.rows().collect();
        PositionTable::new(&rows, t.table_type(), wanted, t.periodic())
            .map(|t| Some(CamProfile::Table(t)))
            .map_err(|e| e.code() as u32)
    }

    pub(super) fn cam_in(&mut self, request: &AcyclicRequest, axes: &mut AxisSet) -> HandlerResult {
        let call: CamInCall = decode_body(request)?;
        let slave = request.target as usize;
        if slave >= axes.len() {
            return Err(ErrorCode::InvalidTarget);
        }
        let ask = match self.cam_in_ask(&call, slave, axes) {
            Ok(ask) => ask,
            Err(e) => return code(e),
        };
        let Some(axis) = axes.axis(slave) else {
            return Err(ErrorCode::InvalidTarget);
        };
        match (axis.coupling(), self.slaves[slave].as_ref()) {
            // Coupled through a cam already: a switch (MC_CamInExt both times) or a refusal.
            (Some(_), Some(s)) if axes.holds(s.lease) => self.queue_switch(slave, &call, ask),
            (Some(_), _) => code(AxisError::Coupled.raw()),
            (None, _) => self.couple_first(slave, &call, ask, axes),
        }
    }

    /// MC_CamIn's values checked (of an existing slave axis), its table's profile made and
    /// the master's set-point read: `Err` is the code of a refusal.
    fn cam_in_ask(&self, call: &CamInCall, slave: usize, axes: &AxisSet) -> Result<CamInAsk, u32> {
        let master = call.master as usize;
        if master >= axes.len() {
            return Err(CamCouplingError::NoSuchMaster.raw());
        }
        if master == slave {
            return Err(CamCouplingError::MasterIsSlave.raw());
        }
        // MC_CamTableSelect's MasterAbsolute/SlaveAbsolute choose absolute or relative
        // (FALSE: relative); MC_CamIn's StartMode 0 takes that choice (a table never selected:
        // absolute), and an explicit StartMode must say the same.
        let selected = self.selects.get(call.table_id as usize).copied().flatten();
        let chosen = selected.map(|s| start_of(s.absolute));
        let given = match call.start_mode {
            0 => Some(chosen.unwrap_or(CamStartMode::Absolute)),
            raw => CamStartMode::from_raw(raw),
        };
        let (Some(start), Some(activation), Some(master_mode), Some(slave_mode)) = (
            given,
            Activation::from_raw(call.activation_mode, call.activation_position),
            CamScalingMode::from_raw(call.master_scaling_mode),
            CamScalingMode::from_raw(call.slave_scaling_mode),
        ) else {
            return Err(CamCouplingError::UnknownMode.raw());
        };
        if call.extended > 1 || call.master_source > 1 || !call.activation_position.is_finite() {
            return Err(CamCouplingError::BadParameter.raw());
        }
        // The selection and an explicit StartMode say the same thing twice: one that says
        // otherwise is refused rather than one of the two silently ignored.
        if chosen.is_some_and(|c| c != start) {
            return Err(CamCouplingError::ModeCombination.raw());
        }
        let scaling = Scaling {
            master_offset: call.master_offset,
            slave_offset: call.slave_offset,
            master_scaling: call.master_scaling,
            slave_scaling: call.slave_scaling,
        };
        if let Err(e) = scaling.check() {
            return Err(coupling_code(e));
        }
        let own = self.profile_for(call.table_id, call.interpolation)?;
        let follow_actual = call.master_source == 1;
        let Some(master_set) = master_of(axes, master, follow_actual) else {
            return Err(CamCouplingError::NoSuchMaster.raw());
        };
        // The master's direction of travel decides whether an axis position lies behind it.
        let now = MasterNow {
            axis: (
                master_set.position - master_set.velocity,
                master_set.position,
            ),
            ..MasterNow::default()
        };
        Ok(CamInAsk {
            master,
            start,
            activation,
            modes: (master_mode, slave_mode),
            scaling,
            own,
            follow_actual,
            master_set,
            now,
        })
    }

    /// MC_CamInExt on a slave coupled with MC_CamInExt: queues the switch to `call`'s table
    /// (or deletes the queued one).
    fn queue_switch(&mut self, slave: usize, call: &CamInCall, ask: CamInAsk) -> HandlerResult {
        let current = self.slaves[slave]
            .as_mut()
            .expect("cam_in matched a cam slave");
        if !(current.extended && call.extended == 1) {
            return code(CamCouplingError::NotSwitchable.raw());
        }
        if !current.active {
            return code(CamCouplingError::CouplingPending.raw());
        }
        if current.master != ask.master {
            return code(CamCouplingError::NoSuchMaster.raw());
        }
        if let Err(e) = check_switch(ask.activation, ask.start, ask.master_auto())
            .and_then(|()| check_not_passed(ask.activation, ask.now))
        {
            return code(coupling_code(e));
        }
        if ask.activation == Activation::DeleteQueuedData {
            if current.switch.take().is_some() {
                if let Some(old) = current.switch_own.take() {
                    self.retired.push(old);
                }
            }
            return accepted();
        }
        if let Some(old) = core::mem::replace(&mut current.switch_own, ask.own) {
            self.retired.push(old);
        }
        current.switch = Some(Queued::Switch {
            table: call.table_id,
            scaling: ask.scaling,
            modes: ask.modes,
            start: ask.start,
            activation: ask.activation.timing().expect("checked: a timed mode"),
        });
        accepted()
    }

    /// A first coupling of a free axis: coupled at once, held where it stands (pre-phase)
    /// until its activation.
    fn couple_first(
        &mut self,
        slave: usize,
        call: &CamInCall,
        ask: CamInAsk,
        axes: &mut AxisSet,
    ) -> HandlerResult {
        // Whatever the engine still held for this axis is stale: the axis layer
        // dropped the coupling (a fault, power off).
        self.multis[slave] = None;
        if let Err(e) = check_couple(ask.activation, ask.start, ask.master_auto())
            .and_then(|()| check_not_passed(ask.activation, ask.now))
        {
            return code(coupling_code(e));
        }
        let profile = match &ask.own {
            Some(p) => p,
            None => self
                .store
                .get(call.table_id)
                .map_err(|_| ErrorCode::InvalidData)?,
        };
        let periodic = self.select_periodic(call.table_id, profile);
        let Some(hold) = axes.axis(slave).map(|a| a.engine_setpoint().position) else {
            return Err(ErrorCode::InvalidTarget);
        };
        let master_at = ask.master_set.position;
        let law = CamLaw::new(profile, ask.scaling, ask.start, periodic, master_at, hold);
        let lease = match couple_cam(axes, slave, ask.master, AxisState::SlavePrephase) {
            Ok(lease) => lease,
            Err(e) => return code(e),
        };
        let held = Kinematic {
            position: hold,
            ..Kinematic::default()
        };
        axes.drive(lease, held, AxisState::SlavePrephase);
        let timing = ask.activation.timing().expect("checked: a timed mode");
        // A new coupling: the last one's state, kept after a fault, is no longer the slave's.
        self.lost[slave] = None;
        self.slaves[slave] = Some(Slave {
            lease,
            master: ask.master,
            table: call.table_id,
            own: ask.own,
            switch_own: None,
            law,
            cursor: ProfileCursor::default(),
            active: false,
            extended: call.extended == 1,
            waiting: Some(timing),
            switch: None,
            scale: None,
            master_before: master_at,
            hold,
            coupled_at: (master_at, hold),
            follow_actual: ask.follow_actual,
        });
        accepted()
    }

    pub(super) fn table_weight(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let w: TableWeight = decode_body(request)?;
        let id = request.target;
        if !(1..=255).contains(&id) {
            return code(TABLE_INVALID);
        }
        if check_weight(&w).is_err() {
            return code(CamCouplingError::BadParameter.raw());
        }
        // The seed (000 4.6.3): a table's scaling is set before it becomes active, never
        // while it is; a table of a running coupling that is not active yet takes it.
        if self.multis.iter().flatten().any(|m| m.law.is_active(id)) {
            return code(CamCouplingError::TableInUse.raw());
        }
        for m in self.multis.iter_mut().flatten() {
            // Only the couplings that have the table (checked and not active: no refusal).
            if m.law.tables().any(|t| t == id) {
                let _ = m.law.set_weight(id, w);
            }
        }
        self.weights[id as usize] = w;
        accepted()
    }

    pub(super) fn multi_couple(
        &mut self,
        request: &AcyclicRequest,
        axes: &mut AxisSet,
    ) -> HandlerResult {
        let call: CamMultiCoupleCall = decode_body(request)?;
        let slave = request.target as usize;
        if slave >= axes.len() {
            return Err(ErrorCode::InvalidTarget);
        }
        if call.on == 0 {
            let Some(multi) = self.multis[slave].take() else {
                return code(CamCouplingError::NotCamCoupled.raw());
            };
            // Only its own coupling (another engine may hold the axis since).
            axes.release(multi.lease);
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
        if call.master_source > 1 {
            return code(CamCouplingError::UnknownMode.raw());
        }
        let follow_actual = call.master_source == 1;
        let Some(m) = master_of(axes, master, follow_actual) else {
            return code(CamCouplingError::NoSuchMaster.raw());
        };
        let slave_at = axes
            .axis(slave)
            .map_or(0.0, |a| a.engine_setpoint().position);
        let law = match MultiTableLaw::new(&specs, m.position, slave_at) {
            Ok(law) => law,
            Err(MultiTableError::Parameter { .. }) => {
                return code(CamCouplingError::BadParameter.raw())
            }
            Err(_) => return code(CamCouplingError::UnknownMode.raw()),
        };
        let lease = match couple_cam(axes, slave, master, AxisState::SlaveSynchronous) {
            Ok(lease) => lease,
            Err(e) => return code(e),
        };
        // A new coupling: a cam coupling lost before is no longer the slave's.
        self.lost[slave] = None;
        if let Some(stale) = self.slaves[slave].take() {
            self.retired.extend(stale.own);
            self.retired.extend(stale.switch_own);
        }
        self.multis[slave] = Some(MultiSlave {
            lease,
            master,
            follow_actual,
            law,
        });
        accepted()
    }

    pub(super) fn multi_table(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let call: CamMultiTableCall = decode_body(request)?;
        let Some(m) = self
            .multis
            .get_mut(request.target as usize)
            .and_then(Option::as_mut)
        else {
            return code(CamCouplingError::NotCamCoupled.raw());
        };
        let done = match CamMultiTableOp::from_raw(call.op) {
            Some(CamMultiTableOp::EnableCorrection) => {
                if call.flags & 1 != 0 && !call.position.is_finite() {
                    return code(CamCouplingError::BadParameter.raw());
                }
                let at = (call.flags & 1 != 0).then_some(call.position);
                m.law.enable_correction(call.table, at)
            }
            Some(CamMultiTableOp::StopCyclic) => m.law.stop_cyclic(call.table),
            None => return code(CamCouplingError::UnknownMode.raw()),
        };
        match done {
            Ok(()) => accepted(),
            Err(_) => code(TABLE_INVALID),
        }
    }

    pub(super) fn cam_out(
        &mut self,
        request: &AcyclicRequest,
        axes: &mut AxisSet,
    ) -> HandlerResult {
        let _: CamOutCall = decode_body(request)?;
        let slave = request.target as usize;
        if slave >= axes.len() {
            return Err(ErrorCode::InvalidTarget);
        }
        // A coupling lost to a fault counts as coupled until this decoupling (seed 000
        // 5.1.15: MC_CamInfo before decoupling); MC_CamInfo reads nothing after it.
        // (Not when another engine has coupled the axis since: that coupling is not ours.)
        let was_lost = self.lost[slave].take().is_some()
            && axes.axis(slave).is_some_and(|a| a.coupling().is_none());
        let multi = self.multis[slave].as_ref().map(|m| m.lease);
        if let Some(lease) = multi.filter(|l| axes.holds(*l)) {
            self.multis[slave] = None;
            axes.release(lease);
            return accepted();
        }
        let Some(state) = self.slaves[slave].take().filter(|s| axes.holds(s.lease)) else {
            if was_lost {
                return accepted();
            }
            return code(CamCouplingError::NotCamCoupled.raw());
        };
        axes.release(state.lease);
        drop(state);
        accepted()
    }

    pub(super) fn cam_scaling(
        &mut self,
        request: &AcyclicRequest,
        axes: &AxisSet,
    ) -> HandlerResult {
        let call: CamScalingCall = decode_body(request)?;
        let slave = request.target as usize;
        if slave >= axes.len() {
            return Err(ErrorCode::InvalidTarget);
        }
        let (Some(activation), Some(master_mode), Some(slave_mode)) = (
            Activation::from_raw(call.activation_mode, call.activation_position),
            CamScalingMode::from_raw(call.master_scaling_mode),
            CamScalingMode::from_raw(call.slave_scaling_mode),
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
            master_mode == CamScalingMode::AutoOffset,
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

/// The start mode MC_CamTableSelect's (MasterAbsolute, SlaveAbsolute) choose.
fn start_of((master_absolute, slave_absolute): (bool, bool)) -> CamStartMode {
    match (master_absolute, slave_absolute) {
        (true, true) => CamStartMode::Absolute,
        (false, false) => CamStartMode::Relative,
        (true, false) => CamStartMode::MasterAbsSlaveRel,
        (false, true) => CamStartMode::MasterRelSlaveAbs,
    }
}
