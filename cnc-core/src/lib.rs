//! The CNC side of the runtime.
//!
//! The library: `machine` (one tick for channels, axes and engines, the engine set),
//! `channel` (NC channels and the dynamic CS), `axis` (the axis layer and the process image),
//! the engines each in its folder (`gear`, `cam`: cam profiles and the cam engine, `fifo`:
//! FIFO groups, `saw`: the flying saw), `nc` (the NC language), `setpoint` (the set-point
//! every one of them speaks), `harness` (a machine for tests). It knows no
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
