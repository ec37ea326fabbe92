//! `cnc run` as two processes (the CNC and the PLC it spawns) on a real shared-memory segment:
//! lockstep runs are bit-identical to each other and to the in-process run; a real-time run
//! completes; bad scenarios are refused before anything starts.

use cnc_app::scenario::{InProcess, Scenario};
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};
use tests::{Cli, Scratch};

fn cnc_run(args: &[&str], instance: &str, trace: &Path) -> std::process::Output {
    tests::cli::cnc_run(env!("CARGO_BIN_EXE_cnc"), args, instance, trace)
}

#[test]
fn lockstep_traces_are_bit_identical_across_runs_and_match_in_process() {
    let dir = Scratch::new("cli-run");
    let path = tests::cli::scenario("example4-turntable-plc");
    let scenario = path.to_str().unwrap();
    let (a, b) = (dir.join("a.csv"), dir.join("b.csv"));
    let args = [scenario, "--lockstep", "--ticks", "6000"];
    let first = cnc_run(&args, &tests::unique_instance("clirun-a"), &a);
    cnc_run(&args, &tests::unique_instance("clirun-b"), &b);
    let (ta, tb) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_eq!(ta, tb, "two lockstep runs differ");
    let text = String::from_utf8(ta.clone()).unwrap();
    assert_eq!(text.lines().count(), 6001, "header and 6000 ticks");
    assert!(text.starts_with("tick,time,gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state,"));
    // The PLC process switched the tracking on: state 2 appears in the trace.
    assert!(text.lines().any(|l| l.split(',').nth(2) == Some("2")));
    let stdout = String::from_utf8_lossy(&first.stdout);
    assert!(stdout.contains("M functions acknowledged 1"), "{stdout}");

    // The in-process lockstep run of the same scenario gives the same bytes.
    let s = Scenario::load(&path).unwrap();
    let mut run = InProcess::new(&s, 6000).unwrap();
    for _ in 0..6000 {
        run.step(s.cycle_s);
    }
    let mut in_process = Vec::new();
    run.trace.write_csv(&mut in_process).unwrap();
    assert_eq!(in_process, ta, "in-process and two-process lockstep differ");
}

#[test]
fn a_real_time_run_completes_with_its_plc() {
    let dir = Scratch::new("cli-run-rt");
    let path = tests::cli::scenario("example4-turntable-hybrid");
    let trace = dir.join("rt.csv");
    let out = cnc_run(
        &[path.to_str().unwrap(), "--ticks", "300"],
        &tests::unique_instance("clirun-rt"),
        &trace,
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("ticks 300;"), "{stdout}");
    assert!(stdout.contains("ended by CncClosed"), "{stdout}");
    let text = std::fs::read_to_string(&trace).unwrap();
    assert_eq!(text.lines().count(), 301);
}

#[test]
fn bad_scenarios_are_refused_with_their_file() {
    let dir = Scratch::new("cli-run-bad");
    let cases = [
        (
            "cycle_ms = 1.0\n[[channel]]\nname = \"a\"\naxes = [\"X\"]\nbogus = 1\n",
            "bogus",
        ),
        (
            "[[channel]]\nname = \"a\"\naxes = [\"X\"]\nprogram = \"p.nc\"\n",
            "p.nc",
        ),
        (
            "[[channel]]\nname = \"a\"\naxes = [\"X\"]\n[trace]\nsignals = [\"gpCh[0]^nothing\"]\n",
            "nothing",
        ),
    ];
    for (i, (text, needle)) in cases.iter().enumerate() {
        let file = dir.join(format!("bad{i}.toml"));
        std::fs::write(&file, text).unwrap();
        let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
            .arg("run")
            .arg(&file)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "case {i}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "case {i}: {err}");
    }
    // An NC error names FILE:LINE:COL.
    std::fs::write(dir.join("p.nc"), "G1 X1 F100\nG1 Q5\n").unwrap();
    let file = dir.join("bad_program.toml");
    std::fs::write(
        &file,
        "[[channel]]\nname = \"a\"\naxes = [\"X\"]\nprogram = \"p.nc\"\n",
    )
    .unwrap();
    let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .arg("run")
        .arg(&file)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("p.nc:2:"), "{err}");
}

