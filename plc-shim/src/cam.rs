//! The cam blocks of chapter 5.1 for the PLC program: MC_CamTableSelect, MC_CamIn,
//! MC_CamInExt, MC_CamOut and MC_CamScaling. Like the motion blocks, each sends its call on
//! the rising Execute edge without waiting and stays Busy until the CNC answers. MC_CamIn
//! and MC_CamInExt then follow the slave's axis image: InSync once the slave is coupled
//! through a cam and synchronous (`coupling_state_r` 1, `nAxisState` 13), CommandAborted when
//! the coupling goes away, Error with the axis's error when the slave faults. The others are
//! Done when the CNC has taken the command (a scaling with a positional activation mode is
//! then queued in the CNC).

use crate::runtime::PlcIo;
use hli::calls::cam::{CamInCall, CamOutCall, CamReply, CamScalingCall, CamTableSelectCall};
use hli::calls::{AcyclicCall, CallError};
use hli::enums::{AxisState, CouplingState};
use hli::rpc::PendingCall;

/// Outputs of a cam block.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CamOutputs {
    /// The CNC took the command (one-shot blocks).
    pub done: bool,
    /// Sent and not finished.
    pub busy: bool,
    /// MC_CamIn(Ext): the slave follows the cam.
    pub in_sync: bool,
    /// MC_CamIn(Ext): the coupling ended without this block (MC_CamOut, a fault, a stop).
    pub command_aborted: bool,
    /// Refused or failed; see `error_id`.
    pub error: bool,
    /// The CNC's error code.
    pub error_id: u32,
}

impl CamOutputs {
    /// Sent, not finished.
    pub const BUSY: CamOutputs = CamOutputs {
        done: false,
        busy: true,
        in_sync: false,
        command_aborted: false,
        error: false,
        error_id: 0,
    };
    /// Finished.
    pub const DONE: CamOutputs = CamOutputs {
        done: true,
        busy: false,
        in_sync: false,
        command_aborted: false,
        error: false,
        error_id: 0,
    };
}

/// Whether `execute` rose since the last cycle (and remembers it for the next).
pub(crate) fn rose(before: &mut bool, execute: bool) -> bool {
    let rising = execute && !*before;
    *before = execute;
    rising
}

enum Phase<C: AcyclicCall> {
    Idle,
    Sent(PendingCall<C>),
    /// A coupling accepted; `seen` once the slave showed it.
    Following {
        seen: bool,
    },
}

/// The Execute edge, the pending call and the outputs, shared by the cam blocks.
pub struct CamCore<C: AcyclicCall> {
    execute_before: bool,
    phase: Phase<C>,
    out: CamOutputs,
}

impl<C: AcyclicCall> Default for CamCore<C> {
    fn default() -> Self {
        Self {
            execute_before: false,
            phase: Phase::Idle,
            out: CamOutputs::default(),
        }
    }
}

impl<C: AcyclicCall> core::fmt::Debug for CamCore<C> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("CamCore").field("out", &self.out).finish()
    }
}

