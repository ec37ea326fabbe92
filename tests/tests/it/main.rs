//! The cross-crate and multi-process tests in one binary, one module per topic: one linked test
//! binary instead of one per file keeps the build short on a small CI machine.

mod acyclic_and_events;
mod axis_commands;
#[path = "../../support/counting_alloc.rs"]
mod counting_alloc;
mod dyn_cs_blocks;
mod fifo_rows;
mod plc_no_alloc;
mod plc_runtime;
mod probe_blocks;
mod segment_lifecycle;
mod two_process;
