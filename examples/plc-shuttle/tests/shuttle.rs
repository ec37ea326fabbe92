//! The shuttle program against a CNC with one simulated axis, in lockstep: it makes its round
//! trips, ends at home, and the axis passes the far station on the way.

use cnc_core::axis::{AxisConfig, AxisSet};
use plc_shim::runtime::{PlcIo, PlcProgram, PlcRuntime, RunEnd};
use plc_shuttle::{Shuttle, Step};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// The shuttle, plus what the test watches: the farthest position and when to stop the CNC.
struct Watched {
    shuttle: Shuttle,
    farthest: i32,
    finished: Arc<AtomicBool>,
}

impl PlcProgram for Watched {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        self.shuttle.cycle(io);
        if let Some(axis) = io.gp_ax(0) {
            self.farthest = self.farthest.max(axis.lr_state().command_position_acs_r);
        }
        if self.shuttle.finished() {
            self.finished.store(true, Ordering::Release);
        }
    }
}

#[test]
fn the_shuttle_makes_its_round_trips() {
    hli_transport::init_logging();
    let instance = tests::unique_instance("shuttle");
    let finished = Arc::new(AtomicBool::new(false));
    let cnc = tests::serve_axes_in_lockstep(
        &instance,
        1,
        || AxisSet::new(vec![AxisConfig::linear("S", 1)], 0.001).unwrap(),
        finished.clone(),
    );
    let mut runtime = PlcRuntime::attach(&instance, 2_000, Duration::from_millis(5)).unwrap();
    let mut program = Watched {
        shuttle: Shuttle::new(0, 0.0, 50.0, 2, 200.0),
        farthest: 0,
        finished: finished.clone(),
    };
    let summary = runtime.run(&mut program, Some(1_000_000)).unwrap();
    assert!(cnc.join().unwrap(), "{}", program.shuttle.summary());
    assert_eq!(summary.end, RunEnd::CncClosed);
    assert_eq!(program.shuttle.step, Step::Done);
    assert_eq!(program.shuttle.made, 2);
    // The far station is 50 mm = 500000 HLI units; MC_MoveAbsolute reaches it exactly.
    assert_eq!(program.farthest, 500_000);
}
