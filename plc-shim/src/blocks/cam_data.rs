//! The cam blocks of chapter 5.1 that send table data: MC_CamTableSelect (with the table's
//! rows or points, if given, before the selection) and MC_WriteMotionFunction, both sending
//! their data in chunks, one chunk in flight and one per cycle at most.

use super::cam::recorded;
use super::cam_room::CamRoom;
use crate::kernel::{
    call_error_code, done_unless, no_follow, send, Accept, InFlight, Kernel, Outputs, Polled,
};
use crate::runtime::PlcIo;
use crate::timeline::registry::{
    mode, number, BlockSpec, CamRefIn, InputField, Kind, StForm, TimelineBlock, Value,
};
use hli::calls::cam::{CamInterpolation, CamReply, CamTableSelectCall, McMotionFunctionPoint};
use hli::calls::CallError;
use hli_transport::rpc::PendingCall;
use std::sync::Arc;

/// MC_CamTableSelect: how couplings through table `table` run (cyclic or linear).
#[derive(Debug, Default)]
pub struct McCamTableSelect {
    /// Input: a rising edge sends the selection.
    pub execute: bool,
    /// Input: the table ID.
    pub table: u32,
    /// Input: continued period by period.
    pub periodic: bool,
    /// Input: master coordinates absolute.
    pub master_absolute: bool,
    /// Input: slave coordinates absolute.
    pub slave_absolute: bool,
    /// Input: the table's data, loaded into the CNC first (none: a table the CNC has).
    pub data: CamData,
    /// Input: raw `MC_TableType` of rows sent (10 equidistant, 11 non-equidistant; 0: 10).
    pub table_type: u32,
    /// Input: raw `MC_InterpolationType` of rows sent.
    pub interpolation: u32,
    /// Input: the seed's `CamTable` (an MC_CAM_REF): when given, its data (as many rows as
    /// it says, after its check) in place of `data`, and its table type.
    pub cam_ref: Option<CamRef>,
    /// Outputs of the last call.
    pub out: Outputs,
    kernel: Kernel<SelectTransfer>,
    /// Room for a PLC program's `MC_CAM_REF` (Structured Text), made at load.
    room: Option<CamRoom>,
}

impl McCamTableSelect {
    timeout_input!(kernel);

    /// One cycle: the data in chunks (if any), then the selection.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let (checked, given_type) = match &self.cam_ref {
            Some(r) => (Some(r.check()), r.table_type),
            None => (None, self.table_type),
        };
        let data = match self.cam_ref.as_mut() {
            Some(r) => &mut r.data,
            None => &mut self.data,
        };
        if let CamData::Rows {
            table_type,
            interpolation,
            ..
        } = data
        {
            *table_type = if given_type == 0 { 10 } else { given_type };
            *interpolation = self.interpolation;
        }
        let refused = checked.and_then(Result::err);
        let count = checked.and_then(Result::ok);
        let data = match &self.cam_ref {
            Some(r) => &r.data,
            None => &self.data,
        };
        let call = CamTableSelectCall {
            periodic: u32::from(self.periodic),
            master_absolute: u32::from(self.master_absolute),
            slave_absolute: u32::from(self.slave_absolute),
            reserved: 0,
        };
        let (table, periodic) = (self.table, self.periodic);
        let send = |io: &mut PlcIo<'_>| match (refused, data) {
            (Some(code), _) => Err(code),
            (None, CamData::None) => send(io, table, &call).map(SelectTransfer::Selecting),
            (None, data) => Ok(SelectTransfer::Loading(
                ChunkTransfer::new(table, data, true, periodic)
                    .with_count(count.unwrap_or(data.len())),
                call,
            )),
        };
        self.out = self.kernel.cycle(
            io,
            self.execute,
            send,
            |reply| done_unless(reply.error_id),
            no_follow,
        );
    }
}

/// A transfer of table data in chunks, one chunk in flight: what MC_CamTableSelect with data
/// and MC_WriteMotionFunction send before they are done.
#[derive(Debug, Clone, Default)]
pub enum CamData {
    /// Nothing to send.
    #[default]
    None,
    /// A position table: `[master, slave]` rows.
    Rows {
        /// The rows.
        rows: std::sync::Arc<[[f64; 2]]>,
        /// Raw `MC_TableType` (10, 11).
        table_type: u32,
        /// Raw `MC_InterpolationType`.
        interpolation: u32,
    },
    /// Motion-function points.
    Points(std::sync::Arc<[hli::calls::cam::McMotionFunctionPoint]>),
}

