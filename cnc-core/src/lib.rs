//! The CNC side of the runtime.
//!
//! The library: `machine` (one tick for channels, axes and engines), `channel` (NC channels
//! and the dynamic CS), `axis` (the axis layer and the process image), `cam` (cam profiles), `fifo` (FIFO groups: rows, override, set-points),
//! `nc` (the NC language), `setpoint` (the set-point every one of them speaks). It knows no
//! PLC program and no process: the application (scenarios, `cnc run`, the demo, the
//! command-line tools and the `cnc` binary) is the package `cnc-app` in `cnc-core/app/`, and
//! Cargo keeps the PLC crate out of this one.

#![forbid(unsafe_code)]

pub mod axis;
pub mod cam;
pub mod channel;
pub mod fifo;
pub mod gear;
pub mod harness;
pub mod machine;
pub mod nc;
pub mod saw;
/// The vocabulary of set-points shared by the axis layer, the channels and the engines
/// (`Kinematic`).
pub mod setpoint;
