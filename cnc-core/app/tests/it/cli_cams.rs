//! The cam blocks with a real PLC process: `cnc run --lockstep` on the conveyor scenario
//! couples, scales, changes a point and decouples through the acyclic service between two
//! processes, and gives the same trace and block edges as the in-process run.

use cnc_app::scenario::{InProcess, Scenario};
use std::path::PathBuf;
use std::process::Command;

fn scenario_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/cam-conveyor/scenario.toml")
}

fn blocks(report: &str) -> Vec<String> {
    report
        .lines()
        .filter(|l| l.starts_with("block "))
        .map(str::to_string)
        .collect()
}

#[test]
fn a_plc_process_couples_scales_changes_and_decouples_a_cam_slave() {
    let pid = std::process::id();
    let trace = std::env::temp_dir().join(format!("cli-cams-{pid}.csv"));
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["run", scenario_path().to_str().unwrap(), "--lockstep"])
        .args(["--instance", &format!("cli-cams-{pid}"), "--trace"])
        .arg(&trace)
        .output()
        .unwrap();
    let report =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{report}");
    for needle in [
        "block cam (MC_CamIn on gpAx[1]): Busy 7 (x1), CommandAborted 4086 (x1), InSync 9 (x1)",
        "block scale (MC_CamScaling on gpAx[1]): Done",
        "block point (MC_WriteMotionFunctionPoint on gpAx[1]): Done",
        "block out (MC_CamOut on gpAx[1]): Done",
    ] {
        assert!(report.contains(needle), "{needle}\n{report}");
    }
    assert!(!report.contains("ErrorID"), "{report}");
    let two_process = std::fs::read(&trace).unwrap();
    let _ = std::fs::remove_file(&trace);

    let s = Scenario::load(&scenario_path()).unwrap();
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
}

#[test]
fn the_plc_program_does_what_the_timeline_does_tick_for_tick() {
    let pid = std::process::id();
    let run = |scenario: &str, tag: &str| {
        let trace = std::env::temp_dir().join(format!("cli-cams-{tag}-{pid}.csv"));
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join(format!("../../scenarios/{scenario}/scenario.toml"));
        let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
            .args(["run", path.to_str().unwrap(), "--lockstep"])
            .args(["--instance", &format!("cli-cams-{tag}-{pid}"), "--trace"])
            .arg(&trace)
            .output()
            .unwrap();
        let report = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{report}");
        let rows = std::fs::read(&trace).unwrap();
        let _ = std::fs::remove_file(&trace);
        (report, rows)
    };
    let (report, program) = run("cam-conveyor-program", "program");
    assert!(
        report.contains("cam-conveyor: Finished; Select at cycle 0, Couple at cycle 5"),
        "{report}"
    );
    let (_, timeline) = run("cam-conveyor", "timeline");
    assert_eq!(program, timeline, "the program and the timeline differ");
}