impl CamData {
    /// Rows or points held.
    pub fn len(&self) -> usize {
        match self {
            CamData::None => 0,
            CamData::Rows { rows, .. } => rows.len(),
            CamData::Points(points) => points.len(),
        }
    }

    /// Whether it holds nothing.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The seed's `MC_CAM_REF` (000 5.1.16.2): the array a table's data lie in and how much of
/// it is the table. MC_CamTableSelect and MC_WriteMotionFunction take one (`cam_ref`) in
/// place of their bare data, and check it before anything is sent.
#[derive(Debug, Clone, Default)]
pub struct CamRef {
    /// The array: `[master, slave]` rows of a position table, or motion-function points.
    pub data: CamData,
    /// SIZEOF the array, bytes.
    pub array_size: u32,
    /// `MC_TableType`: 10 equidistant or 11 non-equidistant rows, 22 a motion function.
    pub table_type: u32,
    /// Rows (points) of the table, from the array's start.
    pub rows: u32,
    /// Columns: 2 (master, slave) for rows, 1 (a point) for a motion function.
    pub columns: u32,
    /// The array's elements when `data` has more room than the array (a PLC program's
    /// array copied into room made at load); `None`: all of `data`.
    pub held: Option<usize>,
}

impl CamRef {
    /// The rows (points) to send, or the seed's code (5.1.16.12) of what does not match: a
    /// table type that is not the data's (0x4B35), columns other than the type's (0x4B37),
    /// fewer than 2 rows or more than the array holds (0x4B36), an array size other than its
    /// elements' (0x4B31).
    pub fn check(&self) -> Result<usize, u32> {
        let (held, element_bytes, columns) = match (&self.data, self.table_type) {
            (CamData::Rows { rows, .. }, 10 | 11) => (rows.len(), 8, 2),
            (CamData::Points(points), 22) => (
                points.len(),
                core::mem::size_of::<McMotionFunctionPoint>(),
                1,
            ),
            _ => return Err(0x4B35),
        };
        let held = self.held.map_or(held, |h| h.min(held));
        if self.columns != columns {
            return Err(super::cam_read::ERROR_COLUMNS);
        }
        let rows = self.rows as usize;
        if rows < 2 || rows > held {
            return Err(0x4B36);
        }
        if self.array_size as usize != held * element_bytes * columns as usize {
            return Err(super::cam_read::ERROR_ARRAY_SIZE);
        }
        Ok(rows)
    }
}

enum Pending {
    Rows(PendingCall<hli::calls::cam::CamRowsWriteCall>),
    Points(PendingCall<hli::calls::cam::CamPointsWriteCall>),
}

/// [`CamData`] on its way to table `table`, chunk by chunk, one chunk in flight and one per
/// cycle at most (a PLC cycle never waits); answered when the last chunk is taken.
pub struct ChunkTransfer {
    table: u32,
    data: CamData,
    /// The points make a new function.
    create: bool,
    /// Rows of a cyclic table.
    periodic: bool,
    pending: Option<Pending>,
    next: usize,
    /// Rows per call (iBlockSize of the compatibility blocks), 1..=CAM_ROWS_PER_CALL.
    rows_per_call: usize,
    /// Rows (points) of `data` sent: all, or an MC_CAM_REF's row count.
    count: usize,
}

/// Bytes of one table row (master and slave, two LREALs): the least iBlockSize moves.
pub const ROW_BYTES: u32 = 16;

impl core::fmt::Debug for ChunkTransfer {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ChunkTransfer")
            .field("table", &self.table)
            .field("next", &self.next)
            .finish()
    }
}

fn chunk_flags(first: bool, last: bool) -> u32 {
    let mut flags = 0;
    if first {
        flags |= hli::calls::cam::CAM_CHUNK_FIRST;
    }
    if last {
        flags |= hli::calls::cam::CAM_CHUNK_LAST;
    }
    flags
}

impl ChunkTransfer {
    /// A transfer of `data` (shared, not copied) to `table`; nothing is sent before the
    /// first poll.
    pub fn new(table: u32, data: &CamData, create: bool, periodic: bool) -> ChunkTransfer {
        ChunkTransfer {
            table,
            data: data.clone(),
            create,
            periodic,
            pending: None,
            next: 0,
            rows_per_call: hli::calls::cam::CAM_ROWS_PER_CALL,
            count: data.len(),
        }
    }

    /// Only the first `count` rows (points) of the data (an MC_CAM_REF's).
    pub fn with_count(mut self, count: usize) -> ChunkTransfer {
        self.count = count.min(self.data.len());
        self
    }

