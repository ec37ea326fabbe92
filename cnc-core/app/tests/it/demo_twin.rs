//! The demo machine with its PLC program in one process (the in-process twin of `cnc demo`):
//! it runs its whole cycle like the two processes do, and with every engine at work (four
//! robot channels, three tracking; a cam slave through a rescale and an online point change;
//! a flying saw cutting) the machine tick allocates nothing. The PLC program's cycle allocates
//! exactly once per acyclic call it sends, inside iceoryx2's request-response (each loaned
//! request gets a reference-counted shared state, `ChunkMutSharedState::new`), and nothing
//! else.

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
        plc_allocs as u64, calls,
        "the PLC program's cycles allocate once per call sent (iceoryx2), nothing else"
    );
}
