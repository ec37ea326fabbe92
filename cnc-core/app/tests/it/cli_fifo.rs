//! FIFO groups with a real PLC process: `cnc run --lockstep` with the built-in program
//! `fifo-stream` streams the contour scenario and a 100,000-row file through the row service
//! and the segment; the set-points are checked row by row against the files.

use std::path::Path;
use tests::{Cli, Scratch};

/// `cnc run SCENARIO --lockstep` with a trace: the report and the trace.
fn run(scenario: &Path, tag: &str) -> (String, Trace) {
    let (report, trace) = tests::cli::cnc_run_lockstep(env!("CARGO_BIN_EXE_cnc"), scenario, tag);
    (report, Trace::parse(&trace))
}

/// The trace: a header line, then ticks; columns by name.
struct Trace {
    names: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Trace {
    fn read(path: &Path) -> Trace {
        Trace::parse(&std::fs::read(path).unwrap())
    }

    fn parse(bytes: &[u8]) -> Trace {
        let text = std::str::from_utf8(bytes).unwrap();
        let mut lines = text.lines();
        let names = lines
            .next()
            .unwrap()
            .split(',')
            .map(str::to_string)
            .collect();
        let rows = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        Trace { names, rows }
    }

    fn column(&self, name: &str) -> Vec<f64> {
        let i = self.names.iter().position(|n| n == name).expect(name);
        self.rows.iter().map(|r| r[i]).collect()
    }
}

const RUNNING: f64 = 2.0;

#[test]
fn the_contour_scenario_streams_every_row_from_a_plc_process() {
    let dir = tests::cli::repo_root().join("scenarios/fifo-contour");
    let (report, trace) = run(&dir.join("scenario.toml"), "cli-fifo");
    assert!(
        report.contains("fifo-stream: Finished; 3001 rows in"),
        "{report}"
    );
    assert!(report.contains(", 0 underrun ticks"), "{report}");
    let (columns, rows) = plc_shim::fifo_file::RowReader::open(&dir.join("contour.csv"))
        .unwrap()
        .read_all()
        .unwrap();
    assert_eq!(columns, 3);
    let state = trace.column("gpFifo[0]^group_state_r");
    let start = state
        .iter()
        .position(|s| *s == RUNNING)
        .expect("the group ran");
    let end = state.iter().rposition(|s| *s == RUNNING).unwrap();
    // T_f = 2 ticks: in the tick t of the job (from 1), the job time is t ticks = t/2 rows.
    for axis in 0..3 {
        let set = trace.column(&format!("gpAx[{axis}]^lr_state.command_position_acs_r"));
        for (t, tick) in (start..=end).enumerate() {
            let r = (t + 1) as f64 / 2.0;
            let k = (r.floor() as usize).min(3000);
            let want = if k < 3000 {
                rows[3 * k + axis]
                    + (r - k as f64) * (rows[3 * (k + 1) + axis] - rows[3 * k + axis])
            } else {
                rows[3 * 3000 + axis]
            };
            // The image holds 0.1 um.
            assert!(
                (set[tick] - (want * 1e4).round()).abs() <= 1.0,
                "axis {axis}, tick {tick}: {} vs {want}",
                set[tick]
            );
        }
    }
    let consumed = trace.column("gpFifo[0]^rows_consumed_r");
    assert_eq!(consumed[end], 3000.0, "3000 rows passed, the last one held");
    let fill = trace.column("gpFifo[0]^entries_r");
    assert!(
        fill[start..end - 600].iter().all(|f| *f >= 300.0),
        "the PLC kept the FIFO filled"
    );
}

/// 100,000 rows through the real segment and row service: every row executed once, in
/// order (T_f = 1 tick: the set-point of the job's tick t is row t), counted on both sides.
/// The FIFO (3000 rows) is longer than one block (2730 rows of 3), so the first fill ends
/// with fewer rows free than a quarter FIFO.
#[test]
fn a_hundred_thousand_rows_arrive_whole_and_in_order() {
    const ROWS: usize = 100_000;
    let dir = Scratch::new("cli-fifo-100k");
    // Row k: X at k um, Y at -k/2 um, Z at 0; the last row repeated (the end at rest).
    let mut values = Vec::with_capacity(3 * (ROWS + 1));
    for k in 0..ROWS {
        let k = k.min(ROWS - 2) as f64;
        values.extend([k * 1e-3, -k * 0.5e-3, 0.0]);
    }
    plc_shim::fifo_file::write_binary(&dir.join("rows.fifo"), 3, &values).unwrap();
    let axis = "[[axis]]\nname = \"{n}\"\nvelocity = 100.0\n";
    let scenario = format!(
        "cycle_ms = 1.0\nticks = {}\n{}{}{}\
         [[fifo_group]]\ndimension = 3\nrows = 3000\nfifo_cycle_ms = 1.0\n\
         [plc]\nprogram = \"fifo-stream\"\nfile = \"rows.fifo\"\n\
         [trace]\nsignals = [\"gpAx[0]^lr_state.command_position_acs_r\", \
         \"gpAx[1]^lr_state.command_position_acs_r\", \"gpFifo[0]^group_state_r\", \
         \"gpFifo[0]^rows_written_r\", \"gpFifo[0]^rows_consumed_r\"]\n",
        ROWS + 200,
        axis.replace("{n}", "X"),
        axis.replace("{n}", "Y"),
        axis.replace("{n}", "Z"),
    );
    std::fs::write(dir.join("scenario.toml"), scenario).unwrap();
    let (report, trace) = run(&dir.join("scenario.toml"), "fifo-100k");
    // The PLC's count.
    assert!(
        report.contains(&format!("fifo-stream: Finished; {ROWS} rows in")),
        "{report}"
    );
    // The CNC's count.
    let written = trace.column("gpFifo[0]^rows_written_r");
    let consumed = trace.column("gpFifo[0]^rows_consumed_r");
    assert_eq!(written.iter().cloned().fold(0.0, f64::max), ROWS as f64);
    assert_eq!(
        consumed.iter().cloned().fold(0.0, f64::max),
        (ROWS - 1) as f64
    );
    // Row by row: tick t of the job shows row t, X in 0.1 um = 10 t, Y = -5 t.
    let state = trace.column("gpFifo[0]^group_state_r");
    let start = state.iter().position(|s| *s == RUNNING).unwrap();
    let x = trace.column("gpAx[0]^lr_state.command_position_acs_r");
    let y = trace.column("gpAx[1]^lr_state.command_position_acs_r");
    for t in 0..ROWS - 2 {
        let row = (t + 1) as f64;
        assert_eq!(x[start + t], 10.0 * row, "tick {t} of the job");
        assert_eq!(y[start + t], -5.0 * row, "tick {t} of the job");
    }
}

/// `cnc fifo run`: the trace's columns, the set-points on the rows (T_f = 3 ticks), the
/// override on the velocity, and refusals with their exit codes.
#[test]
fn cnc_fifo_run_traces_the_set_points() {
    let dir = Scratch::new("cli-fifo-run");
    let csv = dir.join("rows.csv");
    // X climbs 3 per row for 10 rows, then stands; Y stands at 5.
    let mut text = String::from("x,y\n");
    for k in 0..14 {
        text.push_str(&format!("{},5\n", 3 * k.min(10)));
    }
    std::fs::write(&csv, text).unwrap();
    let trace = dir.join("trace.csv");
    let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["fifo", "run", "--rows", csv.to_str().unwrap()])
        .args([
            "--tf",
            "0.003",
            "--cycle",
            "0.001",
            "--override",
            "50",
            "--trace",
        ])
        .arg(&trace)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("14 rows x 2 axes"), "{stdout}");
    assert!(stdout.contains("end at [30.0000, 5.0000]"), "{stdout}");
    let t = Trace::read(&trace);
    assert_eq!(
        t.names,
        [
            "time",
            "fill",
            "override",
            "a0_position",
            "a0_velocity",
            "a0_acceleration",
            "a0_direction",
            "a1_position",
            "a1_velocity",
            "a1_acceleration",
            "a1_direction"
        ]
    );
    let x = t.column("a0_position");
    let v = t.column("a0_velocity");
    // At 50 % a row lasts 6 ticks: X moves 0.5 per tick, at 500 /s.
    for (n, p) in x.iter().take(50).enumerate() {
        assert!((p - 0.5 * (n + 1) as f64).abs() < 1e-9, "tick {n}: {p}");
        assert!((v[n] - 500.0).abs() < 1e-6);
    }
    assert_eq!(t.column("a0_direction")[10], 1.0);
    assert_eq!(t.column("a1_direction")[10], 0.0);
    assert_eq!(t.column("override")[0], 50.0);
    let fifo_run = |args: &[&str]| {
        Cli::new(env!("CARGO_BIN_EXE_cnc"))
            .args([
                "fifo",
                "run",
                "--rows",
                csv.to_str().unwrap(),
                "--cycle",
                "0.001",
            ])
            .args(args)
            .output()
            .unwrap()
    };
    for args in [
        &["--tf", "0"][..],
        &["--tf", "0.001", "--override", "0"],
        &["--tf", "0.001", "--fifo-rows", "1"],
    ] {
        assert_eq!(fifo_run(args).status.code(), Some(1), "{args:?}");
    }
    std::fs::write(&csv, "1,2\n3,nan\n").unwrap();
    let out = fifo_run(&["--tf", "0.001"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("rows.csv:2:3"));
}