pub(crate) fn failed(code: u32) -> CamOutputs {
    CamOutputs {
        error: true,
        error_id: code,
        ..CamOutputs::default()
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
    ) -> CamOutputs {
        let rising = rose(&mut self.execute_before, execute);
        if rising {
            self.out = CamOutputs::default();
            self.phase = match io.acyclic.start(target, &call()) {
                Ok(pending) => Phase::Sent(pending),
                Err(_) => {
                    self.out = failed(crate::motion::ERROR_NO_ANSWER);
                    Phase::Idle
                }
            };
        }
        if let Phase::Sent(pending) = &self.phase {
            match pending.poll() {
                None => self.out.busy = true,
                Some(Ok(reply)) if reply.error_id != 0 => {
                    self.out = failed(reply.error_id);
                    self.phase = Phase::Idle;
                }
                Some(Ok(_)) => match couples {
                    Some(_) => self.phase = Phase::Following { seen: false },
                    None => {
                        self.out = CamOutputs::DONE;
                        self.phase = Phase::Idle;
                    }
                },
                Some(Err(CallError::Refused { code })) => {
                    self.out = failed(code.raw());
                    self.phase = Phase::Idle;
                }
                Some(Err(_)) => {
                    self.out = failed(crate::motion::ERROR_NO_ANSWER);
                    self.phase = Phase::Idle;
                }
            }
        }
        if let (Phase::Following { seen }, Some(slave)) = (&mut self.phase, couples) {
            let state = io.view.axis_state(slave as usize).ok();
            let cam = state.is_some_and(|s| s.coupling_state_r == CouplingState::Cam.raw());
            let synchronous =
                state.is_some_and(|s| s.axis_state_r == AxisState::SlaveSynchronous.raw() && cam);
            let error = state.map_or(0, |s| s.error_id_r);
            if error != 0 {
                self.out = failed(error);
                self.phase = Phase::Idle;
            } else if cam {
                *seen = true;
                self.out = CamOutputs {
                    in_sync: synchronous,
                    busy: !synchronous,
                    ..CamOutputs::default()
                };
            } else if *seen {
                self.out = CamOutputs {
                    command_aborted: true,
                    ..CamOutputs::default()
                };
                self.phase = Phase::Idle;
            } else {
                // Accepted between two ticks: the image shows it from the next tick on.
                self.out.busy = true;
            }
        }
        if !execute && matches!(self.phase, Phase::Idle) {
            // Execute low and nothing running: the outputs clear (after one cycle shown).
            let shown = self.out;
            self.out = CamOutputs::default();
            return shown;
        }
        self.out
    }
}

/// What a pending call gave this cycle, with a transport failure or a refusal as its code.
enum Polled<R> {
    /// No answer yet.
    Waiting,
    /// The reply body.
    Reply(R),
    /// Refused or not answered: the code the block reports.
    Failed(u32),
}

fn poll<C: AcyclicCall>(pending: &PendingCall<C>) -> Polled<C::Reply> {
    match pending.poll() {
        None => Polled::Waiting,
        Some(Ok(reply)) => Polled::Reply(reply),
        Some(Err(CallError::Refused { code })) => Polled::Failed(code.raw()),
        Some(Err(_)) => Polled::Failed(crate::motion::ERROR_NO_ANSWER),
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
    pub out: CamOutputs,
    core: CamCore<CamTableSelectCall>,
    chunker: Chunker,
    execute_before: bool,
    loading: bool,
}

impl McCamTableSelect {
    /// One cycle: the data in chunks (if any), then the selection.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let rising = rose(&mut self.execute_before, self.execute);
        if rising && !matches!(self.data, CamData::None) {
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
            self.chunker.reset();
            self.loading = true;
            self.core = CamCore::default();
        }
        if self.loading {
            match self
                .chunker
                .cycle(io, self.table, &self.data, true, self.periodic)
            {
                Transfer::Running => {
                    self.out = CamOutputs::BUSY;
                    return;
                }
                Transfer::Failed(code) => {
                    self.loading = false;
                    self.out = failed(code);
                    return;
                }
                // Loaded: the selection goes out with a rising edge of its own core.
                Transfer::Done => self.loading = false,
            }
        }
        let call = CamTableSelectCall {
            periodic: u32::from(self.periodic),
            master_absolute: u32::from(self.master_absolute),
            slave_absolute: u32::from(self.slave_absolute),
            reserved: 0,
        };
        self.out = self.core.cycle(io, self.execute, self.table, || call, None);
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
    pub out: CamOutputs,
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
            out: CamOutputs::default(),
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
    pub out: CamOutputs,
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
    pub out: CamOutputs,
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
            out: CamOutputs::default(),
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
    pub out: CamOutputs,
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
    pub out: CamOutputs,
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

/// Sends [`CamData`] chunk by chunk, one per cycle at most (a PLC cycle never waits).
#[derive(Default)]
pub struct Chunker {
    pending: Option<Pending>,
    next: usize,
    done: bool,
}

impl core::fmt::Debug for Chunker {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Chunker")
            .field("next", &self.next)
            .field("done", &self.done)
            .finish()
    }
}

/// Where a transfer stands after a cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transfer {
    /// Chunks still to go.
    Running,
    /// Every chunk taken.
    Done,
    /// Refused with this code (or no answer).
    Failed(u32),
}

