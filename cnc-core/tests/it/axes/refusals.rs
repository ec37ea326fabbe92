//! Software limits, refused commands, configurations, rotary axes, power, couplings and leases.

use super::*;

#[test]
fn velocity_move_stops_on_the_software_limit() {
    let mut config = AxisConfig::linear("X", 1);
    config.soft_limits = Some([-20.0, 20.0]);
    let mut rig = Rig::new(vec![config]);
    rig.enable(0);
    let id = rig
        .call(0, AxisCommandCall::move_velocity(1, LIMITS))
        .unwrap();
    let mut highest: f64 = 0.0;
    rig.until(10_000, |r| {
        highest = highest.max(r.set_point(0).position);
        r.view(0, id) == CommandView::Error(AxisError::SoftwareLimitReached.raw())
    });
    rig.ticks(1_000);
    highest = highest.max(rig.set_point(0).position);
    assert_eq!(rig.set_point(0).position, 20.0);
    assert!(highest <= 20.0, "overshot the limit to {highest}");
}

/// Bad commands are refused with their codes and leave a running move exactly as an
/// undisturbed twin runs.
#[test]
fn bad_commands_are_refused_and_do_not_disturb_a_running_move() {
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1), AxisConfig::linear("Y", 2)]);
    rig.enable(0);
    rig.call(1, AxisCommandCall::power(true)).unwrap();
    rig.call(0, AxisCommandCall::move_absolute(300.0, LIMITS))
        .unwrap();
    rig.call(1, AxisCommandCall::move_absolute(300.0, LIMITS))
        .unwrap();
    rig.ticks(100);
    let nan = f64::NAN;
    let refused = [
        (
            AxisCommandCall::move_absolute(5000.0, LIMITS),
            AxisError::TargetOutsideLimits,
        ),
        (
            AxisCommandCall::move_absolute(nan, LIMITS),
            AxisError::TargetOutsideLimits,
        ),
        (
            AxisCommandCall::move_relative(-2000.0, LIMITS),
            AxisError::TargetOutsideLimits,
        ),
        (
            AxisCommandCall::move_absolute(1.0, [0.0, 1.0, 1.0, 1.0]),
            AxisError::InvalidVelocity,
        ),
        (
            AxisCommandCall::move_absolute(1.0, [-5.0, 1.0, 1.0, 1.0]),
            AxisError::InvalidVelocity,
        ),
        (
            AxisCommandCall::move_absolute(1.0, [5000.0, 1.0, 1.0, 1.0]),
            AxisError::InvalidVelocity,
        ),
        (
            AxisCommandCall::move_absolute(1.0, [5.0, 0.0, 1.0, 1.0]),
            AxisError::InvalidAcceleration,
        ),
        (
            AxisCommandCall::move_absolute(1.0, [5.0, 1.0, -1.0, 1.0]),
            AxisError::InvalidDeceleration,
        ),
        (
            AxisCommandCall::move_absolute(1.0, [5.0, 1.0, 1.0, nan]),
            AxisError::InvalidJerk,
        ),
        (
            AxisCommandCall::move_velocity(0, LIMITS),
            AxisError::InvalidDirection,
        ),
        (
            AxisCommandCall::halt(0.0, 1.0),
            AxisError::InvalidDeceleration,
        ),
        (
            AxisCommandCall {
                command: 99,
                ..AxisCommandCall::default()
            },
            AxisError::InvalidParameter,
        ),
        (
            AxisCommandCall {
                reserved: 1,
                ..AxisCommandCall::reset()
            },
            AxisError::InvalidParameter,
        ),
        (AxisCommandCall::power(false), AxisError::MovingWhileDisable),
    ];
    for (call, code) in refused {
        assert_eq!(rig.call(0, call), Err(code), "{call:?}");
        rig.tick();
        assert_eq!(
            rig.set_point(0),
            rig.set_point(1),
            "the refused {call:?} disturbed the move"
        );
    }
    // A disabled axis and a coupled one refuse moves.
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
    rig.tick();
    assert_eq!(
        rig.call(0, AxisCommandCall::move_absolute(1.0, LIMITS)),
        Err(AxisError::NotEnabled)
    );
    rig.call(0, AxisCommandCall::power(true)).unwrap();
    let _lease = rig
        .set
        .couple(
            0,
            Coupling {
                kind: CouplingState::Cam,
                master: 1,
                phase: AxisState::SlaveSynchronizing,
            },
        )
        .unwrap();
    assert_eq!(
        rig.call(0, AxisCommandCall::move_absolute(1.0, LIMITS)),
        Err(AxisError::Coupled)
    );
    assert_eq!(
        rig.call(0, AxisCommandCall::halt(10.0, 100.0)),
        Err(AxisError::Coupled)
    );
}

