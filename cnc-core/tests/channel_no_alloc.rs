//! The CNC tick of twelve tracking robots (interpreter in an endless loop, interpolation,
//! kinematic transformation both ways, dynamic CS, HLI outputs, axis images) allocates nothing
//! once the programs run.

use cnc_core::scenario::fleet::running;

#[path = "../../tests/support/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocations;

#[test]
fn twelve_tracking_robots_tick_without_allocating() {
    // Start-up: programs begin, tracking switches on, the loops run once.
    let mut run = running(12, 3000).unwrap();
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
