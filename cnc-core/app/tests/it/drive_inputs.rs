//! The axis image options a scenario gives (`io = { ... }`), as the machine then answers:
//! the scenario reader's part of the drive inputs (the axis layer's own rules are
//! `cnc-core/tests/it/axes/drive_inputs.rs`).

use hli::enums::{AxisError, DriveState};
use hli::layout::{HliAxis, HliAxisDriveState};
use hli::views::CncView;
use hli::PlaceExt;

#[test]
fn a_scenario_configures_the_image_options_and_the_machine_answers_probe_calls() {
    use cnc_app::scenario::{InProcess, Scenario};
    let toml = "cycle_ms = 1.0\nticks = 10\n[[axis]]\nname = \"Table\"\npower = true\n\
                io = { protocol = \"cia402\", probe = \"sercos\", dc_compensation = true }\n";
    let no_files = |f: &str| -> Result<(std::path::PathBuf, String), _> {
        Err(cnc_app::scenario::ScenarioError::Read {
            file: f.into(),
            message: "no files here".into(),
        })
    };
    let scenario = Scenario::parse("io.toml", toml, no_files).unwrap();
    let mut run = InProcess::new(&scenario, 0).unwrap();
    for _ in 0..6 {
        run.machine.tick(&run.memory);
    }
    let view = CncView::new(&run.memory);
    let state: HliAxisDriveState = view
        .axis(0)
        .unwrap()
        .field::<HliAxisDriveState>(core::mem::offset_of!(HliAxis, drive_state))
        .read();
    // Powered at start through the CiA 402 sequence.
    assert_eq!(state.drive_state_r, DriveState::OperationEnabled.raw());
    let arm = hli::calls::probe::ProbeArmCall {
        probe: 2,
        edge: hli::enums::ProbeEdge::Negative.raw(),
        ..Default::default()
    };
    let reply = run.machine.call(&view, 0, &arm).unwrap();
    assert_eq!((reply.arm_id, reply.error_id), (1, 0));
    let again = run.machine.call(&view, 0, &arm).unwrap();
    assert_eq!(again.error_id, AxisError::ProbeAlreadyArmed.raw());
    let bad = toml.replace("dc_compensation", "dc_compensaton");
    assert!(Scenario::parse("io.toml", &bad, no_files).is_err());
}
