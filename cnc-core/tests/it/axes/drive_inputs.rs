//! The optional signals of the axis process image (seed 004), each with its value: the drive's
//! following error and torque, the CiA 402 state machine (`nCtrl1`, `nStatus1/2`), the drive
//! outputs of every drive mode, dead-time compensation from the distributed-clock times, and
//! undefined input words.

use cnc_core::axis::config::{AxisConfig, DriveLink, DriveMode, DriveProtocol};
use cnc_core::axis::sim_drive::{Dynamic, SimDriveConfig};
use hli::calls::axis::AxisCommandCall;
use hli::enums::{axis_status, drive_flags, AxisError, DriveState};
use hli::layout::{HliAxisLrState, NcDriveIn, NcDriveOut, NcEncoderIn};

type Rig = tests::AxisRig;

fn external(name: &str, id: u32, mode: DriveMode) -> AxisConfig {
    let mut c = AxisConfig::linear(name, id);
    c.drive = DriveLink::External;
    c.drive_mode = mode;
    c
}

fn cia402(mut c: AxisConfig) -> AxisConfig {
    c.io.protocol = DriveProtocol::Cia402;
    c
}

#[test]
fn the_drives_following_error_and_torque_are_scaled_into_the_axis_block() {
    let mut position = external("P", 1, DriveMode::Position);
    position.io.torque_increments_per_percent = 4.0;
    let velocity = external("V", 2, DriveMode::Velocity);
    let mut rig = Rig::new(vec![position, velocity]);
    for axis in 0..2 {
        rig.set_drive_in(
            axis,
            NcDriveIn {
                nInData1: 250,
                nInData3: -1234,
                ..bytemuck::Zeroable::zeroed()
            },
        );
    }
    rig.tick();
    let p = rig.drive_state(0);
    // 250 increments at 10000 per mm: 0.025 mm = 250 x 0.1 um.
    assert_eq!(p.drive_following_error_r, 250);
    // -1234 increments at 4 per percent: -308.5 % = -3085 x 0.1 %.
    assert_eq!(p.actual_torque_r, -3085);
    let v = rig.drive_state(1);
    // Only a cyclic-position drive reports a following error; torque at CiA 402's per mille.
    assert_eq!(v.drive_following_error_r, 0);
    assert_eq!(v.actual_torque_r, -1234);
    assert_eq!(p.drive_state_r, DriveState::NotEvaluated.raw());
}

#[test]
fn the_drives_own_following_error_over_the_limit_stops_a_position_mode_axis() {
    let mut rig = Rig::new(vec![external("P", 1, DriveMode::Position)]);
    rig.tick();
    rig.call(0, AxisCommandCall::power(true)).unwrap();
    rig.tick();
    // 4.9 mm is inside the 5 mm limit, 5.1 mm is not.
    rig.set_drive_in(
        0,
        NcDriveIn {
            nInData1: 49_000,
            ..bytemuck::Zeroable::zeroed()
        },
    );
    rig.ticks(3);
    assert_eq!(rig.lr(0).error_id_r, 0);
    rig.set_drive_in(
        0,
        NcDriveIn {
            nInData1: -51_000,
            ..bytemuck::Zeroable::zeroed()
        },
    );
    rig.tick();
    assert_eq!(
        rig.lr(0).error_id_r,
        AxisError::ExternalFollowingError.raw()
    );
    assert_eq!(rig.drive_state(0).drive_following_error_r, -51_000);
}

#[test]
fn a_simulated_drive_reports_torque_in_proportion_to_its_acceleration() {
    // Rated torque at the axis's 10000 mm/s^2: a move accelerating at 5000 mm/s^2 needs 50 %.
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
    rig.tick();
    rig.call(0, AxisCommandCall::power(true)).unwrap();
    rig.call(
        0,
        AxisCommandCall::move_absolute(500.0, [400.0, 5000.0, 5000.0, 200_000.0]),
    )
    .unwrap();
    let mut peak = 0;
    for _ in 0..40 {
        rig.tick();
        peak = peak.max(rig.drive_state(0).actual_torque_r);
    }
    // 50.0 % in 0.1 %.
    assert!((495..=505).contains(&peak), "peak torque {peak}");
    rig.until(1000, |r| r.lr(0).command_velocity_r == 4_000_000);
    rig.ticks(3);
    assert_eq!(rig.drive_state(0).actual_torque_r, 0);
}

