//! MC_MoveSuperimposed on a cam slave: the distance is added to the coupled motion on its own
//! jerk-limited profile, never more than the velocity difference given faster or slower than
//! the cam; MC_CamInfo shows the sum (SumOfSuperpositionDistance); a new move aborts the one
//! running; the coupling's end keeps the offset without a jump; a free axis refuses it.

use super::recovery::{cam_info, machine};
use super::*;
use crate::axis::Axis;
use hli::calls::axis::{AxisCommandCall, AxisCommandReply};
use hli::command_book::{view_command, CommandView};

fn superimpose(run: &mut Harness, axis: usize, distance: f64, vdiff: f64) -> AxisCommandReply {
    let c = AxisCommandCall::move_superimposed(distance, [vdiff, 500.0, 500.0, 1e5]);
    run.call(axis as u32, &c).unwrap()
}

fn slave(run: &Harness) -> &Axis {
    run.axis(SLAVE)
}

fn outcome(run: &Harness, id: u32) -> CommandView {
    view_command(&slave(run).book().image(), id)
}

/// The slave coupled to the stroke table (20 per master period of 360), the master at
/// 360 mm/s for 0.2 s.
fn coupled() -> Harness {
    let mut run = machine();
    run.step();
    select_cyclic(&mut run, 3);
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(3)), 0);
    run_master(&mut run, 360.0);
    for _ in 0..200 {
        run.step();
    }
    run
}

#[test]
fn a_superimposed_move_shifts_a_cam_slave_within_its_velocity_difference() {
    let mut run = coupled();
    let reply = superimpose(&mut run, SLAVE, 10.0, 50.0);
    assert_eq!(reply.error_id, 0);
    let mut ticks = 0;
    // Running beside the cam's command: shown as the axis's superimposed move.
    while slave(&run).drive_state().superimposed_id_r == reply.command_id {
        run.step();
        let (total, engine) = (slave(&run).setpoint(), slave(&run).engine_setpoint());
        let dv = total.velocity - engine.velocity;
        assert!(dv.abs() <= 50.0 + 1e-9, "tick {ticks}: {dv}");
        ticks += 1;
        assert!(ticks < 2000, "the move never ended");
    }
    assert_eq!(outcome(&run, reply.command_id), CommandView::Done);
    // 10 mm at 50 mm/s: at least 0.2 s.
    assert!(ticks >= 200, "{ticks}");
    let (total, engine) = (slave(&run).setpoint(), slave(&run).engine_setpoint());
    assert!((total.position - engine.position - 10.0).abs() < 1e-9);
    assert_eq!(slave(&run).drive_state().superimposed_id_r, 0);
    // The cam itself went on: the engine's slave is on the stroke table's line.
    let master = set(&run, MASTER).position;
    assert!((engine.position - 20.0 * master / 360.0).abs() < 1e-6);
    let info = cam_info(&mut run, None).unwrap();
    assert_eq!(info[19], 10.0, "SumOfSuperpositionDistance");
    assert!(
        (info[21] - total.position).abs() < 1e-6,
        "ActualSlaveAxisPos {} vs {}",
        info[21],
        total.position
    );
}

#[test]
fn a_new_superimposed_move_aborts_the_running_one_and_goes_on_from_its_offset() {
    let mut run = coupled();
    let first = superimpose(&mut run, SLAVE, -4.0, 20.0);
    assert_eq!(first.error_id, 0);
    for _ in 0..50 {
        run.step();
    }
    let reached = slave(&run).superimposed_offset();
    assert!(reached < 0.0 && reached > -4.0, "{reached}");
    let second = superimpose(&mut run, SLAVE, 1.0, 20.0);
    assert_eq!(second.error_id, 0);
    assert_eq!(outcome(&run, first.command_id), CommandView::Aborted);
    let mut last = slave(&run).setpoint();
    for _ in 0..1000 {
        run.step();
        let now = slave(&run).setpoint();
        // No jump at the switch: within the velocity reached plus what changes in a tick.
        assert!(
            (now.position - last.position).abs() < 0.1,
            "{last:?} -> {now:?}"
        );
        last = now;
    }
    assert_eq!(outcome(&run, second.command_id), CommandView::Done);
    assert!((slave(&run).superimposed_offset() - (reached + 1.0)).abs() < 1e-9);
}

#[test]
fn the_coupling_end_keeps_the_offset_and_a_free_axis_refuses() {
    let mut run = coupled();
    // A free axis (the master) and limits beyond the axis's are refused, nothing changes.
    let free = superimpose(&mut run, MASTER, 1.0, 10.0);
    assert_eq!(free.error_id, AxisError::SuperimposedNotCoupled.raw());
    let bad = superimpose(&mut run, SLAVE, 1.0, 0.0);
    assert_eq!(bad.error_id, AxisError::InvalidVelocity.raw());
    let nan = superimpose(&mut run, SLAVE, f64::NAN, 10.0);
    assert_eq!(nan.error_id, AxisError::TargetOutsideLimits.raw());
    // On top of the cam's 20 mm/s, the axis's 2000 mm/s leave less than 1990 to the move;
    // an end beyond the software limit (1e5) is refused before it starts.
    let fast = superimpose(&mut run, SLAVE, 1.0, 1990.0);
    assert_eq!(fast.error_id, AxisError::InvalidVelocity.raw());
    let far = superimpose(&mut run, SLAVE, 2e5, 10.0);
    assert_eq!(far.error_id, AxisError::TargetOutsideLimits.raw());
    assert_eq!(slave(&run).superimposed_offset(), 0.0);
    // Half-way through a move the slave is decoupled: the move is aborted, the slave goes on
    // from where it stood with the offset, without a jump.
    let running = superimpose(&mut run, SLAVE, 5.0, 50.0);
    for _ in 0..60 {
        run.step();
    }
    let before = slave(&run).setpoint();
    assert_eq!(call(&mut run, SLAVE as u32, CamOutCall::default()), 0);
    assert_eq!(outcome(&run, running.command_id), CommandView::Aborted);
    run.step();
    let after = slave(&run).setpoint();
    assert!(slave(&run).coupling().is_none());
    assert_eq!(slave(&run).superimposed_offset(), 0.0);
    let expected = before.position + before.velocity * 0.001;
    assert!(
        (after.position - expected).abs() < 1e-3,
        "{before:?} -> {after:?}"
    );
}

/// MC_Power off while a superimposed move runs on a slave whose master stands is refused
/// (the axis moves: 0x4234); once the move is done it is taken, and the move's state is
/// cleared with the coupling.
#[test]
fn power_off_waits_for_a_running_superimposed_move() {
    let mut run = machine();
    run.step();
    select_cyclic(&mut run, 3);
    assert_eq!(call(&mut run, SLAVE as u32, cam_in(3)), 0);
    run.step();
    let shift = superimpose(&mut run, SLAVE, 2.0, 50.0);
    assert_eq!(shift.error_id, 0);
    run.step();
    let off = AxisCommandCall::power(false);
    let refused = run.call(SLAVE as u32, &off).unwrap();
    assert_eq!(refused.error_id, AxisError::MovingWhileDisable.raw());
    while slave(&run).drive_state().superimposed_id_r == shift.command_id {
        run.step();
    }
    assert_eq!(run.call(SLAVE as u32, &off).unwrap().error_id, 0);
    run.step();
    assert!(slave(&run).coupling().is_none());
    assert_eq!(slave(&run).drive_state().superimposed_id_r, 0);
    assert_eq!(slave(&run).superimposed_offset(), 0.0);
}
