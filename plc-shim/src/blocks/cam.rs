//! The cam blocks of chapter 5.1 for the PLC program: MC_CamTableSelect, MC_CamIn,
//! MC_CamInExt, MC_CamOut and MC_CamScaling. Like the motion blocks, each sends its call on
//! the rising Execute edge without waiting and stays Busy until the CNC answers. MC_CamIn
//! and MC_CamInExt then follow the slave's axis image: InSync once the slave is coupled
//! through a cam and synchronous (`coupling_state_r` 1, `nAxisState` 13), CommandAborted when
//! the coupling goes away, Error with the axis's error when the slave faults. The others are
//! Done when the CNC has taken the command (a scaling with a positional activation mode is
//! then queued in the CNC).

use crate::kernel::{
    call_error_code, done_unless, no_follow, Accept, InFlight, Kernel, Outputs, Polled, Step,
};
use crate::runtime::PlcIo;
use hli::calls::cam::{CamInCall, CamOutCall, CamReply, CamScalingCall, CamTableSelectCall};
use hli::calls::{AcyclicCall, CallError};
use hli::enums::{AxisState, CouplingState};
use hli::rpc::PendingCall;

/// The block kernel as the cam blocks use it: a coupling (MC_CamIn) follows the slave's
/// image, remembering whether it has seen the coupling there; the others are Done when the
/// CNC took the call.
pub struct CamCore<C: AcyclicCall> {
    kernel: Kernel<PendingCall<C>, bool>,
}

impl<C: AcyclicCall> Default for CamCore<C> {
    fn default() -> Self {
        Self {
            kernel: Kernel::default(),
        }
    }
}

impl<C: AcyclicCall> core::fmt::Debug for CamCore<C> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.kernel.fmt(f)
    }
}

pub(crate) fn failed(code: u32) -> Outputs {
    Outputs::failed(code)
}

/// A cam coupling of `slave` as its image shows it; `seen` once the coupling showed there.
fn follow_coupling(io: &PlcIo<'_>, slave: u32, seen: &mut bool) -> Step<()> {
    let state = io.view.axis_state(slave as usize).ok();
    let cam = state.is_some_and(|s| s.coupling_state_r == CouplingState::Cam.raw());
    let synchronous =
        state.is_some_and(|s| s.axis_state_r == AxisState::SlaveSynchronous.raw() && cam);
    let error = state.map_or(0, |s| s.error_id_r);
    if error != 0 {
        Step::Ended(failed(error))
    } else if cam {
        *seen = true;
        Step::Running(Outputs {
            in_sync: synchronous,
            busy: !synchronous,
            ..Outputs::default()
        })
    } else if *seen {
        Step::Ended(Outputs::aborted())
    } else {
        // Accepted between two ticks: the image shows it from the next tick on.
        Step::Running(Outputs::busy())
    }
}

impl<C: AcyclicCall<Reply = CamReply>> CamCore<C> {
    /// One cycle: `call` goes to `target` on a rising edge of `execute`; a coupling block
    /// (`couples`) then follows `slave`'s image.
    pub fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        execute: bool,
        target: u32,
        call: impl FnOnce() -> C,
        couples: Option<u32>,
    ) -> Outputs {
        self.kernel.cycle(
            io,
            execute,
            |io| {
                io.acyclic
                    .start(target, &call())
                    .map_err(|e| call_error_code(&e))
            },
            |reply| match (reply.error_id, couples) {
                (0, Some(_)) => Accept::Follow(false, Outputs::busy()),
                (code, _) => done_unless(code),
            },
            |seen, io, _| match couples {
                Some(slave) => follow_coupling(io, slave, seen),
                None => Step::Ended(Outputs::done(())),
            },
        )
    }

    /// Input tTimeout: cycles to wait for the CNC's answer.
    pub fn set_timeout_cycles(&mut self, cycles: u64) {
        self.kernel.set_timeout_cycles(cycles);
    }
}

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
    /// Outputs of the last call.
    pub out: Outputs,
    kernel: Kernel<SelectTransfer>,
}

