//! The cam data service: motion-function points written (a new function, or a change under
//! the table's online-change mode) and read, position tables declared and written, the
//! online-change mode set, a table deleted. Data comes in chunks that change nothing until
//! the last one is checked whole.

use super::{accepted, code, master_of, CamEngine, TABLE_INVALID};
use crate::axis::AxisSet;
use crate::cam::multi_table::TableWeight;
use crate::cam::online::{ActivationMode, MasterNow};
use crate::cam::{
    CamProfile, MotionFunction, MotionFunctionPoint, PositionTable, TableErrorCode, TableType,
};
use hli::calls::cam::CamCouplingError;
use hli::calls::cam::{
    CamActivationMode, CamInterpolation, CamOnlineModeCall, CamPointsReadCall, CamPointsReply,
    CamPointsWriteCall, CamRowsWriteCall, CamScalingMode, CamTableDeleteCall,
    McMotionFunctionPoint, CAM_CHUNK_FIRST, CAM_CHUNK_LAST, CAM_POINTS_CREATE, CAM_POINTS_PER_CALL,
    CAM_ROWS_DECLARE, CAM_ROWS_PER_CALL,
};
use hli::calls::{decode_body, reply, HandlerResult};
use hli::wire::AcyclicRequest;

/// Points of a transfer received so far.
#[derive(Debug)]
pub(super) struct PointsTransfer {
    first: u32,
    total: u32,
    create: bool,
    points: Vec<MotionFunctionPoint>,
}

/// Rows of a table transfer received so far.
#[derive(Debug)]
pub(super) struct RowsTransfer {
    total: u32,
    table_type: u32,
    interpolation: u32,
    periodic: u32,
    rows: Vec<[f64; 2]>,
}

impl CamEngine {
    /// The master's motion over the last tick in the cam of a coupling that uses table `id`
    /// (standing at 0 when none does): what an online change's activation is checked against.
    pub(super) fn master_now_of(&self, id: u32, axes: &AxisSet) -> MasterNow {
        for s in self.slaves.iter().flatten().filter(|s| s.table == id) {
            if let Some(m) = master_of(axes, s.master, s.follow_actual) {
                // Between ticks the master's direction comes from its velocity.
                return s.law.master_now(m.position - m.velocity * 1e-3, m.position);
            }
        }
        MasterNow::standing(0.0)
    }

