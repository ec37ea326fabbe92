//! The axis layer against its contract: PTP moves within their limits, halt and stop, the
//! process image (increments, wraps, direction bits, drive modes), following error, I/O faults
//! and refused commands.

use cnc_core::axis::commands::CommandView;
use cnc_core::axis::config::{AxisConfig, DriveLink, DriveMode};
use cnc_core::axis::increments::CounterWidth;
use cnc_core::axis::sim_drive::{Dynamic, SimDriveConfig};
use cnc_core::axis::{AxisSet, Coupling};
use cnc_core::setpoint::Kinematic;
use hli::calls::axis::AxisCommandCall;
use hli::enums::{AxisError, AxisState, CouplingState, DirectionBits};
use hli::layout::{HliAxis, NcEncoderIn};
use hli::views::CncView;
use hli::PlaceExt;
use proptest::prelude::*;

mod drive_image_gaps;
mod drive_inputs;
mod refusals;

const CYCLE: f64 = 0.001;

type Rig = tests::AxisRig;

const LIMITS: [f64; 4] = [500.0, 5000.0, 4000.0, 100_000.0];

#[test]
fn move_absolute_reaches_its_target_exactly_and_reports_done() {
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
    rig.enable(0);
    let id = rig
        .call(0, AxisCommandCall::move_absolute(123.456, LIMITS))
        .unwrap();
    assert_eq!(rig.view(0, id), CommandView::Busy(false));
    rig.until(5_000, |r| r.view(0, id) == CommandView::Done);
    let axis = rig.set.axis(0).unwrap();
    assert_eq!(axis.setpoint().position, 123.456);
    assert!(
        (axis.actual() - 123.456).abs() < 1e-4,
        "actual {}",
        axis.actual()
    );
    let lr = CncView::new(&rig.memory)
        .axis(0)
        .unwrap()
        .field::<hli::layout::HliAxisLrState>(0)
        .read();
    assert_eq!(lr.command_position_acs_r, 1_234_560);
    assert_eq!(lr.axis_state_r, AxisState::Standstill.raw());
}

#[test]
fn move_relative_counts_from_the_set_position() {
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
    rig.enable(0);
    let a = rig
        .call(0, AxisCommandCall::move_absolute(10.0, LIMITS))
        .unwrap();
    rig.until(5_000, |r| r.view(0, a) == CommandView::Done);
    let b = rig
        .call(0, AxisCommandCall::move_relative(-25.0, LIMITS))
        .unwrap();
    rig.until(5_000, |r| r.view(0, b) == CommandView::Done);
    assert_eq!(rig.set_point(0).position, -15.0);
}

/// Checks one tick of a set-point against the limits of a move in direction `sign`.
fn within(k: Kinematic, l: [f64; 4], sign: f64) -> Result<(), String> {
    let eps = 1e-6;
    let [v, acc, dec, jerk] = l;
    let (up, down) = if sign >= 0.0 { (acc, dec) } else { (dec, acc) };
    if k.velocity.abs() > v * (1.0 + eps) {
        return Err(format!("velocity {} above {v}", k.velocity));
    }
    if k.acceleration > up * (1.0 + eps) || k.acceleration < -down * (1.0 + eps) {
        return Err(format!(
            "acceleration {} outside [-{down}, {up}]",
            k.acceleration
        ));
    }
    if k.jerk.abs() > jerk * (1.0 + eps) {
        return Err(format!("jerk {} above {jerk}", k.jerk));
    }
    Ok(())
}

/// A generous tick budget for a move of `distance` under `limits` (a watchdog, not a bound).
fn budget(distance: f64, [v, a, d, j]: [f64; 4]) -> usize {
    let seconds = distance / v + 2.0 * v / a.min(d) + 4.0 * a.max(d) / j + 1.0;
    (2.0 * seconds / CYCLE) as usize
}

