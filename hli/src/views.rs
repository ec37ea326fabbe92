//! Side-typed views of an image. The CNC's view hands out the reading end of commands and the
//! writing end of requests; the PLC's view the opposite. A handle of the wrong direction cannot
//! be obtained, so the protocol's direction is checked by the compiler:
//!
//! ```compile_fail
//! # let mem = hli::image::heap_image(1, 0);
//! let cnc = hli::views::CncView::new(&mem);
//! // The CNC consumes dyn-CS commands; it cannot get their writing end.
//! let sender: hli::handshake::Writer<'_, hli::layout::HliCoordinateSystemInt> =
//!     cnc.dyn_cs_command(0).unwrap();
//! ```
//!
//! Indices are checked against the counts in the segment header: an out-of-range channel or
//! axis is an [`IndexError`], never an access outside the configured part of the image.

use crate::desc::{Bool, PlaceExt};
use crate::enums::{DynCsState, InvalidValue};
use crate::handshake::{Reader, TransitionReader, TransitionWriter, Writer};
use crate::layout::*;
use crate::raw::{ImageMemory, Place};
use core::mem::offset_of;

mod channel_control;
mod path_override;
mod transition;

use path_override::validate_override;
pub use path_override::{
    OverrideError, PathOverride, DEFAULT_PATH_OVERRIDE, MAX_FEED_OVERRIDE, MAX_RAPID_OVERRIDE,
};

/// A channel or axis index outside the configured range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("{what} index {index} out of range (configured: {count})")]
pub struct IndexError {
    /// "channel", "axis" or "FIFO group".
    pub what: &'static str,
    /// The index given.
    pub index: usize,
    /// How many are configured.
    pub count: usize,
}

/// Navigation shared by both views.
#[derive(Debug, Clone, Copy)]
struct Nav<'m> {
    image: Place<'m, HliImage>,
    channels: usize,
    axes: usize,
}

impl<'m> Nav<'m> {
    fn new(memory: &'m ImageMemory) -> Self {
        let image = memory.place::<HliImage>(0);
        let header = image.field::<HliSegmentHeader>(offset_of!(HliImage, header));
        let channels = header
            .field::<u32>(offset_of!(HliSegmentHeader, channel_count))
            .load() as usize;
        let axes = header
            .field::<u32>(offset_of!(HliSegmentHeader, axis_count))
            .load() as usize;
        Self {
            image,
            channels: channels.min(HLI_MAX_CHANNELS),
            axes: axes.min(HLI_MAX_AXES),
        }
    }

    fn channel(&self, index: usize) -> Result<Place<'m, HliChannel>, IndexError> {
        if index >= self.channels {
            return Err(IndexError {
                what: "channel",
                index,
                count: self.channels,
            });
        }
        Ok(self
            .image
            .field::<[HliChannel; HLI_MAX_CHANNELS]>(offset_of!(HliImage, gpCh))
            .at(index))
    }

    fn axis(&self, index: usize) -> Result<Place<'m, HliAxis>, IndexError> {
        if index >= self.axes {
            return Err(IndexError {
                what: "axis",
                index,
                count: self.axes,
            });
        }
        Ok(self
            .image
            .field::<[HliAxis; HLI_MAX_AXES]>(offset_of!(HliImage, gpAx))
            .at(index))
    }

    fn fifo_group(&self, index: usize) -> Result<Place<'m, HliFifoGroupState>, IndexError> {
        self.image
            .field::<[HliFifoGroupState; HLI_MAX_FIFO_GROUPS]>(offset_of!(HliImage, gpFifo))
            .get(index)
            .ok_or(IndexError {
                what: "FIFO group",
                index,
                count: HLI_MAX_FIFO_GROUPS,
            })
    }

    fn dyn_cs(&self, channel: usize) -> Result<Place<'m, McControlDynCsUnit>, IndexError> {
        Ok(control_unit(
            self.channel(channel)?,
            offset_of!(HliChannelMcControl, dyn_cs),
        ))
    }

    fn path_override(
        &self,
        channel: usize,
    ) -> Result<Place<'m, HliChannelOverrideUnit>, IndexError> {
        Ok(control_unit(
            self.channel(channel)?,
            offset_of!(HliChannelMcControl, path_override),
        ))
    }

    fn m_function(&self, channel: usize) -> Result<Place<'m, HliMFunctionUnit>, IndexError> {
        Ok(control_unit(
            self.channel(channel)?,
            offset_of!(HliChannelMcControl, m_function),
        ))
    }
}

