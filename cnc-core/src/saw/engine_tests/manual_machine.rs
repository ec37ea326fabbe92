//! The flying saw in the machine tick against two points of the seed (001) the audit found
//! untested: a coupling command whose Velocity, Acceleration, Deceleration or Jerk is 0
//! plans and checks with the slave axis's own machine data (chapter 11: an input not given
//! takes the axis's configured maximum), and the axis image shows the slave states as the
//! seed's numbers 11, 12 and 13 (chapter 9).

use super::{command, machine, phase, set, MASTER, SAW};
use crate::harness::Harness;
use hli::calls::axis::AxisCommandCall;
use hli::calls::saw::SawError;
use hli::calls::saw::{
    sync_mask as m, SawCharacCall, SawGearInCall, SawGearOutCall, SawSyncTarget,
};
use hli::enums::AxisState;

/// The saw axis's machine data, as the saw tests' machine (`super::machine`) gives them.
const AXIS_VELOCITY: f64 = 3000.0;
const AXIS_ACC: f64 = 20000.0;
const AXIS_JERK: f64 = 1e7;

fn gear_in(run: &mut Harness, call: SawGearInCall) -> u32 {
    run.call(SAW as u32, &call).unwrap().error_id
}

fn gear_out(run: &mut Harness) -> u32 {
    run.call(SAW as u32, &SawGearOutCall::default())
        .unwrap()
        .error_id
}

/// One part of MC_ReadFlyingSawCharacteristics (part 1: fields 17-31 at 0-14).
fn charac(run: &mut Harness, part: u32) -> [f64; 16] {
    let reply = run.call(SAW as u32, &SawCharacCall { part }).unwrap();
    assert_eq!(reply.error_id, 0);
    reply.values
}

/// Part 1 places: fSlaveAccMin (17), fSlaveAccMax (26), fSlaveJerkMax (28).
const ACC_MIN: usize = 0;
const ACC_MAX: usize = 9;
const JERK_MAX: usize = 11;

/// Master at +500 mm/s, the saw at +`slave_velocity`, both at constant velocity.
fn moving(slave_velocity: f64) -> Harness {
    let mut run = machine();
    let master = AxisCommandCall::move_velocity(1, [500.0, 10000.0, 10000.0, 1e6]);
    assert_eq!(command(&mut run, MASTER, master), 0);
    let saw = AxisCommandCall::move_velocity(1, [slave_velocity, 10000.0, 10000.0, 1e6]);
    assert_eq!(command(&mut run, SAW, saw), 0);
    run.until(2000, |r| {
        set(r, MASTER).acceleration == 0.0
            && set(r, SAW).acceleration == 0.0
            && set(r, MASTER).velocity == 500.0
            && set(r, SAW).velocity == slave_velocity
    });
    run
}

/// A coupling with Velocity, Acceleration, Deceleration and Jerk all 0 (not given).
fn without_limits(target: SawSyncTarget, ratio: f64, mask: u32) -> SawGearInCall {
    SawGearInCall {
        master: MASTER as u32,
        target: target.raw(),
        ratio_numerator: ratio,
        ratio_denominator: 1,
        mask,
        ..SawGearInCall::default()
    }
}

/// Velocity sync from 250 mm/s with no limits given: the phase is shaped by the axis's
/// 20000 mm/s^2 and 1e7 mm/s^3. To 500 mm/s (dv 250) the acceleration binds (T = 1.5 x 250
/// / 20000 = 18.75 ms, longer than the jerk's sqrt(6 x 250 / 1e7) = 12.2 ms): the phase's
/// acceleration peak is exactly the axis's, and the set-points reach it without passing it.
/// To 100 mm/s the deceleration binds the same way. To 300 mm/s (dv 50) the jerk binds
/// (sqrt(6 x 50 / 1e7) = 5.5 ms > 1.5 x 50 / 20000 = 3.75 ms): the jerk peak is the axis's.
#[test]
fn a_coupling_without_limits_is_shaped_by_the_axis_acceleration_deceleration_and_jerk() {
    // Speeding up: the acceleration.
    let mut run = moving(250.0);
    let call = without_limits(SawSyncTarget::Velocity, 1.0, 0);
    assert_eq!(gear_in(&mut run, call), 0);
    let part = charac(&mut run, 1);
    assert!((part[ACC_MAX] - AXIS_ACC).abs() < 1e-6, "{part:?}");
    let mut peak: f64 = 0.0;
    for _ in 0..200 {
        run.step();
        peak = peak.max(set(&run, SAW).acceleration);
        if phase(&run, SAW) == AxisState::SlaveSynchronous.raw() {
            break;
        }
    }
    assert_eq!(phase(&run, SAW), AxisState::SlaveSynchronous.raw());
    assert!((set(&run, SAW).velocity - 500.0).abs() < 1e-9);
    assert!(
        peak <= AXIS_ACC * (1.0 + 1e-9) && peak > 0.99 * AXIS_ACC,
        "peak set-point acceleration {peak}"
    );

    // Slowing down: the deceleration.
    let mut run = moving(250.0);
    let call = without_limits(SawSyncTarget::Velocity, 0.2, 0);
    assert_eq!(gear_in(&mut run, call), 0);
    let part = charac(&mut run, 1);
    assert!((part[ACC_MIN] + AXIS_ACC).abs() < 1e-6, "{part:?}");

    // A small change: the jerk.
    let mut run = moving(250.0);
    let call = without_limits(SawSyncTarget::Velocity, 0.6, 0);
    assert_eq!(gear_in(&mut run, call), 0);
    let part = charac(&mut run, 1);
    assert!((part[JERK_MAX] - AXIS_JERK).abs() < 1e-3, "{part:?}");
    assert!(part[ACC_MAX] < 0.9 * AXIS_ACC, "{part:?}");
}