fn limits_strategy() -> impl Strategy<Value = [f64; 4]> {
    (
        20.0..1000.0f64,
        50.0..10_000.0f64,
        50.0..10_000.0f64,
        1_000.0..200_000.0f64,
    )
        .prop_map(|(v, a, d, j)| [v, a, d, j])
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// A move from rest never leaves its velocity, acceleration/deceleration and jerk limits,
    /// and lands exactly on the target.
    #[test]
    fn a_move_stays_within_its_limits(target in -900.0..900.0f64, limits in limits_strategy()) {
        let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
        rig.enable(0);
        let id = rig.call(0, AxisCommandCall::move_absolute(target, limits)).unwrap();
        let sign = target.signum();
        for _ in 0..budget(1800.0, limits) {
            rig.tick();
            let k = rig.set_point(0);
            within(k, limits, sign).map_err(TestCaseError::fail)?;
            if rig.view(0, id) == CommandView::Done { break; }
        }
        prop_assert_eq!(rig.view(0, id), CommandView::Done);
        prop_assert_eq!(rig.set_point(0).position, target);
    }

    /// Re-targeting while moving (new targets and new limits at random ticks) keeps the
    /// set-point continuous and within the axis's maximum dynamics, and the last move lands.
    #[test]
    fn retargets_stay_within_the_axis_limits(
        moves in proptest::collection::vec((-900.0..900.0f64, limits_strategy(), 1usize..400), 1..6)
    ) {
        let config = AxisConfig::linear("X", 1);
        let d = config.dynamics;
        let max = [d.velocity, d.acceleration.max(d.deceleration), d.acceleration.max(d.deceleration), d.jerk];
        let mut rig = Rig::new(vec![config]);
        rig.enable(0);
        let mut last = None;
        let mut before = rig.set_point(0);
        for (target, limits, after) in &moves {
            let id = rig.call(0, AxisCommandCall::move_absolute(*target, *limits));
            let id = id.map_err(|e| TestCaseError::fail(format!("{e:?}: axis error {:?} at {:?}", rig.set.axis(0).unwrap().error(), rig.set_point(0))))?;
            last = Some((id, *target));
            for _ in 0..*after {
                rig.tick();
                let k = rig.set_point(0);
                within(k, max, 1.0).map_err(TestCaseError::fail)?;
                // Continuity: no position step beyond what the velocity explains.
                prop_assert!((k.position - before.position).abs() <= max[0] * CYCLE * 1.0001);
                before = k;
            }
        }
        let (id, target) = last.unwrap();
        let slowest = moves.last().unwrap().1;
        // The last move may take over at the speed of an earlier, faster one and brake from it
        // with its own (low) deceleration: that distance and time come on top.
        let fastest = moves.iter().map(|m| m.1[0]).fold(0.0, f64::max);
        let decel = slowest[1].min(slowest[2]);
        let braking = fastest * fastest / (2.0 * decel);
        let extra = (2.0 * fastest / decel / CYCLE) as usize;
        rig.until(budget(3600.0 + braking, slowest) + extra, |r| r.view(0, id) == CommandView::Done);
        prop_assert_eq!(rig.set_point(0).position, target);
    }
}

#[test]
fn halt_brakes_to_standstill_and_aborts_the_velocity_move() {
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
    rig.enable(0);
    let run = rig
        .call(0, AxisCommandCall::move_velocity(1, LIMITS))
        .unwrap();
    rig.until(2_000, |r| r.view(0, run) == CommandView::Busy(true));
    assert_eq!(rig.set_point(0).velocity, 500.0);
    let halt = rig
        .call(0, AxisCommandCall::halt(4000.0, 100_000.0))
        .unwrap();
    assert_eq!(rig.view(0, run), CommandView::Aborted);
    let mut previous = rig.set_point(0).velocity;
    rig.until(2_000, |r| r.view(0, halt) == CommandView::Done);
    for _ in 0..10 {
        rig.tick();
        let v = rig.set_point(0).velocity;
        assert!(v <= previous + 1e-9, "velocity rose while halted");
        previous = v;
    }
    assert_eq!(rig.set_point(0).velocity, 0.0);
    // After a halt the axis takes moves at once.
    assert!(rig
        .call(0, AxisCommandCall::move_absolute(0.0, LIMITS))
        .is_ok());
}

