//! `cnc demo`: the embedded machine (four robot channels, a cam station, a flying saw) with a
//! spawned PLC process, end to end; its report and the files it writes.

use std::process::Output;
use tests::{Cli, Scratch};

/// A demo run: what it printed, its stdout, and the scratch folder it was told to write to
/// (`out` inside it, which the demo creates).
fn demo(extra: &[&str], tag: &str) -> (Output, String, Scratch) {
    let scratch = Scratch::new(&format!("demo-{tag}"));
    let instance = tests::unique_instance(&format!("demo{tag}"));
    let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .arg("demo")
        .args(extra)
        .args(["--instance", &instance, "--out"])
        .arg(scratch.join("out"))
        .output()
        .expect("run cnc demo");
    // The listings a demo leaves for `cnc diag`.
    let _ = std::fs::remove_dir_all(cnc_app::diag_cli::finished_dir(&instance));
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    (out, stdout, scratch)
}

fn assert_success(out: &Output, stdout: &str) {
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The summary line of a channel, whitespace collapsed.
fn channel_line(stdout: &str, name: &str) -> String {
    let line = stdout
        .lines()
        .skip_while(|l| *l != "== summary")
        .find(|l| l.split_whitespace().next() == Some(name))
        .unwrap_or_else(|| panic!("no summary line for {name}:\n{stdout}"));
    line.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn assert_files(dir: &std::path::Path, min_rows: usize) {
    let trace = std::fs::read_to_string(dir.join("demo.csv")).unwrap();
    assert!(trace.starts_with("tick,time,"));
    assert!(
        trace.lines().count() > min_rows,
        "{}",
        trace.lines().count()
    );
    for plot in ["robots", "tracking", "turntable", "cam", "saw"] {
        let svg = std::fs::read_to_string(dir.join(format!("{plot}.svg"))).unwrap();
        assert!(svg.contains("<svg") && svg.contains("<polyline"), "{plot}");
    }
}

#[test]
fn the_whole_machine_runs_through_in_lockstep() {
    let (out, stdout, dir) = demo(&["--lockstep"], "full");
    assert_success(&out, &stdout);
    // Example 3: the master publishes, both slaves switch on (ON, ACTIVE) and off (OFF,
    // INACTIVE); example 4: the PLC switches the turntable robot on M100 / M101.
    assert_eq!(
        channel_line(&stdout, "master"),
        "master finished blocks 11 tracking state changes 0 M handshakes 0 max tracking error 0.000000 mm"
    );
    for slave in ["slave-left", "slave-right"] {
        let line = channel_line(&stdout, slave);
        assert!(
            line.starts_with(&format!(
                "{slave} finished blocks 11 tracking state changes 4 M handshakes 0"
            )),
            "{line}"
        );
    }
    let line = channel_line(&stdout, "turntable");
    assert!(
        // 23 blocks: the manual's program on a robot that reaches its table (no work frame),
        // with continuous path switched on and off around its square (3 blocks more).
        line.starts_with("turntable finished blocks 23 tracking state changes 4 M handshakes 2"),
        "{line}"
    );
    assert!(stdout.contains("cmd=ON PLC=1"), "{stdout}");
    // Every switching ends softly: no tracking goes to ERROR in a run that ends normally.
    assert!(!stdout.contains("dynCS: ERROR"), "{stdout}");
    assert!(stdout.contains("M-function handshakes 2;"), "{stdout}");
    // The PLC's three stations each ran their sequence through.
    assert!(
        stdout.contains("transitions sent 2 done 2 failed 0, M functions 2 acknowledged 2"),
        "{stdout}"
    );
    assert!(stdout.contains("cam-conveyor: Finished;"), "{stdout}");
    assert!(
        stdout.contains("saw-cut: Finished, 5 cuts, piece length min 500.0000 max 500.0000 mm"),
        "{stdout}"
    );
    assert!(
        stdout.contains("CNC tick (14500 ticks): compute p50"),
        "{stdout}"
    );
    assert!(stdout.contains("PLC task: 14500 cycles"), "{stdout}");
    assert!(stdout.contains("overruns 0"), "{stdout}");
    assert_files(&dir.join("out"), 14_500);
}

#[test]
fn a_shortened_demo_runs_in_real_time() {
    let (out, stdout, dir) = demo(&["--ticks", "3000"], "rt");
    assert_success(&out, &stdout);
    assert!(stdout.contains("real-time mode"), "{stdout}");
    assert!(
        stdout.contains("CNC tick (3000 ticks): compute p50"),
        "{stdout}"
    );
    assert!(stdout.contains("start lateness p50"), "{stdout}");
    // The PLC ran with the CNC and ended in order; its task statistics are reported.
    assert!(stdout.contains("ended by CncClosed"), "{stdout}");
    assert!(stdout.contains("PLC task: "), "{stdout}");
    // Three seconds in: both slaves have switched on and track (ON, ACTIVE).
    for name in ["slave-left", "slave-right"] {
        let line = channel_line(&stdout, name);
        assert!(line.contains("tracking state changes 2 "), "{line}");
    }
    channel_line(&stdout, "master");
    channel_line(&stdout, "turntable");
    assert!(stdout.contains("written to "), "{stdout}");
    assert_files(&dir.join("out"), 2_900);
}

#[test]
fn bad_arguments_are_refused_and_write_nothing() {
    let (out, stdout, dir) = demo(&["--ticks", "many"], "bad");
    assert_eq!(out.status.code(), Some(2), "{stdout}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--ticks"), "{stderr}");
    assert!(!dir.join("out").exists());
}
