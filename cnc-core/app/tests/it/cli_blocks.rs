//! PLC timelines that call PLCopen blocks on scenario axes, with a real PLC process, in
//! lockstep (tick-exact, reproducible) and in real time, and in-process (the same trace and
//! block edges as the two-process lockstep run); bad calls refused before start.

use cnc_app::scenario::{InProcess, Scenario};
use std::path::PathBuf;
use tests::{Cli, Scratch};

fn scenario_path() -> PathBuf {
    tests::cli::scenario("axes-plcopen")
}

fn run(extra: &[&str], tag: &str) -> (i32, String, Vec<Vec<f64>>) {
    let scratch = Scratch::new(&format!("blocks-{tag}"));
    let trace = scratch.join("trace.csv");
    let instance = tests::unique_instance(&format!("blocks-{tag}"));
    let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args([
            "run",
            scenario_path().to_str().unwrap(),
            "--instance",
            &instance,
            "--trace",
        ])
        .arg(&trace)
        .args(extra)
        .output()
        .unwrap();
    let text = tests::cli::report(&out);
    let rows = std::fs::read_to_string(&trace)
        .unwrap_or_default()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    (out.status.code().unwrap_or(-1), text, rows)
}

/// The first rising edge of `output` of block `instance` in the PLC's report.
fn edge(report: &str, instance: &str, output: &str) -> Option<u64> {
    let line = report
        .lines()
        .find(|l| l.starts_with(&format!("block {instance} ")))?;
    let at = line.find(&format!(" {output} "))?;
    line[at + output.len() + 2..]
        .split(' ')
        .next()?
        .parse()
        .ok()
}

fn check(report: &str, rows: &[Vec<f64>]) {
    let e = |i: &str, o: &str| {
        edge(report, i, o).unwrap_or_else(|| panic!("{i}.{o} never rose\n{report}"))
    };
    // Power first, then the moves; Busy before Done.
    assert!(e("power_slide", "Status") < e("move_slide", "Busy"));
    assert!(e("move_slide", "Busy") < e("move_slide", "Done"));
    assert!(e("run_spindle", "Busy") < e("run_spindle", "InVelocity"));
    // MC_Halt takes over the velocity move (it aborts it) and ends Done at standstill.
    assert!(e("halt_spindle", "Busy") <= e("run_spindle", "CommandAborted"));
    assert!(e("halt_spindle", "Busy") < e("halt_spindle", "Done"));
    assert!(edge(report, "move_slide", "Error").is_none(), "{report}");
    // Slide on its target (0.1 um units), spindle at rest; at rest in the trace's last rows.
    let last = rows.last().expect("a trace");
    assert_eq!(last[2], 1_000_000.0, "slide position");
    assert_eq!(
        (last[3], last[4]),
        (0.0, 0.0),
        "both commanded velocities zero"
    );
    // While it ran, the spindle reached 50 mm/s (500000 units/s).
    let top = rows.iter().map(|r| r[4]).fold(0.0, f64::max);
    assert_eq!(top, 500_000.0);
}

#[test]
fn blocks_move_single_axes_in_lockstep_tick_exact() {
    let (code, report, rows) = run(&["--lockstep"], "lock");
    assert_eq!(code, 0, "{report}");
    check(&report, &rows);
    // Lockstep is reproducible to the tick: the halt fires at tick 1000, the block sees its
    // edge in that PLC cycle and the axis takes it with the next CNC tick.
    assert_eq!(
        edge(&report, "halt_spindle", "Busy"),
        Some(1000),
        "{report}"
    );
    assert_eq!(edge(&report, "move_slide", "Busy"), Some(8), "{report}");
    let (_, again, rows_again) = run(&["--lockstep"], "lock2");
    let blocks = |r: &str| {
        r.lines()
            .filter(|l| l.starts_with("block "))
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    assert_eq!(blocks(&report), blocks(&again));
    assert_eq!(
        rows.iter().map(|r| r[2..].to_vec()).collect::<Vec<_>>(),
        rows_again
            .iter()
            .map(|r| r[2..].to_vec())
            .collect::<Vec<_>>()
    );

    // In-process, the same timeline calls the same blocks through an acyclic service of its
    // own: the same trace rows and the same block edges, tick for tick.
    let s = Scenario::load(&scenario_path()).unwrap();
    assert!(s.ticks.is_some(), "the scenario has ticks");
    let run_in = InProcess::run_through(&s).unwrap();
    let in_rows: Vec<Vec<f64>> = String::from_utf8(run_in.trace_csv())
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    assert_eq!(
        in_rows, rows,
        "in-process and two-process lockstep traces differ"
    );
    let in_report = run_in.timeline.as_ref().unwrap().summary();
    assert_eq!(blocks(&in_report), blocks(&report));
    check(&in_report, &in_rows);
}

#[test]
fn blocks_move_single_axes_in_real_time() {
    let (code, report, rows) = run(&[], "rt");
    assert_eq!(code, 0, "{report}");
    check(&report, &rows);
}

#[test]
fn bad_calls_are_refused_before_start() {
    let dir = Scratch::new("blocks-bad");
    let base = std::fs::read_to_string(scenario_path()).unwrap();
    for (timeline, expect) in [
        ("[[step]]\ncall = { block = \"MC_Jump\", axis = 0 }\n", "unknown block \"MC_Jump\""),
        ("[[step]]\ncall = { block = \"MC_Halt\", axis = 0, position = 1.0 }\n", "MC_Halt has no input `position`"),
        ("[[step]]\ncall = { block = \"MC_Halt\", axis = 7 }\n", "axis 7 does not exist"),
        ("[[step]]\ncall = { block = \"MC_Halt\" }\n", "`axis`"),
        ("[[step]]\nwait = \"ghost.Done\"\n", "no instance \"ghost\""),
        ("[[step]]\ncall = { block = \"MC_Halt\", instance = \"h\", axis = 0 }\n[[step]]\nwait = \"h.Finished\"\n", "unknown output \"Finished\""),
        ("[[step]]\ncall = { block = \"MC_MoveVelocity\", axis = 1, direction = 2 }\n", "1 or -1"),
    ] {
        std::fs::write(dir.join("plc.toml"), timeline).unwrap();
        let path = dir.join("scenario.toml");
        std::fs::write(&path, &base).unwrap();
        let out = Cli::new(env!("CARGO_BIN_EXE_cnc")).args(["run", path.to_str().unwrap()]).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{timeline}: {err}");
        assert!(err.contains("plc.toml") && err.contains(expect), "{timeline}: {err}");
    }
}
