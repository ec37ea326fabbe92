//! The FIFO blocks of seed 002 chapter 7 for the PLC program: FiFoGetDimension,
//! FiFoGroupIntegrate, FiFoGroupDisintegrate, FiFoWrite, FiFoOverwrite, FiFoStart, FiFoStop,
//! FiFoSetChannelOverride, our FiFoSetParameters, and the library version function. Each
//! sends on the rising Execute edge without waiting, is Busy until the CNC answers, then
//! Done or Error (with the CNC's code, [`hli::enums::FifoError`] or
//! [`hli::enums::AxisError`]); the outputs clear one cycle after Execute falls. An edge while
//! Busy is ignored (the call on its way keeps its answer). No answer within `timeout_cycles`
//! PLC cycles (the seed's tTimeout; default 1000) is an Error with
//! [`ERROR_NO_ANSWER`]: the call may still have been executed.
//!
//! FiFoWrite and FiFoOverwrite send a row block on the row service: the rows are written
//! once, straight into the shared memory the CNC reads (seed: `AdrdataArray`, `iColDim`,
//! `iRowsToWrite`). A block the FIFO cannot take whole is refused whole (`Full`): offer it
//! again later; [`PlcView::fifo_group`](hli::views::PlcView::fifo_group) tells the free rows.

use crate::cam::rose;
use crate::motion::ERROR_NO_ANSWER;
use crate::runtime::PlcIo;
use hli::calls::fifo::{
    FifoDimensionCall, FifoDisintegrateCall, FifoIntegrateCall, FifoOverrideCall,
    FifoParametersCall, FifoReply, FifoRowsHeader, FifoStartCall, FifoStopCall, FIFO_BLOCK_VALUES,
};
use hli::calls::{AcyclicCall, CallError};
use hli::rpc::{PendingCall, PendingRows};

/// Version of this block library (seed 7.9, Get_TcNcFifoAxis_Version).
pub fn fifo_library_version() -> &'static str {
    concat!("cncplc-fifo ", env!("CARGO_PKG_VERSION"))
}

/// Error id of a row block that does not fit one call (more than
/// [`FIFO_BLOCK_VALUES`] values, or rows x columns not the slice given): refused in the PLC.
pub const ERROR_BLOCK_SIZE: u32 = hli::enums::FifoError::BlockSize as u32;

/// Outputs of a FIFO block.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FifoOutputs {
    /// The CNC took the call.
    pub done: bool,
    /// Sent, not answered.
    pub busy: bool,
    /// Refused or failed; see `error_id`.
    pub error: bool,
    /// The CNC's code (or [`ERROR_NO_ANSWER`]).
    pub error_id: u32,
    /// The CNC's reply: the FIFO's state, fill level, and FiFoGetDimension's values.
    pub reply: FifoReply,
}

fn failed(error_id: u32, reply: FifoReply) -> FifoOutputs {
    FifoOutputs {
        error: true,
        error_id,
        reply,
        ..FifoOutputs::default()
    }
}

fn answered(reply: FifoReply) -> FifoOutputs {
    if reply.error_id != 0 {
        failed(reply.error_id, reply)
    } else {
        FifoOutputs {
            done: true,
            reply,
            ..FifoOutputs::default()
        }
    }
}

/// The outputs an answer gives, or a timeout after `waited` of `timeout` cycles.
fn answer(
    result: Option<Result<FifoReply, CallError>>,
    waited: u64,
    timeout: u64,
) -> Option<FifoOutputs> {
    Some(match result {
        None if waited > timeout => failed(ERROR_NO_ANSWER, FifoReply::default()),
        None => return None,
        Some(Ok(reply)) => answered(reply),
        Some(Err(CallError::Refused { code })) => failed(code.raw(), FifoReply::default()),
        Some(Err(_)) => failed(ERROR_NO_ANSWER, FifoReply::default()),
    })
}

/// PLC cycles a block waits for its answer by default (1 s at a 1 ms cycle).
pub const DEFAULT_TIMEOUT_CYCLES: u64 = 1000;

/// Something on its way to the CNC that yields a [`FifoReply`].
trait Answer {
    fn poll_reply(&self) -> Option<Result<FifoReply, CallError>>;
}

impl<C: AcyclicCall<Reply = FifoReply>> Answer for PendingCall<C> {
    fn poll_reply(&self) -> Option<Result<FifoReply, CallError>> {
        self.poll()
    }
}

impl Answer for PendingRows {
    fn poll_reply(&self) -> Option<Result<FifoReply, CallError>> {
        self.poll()
    }
}

/// Execute edge, the call on its way (with the cycle it left in) and the outputs: what every
/// FIFO block shares.
struct Core<P> {
    timeout_cycles: u64,
    execute_before: bool,
    pending: Option<(P, u64)>,
    out: FifoOutputs,
}

impl<P> Default for Core<P> {
    fn default() -> Self {
        Core {
            timeout_cycles: DEFAULT_TIMEOUT_CYCLES,
            execute_before: false,
            pending: None,
            out: FifoOutputs::default(),
        }
    }
}

impl<P: Answer> Core<P> {
    /// A rising edge with nothing on its way: the block sends now (outputs cleared).
    fn edge(&mut self, execute: bool) -> bool {
        let send = rose(&mut self.execute_before, execute) && self.pending.is_none();
        if send {
            self.out = FifoOutputs::default();
        }
        send
    }

