//! Touch probes through the encoder process image (seed 004: `nInData2..6`, `nStatus1`,
//! `nStatus5..8`, `nCtrl1`, `nCtrl5/6`), on each of the three interfaces: the recorded
//! position is the sensor's edge to one increment, where a tick-sampled position would miss it
//! by up to a tick's travel; windows, a probe armed twice, aborts, stale latches, undefined
//! status bits and lost encoder data. Also the encoder's register (`nCtrl2`/`nStatus2`): the
//! absolute position read at start-up and MC_SetPosition's counter set; and the torque
//! set-point in `drive_out.nOutData3`.

use cnc_core::axis::config::{AxisConfig, DriveLink, ProbeInterface};
use cnc_core::axis::sim_drive::SimDriveConfig;
use hli::calls::axis::AxisCommandCall;
use hli::calls::probe::{ProbeAbortCall, ProbeArmCall};
use hli::enums::{AxisError, ProbeEdge, ProbeState};
use hli::layout::{HliAxis, HliAxisDriveState, HliAxisProbe, NcEncoderIn, NcEncoderOut};
use hli::views::CncView;
use hli::PlaceExt;

/// One increment at 10000 per mm.
const INCREMENT: f64 = 1e-4;

/// The kit's axis rig with one axis, and the probe's own accessors.
struct Rig(tests::AxisRig);

impl core::ops::Deref for Rig {
    type Target = tests::AxisRig;
    fn deref(&self) -> &tests::AxisRig {
        &self.0
    }
}

impl core::ops::DerefMut for Rig {
    fn deref_mut(&mut self) -> &mut tests::AxisRig {
        &mut self.0
    }
}

impl Rig {
    fn new(config: AxisConfig) -> Self {
        Rig(tests::AxisRig::powered(config))
    }
    fn unpowered(config: AxisConfig) -> Self {
        Rig(tests::AxisRig::new(vec![config]))
    }
    fn place(&self) -> hli::Place<'_, HliAxis> {
        CncView::new(&self.memory).axis(0).unwrap()
    }
    fn probe(&self, k: usize) -> HliAxisProbe {
        self.place()
            .field::<HliAxisDriveState>(core::mem::offset_of!(HliAxis, drive_state))
            .read()
            .probe_r[k]
    }
    fn undefined(&self) -> u32 {
        self.place()
            .field::<HliAxisDriveState>(core::mem::offset_of!(HliAxis, drive_state))
            .read()
            .undefined_inputs_r
    }
    fn enc_out(&self) -> NcEncoderOut {
        self.place()
            .field::<NcEncoderOut>(core::mem::offset_of!(HliAxis, enc_out))
            .read()
    }
    fn set_enc_in(&self, value: NcEncoderIn) {
        self.place()
            .field::<NcEncoderIn>(core::mem::offset_of!(HliAxis, enc_in))
            .write(&value)
    }
    fn arm(
        &mut self,
        probe: u32,
        edge: ProbeEdge,
        window: Option<[f64; 2]>,
    ) -> Result<u32, AxisError> {
        let [first_position, last_position] = window.unwrap_or([0.0, 0.0]);
        self.set.axis_mut(0).unwrap().arm_probe(&ProbeArmCall {
            probe,
            edge: edge.raw(),
            window_only: u32::from(window.is_some()),
            reserved: 0,
            first_position,
            last_position,
        })
    }
    fn abort(&mut self, probe: u32) -> Result<u32, AxisError> {
        self.set
            .axis_mut(0)
            .unwrap()
            .abort_probe(&ProbeAbortCall { probe, reserved: 0 })
    }
    fn move_to(&mut self, target: f64) {
        self.set
            .axis_mut(0)
            .unwrap()
            .command(&AxisCommandCall::move_absolute(
                target,
                [100.0, 2000.0, 2000.0, 50_000.0],
            ))
            .unwrap();
    }
    /// Ticks until the axis stands at `target`, returning the tick-sampled positions.
    fn run_to(&mut self, target: f64) -> Vec<f64> {
        self.move_to(target);
        let mut seen = vec![];
        for _ in 0..5000 {
            self.tick();
            let axis = self.set.axis(0).unwrap();
            seen.push(axis.actual());
            if (axis.actual() - target).abs() < INCREMENT && axis.setpoint().velocity == 0.0 {
                return seen;
            }
        }
        panic!("watchdog: the axis did not reach {target}");
    }
}