/// The control unit at `offset` in a channel's `channel_mc_control` (both views reach their
/// units through here).
fn control_unit<U>(channel: Place<'_, HliChannel>, offset: usize) -> Place<'_, U> {
    channel
        .field::<HliChannelMcControl>(offset_of!(HliChannel, channel_mc_control))
        .field(offset)
}

macro_rules! unit_field {
    ($unit:expr, $ty:ty, $field:ident) => {
        $unit.field::<_>(offset_of!($ty, $field))
    };
}

/// What a channel reports of its block execution every tick (`HLI_BAHN_STATE`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlockProgress {
    /// Source line of the block executing.
    pub block_nr: i32,
    /// Program state.
    pub program_state: crate::enums::ProgramState,
    /// Path velocity, 1 um/s.
    pub path_feed_um_s: i32,
    /// Why the channel stopped ([`crate::enums::ChannelErrorId::None`] while it runs).
    pub error_id: crate::enums::ChannelErrorId,
    /// Channel ticks so far.
    pub tick: u64,
}

/// What both views have: the image's size and its channel and axis blocks. A side writes only
/// the values its role owns (`_w` for the PLC, `_r` for the CNC).
macro_rules! navigation {
    ($view:ident) => {
        impl<'m> $view<'m> {
            /// View of `memory` (a segment's or a heap image).
            pub fn new(memory: &'m ImageMemory) -> Self {
                Self {
                    nav: Nav::new(memory),
                }
            }

            /// Configured channels.
            pub fn channel_count(&self) -> usize {
                self.nav.channels
            }

            /// Configured axes.
            pub fn axis_count(&self) -> usize {
                self.nav.axes
            }

            /// Channel block `gpCh[index]^`.
            pub fn channel(&self, index: usize) -> Result<Place<'m, HliChannel>, IndexError> {
                self.nav.channel(index)
            }

            /// Axis block `gpAx[index]^`.
            pub fn axis(&self, index: usize) -> Result<Place<'m, HliAxis>, IndexError> {
                self.nav.axis(index)
            }
        }
    };
}

navigation!(CncView);
navigation!(PlcView);

/// The CNC's view of an image.
#[derive(Debug, Clone, Copy)]
pub struct CncView<'m> {
    nav: Nav<'m>,
}

