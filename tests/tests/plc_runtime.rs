//! The PLC runtime stops by itself when the CNC process dies (heartbeat watchdog).

use plc_shim::runtime::{PlcIo, PlcProgram, PlcRuntime, RunEnd};
use std::time::Duration;
use tests::unique_instance;

struct Idle;
impl PlcProgram for Idle {
    fn cycle(&mut self, _io: &mut PlcIo<'_>) {}
}

#[test]
fn plc_runtime_ends_with_cnc_lost_when_the_cnc_is_killed() {
    hli::init_logging();
    let instance = unique_instance("plc-lost");
    let mut child = tests::spawn_ready_peer(env!("CARGO_BIN_EXE_hli-peer"), "cnc-beat", &instance);
    let mut runtime = PlcRuntime::attach(&instance, 5, Duration::from_millis(5)).unwrap();
    child.0.kill().unwrap();
    child.0.wait().unwrap();
    // The max_cycles bound is a watchdog. The PLC gets one cycle for the last tick the CNC
    // finished before the loop started (lockstep needs that cycle); without new ticks no
    // further cycle runs.
    let summary = runtime.run(&mut Idle, Some(1_000)).unwrap();
    assert_eq!(summary.end, RunEnd::CncLost);
    assert!(
        summary.cycles <= 1,
        "{} cycles without CNC ticks",
        summary.cycles
    );
    drop(runtime);
    tests::remove_stale_segment(&instance);
}
