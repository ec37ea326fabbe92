//! Shared helpers of the integration tests: unique instance names, payloads with checksums,
//! and a watchdog for child processes. Nothing here is used by production code.

#![forbid(unsafe_code)]

use hli::layout::HliCoordinateSystemInt;
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// A shared-memory instance name no other test (or test run) uses.
pub fn unique_instance(test: &str) -> String {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    format!(
        "t{}-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed),
        test
    )
}

/// A payload carrying `seq` and a checksum over it (in `fill_up_1`).
pub fn payload(seq: u32) -> HliCoordinateSystemInt {
    let s = seq as i32;
    let mut p = HliCoordinateSystemInt {
        translation: [s, s.wrapping_mul(-3), s ^ 0x0F0F_0F0F],
        fill_up_2: 0,
        rotation: [s.wrapping_add(17), s.rotate_left(7), !s],
        fill_up_1: 0,
    };
    p.fill_up_1 = checksum(&p);
    p
}

/// FNV-style checksum over the six words.
pub fn checksum(p: &HliCoordinateSystemInt) -> i32 {
    p.translation
        .iter()
        .chain(p.rotation.iter())
        .fold(0x811c_9dc5u32, |h, &w| {
            (h ^ w as u32).wrapping_mul(16_777_619)
        }) as i32
}

/// The sequence number of a whole payload; `None` when it is torn or corrupt.
pub fn verify(p: &HliCoordinateSystemInt) -> Option<u32> {
    let seq = p.translation[0] as u32;
    (payload(seq) == *p).then_some(seq)
}

/// Kills `child` when dropped unless it has exited: a hung child never outlives its test.
pub struct ChildGuard(pub Child);

impl ChildGuard {
    /// Waits for the child to exit, up to `limit`; kills it and returns `None` on expiry.
    pub fn wait_with_watchdog(&mut self, limit: Duration) -> Option<std::process::ExitStatus> {
        let deadline = Instant::now() + limit;
        loop {
            if let Ok(Some(status)) = self.0.try_wait() {
                return Some(status);
            }
            if Instant::now() > deadline {
                let _ = self.0.kill();
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

impl Drop for ChildGuard {
    fn drop(&mut self) {
        if let Ok(None) = self.0.try_wait() {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
    }
}

/// Starts the `hli-peer` helper binary (path from the calling test's `CARGO_BIN_EXE_hli-peer`)
/// in `mode` for `instance` and waits for its `ready` line.
pub fn spawn_ready_peer(peer_exe: &str, mode: &str, instance: &str) -> ChildGuard {
    let mut child = ChildGuard(
        Command::new(peer_exe)
            .args([mode, instance])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn hli-peer"),
    );
    let mut line = String::new();
    BufReader::new(child.0.stdout.as_mut().expect("piped stdout"))
        .read_line(&mut line)
        .expect("read the peer's ready line");
    assert_eq!(line.trim(), "ready", "hli-peer {mode} did not start");
    child
}

/// Removes the segment a killed CNC peer left behind: takes it over as stale (its process is
/// gone) and drops it, which unlinks it. Tests that SIGKILL a CNC call this last, so a test
/// run leaves nothing in /dev/shm.
pub fn remove_stale_segment(instance: &str) {
    match hli::segment::CncSegment::create(instance, 1, 1) {
        Ok(segment) => assert!(
            segment.replaced_stale().is_some(),
            "{instance}: the segment was expected to be stale"
        ),
        Err(e) => panic!("{instance}: the stale segment could not be taken over: {e}"),
    }
}

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
    let segment = hli::segment::CncSegment::create(instance, 1, axes).unwrap();
    let instance = instance.to_string();
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    let cnc = std::thread::spawn(move || {
        let view = hli::views::CncView::new(segment.memory());
        let mut axes = build();
        axes.prime(&view);
        let events = hli::events::EventLink::open(&instance, hli::events::Side::Cnc).unwrap();
        let server = hli::rpc::AcyclicServer::open(&instance).unwrap();
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
    let segment = hli::segment::CncSegment::create(instance, 1, 1).unwrap();
    let instance = instance.to_string();
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    let cnc = std::thread::spawn(move || {
        let events = hli::events::EventLink::open(&instance, hli::events::Side::Cnc).unwrap();
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