#[test]
fn stop_locks_the_axis_until_released() {
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
    rig.enable(0);
    let run = rig
        .call(0, AxisCommandCall::move_velocity(-1, LIMITS))
        .unwrap();
    rig.ticks(50);
    assert!(rig.set_point(0).velocity < 0.0);
    let stop = rig
        .call(0, AxisCommandCall::stop(4000.0, 100_000.0))
        .unwrap();
    assert_eq!(rig.view(0, run), CommandView::Aborted);
    assert_eq!(
        rig.call(0, AxisCommandCall::move_absolute(0.0, LIMITS)),
        Err(AxisError::StopActive)
    );
    assert_eq!(
        rig.call(0, AxisCommandCall::halt(4000.0, 100_000.0)),
        Err(AxisError::StopActive)
    );
    rig.until(2_000, |r| r.view(0, stop) == CommandView::Busy(true));
    assert_eq!(rig.set_point(0).velocity, 0.0);
    rig.ticks(20);
    assert_eq!(
        rig.view(0, stop),
        CommandView::Busy(true),
        "held while Execute stays high"
    );
    rig.call(0, AxisCommandCall::stop_release()).unwrap();
    rig.tick();
    assert_eq!(rig.view(0, stop), CommandView::Done);
    assert!(rig
        .call(0, AxisCommandCall::move_absolute(0.0, LIMITS))
        .is_ok());
}

#[test]
fn direction_bits_follow_the_set_point_and_the_total_output() {
    let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
    rig.enable(0);
    rig.tick();
    assert_eq!(rig.drive_out(0).nCtrl2, DirectionBits::Stop.raw());
    assert_eq!(rig.drive_out(0).nCtrl3, DirectionBits::Stop.raw());
    let a = rig
        .call(0, AxisCommandCall::move_absolute(50.0, LIMITS))
        .unwrap();
    rig.ticks(30);
    assert_eq!(rig.drive_out(0).nCtrl2, 0x42);
    assert_eq!(rig.drive_out(0).nCtrl3, 0x42);
    assert!(rig.drive_out(0).nOutData1 > 0);
    rig.until(5_000, |r| r.view(0, a) == CommandView::Done);
    let b = rig
        .call(0, AxisCommandCall::move_absolute(-50.0, LIMITS))
        .unwrap();
    rig.ticks(30);
    assert_eq!(rig.drive_out(0).nCtrl2, 0x41);
    assert_eq!(rig.drive_out(0).nCtrl3, 0x41);
    assert!(rig.drive_out(0).nOutData1 < 0);
    assert!(
        rig.drive_out(0).nOutData3 != 0,
        "set acceleration is output"
    );
    rig.until(5_000, |r| r.view(0, b) == CommandView::Done);
    rig.tick();
    assert_eq!(rig.drive_out(0).nCtrl2, 0x80);
}

/// `nCtrl2` is the set-point generator's direction alone, `nCtrl3` the direction of the total
/// output (generator plus position controller): an axis standing still at 0 whose encoder
/// reads 0.1 mm ahead has no set-point direction (Stop, 0x80) but a controller output back
/// towards it (minus, 0x41; Kv 50 / s x 0.1 mm = 5 mm/s); 0.1 mm behind, plus (0x42).
#[test]
fn the_total_outputs_direction_is_its_own_where_it_differs_from_the_set_points() {
    for (ahead, total) in [(1000, 0x41), (-1000, 0x42)] {
        let mut config = AxisConfig::linear("X", 1);
        config.drive = DriveLink::External;
        let mut rig = Rig::new(vec![config]);
        rig.enable(0);
        rig.tick();
        let enc = CncView::new(&rig.memory)
            .axis(0)
            .unwrap()
            .field::<NcEncoderIn>(core::mem::offset_of!(HliAxis, enc_in));
        enc.write(&NcEncoderIn {
            nInData1: ahead,
            ..bytemuck::Zeroable::zeroed()
        });
        rig.ticks(2);
        let out = rig.drive_out(0);
        assert_eq!(out.nCtrl2, DirectionBits::Stop.raw(), "{ahead}");
        assert_eq!(out.nCtrl3, total, "{ahead}");
        assert_eq!(
            out.nOutData1.signum(),
            -ahead.signum(),
            "{ahead}: {}",
            out.nOutData1
        );
    }
}

