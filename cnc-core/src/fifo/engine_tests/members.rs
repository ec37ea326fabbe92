//! The FIFO group's members (integration, faults, commands that keep an axis out), its status
//! and dimension reads, and how its calls are refused.

use super::*;
use hli::calls::CallKind;
use hli::enums::{AxisError, CouplingState};
use hli::views::CncView;

/// A moving axis does not join; a PTP command to a member is refused as coupled; after
/// FiFoGroupDisintegrate the axes are free PTP axes again.
#[test]
fn integration_couples_and_disintegration_frees() {
    let mut run = machine(instant(16, 1.0));
    let limits = [50.0, 1000.0, 1000.0, 10000.0];
    assert_eq!(
        axis_command(
            &mut run,
            FREE as u32,
            AxisCommandCall::move_velocity(1, limits)
        ),
        0
    );
    run.step();
    run.step();
    let r = call(
        &mut run,
        0,
        FifoIntegrateCall {
            axis: FREE as u32,
            group_position: 1,
        },
    );
    assert_eq!(r.error_id, FifoError::AxisMoving.raw());
    integrate(&mut run);
    run.step();
    let axis_state = |run: &Harness, axis| run.plc_view().axis_state(axis).unwrap();
    assert_eq!(
        axis_state(&run, 0).coupling_state_r,
        CouplingState::Fifo.raw()
    );
    assert_eq!(status(&run).axis_count_r, 3);
    let r = axis_command(&mut run, 0, AxisCommandCall::move_absolute(5.0, limits));
    assert_eq!(r, AxisError::Coupled.raw());
    assert_eq!(
        call(&mut run, 0, FifoDisintegrateCall::default()).error_id,
        0
    );
    run.step();
    assert_eq!(
        axis_state(&run, 0).coupling_state_r,
        CouplingState::Uncoupled.raw()
    );
    assert_eq!(
        axis_command(&mut run, 0, AxisCommandCall::move_absolute(5.0, limits)),
        0
    );
}

/// A member that faults (here: Y runs into its soft limit) ends the job: Error with
/// AxisFault, the other members leave the group and stop on their own; a new integration
/// clears the error.
#[test]
fn a_faulted_member_ends_the_job() {
    let mut run = machine_y(instant(600, 1.0), |y| y.soft_limits = Some([-10.0, 1.0]));
    integrate(&mut run);
    let rows: Vec<[f64; 3]> = (0..500).map(|k| [k as f64 * 0.05; 3]).collect();
    write(&mut run, &rows, false);
    start(&mut run);
    let mut ticks = 0;
    loop {
        run.step();
        ticks += 1;
        if status(&run).group_state_r != FifoGroupState::Running.raw() {
            break;
        }
        assert!(ticks < 100, "Y never reached its limit");
    }
    assert!(
        (20..=22).contains(&ticks),
        "Y passes 1.0 at tick 20: {ticks}"
    );
    assert!(
        velocity(&run, 0) > 0.0,
        "X goes on as a free axis and stops by itself"
    );
    let s = status(&run);
    assert_eq!(s.group_state_r, FifoGroupState::Error.raw());
    assert_eq!(s.error_id_r, FifoError::AxisFault.raw());
    assert_eq!((s.axis_count_r, s.entries_r), (0, 0));
    assert_eq!(
        write(&mut run, &rows[..2], false).error_id,
        FifoError::AxisFault.raw()
    );
    let mut ticks = 0;
    while velocity(&run, 0) != 0.0 {
        run.step();
        ticks += 1;
        assert!(ticks < 5000, "the other members never stopped");
    }
    let r = call(
        &mut run,
        0,
        FifoIntegrateCall {
            axis: 0,
            group_position: 1,
        },
    );
    assert_eq!(r.error_id, 0);
    assert_eq!(
        status_after_tick(&mut run).group_state_r,
        FifoGroupState::Idle.raw()
    );
}

fn status_after_tick(run: &mut Harness) -> hli::layout::HliFifoGroupState {
    run.step();
    status(run)
}

/// FiFoGetDimension gives N and Z; a stopped machine still answers it.
#[test]
fn get_dimension() {
    let mut run = machine(instant(250, 2.0));
    let r = call(&mut run, 0, FifoDimensionCall::default());
    assert_eq!((r.error_id, r.dimension, r.capacity), (0, 3, 250));
    run.machine.stop("test");
    let r = call(&mut run, 0, FifoDimensionCall::default());
    assert_eq!(r.dimension, 3);
    assert_eq!(
        write(&mut run, &[[0.0; 3]], false).error_id,
        hli::calls::ErrorCode::Busy.raw()
    );
}

/// FiFoOverwrite on a group not started replaces every queued row; on a running group that
/// holds its last row (dry), it keeps that row.
#[test]
fn overwrite_before_the_start_and_when_dry() {
    let mut run = machine(instant(16, 1.0));
    integrate(&mut run);
    write(&mut run, &[[0.0; 3], [5.0; 3], [9.0; 3]], false);
    let r = write(&mut run, &[[0.0; 3], [1.0; 3]], true);
    assert_eq!((r.error_id, r.entries), (0, 2));
    start(&mut run);
    run.step();
    run.step();
    assert_eq!(position(&run, 0), 1.0, "the replaced rows, not 5 and 9");
    // Dry: one row (1.0) held; an overwrite keeps it and goes on from it.
    let r = write(&mut run, &[[1.5; 3], [2.0; 3]], true);
    assert_eq!((r.error_id, r.entries), (0, 3));
    run.step();
    assert_eq!(position(&run, 0), 1.5);
    let s = status_after_tick(&mut run);
    assert!(s.rows_written_r >= s.rows_consumed_r);
    assert_eq!(s.rows_written_r, 4, "0, 1 and the two overwritten rows");
}

