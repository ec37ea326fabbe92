//! The reads of chapter 5.1: MC_ReadCamTableSlaveDynamics, MC_ReadCamTableCharacteristics,
//! MC_ReadMotionFunctionValues and MC_CamInfo ([`McCamRead`], answers in parts of 28
//! numbers) and MC_ReadMotionFunction / MC_ReadMotionFunctionPoint ([`McReadMotionFunction`],
//! four points per cycle), each into an array whose room is set when the block is made.

use super::cam::recorded;
use super::cam_results;
use crate::kernel::{call_error_code, no_follow, send, Accept, InFlight, Kernel, Outputs, Polled};
use crate::runtime::PlcIo;
use crate::timeline::registry::{
    input, BlockSpec, CamRefIn, InputSpec, Kind, Results, StForm, TimelineBlock, Value,
};
use hli::calls::cam::CamReadKind;
use hli_transport::rpc::PendingCall;

/// MC_ERROR_ARRAYSIZE_INVALID: an answer does not fit the block's array.
pub const ERROR_ARRAY_SIZE: u32 = 0x4B31;

/// MC_ERROR_NUMCOLUMNS_INVALID: the array's column count does not match what is read.
pub const ERROR_COLUMNS: u32 = 0x4B37;

/// A read of numbers in parts of 28, one part per cycle, appended to the block's array (the
/// buffer); answered with the columns per row once all are in.
pub struct PartRead {
    target: u32,
    request: hli::calls::cam::CamReadCall,
    pending: PendingCall<hli::calls::cam::CamReadCall>,
    /// Numbers the array holds beside the buffer's room (its size in bytes / 8).
    limit: usize,
}

impl core::fmt::Debug for PartRead {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("PartRead")
            .field("part", &self.request.part)
            .finish()
    }
}

impl PartRead {
    fn start(
        io: &mut PlcIo<'_>,
        target: u32,
        request: hli::calls::cam::CamReadCall,
        limit: usize,
    ) -> Result<PartRead, u32> {
        let pending = send(io, target, &request)?;
        Ok(PartRead {
            target,
            request,
            pending,
            limit,
        })
    }
}

impl InFlight for PartRead {
    type Reply = u32;
    type Buffer = Vec<f64>;

    fn poll(&mut self, io: &mut PlcIo<'_>, values: &mut Vec<f64>) -> Polled<u32> {
        let reply = match self.pending.poll() {
            None => return Polled::Waiting,
            Some(Err(e)) => return Polled::Answer(Err(call_error_code(&e))),
            Some(Ok(reply)) if reply.error_id != 0 => return Polled::Answer(Err(reply.error_id)),
            Some(Ok(reply)) => reply,
        };
        let count = reply.count as usize;
        if count > reply.values.len() {
            // A part the reply cannot hold: as if no answer came.
            return Polled::Answer(Err(crate::kernel::ERROR_NO_ANSWER));
        }
        // The array holds what its room and its size (when given) both hold.
        let room = values.capacity().min(self.limit);
        if values.len() + count > room || reply.total as usize > room {
            return Polled::Answer(Err(ERROR_ARRAY_SIZE));
        }
        values.extend_from_slice(&reply.values[..count]);
        if values.len() >= reply.total as usize || count == 0 {
            return Polled::Answer(Ok(reply.columns));
        }
        self.request.part += 1;
        match io.acyclic.start(self.target, &self.request) {
            Ok(pending) => {
                self.pending = pending;
                Polled::Progress
            }
            Err(e) => Polled::Answer(Err(call_error_code(&e))),
        }
    }
}