#[test]
fn universal_drive_outputs_signed_velocity_and_its_magnitude() {
    let mut config = AxisConfig::linear("X", 1);
    config.drive_mode = DriveMode::Universal;
    let mut rig = Rig::new(vec![config]);
    rig.enable(0);
    rig.call(0, AxisCommandCall::move_velocity(-1, LIMITS))
        .unwrap();
    rig.ticks(200);
    let out = rig.drive_out(0);
    assert!(out.nOutData1 < 0);
    assert_eq!(out.nOutData2, -out.nOutData1);
    assert_eq!(
        out.nOutData1, -5_000_000,
        "500 mm/s at 10000 increments per mm/s"
    );
}

/// Runs a 16- or 32-bit encoder through many wraps forth and back; the actual position follows
/// the set-point throughout and the encoder output mirrors the input.
fn wraps(width: CounterWidth, increments_per_unit: f64, distance: f64, mode: DriveMode) {
    let mut config = AxisConfig::linear("X", 1);
    config.encoder_width = width;
    config.increments_per_unit = increments_per_unit;
    config.drive_mode = mode;
    config.soft_limits = Some([-5000.0, 5000.0]);
    let wrap_units = match width {
        CounterWidth::Bits16 => 65_536.0,
        CounterWidth::Bits32 => 4_294_967_296.0,
    } / increments_per_unit;
    assert!(
        distance / wrap_units >= 4.0,
        "the test must cross several wraps"
    );
    let mut rig = Rig::new(vec![config]);
    rig.enable(0);
    let limits = [1000.0, 10_000.0, 10_000.0, 200_000.0];
    for target in [distance, -distance, 0.0] {
        let id = rig
            .call(0, AxisCommandCall::move_absolute(target, limits))
            .unwrap();
        let mut worst: f64 = 0.0;
        rig.until(100_000, |r| {
            let axis = r.set.axis(0).unwrap();
            worst = worst.max(axis.following_error().abs());
            let enc = r.enc_in(0);
            let raw_ok = match width {
                CounterWidth::Bits16 => (0..=65_535).contains(&enc.nInData1),
                CounterWidth::Bits32 => true,
            };
            assert!(raw_ok);
            r.view(0, id) == CommandView::Done
        });
        rig.ticks(50);
        let axis = rig.set.axis(0).unwrap();
        assert!(
            (axis.actual() - target).abs() <= 1e-5,
            "{width:?} {mode:?}: at {} for {target}",
            axis.actual()
        );
        assert!(
            worst < 1.0,
            "following error {worst} (the controller lost the wraps)"
        );
        assert_eq!(axis.error(), None);
    }
}

#[test]
fn sixteen_bit_encoder_wraps_many_times_in_both_directions() {
    wraps(CounterWidth::Bits16, 10_000.0, 100.0, DriveMode::Velocity);
    wraps(CounterWidth::Bits16, 10_000.0, 100.0, DriveMode::Position);
}

#[test]
fn thirty_two_bit_encoder_wraps_many_times_in_both_directions() {
    wraps(CounterWidth::Bits32, 1.0e7, 2000.0, DriveMode::Velocity);
    wraps(CounterWidth::Bits32, 1.0e7, 2000.0, DriveMode::Position);
}

fn lagging(limit: f64) -> AxisConfig {
    let mut config = AxisConfig::linear("X", 1);
    config.feed_forward = 0.0;
    config.position_gain = 20.0;
    config.following_error_limit = limit;
    config.drive = DriveLink::Simulated(SimDriveConfig {
        dynamic: Dynamic::Pt1 { t1_s: 0.02 },
        dead_time_ticks: 3,
        start_position: 0.0,
        ..SimDriveConfig::default()
    });
    config
}

