//! `cnc run --plc-restart`: the PLC is killed mid-move three times in one CNC run and a new
//! PLC process takes over each time. The machine stops at rest between two PLCs, the new PLC
//! finds the image set back and moves the axis again. Waits are polls with watchdogs.

use hli::access::Leaf;
use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{ChildStderr, Stdio};
use std::time::{Duration, Instant};
use tests::child::{plc_pid, signal};
use tests::{ChildGuard, Cli};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/restart")
        .join(name)
}

/// A leaf of the slide's axis block, read from the segment file (`None` once it is gone).
fn slide(instance: &str, leaf: &str) -> Option<i64> {
    let leaf = Leaf::resolve(&format!("gpAx[0]^lr_state.{leaf}")).unwrap();
    let bytes = std::fs::read(format!("/dev/shm/cncplc_{instance}.hli")).ok()?;
    let raw = bytes.get(leaf.offset..leaf.offset + 4)?;
    Some(i64::from(i32::from_le_bytes(raw.try_into().ok()?)))
}

/// The slide's commanded position (mm) and velocity (HLI units), once the segment exists.
fn try_position_and_velocity(instance: &str) -> Option<(f64, i64)> {
    let p = slide(instance, "command_position_acs_r")?;
    let v = slide(instance, "command_velocity_r")?;
    Some((p as f64 / 10_000.0, v))
}

fn position_and_velocity(instance: &str) -> (f64, i64) {
    try_position_and_velocity(instance).expect("the segment")
}

/// Polls (watchdog 30 s) until `done` holds for the slide.
fn wait_for(instance: &str, what: &str, done: impl Fn(f64, i64) -> bool) -> (f64, i64) {
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let now = try_position_and_velocity(instance);
        if let Some((p, v)) = now.filter(|&(p, v)| done(p, v)) {
            return (p, v);
        }
        assert!(Instant::now() < deadline, "watchdog: {what} ({now:?})");
        // A poll, not a synchronisation: the watchdog above bounds it.
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Reads the CNC's log until a line containing `needle`; returns it.
fn expect_line(log: &mut BufReader<ChildStderr>, needle: &str) -> String {
    let mut line = String::new();
    loop {
        line.clear();
        let n = log.read_line(&mut line).unwrap();
        assert!(n > 0, "the CNC ended before saying {needle:?}");
        if line.contains(needle) {
            return line;
        }
    }
}

fn start_plc(instance: &str, timeline: &str) -> ChildGuard {
    Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["plc", "--instance", instance, "--timeline"])
        .arg(data(timeline))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Kills the PLC of `instance` and waits for the CNC to say the machine came to rest.
fn kill_plc(instance: &str, log: &mut BufReader<ChildStderr>) -> (f64, i64) {
    let pid = plc_pid(instance).expect("a PLC process");
    assert!(signal(pid, "KILL"));
    expect_line(log, "stopping the machine and waiting for a new PLC");
    expect_line(log, "PLC leaves cleared; waiting for a new PLC");
    position_and_velocity(instance)
}

/// `cnc run --plc-restart` of `scenario` (a file of tests/data/restart) and its log.
fn start_cnc(instance: &str, scenario: &str) -> (ChildGuard, BufReader<ChildStderr>) {
    let mut cnc = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["run", data(scenario).to_str().unwrap()])
        .args(["--plc-restart", "--instance", instance])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .watchdog(Duration::from_secs(120))
        .spawn()
        .unwrap();
    let log = BufReader::new(cnc.0.stderr.take().unwrap());
    (cnc, log)
}

#[test]
fn a_plc_killed_three_times_mid_run_is_replaced_and_moves_the_axis_again() {
    let instance = tests::unique_instance("restart");
    let (mut cnc, mut log) = start_cnc(&instance, "scenario.toml");
    // PLC 0 (spawned by the CNC) moves the slide towards 100 mm; killed on the way.
    wait_for(&instance, "the first move", |p, v| p > 20.0 && v != 0);
    let (stop_1, v) = kill_plc(&instance, &mut log);
    assert_eq!(v, 0, "at rest after the first loss");
    assert!(
        stop_1 > 20.0 && stop_1 < 100.0,
        "braked on the way: {stop_1} mm"
    );
    // PLC 1 moves it back towards 0; killed on the way too.
    let mut plcs = vec![start_plc(&instance, "back.toml")];
    expect_line(&mut log, "runs its cycles");
    wait_for(&instance, "the move back", |p, v| {
        p < stop_1 - 10.0 && v != 0
    });
    let (stop_2, v) = kill_plc(&instance, &mut log);
    assert_eq!(v, 0);
    assert!(
        stop_2 > 0.0 && stop_2 < stop_1 - 10.0,
        "braked on the way: {stop_2} mm"
    );
    // PLC 2 finishes the move to 100 mm; killed at rest.
    plcs.push(start_plc(&instance, "forth.toml"));
    expect_line(&mut log, "runs its cycles");
    wait_for(&instance, "arrival at 100 mm", |p, v| p == 100.0 && v == 0);
    kill_plc(&instance, &mut log);
    // PLC 3 brings it home and stays until the CNC ends.
    plcs.push(start_plc(&instance, "back.toml"));
    expect_line(&mut log, "runs its cycles");
    wait_for(&instance, "arrival at 0 mm", |p, v| p == 0.0 && v == 0);
    assert!(cnc.signal("INT"));
    let out = cnc.wait_with_output(Duration::from_secs(60)).unwrap();
    let report = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(130), "{report}");
    assert!(report.contains("PLC restarts: 3\n"), "{report}");
    let last = plcs
        .pop()
        .unwrap()
        .wait_with_output(Duration::from_secs(30))
        .unwrap();
    let said = String::from_utf8_lossy(&last.stdout);
    assert_eq!(last.status.code(), Some(0), "{said}");
    assert!(said.contains("ended by CncClosed"), "{said}");
    assert!(
        slide(&instance, "command_position_acs_r").is_none(),
        "segment left behind"
    );
}

#[test]
fn drives_configured_to_disable_stand_off_until_the_new_plc_powers_them() {
    let instance = tests::unique_instance("restart-off");
    let (mut cnc, mut log) = start_cnc(&instance, "disable.toml");
    wait_for(&instance, "the first move", |p, v| p > 20.0 && v != 0);
    assert!(signal(plc_pid(&instance).expect("a PLC process"), "KILL"));
    let line = expect_line(&mut log, "PLC leaves cleared");
    assert!(line.contains("drives disabled"), "{line}");
    // Off from the next tick on (a poll with a watchdog).
    let deadline = Instant::now() + Duration::from_secs(30);
    let enabled = hli::enums::axis_status::ENABLED;
    while slide(&instance, "status_r").is_some_and(|s| s as u32 & enabled != 0) {
        assert!(
            Instant::now() < deadline,
            "watchdog: the slide stays enabled"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    // The new PLC powers it (MC_Power) and moves it on to 100 mm.
    let plc = start_plc(&instance, "forth.toml");
    expect_line(&mut log, "runs its cycles");
    wait_for(&instance, "arrival at 100 mm", |p, v| p == 100.0 && v == 0);
    assert!(cnc.signal("INT"));
    let out = cnc.wait_with_output(Duration::from_secs(60)).unwrap();
    assert_eq!(out.status.code(), Some(130));
    assert!(String::from_utf8_lossy(&out.stdout).contains("PLC restarts: 1\n"));
    drop(plc);
}