    /// What the send gave: the call on its way, or an error now.
    fn sent(&mut self, result: Result<P, u32>, cycle: u64) {
        match result {
            Ok(p) => self.pending = Some((p, cycle)),
            Err(code) => self.out = failed(code, FifoReply::default()),
        }
    }

    /// Follows the call on its way; the outputs of this cycle.
    fn follow(&mut self, execute: bool, cycle: u64) -> FifoOutputs {
        if let Some((p, sent)) = &self.pending {
            let waited = cycle.saturating_sub(*sent);
            match answer(p.poll_reply(), waited, self.timeout_cycles) {
                None => self.out.busy = true,
                Some(out) => {
                    self.out = out;
                    self.pending = None;
                }
            }
        }
        // Execute low and nothing on its way: the outputs clear (after one cycle shown).
        let shown = self.out;
        if !execute && self.pending.is_none() {
            self.out = FifoOutputs::default();
        }
        shown
    }
}

/// A one-frame FIFO block.
pub struct FifoBlock<C: AcyclicCall<Reply = FifoReply>> {
    core: Core<PendingCall<C>>,
}

impl<C: AcyclicCall<Reply = FifoReply>> Default for FifoBlock<C> {
    fn default() -> Self {
        Self {
            core: Core::default(),
        }
    }
}

impl<C: AcyclicCall<Reply = FifoReply>> core::fmt::Debug for FifoBlock<C> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("FifoBlock")
            .field("out", &self.core.out)
            .finish()
    }
}

impl<C: AcyclicCall<Reply = FifoReply>> FifoBlock<C> {
    /// Input: cycles to wait for the answer (tTimeout).
    pub fn set_timeout_cycles(&mut self, cycles: u64) {
        self.core.timeout_cycles = cycles;
    }

    /// One cycle: on a rising `execute`, `call()` goes to FIFO group `group`.
    pub fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        execute: bool,
        group: u32,
        call: impl FnOnce() -> C,
    ) -> FifoOutputs {
        if self.core.edge(execute) {
            let result = io.acyclic.start(group, &call());
            self.core
                .sent(result.map_err(|_| ERROR_NO_ANSWER), io.cycle);
        }
        self.core.follow(execute, io.cycle)
    }
}

/// FiFoGetDimension: `reply.dimension` (iNoOfAxes) and `reply.capacity` (iNoOfFifoEntries).
pub type FifoGetDimension = FifoBlock<FifoDimensionCall>;
/// FiFoGroupIntegrate.
pub type FifoGroupIntegrate = FifoBlock<FifoIntegrateCall>;
/// FiFoGroupDisintegrate.
pub type FifoGroupDisintegrate = FifoBlock<FifoDisintegrateCall>;
/// FiFoStart.
pub type FifoStart = FifoBlock<FifoStartCall>;
/// FiFoStop.
pub type FifoStop = FifoBlock<FifoStopCall>;
/// FiFoSetChannelOverride (ppm, 1,000,000 = 100 %).
pub type FifoSetChannelOverride = FifoBlock<FifoOverrideCall>;
/// FiFoSetParameters (ours): T_f and the override type while the group is not running.
pub type FifoSetParameters = FifoBlock<FifoParametersCall>;

/// FiFoWrite (`overwrite` false) or FiFoOverwrite (true).
#[derive(Default)]
pub struct FifoWrite {
    /// FiFoOverwrite: replace the rows queued behind the pair in use.
    pub overwrite: bool,
    core: Core<PendingRows>,
}

impl core::fmt::Debug for FifoWrite {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("FifoWrite")
            .field("overwrite", &self.overwrite)
            .field("out", &self.core.out)
            .finish()
    }
}

impl FifoWrite {
    /// FiFoOverwrite.
    pub fn overwrite() -> FifoWrite {
        FifoWrite {
            overwrite: true,
            ..FifoWrite::default()
        }
    }

    /// Input: cycles to wait for the answer (tTimeout).
    pub fn set_timeout_cycles(&mut self, cycles: u64) {
        self.core.timeout_cycles = cycles;
    }

    /// One cycle: on a rising `execute`, the first `rows` rows of `data` (rows of `columns`
    /// values, row after row: iColDim, iRowsToWrite) go to group `group`.
    pub fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        execute: bool,
        group: u32,
        data: &[f64],
        columns: u32,
        rows: u32,
    ) -> FifoOutputs {
        if self.core.edge(execute) {
            let values = (columns as usize).checked_mul(rows as usize);
            let result = match values {
                Some(n) if n <= data.len() && n <= FIFO_BLOCK_VALUES => {
                    let header = FifoRowsHeader {
                        group,
                        columns,
                        rows,
                        overwrite: u32::from(self.overwrite),
                    };
                    io.acyclic
                        .start_rows(header, &data[..n])
                        .map_err(|_| ERROR_NO_ANSWER)
                }
                _ => Err(ERROR_BLOCK_SIZE),
            };
            self.core.sent(result, io.cycle);
        }
        self.core.follow(execute, io.cycle)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_library_names_its_version() {
        let v = super::fifo_library_version();
        assert_eq!(v, concat!("cncplc-fifo ", env!("CARGO_PKG_VERSION")));
        assert!(v.len() <= 20, "fits the seed's STRING(20)");
    }
}