fn probed(interface: ProbeInterface, windows: [Option<[f64; 2]>; 2]) -> AxisConfig {
    let mut c = AxisConfig::linear("X", 1);
    c.io.probe = interface;
    c.drive = DriveLink::Simulated(SimDriveConfig {
        probe_windows: windows,
        ..SimDriveConfig::default()
    });
    c
}

/// The tick-sampled position nearest to `edge`: what a probe evaluated per tick could at best
/// have recorded.
fn nearest_sample(seen: &[f64], edge: f64) -> f64 {
    seen.iter()
        .map(|p| (p - edge).abs())
        .fold(f64::MAX, f64::min)
}

#[test]
fn each_interface_records_the_edges_exact_position() {
    for interface in [
        ProbeInterface::Terminal,
        ProbeInterface::Canopen,
        ProbeInterface::Sercos,
    ] {
        let two = interface != ProbeInterface::Terminal;
        let second = two.then_some([40.0, 45.0]);
        let mut rig = Rig::new(probed(interface, [Some([20.0123, 30.00007]), second]));
        let id = rig.arm(1, ProbeEdge::Positive, None).unwrap();
        assert_eq!(id, 1);
        if two {
            rig.arm(2, ProbeEdge::Negative, None).unwrap();
        }
        let seen = rig.run_to(60.0);
        let p1 = rig.probe(0);
        assert_eq!(p1.state_r, ProbeState::Recorded.raw(), "{interface:?}");
        assert_eq!(p1.arm_id_r, id);
        assert_eq!(p1.edge_r, ProbeEdge::Positive.raw());
        assert!(
            (p1.recorded_position_r - 20.0123).abs() <= INCREMENT / 2.0,
            "{interface:?}: {}",
            p1.recorded_position_r
        );
        // At 100 mm/s a tick travels 0.1 mm: sampling per tick would have missed the edge.
        assert!(nearest_sample(&seen, 20.0123) > 10.0 * INCREMENT);
        if two {
            let p2 = rig.probe(1);
            assert_eq!(p2.state_r, ProbeState::Recorded.raw(), "{interface:?}");
            assert!((p2.recorded_position_r - 45.0).abs() <= INCREMENT / 2.0);
        }
        // The falling edge of probe 1, on the way back (the sensor goes off at its lower end).
        rig.arm(1, ProbeEdge::Negative, None).unwrap();
        rig.run_to(0.0);
        let p1 = rig.probe(0);
        assert_eq!(p1.arm_id_r, 2);
        assert_eq!(p1.state_r, ProbeState::Recorded.raw());
        assert!(
            (p1.recorded_position_r - 20.0123).abs() <= INCREMENT / 2.0,
            "{interface:?} back: {}",
            p1.recorded_position_r
        );
        // Recorded: the probe's enable is off again.
        let out = rig.enc_out();
        assert_eq!((out.nCtrl1, out.nCtrl5, out.nCtrl6), (0, 0, 0));
    }
}

#[test]
fn the_control_bytes_follow_the_interfaces_coding() {
    let cases = [
        (ProbeInterface::Terminal, ProbeEdge::Positive, (0x02, 0, 0)),
        (ProbeInterface::Terminal, ProbeEdge::Negative, (0x08, 0, 0)),
        (ProbeInterface::Canopen, ProbeEdge::Positive, (0, 0x11, 0)),
        (ProbeInterface::Canopen, ProbeEdge::Negative, (0, 0x21, 0)),
        (ProbeInterface::Sercos, ProbeEdge::Negative, (0, 0x01, 0)),
    ];
    for (interface, edge, expected) in cases {
        let mut rig = Rig::new(probed(interface, [None, None]));
        rig.arm(1, edge, None).unwrap();
        // The first tick checks the status is clear; the enable goes on with it.
        rig.tick();
        let out = rig.enc_out();
        assert_eq!(
            (out.nCtrl1, out.nCtrl5, out.nCtrl6),
            expected,
            "{interface:?}"
        );
        rig.abort(1).unwrap();
        rig.tick();
        let out = rig.enc_out();
        assert_eq!((out.nCtrl1, out.nCtrl5, out.nCtrl6), (0, 0, 0));
    }
}