#[test]
fn a_cia402_drive_is_switched_on_step_by_step_and_the_axis_enabled_in_operation() {
    let mut rig = Rig::new(vec![cia402(AxisConfig::linear("X", 1))]);
    rig.ticks(2);
    // Not powered: the CNC holds the drive in Ready to switch on (shutdown).
    assert_eq!(rig.drive_out(0).nCtrl1, 0x06);
    assert_eq!(
        rig.drive_state(0).drive_state_r,
        DriveState::ReadyToSwitchOn.raw()
    );
    rig.call(0, AxisCommandCall::power(true)).unwrap();
    let mut seen = vec![];
    for _ in 0..4 {
        rig.tick();
        let lr = rig.lr(0);
        seen.push((
            rig.drive_out(0).nCtrl1,
            DriveState::decode(rig.drive_state(0).drive_state_r).unwrap(),
            lr.status_r & axis_status::ENABLED != 0,
        ));
    }
    assert_eq!(
        seen,
        [
            (0x0F, DriveState::ReadyToSwitchOn, false),
            (0x0F, DriveState::SwitchedOn, false),
            (0x0F, DriveState::OperationEnabled, true),
            (0x0F, DriveState::OperationEnabled, true),
        ]
    );
    assert_eq!(
        rig.drive_state(0).drive_flags_r,
        drive_flags::REMOTE | drive_flags::TARGET_REACHED
    );
    // MC_Power off: shutdown, back to Ready to switch on, the axis disabled.
    rig.call(0, AxisCommandCall::power(false)).unwrap();
    rig.ticks(2);
    assert_eq!(rig.drive_out(0).nCtrl1, 0x06);
    assert_eq!(
        rig.drive_state(0).drive_state_r,
        DriveState::ReadyToSwitchOn.raw()
    );
    assert_eq!(rig.lr(0).status_r & axis_status::ENABLED, 0);
}

#[test]
fn a_drive_fault_stops_the_axis_and_mc_reset_clears_it_with_a_fault_reset_edge() {
    let mut c = cia402(AxisConfig::linear("X", 1));
    c.drive_mode = DriveMode::Position;
    let mut rig = Rig::new(vec![c]);
    rig.tick();
    rig.call(0, AxisCommandCall::power(true)).unwrap();
    rig.until(10, |r| r.lr(0).status_r & axis_status::ENABLED != 0);
    assert_eq!(
        rig.drive_state(0).drive_flags_r & drive_flags::FOLLOWS_COMMAND,
        drive_flags::FOLLOWS_COMMAND
    );
    rig.call(
        0,
        AxisCommandCall::move_absolute(100.0, [200.0, 2000.0, 2000.0, 50_000.0]),
    )
    .unwrap();
    rig.ticks(100);
    rig.set.drive_mut(0).unwrap().inject_fault = true;
    rig.ticks(2);
    let lr = rig.lr(0);
    assert_eq!(lr.error_id_r, AxisError::DriveFault.raw());
    assert_eq!(lr.status_r & axis_status::ENABLED, 0);
    assert_eq!(rig.drive_state(0).drive_state_r, DriveState::Fault.raw());
    // Power is refused while the error stands; MC_Reset sends the fault reset.
    assert_eq!(
        rig.call(0, AxisCommandCall::power(true)),
        Err(AxisError::AxisInError)
    );
    let reset = rig.call(0, AxisCommandCall::reset()).unwrap();
    let mut controls = vec![];
    for _ in 0..6 {
        rig.tick();
        controls.push(rig.drive_out(0).nCtrl1);
    }
    // Fault reset once, then shutdown and enable operation: MC_Power's level still stands.
    assert_eq!(controls, [0x80, 0x06, 0x0F, 0x0F, 0x0F, 0x0F]);
    let book = rig.set.axis(0).unwrap().book().image();
    assert_eq!(
        cnc_core::axis::commands::view_command(&book, reset),
        cnc_core::axis::commands::CommandView::Done
    );
    let lr = rig.lr(0);
    assert_eq!(lr.error_id_r, 0);
    assert_ne!(lr.status_r & axis_status::ENABLED, 0);
}

#[test]
fn a_drive_that_leaves_operation_or_reports_no_state_stops_the_axis_and_is_counted() {
    let mut rig = Rig::new(vec![cia402(AxisConfig::linear("X", 1))]);
    rig.tick();
    rig.call(0, AxisCommandCall::power(true)).unwrap();
    rig.until(10, |r| r.lr(0).status_r & axis_status::ENABLED != 0);
    // Switched off locally: Switch on disabled while the axis is enabled.
    rig.set.drive_mut(0).unwrap().status_override = Some(0x40);
    rig.ticks(2);
    assert_eq!(rig.lr(0).error_id_r, AxisError::DriveStateInvalid.raw());
    assert_eq!(rig.drive_state(0).undefined_inputs_r, 0);
    // An undefined pattern is counted every tick it stands and never taken for a state.
    rig.set.drive_mut(0).unwrap().status_override = Some(0x05);
    rig.tick();
    let before = rig.drive_state(0);
    rig.ticks(10);
    let after = rig.drive_state(0);
    assert_eq!(after.undefined_inputs_r - before.undefined_inputs_r, 10);
    assert_eq!(after.drive_state_r, DriveState::SwitchOnDisabled.raw());
    assert_eq!(rig.lr(0).error_id_r, AxisError::DriveStateInvalid.raw());
}