impl McCamTableSelect {
    /// One cycle: the data in chunks (if any), then the selection.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        if let CamData::Rows {
            table_type,
            interpolation,
            ..
        } = &mut self.data
        {
            *table_type = if self.table_type == 0 {
                10
            } else {
                self.table_type
            };
            *interpolation = self.interpolation;
        }
        let call = CamTableSelectCall {
            periodic: u32::from(self.periodic),
            master_absolute: u32::from(self.master_absolute),
            slave_absolute: u32::from(self.slave_absolute),
            reserved: 0,
        };
        let (table, data, periodic) = (self.table, &self.data, self.periodic);
        let send = |io: &mut PlcIo<'_>| match data {
            CamData::None => io
                .acyclic
                .start(table, &call)
                .map(SelectTransfer::Selecting)
                .map_err(|e| call_error_code(&e)),
            data => Ok(SelectTransfer::Loading(
                ChunkTransfer::new(table, data, true, periodic),
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

/// MC_CamIn and MC_CamInExt (`extended`): couples `slave` to `master` through a cam.
#[derive(Debug)]
pub struct McCamIn {
    /// Input: a rising edge sends the coupling.
    pub execute: bool,
    /// Input: the master axis.
    pub master: u32,
    /// Input: the cam table ID.
    pub table: u32,
    /// Input: raw `MC_StartMode` (1 absolute .. 4).
    pub start_mode: u32,
    /// Input (Ext): raw `MC_CamActivationMode`.
    pub activation_mode: u32,
    /// Input (Ext): the activation position.
    pub activation_position: f64,
    /// Input (Ext): raw `MC_CamScalingMode` of the master.
    pub master_scaling_mode: u32,
    /// Input (Ext): raw `MC_CamScalingMode` of the slave.
    pub slave_scaling_mode: u32,
    /// Input: master offset.
    pub master_offset: f64,
    /// Input: slave offset.
    pub slave_offset: f64,
    /// Input: master scaling.
    pub master_scaling: f64,
    /// Input: slave scaling.
    pub slave_scaling: f64,
    /// Input: raw `MC_InterpolationType` (tables).
    pub interpolation: u32,
    /// MC_CamInExt rather than MC_CamIn.
    pub extended: bool,
    /// Input: follow the master's actual position (else its set-point).
    pub master_actual: bool,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<CamInCall>,
}

impl Default for McCamIn {
    fn default() -> Self {
        Self {
            execute: false,
            master: 0,
            table: 0,
            start_mode: 1,
            activation_mode: 0,
            activation_position: 0.0,
            master_scaling_mode: 0,
            slave_scaling_mode: 0,
            master_offset: 0.0,
            slave_offset: 0.0,
            master_scaling: 1.0,
            slave_scaling: 1.0,
            interpolation: 0,
            extended: false,
            master_actual: false,
            out: Outputs::default(),
            core: CamCore::default(),
        }
    }
}

impl McCamIn {
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let call = CamInCall {
            master: self.master,
            table_id: self.table,
            start_mode: self.start_mode,
            activation_mode: self.activation_mode,
            master_scaling_mode: self.master_scaling_mode,
            slave_scaling_mode: self.slave_scaling_mode,
            interpolation: self.interpolation,
            extended: u32::from(self.extended),
            activation_position: self.activation_position,
            master_offset: self.master_offset,
            slave_offset: self.slave_offset,
            master_scaling: self.master_scaling,
            slave_scaling: self.slave_scaling,
            master_source: u32::from(self.master_actual),
            reserved: 0,
        };
        self.out = self
            .core
            .cycle(io, self.execute, slave, || call, Some(slave));
    }
}

/// MC_CamOut: the slave leaves its cam and goes on at its velocity as a free axis.
#[derive(Debug, Default)]
pub struct McCamOut {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<CamOutCall>,
}

impl McCamOut {
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        self.out = self
            .core
            .cycle(io, self.execute, slave, CamOutCall::default, None);
    }
}