    /// The transfer in steps of at most `bytes` (iBlockSize): `bytes / 16` rows per call, at
    /// most the call's room; 0 (the seed's default) and anything below a row keep the room.
    pub fn with_block_size(mut self, bytes: u32) -> ChunkTransfer {
        if bytes >= ROW_BYTES {
            let rows = (bytes / ROW_BYTES) as usize;
            self.rows_per_call = rows.min(hli::calls::cam::CAM_ROWS_PER_CALL);
        }
        self
    }

    /// The next chunk, sent; `None` when every chunk is out.
    fn send_next(&mut self, io: &mut PlcIo<'_>) -> Option<Result<Pending, CallError>> {
        match &self.data {
            CamData::None => None,
            CamData::Rows {
                rows,
                table_type,
                interpolation,
            } => {
                let rows = &rows[..self.count];
                let chunk = rows
                    .get(self.next..)?
                    .get(..self.rows_per_call.min(rows.len() - self.next))?;
                if chunk.is_empty() {
                    return None;
                }
                let mut call = hli::calls::cam::CamRowsWriteCall {
                    first_row: self.next as u32,
                    count: chunk.len() as u32,
                    flags: chunk_flags(self.next == 0, self.next + chunk.len() == rows.len()),
                    total: rows.len() as u32,
                    table_type: *table_type,
                    interpolation: *interpolation,
                    periodic: u32::from(self.periodic),
                    ..Default::default()
                };
                call.rows[..chunk.len()].copy_from_slice(chunk);
                self.next += chunk.len();
                Some(io.acyclic.start(self.table, &call).map(Pending::Rows))
            }
            CamData::Points(points) => {
                let points = &points[..self.count];
                let per = hli::calls::cam::CAM_POINTS_PER_CALL;
                let chunk = points
                    .get(self.next..)?
                    .get(..per.min(points.len() - self.next))?;
                if chunk.is_empty() {
                    return None;
                }
                let last = self.next + chunk.len() == points.len();
                let create = if self.create {
                    hli::calls::cam::CAM_POINTS_CREATE
                } else {
                    0
                };
                let mut call = hli::calls::cam::CamPointsWriteCall {
                    first: chunk[0].point_index,
                    count: chunk.len() as u32,
                    flags: chunk_flags(self.next == 0, last) | create,
                    total: points.len() as u32,
                    ..Default::default()
                };
                call.points[..chunk.len()].copy_from_slice(chunk);
                self.next += chunk.len();
                Some(io.acyclic.start(self.table, &call).map(Pending::Points))
            }
        }
    }
}

impl InFlight for ChunkTransfer {
    type Reply = ();
    type Buffer = ();

    fn poll(&mut self, io: &mut PlcIo<'_>, _: &mut ()) -> Polled<()> {
        let answered = match &self.pending {
            None => None,
            Some(Pending::Rows(p)) => p.poll().map(|r| r.map(|r| r.error_id)),
            Some(Pending::Points(p)) => p.poll().map(|r| r.map(|r| r.error_id)),
        };
        match answered {
            Some(Ok(0)) => self.pending = None,
            Some(Ok(code)) => return Polled::Answer(Err(code)),
            Some(Err(e)) => return Polled::Answer(Err(call_error_code(&e))),
            None if self.pending.is_some() => return Polled::Waiting,
            None => {}
        }
        match self.send_next(io) {
            None => Polled::Answer(Ok(())),
            Some(Ok(pending)) => {
                self.pending = Some(pending);
                Polled::Progress
            }
            Some(Err(e)) => Polled::Answer(Err(call_error_code(&e))),
        }
    }
}

/// The data of MC_CamTableSelect (if any) and then the selection itself.
pub enum SelectTransfer {
    /// The table's data, chunk by chunk; the selection waits.
    Loading(ChunkTransfer, CamTableSelectCall),
    /// The selection, on its way.
    Selecting(PendingCall<CamTableSelectCall>),
}

impl InFlight for SelectTransfer {
    type Reply = CamReply;
    type Buffer = ();

    fn poll(&mut self, io: &mut PlcIo<'_>, _: &mut ()) -> Polled<CamReply> {
        match self {
            SelectTransfer::Selecting(pending) => InFlight::poll(pending, io, &mut ()),
            SelectTransfer::Loading(transfer, call) => match transfer.poll(io, &mut ()) {
                Polled::Answer(Ok(())) => match io.acyclic.start(transfer.table, call) {
                    Ok(pending) => {
                        *self = SelectTransfer::Selecting(pending);
                        Polled::Progress
                    }
                    Err(e) => Polled::Answer(Err(call_error_code(&e))),
                },
                Polled::Answer(Err(code)) => Polled::Answer(Err(code)),
                Polled::Waiting => Polled::Waiting,
                Polled::Progress => Polled::Progress,
            },
        }
    }
}