#[test]
fn a_window_skips_edges_outside_it() {
    let mut rig = Rig::new(probed(ProbeInterface::Canopen, [Some([20.0, 30.0]), None]));
    // The rising edge at 20 lies outside [25, 35]: not recorded, the probe stays armed.
    rig.arm(1, ProbeEdge::Positive, Some([25.0, 35.0])).unwrap();
    rig.run_to(50.0);
    assert_eq!(rig.probe(0).state_r, ProbeState::Armed.raw());
    // Moving down the sensor switches on at 30, inside the window.
    rig.run_to(0.0);
    let p = rig.probe(0);
    assert_eq!(p.state_r, ProbeState::Recorded.raw());
    assert!((p.recorded_position_r - 30.0).abs() <= INCREMENT / 2.0);
}

#[test]
fn a_probe_armed_twice_is_refused_and_the_first_arming_records() {
    let mut rig = Rig::new(probed(ProbeInterface::Sercos, [Some([10.0, 12.0]), None]));
    let id = rig.arm(1, ProbeEdge::Positive, None).unwrap();
    assert_eq!(
        rig.arm(1, ProbeEdge::Negative, None),
        Err(AxisError::ProbeAlreadyArmed)
    );
    rig.run_to(20.0);
    let p = rig.probe(0);
    assert_eq!((p.state_r, p.arm_id_r), (ProbeState::Recorded.raw(), id));
    assert_eq!(p.edge_r, ProbeEdge::Positive.raw());
    assert!((p.recorded_position_r - 10.0).abs() <= INCREMENT / 2.0);
}

#[test]
fn bad_arming_calls_are_refused_with_their_codes() {
    let mut terminal = Rig::new(probed(ProbeInterface::Terminal, [None, None]));
    assert_eq!(
        terminal.arm(2, ProbeEdge::Positive, None),
        Err(AxisError::ProbeNotAvailable)
    );
    assert_eq!(
        terminal.arm(3, ProbeEdge::Positive, None),
        Err(AxisError::InvalidProbeParameter)
    );
    assert_eq!(
        terminal.arm(1, ProbeEdge::Positive, Some([5.0, 1.0])),
        Err(AxisError::InvalidProbeParameter)
    );
    assert_eq!(
        terminal.arm(1, ProbeEdge::Positive, Some([f64::NAN, 1.0])),
        Err(AxisError::InvalidProbeParameter)
    );
    let bad_edge = terminal.set.axis_mut(0).unwrap().arm_probe(&ProbeArmCall {
        probe: 1,
        edge: 0,
        ..ProbeArmCall::default()
    });
    assert_eq!(bad_edge, Err(AxisError::InvalidProbeParameter));
    assert_eq!(terminal.abort(1), Err(AxisError::ProbeNotArmed));
    let mut none = Rig::new(probed(ProbeInterface::None, [None, None]));
    assert_eq!(
        none.arm(1, ProbeEdge::Positive, None),
        Err(AxisError::ProbeNotAvailable)
    );
    // Nothing of it armed anything.
    assert_eq!(terminal.probe(0).state_r, ProbeState::Idle.raw());
}

#[test]
fn an_aborted_probe_records_nothing() {
    let mut rig = Rig::new(probed(ProbeInterface::Canopen, [Some([10.0, 12.0]), None]));
    let id = rig.arm(1, ProbeEdge::Positive, None).unwrap();
    rig.tick();
    assert_eq!(rig.abort(1), Ok(id));
    rig.run_to(20.0);
    let p = rig.probe(0);
    assert_eq!(p.state_r, ProbeState::Aborted.raw());
    assert_eq!(p.recorded_position_r, 0.0);
}

fn external_canopen() -> AxisConfig {
    let mut c = AxisConfig::linear("X", 1);
    c.io.probe = ProbeInterface::Canopen;
    c.drive = DriveLink::External;
    c
}

#[test]
fn a_latch_left_from_before_the_arming_is_never_taken() {
    let mut rig = Rig::new(external_canopen());
    let stale = NcEncoderIn {
        nInData1: 50_000,
        nInData3: 12_345,
        nStatus5: 0x03, // enabled, positive edge stored: from an earlier arming
        ..bytemuck::Zeroable::zeroed()
    };
    rig.set_enc_in(stale);
    rig.arm(1, ProbeEdge::Positive, None).unwrap();
    for _ in 0..5 {
        rig.tick();
        // The enable stays off until the drive has cleared its status.
        assert_eq!(rig.enc_out().nCtrl5, 0);
        assert_eq!(rig.probe(0).state_r, ProbeState::Armed.raw());
    }
    rig.set_enc_in(NcEncoderIn {
        nStatus5: 0,
        ..stale
    });
    rig.tick();
    assert_eq!(rig.enc_out().nCtrl5, 0x11);
    // A fresh latch: 60000 increments, 1 mm past the reading of 50000.
    rig.set_enc_in(NcEncoderIn {
        nStatus5: 0x03,
        nInData3: 60_000,
        ..stale
    });
    rig.tick();
    let p = rig.probe(0);
    assert_eq!(p.state_r, ProbeState::Recorded.raw());
    assert!((p.recorded_position_r - 6.0).abs() < 1e-12);
}