#[test]
fn a_lagging_drive_builds_following_error_and_a_tight_limit_stops_the_axis() {
    // Generous limit: the move completes with a following error about v / Kv.
    let mut rig = Rig::new(vec![lagging(100.0)]);
    rig.enable(0);
    let id = rig
        .call(0, AxisCommandCall::move_absolute(400.0, LIMITS))
        .unwrap();
    let mut worst: f64 = 0.0;
    rig.until(20_000, |r| {
        worst = worst.max(r.set.axis(0).unwrap().following_error().abs());
        r.view(0, id) == CommandView::Done
    });
    let steady = 500.0 / 20.0; // v / Kv
    assert!(
        worst > 0.8 * steady && worst < 1.5 * steady,
        "following error {worst}, expected about {steady}"
    );
    rig.ticks(2_000);
    assert!((rig.set.axis(0).unwrap().actual() - 400.0).abs() < 0.01);

    // Tight limit: the axis stops with the following-error code on axis and command.
    let mut rig = Rig::new(vec![lagging(5.0)]);
    rig.enable(0);
    let id = rig
        .call(0, AxisCommandCall::move_absolute(400.0, LIMITS))
        .unwrap();
    rig.until(5_000, |r| r.set.axis(0).unwrap().error().is_some());
    assert_eq!(
        rig.set.axis(0).unwrap().error(),
        Some(AxisError::FollowingError)
    );
    assert_eq!(rig.view(0, id), CommandView::Error(0x4240));
    rig.tick();
    assert_eq!(rig.drive_out(0).nOutData1, 0, "no output after the fault");
    assert_eq!(rig.drive_out(0).nCtrl3, DirectionBits::Stop.raw());
    assert_eq!(
        rig.call(0, AxisCommandCall::move_absolute(0.0, LIMITS)),
        Err(AxisError::AxisInError)
    );
    rig.call(0, AxisCommandCall::reset()).unwrap();
    assert!(rig
        .call(
            0,
            AxisCommandCall::move_absolute(0.0, [10.0, 100.0, 100.0, 1000.0])
        )
        .is_ok());
}

#[test]
fn io_invalid_stops_the_axis_with_an_error_until_reset() {
    for encoder in [true, false] {
        let mut rig = Rig::new(vec![AxisConfig::linear("X", 1)]);
        rig.enable(0);
        let id = rig
            .call(0, AxisCommandCall::move_velocity(1, LIMITS))
            .unwrap();
        rig.ticks(100);
        let drive = rig.set.drive_mut(0).unwrap();
        if encoder {
            drive.encoder_io_invalid = true;
        } else {
            drive.drive_io_invalid = true;
        }
        rig.ticks(2);
        let expected = if encoder {
            AxisError::EncoderIoInvalid
        } else {
            AxisError::DriveIoInvalid
        };
        assert_eq!(rig.set.axis(0).unwrap().error(), Some(expected));
        assert_eq!(rig.view(0, id), CommandView::Error(expected.raw()));
        rig.tick();
        assert_eq!(rig.drive_out(0).nOutData1, 0);
        assert_eq!(
            rig.call(0, AxisCommandCall::reset()),
            Err(AxisError::ResetRefused)
        );
        let drive = rig.set.drive_mut(0).unwrap();
        drive.encoder_io_invalid = false;
        drive.drive_io_invalid = false;
        rig.ticks(2);
        rig.call(0, AxisCommandCall::reset()).unwrap();
        assert_eq!(rig.set.axis(0).unwrap().error(), None);
    }
}

#[test]
fn a_status_byte_that_is_neither_valid_nor_invalid_counts_as_invalid() {
    let mut config = AxisConfig::linear("X", 1);
    config.drive = DriveLink::External;
    let mut rig = Rig::new(vec![config]);
    rig.enable(0);
    let enc = CncView::new(&rig.memory)
        .axis(0)
        .unwrap()
        .field::<NcEncoderIn>(core::mem::offset_of!(HliAxis, enc_in));
    enc.write(&NcEncoderIn {
        nStatus4: 7,
        ..bytemuck::Zeroable::zeroed()
    });
    rig.tick();
    assert_eq!(
        rig.set.axis(0).unwrap().error(),
        Some(AxisError::EncoderIoInvalid)
    );
}