/// MC_WriteMotionFunction: several points of the motion function `table` (the first one's
/// index says where they go), sent in chunks and taken whole with the last.
#[derive(Debug, Default)]
pub struct McWriteMotionFunction {
    /// Input: a rising edge starts the transfer.
    pub execute: bool,
    /// Input: the table ID.
    pub table: u32,
    /// Input: the points.
    pub points: CamData,
    /// Input: the seed's `CamTable` (an MC_CAM_REF of type 22): when given, its points (as
    /// many as it says, after its check) in place of `points`.
    pub cam_ref: Option<CamRef>,
    /// Outputs of the last call.
    pub out: Outputs,
    kernel: Kernel<ChunkTransfer>,
    /// Room for a PLC program's `MC_CAM_REF` (Structured Text), made at load.
    room: Option<CamRoom>,
}

impl McWriteMotionFunction {
    timeout_input!(kernel);

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        // A motion function's points only (a position table's rows are MC_CamTableSelect's).
        let check = |r: &CamRef| match r.table_type {
            22 => r.check(),
            _ => Err(0x4B35),
        };
        let (table, checked) = (self.table, self.cam_ref.as_ref().map(check));
        let points = self.cam_ref.as_ref().map_or(&self.points, |r| &r.data);
        let send = |_: &mut PlcIo<'_>| match checked {
            Some(Err(code)) => Err(code),
            Some(Ok(count)) => {
                Ok(ChunkTransfer::new(table, points, false, false).with_count(count))
            }
            None => Ok(ChunkTransfer::new(table, points, false, false)),
        };
        self.out = self
            .kernel
            .cycle(io, self.execute, send, |()| Accept::Done(()), no_follow);
    }
}

/// `rows = [[master, slave], ...]`.
pub fn rows_of(value: &toml::Value) -> Result<Arc<[[f64; 2]]>, String> {
    let bad = || "call: `rows` must be [[master, slave], ...] of finite numbers".to_string();
    let list = value.as_array().ok_or_else(bad)?;
    list.iter()
        .map(|row| match row.as_array().map(|r| r.as_slice()) {
            Some([m, s]) => match (number(m), number(s)) {
                (Some(m), Some(s)) if m.is_finite() && s.is_finite() => Ok([m, s]),
                _ => Err(bad()),
            },
            _ => Err(bad()),
        })
        .collect()
}

/// The fields of a point in `points`.
const POINT_FIELDS: [&str; 9] = [
    "index",
    "function",
    "type",
    "rel_index_next",
    "master",
    "slave",
    "velocity",
    "acceleration",
    "jerk",
];

/// Point `i` of `points`.
fn point_of(i: usize, p: &toml::Value) -> Result<McMotionFunctionPoint, String> {
    let t = p
        .as_table()
        .ok_or_else(|| format!("call: points[{i}] is not a table"))?;
    let int = |k: &str, default: Option<u32>| -> Result<u32, String> {
        match t.get(k) {
            Some(v) => v
                .as_integer()
                .filter(|v| (0..i64::from(u32::MAX)).contains(v))
                .map(|v| v as u32)
                .ok_or_else(|| format!("call: points[{i}].{k} = {v} is not valid")),
            None => default.ok_or_else(|| format!("call: points[{i}].{k} is missing")),
        }
    };
    let num = |k: &str, required: bool| -> Result<f64, String> {
        match t.get(k) {
            Some(v) => number(v)
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("call: points[{i}].{k} = {v} is not valid")),
            None if required => Err(format!("call: points[{i}].{k} is missing")),
            None => Ok(0.0),
        }
    };
    if let Some(key) = t.keys().find(|k| !POINT_FIELDS.contains(&k.as_str())) {
        return Err(format!(
            "call: points[{i}] has no field `{key}` (fields: {})",
            POINT_FIELDS.join(", ")
        ));
    }
    Ok(McMotionFunctionPoint {
        point_index: int("index", None)?,
        function_type: int("function", None)?,
        point_type: int("type", None)?,
        rel_index_next_point: int("rel_index_next", Some(1))?,
        master_pos: num("master", true)?,
        slave_pos: num("slave", true)?,
        slave_velo: num("velocity", false)?,
        slave_acc: num("acceleration", false)?,
        slave_jerk: num("jerk", false)?,
    })
}

