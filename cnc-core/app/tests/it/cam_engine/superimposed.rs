//! MC_MoveSuperimposed on a cam slave through the PLC block: Busy beside MC_CamIn, Done at its
//! end, aborted by a second one, refused on a free axis.

use super::*;

/// The PLC block: MC_MoveSuperimposed is Busy while it runs beside MC_CamIn (which stays
/// InSync), Done at its end; a second one started while the first runs aborts it
/// (CommandAborted); on the free master it ends with 0x4235.
#[test]
fn the_plc_block_runs_beside_the_cam_and_reports_done_aborted_and_refused() {
    let timeline = format!(
        "{COUPLED_AND_RUNNING}{}",
        r#"
[[step]]
at_tick = 600
call = { block = "MC_MoveSuperimposed", instance = "shift", axis = 1, distance = 3.0, velocity_diff = 20.0, acceleration = 200.0, deceleration = 200.0, jerk = 1e4 }
[[step]]
wait = "shift.Done"
call = { block = "MC_MoveSuperimposed", instance = "first", axis = 1, distance = 20.0, velocity_diff = 20.0, acceleration = 200.0, deceleration = 200.0, jerk = 1e4 }
[[step]]
at_tick = 1400
call = { block = "MC_MoveSuperimposed", instance = "second", axis = 1, distance = -1.0, velocity_diff = 20.0, acceleration = 200.0, deceleration = 200.0, jerk = 1e4 }
[[step]]
at_tick = 1410
call = { block = "MC_MoveSuperimposed", instance = "free", axis = 0, distance = 1.0, velocity_diff = 20.0, acceleration = 200.0, deceleration = 200.0, jerk = 1e4 }
"#
    );
    let toml = "cycle_ms = 1.0\nticks = 3000\n\
        [[axis]]\nname = \"Conveyor\"\nkind = \"rotary\"\npower = true\nvelocity = 720.0\n\
        acceleration = 3600.0\ndeceleration = 3600.0\njerk = 36000.0\n\
        [[axis]]\nname = \"Lifter\"\npower = true\nsoft_limits = [-10.0, 100.0]\n\
        [[cam_table]]\nfile = \"seed_example.json\"\n[plc]\ntimeline = \"plc.toml\"\n";
    let s = with_timeline("superimposed.toml", toml, &timeline);
    let run = InProcess::run_through(&s).unwrap();
    let summary = run.timeline.as_ref().unwrap().summary();
    let line = |name: &str| block_line(&summary, name);
    assert!(line("shift").contains("Done "), "{summary}");
    assert!(line("first").contains("CommandAborted "), "{summary}");
    assert!(line("second").contains("Done "), "{summary}");
    assert!(line("free").contains("ErrorID 0x4235"), "{summary}");
    assert!(!line("cam").contains("CommandAborted"), "{summary}");
    let offset = run
        .machine
        .axes()
        .axis(SLAVE)
        .unwrap()
        .superimposed_offset();
    assert!(offset > 3.0 && offset < 23.0, "{offset}");
}