/// An encoder-error bit in `enc_in.nStatus1` (`io.encoder_error`, coding configurable): while
/// reported, an enabled axis stops with `EncoderError` (0x4247), outputs nothing and refuses a
/// reset; cleared, the reset is taken. Active low: a cleared bit is the error. A mask of 0 and
/// the terminal probe's status byte are refused with the key.
#[test]
fn an_encoder_error_bit_faults_the_axis_until_it_clears() {
    use cnc_core::axis::config::{EncoderErrorBit, ProbeInterface};
    for (active_low, error, fine) in [(false, 0x10u8, 0x00u8), (true, 0x00, 0x01)] {
        let mut config = AxisConfig::linear("X", 1);
        config.drive = DriveLink::External;
        let mask = if active_low { 0x01 } else { 0x10 };
        config.io.encoder_error = Some(EncoderErrorBit { mask, active_low });
        let mut rig = Rig::new(vec![config]);
        let status = |rig: &Rig, s: u8| {
            rig.set_enc_in(
                0,
                NcEncoderIn {
                    nStatus1: s,
                    ..bytemuck::Zeroable::zeroed()
                },
            )
        };
        status(&rig, fine);
        rig.enable(0);
        rig.ticks(2);
        assert_eq!(rig.set.axis(0).unwrap().error(), None, "{active_low}");
        status(&rig, error);
        rig.ticks(2);
        assert_eq!(
            rig.set.axis(0).unwrap().error(),
            Some(AxisError::EncoderError),
            "{active_low}"
        );
        assert_eq!(AxisError::EncoderError.raw(), 0x4247);
        assert_eq!(rig.drive_out(0).nOutData1, 0);
        assert_eq!(rig.drive_out(0).nCtrl3, DirectionBits::Stop.raw());
        assert_eq!(
            rig.call(0, AxisCommandCall::reset()),
            Err(AxisError::ResetRefused)
        );
        status(&rig, fine);
        rig.ticks(2);
        rig.call(0, AxisCommandCall::reset()).unwrap();
        assert_eq!(rig.set.axis(0).unwrap().error(), None);
    }
    let mut config = AxisConfig::linear("X", 1);
    config.io.encoder_error = Some(EncoderErrorBit {
        mask: 0,
        active_low: false,
    });
    let e = config.validate().unwrap_err();
    assert_eq!(e.field, "io.encoder_error.mask");
    config.io.encoder_error = Some(EncoderErrorBit {
        mask: 0x10,
        active_low: false,
    });
    config.io.probe = ProbeInterface::Terminal;
    assert_eq!(config.validate().unwrap_err().field, "io.encoder_error");
}

/// A drive the fixed codings do not know, linked signal by signal (`io.map`): its encoder
/// puts a 32-bit position at byte 4 and an "invalid" flag at bit 7 of byte 0; it takes a
/// 16-bit velocity in units of 100 increments at byte 0 and its enable at bit 16. The axis
/// reads its position from there, faults on the flag, and writes its outputs in those bits.
#[test]
fn a_drive_mapped_signal_by_signal_is_read_and_written_in_its_own_bytes() {
    let toml = r#"map = [
        { signal = "enc_in.nInData1", bit = 32, width = 32, signed = true },
        { signal = "enc_in.nStatus4", bit = 7, width = 1 },
        { signal = "drive_out.nOutData1", bit = 0, width = 16, signed = true, scale = 100.0 },
        { signal = "drive_out.nCtrl1", bit = 16, width = 1 },
    ]"#;
    let mut config = AxisConfig::linear("X", 1);
    config.drive = DriveLink::External;
    config.io = toml::from_str(toml).unwrap();
    config.validate().unwrap();
    let scale = config.increments_per_unit;
    let mut rig = Rig::new(vec![config]);
    let hardware = |position: i32, invalid: bool| {
        let mut raw: NcEncoderIn = bytemuck::Zeroable::zeroed();
        let bytes = bytemuck::bytes_of_mut(&mut raw);
        bytes[0] = u8::from(invalid) << 7;
        bytes[4..8].copy_from_slice(&position.to_le_bytes());
        raw
    };
    rig.set_enc_in(0, hardware(50_000, false));
    rig.enable(0);
    rig.ticks(3);
    assert_eq!(rig.set.axis(0).unwrap().actual(), 50_000.0 / scale);
    let raw = rig.drive_out(0);
    let bytes = bytemuck::bytes_of(&raw);
    assert_eq!(bytes[2] & 1, 1, "enabled: bit 16");
    // A velocity move at 20 mm/s = 200,000 increments/s: 2000 in units of 100.
    let slow = [20.0, 5000.0, 4000.0, 100_000.0];
    rig.call(0, AxisCommandCall::move_velocity(1, slow))
        .unwrap();
    let mut position = 50_000i32;
    let mut last = 0;
    for _ in 0..300 {
        rig.tick();
        let raw = rig.drive_out(0);
        let bytes = bytemuck::bytes_of(&raw);
        last = i16::from_le_bytes([bytes[0], bytes[1]]);
        assert!(
            bytes[4..].iter().all(|b| *b == 0),
            "nothing outside the mapped bits"
        );
        // The drive follows: the encoder counts what it was told, a tick's worth.
        position += i32::from(last) * 100 / 1000;
        rig.set_enc_in(0, hardware(position, false));
    }
    assert!((1990..=2010).contains(&last), "at speed: {last}");
    rig.tick();
    let actual = rig.set.axis(0).unwrap().actual();
    assert!(
        (actual - f64::from(position) / scale).abs() < 0.01,
        "{actual} vs {position}"
    );
    rig.set_enc_in(0, hardware(position, true));
    rig.ticks(2);
    assert_eq!(
        rig.set.axis(0).unwrap().error(),
        Some(AxisError::EncoderIoInvalid)
    );
}

