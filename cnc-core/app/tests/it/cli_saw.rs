//! `cnc saw plan`: the characteristic values as JSON under the seed's field names, the
//! trace with the master at constant velocity, exit 1 with the error code when refused,
//! exit 2 on bad arguments.

use std::process::Output;
use tests::{Cli, Scratch};

fn saw(args: &[&str]) -> Output {
    Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .arg("saw")
        .arg("plan")
        .args(args)
        .output()
        .unwrap()
}

/// Position example 1 of the seed.
const EXAMPLE: [&str; 26] = [
    "--mode",
    "position",
    "--master-position",
    "-500",
    "--master-velocity",
    "500",
    "--slave-position",
    "-250",
    "--slave-velocity",
    "250",
    "--ratio",
    "1",
    "--master-sync",
    "1000",
    "--slave-sync",
    "1000",
    "--velocity",
    "3000",
    "--acceleration",
    "2500",
    "--deceleration",
    "2500",
    "--jerk",
    "5000",
    "--check",
    "MAXACC,MAXDEC,MAXJERK,OVERSHOOTVELO",
];

#[test]
fn the_plan_prints_every_characteristic_value_and_traces_to_the_sync_point() {
    let scratch = Scratch::new("saw-plan");
    let trace = scratch.join("trace.csv");
    let mut args = EXAMPLE.to_vec();
    args.extend(["--trace", trace.to_str().unwrap(), "--duration", "3.5"]);
    let out = saw(&args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for (name, want) in [
        ("fMasterVeloNom", 500.0),
        ("fMasterPosStart", -500.0),
        ("fSlavePosStart", -250.0),
        ("fMasterPosEnd", 1000.0),
        ("fSlavePosEnd", 1000.0),
        ("fSlaveVeloEnd", 500.0),
        ("fSlaveVeloMax", 500.0),
        ("fSlaveVeloMin", 250.0),
    ] {
        assert_eq!(json[name].as_f64(), Some(want), "{name}: {json}");
    }
    assert_eq!(json.as_object().unwrap().len(), 32, "shape and 31 fields");
    let text = std::fs::read_to_string(&trace).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("time,master_position,master_velocity,slave_position,slave_velocity,slave_acceleration,axis_state")
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 3501);
    // At 3 s the master is at 1000: synchronous, the slave at 1000 with 500 mm/s.
    let at = &rows[3000];
    assert_eq!(&at[..7], &[3.0, 1000.0, 500.0, 1000.0, 500.0, 0.0, 13.0]);
    assert_eq!(rows[2999][6], 12.0);
    assert_eq!(rows[3500][3], 1250.0);
}

#[test]
fn a_refused_plan_exits_1_with_its_code() {
    let mut args = EXAMPLE.to_vec();
    args[13] = "-1000"; // the master sync position behind the master
    let out = saw(&args);
    assert_eq!(out.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["error_id"].as_u64(), Some(0x4404));
    assert!(String::from_utf8_lossy(&out.stderr).contains("MasterSyncNotAhead"));
    // A limit that cannot be kept, with the detailed code asked for.
    let mut args = EXAMPLE.to_vec();
    args[19] = "10";
    args.extend(["--op", "DETAILEDERRORCODES"]);
    let out = saw(&args);
    assert_eq!(out.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["error"].as_str(), Some("CheckMaxAcc"));
}

#[test]
fn bad_arguments_exit_2() {
    for bad in [
        vec!["--check", "ROLLBACKLOCK"],
        vec!["--op", "MAXACC"],
        vec!["--check", "NOSUCHBIT"],
        vec!["--cycle", "0"],
        vec!["--duration", "inf", "--trace", "/dev/null"],
        vec!["--duration", "-1", "--trace", "/dev/null"],
    ] {
        let mut args = EXAMPLE[..24].to_vec();
        args.extend(bad.iter());
        let out = saw(&args);
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
    }
    let velocity_with_sync = saw(&[
        "--mode",
        "velocity",
        "--master-position",
        "0",
        "--master-velocity",
        "1",
        "--slave-position",
        "0",
        "--slave-velocity",
        "0",
        "--ratio",
        "1",
        "--master-sync",
        "5",
        "--velocity",
        "1",
        "--acceleration",
        "1",
        "--deceleration",
        "1",
        "--jerk",
        "1",
    ]);
    assert_eq!(velocity_with_sync.status.code(), Some(2));
}

