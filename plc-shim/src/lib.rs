//! The PLC process: attaches to a CNC's HLI segment and runs a PLC program once per cycle,
//! woken by the CNC's "tick done" event. It reaches the CNC only through the HLI segment and
//! the acyclic calls' mailbox (`hli_transport::rpc`).

#![forbid(unsafe_code)]

pub mod blocks;
pub mod call_tool;
pub mod channel_tool;
pub mod cli;
pub mod fifo_file;
pub mod kernel;
pub mod programs;
pub mod realtime;
pub mod runtime;
pub mod st;
pub mod timeline;
pub mod tools;
pub mod wakeups;
pub mod watchdog;

pub use runtime::{PlcIo, PlcProgram, PlcRuntime, RunSummary, RuntimeError};
