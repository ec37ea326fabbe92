//! The cam blocks with a real PLC process: `cnc run --lockstep` on the conveyor scenario
//! couples, scales, changes a point and decouples through the acyclic service between two
//! processes, and gives the same trace and block edges as the in-process run.

use cnc_app::scenario::{InProcess, Scenario};
use std::path::PathBuf;

fn scenario_path() -> PathBuf {
    tests::cli::scenario("cam-conveyor")
}

fn run_lockstep(scenario: &std::path::Path, tag: &str) -> (String, Vec<u8>) {
    tests::cli::cnc_run_lockstep(env!("CARGO_BIN_EXE_cnc"), scenario, tag)
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
    let (report, two_process) = run_lockstep(&scenario_path(), "cams-couple");
    for needle in [
        "block cam (MC_CamIn on gpAx[1]): Busy 7 (x1), CommandAborted 4086 (x1), InSync 9 (x1)",
        "block scale (MC_CamScaling on gpAx[1]): Done",
        "block point (MC_WriteMotionFunctionPoint on gpAx[1]): Done",
        "block out (MC_CamOut on gpAx[1]): Done",
    ] {
        assert!(report.contains(needle), "{needle}\n{report}");
    }
    assert!(!report.contains("ErrorID"), "{report}");

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
    let run = |scenario: &str, tag: &str| run_lockstep(&tests::cli::scenario(scenario), tag);
    let (report, program) = run("cam-conveyor-program", "cams-program");
    assert!(
        report.contains("cam-conveyor: Finished; Select at cycle 0, Couple at cycle 5"),
        "{report}"
    );
    let (_, timeline) = run("cam-conveyor", "cams-timeline");
    assert_eq!(program, timeline, "the program and the timeline differ");
}
