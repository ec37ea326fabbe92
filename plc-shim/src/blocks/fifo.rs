//! The FIFO blocks of seed 002 chapter 7 for the PLC program: FiFoGetDimension,
//! FiFoGroupIntegrate, FiFoGroupDisintegrate, FiFoWrite, FiFoOverwrite, FiFoStart, FiFoStop,
//! FiFoSetChannelOverride, our FiFoSetParameters, and the library version function, on the
//! block kernel ([`crate::kernel`]: its Execute, timeout and output rules). Each sends on the
//! rising Execute edge without waiting, is Busy until the CNC answers, then Done or Error
//! (with the CNC's code, [`hli::enums::FifoError`] or [`hli::enums::AxisError`]). No answer
//! within the timeout (the seed's tTimeout; default 1000 cycles) is an Error with
//! [`crate::kernel::ERROR_NO_ANSWER`]: the call may still have been executed.
//!
//! FiFoWrite and FiFoOverwrite send a row block on the row service: the rows are written
//! once, straight into the shared memory the CNC reads (seed: `AdrdataArray`, `iColDim`,
//! `iRowsToWrite`). A block the FIFO cannot take whole is refused whole (`Full`): offer it
//! again later; [`PlcView::fifo_group`](hli::views::PlcView::fifo_group) tells the free rows.

use crate::kernel::{call_error_code, no_follow, Accept, Kernel, Outputs};
use crate::runtime::PlcIo;
use hli::calls::fifo::{
    FifoDimensionCall, FifoDisintegrateCall, FifoIntegrateCall, FifoOverrideCall,
    FifoParametersCall, FifoReply, FifoRowsHeader, FifoStartCall, FifoStopCall, FIFO_BLOCK_VALUES,
};
use hli::calls::AcyclicCall;

use hli::rpc::{PendingCall, PendingRows};

/// Version of this block library (seed 7.9, Get_TcNcFifoAxis_Version).
pub fn fifo_library_version() -> &'static str {
    concat!("cncplc-fifo ", env!("CARGO_PKG_VERSION"))
}

/// Error id of a row block that does not fit one call (more than
/// [`FIFO_BLOCK_VALUES`] values, or rows x columns not the slice given): refused in the PLC.
pub const ERROR_BLOCK_SIZE: u32 = hli::enums::FifoError::BlockSize as u32;

/// The CNC's answer to a FIFO call: Done with its reply, or Error with its code (the reply
/// beside it: the FIFO's state and fill level).
fn accept(reply: FifoReply) -> Accept<(), FifoReply> {
    if reply.error_id != 0 {
        Accept::Failed(reply.error_id, reply)
    } else {
        Accept::Done(reply)
    }
}

/// A one-frame FIFO block. Its outputs carry the CNC's reply as their extra: the FIFO's
/// state, fill level, and FiFoGetDimension's values.
pub struct FifoBlock<C: AcyclicCall<Reply = FifoReply>> {
    kernel: Kernel<PendingCall<C>, (), FifoReply>,
}

impl<C: AcyclicCall<Reply = FifoReply>> Default for FifoBlock<C> {
    fn default() -> Self {
        Self {
            kernel: Kernel::default(),
        }
    }
}

impl<C: AcyclicCall<Reply = FifoReply>> core::fmt::Debug for FifoBlock<C> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.kernel.fmt(f)
    }
}

impl<C: AcyclicCall<Reply = FifoReply>> FifoBlock<C> {
    /// Input: cycles to wait for the answer (tTimeout).
    pub fn set_timeout_cycles(&mut self, cycles: u64) {
        self.kernel.set_timeout_cycles(cycles);
    }

    /// One cycle: on a rising `execute`, `call()` goes to FIFO group `group`.
    pub fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        execute: bool,
        group: u32,
        call: impl FnOnce() -> C,
    ) -> Outputs<FifoReply> {
        self.kernel.cycle(
            io,
            execute,
            |io| {
                io.acyclic
                    .start(group, &call())
                    .map_err(|e| call_error_code(&e))
            },
            accept,
            no_follow,
        )
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
    kernel: Kernel<PendingRows, (), FifoReply>,
}

impl core::fmt::Debug for FifoWrite {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("FifoWrite")
            .field("overwrite", &self.overwrite)
            .field("kernel", &self.kernel)
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
        self.kernel.set_timeout_cycles(cycles);
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
    ) -> Outputs<FifoReply> {
        let overwrite = self.overwrite;
        let send = |io: &mut PlcIo<'_>| {
            let values = (columns as usize).checked_mul(rows as usize);
            match values {
                Some(n) if n <= data.len() && n <= FIFO_BLOCK_VALUES => {
                    let header = FifoRowsHeader {
                        group,
                        columns,
                        rows,
                        overwrite: u32::from(overwrite),
                    };
                    io.acyclic
                        .start_rows(header, &data[..n])
                        .map_err(|e| call_error_code(&e))
                }
                _ => Err(ERROR_BLOCK_SIZE),
            }
        };
        self.kernel.cycle(io, execute, send, accept, no_follow)
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
