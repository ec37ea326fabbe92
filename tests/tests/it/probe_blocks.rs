//! MC_TouchProbe and MC_AbortTrigger against a CNC's axis through the real segment and the
//! acyclic service: a CNC thread ticks a simulated axis with a CANopen touch probe in lockstep
//! with a PLC program that arms, moves across the sensor, reads the recorded position, is
//! refused a second arming, and aborts an arming that sees no edge.

use cnc_core::axis::config::{AxisConfig, DriveLink, ProbeInterface};
use cnc_core::axis::sim_drive::SimDriveConfig;
use cnc_core::axis::AxisSet;
use hli::enums::ProbeEdge;
use plc_shim::blocks::motion::{McMoveAbsolute, McPower};
use plc_shim::blocks::probe::{McAbortTrigger, McTouchProbe};
use plc_shim::runtime::{PlcIo, PlcProgram, PlcRuntime, RunEnd};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tests::unique_instance;

const X: u32 = 0;

#[derive(Default)]
struct Sequence {
    step: usize,
    power: McPower,
    travel: McMoveAbsolute,
    probe: McTouchProbe,
    again: McTouchProbe,
    abort: McAbortTrigger,
    log: Vec<String>,
    finished: Arc<AtomicBool>,
}

impl Sequence {
    fn go(&mut self, target: f64) {
        let m = &mut self.travel;
        (
            m.position,
            m.velocity,
            m.acceleration,
            m.deceleration,
            m.jerk,
        ) = (target, 100.0, 2000.0, 2000.0, 50_000.0);
        m.execute = true;
    }
}

impl PlcProgram for Sequence {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        self.power.enable = true;
        self.power.call(io, X);
        match self.step {
            0 if self.power.status => {
                self.probe.edge = ProbeEdge::Positive;
                self.probe.execute = true;
                self.step = 1;
            }
            1 if self.probe.out.busy => {
                // The same probe once more while it is armed.
                self.again.execute = true;
                self.step = 2;
            }
            2 if self.again.out.error => {
                self.log.push(format!(
                    "second arming refused 0x{:X}",
                    self.again.out.error_id
                ));
                self.again.execute = false;
                self.go(50.0);
                self.step = 3;
            }
            3 if self.probe.out.done => {
                self.log
                    .push(format!("recorded {:.4}", self.probe.out.extra));
                self.probe.execute = false;
                self.step = 4;
            }
            4 if self.travel.out.done => {
                self.travel.execute = false;
                // Armed for a window the sensor never reaches.
                self.probe.window_only = true;
                (self.probe.first_position, self.probe.last_position) = (70.0, 80.0);
                self.probe.execute = true;
                self.step = 5;
            }
            5 if self.probe.out.busy => {
                self.go(0.0);
                self.step = 6;
            }
            6 if self.travel.out.done => {
                self.log
                    .push(format!("still armed: {}", self.probe.out.busy));
                self.abort.execute = true;
                self.step = 7;
            }
            7 if self.abort.out.done && self.probe.out.command_aborted => {
                self.log.push("aborted".into());
                self.finished.store(true, Ordering::Release);
                self.step = 8;
            }
            _ => {}
        }
        self.travel.call(io, X);
        self.probe.call(io, X);
        self.again.call(io, X);
        self.abort.call(io, X);
    }
}

#[test]
fn plc_probe_blocks_arm_record_refuse_and_abort_through_the_segment() {
    hli_transport::init_logging();
    let instance = unique_instance("probe-fb");
    let finished = Arc::new(AtomicBool::new(false));
    let cnc = tests::serve_axes_in_lockstep(
        &instance,
        1,
        || {
            let mut x = AxisConfig::linear("X", 1);
            x.io.probe = ProbeInterface::Canopen;
            x.drive = DriveLink::Simulated(SimDriveConfig {
                probe_windows: [Some([20.0017, 30.0]), None],
                ..SimDriveConfig::default()
            });
            AxisSet::new(vec![x], 0.001).unwrap()
        },
        finished.clone(),
    );
    let mut runtime = PlcRuntime::attach(&instance, 2_000, Duration::from_millis(5)).unwrap();
    let mut program = Sequence {
        finished: finished.clone(),
        ..Sequence::default()
    };
    let summary = runtime.run(&mut program, Some(1_000_000)).unwrap();
    let cnc_done = cnc.join().unwrap();
    assert!(cnc_done, "the sequence did not finish: {:?}", program.log);
    assert_eq!(summary.end, RunEnd::CncClosed);
    assert_eq!(
        program.log,
        [
            "second arming refused 0x4260",
            "recorded 20.0017",
            "still armed: true",
            "aborted",
        ]
    );
}
