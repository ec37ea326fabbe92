//! The `cnc` application around the `cnc-core` library: scenarios and `cnc run` (the CNC
//! process with its spawned PLC), the demo, and the command-line tools. This package may use
//! the PLC crate (`plc-shim`: timelines, the PLC process); the library does not depend on it.

#![forbid(unsafe_code)]

pub mod cam_cli;
pub mod check_cli;
pub mod cli;
pub mod demo;
pub mod demo_plots;
pub mod diag_cli;
pub mod fifo_cli;
pub mod kin_cli;
pub mod opcua;
pub mod plot;
pub mod progress;
pub mod saw_cli;
pub mod scenario;
pub mod stats;

/// The operating system's memory advice for an NC program's tree (installed by the `cnc`
/// binary with `cnc_core::nc::set_buffer_advice`): its arenas in transparent huge pages.
pub fn huge_page_advice(program: &mut cnc_core::nc::ast::Program) {
    cnc_os::advise_huge_pages(&mut program.blocks);
    cnc_os::advise_huge_pages(&mut program.items);
}