#[test]
fn a_decoupled_slave_goes_on_at_constant_velocity() {
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
    rig.enable(0);
    let lease = rig
        .set
        .couple(
            0,
            Coupling {
                kind: CouplingState::GearVelocity,
                master: 1,
                phase: AxisState::SlaveSynchronous,
            },
        )
        .unwrap();
    // The coupled engine moves the slave at 100 mm/s.
    for n in 0..200 {
        let p = n as f64 * 0.1;
        rig.set.drive(
            lease,
            Kinematic {
                position: p,
                velocity: 100.0,
                acceleration: 0.0,
                jerk: 0.0,
            },
            AxisState::SlaveSynchronous,
        );
        rig.tick();
    }
    let lr = CncView::new(&rig.memory)
        .axis(0)
        .unwrap()
        .field::<hli::layout::HliAxisLrState>(0)
        .read();
    assert_eq!(lr.axis_state_r, 13);
    assert_eq!(lr.coupling_state_r, CouplingState::GearVelocity.raw());
    rig.set.release(lease);
    rig.ticks(500);
    let k = rig.set_point(0);
    assert!((k.velocity - 100.0).abs() < 1e-9, "velocity {}", k.velocity);
    assert_eq!(k.acceleration, 0.0);
    assert!(
        (k.position - (19.9 + 0.5 * 100.0)).abs() < 1e-6,
        "position {}",
        k.position
    );
    let lr = CncView::new(&rig.memory)
        .axis(0)
        .unwrap()
        .field::<hli::layout::HliAxisLrState>(0)
        .read();
    assert_eq!(lr.axis_state_r, AxisState::ConstantVelocity.raw());
}

#[test]
fn configurations_out_of_range_are_refused_by_name() {
    let mut bad = AxisConfig::linear("X", 1);
    bad.dynamics.jerk = 0.0;
    let err = AxisSet::new(vec![bad], CYCLE).unwrap_err();
    assert!(err.to_string().contains("dynamics.jerk = 0"), "{err}");
    let mut bad = AxisConfig::linear("X", 1);
    bad.drive = DriveLink::Simulated(SimDriveConfig {
        dead_time_ticks: 65,
        ..SimDriveConfig::default()
    });
    assert!(AxisSet::new(vec![bad], CYCLE).is_err());
    let mut tiny = AxisConfig::rotary("C", 1);
    tiny.kind = cnc_core::axis::AxisKind::Rotary { modulo: 0.00001 };
    assert!(
        AxisSet::new(vec![tiny], CYCLE).is_err(),
        "a modulo below one HLI unit"
    );
    let twins = vec![AxisConfig::linear("X", 1), AxisConfig::linear("X", 2)];
    assert!(AxisSet::new(twins, CYCLE).is_err());
    let many = (0..33)
        .map(|i| AxisConfig::linear(&format!("A{i}"), i + 1))
        .collect();
    assert!(AxisSet::new(many, CYCLE).is_err());
}