#[test]
fn a_latched_count_is_unwrapped_against_the_encoders_count() {
    let mut c = external_canopen();
    c.encoder_width = cnc_core::axis::increments::CounterWidth::Bits16;
    let mut rig = Rig::new(c);
    // The 16-bit counter stands at 65000 after a wrap from 0 downwards: -536 increments.
    rig.set_enc_in(NcEncoderIn {
        nInData1: 0,
        ..bytemuck::Zeroable::zeroed()
    });
    rig.tick();
    rig.set_enc_in(NcEncoderIn {
        nInData1: 65_000,
        ..bytemuck::Zeroable::zeroed()
    });
    rig.arm(1, ProbeEdge::Positive, None).unwrap();
    rig.tick();
    // The latch at 100 lies 636 increments above 65000, across the wrap.
    rig.set_enc_in(NcEncoderIn {
        nInData1: 65_000,
        nInData3: 100,
        nStatus5: 0x03,
        ..bytemuck::Zeroable::zeroed()
    });
    rig.tick();
    let p = rig.probe(0);
    assert_eq!(p.state_r, ProbeState::Recorded.raw());
    assert!(
        (p.recorded_position_r - 0.01).abs() < 1e-12,
        "{}",
        p.recorded_position_r
    );
}

#[test]
fn undefined_status_bits_are_counted_and_never_recorded() {
    let mut rig = Rig::new(external_canopen());
    rig.arm(1, ProbeEdge::Positive, None).unwrap();
    rig.tick();
    // Bit 3 of the CANopen probe status is reserved.
    rig.set_enc_in(NcEncoderIn {
        nStatus5: 0x0B,
        nInData3: 777,
        ..bytemuck::Zeroable::zeroed()
    });
    let before = rig.undefined();
    for _ in 0..4 {
        rig.tick();
    }
    assert_eq!(rig.undefined() - before, 4);
    assert_eq!(rig.probe(0).state_r, ProbeState::Armed.raw());
    // SERCOS: a latched flag is 0 or 1.
    let mut c = external_canopen();
    c.io.probe = ProbeInterface::Sercos;
    let mut rig = Rig::new(c);
    rig.arm(1, ProbeEdge::Positive, None).unwrap();
    rig.set_enc_in(NcEncoderIn {
        nStatus5: 2,
        ..bytemuck::Zeroable::zeroed()
    });
    rig.tick();
    assert_eq!(rig.undefined(), 1);
    assert_eq!(rig.probe(0).state_r, ProbeState::Armed.raw());
}

#[test]
fn lost_encoder_data_ends_an_armed_probe_with_the_cause() {
    let mut rig = Rig::new(external_canopen());
    rig.arm(1, ProbeEdge::Positive, None).unwrap();
    rig.tick();
    rig.set_enc_in(NcEncoderIn {
        nStatus4: 1,
        ..bytemuck::Zeroable::zeroed()
    });
    rig.tick();
    let p = rig.probe(0);
    assert_eq!(p.state_r, ProbeState::Aborted.raw());
    assert_eq!(p.error_id_r, AxisError::EncoderIoInvalid.raw());
}

/// Probe 2 on its rising edge (CANopen and SERCOS have two probes): its enable in `nCtrl6`,
/// the position where the sensor comes on recorded exactly, probe 1 untouched.
#[test]
fn probe_2_records_its_rising_edge() {
    for (interface, enable) in [
        (ProbeInterface::Canopen, 0x11),
        (ProbeInterface::Sercos, 0x01),
    ] {
        let mut rig = Rig::new(probed(interface, [None, Some([40.0031, 45.0])]));
        let id = rig.arm(2, ProbeEdge::Positive, None).unwrap();
        rig.tick();
        let out = rig.enc_out();
        assert_eq!((out.nCtrl5, out.nCtrl6), (0, enable), "{interface:?}");
        rig.run_to(60.0);
        let p2 = rig.probe(1);
        assert_eq!(p2.state_r, ProbeState::Recorded.raw(), "{interface:?}");
        assert_eq!((p2.arm_id_r, p2.edge_r), (id, ProbeEdge::Positive.raw()));
        assert!(
            (p2.recorded_position_r - 40.0031).abs() <= INCREMENT / 2.0,
            "{interface:?}: {}",
            p2.recorded_position_r
        );
        assert_eq!(rig.probe(0).state_r, ProbeState::Idle.raw());
    }
}