/// `#TRACK CS ON [LOG_FILE=..]`: after the run, `cnc run` writes the channel's diagnosis
/// (history and switching log) to the named file under `--log-dir`.
#[test]
fn a_log_file_named_in_the_program_receives_the_diagnosis() {
    let dir = Scratch::new("cli-run-log");
    std::fs::write(
        dir.join("master.nc"),
        "#CHANNEL INTERFACE ON [DYN_CS]\nG1 X20 F1200\nM30\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("slave.nc"),
        "#TRACK CS ON [CH=1 RELATIVE FILTER=10 WAIT LOG_FILE=\"logs/slave.log\"]\n\
         G1 Y5 F1200\n#TRACK CS OFF [FILTER=500 WAIT]\nM30\n",
    )
    .unwrap();
    let scenario = dir.join("scenario.toml");
    std::fs::write(
        &scenario,
        "cycle_ms = 1.0\n\
         [[channel]]\nname = \"master\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprogram = \"master.nc\"\n\
         [[channel]]\nname = \"slave\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprogram = \"slave.nc\"\n\
         [trace]\nsignals = [\"gpCh[1]^channel_mc_control.dyn_cs.state_r.actual_state\"]\n",
    )
    .unwrap();
    let out_dir = dir.join("out");
    let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .arg("run")
        .arg(&scenario)
        .arg("--log-dir")
        .arg(&out_dir)
        .args(["--instance", &tests::unique_instance("clirun-log")])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let log = out_dir.join("logs/slave.log");
    assert!(stdout.contains("dynamic-CS log: "), "{stdout}");
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(
        text.starts_with("BAHN : DYNAMIC CS, CHANNEL-NR.: 2"),
        "{text}"
    );
    assert!(
        text.contains("dynCS: cmd=ON CH=1 NO FILTER=10 WAIT=1 RELATIVE"),
        "{text}"
    );
    assert!(
        text.contains("dynCS: is off = DYN_CS_SYNC_INACTIVE"),
        "{text}"
    );
}

/// The LOG_FILE is written while the CNC runs, not only at its end: the switch-on's lines
/// are in the file while the program still waits, and after a SIGTERM the file holds the
/// complete listing (history and log).
#[test]
fn the_log_file_is_written_as_the_events_happen() {
    let dir = Scratch::new("cli-run-live-log");
    std::fs::write(
        dir.join("slave.nc"),
        "#TRACK CS ON [ID=0 FILTER=0 LOG_FILE=\"live.log\"]\n#TIME 120\nM30\n",
    )
    .unwrap();
    let scenario = dir.join("scenario.toml");
    std::fs::write(
        &scenario,
        "cycle_ms = 1.0\n[[channel]]\nname = \"slave\"\n\
         axes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprogram = \"slave.nc\"\n",
    )
    .unwrap();
    let out_dir = dir.join("out");
    let mut cnc = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .arg("run")
        .arg(&scenario)
        .arg("--log-dir")
        .arg(&out_dir)
        .args(["--instance", &tests::unique_instance("clirun-live")])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let log = out_dir.join("live.log");
    let deadline = Instant::now() + Duration::from_secs(60);
    let live = loop {
        let text = std::fs::read_to_string(&log).unwrap_or_default();
        if text.contains("dynCS: cmd=ON PLC=1 NO FILTER=0") {
            break text;
        }
        assert!(
            Instant::now() < deadline,
            "watchdog: nothing in {} while running:\n{text}",
            log.display()
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(live.starts_with("BAHN LOGGING KANAL-NR.: 1"), "{live}");
    assert!(live.contains("BAHN restart... start"), "{live}");
    assert!(cnc.signal("TERM"));
    let out = cnc
        .wait_with_output(tests::cli::default_watchdog())
        .unwrap();
    assert_eq!(out.status.code(), Some(128 + 15));
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(
        text.starts_with("BAHN : DYNAMIC CS, CHANNEL-NR.: 1"),
        "{text}"
    );
    assert!(text.contains("dynCS: ERROR: machine stop"), "{text}");
}
