//! MC_CamScaling's Done in a PLC timeline: when its scaling activates.

use super::*;

/// MC_CamScaling is Done when the scaling has been carried out (seed 000 5.1.6), not when the
/// CNC took it: sent mid-cycle with ActivationMode NextCycle, it stays Busy until the master
/// crosses the cycle boundary; the step waiting for its Done fires only then.
#[test]
fn cam_scaling_is_done_when_its_scaling_activates() {
    let scenario = "cycle_ms = 1.0\nticks = 2500\n\
        [[axis]]\nname = \"Conveyor\"\nkind = \"rotary\"\npower = true\nvelocity = 720.0\n\
        acceleration = 3600.0\ndeceleration = 3600.0\njerk = 36000.0\n\
        [[axis]]\nname = \"Lifter\"\npower = true\nsoft_limits = [-100.0, 200.0]\n\
        [[cam_table]]\nfile = \"seed_example.json\"\n[plc]\ntimeline = \"plc.toml\"\n";
    let timeline = &format!(
        "{COUPLED_AND_RUNNING}{}",
        r#"
[[step]]
at_tick = 500
call = { block = "MC_CamScaling", instance = "scale", axis = 1, activation_mode = "next_cycle", slave_scaling_mode = "auto_offset", slave_scaling = 0.5 }
[[step]]
wait = "scale.Done"
call = { block = "MC_Halt", instance = "halt", axis = 0, deceleration = 3600.0, jerk = 36000.0 }
"#
    );
    let s = with_timeline("scaling-done.toml", scenario, timeline);
    let mut run = InProcess::new(&s, 0).unwrap();
    let mut crossed = None;
    let mut before: f64 = 0.0;
    for tick in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let m = set(&run, MASTER).position;
        if crossed.is_none() && tick > 500 && m.rem_euclid(360.0) < before.rem_euclid(360.0) {
            crossed = Some(tick);
        }
        before = m;
    }
    let crossed = crossed.expect("the master crossed a cycle boundary after tick 500");
    let records = run.timeline.as_ref().unwrap().records().to_vec();
    let sent = records[3].first_fired_at.expect("the scaling was sent");
    let done = records[4].first_fired_at.expect("the scaling became Done");
    assert!(
        sent >= 500 && sent + 100 < crossed,
        "sent at {sent}, boundary at {crossed}"
    );
    assert!(
        (crossed..crossed + 5).contains(&done),
        "Done at tick {done}, the boundary at {crossed}"
    );
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
}
