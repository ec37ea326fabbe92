//! Supervision and signals of `cnc run`: a PLC killed or hung, SIGINT and SIGTERM. Each
//! ends in a controlled stop (channels brake on their path, single axes brake with their
//! deceleration), with the documented exit code, the report and the trace, and no segment
//! left behind. Waits are polls with watchdogs.

use hli::access::Leaf;
use std::path::PathBuf;
use std::process::Stdio;
use std::time::{Duration, Instant};
use tests::child::signal;
use tests::{ChildGuard, Cli, Scratch};

fn scenario() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/supervision/scenario.toml")
}

fn start(instance: &str, trace: &std::path::Path) -> ChildGuard {
    Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args([
            "run",
            scenario().to_str().unwrap(),
            "--instance",
            instance,
            "--trace",
        ])
        .arg(trace)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

pub(crate) fn segment(instance: &str) -> PathBuf {
    PathBuf::from(format!("/dev/shm/cncplc_{instance}.hli"))
}

/// The PLC heartbeat, read from the segment file.
fn plc_heartbeat(instance: &str) -> Option<u64> {
    heartbeat(instance, "header.plc_heartbeat")
}

/// A heartbeat of the header (`header.plc_heartbeat`, `header.cnc_heartbeat`: the CNC's
/// ticks), read from the segment file.
fn heartbeat(instance: &str, leaf: &str) -> Option<u64> {
    let offset = Leaf::resolve(leaf).unwrap().offset;
    let bytes = std::fs::read(segment(instance)).ok()?;
    Some(u64::from_le_bytes(
        bytes.get(offset..offset + 8)?.try_into().ok()?,
    ))
}

/// Waits (watchdog 30 s) until the PLC has cycled `n` times: the run is in the middle of its
/// first move then.
pub(crate) fn wait_for_plc_cycles(instance: &str, n: u64) {
    let deadline = Instant::now() + Duration::from_secs(30);
    while plc_heartbeat(instance).unwrap_or(0) < n {
        assert!(
            Instant::now() < deadline,
            "watchdog: the PLC of {instance} did not cycle"
        );
        // A poll, not a synchronisation: the watchdog above bounds it.
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Waits (watchdog 30 s) until the CNC has run `n` ticks (a PLC that misses ticks falls
/// behind them, so a point of the run is a tick, not a PLC cycle).
pub(crate) fn wait_for_cnc_ticks(instance: &str, n: u64) {
    let deadline = Instant::now() + Duration::from_secs(30);
    while heartbeat(instance, "header.cnc_heartbeat").unwrap_or(0) < n {
        assert!(
            Instant::now() < deadline,
            "watchdog: the CNC of {instance} did not reach tick {n}"
        );
        // A poll, not a synchronisation: the watchdog above bounds it.
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Waits for `child` (watchdog 60 s), returns exit code and stdout + stderr.
pub(crate) fn finish(mut child: ChildGuard) -> (i32, String) {
    let out = child.wait_with_output(Duration::from_secs(60)).unwrap();
    (
        out.status.code().unwrap_or(-1),
        format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ),
    )
}

/// Ticks the report says the machine needed to come to rest.
pub(crate) fn rest_ticks(report: &str) -> u64 {
    let line = report
        .lines()
        .find(|l| l.starts_with("stopped:"))
        .unwrap_or_else(|| panic!("{report}"));
    let at = line
        .find("machine at rest ")
        .unwrap_or_else(|| panic!("{line}"));
    line[at + 16..].split(' ').next().unwrap().parse().unwrap()
}

/// The last trace row's commanded velocities (HLI units) of the channel X and the follower.
fn last_velocities(trace: &std::path::Path) -> (i64, i64) {
    let text = std::fs::read_to_string(trace).unwrap();
    let last = text.lines().last().unwrap();
    let cells: Vec<i64> = last
        .split(',')
        .skip(2)
        .map(|c| c.parse().unwrap())
        .collect();
    (cells[0], cells[1])
}

fn check_controlled_stop(
    instance: &str,
    trace: &std::path::Path,
    code: i32,
    expect_code: i32,
    report: &str,
    cause: &str,
) {
    assert_eq!(code, expect_code, "{report}");
    assert!(report.contains(cause), "{report}");
    assert!(
        report.contains("error at line") && report.contains("machine stop"),
        "{report}"
    );
    // Both axes brake from at most 200 mm/s (follower 300) at 1000 (2000) mm/s^2, jerk-limited:
    // well under half a second; the watchdog or the signal poll adds at most 64 ticks.
    let rest = rest_ticks(report);
    assert!(rest <= 500, "{rest} ticks to rest\n{report}");
    assert_eq!(
        last_velocities(trace),
        (0, 0),
        "standing at the end of the trace"
    );
    assert!(!segment(instance).exists(), "segment left behind");
}

#[test]
fn a_killed_plc_stops_the_machine_with_exit_4() {
    let instance = tests::unique_instance("sup-kill");
    let scratch = Scratch::new("sup-kill");
    let trace = scratch.join("trace.csv");
    let child = start(&instance, &trace);
    wait_for_plc_cycles(&instance, 300);
    assert!(signal(
        tests::child::plc_pid(&instance).expect("the PLC process"),
        "KILL"
    ));
    let (code, report) = finish(child);
    check_controlled_stop(
        &instance,
        &trace,
        code,
        4,
        &report,
        "the PLC process exited (signal: 9",
    );
}

#[test]
fn a_plc_whose_cnc_is_killed_stops_saying_why_though_its_stdout_is_gone() {
    use std::io::Read;
    let instance = tests::unique_instance("sup-cnc-kill");
    let scratch = Scratch::new("sup-cnc-kill");
    let mut child = start(&instance, &scratch.join("trace.csv"));
    wait_for_plc_cycles(&instance, 300);
    let plc = tests::child::plc_pid(&instance).expect("the PLC process");
    // The PLC's stdout is a pipe to the CNC: it breaks with the kill. Its stderr is the
    // CNC's, so ours: read until the PLC has ended too (a watchdog bounds it).
    let mut err = child.0.stderr.take().unwrap();
    assert!(child.signal("KILL"));
    let (tx, said) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut text = String::new();
        let _ = err.read_to_string(&mut text);
        let _ = tx.send(text);
    });
    let said = said
        .recv_timeout(Duration::from_secs(60))
        .expect("watchdog: the PLC did not end");
    assert!(said.contains("plc: CNC lost"), "{said}");
    assert!(!said.contains("panicked"), "{said}");
    // Its stderr closed as it exits; the process itself ends (or waits as a zombie for the
    // reaper it was handed to) a moment later.
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let stat = std::fs::read_to_string(format!("/proc/{plc}/stat")).unwrap_or_default();
        if stat.is_empty() || stat.contains(") Z ") || stat.contains(") X ") {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "watchdog: the PLC runs on: {stat}"
        );
        // A poll, not a synchronisation: the watchdog above bounds it.
        std::thread::sleep(Duration::from_millis(5));
    }
    let _ = child.wait_with_watchdog(Duration::from_secs(10));
    tests::remove_stale_segment(&instance);
}

#[test]
fn a_hung_plc_is_reported_after_the_watchdog() {
    let instance = tests::unique_instance("sup-hang");
    let scratch = Scratch::new("sup-hang");
    let trace = scratch.join("trace.csv");
    let child = start(&instance, &trace);
    wait_for_plc_cycles(&instance, 300);
    let pid = tests::child::plc_pid(&instance).expect("the PLC process");
    assert!(signal(pid, "STOP"));
    let (code, report) = finish(child);
    // The CNC killed the hung PLC itself; make sure in any case.
    let _ = signal(pid, "KILL");
    check_controlled_stop(
        &instance,
        &trace,
        code,
        4,
        &report,
        "ticks, the process is alive (hung)",
    );
}

#[test]
fn sigint_and_sigterm_stop_the_machine_and_write_the_trace() {
    for (name, code) in [("INT", 130), ("TERM", 143)] {
        let instance = tests::unique_instance(&format!("sup-{}", name.to_lowercase()));
        let scratch = Scratch::new("sup-signal");
        let trace = scratch.join("trace.csv");
        let child = start(&instance, &trace);
        wait_for_plc_cycles(&instance, 300);
        assert!(child.signal(name));
        let (exit, report) = finish(child);
        check_controlled_stop(
            &instance,
            &trace,
            exit,
            code,
            &report,
            &format!("SIG{name} at tick"),
        );
        assert!(
            report.contains("ended by CncClosed"),
            "the PLC stopped cleanly too\n{report}"
        );
    }
}

#[test]
fn a_second_signal_during_the_stop_ends_at_once_and_still_cleans_up() {
    use std::io::{BufRead, BufReader};
    let instance = tests::unique_instance("sup-twice");
    let scratch = Scratch::new("sup-twice");
    let trace = scratch.join("trace.csv");
    let mut child = start(&instance, &trace);
    wait_for_plc_cycles(&instance, 300);
    let plc = tests::child::plc_pid(&instance).expect("the PLC process");
    assert!(child.signal("INT"));
    // Once the CNC says it stops (the stop takes hundreds of ticks), the second signal.
    let mut err = BufReader::new(child.0.stderr.take().unwrap());
    let mut line = String::new();
    while !line.contains("stopping the machine") {
        line.clear();
        assert!(
            err.read_line(&mut line).unwrap() > 0,
            "the CNC ended before saying it stops"
        );
    }
    assert!(child.signal("INT"));
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut err, &mut rest).unwrap();
    let out = child.wait_with_output(Duration::from_secs(60)).unwrap();
    assert_eq!(out.status.code(), Some(130), "{rest}");
    assert!(
        rest.contains("SIGINT during the stop: ending at once"),
        "{rest}"
    );
    assert!(!segment(&instance).exists(), "segment left behind");
    assert!(
        !std::path::Path::new(&format!("/proc/{plc}")).exists() || {
            let stat = std::fs::read_to_string(format!("/proc/{plc}/stat")).unwrap_or_default();
            stat.contains(") Z ")
        },
        "the PLC process is gone"
    );
}

/// Writes `bytes` over the leaf `path` of the segment file, as a PLC that writes where only
/// the CNC writes.
fn write_over(instance: &str, path: &str, bytes: &[u8]) {
    use std::os::unix::fs::FileExt;
    let offset = Leaf::resolve(path).unwrap().offset as u64;
    let file = std::fs::OpenOptions::new()
        .write(true)
        .open(segment(instance))
        .unwrap();
    file.write_all_at(bytes, offset).unwrap();
}

#[test]
fn a_header_written_over_stops_both_sides_naming_the_field() {
    // Before: the PLC read a changed state as the CNC's orderly close and exited 0, the CNC
    // neither noticed nor stopped. Now both name the field; the machine stops at rest.
    for (path, bytes) in [
        ("header.magic", &[0xA5u8; 8][..]),
        ("header.segment_state", &[7, 0, 0, 0][..]),
        ("header.layout_hash", &[1, 2, 3, 4, 5, 6, 7, 8][..]),
    ] {
        let instance = tests::unique_instance("sup-header");
        let scratch = Scratch::new("sup-header");
        let trace = scratch.join("trace.csv");
        let child = start(&instance, &trace);
        wait_for_plc_cycles(&instance, 300);
        write_over(&instance, path, bytes);
        let (code, report) = finish(child);
        let cause = format!("segment header corrupted: {path} is 0x");
        check_controlled_stop(&instance, &trace, code, 5, &report, &cause);
        assert!(
            report.contains(&format!("plc: {cause}")),
            "the PLC names it too\n{report}"
        );
        assert!(report.contains("ended by SegmentCorrupt"), "{report}");
    }
}
