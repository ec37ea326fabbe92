//! The outcome of the PLC's dynamic-CS transitions (`gpCh[i]^channel_mc_control.dyn_cs_result`):
//! written by the CNC, read by the PLC.

use super::{control_unit, CncView, IndexError, PlcChannel};
use crate::desc::PlaceExt;
use crate::layout::{HliChannelMcControl, HliDynCsTransitionResult};
use core::mem::offset_of;

impl CncView<'_> {
    /// Writes channel `channel`'s transition result.
    pub fn write_dyn_cs_result(
        &self,
        channel: usize,
        result: &HliDynCsTransitionResult,
    ) -> Result<(), IndexError> {
        let block = self.nav.channel(channel)?;
        control_unit::<HliDynCsTransitionResult>(
            block,
            offset_of!(HliChannelMcControl, dyn_cs_result),
        )
        .write(result);
        Ok(())
    }
}

impl PlcChannel<'_> {
    /// Reads the outcome of the dynamic-CS transitions.
    pub fn dyn_cs_result(&self) -> HliDynCsTransitionResult {
        control_unit::<HliDynCsTransitionResult>(
            self.block,
            offset_of!(HliChannelMcControl, dyn_cs_result),
        )
        .read()
    }
}
