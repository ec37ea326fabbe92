//! The PLC program of `cnc demo`'s machine (`scenarios/demo`): one PLC task drives three
//! stations of one machine at once, each the program of its own example on the demo's axes:
//!
//! * the turntable of application example 4 in the PLC-only variant ([`Turntable`]): channel 3,
//!   the table on `gpAx[24]`;
//! * the cam conveyor ([`CamConveyor`]): the conveyor on `gpAx[25]`, the lifter on `gpAx[26]`;
//! * the flying saw ([`SawCut`]): material conveyor, saw carriage and blade on `gpAx[27..=29]`.
//!
//! The robots' programs (channels 0 to 3) are selected when the CNC starts and wait for the
//! PLC: the program starts them with `ChannelStart` in its first cycle, as a line PLC starts
//! its cells. The robots of application example 3 (channels 0 to 2) need no PLC beyond that:
//! their NC programs switch the tracking themselves. The stations share nothing but the task,
//! as three POUs called from one cyclic task would.

use super::cam_conveyor::CamConveyor;
use super::saw_cut::SawCut;
use super::turntable::{Turntable, Variant};
use crate::blocks::channel::ChannelCommandBlock;
use crate::runtime::{PlcIo, PlcProgram};
use hli::enums::ChannelCommand;

/// The robots' channels the program starts.
pub const ROBOT_CHANNELS: usize = 4;
/// The turntable robot's channel.
pub const TURNTABLE_CHANNEL: usize = 3;
/// The table axis.
pub const TABLE_AXIS: usize = 24;
/// Conveyor and lifter of the cam station.
pub const CAM_AXES: [u32; 2] = [25, 26];
/// Material conveyor, saw carriage and blade of the saw station.
pub const SAW_AXES: [u32; 3] = [27, 28, 29];

/// The three stations.
#[derive(Debug)]
pub struct DemoMachine {
    /// Example 4's table.
    pub turntable: Turntable,
    /// The cam station.
    pub cam: CamConveyor,
    /// The saw station.
    pub saw: SawCut,
    /// `ChannelStart` of each robot's channel.
    pub start: [ChannelCommandBlock; ROBOT_CHANNELS],
}

impl DemoMachine {
    /// The demo machine's program; the saw cuts `cuts` pieces of `length` mm with the
    /// material running at `speed` mm/s.
    pub fn new(cuts: usize, length: f64, speed: f64) -> DemoMachine {
        DemoMachine {
            turntable: Turntable::on(Variant::PlcOnly, TURNTABLE_CHANNEL, TABLE_AXIS),
            cam: CamConveyor::on_axes(CAM_AXES),
            saw: SawCut::new(cuts, length, speed).on_axes(SAW_AXES),
            start: core::array::from_fn(|_| ChannelCommandBlock::new(ChannelCommand::Start)),
        }
    }
}

impl PlcProgram for DemoMachine {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        for (channel, start) in self.start.iter_mut().enumerate() {
            start.execute = true;
            start.call(io, channel);
        }
        self.turntable.cycle(io);
        self.cam.cycle(io);
        self.saw.cycle(io);
    }

    fn summary(&self) -> String {
        let started = self.start.iter().filter(|s| s.out.done).count();
        format!(
            "robots started by the PLC: {started} of {ROBOT_CHANNELS}\n{}\n{}\n{}",
            self.turntable.summary(),
            self.cam.summary(),
            self.saw.summary()
        )
    }
}