impl<'m> CncView<'m> {
    /// FIFO group status `gpFifo[index]^`.
    pub fn fifo_group(&self, index: usize) -> Result<Place<'m, HliFifoGroupState>, IndexError> {
        self.nav.fifo_group(index)
    }

    /// The dynamic-CS unit of a channel (for values without a handshake).
    pub fn dyn_cs_unit(&self, channel: usize) -> Result<Place<'m, McControlDynCsUnit>, IndexError> {
        self.nav.dyn_cs(channel)
    }

    /// Consumes `command_w` (command pattern).
    pub fn dyn_cs_command(
        &self,
        channel: usize,
    ) -> Result<Reader<'m, HliCoordinateSystemInt>, IndexError> {
        let unit = self.nav.dyn_cs(channel)?;
        Ok(Reader::new(
            unit_field!(unit, McControlDynCsUnit, command_semaphore_rw),
            unit_field!(unit, McControlDynCsUnit, command_w),
        ))
    }

    /// Publishes `request_r` (request pattern).
    pub fn dyn_cs_request(
        &self,
        channel: usize,
    ) -> Result<Writer<'m, HliCoordinateSystemInt>, IndexError> {
        let unit = self.nav.dyn_cs(channel)?;
        Ok(Writer::new(
            unit_field!(unit, McControlDynCsUnit, request_semaphore_rw),
            unit_field!(unit, McControlDynCsUnit, request_r),
        ))
    }

    /// Takes `transition_w`.
    pub fn dyn_cs_transition(&self, channel: usize) -> Result<TransitionReader<'m>, IndexError> {
        let unit = self.nav.dyn_cs(channel)?;
        Ok(TransitionReader::new(unit_field!(
            unit,
            McControlDynCsUnit,
            transition_w
        )))
    }

    /// Whether the PLC took over the unit (`enable_w`); `Err(raw)` for a garbage byte.
    pub fn dyn_cs_enabled(&self, channel: usize) -> Result<Result<bool, u8>, IndexError> {
        let unit = self.nav.dyn_cs(channel)?;
        let raw = unit
            .field::<Bool>(offset_of!(McControlDynCsUnit, enable_w))
            .cast::<u8>()
            .load_acquire();
        Ok(Bool(raw).get())
    }

    /// Reports the tracking state in `state_r`.
    pub fn set_dyn_cs_state(&self, channel: usize, state: DynCsState) -> Result<(), IndexError> {
        let unit = self.nav.dyn_cs(channel)?;
        unit.field::<HliDynCsState>(offset_of!(McControlDynCsUnit, state_r))
            .field::<u32>(offset_of!(HliDynCsState, actual_state))
            .store_release(state.raw());
        Ok(())
    }

    /// Writes the display values of path axis `axis` (`bahn_state.coord_r[axis]`); an axis
    /// beyond the image's path axes is an [`IndexError`].
    pub fn write_coord_state(
        &self,
        channel: usize,
        axis: usize,
        state: &HliCoordState,
    ) -> Result<(), IndexError> {
        if axis >= HLI_CHANNEL_AXES {
            return Err(IndexError {
                what: "path axis",
                index: axis,
                count: HLI_CHANNEL_AXES,
            });
        }
        self.bahn_state(channel)?
            .field::<HliCoordState>(
                offset_of!(HliBahnState, coord_r) + axis * core::mem::size_of::<HliCoordState>(),
            )
            .write(state);
        Ok(())
    }

    /// Writes the block progress of a channel (`bahn_state`, the display values aside).
    pub fn write_block_progress(
        &self,
        channel: usize,
        progress: &BlockProgress,
    ) -> Result<(), IndexError> {
        let bahn = self.bahn_state(channel)?;
        unit_field!(bahn, HliBahnState, active_block_nr_r).store(progress.block_nr);
        unit_field!(bahn, HliBahnState, program_state_r).store(progress.program_state.raw());
        unit_field!(bahn, HliBahnState, path_feed_r).store(progress.path_feed_um_s);
        unit_field!(bahn, HliBahnState, error_id_r).store(progress.error_id.raw());
        unit_field!(bahn, HliBahnState, tick_counter_r).store(progress.tick);
        Ok(())
    }

    /// Reports the feed override the channel applies (`feed_override_r`, 0.1 %).
    pub fn write_feed_override_applied(
        &self,
        channel: usize,
        permille: u32,
    ) -> Result<(), IndexError> {
        self.nav
            .path_override(channel)?
            .field::<u32>(offset_of!(HliChannelOverrideUnit, feed_override_r))
            .store(permille);
        Ok(())
    }

    /// Writes the dynamic-CS part of a channel's interface (what tracking channels and the PLC
    /// read of this channel's published frame).
    pub fn write_channel_interface(
        &self,
        channel: usize,
        interface: &HliDynCsChannelInterface,
    ) -> Result<(), IndexError> {
        self.nav
            .channel(channel)?
            .field::<HliChannelInterface>(offset_of!(HliChannel, channel_interface))
            .field::<HliDynCsChannelInterface>(offset_of!(HliChannelInterface, dyn_cs))
            .write(interface);
        Ok(())
    }

    fn bahn_state(&self, channel: usize) -> Result<Place<'m, HliBahnState>, IndexError> {
        Ok(self
            .nav
            .channel(channel)?
            .field::<HliBahnState>(offset_of!(HliChannel, bahn_state)))
    }

    /// Reads and validates the PLC's override and feed hold; the caller keeps its last valid
    /// value (or stops) on an error.
    pub fn path_override(
        &self,
        channel: usize,
    ) -> Result<Result<PathOverride, OverrideError>, IndexError> {
        let unit = self.nav.path_override(channel)?.read();
        Ok(validate_override(&unit))
    }

    /// Announces M functions (request pattern).
    pub fn m_function_request(
        &self,
        channel: usize,
    ) -> Result<Writer<'m, HliMFunctionRequest>, IndexError> {
        let unit = self.nav.m_function(channel)?;
        Ok(Writer::new(
            unit_field!(unit, HliMFunctionUnit, request_semaphore_rw),
            unit_field!(unit, HliMFunctionUnit, request_r),
        ))
    }

    /// Takes M-function acknowledges (command pattern).
    pub fn m_function_ack(
        &self,
        channel: usize,
    ) -> Result<Reader<'m, HliMFunctionAck>, IndexError> {
        let unit = self.nav.m_function(channel)?;
        Ok(Reader::new(
            unit_field!(unit, HliMFunctionUnit, ack_semaphore_rw),
            unit_field!(unit, HliMFunctionUnit, ack_w),
        ))
    }
}