    pub(super) fn points_write(
        &mut self,
        request: &AcyclicRequest,
        axes: &AxisSet,
    ) -> HandlerResult {
        let call: CamPointsWriteCall = decode_body(request)?;
        let id = request.target;
        if !(1..=255).contains(&id) {
            return code(TABLE_INVALID);
        }
        let slot = id as usize;
        let count = call.count as usize;
        if count == 0 || count > CAM_POINTS_PER_CALL || call.total == 0 {
            self.drop_points(slot);
            return code(TableErrorCode::NumPointsInvalid as u32);
        }
        let create = call.flags & CAM_POINTS_CREATE != 0;
        if call.flags & CAM_CHUNK_FIRST != 0 {
            // A new transfer: whatever an earlier one left unfinished goes.
            self.drop_points(slot);
            if create && self.in_use(id) {
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
            self.drop_points(slot);
            return code(CamCouplingError::ChunkOutOfOrder.raw());
        }
        transfer
            .points
            .extend(call.points[..count].iter().map(point_from_plc));
        self.data_balance.taken = self.data_balance.taken.saturating_add(count as u64);
        if call.flags & CAM_CHUNK_LAST == 0 {
            return accepted();
        }
        let transfer = self.points_in[slot].take().expect("filled above");
        let units = transfer.points.len();
        let answer = self.store_points(id, transfer, axes);
        self.settle(units, &answer);
        answer
    }

    /// The last chunk came: the points, checked whole, become a motion function or change
    /// table `id`'s.
    fn store_points(&mut self, id: u32, transfer: PointsTransfer, axes: &AxisSet) -> HandlerResult {
        let slot = id as usize;
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

    pub(super) fn points_read(&mut self, request: &AcyclicRequest) -> HandlerResult {
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

    pub(super) fn online_mode(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let call: CamOnlineModeCall = decode_body(request)?;
        let id = request.target;
        let (Some(master_mode), Some(slave_mode)) = (
            CamScalingMode::from_raw(call.master_scaling_mode),
            CamScalingMode::from_raw(call.slave_scaling_mode),
        ) else {
            return code(CamCouplingError::UnknownMode.raw());
        };
        if !call.activation_position.is_finite() {
            return code(CamCouplingError::BadParameter.raw());
        }
        let Ok(queue) = self.store.queue_mut(id) else {
            return code(TABLE_INVALID);
        };
        if CamActivationMode::from_raw(call.activation_mode)
            == Some(CamActivationMode::DeleteQueuedData)
        {
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

    pub(super) fn rows_write(&mut self, request: &AcyclicRequest) -> HandlerResult {
        let mut call: CamRowsWriteCall = decode_body(request)?;
        let id = request.target;
        if !(1..=255).contains(&id) {
            return code(TABLE_INVALID);
        }
        let slot = id as usize;
        if call.flags & CAM_ROWS_DECLARE != 0 {
            return self.declare_rows(slot, &call);
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
        if let Err(e) = self.receive_rows(id, &call) {
            return code(e);
        }
        if call.flags & CAM_CHUNK_LAST == 0 {
            return accepted();
        }
        let transfer = self.rows_in[slot].take().expect("filled above");
        let units = transfer.rows.len();
        let answer = self.store_rows(id, transfer);
        self.settle(units, &answer);
        answer
    }

    /// Drops table `slot`'s open points transfer; its points count as dropped.
    pub(super) fn drop_points(&mut self, slot: usize) {
        if let Some(t) = self.points_in[slot].take() {
            let b = &mut self.data_balance;
            b.dropped = b.dropped.saturating_add(t.points.len() as u64);
        }
    }

    /// Drops table `slot`'s open rows transfer; its rows count as dropped.
    pub(super) fn drop_rows(&mut self, slot: usize) {
        if let Some(t) = self.rows_in[slot].take() {
            let b = &mut self.data_balance;
            b.dropped = b.dropped.saturating_add(t.rows.len() as u64);
        }
    }

    /// A finished transfer of `units` answered with `answer`: stored, or dropped.
    fn settle(&mut self, units: usize, answer: &HandlerResult) {
        let b = &mut self.data_balance;
        let to = if answer.is_ok() {
            &mut b.done
        } else {
            &mut b.dropped
        };
        *to = to.saturating_add(units as u64);
    }

    /// Points and rows in open transfers.
    pub(super) fn pending_units(&self) -> u64 {
        let points = self.points_in.iter().flatten().map(|t| t.points.len());
        let rows = self.rows_in.iter().flatten().map(|t| t.rows.len());
        points
            .chain(rows)
            .map(|n| n as u64)
            .fold(0, u64::saturating_add)
    }

    /// CamTableCreate: the table's type and size, for the rows that follow.
    fn declare_rows(&mut self, slot: usize, call: &CamRowsWriteCall) -> HandlerResult {
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
        self.drop_rows(slot);
        accepted()
    }

    /// One chunk of rows for table `id` added to its transfer (the first chunk starts one);
    /// `Err` is the refusal, which drops the transfer but for a missing one.
    fn receive_rows(&mut self, id: u32, call: &CamRowsWriteCall) -> Result<(), u32> {
        let slot = id as usize;
        let count = call.count as usize;
        if count == 0 || count > CAM_ROWS_PER_CALL || call.total == 0 {
            self.drop_rows(slot);
            return Err(TableErrorCode::NumRowsInvalid as u32);
        }
        if call.flags & CAM_CHUNK_FIRST != 0 {
            // A new transfer, refused at once for a table in use.
            self.drop_rows(slot);
            if self.in_use(id) {
                return Err(CamCouplingError::TableInUse.raw());
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
            return Err(CamCouplingError::ChunkOutOfOrder.raw());
        };
        let continues = transfer.total == call.total
            && transfer.table_type == call.table_type
            && transfer.interpolation == call.interpolation
            && transfer.periodic == call.periodic
            && call.first_row as usize == transfer.rows.len()
            && transfer.rows.len() + count <= call.total as usize;
        if !continues {
            self.drop_rows(slot);
            return Err(CamCouplingError::ChunkOutOfOrder.raw());
        }
        transfer.rows.extend_from_slice(&call.rows[..count]);
        let b = &mut self.data_balance;
        b.taken = b.taken.saturating_add(count as u64);
        Ok(())
    }

    /// The last chunk came: the rows, checked whole, become table `id`.
    fn store_rows(&mut self, id: u32, transfer: RowsTransfer) -> HandlerResult {
        if transfer.rows.len() != transfer.total as usize {
            return code(CamCouplingError::ChunkOutOfOrder.raw());
        }
        let table_type = match transfer.table_type {
            10 => TableType::Equidistant,
            11 => TableType::NonEquidistant,
            _ => return code(TableErrorCode::McTableTypeInvalid as u32),
        };
        let Some(interpolation) = CamInterpolation::from_raw(transfer.interpolation) else {
            return code(CamCouplingError::UnknownMode.raw());
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
                self.selects[id as usize] = None;
                accepted()
            }
            Err(e) => code(e.code() as u32),
        }
    }

    pub(super) fn table_delete(&mut self, request: &AcyclicRequest) -> HandlerResult {
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
