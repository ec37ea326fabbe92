//! The PLC process: attaches to a CNC's HLI segment and runs a PLC program once per cycle,
//! woken by the CNC's "tick done" event. It reaches the CNC only through the HLI segment and
//! the acyclic request-response service.

pub mod cam;
pub mod cam_compat;
pub mod cli;
pub mod dyn_cs;
pub mod fifo;
pub mod fifo_file;
pub mod kernel;
pub mod motion;
pub mod probe;
pub mod programs;
pub mod realtime;
pub mod runtime;
pub mod saw;
pub mod timeline;
pub mod tools;

pub use runtime::{PlcIo, PlcProgram, PlcRuntime, RunSummary, RuntimeError};
