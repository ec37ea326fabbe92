//! The `cnc` application around the `cnc-core` library: scenarios and `cnc run` (the CNC
//! process with its spawned PLC), the demo, and the command-line tools. This package may use
//! the PLC crate (`plc-shim`: timelines, the PLC process); the library does not depend on it.

#![forbid(unsafe_code)]

pub mod cam_cli;
pub mod check_cli;
pub mod demo;
pub mod demo_plots;
pub mod diag_cli;
pub mod fifo_cli;
pub mod kin_cli;
pub mod opcua;
pub mod plot;
pub mod progress;
pub mod saw_cli;
pub mod scenario;
pub mod stats;
