//! The `cnc` command line: every command of the `cnc` binary, whose `main` is [`main`].

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Debug, Parser)]
#[command(name = "cnc", about = "CNC process of the CNC/PLC runtime", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run the demo: one machine with every engine (four robots, a cam station, a flying saw)
    /// in real time with a PLC process; report, trace and plots.
    Demo(crate::demo::DemoArgs),
    /// Run a scenario: machine configuration, NC programs, PLC timeline, trace.
    Run(crate::scenario::runner::RunArgs),
    /// HLI tooling.
    Hli {
        #[command(subcommand)]
        what: HliCommand,
    },
    /// Check NC programs: parse, decode, report FILE:LINE:COL diagnostics.
    Check(crate::check_cli::CheckArgs),
    /// Cam profiles: evaluate, characteristic values, plot.
    Cam {
        #[command(subcommand)]
        what: crate::cam_cli::CamCommand,
    },
    /// FIFO groups: run a position file through a group and trace the set-points.
    Fifo {
        #[command(subcommand)]
        what: crate::fifo_cli::FifoCommand,
    },
    /// Flying saw: plan a synchronisation, its characteristic values, a trace.
    Saw {
        #[command(subcommand)]
        what: crate::saw_cli::SawCommand,
    },
    /// Diagnosis of a running or finished CNC.
    Diag {
        #[command(subcommand)]
        what: crate::diag_cli::DiagCommand,
    },
    /// Plot signals of a trace CSV as SVG (one panel per unit, with legends).
    Plot(crate::plot::PlotArgs),
    /// Kinematics: forward and inverse transformation.
    Kin {
        #[command(subcommand)]
        what: crate::kin_cli::KinCommand,
    },
    /// The PLC process (what `cnc demo` spawns) and the image tools `get`, `set`, `watch`;
    /// the same as the `plc` binary.
    #[command(args_conflicts_with_subcommands = true)]
    Plc(plc_shim::cli::PlcCli),
    /// Serve a running CNC's image over OPC UA (docs/opcua.md): runs the `cnc-opcua` binary
    /// built beside this one (`cargo build --release -p cnc-opcua`).
    Opcua {
        /// The CNC's instance name.
        #[arg(long)]
        instance: String,
        /// TCP port of the endpoint.
        #[arg(long, default_value_t = 4840)]
        port: u16,
        /// Folder of the server's certificate store (default: a folder per instance in the
        /// system's temporary folder).
        #[arg(long)]
        pki: Option<std::path::PathBuf>,
        /// The server's configuration: users, writable leaves, certificates, limits (TOML).
        #[arg(long)]
        config: Option<std::path::PathBuf>,
    },
}

#[derive(Debug, Subcommand)]
enum HliCommand {
    /// Print the symbol table: PATH OFFSET SIZE TYPE WRITER, one line per node and leaf.
    Symbols,
    /// Print a C header of the whole image (sizes and offsets asserted).
    Header,
    /// Print the image's units and pointer arrays as Structured Text declarations.
    St,
}

/// The `cnc` binary's `main`: its commands parsed from the process's arguments and run. A
/// binary of one's own that adds an extension engine (`examples/engine-template`) registers
/// it, then calls this.
pub fn main() -> ExitCode {
    hli_transport::init_logging();
    // Long NC programs fill their tree in huge pages where the system has them.
    cnc_core::nc::set_buffer_advice(crate::huge_page_advice);
    match Cli::parse().command {
        Command::Demo(args) => crate::demo::main(args),
        Command::Run(args) => crate::scenario::runner::main(args),
        Command::Hli { what } => {
            let text = match what {
                HliCommand::Symbols => {
                    hli::symbols::format_table(hli::symbols::SymbolTable::global())
                }
                HliCommand::Header => hli::c_header::generate(),
                HliCommand::St => hli::st_prelude::generate(),
            };
            print_or_fail(&text)
        }
        Command::Check(args) => crate::check_cli::main(args),
        Command::Plot(args) => crate::plot::main(args),
        Command::Diag { what } => crate::diag_cli::main(what),
        Command::Kin { what } => crate::kin_cli::main(what),
        Command::Cam { what } => crate::cam_cli::main(what),
        Command::Fifo { what } => crate::fifo_cli::main(what),
        Command::Saw { what } => crate::saw_cli::main(what),
        Command::Plc(args) => plc_shim::cli::main(args),
        Command::Opcua {
            instance,
            port,
            pki,
            config,
        } => crate::opcua::main(&instance, port, pki.as_deref(), config.as_deref()),
    }
}

/// Prints `text`; a closed pipe (`cnc hli symbols | head`) is not an error worth a panic.
fn print_or_fail(text: &str) -> ExitCode {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("cnc: {e}");
            ExitCode::from(1)
        }
    }
}
