//! The CNC tick of twelve tracking robots (interpreter in an endless loop, interpolation,
//! kinematic transformation both ways, dynamic CS, HLI outputs, axis images) allocates nothing
//! once the programs run.

use cnc_core::scenario::fleet::{plc_setup, tracking_robots};
use cnc_core::scenario::InProcess;
use hli::enums::DynCsState;
use hli::views::PlcView;

#[path = "../../tests/support/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocations;

#[test]
fn twelve_tracking_robots_tick_without_allocating() {
    let s = tracking_robots(12).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    plc_setup(&PlcView::new(&run.memory));
    // Start-up: programs begin, tracking switches on, the loops run once.
    for _ in 0..3000 {
        run.machine.tick(&run.memory);
    }
    for c in run.machine.controller().channels() {
        assert_eq!(
            c.tracker().state(),
            DynCsState::Active,
            "{}",
            c.config().name
        );
        assert!(c.error().is_none(), "{:?}", c.error());
    }
    let before = allocations();
    for _ in 0..5000 {
        run.machine.tick(&run.memory);
    }
    let made = allocations() - before;
    assert_eq!(made, 0, "{made} allocations in 5000 ticks of 12 channels");
    // The robots moved: the loops ran through the measured ticks.
    assert!(run
        .machine
        .controller()
        .channels()
        .iter()
        .all(|c| c.is_moving()));
}
