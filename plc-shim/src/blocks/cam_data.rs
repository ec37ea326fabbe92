//! The cam blocks of chapter 5.1 that send table data: MC_CamTableSelect (with the table's
//! rows or points, if given, before the selection) and MC_WriteMotionFunction, both sending
//! their data in chunks, one chunk in flight and one per cycle at most.

use crate::kernel::{
    call_error_code, done_unless, no_follow, Accept, InFlight, Kernel, Outputs, Polled,
};
use crate::runtime::PlcIo;
use hli::calls::cam::{CamReply, CamTableSelectCall};
use hli::calls::CallError;
use hli::rpc::PendingCall;

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