#[test]
fn an_endless_rotary_axis_wraps_its_displayed_positions() {
    let mut rig = Rig::new(vec![AxisConfig::rotary("C", 1)]);
    rig.enable(0);
    rig.call(
        0,
        AxisCommandCall::move_velocity(1, [3600.0, 36_000.0, 36_000.0, 720_000.0]),
    )
    .unwrap();
    let mut seen_wrap = false;
    let mut last = 0;
    for _ in 0..2_000 {
        rig.tick();
        let lr = CncView::new(&rig.memory)
            .axis(0)
            .unwrap()
            .field::<hli::layout::HliAxisLrState>(0)
            .read();
        assert!(
            (0..3_600_000).contains(&lr.command_position_acs_r),
            "{}",
            lr.command_position_acs_r
        );
        seen_wrap |= lr.command_position_acs_r < last;
        last = lr.command_position_acs_r;
    }
    assert!(seen_wrap);
    assert!(
        rig.set_point(0).position > 3600.0,
        "ten turns and more, unbounded inside"
    );
    assert_eq!(rig.set.axis(0).unwrap().error(), None);
}

#[test]
fn a_velocity_move_from_the_soft_limit_outwards_ends_at_once_without_moving() {
    let mut config = AxisConfig::linear("X", 1);
    config.soft_limits = Some([-20.0, 20.0]);
    let mut rig = Rig::new(vec![config]);
    rig.enable(0);
    let to_limit = rig
        .call(0, AxisCommandCall::move_absolute(20.0, LIMITS))
        .unwrap();
    rig.until(5_000, |r| r.view(0, to_limit) == CommandView::Done);
    let out = rig
        .call(0, AxisCommandCall::move_velocity(1, LIMITS))
        .unwrap();
    rig.until(100, |r| {
        r.view(0, out) == CommandView::Error(AxisError::SoftwareLimitReached.raw())
    });
    rig.ticks(200);
    assert!(rig.set_point(0).position <= 20.0);
    assert_eq!(rig.set.axis(0).unwrap().error(), None);
}

#[test]
fn reset_without_an_error_leaves_a_running_move_alone() {
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1), AxisConfig::linear("Y", 2)]);
    rig.enable(0);
    rig.call(1, AxisCommandCall::power(true)).unwrap();
    let id = rig
        .call(0, AxisCommandCall::move_absolute(200.0, LIMITS))
        .unwrap();
    rig.call(1, AxisCommandCall::move_absolute(200.0, LIMITS))
        .unwrap();
    rig.ticks(100);
    rig.call(0, AxisCommandCall::reset()).unwrap();
    for _ in 0..50 {
        rig.tick();
        assert_eq!(rig.set_point(0), rig.set_point(1));
    }
    rig.until(5_000, |r| r.view(0, id) == CommandView::Done);
}

#[test]
fn power_off_ends_a_coupling_at_rest_and_is_refused_at_speed() {
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
    rig.enable(0);
    let slave = Coupling {
        kind: CouplingState::Cam,
        master: 1,
        phase: AxisState::SlaveSynchronous,
    };
    let lease = rig.set.couple(0, slave).unwrap();
    let moving = Kinematic {
        position: 0.0,
        velocity: 10.0,
        acceleration: 0.0,
        jerk: 0.0,
    };
    rig.set.drive(lease, moving, AxisState::SlaveSynchronous);
    rig.tick();
    assert_eq!(
        rig.call(0, AxisCommandCall::power(false)),
        Err(AxisError::MovingWhileDisable)
    );
    let resting = Kinematic {
        velocity: 0.0,
        ..moving
    };
    rig.set.drive(lease, resting, AxisState::SlaveSynchronous);
    rig.tick();
    rig.call(0, AxisCommandCall::power(false)).unwrap();
    rig.tick();
    let lr = CncView::new(&rig.memory)
        .axis(0)
        .unwrap()
        .field::<hli::layout::HliAxisLrState>(0)
        .read();
    assert_eq!(lr.coupling_state_r, CouplingState::Uncoupled.raw());
    assert_eq!(lr.axis_state_r, AxisState::Inactive.raw());
}