/// MC_CamScaling: new offsets and scalings of a coupling, now or at an activation.
#[derive(Debug)]
pub struct McCamScaling {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Input: raw `MC_CamActivationMode`.
    pub activation_mode: u32,
    /// Input: the activation position.
    pub activation_position: f64,
    /// Input: raw `MC_CamScalingMode` of the master.
    pub master_scaling_mode: u32,
    /// Input: raw `MC_CamScalingMode` of the slave.
    pub slave_scaling_mode: u32,
    /// Input: master offset.
    pub master_offset: f64,
    /// Input: slave offset.
    pub slave_offset: f64,
    /// Input: master scaling.
    pub master_scaling: f64,
    /// Input: slave scaling.
    pub slave_scaling: f64,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<CamScalingCall>,
}

impl Default for McCamScaling {
    fn default() -> Self {
        Self {
            execute: false,
            activation_mode: 0,
            activation_position: 0.0,
            master_scaling_mode: 0,
            slave_scaling_mode: 0,
            master_offset: 0.0,
            slave_offset: 0.0,
            master_scaling: 1.0,
            slave_scaling: 1.0,
            out: Outputs::default(),
            core: CamCore::default(),
        }
    }
}

impl McCamScaling {
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let call = CamScalingCall {
            activation_mode: self.activation_mode,
            master_scaling_mode: self.master_scaling_mode,
            slave_scaling_mode: self.slave_scaling_mode,
            reserved: 0,
            activation_position: self.activation_position,
            master_offset: self.master_offset,
            slave_offset: self.slave_offset,
            master_scaling: self.master_scaling,
            slave_scaling: self.slave_scaling,
        };
        self.out = self.core.cycle(io, self.execute, slave, || call, None);
    }
}

/// MC_WriteMotionFunctionPoint: one point of the motion function `table` changed, under the
/// table's online-change mode (MC_SetCamOnlineChangeMode). Done when the CNC took it (checked
/// whole with the function it changes; queued when its activation is still to come).
#[derive(Debug, Default)]
pub struct McWriteMotionFunctionPoint {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Input: the table ID.
    pub table: u32,
    /// Input: the point.
    pub point: hli::calls::cam::McMotionFunctionPoint,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<hli::calls::cam::CamPointsWriteCall>,
}

impl McWriteMotionFunctionPoint {
    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let mut points = [hli::calls::cam::McMotionFunctionPoint::default(); 4];
        points[0] = self.point;
        let call = hli::calls::cam::CamPointsWriteCall {
            first: self.point.point_index,
            count: 1,
            flags: hli::calls::cam::CAM_CHUNK_FIRST | hli::calls::cam::CAM_CHUNK_LAST,
            total: 1,
            points,
        };
        self.out = self.core.cycle(io, self.execute, self.table, || call, None);
    }
}

/// MC_SetCamOnlineChangeMode: when point changes of `table` apply, and whether the master
/// and slave offsets follow so that nothing jumps.
#[derive(Debug, Default)]
pub struct McSetCamOnlineChangeMode {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Input: the table ID.
    pub table: u32,
    /// Input: raw `MC_CamActivationMode`.
    pub activation_mode: u32,
    /// Input: the activation position.
    pub activation_position: f64,
    /// Input: raw `MC_CamScalingMode` of the master.
    pub master_scaling_mode: u32,
    /// Input: raw `MC_CamScalingMode` of the slave.
    pub slave_scaling_mode: u32,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<hli::calls::cam::CamOnlineModeCall>,
}