#[test]
fn an_undefined_status_while_enabled_faults_the_axis_where_it_stands() {
    let mut rig = Rig::new(vec![cia402(AxisConfig::linear("X", 1))]);
    rig.tick();
    rig.call(0, AxisCommandCall::power(true)).unwrap();
    rig.until(10, |r| r.lr(0).status_r & axis_status::ENABLED != 0);
    rig.call(
        0,
        AxisCommandCall::move_absolute(100.0, [200.0, 2000.0, 2000.0, 50_000.0]),
    )
    .unwrap();
    rig.ticks(50);
    rig.set.drive_mut(0).unwrap().status_override = Some(0x29);
    rig.ticks(2);
    let lr = rig.lr(0);
    assert_eq!(lr.error_id_r, AxisError::DriveStateInvalid.raw());
    // The set-point stands (the generator holds the actual position).
    let held = lr.command_position_acs_r;
    rig.ticks(20);
    assert_eq!(rig.lr(0).command_position_acs_r, held);
    assert_eq!(rig.lr(0).command_velocity_r, 0);
}

/// The drive outputs of one tick against the cyclic state written in the same tick.
fn outputs_match_the_set_point(mode: DriveMode, out: &NcDriveOut, lr: &HliAxisLrState) {
    // Scalings of AxisConfig::linear: 10000 increments/mm (= 0.1 um units of the state),
    // 10000 velocity increments per mm/s, 1000 acceleration increments per mm/s^2.
    assert_eq!(out.nOutData3, lr.command_acceleration_r, "{mode:?}");
    match mode {
        DriveMode::Position => {
            assert_eq!(out.nOutData1, lr.command_position_acs_r);
            assert_eq!(out.nOutData2, lr.command_velocity_r);
        }
        DriveMode::Velocity => {
            assert_eq!(out.nOutData2, lr.command_position_acs_r);
            // The total velocity: the mean set velocity over the coming tick (up to a T / 2 =
            // 5000 units from the velocity at its end) plus the controller's share.
            assert!(
                (out.nOutData1 - lr.command_velocity_r).abs() <= 6_000,
                "{out:?}"
            );
        }
        DriveMode::Universal => {
            assert_eq!(out.nOutData2, out.nOutData1.abs());
            assert!(
                (out.nOutData1 - lr.command_velocity_r).abs() <= 6_000,
                "{out:?}"
            );
        }
    }
}

#[test]
fn every_drive_mode_writes_its_outputs_and_control_byte_with_either_protocol() {
    let modes = [
        DriveMode::Position,
        DriveMode::Velocity,
        DriveMode::Universal,
    ];
    let mut configs = vec![];
    for (i, mode) in modes.iter().enumerate() {
        for (j, protocol) in [DriveProtocol::Plain, DriveProtocol::Cia402]
            .iter()
            .enumerate()
        {
            let mut c = AxisConfig::linear(&format!("A{i}{j}"), (2 * i + j + 1) as u32);
            c.drive_mode = *mode;
            c.io.protocol = *protocol;
            configs.push(c);
        }
    }
    let mut rig = Rig::new(configs);
    rig.tick();
    for k in 0..6 {
        assert_eq!(rig.drive_out(k).nCtrl1, [0x00, 0x06][k % 2], "axis {k} off");
        rig.call(k, AxisCommandCall::power(true)).unwrap();
    }
    rig.until(10, |r| {
        (0..6).all(|k| r.lr(k).status_r & axis_status::ENABLED != 0)
    });
    for k in 0..6 {
        rig.call(
            k,
            AxisCommandCall::move_absolute(-80.0, [100.0, 1000.0, 1000.0, 20_000.0]),
        )
        .unwrap();
    }
    let mut accelerating = 0;
    for _ in 0..1000 {
        rig.tick();
        for k in 0..6 {
            let (out, lr) = (rig.drive_out(k), rig.lr(k));
            outputs_match_the_set_point(modes[k / 2], &out, &lr);
            assert_eq!(out.nCtrl1, [0x01, 0x0F][k % 2], "axis {k} on");
            if lr.command_acceleration_r != 0 {
                accelerating += 1;
            }
        }
    }
    assert!(accelerating > 600, "the acceleration phases were seen");
    // The encoder outputs mirror the encoder's count.
    for k in 0..6 {
        assert_eq!(rig.enc_out(k).nOutData1, rig.enc_in(k).nInData1);
    }
}