impl Transfer {
    /// The block outputs it shows, and whether the transfer still runs.
    pub fn outputs(self) -> (CamOutputs, bool) {
        match self {
            Transfer::Running => (CamOutputs::BUSY, true),
            Transfer::Done => (CamOutputs::DONE, false),
            Transfer::Failed(code) => (failed(code), false),
        }
    }
}

impl Chunker {
    /// Starts over.
    pub fn reset(&mut self) {
        *self = Chunker::default();
    }

    /// One cycle of the transfer of `data` to table `table` (`create`: the points make a new
    /// function; `periodic` for rows).
    pub fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        table: u32,
        data: &CamData,
        create: bool,
        periodic: bool,
    ) -> Transfer {
        if self.done {
            return Transfer::Done;
        }
        let answered = match &self.pending {
            None => None,
            Some(Pending::Rows(p)) => p.poll().map(|r| r.map(|r| r.error_id)),
            Some(Pending::Points(p)) => p.poll().map(|r| r.map(|r| r.error_id)),
        };
        match answered {
            Some(Ok(0)) => self.pending = None,
            Some(Ok(code)) => return Transfer::Failed(code),
            Some(Err(CallError::Refused { code })) => return Transfer::Failed(code.raw()),
            Some(Err(_)) => return Transfer::Failed(crate::motion::ERROR_NO_ANSWER),
            None if self.pending.is_some() => return Transfer::Running,
            None => {}
        }
        let sent = match data {
            CamData::None => {
                self.done = true;
                return Transfer::Done;
            }
            CamData::Rows {
                rows,
                table_type,
                interpolation,
            } => {
                let per = hli::calls::cam::CAM_ROWS_PER_CALL;
                if self.next >= rows.len() {
                    self.done = true;
                    return Transfer::Done;
                }
                let chunk = &rows[self.next..(self.next + per).min(rows.len())];
                let mut call = hli::calls::cam::CamRowsWriteCall {
                    first_row: self.next as u32,
                    count: chunk.len() as u32,
                    flags: (if self.next + chunk.len() == rows.len() {
                        hli::calls::cam::CAM_CHUNK_LAST
                    } else {
                        0
                    }) | if self.next == 0 {
                        hli::calls::cam::CAM_CHUNK_FIRST
                    } else {
                        0
                    },
                    total: rows.len() as u32,
                    table_type: *table_type,
                    interpolation: *interpolation,
                    periodic: u32::from(periodic),
                    ..Default::default()
                };
                call.rows[..chunk.len()].copy_from_slice(chunk);
                self.next += chunk.len();
                io.acyclic.start(table, &call).map(Pending::Rows)
            }
            CamData::Points(points) => {
                let per = hli::calls::cam::CAM_POINTS_PER_CALL;
                if self.next >= points.len() {
                    self.done = true;
                    return Transfer::Done;
                }
                let chunk = &points[self.next..(self.next + per).min(points.len())];
                let mut call = hli::calls::cam::CamPointsWriteCall {
                    first: chunk[0].point_index,
                    count: chunk.len() as u32,
                    flags: (if self.next + chunk.len() == points.len() {
                        hli::calls::cam::CAM_CHUNK_LAST
                    } else {
                        0
                    }) | if create {
                        hli::calls::cam::CAM_POINTS_CREATE
                    } else {
                        0
                    } | if self.next == 0 {
                        hli::calls::cam::CAM_CHUNK_FIRST
                    } else {
                        0
                    },
                    total: points.len() as u32,
                    ..Default::default()
                };
                call.points[..chunk.len()].copy_from_slice(chunk);
                self.next += chunk.len();
                io.acyclic.start(table, &call).map(Pending::Points)
            }
        };
        match sent {
            Ok(p) => {
                self.pending = Some(p);
                Transfer::Running
            }
            Err(_) => Transfer::Failed(crate::motion::ERROR_NO_ANSWER),
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
    pub out: CamOutputs,
    execute_before: bool,
    chunker: Chunker,
    running: bool,
}

impl McWriteMotionFunction {
    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let rising = rose(&mut self.execute_before, self.execute);
        if rising {
            self.chunker.reset();
            self.running = true;
            self.out = CamOutputs::default();
        }
        if self.running {
            let transfer = self
                .chunker
                .cycle(io, self.table, &self.points, false, false);
            (self.out, self.running) = transfer.outputs();
        } else if !self.execute {
            self.out = CamOutputs::default();
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
    pub out: CamOutputs,
    execute_before: bool,
    pending: Option<PendingCall<hli::calls::cam::CamReadCall>>,
    part: u32,
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
            out: CamOutputs::default(),
            execute_before: false,
            pending: None,
            part: 0,
        }
    }

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let rising = rose(&mut self.execute_before, self.execute);
        if rising {
            self.values.clear();
            self.part = 0;
            self.out = CamOutputs::BUSY;
            self.send(io);
            return;
        }
        let Some(pending) = &self.pending else {
            if !self.execute {
                self.out = CamOutputs::default();
            }
            return;
        };
        match poll(pending) {
            Polled::Waiting => {}
            Polled::Reply(reply) if reply.error_id != 0 => {
                self.pending = None;
                self.out = failed(reply.error_id);
            }
            Polled::Reply(reply) => {
                self.pending = None;
                let count = reply.count as usize;
                if self.values.len() + count > self.values.capacity()
                    || reply.total as usize > self.values.capacity()
                {
                    self.out = failed(0x4B31);
                    return;
                }
                self.values.extend_from_slice(&reply.values[..count]);
                self.columns = reply.columns;
                if self.values.len() >= reply.total as usize || count == 0 {
                    self.out = CamOutputs::DONE;
                } else {
                    self.part += 1;
                    self.send(io);
                }
            }
            Polled::Failed(code) => {
                self.pending = None;
                self.out = failed(code);
            }
        }
    }

    fn send(&mut self, io: &mut PlcIo<'_>) {
        let call = hli::calls::cam::CamReadCall {
            part: self.part,
            ..self.request
        };
        match io.acyclic.start(self.target, &call) {
            Ok(p) => self.pending = Some(p),
            Err(_) => self.out = failed(crate::motion::ERROR_NO_ANSWER),
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
    pub out: CamOutputs,
    execute_before: bool,
    pending: Option<PendingCall<hli::calls::cam::CamPointsReadCall>>,
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
            out: CamOutputs::default(),
            execute_before: false,
            pending: None,
        }
    }

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let rising = rose(&mut self.execute_before, self.execute);
        if rising {
            self.points.clear();
            self.out = CamOutputs::BUSY;
            self.send(io);
            return;
        }
        let Some(pending) = &self.pending else {
            if !self.execute {
                self.out = CamOutputs::default();
            }
            return;
        };
        match poll(pending) {
            Polled::Waiting => {}
            Polled::Reply(reply) if reply.error_id != 0 => {
                self.pending = None;
                self.out = failed(reply.error_id);
            }
            Polled::Reply(reply) => {
                self.pending = None;
                let wanted = if self.count == 0 {
                    (reply.total + 1).saturating_sub(self.first) as usize
                } else {
                    self.count as usize
                };
                if wanted > self.points.capacity() {
                    self.out = failed(0x4B31);
                    return;
                }
                let take = (reply.count as usize).min(wanted.saturating_sub(self.points.len()));
                self.points.extend_from_slice(&reply.points[..take]);
                if self.points.len() >= wanted || reply.count == 0 {
                    self.out = CamOutputs::DONE;
                } else {
                    self.send(io);
                }
            }
            Polled::Failed(code) => {
                self.pending = None;
                self.out = failed(code);
            }
        }
    }

    fn send(&mut self, io: &mut PlcIo<'_>) {
        let call = hli::calls::cam::CamPointsReadCall {
            first: self.first + self.points.len() as u32,
            count: 0,
        };
        match io.acyclic.start(self.table, &call) {
            Ok(p) => self.pending = Some(p),
            Err(_) => self.out = failed(crate::motion::ERROR_NO_ANSWER),
        }
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
    pub out: CamOutputs,
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
            out: CamOutputs::default(),
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
    pub out: CamOutputs,
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
    pub out: CamOutputs,
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