/// The PLC's view of an image.
#[derive(Debug, Clone, Copy)]
pub struct PlcView<'m> {
    nav: Nav<'m>,
}

/// The PLC's view of one channel, `gpCh[i]^` (from [`PlcView::gp_ch`]): the channel's
/// control units without an index to check at every access.
#[derive(Debug, Clone, Copy)]
pub struct PlcChannel<'m> {
    block: Place<'m, HliChannel>,
}

/// The PLC's view of one axis, `gpAx[i]^` (from [`PlcView::gp_ax`]).
#[derive(Debug, Clone, Copy)]
pub struct PlcAxis<'m> {
    block: Place<'m, HliAxis>,
}

impl<'m> PlcView<'m> {
    /// Channel `index` (`gpCh[index]^`), `None` beyond the configured channels.
    pub fn gp_ch(&self, index: usize) -> Option<PlcChannel<'m>> {
        self.ch(index).ok()
    }

    /// Axis `index` (`gpAx[index]^`), `None` beyond the configured axes.
    pub fn gp_ax(&self, index: usize) -> Option<PlcAxis<'m>> {
        self.nav.axis(index).ok().map(|block| PlcAxis { block })
    }

    fn ch(&self, index: usize) -> Result<PlcChannel<'m>, IndexError> {
        self.nav.channel(index).map(|block| PlcChannel { block })
    }

    /// Writes `command_w` (command pattern).
    pub fn dyn_cs_command(
        &self,
        channel: usize,
    ) -> Result<Writer<'m, HliCoordinateSystemInt>, IndexError> {
        Ok(self.ch(channel)?.dyn_cs_command())
    }

    /// Reads `request_r` (request pattern).
    pub fn dyn_cs_request(
        &self,
        channel: usize,
    ) -> Result<Reader<'m, HliCoordinateSystemInt>, IndexError> {
        Ok(self.ch(channel)?.dyn_cs_request())
    }

    /// Writes `transition_w`.
    pub fn dyn_cs_transition(&self, channel: usize) -> Result<TransitionWriter<'m>, IndexError> {
        Ok(self.ch(channel)?.dyn_cs_transition())
    }

    /// Takes over (or releases) the unit: `enable_w`.
    pub fn set_dyn_cs_enabled(&self, channel: usize, enabled: bool) -> Result<(), IndexError> {
        self.ch(channel)?.set_dyn_cs_enabled(enabled);
        Ok(())
    }

    /// The tracking state `state_r`, validated.
    pub fn dyn_cs_state(
        &self,
        channel: usize,
    ) -> Result<Result<DynCsState, InvalidValue>, IndexError> {
        Ok(self.ch(channel)?.dyn_cs_state())
    }

    /// FIFO group status `gpFifo[index]^` as the CNC published it (the fill level a
    /// PLC keeps a FIFO filled by; decode `group_state_r` with
    /// [`crate::enums::FifoGroupState::decode`]).
    pub fn fifo_group(&self, index: usize) -> Result<HliFifoGroupState, IndexError> {
        Ok(self.nav.fifo_group(index)?.read())
    }

    /// Commands the path override and feed hold of `channel` (`path_override.*_w`).
    pub fn set_path_override(&self, channel: usize, value: PathOverride) -> Result<(), IndexError> {
        self.ch(channel)?.set_path_override(value);
        Ok(())
    }

    /// The feed override the channel applies (`feed_override_r`, 0.1 %).
    pub fn feed_override_applied(&self, channel: usize) -> Result<u32, IndexError> {
        Ok(self.ch(channel)?.feed_override_applied())
    }

    /// The path feed the CNC published for `channel` (`path_feed_r`, 1 um/s).
    pub fn path_feed(&self, channel: usize) -> Result<i32, IndexError> {
        Ok(self.ch(channel)?.path_feed())
    }

    /// The channel's error (`error_id_r`), validated.
    pub fn channel_error(
        &self,
        channel: usize,
    ) -> Result<Result<crate::enums::ChannelErrorId, InvalidValue>, IndexError> {
        Ok(self.ch(channel)?.channel_error())
    }

    /// The program state the CNC published for `channel` (`program_state_r`), validated.
    pub fn program_state(
        &self,
        channel: usize,
    ) -> Result<Result<crate::enums::ProgramState, InvalidValue>, IndexError> {
        Ok(self.ch(channel)?.program_state())
    }

    /// Reads M-function announcements (request pattern).
    pub fn m_function_request(
        &self,
        channel: usize,
    ) -> Result<Reader<'m, HliMFunctionRequest>, IndexError> {
        Ok(self.ch(channel)?.m_function_request())
    }

    /// Acknowledges M functions (command pattern).
    pub fn m_function_ack(
        &self,
        channel: usize,
    ) -> Result<Writer<'m, HliMFunctionAck>, IndexError> {
        Ok(self.ch(channel)?.m_function_ack())
    }

    /// The axis cyclic state, copied out.
    pub fn axis_state(&self, axis: usize) -> Result<HliAxisLrState, IndexError> {
        Ok(PlcAxis {
            block: self.nav.axis(axis)?,
        }
        .lr_state())
    }

    /// The image index (`gpAx[i]`) of the axis with NC axis ID `id`, as the CNC writes it in
    /// `lr_state.nc_axis_id_r` (from its first tick on); `None` for ID 0 or an ID no axis has.
    /// A scan of the axes; no allocation.
    pub fn axis_index_by_id(&self, id: u32) -> Option<usize> {
        if id == 0 {
            return None;
        }
        (0..self.axis_count()).find(|&i| self.axis_state(i).is_ok_and(|s| s.nc_axis_id_r == id))
    }
}