/// The sawing cycle of seed 001's sample in two processes: `cnc run` of
/// `scenarios/flying-saw` with the PLC program `saw-cut` in its own process. Every cut is
/// found in the CNC's trace (the tick the blade reaches its depth) and lies on the material
/// at `saw - conveyor`; 20 cuts, every piece 500 mm to 0.01 mm, and every sync after the
/// first started from a saw still running home.
#[test]
fn the_flying_saw_cuts_twenty_equal_pieces_from_a_plc_process() {
    let (report, trace) = tests::cli::cnc_run_lockstep(
        env!("CARGO_BIN_EXE_cnc"),
        &tests::cli::scenario("flying-saw"),
        "cli-saw",
    );
    assert!(report.contains("saw-cut: Finished, 20 cuts"), "{report}");
    let text = String::from_utf8(trace).unwrap();
    let mut lines = text.lines();
    let names: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| names.iter().position(|c| *c == n).expect(n);
    let (conveyor, saw, blade, coupling) = (
        col("gpAx[0]^lr_state.command_position_acs_r"),
        col("gpAx[1]^lr_state.command_position_acs_r"),
        col("gpAx[2]^lr_state.command_position_acs_r"),
        col("gpAx[1]^lr_state.coupling_state_r"),
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    const DEPTH: f64 = 50.0 * 1e4; // 0.1 um
    let mut cuts = Vec::new();
    let mut syncs_from_moving_back = 0;
    for w in rows.windows(3) {
        if w[1][blade] < DEPTH && w[2][blade] >= DEPTH {
            // Saw and conveyor set-points in mm: where the cut lies on the material.
            cuts.push((w[2][saw] - w[2][conveyor]) * 1e-4);
        }
        if w[1][coupling] == 0.0 && w[2][coupling] == 3.0 && w[1][saw] < w[0][saw] {
            syncs_from_moving_back += 1;
        }
    }
    assert_eq!(cuts.len(), 20, "{cuts:?}");
    for pair in cuts.windows(2) {
        let piece = pair[0] - pair[1];
        assert!((piece - 500.0).abs() <= 0.01, "piece {piece} mm: {cuts:?}");
    }
    assert_eq!(
        syncs_from_moving_back, 19,
        "every sync after the first from a returning saw"
    );
}

/// The flying-saw blocks called by name from a timeline (`scenarios/saw-blocks`), in
/// process: the saw is synchronous exactly when the master passes its sync position, the
/// characteristic values are read, MC_GearOut leaves the saw at the master's speed until
/// MC_Halt.
#[test]
fn the_saw_blocks_run_from_a_timeline() {
    use cnc_app::scenario::{InProcess, Scenario};
    let path = tests::cli::scenario("saw-blocks");
    let s = Scenario::load(&path).unwrap();
    let run = InProcess::run_through(&s).unwrap();
    let summary = run.timeline.as_ref().unwrap().summary();
    assert!(!summary.contains("ErrorID"), "{summary}");
    for block in [
        "sync (MC_GearInPos",
        "charac (MC_ReadFlyingSawCharacteristics",
        "out (MC_GearOut",
        "halt (MC_Halt",
    ] {
        assert!(summary.contains(block), "{block}: {summary}");
    }
    let csv = String::from_utf8(run.trace_csv()).unwrap();
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    // tick, time, master, saw, saw velocity, nAxisState, coupling (0.1 um, 0.1 um/s).
    let at = rows
        .iter()
        .position(|r| r[2] >= 1500.0 * 1e4)
        .expect("the master passes 1500");
    let r = &rows[at];
    assert_eq!(r[5], 13.0, "synchronous at the sync point");
    assert_eq!(rows[at - 1][5], 12.0, "synchronising the tick before");
    let expected = 1000.0 * 1e4 + (r[2] - 1500.0 * 1e4);
    assert!(
        (r[3] - expected).abs() <= 1.0,
        "saw {} expected {expected}",
        r[3]
    );
    assert_eq!(r[4], 500.0 * 1e4);
    // After MC_GearOut (tick 3700) and before MC_Halt (4000): free, at 500 mm/s.
    let free = &rows[3900];
    assert_eq!((free[5], free[6], free[4]), (2.0, 0.0, 500.0 * 1e4));
    assert_eq!(rows.last().unwrap()[4], 0.0, "halted");
}

/// PLCopen: a block whose slave another block instance couples again is CommandAborted, also
/// when the new coupling is of the same kind to the same master (which the axis image cannot
/// tell from the first block's own): the first follows its command id in the slave's book.
#[test]
fn a_coupling_taken_over_by_another_instance_is_command_aborted() {
    use cnc_app::scenario::{InProcess, Scenario};
    let scenario = "cycle_ms = 1.0\nticks = 1500\n\
        [[axis]]\nname = \"Master\"\npower = true\nsoft_limits = [-1000.0, 5000.0]\nvelocity = 1000.0\n\
        [[axis]]\nname = \"Saw\"\npower = true\nsoft_limits = [-1000.0, 5000.0]\nvelocity = 1000.0\n\
        [plc]\ntimeline = \"plc.toml\"\n";
    let velo = |name: &str| {
        format!(
            "call = {{ block = \"MC_GearInVelo\", instance = \"{name}\", Master = 0, Slave = 1, \
             RatioNumerator = 0.5, RatioDenominator = 1, Acceleration = 2500.0, Deceleration = 2500.0, Jerk = 50000.0 }}\n"
        )
    };
    let timeline = format!(
        "[[step]]\nat_tick = 2\ncall = {{ block = \"MC_MoveVelocity\", instance = \"master\", axis = 0, direction = 1, \
         velocity = 500.0, acceleration = 5000.0, deceleration = 5000.0, jerk = 100000.0 }}\n\
         [[step]]\nwait = \"master.InVelocity\"\n{}\
         [[step]]\nwait = \"first.InSync\"\n{}",
        velo("first"),
        velo("second")
    );
    let s = Scenario::parse("takeover.toml", scenario, |f| {
        let text = match f {
            "plc.toml" => timeline.clone(),
            other => panic!("{other}"),
        };
        Ok((std::path::PathBuf::from(f), text))
    })
    .unwrap();
    let run = InProcess::run_through(&s).unwrap();
    let summary = run.timeline.as_ref().unwrap().summary();
    let line = |name: &str| {
        summary
            .lines()
            .find(|l| l.starts_with(&format!("block {name} ")))
            .unwrap_or_else(|| panic!("{name}: {summary}"))
            .to_string()
    };
    assert!(line("first").contains("InSync"), "{summary}");
    assert!(line("first").contains("CommandAborted"), "{summary}");
    assert!(line("second").contains("InSync"), "{summary}");
    assert!(!line("second").contains("CommandAborted"), "{summary}");
    assert!(!summary.contains("ErrorID"), "{summary}");
}