/// The reads of chapter 5.1 (MC_ReadCamTableSlaveDynamics, MC_ReadCamTableCharacteristics,
/// MC_ReadMotionFunctionValues, MC_CamInfo): the answer comes in parts of 28 numbers, one
/// part per cycle, into `values`, whose room is set when the instance is made (like the
/// array an MC_CAM_REF points to); an answer that does not fit is refused with
/// MC_ERROR_ARRAYSIZE_INVALID.
#[derive(Debug)]
pub struct McCamRead {
    /// Input: a rising edge starts the read.
    pub execute: bool,
    /// What is read and its parameters (the target is set by [`McCamRead::target`]).
    pub request: hli::calls::cam::CamReadCall,
    /// Table ID, or the slave axis of MC_CamInfo.
    pub target: u32,
    /// Output: the numbers read.
    pub values: Vec<f64>,
    /// Output: columns per row of a value table.
    pub columns: u32,
    /// Outputs of the last call.
    pub out: Outputs,
    /// A refusal the block's own inputs make (an array that cannot hold what it asks for):
    /// the read ends in Error with this code without a call.
    pub refuse: Option<u32>,
    /// MC_ReadMotionFunctionValues' array: its column count (the MC_CAM_REF's nNoOfCols),
    /// if given. Other than 1 + the bits of the ValueSelectMask (seed 000 5.1.13: the
    /// CamTable's columns must match the mask) is refused with MC_ERROR_NUMCOLUMNS_INVALID
    /// (0x4B37) without a call.
    pub array_columns: Option<u32>,
    /// The array's size in numbers (bytes / 8) when it is given apart from the room
    /// (CamTableReadData's `size`): an answer with more numbers than it holds is refused
    /// with MC_ERROR_ARRAYSIZE_INVALID once the first part tells how many come (a read of
    /// all rows, whose count only the CNC knows).
    pub size_limit: Option<usize>,
    kernel: Kernel<PartRead>,
}

/// Room of a read block's answer when the timeline does not say.
pub const DEFAULT_READ_ROOM: usize = 1024;

impl McCamRead {
    /// A read of kind `what` with room for `room` numbers.
    pub fn new(what: CamReadKind, room: usize) -> McCamRead {
        McCamRead {
            execute: false,
            request: hli::calls::cam::CamReadCall {
                what: what.raw(),
                ..Default::default()
            },
            target: 0,
            values: Vec::with_capacity(room),
            columns: 1,
            out: Outputs::default(),
            refuse: None,
            array_columns: None,
            size_limit: None,
            kernel: Kernel::default(),
        }
    }

    timeout_input!(kernel);

    /// MC_ReadMotionFunctionValues' array against its ValueSelectMask: 0x4B37 when a column
    /// count is given and is not the master column and one per bit of the mask.
    fn columns_refusal(&self) -> Option<u32> {
        let values = self.request.what == CamReadKind::Values.raw();
        let wanted = 1 + self.request.mask.count_ones();
        match self.array_columns {
            Some(columns) if values && columns != wanted => Some(ERROR_COLUMNS),
            _ => None,
        }
    }

    /// The organisation fields of a characteristics read (after its 31 values), once read.
    pub fn organisation(&self) -> Option<hli::calls::cam::TableOrganisation> {
        let read = self.request.what == CamReadKind::Characteristics.raw();
        let fields = self.values.get(31..36).filter(|_| read)?;
        hli::calls::cam::TableOrganisation::from_values(fields)
    }

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let (target, request) = (self.target, self.request);
        let refuse = self.refuse.or_else(|| self.columns_refusal());
        let limit = self.size_limit.unwrap_or(usize::MAX);
        let columns = &mut self.columns;
        let send = |io: &mut PlcIo<'_>, values: &mut Vec<f64>| {
            values.clear();
            if let Some(code) = refuse {
                return Err(code);
            }
            PartRead::start(
                io,
                target,
                hli::calls::cam::CamReadCall { part: 0, ..request },
                limit,
            )
        };
        self.out = self.kernel.cycle_with(
            io,
            &mut self.values,
            self.execute,
            send,
            |c| {
                *columns = c;
                Accept::Done(())
            },
            no_follow,
        );
    }
}

/// A read of motion-function points, four per cycle, appended to the block's array until
/// `wanted` (0: to the end of the function from `first`).
pub struct PointsRead {
    table: u32,
    first: u32,
    count: u32,
    /// The most points the array takes (its room, or a program's array's size).
    limit: usize,
    pending: PendingCall<hli::calls::cam::CamPointsReadCall>,
}

