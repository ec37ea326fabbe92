//! PLC motion blocks against the CNC's axes through the real segment and the acyclic service:
//! a CNC thread ticks two simulated axes in lockstep with a PLC runtime whose program walks
//! through MC_Power, MC_MoveAbsolute, MC_MoveRelative, MC_MoveVelocity, MC_Halt, MC_Stop and
//! a refused move, checking the blocks' outputs on the way.

use cnc_core::axis::config::{AxisConfig, DriveLink};
use cnc_core::axis::sim_drive::{Dynamic, SimDriveConfig};
use cnc_core::axis::AxisSet;
use plc_shim::blocks::motion::{
    McHalt, McMoveAbsolute, McMoveRelative, McMoveVelocity, McPower, McStop,
};
use plc_shim::runtime::{PlcIo, PlcProgram, PlcRuntime, RunEnd};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tests::unique_instance;

const X: u32 = 0;
const Y: u32 = 1;

#[derive(Default)]
struct Sequence {
    step: usize,
    power_x: McPower,
    power_y: McPower,
    move_x: McMoveAbsolute,
    relative_x: McMoveRelative,
    run_y: McMoveVelocity,
    bad_y: McMoveAbsolute,
    halt_y: McHalt,
    stop_x: McStop,
    after_stop_x: McMoveAbsolute,
    /// What the program saw, in order.
    log: Vec<String>,
    finished: Arc<AtomicBool>,
}

fn limits(block: &mut McMoveAbsolute, position: f64) {
    block.position = position;
    block.velocity = 200.0;
    block.acceleration = 2000.0;
    block.deceleration = 2000.0;
    block.jerk = 50_000.0;
}

impl PlcProgram for Sequence {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        self.power_x.enable = true;
        self.power_y.enable = true;
        self.power_x.call(io, X);
        self.power_y.call(io, Y);
        match self.step {
            0 if self.power_x.status && self.power_y.status => {
                self.log.push("powered".into());
                limits(&mut self.move_x, 100.0);
                self.move_x.execute = true;
                self.step = 1;
            }
            1 if self.move_x.out.done => {
                let x = io.view.axis_state(X as usize).unwrap();
                self.log.push(format!("x at {}", x.command_position_acs_r));
                self.move_x.execute = false;
                let r = &mut self.relative_x;
                (
                    r.distance,
                    r.velocity,
                    r.acceleration,
                    r.deceleration,
                    r.jerk,
                ) = (-30.0, 100.0, 1000.0, 1000.0, 20_000.0);
                r.execute = true;
                let v = &mut self.run_y;
                (
                    v.direction,
                    v.velocity,
                    v.acceleration,
                    v.deceleration,
                    v.jerk,
                ) = (-1, 50.0, 500.0, 500.0, 10_000.0);
                v.execute = true;
                self.step = 2;
            }
            2 if self.relative_x.out.done && self.run_y.out.in_velocity => {
                let x = io.view.axis_state(X as usize).unwrap();
                self.log.push(format!("x at {}", x.command_position_acs_r));
                self.log.push("y in velocity".into());
                limits(&mut self.bad_y, 5000.0);
                self.bad_y.execute = true;
                self.step = 3;
            }
            3 if self.bad_y.out.error => {
                self.log
                    .push(format!("bad move refused 0x{:X}", self.bad_y.out.error_id));
                self.log.push(format!(
                    "y still running: {}",
                    self.run_y.out.busy && self.run_y.out.in_velocity
                ));
                (self.halt_y.deceleration, self.halt_y.jerk) = (400.0, 8000.0);
                self.halt_y.execute = true;
                self.step = 4;
            }
            4 if self.halt_y.out.done => {
                self.log.push(format!(
                    "velocity block aborted: {}",
                    self.run_y.out.command_aborted
                ));
                let y = io.view.axis_state(Y as usize).unwrap();
                self.log
                    .push(format!("y velocity {}", y.command_velocity_r));
                limits(&mut self.move_x, -100.0);
                self.move_x.execute = true; // rising edge again (it fell in step 1)
                self.step = 5;
            }
            5 if self.move_x.out.busy
                && io.view.axis_state(X as usize).unwrap().command_velocity_r < -100_000 =>
            {
                (self.stop_x.deceleration, self.stop_x.jerk) = (2000.0, 50_000.0);
                self.stop_x.execute = true;
                self.step = 6;
            }
            6 if self.stop_x.out.done => {
                self.log.push(format!(
                    "move aborted by stop: {}",
                    self.move_x.out.command_aborted
                ));
                limits(&mut self.after_stop_x, 0.0);
                self.after_stop_x.execute = true;
                self.step = 7;
            }
            7 if self.after_stop_x.out.error => {
                self.log
                    .push(format!("locked 0x{:X}", self.after_stop_x.out.error_id));
                self.after_stop_x.execute = false;
                self.stop_x.execute = false;
                self.step = 8;
            }
            8 => {
                self.after_stop_x.execute = true;
                self.step = 9;
            }
            9 if self.after_stop_x.out.done => {
                let x = io.view.axis_state(X as usize).unwrap();
                self.log.push(format!("x at {}", x.command_position_acs_r));
                self.finished.store(true, Ordering::Release);
                self.step = 10;
            }
            _ => {}
        }
        self.move_x.call(io, X);
        self.relative_x.call(io, X);
        self.run_y.call(io, Y);
        self.bad_y.call(io, Y);
        self.halt_y.call(io, Y);
        self.stop_x.call(io, X);
        self.after_stop_x.call(io, X);
    }
}

#[test]
fn plc_motion_blocks_drive_simulated_axes_through_the_segment() {
    hli_transport::init_logging();
    let instance = unique_instance("axis-fb");
    let finished = Arc::new(AtomicBool::new(false));
    let cnc = tests::serve_axes_in_lockstep(
        &instance,
        2,
        || {
            let mut lagging = AxisConfig::linear("Y", 2);
            lagging.drive = DriveLink::Simulated(SimDriveConfig {
                dynamic: Dynamic::Pt1 { t1_s: 0.005 },
                dead_time_ticks: 1,
                start_position: 0.0,
                ..SimDriveConfig::default()
            });
            AxisSet::new(vec![AxisConfig::linear("X", 1), lagging], 0.001).unwrap()
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
            "powered",
            "x at 1000000",
            "x at 700000",
            "y in velocity",
            "bad move refused 0x4225",
            "y still running: true",
            "velocity block aborted: true",
            "y velocity 0",
            "move aborted by stop: true",
            "locked 0x4232",
            "x at 0",
        ]
    );
}