/// A map is an external drive's only, and its encoder counter is the configured one.
#[test]
fn a_map_of_a_simulated_drive_or_a_foreign_counter_is_refused() {
    let mut config = AxisConfig::linear("X", 1);
    config.io =
        toml::from_str(r#"map = [{ signal = "drive_out.nCtrl1", bit = 0, width = 1 }]"#).unwrap();
    assert_eq!(config.validate().unwrap_err().field, "io.map");
    config.drive = DriveLink::External;
    config.validate().unwrap();
    config.io =
        toml::from_str(r#"map = [{ signal = "enc_in.nInData1", bit = 0, width = 24 }]"#).unwrap();
    let e = config.validate().unwrap_err();
    assert_eq!((e.field, e.value), ("io.map", 24.0));
}

/// An encoder master's actual velocity and acceleration (seed 001: "carefully filtered", or
/// the acceleration switched off): an encoder at a constant 123.4567 mm/s in 0.1 um
/// increments reads 1234 or 1235 increments a tick, so the raw acceleration jumps by 100
/// mm/s^2; `io.actual_filter_s` = 20 ms takes it below 10 and keeps the velocity; with
/// `io.actual_acceleration` off it is 0.
#[test]
fn an_encoders_actual_values_are_filtered_or_the_acceleration_is_off() {
    let run = |filter_s: f64, acceleration: bool| -> (f64, f64) {
        let mut config = AxisConfig::linear("X", 1);
        config.drive = DriveLink::External;
        config.io.actual_filter_s = filter_s;
        config.io.actual_acceleration = acceleration;
        config.validate().unwrap();
        let mut rig = Rig::new(vec![config]);
        let (mut worst, mut velocity) = (0.0f64, 0.0);
        for tick in 0..400 {
            let counts = (f64::from(tick) * 1234.567).round() as i32;
            rig.set_enc_in(
                0,
                NcEncoderIn {
                    nInData1: counts,
                    ..bytemuck::Zeroable::zeroed()
                },
            );
            rig.tick();
            let k = rig.set.axis(0).unwrap().actual_kinematic();
            if tick > 200 {
                worst = worst.max(k.acceleration.abs());
                velocity = k.velocity;
            }
        }
        (worst, velocity)
    };
    let (raw, v) = run(0.0, true);
    assert!(raw >= 50.0, "{raw}");
    assert!((v - 123.4567).abs() < 0.1, "{v}");
    let (filtered, v) = run(0.02, true);
    assert!(filtered < 10.0, "{filtered}");
    assert!((v - 123.4567).abs() < 0.1, "{v}");
    assert_eq!(run(0.0, false).0, 0.0);
    let mut config = AxisConfig::linear("X", 1);
    config.io.actual_filter_s = -1.0;
    assert_eq!(config.validate().unwrap_err().field, "io.actual_filter_s");
}
