//! The reads of chapter 5.1: MC_ReadCamTableSlaveDynamics, MC_ReadCamTableCharacteristics,
//! MC_ReadMotionFunctionValues and MC_CamInfo ([`McCamRead`], answers in parts of 28
//! numbers) and MC_ReadMotionFunction / MC_ReadMotionFunctionPoint ([`McReadMotionFunction`],
//! four points per cycle), each into an array whose room is set when the block is made.

use crate::kernel::{call_error_code, no_follow, Accept, InFlight, Kernel, Outputs, Polled};
use crate::runtime::PlcIo;
use hli::rpc::PendingCall;

/// MC_ERROR_ARRAYSIZE_INVALID: an answer does not fit the block's array.
pub const ERROR_ARRAY_SIZE: u32 = 0x4B31;

/// A read of numbers in parts of 28, one part per cycle, appended to the block's array (the
/// buffer); answered with the columns per row once all are in.
pub struct PartRead {
    target: u32,
    request: hli::calls::cam::CamReadCall,
    pending: PendingCall<hli::calls::cam::CamReadCall>,
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
    ) -> Result<PartRead, u32> {
        let pending = io
            .acyclic
            .start(target, &request)
            .map_err(|e| call_error_code(&e))?;
        Ok(PartRead {
            target,
            request,
            pending,
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
        if values.len() + count > values.capacity() || reply.total as usize > values.capacity() {
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
    kernel: Kernel<PartRead>,
}

/// Room of a read block's answer when the timeline does not say.
pub const DEFAULT_READ_ROOM: usize = 1024;

impl McCamRead {
    /// A read of kind `what` with room for `room` numbers.
    pub fn new(what: u32, room: usize) -> McCamRead {
        McCamRead {
            execute: false,
            request: hli::calls::cam::CamReadCall {
                what,
                ..Default::default()
            },
            target: 0,
            values: Vec::with_capacity(room),
            columns: 1,
            out: Outputs::default(),
            kernel: Kernel::default(),
        }
    }

    /// Input tTimeout: cycles to wait for each part.
    pub fn set_timeout_cycles(&mut self, cycles: u64) {
        self.kernel.set_timeout_cycles(cycles);
    }

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let (target, request) = (self.target, self.request);
        let columns = &mut self.columns;
        let send = |io: &mut PlcIo<'_>, values: &mut Vec<f64>| {
            values.clear();
            PartRead::start(
                io,
                target,
                hli::calls::cam::CamReadCall { part: 0, ..request },
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
    io.acyclic
        .start(table, &call)
        .map_err(|e| call_error_code(&e))
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
        let wanted = if self.count == 0 {
            (reply.total + 1).saturating_sub(self.first) as usize
        } else {
            self.count as usize
        };
        if wanted > points.capacity() {
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
    kernel: Kernel<PointsRead>,
}

impl McReadMotionFunction {
    /// A reader with room for `room` points.
    pub fn new(room: usize) -> McReadMotionFunction {
        McReadMotionFunction {
            execute: false,
            table: 0,
            first: 1,
            count: 0,
            points: Vec::with_capacity(room),
            out: Outputs::default(),
            kernel: Kernel::default(),
        }
    }

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let (table, first, count) = (self.table, self.first, self.count);
        let send = |io: &mut PlcIo<'_>,
                    points: &mut Vec<hli::calls::cam::McMotionFunctionPoint>| {
            points.clear();
            Ok(PointsRead {
                table,
                first,
                count,
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
