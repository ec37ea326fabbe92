//! The `cnc` binary: the command line of `cnc_app::cli`.

#![forbid(unsafe_code)]

fn main() -> std::process::ExitCode {
    cnc_app::cli::main()
}
