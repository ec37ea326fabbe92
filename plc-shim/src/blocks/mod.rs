//! The function blocks a PLC program calls, one file per family, all on the block kernel
//! ([`crate::kernel`]).

pub mod cam;
pub mod cam_compat;
pub mod cam_data;
pub mod cam_multi;
pub mod cam_read;
pub mod dyn_cs;
pub mod fifo;
pub mod motion;
pub mod probe;
pub mod saw;