impl<'m> PlcChannel<'m> {
    /// The whole block `gpCh[i]^` (read its `_r` values; write only `_w` values).
    pub fn block(&self) -> Place<'m, HliChannel> {
        self.block
    }

    fn dyn_cs(&self) -> Place<'m, McControlDynCsUnit> {
        control_unit(self.block, offset_of!(HliChannelMcControl, dyn_cs))
    }

    fn m_function(&self) -> Place<'m, HliMFunctionUnit> {
        control_unit(self.block, offset_of!(HliChannelMcControl, m_function))
    }

    fn path_override(&self) -> Place<'m, HliChannelOverrideUnit> {
        control_unit(self.block, offset_of!(HliChannelMcControl, path_override))
    }

    fn bahn_state(&self) -> Place<'m, HliBahnState> {
        self.block
            .field::<HliBahnState>(offset_of!(HliChannel, bahn_state))
    }

    /// Writes `channel_mc_control.dyn_cs.command_w` (command pattern).
    pub fn dyn_cs_command(&self) -> Writer<'m, HliCoordinateSystemInt> {
        let unit = self.dyn_cs();
        Writer::new(
            unit_field!(unit, McControlDynCsUnit, command_semaphore_rw),
            unit_field!(unit, McControlDynCsUnit, command_w),
        )
    }

    /// Reads `channel_mc_control.dyn_cs.request_r` (request pattern).
    pub fn dyn_cs_request(&self) -> Reader<'m, HliCoordinateSystemInt> {
        let unit = self.dyn_cs();
        Reader::new(
            unit_field!(unit, McControlDynCsUnit, request_semaphore_rw),
            unit_field!(unit, McControlDynCsUnit, request_r),
        )
    }

    /// Writes `channel_mc_control.dyn_cs.transition_w`.
    pub fn dyn_cs_transition(&self) -> TransitionWriter<'m> {
        let unit = self.dyn_cs();
        TransitionWriter::new(unit_field!(unit, McControlDynCsUnit, transition_w))
    }

    /// Takes over (or releases) the dynamic-CS unit: `enable_w`.
    pub fn set_dyn_cs_enabled(&self, enabled: bool) {
        self.dyn_cs()
            .field::<Bool>(offset_of!(McControlDynCsUnit, enable_w))
            .cast::<u8>()
            .store_release(u8::from(enabled));
    }

    /// The tracking state `state_r`, validated.
    pub fn dyn_cs_state(&self) -> Result<DynCsState, InvalidValue> {
        let raw = self
            .dyn_cs()
            .field::<HliDynCsState>(offset_of!(McControlDynCsUnit, state_r))
            .field::<u32>(offset_of!(HliDynCsState, actual_state))
            .load_acquire();
        DynCsState::decode(raw)
    }

    /// Commands the path override and feed hold (`path_override.*_w`).
    pub fn set_path_override(&self, value: PathOverride) {
        let unit = self.path_override();
        unit_field!(unit, HliChannelOverrideUnit, feed_override_w).store(value.feed_permille);
        unit_field!(unit, HliChannelOverrideUnit, rapid_override_w).store(value.rapid_permille);
        unit.field::<Bool>(offset_of!(HliChannelOverrideUnit, feed_hold_w))
            .cast::<u8>()
            .store_release(u8::from(value.feed_hold));
    }

    /// The feed override the channel applies (`feed_override_r`, 0.1 %).
    pub fn feed_override_applied(&self) -> u32 {
        self.path_override()
            .field::<u32>(offset_of!(HliChannelOverrideUnit, feed_override_r))
            .load()
    }

    /// The path feed the CNC published (`path_feed_r`, 1 um/s).
    pub fn path_feed(&self) -> i32 {
        self.bahn_state()
            .field::<i32>(offset_of!(HliBahnState, path_feed_r))
            .load()
    }

    /// The channel's error (`error_id_r`), validated.
    pub fn channel_error(&self) -> Result<crate::enums::ChannelErrorId, InvalidValue> {
        let raw = self
            .bahn_state()
            .field::<u32>(offset_of!(HliBahnState, error_id_r))
            .load();
        crate::enums::ChannelErrorId::decode(raw)
    }

    /// The program state the CNC published (`program_state_r`), validated.
    pub fn program_state(&self) -> Result<crate::enums::ProgramState, InvalidValue> {
        let raw = self
            .bahn_state()
            .field::<i32>(offset_of!(HliBahnState, program_state_r))
            .load();
        crate::enums::ProgramState::decode(raw)
    }

    /// Reads M-function announcements (request pattern).
    pub fn m_function_request(&self) -> Reader<'m, HliMFunctionRequest> {
        let unit = self.m_function();
        Reader::new(
            unit_field!(unit, HliMFunctionUnit, request_semaphore_rw),
            unit_field!(unit, HliMFunctionUnit, request_r),
        )
    }

    /// Acknowledges M functions (command pattern).
    pub fn m_function_ack(&self) -> Writer<'m, HliMFunctionAck> {
        let unit = self.m_function();
        Writer::new(
            unit_field!(unit, HliMFunctionUnit, ack_semaphore_rw),
            unit_field!(unit, HliMFunctionUnit, ack_w),
        )
    }
}

