//! Stand-in CNCs in a thread, in lockstep with a PLC runtime of the test: one that ticks an
//! axis set and answers its acyclic calls, one that only beats, one that runs a script.

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// Runs a CNC in a thread that ticks the axes `build` returns against a fresh segment of
/// `instance` (1 channel, `axes` axes), in lockstep with one PLC runtime: each tick answers the
/// pending acyclic calls (axis commands, axis reads, probe calls), ticks, beats and notifies,
/// then waits for the PLC's cycle. Returns once the segment is ready for the PLC to attach;
/// the thread ends when `finished` is set (its result: whether it was) or after a watchdog of
/// two million ticks, and drops the segment, which ends the PLC runtime.
pub fn serve_axes_in_lockstep(
    instance: &str,
    axes: u32,
    build: impl FnOnce() -> cnc_core::axis::AxisSet + Send + 'static,
    finished: std::sync::Arc<std::sync::atomic::AtomicBool>,
) -> std::thread::JoinHandle<bool> {
    use hli::calls::CallKind;
    let segment = hli_transport::segment::CncSegment::create_with(
        instance,
        1,
        axes,
        hli_transport::segment::CncTiming::lockstep(),
    )
    .unwrap();
    let instance = instance.to_string();
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    let cnc = std::thread::spawn(move || {
        let view = hli::views::CncView::new(segment.memory());
        let mut axes = build();
        axes.prime(&view);
        let events =
            hli_transport::events::EventLink::open(&instance, hli_transport::events::Side::Cnc)
                .unwrap();
        let server = hli_transport::rpc::AcyclicServer::open(&instance).unwrap();
        ready_tx.send(()).unwrap();
        for _ in 0..2_000_000 {
            if finished.load(Ordering::Acquire) {
                break;
            }
            server
                .poll(|kind, request| match kind {
                    CallKind::AXIS_COMMAND => axes.handle_command(request),
                    CallKind::READ_AXIS_STATE => hli::views::handle_read_axis_state(&view, request),
                    CallKind::PROBE_ARM => axes.handle_probe(request, true),
                    CallKind::PROBE_ABORT => axes.handle_probe(request, false),
                    _ => Err(hli::calls::ErrorCode::ServiceNotSupported),
                })
                .unwrap();
            axes.tick(&view);
            segment.beat();
            events.notify().unwrap();
            // Lockstep: the next tick after the PLC's cycle (the timeout only covers start-up).
            let _ = events.wait(Duration::from_millis(2)).unwrap();
        }
        finished.load(Ordering::Acquire)
    });
    ready_rx.recv().unwrap();
    cnc
}

/// A CNC in strict lockstep in a thread, with no machine behind it: a fresh segment of
/// `instance` (1 channel, 1 axis), `ticks` ticks, each raising the heartbeat by `step` (2 = a
/// CNC that runs ahead of its PLC by one tick per cycle), notifying and then waiting for the
/// PLC's heartbeat to reach the tick (watchdog 10 s). Returns once the PLC can attach; the
/// segment closes when the thread ends.
pub fn lockstep_beats(instance: &str, ticks: u64, step: u64) -> std::thread::JoinHandle<()> {
    lockstep_script(instance, ticks, step, |_, _| {})
}

/// [`lockstep_beats`] with `script(view, tick)` run at the start of every tick: a stand-in
/// CNC that takes and answers what the PLC writes as the test says.
pub fn lockstep_script(
    instance: &str,
    ticks: u64,
    step: u64,
    mut script: impl FnMut(&hli::views::CncView<'_>, u64) + Send + 'static,
) -> std::thread::JoinHandle<()> {
    let segment = hli_transport::segment::CncSegment::create_with(
        instance,
        1,
        1,
        hli_transport::segment::CncTiming::lockstep(),
    )
    .unwrap();
    let instance = instance.to_string();
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    let cnc = std::thread::spawn(move || {
        let events =
            hli_transport::events::EventLink::open(&instance, hli_transport::events::Side::Cnc)
                .unwrap();
        // A mailbox nobody answers: the PLC's calls time out, as with a CNC that takes none.
        let _calls = hli_transport::rpc::AcyclicServer::open(&instance).unwrap();
        let view = hli::views::CncView::new(segment.memory());
        ready_tx.send(()).unwrap();
        for n in 1..=ticks {
            script(&view, n);
            for _ in 0..step {
                segment.beat();
            }
            events.notify().unwrap();
            let deadline = Instant::now() + Duration::from_secs(10);
            while segment.plc_heartbeat() < n {
                assert!(Instant::now() < deadline, "watchdog: PLC cycle {n}");
                let _ = events.wait(Duration::from_millis(10)).unwrap();
            }
        }
    });
    ready_rx.recv().unwrap();
    cnc
}
