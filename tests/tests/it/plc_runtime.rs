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
    hli_transport::init_logging();
    let instance = unique_instance("plc-lost");
    let mut child = tests::spawn_ready_peer(env!("CARGO_BIN_EXE_hli-peer"), "cnc-beat", &instance);
    let mut runtime = PlcRuntime::attach(&instance, 5, Duration::from_millis(5)).unwrap();
    child.0.kill().unwrap();
    child
        .wait_with_watchdog(Duration::from_secs(30))
        .expect("watchdog: the killed peer was not reaped");
    // The max_cycles bound is a watchdog. The PLC gets one cycle for the last tick the CNC
    // finished before the loop started (lockstep needs that cycle); without new ticks no
    // further cycle runs.
    let summary = runtime.run(&mut Idle, Some(1_000)).unwrap();
    assert!(
        matches!(
            summary.end,
            RunEnd::CncLost(plc_shim::runtime::CncLoss::Dead { .. })
        ),
        "{:?}",
        summary.end
    );
    assert!(
        summary.cycles() <= 1,
        "{} cycles without CNC ticks",
        summary.cycles()
    );
    drop(runtime);
    tests::remove_stale_segment(&instance);
}

/// Records the CNC tick of each cycle and uses the typed channel and axis views.
#[derive(Default)]
struct Recorder {
    ticks: Vec<u64>,
    views_ok: bool,
}

impl PlcProgram for Recorder {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        let beat = hli::access::Leaf::resolve("header.cnc_heartbeat").unwrap();
        self.ticks.push(beat.read(io.memory).as_f64() as u64);
        // gpCh[0] and gpAx[0] exist, gpCh[1] and gpAx[1] do not (one of each configured).
        let channel = io.gp_ch(0).expect("gpCh[0]");
        channel.set_dyn_cs_enabled(true);
        let enable = hli::access::Leaf::resolve("gpCh[0]^channel_mc_control.dyn_cs.enable_w");
        self.views_ok = enable.unwrap().read(io.memory).as_f64() == 1.0
            && channel.dyn_cs_state().is_ok()
            && io.gp_ch(1).is_none()
            && io.gp_ax(0).is_some_and(|a| a.lr_state().error_id_r == 0)
            && io.gp_ax(1).is_none();
    }
}

#[test]
fn a_task_every_third_tick_runs_in_lockstep_and_is_timed() {
    hli_transport::init_logging();
    let instance = unique_instance("plc-period");
    let cnc = tests::lockstep_beats(&instance, 300, 1);
    let mut runtime = PlcRuntime::attach(&instance, 2_000, Duration::from_millis(5)).unwrap();
    runtime.set_period_ticks(3);
    let mut program = Recorder::default();
    let summary = runtime.run(&mut program, Some(1_000)).unwrap();
    cnc.join().unwrap();
    assert_eq!(summary.end, RunEnd::CncClosed);
    // Ticks 1, 4, 7, ... 298: a hundred cycles, none missed.
    assert_eq!(
        program.ticks,
        (0..100).map(|k| 1 + 3 * k).collect::<Vec<u64>>()
    );
    assert_eq!(summary.cycles(), 100);
    assert_eq!(summary.stats.cycles, 100);
    assert_eq!(summary.stats.overruns, 0);
    assert!(summary.stats.max_ns > 0);
    assert!(summary.stats.quantile_us(0.5) <= summary.stats.quantile_us(0.99));
    assert!(summary.stats.quantile_us(0.99) <= summary.stats.max_ns as f64 / 1e3 + 1.0);
    assert!(program.views_ok);
}

#[test]
fn ticks_the_task_missed_count_as_overruns() {
    hli_transport::init_logging();
    let instance = unique_instance("plc-overrun");
    // Two CNC ticks per PLC cycle: every cycle after the first comes one slot late.
    let cnc = tests::lockstep_beats(&instance, 50, 2);
    let mut runtime = PlcRuntime::attach(&instance, 2_000, Duration::from_millis(5)).unwrap();
    let mut program = Recorder::default();
    let summary = runtime.run(&mut program, Some(1_000)).unwrap();
    cnc.join().unwrap();
    assert_eq!(program.ticks, (1..=50).map(|k| 2 * k).collect::<Vec<u64>>());
    assert_eq!(summary.stats.overruns, 49);
}

/// Signals the CNC peer `pid` with `signal` in its 50th cycle; records every cycle's link.
struct Betrayed {
    pid: u32,
    signal: &'static str,
    links: Vec<plc_shim::runtime::Link>,
}