fn position_follower(dead_time_ticks: u32, compensate: bool) -> AxisConfig {
    let mut c = AxisConfig::linear("X", 1);
    c.drive_mode = DriveMode::Position;
    c.io.dc_compensation = compensate;
    c.drive = DriveLink::Simulated(SimDriveConfig {
        dynamic: Dynamic::Ideal,
        dead_time_ticks,
        ..SimDriveConfig::default()
    });
    c
}

/// Runs axis 0 at 100 mm/s and returns (following error, true motor position - set position)
/// in mm once the velocity is constant.
fn cruise(rig: &mut Rig) -> (f64, f64) {
    rig.tick();
    rig.call(0, AxisCommandCall::power(true)).unwrap();
    rig.call(
        0,
        AxisCommandCall::move_velocity(1, [100.0, 5000.0, 5000.0, 100_000.0]),
    )
    .unwrap();
    rig.ticks(300);
    let axis = rig.set.axis(0).unwrap();
    let (fe, set) = (axis.following_error(), axis.setpoint().position);
    let motor = rig.set.drive_mut(0).unwrap().position();
    (fe, motor - set)
}

#[test]
fn the_drives_output_time_compensates_its_dead_time_in_position_mode() {
    // Two ticks of dead time at 100 mm/s: 0.2 mm behind without compensation.
    let (fe, _) = cruise(&mut Rig::new(vec![position_follower(2, false)]));
    assert!((fe - 0.2).abs() < 2e-4, "uncompensated {fe}");
    let mut rig = Rig::new(vec![position_follower(2, true)]);
    let (fe, _) = cruise(&mut rig);
    assert!(fe.abs() < 2e-4, "compensated {fe}");
    let d = rig.drive_state(0);
    assert_eq!(d.dc_output_shift_r, 2_000_000);
    assert_eq!(d.undefined_inputs_r, 0);
}

#[test]
fn the_encoders_input_time_compensates_its_sampling_delay() {
    let sampled_early = |compensate: bool| {
        let mut c = AxisConfig::linear("X", 1);
        c.io.dc_compensation = compensate;
        c.drive = DriveLink::Simulated(SimDriveConfig {
            input_delay_ns: 500_000,
            ..SimDriveConfig::default()
        });
        c
    };
    // Sampled 0.5 ms early at 100 mm/s: the loop closes on a reading 0.05 mm behind, so the
    // motor runs 0.05 mm ahead of its set-point.
    let (_, ahead) = cruise(&mut Rig::new(vec![sampled_early(false)]));
    assert!((ahead - 0.05).abs() < 2e-4, "uncompensated {ahead}");
    let mut rig = Rig::new(vec![sampled_early(true)]);
    let (_, ahead) = cruise(&mut rig);
    assert!(ahead.abs() < 2e-4, "compensated {ahead}");
    assert_eq!(rig.drive_state(0).dc_input_lag_r, 500_000);
}

#[test]
fn distributed_clock_times_out_of_range_are_counted_and_not_used() {
    let mut c = external("X", 1, DriveMode::Position);
    c.io.dc_compensation = true;
    let mut rig = Rig::new(vec![c]);
    // An external drive that writes no times: the input is "ticks old" and the output time
    // lies in the past; both are refused every tick.
    rig.ticks(5);
    let d = rig.drive_state(0);
    assert_eq!(d.dc_input_lag_r, 0);
    assert_eq!(d.dc_output_shift_r, 0);
    // Valid: input lags of 0, 1 and 2 ms (ticks 0..2, up to two ticks) and tick 0's output
    // time one tick early; refused: the lags of ticks 3 and 4 and the output times of ticks
    // 1..4.
    assert_eq!(d.undefined_inputs_r, 2 + 4);
    // Valid times from here: 0.25 ms lag, 1 tick output shift.
    for tick in 5u32..8 {
        let now = tick * 1_000_000;
        rig.set_enc_in(
            0,
            NcEncoderIn {
                nDcInputTime: (now - 250_000) as i32,
                ..bytemuck::Zeroable::zeroed()
            },
        );
        rig.set_drive_in(
            0,
            NcDriveIn {
                nDcOutputTime: (now + 2_000_000) as i32,
                ..bytemuck::Zeroable::zeroed()
            },
        );
        rig.tick();
    }
    let d = rig.drive_state(0);
    assert_eq!(d.dc_input_lag_r, 250_000);
    assert_eq!(d.dc_output_shift_r, 1_000_000);
    assert_eq!(d.undefined_inputs_r, 6);
}
