//! CNC channels: the interpreter and interpolator that run NC programs, the `#CS` frames and
//! the kinematic transformation, and the dynamic coordinate system of seed 003 (a channel
//! publishing its frame with `#CHANNEL INTERFACE`, the PLC as master through
//! `MC_CONTROL_DYN_CS_UNIT`, and tracking slaves with `#TRACK CS`).

pub mod catch_up;
pub mod config;
pub mod controller;
pub mod diag_wire;
pub mod diagnosis;
pub mod dyn_cs;
pub mod folder;
pub mod guard;
pub mod hli_frame;
pub mod kin_config;
pub mod path;
pub mod plc_io;
pub mod program;
pub mod ring;
pub mod run;
pub mod sync;
pub mod track_error;

pub use config::{ChannelConfig, ChannelConfigError};
pub use controller::{Controller, ControllerError};
pub use dyn_cs::{MasterSample, MasterSource, TrackError, TrackSetup, Tracker};
pub use program::{LoadedProgram, ProgramError};
pub use run::{Channel, ChannelError, ChannelFault, RunState, MAX_CHANNELS};
