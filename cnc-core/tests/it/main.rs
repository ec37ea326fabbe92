//! The integration tests of the cnc-core library in one binary, one module per topic: one
//! linked test binary instead of one per file keeps the build short on a small CI machine.

mod axes;
mod axis_no_alloc;
mod cam_coupling;
mod cam_laws;
mod cam_manual_numbers;
mod cam_multi_table;
mod cam_online;
mod cam_props;
mod cam_refusals;
mod cam_seed;
mod cam_tables;
mod channel_axes;
mod channel_control;
mod channel_display;
mod channel_override;
mod channels;
mod continuous_path;
#[path = "../../../tests/support/counting_alloc.rs"]
mod counting_alloc;
mod dyn_cs_manual;
mod nc_core;
mod nc_golden;
mod nc_props;
mod nc_rs274;
mod nc_seed;
mod robot_config;
mod saw_manual_checks;
mod saw_plan;

mod touch_probe;
mod track_cs_gaps;
mod track_cs_language;
mod track_cs_rotary;
mod tracking_plc_rate;
mod tracking_safety;