#[test]
fn a_sixteen_bit_position_drive_starting_far_from_zero_does_not_jump() {
    let mut config = AxisConfig::linear("X", 1);
    config.encoder_width = CounterWidth::Bits16;
    config.drive_mode = DriveMode::Position;
    config.drive = DriveLink::Simulated(SimDriveConfig {
        dynamic: Dynamic::Pt1 { t1_s: 0.01 },
        dead_time_ticks: 0,
        start_position: 5.0,
        ..SimDriveConfig::default()
    });
    let mut rig = Rig::new(vec![config]);
    rig.enable(0);
    rig.ticks(200);
    // The motor stays where it started; the NC reads the 16-bit counter as a signed first value
    // (an incremental counter knows no absolute position before homing): one wrap apart.
    let motor = rig.set.drive_mut(0).unwrap().position();
    assert!((motor - 5.0).abs() < 1e-9, "motor moved to {motor}");
    let axis = rig.set.axis(0).unwrap();
    assert!(
        (axis.actual() - (5.0 - 6.5536)).abs() < 1e-9,
        "actual {}",
        axis.actual()
    );
    assert_eq!(axis.error(), None);
}

#[test]
fn decoupling_inside_an_engines_tick_keeps_the_motion_going() {
    // A slave coupled at 100 units/s; an engine decouples it between sense and act: the
    // set-point of that very tick moves on by one tick's travel, no stall.
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
    rig.enable(0);
    let lease = rig
        .set
        .couple(
            0,
            Coupling {
                kind: CouplingState::Cam,
                master: -1,
                phase: AxisState::SlaveSynchronous,
            },
        )
        .unwrap();
    let view = CncView::new(&rig.memory);
    for k in 1..=50 {
        rig.set.sense(&view);
        rig.set.drive(
            lease,
            Kinematic {
                position: 0.1 * k as f64,
                velocity: 100.0,
                ..Kinematic::default()
            },
            AxisState::SlaveSynchronous,
        );
        rig.set.act(&view);
    }
    let before = rig.set_point(0).position;
    rig.set.sense(&view);
    rig.set.release(lease);
    rig.set.act(&view);
    let after = rig.set_point(0);
    assert!(
        ((after.position - before) - 0.1).abs() < 1e-9,
        "moved {} in the decoupling tick",
        after.position - before
    );
    assert!((after.velocity - 100.0).abs() < 1e-9);
    // Between ticks the generator takes over with the next tick (no double step).
    rig.tick();
    assert!((rig.set_point(0).position - after.position - 0.1).abs() < 1e-9);
}

/// Issue 32: one ownership rule. A coupling is driven and released through its lease; once
/// another coupling took the axis (here after a release), the old lease does nothing.
#[test]
fn a_stale_lease_neither_drives_nor_releases_the_axis() {
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
    rig.enable(0);
    let coupling = |kind| Coupling {
        kind,
        master: -1,
        phase: AxisState::SlaveSynchronous,
    };
    let first = rig.set.couple(0, coupling(CouplingState::Cam)).unwrap();
    assert!(rig.set.holds(first));
    assert!(rig.set.release(first));
    let second = rig
        .set
        .couple(0, coupling(CouplingState::GearVelocity))
        .unwrap();
    assert!(!rig.set.holds(first) && rig.set.holds(second));
    let away = Kinematic {
        position: 5.0,
        ..Kinematic::default()
    };
    assert!(!rig.set.drive(first, away, AxisState::SlaveSynchronous));
    assert!(!rig.set.release(first), "a stale lease releases nothing");
    let kind = rig.set.axis(0).unwrap().coupling().map(|c| c.kind);
    assert_eq!(kind, Some(CouplingState::GearVelocity));
    assert!(rig.set.drive(second, away, AxisState::SlaveSynchronous));
}
