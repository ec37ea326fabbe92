//! The channel control unit (`gpCh[i]^channel_control`) in both views: the CNC takes the
//! PLC's command (command pattern) and writes the channel's state; the PLC posts commands and
//! reads that state.

use super::{CncView, IndexError, PlcChannel};
use crate::desc::PlaceExt;
use crate::handshake::{Reader, Writer};
use crate::layout::{HliChannel, HliChannelCommand, HliChannelControlState, HliChannelControlUnit};
use crate::raw::Place;
use core::mem::offset_of;

fn unit(channel: Place<'_, HliChannel>) -> Place<'_, HliChannelControlUnit> {
    channel.field(offset_of!(HliChannel, channel_control))
}

fn state(channel: Place<'_, HliChannel>) -> Place<'_, HliChannelControlState> {
    unit(channel).field(offset_of!(HliChannelControlUnit, state_r))
}

impl<'m> CncView<'m> {
    /// Takes the PLC's channel commands (command pattern).
    pub fn channel_command(
        &self,
        channel: usize,
    ) -> Result<Reader<'m, HliChannelCommand>, IndexError> {
        let unit = unit(self.nav.channel(channel)?);
        Ok(Reader::new(
            unit.field(offset_of!(HliChannelControlUnit, command_semaphore_rw)),
            unit.field(offset_of!(HliChannelControlUnit, command_w)),
        ))
    }

    /// Writes the channel's state block (`channel_control.state_r`).
    pub fn write_channel_control_state(
        &self,
        channel: usize,
        value: &HliChannelControlState,
    ) -> Result<(), IndexError> {
        state(self.nav.channel(channel)?).write(value);
        Ok(())
    }
}

impl<'m> PlcChannel<'m> {
    /// Posts channel commands (command pattern).
    pub fn channel_command(&self) -> Writer<'m, HliChannelCommand> {
        let unit = unit(self.block);
        Writer::new(
            unit.field(offset_of!(HliChannelControlUnit, command_semaphore_rw)),
            unit.field(offset_of!(HliChannelControlUnit, command_w)),
        )
    }

    /// The channel's state block as the CNC wrote it last (raw: decode its values).
    pub fn channel_control_state(&self) -> HliChannelControlState {
        state(self.block).read()
    }
}