/// A stop that ends by a fault or a machine stop gives the override back as well; a new job
/// starts with its counters at 0; dissolving drops the queued rows.
#[test]
fn a_stop_cut_short_keeps_the_override_and_counters_restart() {
    let mut run = machine_y(instant(600, 1.0), |y| y.soft_limits = Some([-10.0, 1.0]));
    pt2(&mut run, 0.5);
    integrate(&mut run);
    let rows: Vec<[f64; 3]> = (0..500).map(|k| [k as f64 * 0.05; 3]).collect();
    write(&mut run, &rows, false);
    call(
        &mut run,
        0,
        FifoOverrideCall {
            override_ppm: 900_000,
        },
    );
    start(&mut run);
    run.steps(15);
    assert_eq!(call(&mut run, 0, FifoStopCall::default()).error_id, 0);
    // The slow PT-2 stop still moves Y past its limit of 1.0: the fault ends the job.
    let mut ticks = 0;
    while status(&run).group_state_r != FifoGroupState::Error.raw() {
        run.step();
        ticks += 1;
        assert!(ticks < 2000, "no fault");
    }
    let s = status(&run);
    assert_eq!(
        (s.override_target_r, s.rows_consumed_r, s.rows_written_r),
        (900_000, 0, 0)
    );
    // Machine stop while stopping.
    let mut run = machine(instant(600, 1.0));
    pt2(&mut run, 0.5);
    integrate(&mut run);
    write(&mut run, &rows, false);
    call(
        &mut run,
        0,
        FifoOverrideCall {
            override_ppm: 700_000,
        },
    );
    start(&mut run);
    run.steps(15);
    call(&mut run, 0, FifoStopCall::default());
    run.step();
    run.machine.stop("test");
    let s = status_after_tick(&mut run);
    assert_eq!(s.group_state_r, FifoGroupState::Idle.raw());
    assert_eq!((s.override_target_r, s.rows_consumed_r), (700_000, 0));
    // Dissolving drops rows.
    let mut run = machine(instant(16, 1.0));
    integrate(&mut run);
    write(&mut run, &[[0.0; 3], [1.0; 3]], false);
    let r = call(&mut run, 0, FifoDisintegrateCall::default());
    assert_eq!((r.error_id, r.entries), (0, 0));
    let s = status_after_tick(&mut run);
    assert_eq!(s.group_state_r, FifoGroupState::Idle.raw());
}

/// An axis with a command that has not moved it yet does not join (coupling would abort the
/// command without a word).
#[test]
fn an_axis_with_an_active_command_does_not_join() {
    let mut run = machine(instant(16, 1.0));
    let command = AxisCommandCall::move_absolute(5.0, [50.0, 1000.0, 1000.0, 10000.0]);
    assert_eq!(axis_command(&mut run, FREE as u32, command), 0);
    let r = call(
        &mut run,
        0,
        FifoIntegrateCall {
            axis: FREE as u32,
            group_position: 1,
        },
    );
    assert_eq!(r.error_id, FifoError::AxisMoving.raw());
}

/// Row blocks come by the bulk service only: the same kind in a frame is refused, and so is
/// a bulk call of a kind that has no bulk handler.
#[test]
fn row_blocks_come_by_the_bulk_service_only() {
    use hli::calls::ErrorCode;
    let mut run = machine(instant(250, 2.0));
    let request = hli::wire::AcyclicRequest {
        invoke_id: 0,
        kind: CallKind::FIFO_WRITE_ROWS.raw(),
        target: 0,
        body_len: 4,
        body: [0; hli::wire::ACYCLIC_BODY_SIZE],
    };
    let view = CncView::new(&run.memory);
    let framed = run
        .machine
        .dispatch(&view, CallKind::FIFO_WRITE_ROWS, &request);
    assert_eq!(framed.unwrap_err(), ErrorCode::ServiceNotSupported);
    let header = BulkHeader {
        kind: CallKind::FIFO_START.raw(),
        target: 0,
        columns: 3,
        rows: 1,
    };
    let bulk = run.machine.dispatch_bulk(&header, &[0.0; 3]);
    assert_eq!(bulk.unwrap_err(), ErrorCode::ServiceNotSupported);
    // A machine without FIFO groups has no engine for row blocks: refused as any FIFO call.
    let mut bare = crate::machine::Machine::new(crate::machine::MachineSetup {
        channels: Vec::new(),
        axes: Vec::new(),
        engines: Vec::new(),
        cycle_s: TICK,
    })
    .unwrap();
    let rows = bare.dispatch_bulk(&rows_header(0, 3, 1, false), &[0.0; 3]);
    assert_eq!(rows.unwrap_err(), ErrorCode::ServiceNotSupported);
}