impl core::fmt::Debug for PointsRead {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("PointsRead")
            .field("table", &self.table)
            .finish()
    }
}

fn read_points(
    io: &mut PlcIo<'_>,
    table: u32,
    first: u32,
) -> Result<PendingCall<hli::calls::cam::CamPointsReadCall>, u32> {
    let call = hli::calls::cam::CamPointsReadCall { first, count: 0 };
    send(io, table, &call)
}

impl InFlight for PointsRead {
    type Reply = ();
    type Buffer = Vec<hli::calls::cam::McMotionFunctionPoint>;

    fn poll(&mut self, io: &mut PlcIo<'_>, points: &mut Self::Buffer) -> Polled<()> {
        let reply = match self.pending.poll() {
            None => return Polled::Waiting,
            Some(Err(e)) => return Polled::Answer(Err(call_error_code(&e))),
            Some(Ok(reply)) if reply.error_id != 0 => return Polled::Answer(Err(reply.error_id)),
            Some(Ok(reply)) => reply,
        };
        // To the function's end; NumPoints beyond it reads what there is (manual 000,
        // 5.1.8: NumPointsRead may be smaller than NumPoints).
        if reply.count as usize > reply.points.len() {
            // A part the reply cannot hold: as if no answer came (as for the value reads).
            return Polled::Answer(Err(crate::kernel::ERROR_NO_ANSWER));
        }
        let left = reply.total.saturating_add(1).saturating_sub(self.first) as usize;
        let wanted = match self.count {
            0 => left,
            count => (count as usize).min(left),
        };
        if wanted > points.capacity().min(self.limit) {
            return Polled::Answer(Err(ERROR_ARRAY_SIZE));
        }
        let take = (reply.count as usize).min(wanted.saturating_sub(points.len()));
        points.extend_from_slice(&reply.points[..take]);
        if points.len() >= wanted || reply.count == 0 {
            return Polled::Answer(Ok(()));
        }
        match read_points(io, self.table, self.first + points.len() as u32) {
            Ok(pending) => {
                self.pending = pending;
                Polled::Progress
            }
            Err(code) => Polled::Answer(Err(code)),
        }
    }
}

/// MC_ReadMotionFunction / MC_ReadMotionFunctionPoint: points of the motion function
/// `table` from `first` on (`count` 0: to the end), four per cycle, into `points`, whose room
/// is set when the instance is made.
#[derive(Debug)]
pub struct McReadMotionFunction {
    /// Input: a rising edge starts the read.
    pub execute: bool,
    /// Input: the table ID.
    pub table: u32,
    /// Input: the first point.
    pub first: u32,
    /// Input: points wanted (0: all from `first`).
    pub count: u32,
    /// Output: the points read.
    pub points: Vec<hli::calls::cam::McMotionFunctionPoint>,
    /// Outputs of the last call.
    pub out: Outputs,
    /// A program's array the points go into: the most it holds, or the seed's code of a
    /// description that does not fit a motion function's points.
    pub destination: Option<Result<usize, u32>>,
    kernel: Kernel<PointsRead>,
}

impl McReadMotionFunction {
    timeout_input!(kernel);

    /// A reader with room for `room` points.
    pub fn new(room: usize) -> McReadMotionFunction {
        McReadMotionFunction {
            execute: false,
            table: 0,
            first: 1,
            count: 0,
            points: Vec::with_capacity(room),
            out: Outputs::default(),
            destination: None,
            kernel: Kernel::default(),
        }
    }

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let (table, first, count) = (self.table, self.first, self.count);
        let destination = self.destination;
        let send = |io: &mut PlcIo<'_>,
                    points: &mut Vec<hli::calls::cam::McMotionFunctionPoint>| {
            points.clear();
            let limit = match destination {
                Some(Err(code)) => return Err(code),
                Some(Ok(limit)) => limit,
                None => usize::MAX,
            };
            Ok(PointsRead {
                table,
                first,
                count,
                limit,
                pending: read_points(io, table, first)?,
            })
        };
        self.out = self.kernel.cycle_with(
            io,
            &mut self.points,
            self.execute,
            send,
            |()| Accept::Done(()),
            no_follow,
        );
    }
}

