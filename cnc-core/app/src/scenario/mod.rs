//! Scenarios: a machine configuration with programs, a PLC part and a trace, run by
//! `cnc run` (two processes, real-time or lockstep) or in-process by tests.

pub mod axes;
pub mod file;
pub mod fleet;
pub mod log_stream;
pub mod machine;
pub mod runner;
pub mod trace;

pub use file::{PlcSetup, Scenario, ScenarioError};
pub use machine::{InProcess, Machine};
pub use trace::Trace;
