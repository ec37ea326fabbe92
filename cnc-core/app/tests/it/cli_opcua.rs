//! `cnc run --opcua` against an independent OPC UA client, the Python `asyncua` package
//! (`.ci/run` installs it): during a real-time run of example 1 the client browses the tree,
//! reads the carriage's position a few times (each value is in the run's trace, at the tick
//! its source timestamp names), subscribes to the machine's tick (at least 90 % of the
//! expected changes arrive), is refused a write anonymously and writes an opened leaf after
//! logging in over Basic256Sha256 SignAndEncrypt.
//!
//! Skipped, and said so, without asyncua or without the `cnc-opcua` binary beside `cnc`
//! (`cargo test --workspace` builds it); `CNC_REQUIRE_ASYNCUA=1` (set by `.ci/run`) makes
//! either a failure.

use std::io::{BufRead, BufReader};
use std::process::Stdio;
use std::time::Duration;
use tests::{Cli, Scratch};

const AXIS: &str = "gpAx[6]^lr_state.current_position_acs_r";
/// A PLC-written leaf of a channel example 1 does not configure: writing it moves nothing.
const WRITABLE: &str = "gpCh[5]^channel_mc_control.path_override.rapid_override_w";

/// Whether the peers are here; says why not.
fn peers_present(cnc_opcua: &std::path::Path) -> bool {
    let asyncua = Cli::new("python3")
        .args(["-c", "import asyncua"])
        .output()
        .is_ok_and(|o| o.status.success());
    let why = match (asyncua, cnc_opcua.is_file()) {
        (true, true) => return true,
        (false, _) => "the Python package asyncua is not installed (pip install asyncua)",
        (_, false) => "no cnc-opcua binary beside cnc (cargo build -p cnc-opcua)",
    };
    assert!(
        std::env::var_os("CNC_REQUIRE_ASYNCUA").is_none(),
        "required: {why}"
    );
    println!("skipped: {why}");
    false
}

#[test]
fn an_independent_client_browses_reads_subscribes_and_writes_during_a_real_time_run() {
    let cnc = std::path::Path::new(env!("CARGO_BIN_EXE_cnc"));
    if !peers_present(&cnc.with_file_name("cnc-opcua")) {
        return;
    }
    let dir = Scratch::new("opcua-asyncua");
    let config = dir.join("opcua.toml");
    let pki = dir.join("pki");
    std::fs::write(
        &config,
        format!(
            "pki_dir = '{}'\ntrust_client_certificates = true\nwritable = ['{WRITABLE}']\n[[users]]\nname = 'operator'\npassword = 's3cret'\n",
            pki.display()
        ),
    )
    .unwrap();
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .unwrap()
        .port()
        .to_string();
    let trace = dir.join("trace.csv");
    let instance = tests::unique_instance("opcua-asyncua");
    let mut run = Cli::new(cnc)
        .arg("run")
        .arg(tests::cli::scenario("example1-axis-following"))
        .args([
            "--ticks",
            "15000",
            "--instance",
            &instance,
            "--opcua",
            &port,
        ])
        .arg("--opcua-config")
        .arg(&config)
        .arg("--trace")
        .arg(&trace)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The server said it serves (its lines come through the CNC's stderr).
    let (tx, rx) = std::sync::mpsc::channel();
    let stderr = run.0.stderr.take().unwrap();
    let said = std::thread::spawn(move || {
        let mut lines = Vec::new();
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if line.contains("serving on") {
                let _ = tx.send(());
            }
            lines.push(line);
        }
        lines
    });
    rx.recv_timeout(Duration::from_secs(60))
        .expect("the OPC UA server serves");

    let script = tests::cli::repo_root().join("cnc-core/opcua/tests/python/asyncua_client.py");
    let url = format!("opc.tcp://127.0.0.1:{port}/");
    let out = Cli::new("python3")
        .arg(script)
        .args([url.as_str(), AXIS, WRITABLE, "operator", "s3cret"])
        .arg(dir.path())
        .watchdog(Duration::from_secs(60))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", tests::cli::report(&out));
    let status = run.wait_with_watchdog(Duration::from_secs(60));
    let said = said.join().unwrap();
    assert!(status.is_some_and(|s| s.success()), "{said:?}");
    let seen: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    judge(&seen, &std::fs::read_to_string(&trace).unwrap());
    assert!(
        said.iter()
            .any(|l| l.contains(&format!("write {WRITABLE} := 123"))),
        "{said:?}"
    );
}

/// What the client saw against the run's trace.
fn judge(seen: &serde_json::Value, trace: &str) {
    let names: Vec<&str> = seen["browsed"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|v| v.as_str())
        .collect();
    assert!(names.contains(&"current_position_acs_r"), "{names:?}");
    assert!(
        names.contains(&"current_position_acs_r_scaled"),
        "{names:?}"
    );

    // The trace's column of the axis, by tick.
    let mut rows = trace.lines();
    let header: Vec<&str> = rows.next().unwrap().split(',').collect();
    let column = header
        .iter()
        .position(|h| *h == AXIS)
        .expect("the axis is traced");
    let positions: Vec<i64> = rows
        .map(|r| r.split(',').nth(column).unwrap().parse().unwrap())
        .collect();
    let cycle = seen["cycle_ns"].as_i64().unwrap();
    // Each read (value, source timestamp): the value is the trace's at a tick, and the
    // timestamps keep the ticks' distance: one offset fits every read within 2 ticks.
    let reads: Vec<(i64, i64)> = seen["reads"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r[0].as_i64().unwrap(), r[1].as_i64().unwrap() / cycle))
        .collect();
    let ticks_of = |value: i64| -> Vec<i64> {
        (0..positions.len() as i64)
            .filter(|&t| positions[t as usize] == value)
            .collect()
    };
    let moving = reads.windows(2).any(|w| w[0].0 != w[1].0);
    assert!(moving, "the axis moved while read: {reads:?}");
    let (first, first_stamp) = reads[0];
    let fits = ticks_of(first).into_iter().any(|t0| {
        let offset = first_stamp - t0;
        reads.iter().all(|&(value, stamp)| {
            ticks_of(value)
                .iter()
                .any(|t| (stamp - t - offset).abs() <= 2)
        })
    });
    assert!(fits, "reads {reads:?} against the trace");
    let scaled = seen["scaled"].as_f64().unwrap();
    assert!(
        scaled > 0.0
            && positions
                .iter()
                .any(|&p| (p as f64 / 1e4 - scaled).abs() < 1e-9)
    );

    let (changes, expected) = (
        seen["changes"].as_i64().unwrap(),
        seen["expected_changes"].as_i64().unwrap(),
    );
    assert!(
        changes * 10 >= expected * 9,
        "{changes} of {expected} data changes"
    );
    assert_eq!(seen["anonymous_write"], "BadUserAccessDenied");
    assert_eq!(seen["user_write"], "Good");
    assert_eq!(seen["read_back"], 123);
}