impl TimelineBlock for McCamRead {
    timeline_timeout!();
    fn set(&mut self, key: &str, value: &Value) {
        let r = &mut self.request;
        match (key, value.uint(), value.real(), value) {
            ("table", Some(v), _, _) => self.target = v,
            ("value_select_mask", Some(v), _, _) => r.mask = v,
            ("columns", Some(v), _, _) => self.array_columns = Some(v),
            ("master_position" | "start_pos_master" | "master_velocity", _, Some(v), _) => r.a = v,
            ("end_pos_master", _, Some(v), _) => r.b = v,
            ("increment", _, Some(v), _) => r.c = v,
            ("at_master_position", _, _, Value::Bool(v)) => r.flags = u32::from(*v),
            _ => {}
        }
    }
    fn execute(&mut self) -> Option<&mut bool> {
        Some(&mut self.execute)
    }
    fn cycle(&mut self, io: &mut PlcIo<'_>, axis: u32) -> (Outputs, bool) {
        if self.request.what == CamReadKind::Info.raw() {
            self.target = axis; // MC_CamInfo reads the slave's coupling
        }
        self.call(io);
        recorded(self.out)
    }
    fn read(&self) -> Option<Vec<f64>> {
        Some(self.values.clone())
    }
    /// MC_ReadMotionFunctionValues' `CamTable`: its columns against the mask, its size in
    /// LREALs the most the answer may hold.
    fn set_destination(&mut self, array: &CamRefIn<'_>) -> bool {
        if self.request.what != CamReadKind::Values.raw() {
            return false;
        }
        self.array_columns = Some(array.columns);
        self.size_limit = Some(array.array_size as usize / 8);
        true
    }
    fn read_bytes(&self, out: &mut [u8]) -> usize {
        cam_results::lreal_bytes(&self.values, out)
    }
    fn results(&self) -> Option<&'static Results> {
        match CamReadKind::from_raw(self.request.what) {
            Some(CamReadKind::SlaveDynamics) => Some(&cam_results::SLAVE_DYNAMICS),
            Some(CamReadKind::Characteristics) => Some(&cam_results::CHARACTERISTICS),
            Some(CamReadKind::Info) => Some(&cam_results::CAM_INFO),
            _ => None,
        }
    }
    fn result_values(&self, out: &mut [f64]) -> usize {
        match CamReadKind::from_raw(self.request.what) {
            Some(CamReadKind::Characteristics) => cam_results::characteristics(&self.values, out),
            _ => cam_results::copied(&self.values, out),
        }
    }
}

