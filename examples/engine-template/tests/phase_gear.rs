//! The phase gear run as a user would: registered once, configured by its `[phase_gear]`
//! table, called from a timeline, on the library's machine in lockstep with the PLC.

use cnc_app::scenario::file::Scenario;
use cnc_app::scenario::machine::InProcess;
use engine_template::calls::{PhaseGearError, PHASE_GEAR_IN};
use std::path::PathBuf;

const MACHINE: &str = "cycle_ms = 1.0\nticks = 3000\n\
    [[axis]]\nname = \"Master\"\npower = true\n\
    [[axis]]\nname = \"Slave\"\npower = true\nstart = 3.0\n\
    [[axis]]\nname = \"Other\"\npower = true\n\
    [phase_gear]\nshift_velocity = 20.0\nshift_acceleration = 200.0\nshift_jerk = 5000.0\n\
    [plc]\ntimeline = \"plc.toml\"\n";

/// Couple at rest with phase 2, move the master, shift to phase 5 while it moves, try a
/// second coupling on the moving master, let the slave go.
const TIMELINE: &str = "\
    [[step]]\nat_tick = 10\ncall = { block = \"PhaseGearIn\", instance = \"gear\", axis = 1, master = 0, ratio = 0.5, phase = 2.0 }\n\
    [[step]]\nwait = \"gear.Done\"\ncall = { block = \"MC_MoveAbsolute\", instance = \"m\", axis = 0, position = 200.0, velocity = 300.0, acceleration = 3000.0, deceleration = 3000.0, jerk = 30000.0 }\n\
    [[step]]\nat_tick = 300\ncall = { block = \"PhaseGearIn\", instance = \"gear\", axis = 1, master = 0, ratio = 0.5, phase = 5.0 }\n\
    [[step]]\nat_tick = 320\ncall = { block = \"PhaseGearIn\", instance = \"late\", axis = 2, master = 0 }\n\
    [[step]]\nat_tick = 2000\ncall = { block = \"PhaseGearOut\", instance = \"out\", axis = 1 }\n";

fn scenario(machine: &str) -> Result<Scenario, String> {
    engine_template::register().unwrap();
    Scenario::parse("phase.toml", machine, |_| {
        Ok((PathBuf::from("plc.toml"), TIMELINE.to_string()))
    })
    .map_err(|e| e.to_string())
}

#[test]
fn the_slave_follows_ratio_and_phase_and_shifts_within_its_limits() {
    let s = scenario(MACHINE).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let (mut coupled, mut last_phase, mut last_rate) = (None, 0.0, 0.0);
    let dt = s.cycle_s;
    for _ in 0..3000 {
        run.step(dt);
        let axes = run.machine.axes();
        let m = axes.axis(0).unwrap().setpoint();
        let slave = axes.axis(1).unwrap();
        let tick = run.machine.ticks();
        if slave.coupling().is_none() {
            continue;
        }
        let origin = *coupled.get_or_insert(m.position);
        // The phase is what the slave has beyond the gear.
        let phase = slave.setpoint().position - (3.0 + 0.5 * (m.position - origin));
        let rate = (phase - last_phase) / dt;
        assert!(rate.abs() <= 20.0 * 1.001, "tick {tick}: phase rate {rate}");
        assert!(
            ((rate - last_rate) / dt).abs() <= 200.0 * 1.01,
            "tick {tick}: phase acceleration"
        );
        (last_phase, last_rate) = (phase, rate);
        if tick == 299 {
            assert!((phase - 2.0).abs() < 1e-9, "phase 2 reached: {phase}");
        }
        if tick == 1999 {
            assert!((phase - 5.0).abs() < 1e-9, "phase 5 reached: {phase}");
        }
    }
    assert!(coupled.is_some(), "the slave was coupled");
    let axes = run.machine.axes();
    let slave = axes.axis(1).unwrap();
    assert!(slave.coupling().is_none(), "PhaseGearOut let it go");
    // Master at 200 since long before the release: the slave stood at 3 + 100 + 5.
    assert!((slave.actual() - 108.0).abs() < 1e-3, "{}", slave.actual());
    // The second coupling on the moving master was refused with the engine's code.
    let report = run.timeline.as_ref().unwrap().summary();
    let code = format!("ErrorID {:#06x}", PhaseGearError::MasterMoving.raw());
    let late = report.lines().find(|l| l.contains("late")).unwrap();
    assert!(late.contains(&code), "{report}");
    assert!(axes.axis(2).unwrap().coupling().is_none());
}

#[test]
fn its_configuration_is_checked_by_the_engine_and_named() {
    let bad = MACHINE.replace("shift_jerk = 5000.0", "shift_jerk = -1.0");
    let e = scenario(&bad).unwrap_err();
    assert!(e.contains("[phase_gear] shift_jerk = -1"), "{e}");
    let bad = MACHINE.replace("shift_jerk = 5000.0", "shift_jerk = 5000.0\nphase = 1.0");
    let e = scenario(&bad).unwrap_err();
    assert!(e.contains("[phase_gear]: unknown field `phase`"), "{e}");
}

#[test]
fn registration_is_once_and_refuses_a_taken_number() {
    engine_template::register().unwrap();
    engine_template::register().unwrap();
    assert_eq!(
        hli::calls::CallKind::decode(70),
        Some(PHASE_GEAR_IN),
        "the extension's kinds decode"
    );
    // A family that takes MC_CamIn's number is refused before anything is registered.
    static TAKEN: &[&[hli::calls::CallSpec]] = &[&[hli::calls::CallSpec {
        kind: hli::calls::CallKind::declare(11),
        name: "MINE",
        read_only: false,
        bulk: false,
        family: "mine",
    }]];
    let e = hli::calls::register_extension(TAKEN).unwrap_err();
    assert!(e.to_string().contains("MINE = 11"), "{e}");
}

/// The template's own binary runs the scenario as two processes (the PLC it spawns is the same
/// binary, registered the same way): the slave ends at 3 + 0.5 x 200 + 5 = 108 mm (the trace
/// holds the image's 0.1 um), and the report names the blocks.
#[test]
fn its_binary_runs_the_phase_gear_in_two_processes() {
    let scenario = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenario/scenario.toml");
    let (report, trace) = tests::cli::cnc_run_lockstep(
        env!("CARGO_BIN_EXE_cnc-phase-gear"),
        &scenario,
        "phase-gear",
    );
    assert!(report.contains("PhaseGearIn"), "{report}");
    let text = String::from_utf8(trace).unwrap();
    let last = text.lines().last().unwrap();
    let slave: i64 = last.split(',').nth(3).unwrap().parse().unwrap();
    assert_eq!(slave, 1_080_000, "{last}");
}
