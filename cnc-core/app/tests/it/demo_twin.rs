//! The demo machine with its PLC program in one process (the in-process twin of `cnc demo`):
//! it runs its whole cycle like the two processes do, and with every engine at work (four
//! robot channels, three tracking; a cam slave through a rescale and an online point change;
//! a flying saw cutting) the machine tick allocates nothing, nor does the PLC program's cycle,
//! the acyclic calls it sends included (they go through the call mailbox; over iceoryx2's
//! request-response each call allocated once).

use crate::counting_alloc::allocations;
use cnc_app::scenario::InProcess;

#[test]
fn the_demo_machine_and_its_plc_program_run_in_process_without_allocating() {
    let scenario = cnc_app::demo::scenario().unwrap();
    let ticks = scenario.ticks.unwrap() as usize;
    let mut run = InProcess::new(&scenario, 0).unwrap();
    let (mut machine_allocs, mut plc_allocs, mut calls) = (0usize, 0usize, 0u64);
    // Tick 0 and the PLC's first cycles set up what they keep (the cam table transfer opens
    // its buffers, the blocks their first calls): counted from tick 50 on.
    const COUNT_FROM: usize = 50;
    for tick in 0..ticks {
        let before = allocations();
        run.machine.tick(&run.memory);
        let after_tick = allocations();
        run.answer_calls();
        let (sent_before, _) = run.calls();
        let before_plc = allocations();
        run.run_program();
        let after_plc = allocations();
        let (sent_after, _) = run.calls();
        run.machine.serve_channels();
        if tick >= COUNT_FROM {
            machine_allocs += after_tick - before;
            plc_allocs += after_plc - before_plc;
            calls += sent_after - sent_before;
        }
    }
    let summary = run.program.as_ref().unwrap().0.summary();
    assert!(
        summary.contains("robots started by the PLC: 4 of 4"),
        "{summary}"
    );
    assert!(summary.contains("saw-cut: Finished, 5 cuts"), "{summary}");
    assert!(summary.contains("cam-conveyor: Finished"), "{summary}");
    let channels = run.machine.controller().channels();
    assert!(channels
        .iter()
        .all(|c| c.programs_ended() == 1 && c.error().is_none()));
    let tracked = channels
        .iter()
        .filter(|c| c.tracker().state_changes() > 0)
        .count();
    assert_eq!(tracked, 3, "the two slaves and the turntable robot tracked");
    assert_eq!(
        machine_allocs, 0,
        "{machine_allocs} allocations in the machine ticks"
    );
    assert!(calls > 20, "the stations sent their calls: {calls}");
    assert_eq!(
        plc_allocs, 0,
        "the PLC program's cycles allocate nothing, its {calls} calls included"
    );
}

/// Two more axes beside the demo's 30, with touch probes, in a 2-axis FIFO group.
const FIFO_STATION: &str = "\
[[axis]]\nname = \"F0\"\npower = true\nsoft_limits = [-1e6, 1e6]\n\
io = { probe = \"canopen\" }\n\
[[axis]]\nname = \"F1\"\npower = true\nsoft_limits = [-1e6, 1e6]\n\
io = { probe = \"canopen\" }\n\
[[fifo_group]]\ndimension = 2\nrows = 400\nfifo_cycle_ms = 2.0\noverride = \"pt2\"\npt2_t0_ms = 20.0\n";

/// Rows `from..from + n` of a slow two-axis sweep, written into the FIFO between ticks.
fn feed(run: &mut InProcess, from: usize, n: usize) -> usize {
    use hli::calls::fifo::{rows_header, FifoReply};
    let values: Vec<f64> = (from..from + n)
        .flat_map(|k| [(k as f64 * 0.002).sin(), (k as f64 * 0.003).cos() - 1.0])
        .collect();
    let (body, len) = run
        .machine
        .dispatch_bulk(&rows_header(0, 2, n as u32, false), &values)
        .unwrap();
    let reply: FifoReply = bytemuck::pod_read_unaligned(&body[..len as usize]);
    assert_eq!(reply.error_id, 0, "rows {from}..");
    from + n
}

/// Every engine at once: the demo (channels tracking, the cam slave through its rescale and
/// point change, the saw cutting) with a FIFO group streaming and touch probes armed on its
/// axes: the machine tick allocates and frees nothing.
#[test]
fn every_engine_at_once_the_machine_tick_allocates_nothing() {
    use crate::counting_alloc::deallocations;
    use hli::calls::fifo::{FifoIntegrateCall, FifoReply, FifoStartCall};
    use hli::calls::probe::ProbeArmCall;
    use hli::views::{CncView, PlcView};
    let scenario = cnc_app::demo::scenario_with(FIFO_STATION).unwrap();
    let ticks = scenario.ticks.unwrap() as usize;
    let mut run = InProcess::new(&scenario, 0).unwrap();
    let n = run.machine.axes().len();
    assert_eq!(n, 32, "the demo's 30 axes and the FIFO station's 2");
    let (f0, f1) = (n as u32 - 2, n as u32 - 1);
    run.machine.tick(&run.memory);
    for (axis, column) in [(f0, 1), (f1, 2)] {
        let view = CncView::new(&run.memory);
        let integrate = FifoIntegrateCall {
            axis,
            group_position: column,
        };
        let reply: FifoReply = run.machine.call(&view, 0, &integrate).unwrap();
        assert_eq!(reply.error_id, 0);
    }
    let mut next = feed(&mut run, 0, 300);
    let view = CncView::new(&run.memory);
    let start: FifoReply = run
        .machine
        .call(&view, 0, &FifoStartCall::default())
        .unwrap();
    assert_eq!(start.error_id, 0);
    let (mut allocs, mut frees, mut armed) = (0usize, 0usize, 0u32);
    const COUNT_FROM: usize = 50;
    for tick in 0..ticks {
        let (a, d) = (allocations(), deallocations());
        run.machine.tick(&run.memory);
        if tick >= COUNT_FROM {
            allocs += allocations() - a;
            frees += deallocations() - d;
        }
        run.answer_calls();
        run.run_program();
        run.machine.serve_channels();
        // The FIFO topped up, the probes armed again, between the ticks (as a PLC does).
        let free = PlcView::new(&run.memory).fifo_group(0).unwrap().free_r as usize;
        if free >= 100 {
            next = feed(&mut run, next, 100);
        }
        if tick % 100 == 0 {
            let view = CncView::new(&run.memory);
            for axis in [f0, f1] {
                let arm = ProbeArmCall {
                    probe: 1,
                    edge: 1,
                    ..Default::default()
                };
                let reply = run.machine.call(&view, axis, &arm).unwrap();
                armed += u32::from(reply.error_id == 0);
            }
        }
    }
    let summary = run.program.as_ref().unwrap().0.summary();
    assert!(summary.contains("saw-cut: Finished, 5 cuts"), "{summary}");
    assert!(summary.contains("cam-conveyor: Finished"), "{summary}");
    let group = PlcView::new(&run.memory).fifo_group(0).unwrap();
    assert!(
        next >= 7_000,
        "the FIFO streamed a row every 2 ticks: {next}"
    );
    assert_eq!(
        group.underrun_ticks_r, 0,
        "the FIFO never ran dry while fed"
    );
    assert!(armed >= 2, "the probes were armed: {armed}");
    assert_eq!(
        (allocs, frees),
        (0, 0),
        "allocations and frees in the machine ticks"
    );
}
