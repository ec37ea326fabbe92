//! The flying saw's settings of a scenario's built-in PLC program (`[plc]`): the one saw test
//! that needs the application. The engine tests (position sync, MC_GearOut, rollback,
//! refusals, the internal table, the characteristic values, the diagonal saw, the time-based
//! phase) run in the library on its machine harness: `cnc_core::saw`'s `engine_tests`.

use cnc_app::scenario::{Scenario, ScenarioError};

/// The saw settings of `[plc]` go with the programs that have a saw, and only in range.
#[test]
fn saw_settings_of_a_plc_program_are_checked() {
    let parse = |plc: &str| {
        let toml = format!("cycle_ms = 1.0\nticks = 10\n[[axis]]\nname = \"A\"\n[plc]\n{plc}\n");
        Scenario::parse("plc.toml", &toml, |f| {
            Err(ScenarioError::Read {
                file: f.into(),
                message: "none".into(),
            })
        })
        .map(|_| ())
        .map_err(|e| e.to_string())
    };
    assert_eq!(
        parse("program = \"saw-cut\"\nsaw_cuts = 3\nsaw_length = 250.0"),
        Ok(())
    );
    assert_eq!(parse("program = \"demo-machine\"\nsaw_cuts = 5"), Ok(()));
    let e = parse("program = \"cam-conveyor\"\nsaw_cuts = 3").unwrap_err();
    assert!(e.contains("belong to saw-cut and demo-machine"), "{e}");
    let e = parse("program = \"saw-cut\"\nsaw_cuts = 0").unwrap_err();
    assert!(e.contains("saw_cuts = 0: 1 to 64"), "{e}");
    let e = parse("program = \"saw-cut\"\nsaw_length = -1.0").unwrap_err();
    assert!(e.contains("saw_length = -1: mm above 0"), "{e}");
    let e = parse("timeline = \"t.toml\"\nsaw_cuts = 3").unwrap_err();
    assert!(e.contains("belong to a built-in program"), "{e}");
}
