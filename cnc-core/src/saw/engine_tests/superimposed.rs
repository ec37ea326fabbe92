//! MC_MoveSuperimposed on a flying-saw slave in its synchronous phase: the distance is added
//! to the gear's motion (the saw's own follower goes on undisturbed, in its frame) and the
//! slave runs at the master's velocity again once it is done.

use super::{machine, velocity_call};
use crate::harness::Harness;
use hli::calls::axis::AxisCommandCall;
use hli::command_book::{view_command, CommandView};
use hli::enums::AxisState;

const MASTER: u32 = 0;
const SAW: u32 = 1;

fn command(run: &mut Harness, axis: u32, c: AxisCommandCall) -> hli::calls::axis::AxisCommandReply {
    run.call(axis, &c).unwrap()
}

/// The master at 500 mm/s and the saw coupled with MC_GearInVelo (ratio 1, SyncMode `mask`),
/// run until it is synchronous.
fn synchronous_saw(mask: u32) -> Harness {
    let mut run = machine();
    let forward = AxisCommandCall::move_velocity(1, [500.0, 10000.0, 10000.0, 1e6]);
    assert_eq!(command(&mut run, MASTER, forward).error_id, 0);
    let gear = velocity_call(1.0, mask);
    assert_eq!(run.call(SAW, &gear).unwrap().error_id, 0);
    for _ in 0..5000 {
        run.step();
        if state(&run) == AxisState::SlaveSynchronous.raw() {
            return run;
        }
    }
    panic!("the saw never synchronised");
}

/// The saw's `nAxisState`.
fn state(run: &Harness) -> i32 {
    let a = run.axis(SAW as usize);
    a.motion_state(a.setpoint()).raw()
}

#[test]
fn a_superimposed_move_shifts_a_synchronous_saw_and_it_runs_with_the_master_again() {
    let mut run = synchronous_saw(0);
    // The saw's phase, set velocity and the engine's velocity.
    let saw = |run: &Harness| {
        let a = run.axis(SAW as usize);
        let set = a.setpoint();
        (
            a.motion_state(set).raw(),
            set.velocity,
            a.engine_setpoint().velocity,
        )
    };
    let shift = AxisCommandCall::move_superimposed(10.0, [100.0, 1000.0, 1000.0, 1e5]);
    let reply = command(&mut run, SAW, shift);
    assert_eq!(reply.error_id, 0);
    run.steps(2000);
    let axis = run.axis(SAW as usize);
    assert_eq!(
        view_command(&axis.book().image(), reply.command_id),
        CommandView::Done
    );
    assert_eq!(axis.superimposed_offset(), 10.0);
    let (state, velocity, engine_velocity) = saw(&run);
    assert_eq!(state, AxisState::SlaveSynchronous.raw());
    let master = run.setpoint(MASTER as usize);
    assert!((velocity - master.velocity).abs() < 1e-9, "{velocity}");
    assert!((engine_velocity - velocity).abs() < 1e-9);
}

/// A rollback with the lock (manual 001, chapter 8): the saw stops and stands (its
/// pre-phase, 11). A superimposed move running then is braked and aborted, so the saw comes
/// to rest, and a new one is refused (0x4235) while it stands.
#[test]
fn a_rollback_brakes_and_aborts_a_superimposed_move_and_refuses_a_new_one() {
    use hli::calls::saw::sync_mask as m;
    let mut run = synchronous_saw(m::ROLLBACKLOCK);
    let long = AxisCommandCall::move_superimposed(500.0, [50.0, 1000.0, 1000.0, 1e5]);
    let shift = command(&mut run, SAW, long);
    assert_eq!(shift.error_id, 0);
    let back = AxisCommandCall::move_velocity(-1, [2000.0, 10000.0, 10000.0, 1e6]);
    assert_eq!(command(&mut run, MASTER, back).error_id, 0);
    run.steps(3000);
    let axis = run.axis(SAW as usize);
    assert_eq!(state(&run), AxisState::SlavePrephase.raw());
    assert_eq!(
        view_command(&axis.book().image(), shift.command_id),
        CommandView::Aborted
    );
    assert_eq!(axis.setpoint().velocity, 0.0, "the saw stands");
    let again = command(&mut run, SAW, long);
    assert_eq!(
        again.error_id,
        hli::enums::AxisError::SuperimposedNotCoupled.raw()
    );
}
