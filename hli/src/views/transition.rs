//! The outcome of the PLC's dynamic-CS transitions (`gpCh[i]^channel_mc_control.dyn_cs_result`):
//! written by the CNC, read by the PLC. The count is the unit's release: the CNC writes it
//! last with release ordering, the PLC reads it first with acquire ordering, so a new count
//! comes with the command word, result and states of its transition.

use super::{control_unit, CncView, IndexError, PlcChannel};
use crate::desc::PlaceExt;
use crate::layout::{HliChannelMcControl, HliDynCsTransitionResult};
use crate::raw::Place;
use core::mem::offset_of;

fn unit(channel: Place<'_, crate::layout::HliChannel>) -> Place<'_, HliDynCsTransitionResult> {
    control_unit(channel, offset_of!(HliChannelMcControl, dyn_cs_result))
}

fn count(unit: Place<'_, HliDynCsTransitionResult>) -> Place<'_, u32> {
    unit.field::<u32>(offset_of!(HliDynCsTransitionResult, taken_count_r))
}

impl CncView<'_> {
    /// Writes channel `channel`'s transition result, the count last.
    pub fn write_dyn_cs_result(
        &self,
        channel: usize,
        result: &HliDynCsTransitionResult,
    ) -> Result<(), IndexError> {
        let unit = unit(self.nav.channel(channel)?);
        for (offset, value) in [
            (
                offset_of!(HliDynCsTransitionResult, command_r),
                result.command_r as u32,
            ),
            (
                offset_of!(HliDynCsTransitionResult, error_id_r),
                result.error_id_r,
            ),
            (
                offset_of!(HliDynCsTransitionResult, states_seen_r),
                result.states_seen_r,
            ),
            (
                offset_of!(HliDynCsTransitionResult, lag_translation_r),
                result.lag_translation_r as u32,
            ),
            (
                offset_of!(HliDynCsTransitionResult, lag_rotation_r),
                result.lag_rotation_r as u32,
            ),
            (
                offset_of!(HliDynCsTransitionResult, catch_ups_r),
                result.catch_ups_r,
            ),
        ] {
            unit.field::<u32>(offset).store(value);
        }
        count(unit).store_release(result.taken_count_r);
        Ok(())
    }
}

impl PlcChannel<'_> {
    /// Reads the outcome of the dynamic-CS transitions, the count first.
    pub fn dyn_cs_result(&self) -> HliDynCsTransitionResult {
        let unit = unit(self.block);
        let taken = count(unit).load_acquire();
        HliDynCsTransitionResult {
            taken_count_r: taken,
            ..unit.read()
        }
    }
}
