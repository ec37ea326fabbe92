//! The function blocks a PLC program calls, one file per family, all on the block kernel
//! ([`crate::kernel`]). Each family's file ends with its `TIMELINE` table, the blocks a
//! timeline calls by name ([`crate::timeline::registry`]); `dyn_cs` has none (its blocks
//! address a channel).

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