/// A 16-bit encoder standing at 500 mm (5 x 10^6 increments, far beyond 16 bits): without the
/// absolute read the axis takes the wrapped count for its position; with it (`nCtrl2` 0x02,
/// the answer in `nStatus2` and the value in `nInData2`) it knows where it stands, and MC_Power
/// is refused until then.
#[test]
fn the_absolute_position_is_read_through_the_encoders_register() {
    let config = |absolute: bool| {
        let mut c = probed(ProbeInterface::None, [None, None]);
        c.encoder_width = cnc_core::axis::increments::CounterWidth::Bits16;
        c.io.encoder_absolute = absolute;
        if let DriveLink::Simulated(sim) = &mut c.drive {
            sim.start_position = 500.0;
        }
        c
    };
    let mut plain = Rig::unpowered(config(false));
    plain.tick();
    assert!((plain.set.axis(0).unwrap().actual() - 500.0).abs() > 1.0);
    let mut rig = Rig::unpowered(config(true));
    let power = |rig: &mut Rig| {
        rig.set
            .axis_mut(0)
            .unwrap()
            .command(&AxisCommandCall::power(true))
    };
    assert_eq!(power(&mut rig), Err(AxisError::EncoderNotReady));
    rig.tick();
    assert_eq!(rig.enc_out().nCtrl2, 0x02, "read requested");
    rig.tick();
    assert!((rig.set.axis(0).unwrap().actual() - 500.0).abs() < INCREMENT);
    assert_eq!(rig.enc_out().nCtrl2, 0, "request released");
    power(&mut rig).unwrap();
    rig.run_to(501.5);
    assert!((rig.set.axis(0).unwrap().actual() - 501.5).abs() < INCREMENT);
}

/// MC_SetPosition: at standstill the encoder counts from the new position (`nCtrl2` 0x01 with
/// the value in `nOutData2`); the axis stands where it stood, its position is the new one, and
/// moves go on from there. Refused while moving, and on an encoder that cannot set its counter.
#[test]
fn set_position_sets_the_encoder_counter_at_standstill() {
    // The sensor sits at 40..45 mm of the motor's travel: 120 mm once the axis counts from
    // 100 at the motor's 20.
    let mut c = probed(ProbeInterface::Canopen, [Some([40.0, 45.0]), None]);
    c.io.encoder_set_counter = true;
    let mut rig = Rig::new(c);
    rig.run_to(10.0);
    let command = |rig: &mut Rig, p: f64| {
        rig.set
            .axis_mut(0)
            .unwrap()
            .command(&AxisCommandCall::set_position(p))
    };
    rig.move_to(20.0);
    rig.tick();
    assert_eq!(
        command(&mut rig, 0.0),
        Err(AxisError::SetPositionWhileMoving)
    );
    rig.run_to(20.0);
    command(&mut rig, 100.0).unwrap();
    rig.tick();
    assert_eq!(rig.enc_out().nCtrl2, 0x01);
    assert_eq!(rig.enc_out().nOutData2, 1_000_000);
    for _ in 0..3 {
        rig.tick();
    }
    let axis = rig.set.axis(0).unwrap();
    assert!(
        (axis.actual() - 100.0).abs() < INCREMENT,
        "{}",
        axis.actual()
    );
    assert!(axis.following_error().abs() < INCREMENT);
    assert_eq!(rig.enc_out().nCtrl2, 0);
    // A probe records on the new scale.
    rig.arm(1, ProbeEdge::Positive, None).unwrap();
    rig.run_to(130.0);
    assert!((rig.probe(0).recorded_position_r - 120.0).abs() <= INCREMENT / 2.0);
    let mut plain = Rig::new(probed(ProbeInterface::None, [None, None]));
    assert_eq!(
        command(&mut plain, 5.0),
        Err(AxisError::SetPositionNotSupported)
    );
}

