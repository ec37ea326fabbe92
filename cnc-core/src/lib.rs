//! The CNC process. This first version holds the cyclic HLI demo (`cnc demo`) and the HLI
//! tooling (`cnc hli symbols`, `cnc hli header`) and kinematics from the command line (`cnc kin`); channels, interpolation and axes follow.

pub mod axis;
pub mod cam;
pub mod cam_cli;
pub mod channel;
pub mod check_cli;
pub mod demo;
pub mod json;
pub mod kin_cli;
pub mod machine;
pub mod nc;
pub mod scenario;
pub mod stats;
