//! The axis layer: PTP axes with jerk-limited set-points, their process image (seed 004) and
//! simulated drives, commanded by the PLC's motion blocks over the acyclic service.
//!
//! Per tick, for every axis: read encoder and drive inputs from the image (validated), count
//! increment wraps, step the set-point generator (or take the coupled engine's set-point),
//! monitor the following error, run the position controller (P + velocity feed-forward), and
//! write the drive and encoder outputs, the cyclic state and the command book. Simulated
//! drives then read those outputs and write the next inputs through the same image.

#[allow(clippy::module_inception)]
mod axis;
pub mod cia402;
pub mod commands;
pub mod config;
pub mod encoder_reg;
pub mod generator;
pub mod increments;
mod inputs;
pub mod io_map;
pub mod probe;
pub mod set;
pub mod sim_drive;
mod sim_probe;

pub use axis::{motion_phase, Axis, AxisOutputs, Coupling};
pub use config::{
    AxisConfig, AxisKind, ConfigError, DriveLink, DriveMode, DriveProtocol, Dynamics, ImageOptions,
    ProbeInterface,
};
pub use set::{AxisSet, Lease};