/// A limit not given is checked against the axis's machine data. Position sync 12 mm of the
/// slave in 10 mm of master travel from 250 to 500 mm/s (mean slope 1.2, beyond the sync
/// slope: the plain P5) needs about 77800 mm/s^2 speeding up, 52900 mm/s^2 slowing down and
/// 3.75e7 mm/s^3: each above the axis's 20000 / 20000 / 1e7, so each check refuses with 0
/// given and passes with a larger limit given. Velocity sync to 7 x 500 = 3500 mm/s breaks
/// the axis's 3000 mm/s: MAXVELO refuses it with 0 given and passes it with 4000.
#[test]
fn a_limit_not_given_is_checked_against_the_axis_machine_data() {
    let cases: [(u32, SawError, [f64; 4]); 3] = [
        (m::MAXACC, SawError::CheckMaxAcc, [0.0, 1e5, 0.0, 0.0]),
        (m::MAXDEC, SawError::CheckMaxDec, [0.0, 0.0, 1e5, 0.0]),
        (m::MAXJERK, SawError::CheckMaxJerk, [0.0, 0.0, 0.0, 1e8]),
    ];
    for (bit, code, [velocity, acceleration, deceleration, jerk]) in cases {
        let mut run = moving(250.0);
        let (m0, s0) = (set(&run, MASTER).position, set(&run, SAW).position);
        let call = SawGearInCall {
            master_sync_position: m0 + 10.0,
            slave_sync_position: s0 + 12.0,
            ..without_limits(SawSyncTarget::Position, 1.0, bit | m::DETAILEDERRORCODES)
        };
        assert_eq!(gear_in(&mut run, call), code.raw(), "{bit:#x} with 0");
        let given = SawGearInCall {
            velocity,
            acceleration,
            deceleration,
            jerk,
            ..call
        };
        assert_eq!(gear_in(&mut run, given), 0, "{bit:#x} given {given:?}");
    }
    // Sync velocity 500 mm/s above the axis's: ratio (3000 + 500) / 500 = 7.
    let mut run = moving(250.0);
    let fast = without_limits(
        SawSyncTarget::Velocity,
        (AXIS_VELOCITY + 500.0) / 500.0,
        m::MAXVELO | m::DETAILEDERRORCODES,
    );
    assert_eq!(gear_in(&mut run, fast), SawError::CheckMaxVelo.raw());
    let given = SawGearInCall {
        velocity: AXIS_VELOCITY + 1000.0,
        ..fast
    };
    assert_eq!(gear_in(&mut run, given), 0);
}

/// Seed 001, chapter 9: `nAxisState` below 10 for a free axis, 12 while synchronising, 11 in
/// the pre-phase (stopped after a rollback, INSTANTSTOPONROLLBACK), 13 synchronous, and below
/// 10 again after MC_GearOut; the numbers themselves, as the image carries them.
#[test]
fn the_image_shows_the_slave_states_as_the_numbers_11_12_and_13() {
    let mut run = moving(250.0);
    assert!(phase(&run, SAW) < 10, "free: {}", phase(&run, SAW));
    let (m0, s0) = (set(&run, MASTER).position, set(&run, SAW).position);
    let far = SawGearInCall {
        master_sync_position: m0 + 1e5,
        slave_sync_position: s0 + 9e4,
        ..without_limits(SawSyncTarget::Position, 1.0, m::INSTANTSTOPONROLLBACK)
    };
    assert_eq!(gear_in(&mut run, far), 0);
    run.steps(200);
    assert_eq!(phase(&run, SAW), 12);
    // The master runs back over the coupling position: the slave stops in that tick.
    let back = AxisCommandCall::move_velocity(-1, [2000.0, 10000.0, 10000.0, 1e6]);
    assert_eq!(command(&mut run, MASTER, back), 0);
    run.until(20_000, |r| set(r, MASTER).position < m0);
    assert_eq!(phase(&run, SAW), 11);
    assert_eq!(set(&run, SAW).velocity, 0.0);
    for _ in 0..20 {
        run.step();
        assert_eq!(phase(&run, SAW), 11, "stands in the pre-phase");
    }

    let mut run = moving(250.0);
    let call = without_limits(SawSyncTarget::Velocity, 1.0, 0);
    assert_eq!(gear_in(&mut run, call), 0);
    run.step();
    assert_eq!(phase(&run, SAW), 12);
    run.until(1000, |r| phase(r, SAW) == 13);
    assert!((set(&run, SAW).velocity - 500.0).abs() < 1e-9);
    assert_eq!(gear_out(&mut run), 0);
    run.step();
    assert!(phase(&run, SAW) < 10, "free again: {}", phase(&run, SAW));
}
