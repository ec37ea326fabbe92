//! The integration tests of the cnc application (the binary, scenarios, in-process runs) in one
//! binary, one module per topic: one linked test binary instead of one per file keeps the build
//! short on a small CI machine.

mod cam_engine;
mod cam_no_alloc;
mod channel_control;
mod channel_no_alloc;
mod channel_rates;
mod cli_blocks;
mod cli_cam;
mod cli_cams;
mod cli_check;
mod cli_diag;
mod cli_fault_matrix;
mod cli_fifo;
mod cli_hli;
mod cli_kin;
mod cli_late_plc;
mod cli_opcua;
mod cli_plc_channel;
mod cli_plc_tools;
mod cli_plot;
mod cli_progress;
mod cli_realtime;
mod cli_restart;
mod cli_run;
mod cli_saw;
mod cli_supervision;
mod cli_syscalls;
mod cli_turntable;
#[path = "../../../../tests/support/counting_alloc.rs"]
mod counting_alloc;
mod cycle_change;
mod demo;
mod demo_twin;
mod drive_inputs;
mod fifo_engine;
mod fifo_no_alloc;
mod fuzz;
mod hostile;
mod machine;
mod saw_encoder;
mod saw_engine;
mod saw_no_alloc;
mod scenario_paths;
mod scenarios;
mod soak;
mod st_plc;