/// The FIFO blocks from a timeline: the same trace and block edges in-process and with a
/// PLC process; FiFoOverwrite changed the end point; X is a free axis again at the end.
#[test]
fn the_fifo_blocks_from_a_timeline_run_alike_in_one_and_two_processes() {
    use cnc_app::scenario::{InProcess, Scenario};
    let path = tests::cli::scenario("fifo-blocks");
    let (report, two_process) =
        tests::cli::cnc_run_lockstep(env!("CARGO_BIN_EXE_cnc"), &path, "fifo-blocks");
    let blocks = |text: &str| -> Vec<String> {
        text.lines()
            .filter(|l| l.starts_with("block "))
            .map(str::to_string)
            .collect()
    };
    assert!(!report.contains("ErrorID"), "{report}");
    assert!(
        report.contains("block back (MC_MoveAbsolute on gpAx[0]): Done"),
        "{report}"
    );
    let s = Scenario::load(&path).unwrap();
    let run = InProcess::run_through(&s).unwrap();
    let in_process = run.trace_csv();
    assert_eq!(
        in_process, two_process,
        "in-process and two-process traces differ"
    );
    assert_eq!(
        blocks(&run.timeline.as_ref().unwrap().summary()),
        blocks(&report)
    );
    let t = Trace::parse(&two_process);
    let x = t.column("gpAx[0]^lr_state.command_position_acs_r");
    let top = x.iter().cloned().fold(f64::MIN, f64::max);
    assert_eq!(top, 80_000.0, "the overwritten rows end at X = 8");
    assert!(
        x.last().unwrap().abs() < 1.0,
        "X moved back as a free axis: {}",
        x.last().unwrap()
    );
}

