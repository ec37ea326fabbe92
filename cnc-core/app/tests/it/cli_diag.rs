//! `cnc diag dyncs --channel N` of a running CNC (read over the acyclic channel while it
//! ticks) and of the same CNC once it has ended; bad input and a missing CNC. Waits are polls
//! with watchdogs.

use std::process::{Output, Stdio};
use std::time::{Duration, Instant};
use tests::Cli;

fn diag(instance: &str, channel: &str) -> Output {
    Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args([
            "diag",
            "dyncs",
            "--instance",
            instance,
            "--channel",
            channel,
        ])
        .output()
        .unwrap()
}

fn text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The log's message lines (after the `-----` rule).
fn log_lines(listing: &str) -> Vec<String> {
    listing
        .lines()
        .skip_while(|l| *l != "-----")
        .skip(1)
        .map(str::to_string)
        .collect()
}

/// History rows (`TIME n) STATE (...)`).
fn history_rows(listing: &str) -> Vec<&str> {
    listing
        .lines()
        .take_while(|l| !l.starts_with("BAHN LOGGING"))
        .filter(|l| l.contains(") ") && l.ends_with(')'))
        .collect()
}

#[test]
fn the_diagnosis_of_a_running_and_then_of_the_finished_cnc() {
    let instance = tests::unique_instance("diag");
    let scenario = tests::cli::scenario("example3-moving-workpiece");
    let mut cnc = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["run", scenario.to_str().unwrap(), "--instance", &instance])
        .arg("--keep-diagnosis")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();

    // Running: slave-left (channel 2) tracks the master from its first ticks on.
    let deadline = Instant::now() + Duration::from_secs(60);
    let live = loop {
        let o = diag(&instance, "2");
        let listing = text(&o);
        if o.status.success()
            && listing.starts_with("running CNC")
            && history_rows(&listing).len() >= 10
        {
            break listing;
        }
        assert!(
            Instant::now() < deadline,
            "watchdog: no live listing\n{listing}"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(live.contains("BAHN : DYNAMIC CS, CHANNEL-NR.: 2"), "{live}");
    let rows = history_rows(&live);
    // The tracking slave's rows are ACTIVE (state 2); a listing caught late (a loaded machine)
    // may end in its switch-off (FILTER=0, caught up): DEACTIVATING (3), then INACTIVE (0). Never
    // back to ACTIVE after that, never another state.
    let states: Vec<&str> = rows
        .iter()
        .map(|row| row.split_whitespace().nth(2).unwrap_or("?"))
        .collect();
    // A listing caught before the history wrapped starts with the switch-on tick (FILTER=0:
    // ACTIVATING, state 1, for that one tick).
    let switch_on = usize::from(states[0] == "1");
    assert_eq!(states[switch_on], "2", "{live}");
    let active = switch_on
        + states[switch_on..]
            .iter()
            .take_while(|s| **s == "2")
            .count();
    for (row, state) in rows.iter().zip(&states).skip(active) {
        assert!(["3", "0"].contains(state), "{row}\n{live}");
    }
    let log = log_lines(&live);
    assert!(
        log.contains(&"0 00000010 dynCS: cmd=ON CH=1 NO FILTER=0 WAIT=1".to_string()),
        "{live}"
    );
    assert!(
        // FILTER=0: ACTIVATING is shown for the switch-on tick, ACTIVE from the next.
        log.contains(&"2 00000010 dynCS: is on = DYN_CS_SYNC_ACTIVE".to_string()),
        "{live}"
    );
    // A channel the CNC does not have: exit 2, nothing printed.
    let o = diag(&instance, "5");
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).is_empty());
    assert!(String::from_utf8_lossy(&o.stderr).contains("has 3 channel(s)"));

    // Stopped with SIGTERM: the controlled stop ends the tracking in ERROR and the run leaves
    // its listings behind.
    assert!(cnc.signal("TERM"));
    let out = cnc
        .wait_with_output(tests::cli::default_watchdog())
        .unwrap();
    assert_eq!(out.status.code(), Some(128 + 15));
    let o = diag(&instance, "2");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let finished = text(&o);
    assert!(finished.starts_with("finished run of"), "{finished}");
    let final_log = log_lines(&finished);
    for line in &log {
        assert!(final_log.contains(line), "{line} not in\n{finished}");
    }
    assert!(
        final_log
            .iter()
            .any(|l| l.ends_with("dynCS: ERROR: machine stop")),
        "{finished}"
    );
    // What the run printed with its report is the same listing.
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!(
            "dynamic-CS diagnosis: `cnc diag dyncs --instance {instance}"
        )),
        "{stdout}"
    );
    let _ = std::fs::remove_dir_all(cnc_app::diag_cli::finished_dir(&instance));
}

#[test]
fn no_cnc_and_bad_channels_are_refused() {
    let nobody = tests::unique_instance("diag-nobody");
    let o = diag(&nobody, "1");
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains(&format!("no CNC \"{nobody}\" is running")));
    for bad in ["0", "13", "x"] {
        let o = diag(&nobody, bad);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        assert!(text(&o).is_empty());
    }
}
