//! The `cnc` binary with the phase gear: the standard command line after one registration
//! line. `cnc-phase-gear run scenario/scenario.toml` runs the CNC and spawns itself as the PLC,
//! registered the same way.

#![forbid(unsafe_code)]

use std::process::ExitCode;

fn main() -> ExitCode {
    if let Err(e) = engine_template::register() {
        eprintln!("cnc-phase-gear: {e}");
        return ExitCode::from(2);
    }
    cnc_app::cli::main()
}
