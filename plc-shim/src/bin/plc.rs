//! The `plc` binary: attaches to a running CNC instance and runs a built-in PLC program.

#![forbid(unsafe_code)]

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    hli_transport::init_logging();
    plc_shim::cli::main(plc_shim::cli::PlcCli::parse())
}