/// `points = [{ index = 1, function = 15, type = 1, master = 0.0, slave = 0.0, ... }, ...]`.
fn points_of(value: &toml::Value) -> Result<Arc<[McMotionFunctionPoint]>, String> {
    let list = value
        .as_array()
        .ok_or("call: `points` must be an array of point tables")?;
    list.iter()
        .enumerate()
        .map(|(i, p)| point_of(i, p))
        .collect()
}

/// `rows` sets a position table, `points` a motion function: what the block then sends.
impl InputField for CamData {
    fn take(&mut self, value: &Value) {
        match value {
            Value::Rows(rows) => {
                *self = CamData::Rows {
                    rows: Arc::clone(rows),
                    table_type: 10,
                    interpolation: 0,
                }
            }
            Value::Points(points) => *self = CamData::Points(Arc::clone(points)),
            _ => {}
        }
    }
}

/// The most bytes of an `MC_CAM_REF`'s array a PLC program in Structured Text gives (the
/// room each instance makes at load, twice for rows and twice for points): 4,096 rows, or
/// 1,170 points.
pub const CAM_REF_ROOM_BYTES: usize = 65_536;

/// Table rows `[[master, slave], ...]` in a timeline.
pub(super) const ROWS: Kind = Kind::Parsed {
    parse: |v| rows_of(v).map(Value::Rows),
    example: "[[0.0, 0.0], [1.0, 2.0]]",
};

/// Motion-function points in a timeline.
const POINTS: Kind = Kind::Parsed {
    parse: |v| points_of(v).map(Value::Points),
    example: "[{ index = 1, function = 15, type = 1, master = 0.0, slave = 0.0 }]",
};

/// In Structured Text a table comes as the seed's `CamTable : MC_CAM_REF`: its rows or
/// points, and its type.
const CAM_TABLE: StForm = StForm::CamRef {
    name: "CamTable",
    max_bytes: CAM_REF_ROOM_BYTES,
};
const HIDDEN: StForm = StForm::Hidden;

inputs! {
    /// MC_CamTableSelect's inputs: the table, the selection and the data sent before it.
    SELECT, set_select: McCamTableSelect {
        "table": Kind::Count => table,
        "periodic": Kind::Bool => periodic,
        "master_absolute": Kind::Bool => master_absolute,
        "slave_absolute": Kind::Bool => slave_absolute,
        "rows" as CAM_TABLE: ROWS => data,
        "points" as HIDDEN: POINTS => data,
        "table_type" as HIDDEN: Kind::OneOf(&[("10 (equidistant)", 10), ("11 (non-equidistant)", 11)])
            => table_type,
        "interpolation": mode::<CamInterpolation>() => interpolation,
    }
}

inputs! {
    /// MC_WriteMotionFunction's inputs.
    WRITE, set_write: McWriteMotionFunction {
        "table": Kind::Count => table,
        "points" as CAM_TABLE: POINTS => points,
    }
}

/// `TimelineBlock::reserve_cam_ref` and `set_cam_ref` of a block with `room` and `cam_ref`.
macro_rules! cam_ref_room {
    () => {
        fn reserve_cam_ref(&mut self, bytes: usize) -> bool {
            self.room = Some(CamRoom::new(bytes));
            true
        }
        fn set_cam_ref(&mut self, table: &CamRefIn<'_>) -> bool {
            // The last table's buffer is given back first: one of the two is then free.
            self.cam_ref = None;
            self.cam_ref = self.room.as_mut().and_then(|room| room.take(table));
            self.cam_ref.is_some()
        }
    };
}

impl TimelineBlock for McCamTableSelect {
    timeline_timeout!();
    fn set(&mut self, key: &str, value: &Value) {
        set_select(self, key, value);
    }
    cam_ref_room!();
    execute_cycle!(no_axis, recorded);
}

impl TimelineBlock for McWriteMotionFunction {
    timeline_timeout!();
    fn set(&mut self, key: &str, value: &Value) {
        set_write(self, key, value);
    }
    cam_ref_room!();
    execute_cycle!(no_axis, recorded);
}

/// The cam blocks with table data a timeline calls.
pub const TIMELINE: &[BlockSpec] = &[
    BlockSpec::on_axis("MC_CamTableSelect", &SELECT, |_| {
        Box::<McCamTableSelect>::default()
    }),
    BlockSpec::on_axis("MC_WriteMotionFunction", &WRITE, |_| {
        Box::<McWriteMotionFunction>::default()
    }),
];