impl McSetCamOnlineChangeMode {
    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let call = hli::calls::cam::CamOnlineModeCall {
            activation_mode: self.activation_mode,
            master_scaling_mode: self.master_scaling_mode,
            slave_scaling_mode: self.slave_scaling_mode,
            reserved: 0,
            activation_position: self.activation_position,
        };
        self.out = self.core.cycle(io, self.execute, self.table, || call, None);
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
}

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
        }
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
                let chunk = rows
                    .get(self.next..)?
                    .get(..hli::calls::cam::CAM_ROWS_PER_CALL.min(rows.len() - self.next))?;
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
    /// Outputs of the last call.
    pub out: Outputs,
    kernel: Kernel<ChunkTransfer>,
}

impl McWriteMotionFunction {
    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let (table, points) = (self.table, &self.points);
        self.out = self.kernel.cycle(
            io,
            self.execute,
            |_| Ok(ChunkTransfer::new(table, points, false, false)),
            |()| Accept::Done(()),
            no_follow,
        );
    }
}

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

/// CamTableSetWeight (5.2.3.1): weight, offsets, slopes and range of `table` in a
/// multi-table slave.
#[derive(Debug)]
pub struct CamTableSetWeight {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Input: the table ID.
    pub table: u32,
    /// Input: the scaling.
    pub weight: hli::calls::cam::CamTableWeightCall,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<hli::calls::cam::CamTableWeightCall>,
}

impl Default for CamTableSetWeight {
    fn default() -> Self {
        Self {
            execute: false,
            table: 0,
            weight: hli::calls::cam::CamTableWeightCall {
                weight: 1.0,
                master_slope: 1.0,
                slave_slope: 1.0,
                range_low: -1e300,
                range_high: 1e300,
                ..Default::default()
            },
            out: Outputs::default(),
            core: CamCore::default(),
        }
    }
}

impl CamTableSetWeight {
    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let call = self.weight;
        self.out = self.core.cycle(io, self.execute, self.table, || call, None);
    }
}

/// CamTableCoupleAxesMultiTables (5.2.3.2): couples `slave` to `master` through up to
/// eight tables (the first `profiles` are profile tables, the others corrections), or
/// decouples it (`on` FALSE; the block's CoupleOff edge).
#[derive(Debug, Default)]
pub struct CamTableCoupleAxesMultiTables {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Input: couple (TRUE) or decouple (FALSE).
    pub on: bool,
    /// Input: the master axis.
    pub master: u32,
    /// Input: the table IDs (up to 8).
    pub tables: [u32; 8],
    /// Input: tables used.
    pub count: u32,
    /// Input: profile tables among them.
    pub profiles: u32,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<hli::calls::cam::CamMultiCoupleCall>,
}

impl CamTableCoupleAxesMultiTables {
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let call = hli::calls::cam::CamMultiCoupleCall {
            master: self.master,
            on: u32::from(self.on),
            tables: self.count,
            profiles: self.profiles,
            table_ids: self.tables,
        };
        self.out = self.core.cycle(io, self.execute, slave, || call, None);
    }
}

/// CamTableEnableCorrectionTable (5.2.3.3) and CamTableDeactivateCyclicTable (5.2.3.4):
/// a table of a multi-table slave started (a correction: at once, or at `position` when
/// `at_position`) or ended at its cycle boundary (a cyclic profile table).
#[derive(Debug, Default)]
pub struct CamMultiTable {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// What it does: [`hli::calls::cam::CAM_MULTI_ENABLE_CORRECTION`] or
    /// [`hli::calls::cam::CAM_MULTI_STOP_CYCLIC`].
    pub op: u32,
    /// Input: the table ID.
    pub table: u32,
    /// Input: a correction starts at `position` rather than at once.
    pub at_position: bool,
    /// Input: the activation position.
    pub position: f64,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<hli::calls::cam::CamMultiTableCall>,
}

impl CamMultiTable {
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let call = hli::calls::cam::CamMultiTableCall {
            op: self.op,
            table: self.table,
            flags: u32::from(self.at_position),
            reserved: 0,
            position: self.position,
        };
        self.out = self.core.cycle(io, self.execute, slave, || call, None);
    }
}
