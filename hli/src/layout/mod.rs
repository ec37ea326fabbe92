//! `#[repr(C)]` layouts of every control unit and state image, each with compile-time asserts
//! of its size and field offsets.

pub mod axis;
pub mod axis_image;
pub mod channel;
pub mod channel_control;
pub mod dyn_cs;
pub mod fifo;
pub mod image;

pub use axis::*;
pub use axis_image::*;
pub use channel::*;
pub use channel_control::*;
pub use dyn_cs::*;
pub use fifo::*;
pub use image::*;
