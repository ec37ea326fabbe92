//! MC_CamTableSelect's choice of absolute and relative, and MC_CamScaling with activation
//! OFF (seed 000).

use super::*;
use hli::calls::cam::CAM_START_AS_SELECTED;

/// A table selected with MasterAbsolute and SlaveAbsolute FALSE couples relative with
/// MC_CamIn's default StartMode: the slave standing at 5 follows 5 + T(master), the seed
/// cam's law counted from where it stood.
#[test]
fn a_table_selected_relative_couples_relative() {
    let mut run = machine();
    run.step();
    let command =
        hli::calls::axis::AxisCommandCall::move_absolute(5.0, [100.0, 1000.0, 1000.0, 10_000.0]);
    run.call(SLAVE as u32, &command).unwrap();
    while set(&run, SLAVE).position != 5.0 || set(&run, SLAVE).velocity != 0.0 {
        run.step();
    }
    let select = CamTableSelectCall {
        periodic: 1,
        master_absolute: 0,
        slave_absolute: 0,
        reserved: 0,
    };
    assert_eq!(call(&mut run, 1, select), 0);
    let c = CamInCall {
        start_mode: CAM_START_AS_SELECTED,
        ..cam_in(1)
    };
    assert_eq!(call(&mut run, SLAVE as u32, c), 0);
    // Coupled in the next tick, with the master still at 0 (its origin).
    run.step();
    run_master(&mut run, 360.0);
    let (profile, law) = (seed_cam(), seed_law(true));
    let mut checked = 0;
    for _ in 0..1500 {
        run.step();
        let m = set(&run, MASTER);
        let expected = 5.0 + law_at(&law, &profile, m).position;
        let got = set(&run, SLAVE).position;
        assert!(
            (got - expected).abs() < 1e-9,
            "at {}: {got} vs {expected}",
            m.position
        );
        checked += u32::from(expected > 6.0);
    }
    assert!(checked > 100, "the cam moved the slave ({checked})");
}

/// MC_CamScaling with ActivationMode OFF carries no scaling out (seed 000 5.1.16.13): taken
/// (0) and nothing changes: the slave stays on its law, and a scaling queued before it (the
/// seed's example 1 at NextCycle) still comes at the next cycle as queued, not the OFF call's.
#[test]
fn a_scaling_with_activation_off_changes_nothing() {
    let mut run = machine();
    run.step();
    select_cyclic(&mut run, 1);
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(1)), 0);
    run_master(&mut run, 360.0);
    let profile = seed_cam();
    let law = seed_law(true);
    let scaling = |activation_mode: u32, slave_scaling: f64| CamScalingCall {
        activation_mode,
        master_scaling_mode: 2,
        slave_scaling_mode: 0,
        master_scaling: 1.0,
        slave_scaling,
        ..CamScalingCall::default()
    };
    while set(&run, MASTER).position < 200.0 {
        run.step();
    }
    assert_eq!(call(&mut run, SLAVE as u32, scaling(3, 0.0)), 0);
    assert_eq!(call(&mut run, SLAVE as u32, scaling(6, 3.0)), 0);
    while set(&run, MASTER).position < 359.0 {
        run.step();
        let expected = law_at(&law, &profile, set(&run, MASTER)).position;
        assert!((set(&run, SLAVE).position - expected).abs() < 1e-9);
    }
    while set(&run, MASTER).position < 380.0 {
        run.step();
    }
    let mut moved: f64 = 0.0;
    while set(&run, MASTER).position < 700.0 {
        run.step();
        moved = moved.max(set(&run, SLAVE).position.abs());
    }
    assert_eq!(
        moved, 0.0,
        "the queued SlaveScaling 0, not the OFF call's 3"
    );
}