impl<'m> PlcAxis<'m> {
    /// The whole block `gpAx[i]^`.
    pub fn block(&self) -> Place<'m, HliAxis> {
        self.block
    }

    /// The cyclic state `lr_state`, copied out.
    pub fn lr_state(&self) -> HliAxisLrState {
        self.block
            .field::<HliAxisLrState>(offset_of!(HliAxis, lr_state))
            .read()
    }

    /// The command book `command_state` (what PLCopen blocks follow), copied out.
    pub fn command_state(&self) -> crate::layout::HliAxisCommandState {
        self.block
            .field::<crate::layout::HliAxisCommandState>(offset_of!(HliAxis, command_state))
            .read()
    }
}

/// The standard handler for [`crate::calls::axis::ReadAxisState`] over a CNC view: validates the index.
pub fn handle_read_axis_state(
    view: &CncView<'_>,
    request: &crate::wire::AcyclicRequest,
) -> crate::calls::HandlerResult {
    let body: crate::calls::axis::ReadAxisState = crate::calls::decode_body(request)?;
    if body.reserved != 0 {
        return Err(crate::calls::ErrorCode::InvalidData);
    }
    let axis = view
        .axis(request.target as usize)
        .map_err(|_| crate::calls::ErrorCode::InvalidTarget)?;
    let state: crate::layout::HliAxisLrState =
        crate::desc::PlaceExt::read(axis.field::<crate::layout::HliAxisLrState>(
            core::mem::offset_of!(crate::layout::HliAxis, lr_state),
        ));
    crate::calls::reply(&state)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::heap_image;

    #[test]
    fn indices_outside_the_configured_counts_are_errors() {
        let mem = heap_image(2, 3);
        let cnc = CncView::new(&mem);
        let plc = PlcView::new(&mem);
        assert!(cnc.channel(1).is_ok());
        assert_eq!(
            cnc.channel(2).unwrap_err(),
            IndexError {
                what: "channel",
                index: 2,
                count: 2
            }
        );
        assert_eq!(plc.axis_state(3).unwrap_err().what, "axis");
        assert!(plc.dyn_cs_command(12).is_err());
        assert!(cnc.fifo_group(8).is_err());
    }

    #[test]
    fn override_values_are_validated() {
        let mem = heap_image(1, 0);
        let cnc = CncView::new(&mem);
        let unit = cnc
            .channel(0)
            .unwrap()
            .field::<HliChannelMcControl>(offset_of!(HliChannel, channel_mc_control))
            .field::<HliChannelOverrideUnit>(offset_of!(HliChannelMcControl, path_override));
        let mut value = HliChannelOverrideUnit {
            feed_override_w: 1000,
            rapid_override_w: 500,
            feed_hold_w: Bool::TRUE,
            fill_up_1: 0,
            fill_up_2: 0,
            feed_override_r: 0,
        };
        unit.write(&value);
        assert_eq!(
            cnc.path_override(0).unwrap(),
            Ok(PathOverride {
                feed_permille: 1000,
                rapid_permille: 500,
                feed_hold: true
            })
        );
        value.feed_override_w = 2001;
        unit.write(&value);
        assert_eq!(
            cnc.path_override(0).unwrap(),
            Err(OverrideError::Feed(2001))
        );
        value.feed_override_w = 0;
        value.rapid_override_w = 1001;
        unit.write(&value);
        assert_eq!(
            cnc.path_override(0).unwrap(),
            Err(OverrideError::Rapid(1001))
        );
        value.rapid_override_w = 0;
        value.feed_hold_w = Bool(9);
        unit.write(&value);
        assert_eq!(
            cnc.path_override(0).unwrap(),
            Err(OverrideError::FeedHold(9))
        );
    }
}