impl PlcProgram for Betrayed {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        self.links.push(io.link);
        if io.cycle == 50 {
            assert!(tests::child::signal(self.pid, self.signal));
        }
    }
}

/// Runs a PLC runtime (watchdog `watchdog` CNC cycles) on a `cnc-beat` peer (1 ms cycle) that
/// gets `signal` in the PLC's 50th cycle; returns how the run ended and the links the program
/// saw.
fn betrayed_by(signal: &'static str, watchdog: u32) -> (RunEnd, Vec<plc_shim::runtime::Link>) {
    hli_transport::init_logging();
    let instance = unique_instance(&format!("plc-{}", signal.to_lowercase()));
    let mut child = tests::spawn_ready_peer(env!("CARGO_BIN_EXE_hli-peer"), "cnc-beat", &instance);
    let mut runtime = PlcRuntime::attach(&instance, watchdog, Duration::from_millis(10)).unwrap();
    let mut program = Betrayed {
        pid: child.id(),
        signal,
        links: Vec::new(),
    };
    // The cycle limit is a watchdog: the loss ends the run long before.
    let summary = runtime.run(&mut program, Some(1_000_000)).unwrap();
    let _ = child.signal("KILL");
    child
        .wait_with_watchdog(Duration::from_secs(30))
        .expect("watchdog: the peer was not reaped");
    drop(runtime);
    tests::remove_stale_segment(&instance);
    (summary.end, program.links)
}

#[test]
fn a_killed_cnc_is_lost_within_cycles_and_the_program_is_told() {
    use plc_shim::runtime::{CncLoss, Link};
    // A long watchdog: a loaded machine's stall must not pass for a hung CNC before the kill
    // (a dead one is seen from its process, whatever the watchdog).
    let (end, links) = betrayed_by("KILL", 2_000);
    let RunEnd::CncLost(CncLoss::Dead { silent_cycles }) = end else {
        panic!("{end:?}");
    };
    // Noticed from the process being gone, at least two cycles after the last tick; how
    // many more depends on the machine's load (a figure for docs/reliability.md, not a
    // timed assertion).
    assert!(silent_cycles >= 2, "{silent_cycles}");
    eprintln!("killed CNC noticed after {silent_cycles} CNC cycles");
    // Every cycle operational but the last one, which comes after the loss.
    let (last, before) = links.split_last().unwrap();
    assert_eq!(*last, Link::NotOperational);
    assert!(before.iter().all(|l| *l == Link::Operational));
    assert!(
        before.len() >= 51,
        "{} cycles before the loss",
        before.len()
    );
}

#[test]
fn a_stopped_cnc_is_lost_after_the_watchdog_cycles() {
    use plc_shim::runtime::{CncLoss, Link};
    let (end, links) = betrayed_by("STOP", plc_shim::watchdog::DEFAULT_WATCHDOG_CYCLES);
    let RunEnd::CncLost(CncLoss::Silent { silent_cycles }) = end else {
        panic!("{end:?}");
    };
    let limit = u64::from(plc_shim::watchdog::DEFAULT_WATCHDOG_CYCLES);
    assert!(silent_cycles >= limit, "{silent_cycles}");
    eprintln!("stopped CNC noticed after {silent_cycles} CNC cycles");
    assert_eq!(links.last(), Some(&Link::NotOperational));
}

/// Writes another pid into the header's PLC slot in its 10th cycle, as a new PLC that the CNC
/// took after it lost this one would.
struct Overtaken;

impl PlcProgram for Overtaken {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        if io.cycle == 10 {
            let pid = hli::access::Leaf::resolve("header.plc_pid").unwrap();
            io.memory.place::<u32>(pid.offset).store(4_000_000);
        }
    }
}

#[test]
fn a_plc_whose_slot_another_plc_claimed_stops_without_another_cycle() {
    hli_transport::init_logging();
    let instance = unique_instance("plc-replaced");
    // Eleven ticks: the eleventh cycle takes the slot over, and the CNC ends after it.
    let cnc = tests::lockstep_beats(&instance, 11, 1);
    let mut runtime = PlcRuntime::attach(&instance, 2_000, Duration::from_millis(5)).unwrap();
    let summary = runtime.run(&mut Overtaken, Some(1_000)).unwrap();
    assert_eq!(summary.end, RunEnd::Replaced(4_000_000));
    assert_eq!(
        summary.cycles(),
        11,
        "no cycle after the take-over was seen"
    );
    drop(runtime);
    cnc.join().unwrap();
}
