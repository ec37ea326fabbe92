//! The CNC side of the runtime.
//!
//! The library: `machine` (one tick for channels, axes and engines), `channel` (NC channels
//! and the dynamic CS), `axis` (the axis layer and the process image), `cam` (cam profiles), `fifo` (FIFO groups: rows, override, set-points),
//! `nc` (the NC language), `setpoint` (the set-point every one of them speaks). It knows no
//! PLC program and no process.
//!
//! The application: `app` (scenarios and `cnc run`, the demo, the command-line tools), which
//! may use the PLC crate; the `cnc` binary sits on top of it.

#![forbid(unsafe_code)]

pub mod app;
pub mod axis;
pub mod cam;
pub mod channel;
pub mod fifo;
pub mod machine;
pub mod nc;
pub mod saw;
/// The vocabulary of set-points shared by the axis layer, the channels and the engines
/// (`Kinematic`).
pub mod setpoint;
