//! The PLC's cyclic path does not allocate: the runtime's loop (wait for the tick, run the
//! task, time it, beat, notify) and a program using the typed views, counted per thread by a
//! counting allocator between the 20th and the 400th cycle.

use crate::counting_alloc;

use counting_alloc::{allocations, deallocations};
use plc_shim::runtime::{PlcIo, PlcProgram, PlcRuntime, RunEnd};
use std::time::Duration;
use tests::unique_instance;

struct Probe {
    at_20: (usize, usize),
    at_400: (usize, usize),
}

impl PlcProgram for Probe {
    fn cycle(&mut self, io: &mut PlcIo<'_>) {
        if io.cycle == 20 {
            self.at_20 = (allocations(), deallocations());
        }
        if io.cycle == 400 {
            self.at_400 = (allocations(), deallocations());
        }
        if let Some(channel) = io.gp_ch(0) {
            channel.set_dyn_cs_enabled(io.cycle.is_multiple_of(2));
            let _ = channel.dyn_cs_state();
            let _ = channel.m_function_request().try_take();
        }
        if let Some(axis) = io.gp_ax(0) {
            let _ = axis.lr_state();
        }
    }
}

#[test]
fn the_plc_cycle_loop_does_not_allocate() {
    hli_transport::init_logging();
    let instance = unique_instance("plc-no-alloc");
    let cnc = tests::lockstep_beats(&instance, 500, 1);
    let mut runtime = PlcRuntime::attach(&instance, 2_000, Duration::from_millis(5)).unwrap();
    let mut probe = Probe {
        at_20: (0, 0),
        at_400: (0, 0),
    };
    let summary = runtime.run(&mut probe, Some(10_000)).unwrap();
    cnc.join().unwrap();
    assert_eq!(summary.end, RunEnd::CncClosed);
    assert!(probe.at_20.0 > 0, "the counter counts");
    assert_eq!(
        (
            probe.at_400.0 - probe.at_20.0,
            probe.at_400.1 - probe.at_20.1
        ),
        (0, 0),
        "allocations and frees in 380 PLC cycles"
    );
}