/// `cnc fifo run` with rows that end at speed: the group holds the last row with an underrun,
/// the run ends there with exit 3, says so with the velocity step, and writes the trace.
#[test]
fn cnc_fifo_run_with_rows_that_end_in_motion_ends_and_says_so() {
    let dir = Scratch::new("cli-fifo-in-motion");
    let csv = dir.join("ramp.csv");
    // X climbs 0.1 per row of T_f = 2 ms (50 units/s) to its last row; Y half as fast.
    let mut text = String::from("x,y\n");
    for k in 0..200 {
        text.push_str(&format!("{},{}\n", 0.1 * k as f64, 0.05 * k as f64));
    }
    std::fs::write(&csv, text).unwrap();
    let trace = dir.join("trace.csv");
    let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["fifo", "run", "--rows", csv.to_str().unwrap()])
        .args(["--tf", "0.002", "--cycle", "0.001", "--trace"])
        .arg(&trace)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("the rows end in motion")
            && stderr.contains("velocity step 50.0000")
            && stderr.contains("on axis 0"),
        "{stderr}"
    );
    let t = Trace::read(&trace);
    let x = t.column("a0_position");
    let v = t.column("a0_velocity");
    // Ended at the first tick of the hold, not after a long wait: the job's 199 row spans.
    assert!(t.rows.len() < 450, "{} ticks", t.rows.len());
    assert!((x[x.len() - 1] - 19.9).abs() < 1e-9, "held at the last row");
    assert!((v[v.len() - 2] - 50.0).abs() < 1e-6 && v[v.len() - 1] == 0.0);
}
