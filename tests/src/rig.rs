//! An axis rig: axes of the axis layer on a heap image, ticked by the test, with the axis
//! image's blocks read and written by name. The axis, probe and drive-input tests share it.

use cnc_core::axis::config::AxisConfig;
use cnc_core::axis::AxisSet;
use cnc_core::setpoint::Kinematic;
use hli::calls::axis::AxisCommandCall;
use hli::command_book::{view_command, CommandView};
use hli::enums::AxisError;
use hli::layout::{
    HliAxis, HliAxisDriveState, HliAxisLrState, NcDriveIn, NcDriveOut, NcEncoderIn, NcEncoderOut,
};
use hli::views::CncView;
use hli::{ImageMemory, PlaceExt};

/// The CNC cycle of a rig, 1 ms.
pub const CYCLE: f64 = 0.001;

/// Axes on a heap image of one channel.
#[derive(Debug)]
pub struct AxisRig {
    /// The image.
    pub memory: ImageMemory,
    /// The axes.
    pub set: AxisSet,
}

/// A reader and a writer of one block of `gpAx[i]^`.
macro_rules! block {
    ($name:ident, $set:ident, $ty:ty, $field:ident) => {
        #[doc = concat!("`gpAx[axis]^.", stringify!($field), "` as it stands.")]
        pub fn $name(&self, axis: usize) -> $ty {
            self.place(axis)
                .field::<$ty>(core::mem::offset_of!(HliAxis, $field))
                .read()
        }
        #[doc = concat!("Writes `gpAx[axis]^.", stringify!($field), "` (as a drive would).")]
        pub fn $set(&self, axis: usize, value: $ty) {
            self.place(axis)
                .field::<$ty>(core::mem::offset_of!(HliAxis, $field))
                .write(&value)
        }
    };
}

impl AxisRig {
    /// These axes, primed on a fresh image, not powered.
    pub fn new(configs: Vec<AxisConfig>) -> Self {
        let memory = hli::image::heap_image(1, configs.len() as u32);
        let set = AxisSet::new(configs, CYCLE).unwrap();
        set.prime(&CncView::new(&memory));
        Self { memory, set }
    }

    /// One axis, ticked once and powered.
    pub fn powered(config: AxisConfig) -> Self {
        let mut rig = Self::new(vec![config]);
        rig.enable(0);
        rig
    }

    /// One CNC tick of every axis.
    pub fn tick(&mut self) {
        self.set.tick(&CncView::new(&self.memory));
    }

    /// `n` ticks.
    pub fn ticks(&mut self, n: usize) {
        for _ in 0..n {
            self.tick();
        }
    }

    /// An axis command, as the acyclic service would hand it over.
    pub fn call(&mut self, axis: usize, call: AxisCommandCall) -> Result<u32, AxisError> {
        self.set.axis_mut(axis).unwrap().command(&call)
    }

    /// One tick, then MC_Power on.
    pub fn enable(&mut self, axis: usize) {
        self.tick();
        self.call(axis, AxisCommandCall::power(true)).unwrap();
    }

    /// The axis's set-point.
    pub fn set_point(&self, axis: usize) -> Kinematic {
        self.set.axis(axis).unwrap().setpoint()
    }

    /// What the command book says of command `id`.
    pub fn view(&self, axis: usize, id: u32) -> CommandView {
        view_command(&self.set.axis(axis).unwrap().book().image(), id)
    }

    /// Ticks until `done` or a watchdog of `max` ticks (a hang fails the test, it does not
    /// time it); the ticks it took.
    pub fn until(&mut self, max: usize, mut done: impl FnMut(&Self) -> bool) -> usize {
        for n in 0..max {
            if done(self) {
                return n;
            }
            self.tick();
        }
        panic!("watchdog: condition not met within {max} ticks");
    }

    /// `gpAx[axis]^`.
    pub fn place(&self, axis: usize) -> hli::Place<'_, HliAxis> {
        CncView::new(&self.memory).axis(axis).unwrap()
    }

    block!(lr, set_lr, HliAxisLrState, lr_state);
    block!(drive_state, set_drive_state, HliAxisDriveState, drive_state);
    block!(drive_out, set_drive_out, NcDriveOut, drive_out);
    block!(enc_out, set_enc_out, NcEncoderOut, enc_out);
    block!(drive_in, set_drive_in, NcDriveIn, drive_in);
    block!(enc_in, set_enc_in, NcEncoderIn, enc_in);
}