impl TimelineBlock for McReadMotionFunction {
    timeline_timeout!();
    fn set(&mut self, key: &str, value: &Value) {
        match (key, value.uint()) {
            ("table", Some(v)) => self.table = v,
            ("point_index", Some(v)) => self.first = v,
            ("num_points", Some(v)) => self.count = v,
            _ => {}
        }
    }
    execute_cycle!(no_axis, recorded);
    /// MC_ReadMotionFunction's `CamTable`: a motion function's (type 22, one column), its
    /// size a whole number of points (the seed's 0x4B35, 0x4B37, 0x4B31 otherwise).
    fn set_destination(&mut self, array: &CamRefIn<'_>) -> bool {
        let point = core::mem::size_of::<hli::calls::cam::McMotionFunctionPoint>();
        let size = array.array_size as usize;
        self.destination = Some(match (array.table_type, array.columns) {
            (22, 1) if size.is_multiple_of(point) => Ok(size / point),
            (22, 1) => Err(ERROR_ARRAY_SIZE),
            (22, _) => Err(ERROR_COLUMNS),
            _ => Err(0x4B35),
        });
        true
    }
    /// MC_ReadMotionFunctionPoint (a reader of one point): the point as an output.
    fn results(&self) -> Option<&'static Results> {
        (self.points.capacity() == 1 && self.count == 1).then_some(&cam_results::POINT)
    }
    fn result_values(&self, out: &mut [f64]) -> usize {
        let Some(p) = self.points.first() else {
            return 0;
        };
        let values = [
            f64::from(p.point_index),
            f64::from(p.function_type),
            f64::from(p.point_type),
            f64::from(p.rel_index_next_point),
            p.master_pos,
            p.slave_pos,
            p.slave_velo,
            p.slave_acc,
            p.slave_jerk,
        ];
        cam_results::copied(&values, out)
    }
    fn read_bytes(&self, out: &mut [u8]) -> usize {
        let bytes: &[u8] = bytemuck::cast_slice(&self.points);
        let n = bytes.len().min(out.len());
        out[..n].copy_from_slice(&bytes[..n]);
        n
    }
    /// Index, master and slave position of every point read.
    fn read(&self) -> Option<Vec<f64>> {
        let points = self.points.iter();
        Some(
            points
                .flat_map(|p| [p.point_index as f64, p.master_pos, p.slave_pos])
                .collect(),
        )
    }
}

const TABLE: InputSpec = input("table", Kind::Count);
const POINT_INDEX: InputSpec = input("point_index", Kind::Count);
const MASTER_POSITION: InputSpec = input("master_position", Kind::Real);
/// The room of a read's answer: in Structured Text the seed's `CamTable : MC_CAM_REF`, the
/// program's array the answer goes into.
const ROOM: InputSpec = input("room", Kind::Room).st_form(StForm::ReadInto { name: "CamTable" });

/// The cam reads a timeline calls; `room` (where a read has it) is the room of the answer,
/// [`DEFAULT_READ_ROOM`] if not given.
pub const TIMELINE: &[BlockSpec] = &[
    BlockSpec::on_axis(
        "MC_ReadMotionFunction",
        &[TABLE, POINT_INDEX, input("num_points", Kind::Count), ROOM],
        |room| {
            let room = room.unwrap_or(DEFAULT_READ_ROOM);
            Box::new(McReadMotionFunction::new(room))
        },
    ),
    BlockSpec::on_axis("MC_ReadMotionFunctionPoint", &[TABLE, POINT_INDEX], |_| {
        Box::new(McReadMotionFunction {
            count: 1,
            ..McReadMotionFunction::new(1)
        })
    }),
    BlockSpec::on_axis(
        "MC_ReadCamTableSlaveDynamics",
        &[TABLE, MASTER_POSITION],
        |_| Box::new(McCamRead::new(CamReadKind::SlaveDynamics, 3)),
    ),
    // `master_velocity`: the values rescaled to a master at that constant velocity (seed 000
    // 3.4; not given or 0: the normed values).
    BlockSpec::on_axis(
        "MC_ReadCamTableCharacteristics",
        &[TABLE, input("master_velocity", Kind::Real)],
        |_| Box::new(McCamRead::new(CamReadKind::Characteristics, 36)),
    ),
    BlockSpec::on_axis(
        "MC_ReadMotionFunctionValues",
        &[
            TABLE,
            input("value_select_mask", Kind::Count),
            input("start_pos_master", Kind::Real),
            input("end_pos_master", Kind::Real),
            input("increment", Kind::Real),
            // The array's column count (MC_CAM_REF nNoOfCols): must be 1 + the mask's bits.
            input("columns", Kind::Range(1, 16)),
            ROOM,
        ],
        |room| {
            let room = room.unwrap_or(DEFAULT_READ_ROOM);
            Box::new(McCamRead::new(CamReadKind::Values, room))
        },
    ),
    BlockSpec::on_axis(
        "MC_CamInfo",
        &[input("at_master_position", Kind::Bool), MASTER_POSITION],
        |_| Box::new(McCamRead::new(CamReadKind::Info, 40)),
    ),
];
