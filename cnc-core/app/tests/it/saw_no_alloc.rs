//! The flying saw in the machine tick allocates and frees nothing: the synchronising phase,
//! the synchronous phase, a rollback with its stop, standing in the pre-phase and the new
//! plan made inside the tick when the master comes forward again.

use cnc_app::scenario::{InProcess, Scenario};
use hli::calls::axis::AxisCommandCall;
use hli::calls::saw::{sync_mask, SawGearInCall, SawSyncTarget};
use hli::enums::AxisState;
use hli::views::{CncView, PlcView};

use crate::counting_alloc;
use counting_alloc::{allocations, deallocations};

const TICK: f64 = 0.001;

fn call<C: hli::calls::AcyclicCall>(run: &mut InProcess, axis: u32, body: C) -> C::Reply {
    let view = CncView::new(&run.memory);
    run.machine.call(&view, axis, &body).expect("answered")
}

/// `n` ticks; the allocations and frees they made.
fn ticks(run: &mut InProcess, n: usize) -> (usize, usize) {
    let (a, d) = (allocations(), deallocations());
    for _ in 0..n {
        run.machine.tick(&run.memory);
    }
    (allocations() - a, deallocations() - d)
}

#[test]
fn the_saw_tick_allocates_nothing() {
    let axis = |name: &str| {
        format!(
            "[[axis]]\nname = \"{name}\"\npower = true\nsoft_limits = [-1e7, 1e7]\nvelocity = 3000.0\n\
             acceleration = 20000.0\ndeceleration = 20000.0\njerk = 1e7\nfollowing_error_limit = 1e4\n"
        )
    };
    let toml = format!("cycle_ms = 1.0\nticks = 1\n{}{}", axis("M"), axis("S"));
    let s = Scenario::parse("saw.toml", &toml, |f| panic!("no file {f}")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    run.step(TICK);
    let limits = [500.0, 10000.0, 10000.0, 1e6];
    let _ = call(&mut run, 0, AxisCommandCall::move_velocity(1, limits));
    ticks(&mut run, 200);
    let gear_in = SawGearInCall {
        master: 0,
        target: SawSyncTarget::Velocity.raw(),
        ratio_numerator: 1.0,
        ratio_denominator: 1,
        mask: sync_mask::ROLLBACKLOCK,
        ..SawGearInCall::default()
    };
    assert_eq!(call(&mut run, 1, gear_in).error_id, 0);
    let state = |run: &InProcess| {
        PlcView::new(&run.memory)
            .axis_state(1)
            .unwrap()
            .axis_state_r
    };
    let mut seen = Vec::with_capacity(8);
    let mut total = (0, 0);
    let mut count = |run: &mut InProcess, n: usize, seen: &mut Vec<i32>| {
        let (a, d) = ticks(run, n);
        total = (total.0 + a, total.1 + d);
        let s = state(run);
        if seen.last() != Some(&s) {
            seen.push(s);
        }
    };
    for _ in 0..100 {
        count(&mut run, 10, &mut seen);
    }
    // The master runs back over the coupling position and forward again.
    let _ = call(&mut run, 0, AxisCommandCall::move_velocity(-1, limits));
    for _ in 0..300 {
        count(&mut run, 10, &mut seen);
    }
    let _ = call(&mut run, 0, AxisCommandCall::move_velocity(1, limits));
    for _ in 0..300 {
        count(&mut run, 10, &mut seen);
    }
    use AxisState::*;
    for phase in [SlaveSynchronizing, SlaveSynchronous, SlavePrephase] {
        assert!(
            seen.contains(&phase.raw()),
            "{phase:?} not reached: {seen:?}"
        );
    }
    assert!(seen.len() >= 5, "sync, rollback, sync again: {seen:?}");
    assert_eq!(total, (0, 0), "allocations and frees in the saw ticks");
}