/// `drive_out.nOutData3` as a torque set-point: percent of the rated torque (which gives the
/// axis's maximum acceleration) in `torque_increments_per_percent`; the simulated drive's actual
/// torque (`nInData3`) follows it.
#[test]
fn out_data3_carries_the_torque_set_point_when_configured() {
    use cnc_core::axis::config::OutData3;
    use hli::layout::{NcDriveIn, NcDriveOut};
    for mode in [OutData3::Torque, OutData3::Sum] {
        let mut c = probed(ProbeInterface::None, [None, None]);
        c.io.out_data3 = mode;
        let max = c.dynamics.acceleration;
        let per_unit = c.acceleration_increments_per_unit;
        let mut rig = Rig::new(c);
        rig.move_to(50.0);
        let mut checked = 0;
        for _ in 0..200 {
            rig.tick();
            let a = rig.set.axis(0).unwrap().setpoint().acceleration;
            let out: NcDriveOut = rig
                .place()
                .field::<NcDriveOut>(core::mem::offset_of!(HliAxis, drive_out))
                .read();
            let torque = 100.0 * a / max * 10.0;
            let expected = match mode {
                OutData3::Sum => (a * per_unit + torque).round() as i32,
                _ => torque.round() as i32,
            };
            assert_eq!(out.nOutData3, expected, "{mode:?}");
            if a.abs() > 0.5 * 2000.0 {
                checked += 1;
                let input: NcDriveIn = rig
                    .place()
                    .field::<NcDriveIn>(core::mem::offset_of!(HliAxis, drive_in))
                    .read();
                assert!(input.nInData3 != 0);
            }
        }
        assert!(checked > 10, "{checked}");
    }
}

/// `io.out_data3 = "sum"` with the default scalings: an acceleration of 2000 units/s^2 is
/// 2000 x 1000 increments of acceleration plus 20 % of the rated torque x 10 increments.
#[test]
fn out_data3_as_the_sum_of_acceleration_and_torque() {
    use cnc_core::axis::config::{AxisConfig, OutData3};
    let mut c = AxisConfig::linear("X", 1);
    c.io.out_data3 = OutData3::Sum;
    c.acceleration_increments_per_unit = 1000.0;
    c.dynamics.acceleration = 10_000.0;
    c.io.torque_increments_per_percent = 10.0;
    assert_eq!(c.out_data3(2000.0), 2_000_200.0);
    assert_eq!(c.out_data3(-2000.0), -2_000_200.0);
}

/// MC_SetPosition on a drive in cyclic position mode with dead time, on 32- and 16-bit
/// counters: the drive switches its set-point over when the NC does, so the motor never
/// moves and the axis stands at the new position without a following error.
#[test]
fn set_position_in_position_mode_moves_nothing() {
    use cnc_core::axis::config::DriveMode;
    use cnc_core::axis::increments::CounterWidth;
    for width in [CounterWidth::Bits32, CounterWidth::Bits16] {
        let mut c = probed(ProbeInterface::None, [None, None]);
        c.io.encoder_set_counter = true;
        c.drive_mode = DriveMode::Position;
        c.encoder_width = width;
        if let DriveLink::Simulated(sim) = &mut c.drive {
            sim.dead_time_ticks = 2;
        }
        let mut rig = Rig::new(c);
        rig.run_to(7.0);
        for _ in 0..5 {
            rig.tick();
        }
        rig.set
            .axis_mut(0)
            .unwrap()
            .command(&AxisCommandCall::set_position(-123.4567))
            .unwrap();
        let refused = rig
            .set
            .axis_mut(0)
            .unwrap()
            .command(&AxisCommandCall::move_absolute(
                0.0,
                [100.0, 2000.0, 2000.0, 50_000.0],
            ));
        assert_eq!(
            refused,
            Err(AxisError::EncoderNotReady),
            "no move while the count changes"
        );
        for _ in 0..20 {
            rig.tick();
            let axis = rig.set.axis(0).unwrap();
            assert!(axis.following_error().abs() < INCREMENT, "{width:?}");
        }
        let axis = rig.set.axis(0).unwrap();
        assert!(
            (axis.actual() + 123.4567).abs() < INCREMENT,
            "{width:?}: {}",
            axis.actual()
        );
        rig.run_to(-120.0);
        assert!((rig.set.axis(0).unwrap().actual() + 120.0).abs() < INCREMENT);
    }
}
