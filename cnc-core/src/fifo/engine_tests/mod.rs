//! The FIFO engine in the machine tick (seed 002): a group of three single axes driven by
//! rows, checked tick by tick against the interpolation of the rows; the override (instant
//! and PT-2) on the velocity; whole-block refusal, underrun and the end at rest; FiFoStop;
//! every refusal with its code while the queued rows stay as they were; a faulted member
//! ending the job. On the library's [`Harness`]: the machine a scenario with these axes, a
//! gear and one `[[fifo_group]]` makes, built here in Rust.

use crate::axis::config::AxisConfig;
use crate::cam::machine::CamEngine;
use crate::cam::online::CamStore;
use crate::fifo::machine::FifoEngine;
use crate::fifo::{FifoParams, OverrideType};
use crate::gear::{GearEngine, GearSpec};
use crate::harness::Harness;
use crate::machine::Engine;
use crate::saw::machine::SawEngine;
use hli::calls::axis::AxisCommandCall;
use hli::calls::fifo::FifoError;
use hli::calls::fifo::{
    rows_header, FifoDimensionCall, FifoDisintegrateCall, FifoIntegrateCall, FifoOverrideCall,
    FifoOverrideType, FifoParametersCall, FifoReply, FifoStartCall, FifoStopCall,
    FifoWriteRowsCall,
};
use hli::calls::{decode_reply, AcyclicCall};
use hli::enums::FifoGroupState;
use hli::layout::{FIFO_FLAG_AT_END, FIFO_FLAG_UNDERRUN};
use hli::wire::BulkHeader;

const TICK: f64 = 0.001;
/// Axes 0..3 form the group; 3 is free; 4 is a gear slave of 3.
const FREE: usize = 3;
const GEAR_SLAVE: usize = 4;
/// X, Y, Z, W, S.
const AXES: usize = 5;

fn machine(group: FifoParams) -> Harness {
    machine_y(group, |_| {})
}

/// With `y` applied to axis Y's configuration.
fn machine_y(group: FifoParams, y: impl FnOnce(&mut AxisConfig)) -> Harness {
    let mut run = Harness::new(TICK, axes(y), engines(group)).unwrap();
    run.power_all();
    run.step();
    run
}

/// X, Y and Z (2000 /s, a following error limit of 100), W and S with the defaults of a
/// linear axis, IDs 1 to 5; `y` applied to Y.
fn axes(y: impl FnOnce(&mut AxisConfig)) -> Vec<AxisConfig> {
    let mut axes: Vec<AxisConfig> = ["X", "Y", "Z", "W", "S"]
        .into_iter()
        .zip(1..)
        .map(|(name, id)| AxisConfig::linear(name, id))
        .collect();
    for a in &mut axes[..3] {
        a.dynamics.velocity = 2000.0;
        a.following_error_limit = 100.0;
    }
    y(&mut axes[1]);
    axes
}

/// The engines of a machine with a gear (S follows W at ratio 2) and one FIFO group, in
/// their tick order: gear, cam, FIFO, saw.
fn engines(group: FifoParams) -> Vec<Box<dyn Engine>> {
    let gear = GearSpec {
        master: FREE,
        slave: GEAR_SLAVE,
        ratio: 2.0,
    };
    vec![
        Box::new(GearEngine::new(&[gear], AXES).unwrap()),
        Box::new(CamEngine::new(CamStore::new(), AXES)),
        Box::new(FifoEngine::new(&[group], TICK).unwrap()),
        Box::new(SawEngine::new(AXES, TICK)),
    ]
}

/// A group of three axes with the instant override, `rows` rows, T_f of `t_f_ms`.
fn instant(rows: usize, t_f_ms: f64) -> FifoParams {
    FifoParams::new(3, rows, t_f_ms * 1e-3, OverrideType::Instant).unwrap()
}

fn call<C: AcyclicCall<Reply = FifoReply>>(run: &mut Harness, group: u32, body: C) -> FifoReply {
    run.call(group, &body).expect("answered")
}

/// An axis command as MC_* sends it: the axis layer's error id.
fn axis_command(run: &mut Harness, axis: u32, command: AxisCommandCall) -> u32 {
    run.call(axis, &command).expect("answered").error_id
}

fn write(run: &mut Harness, rows: &[[f64; 3]], overwrite: bool) -> FifoReply {
    let values: Vec<f64> = rows.iter().flatten().copied().collect();
    let header = rows_header(0, 3, rows.len() as u32, overwrite);
    bulk(run, &header, &values)
}

/// A bulk call (a row block) answered by the machine, as the PLC's block reads it: a
/// refused call as its error id.
fn bulk(run: &mut Harness, header: &BulkHeader, values: &[f64]) -> FifoReply {
    match run.machine.dispatch_bulk(header, values) {
        Ok((body, len)) => decode_reply::<FifoWriteRowsCall>(&body, len).unwrap(),
        Err(code) => FifoReply {
            error_id: code.raw(),
            ..FifoReply::default()
        },
    }
}

fn integrate(run: &mut Harness) {
    for axis in 0..3 {
        let r = call(
            run,
            0,
            FifoIntegrateCall {
                axis,
                group_position: axis + 1,
            },
        );
        assert_eq!(r.error_id, 0, "integrate {axis}");
    }
}

fn start(run: &mut Harness) -> FifoReply {
    call(run, 0, FifoStartCall::default())
}

fn position(run: &Harness, axis: usize) -> f64 {
    run.setpoint(axis).position
}

fn velocity(run: &Harness, axis: usize) -> f64 {
    run.setpoint(axis).velocity
}

fn status(run: &Harness) -> hli::layout::HliFifoGroupState {
    run.plc_view().fifo_group(0).unwrap()
}

/// Rows k = 0..n of a smooth 3-axis contour starting at the origin.
fn contour(n: usize) -> Vec<[f64; 3]> {
    (0..n)
        .map(|k| {
            let t = k as f64 * 0.05;
            [10.0 * t * t, 5.0 * (1.0 - t.cos()), -3.0 * t]
        })
        .collect()
}

fn lerp(rows: &[[f64; 3]], t_over_tf: f64, axis: usize) -> f64 {
    let k = (t_over_tf.floor() as usize).min(rows.len() - 1);
    if k + 1 >= rows.len() {
        return rows[k][axis];
    }
    rows[k][axis] + (t_over_tf - k as f64) * (rows[k + 1][axis] - rows[k][axis])
}

/// The axes' set-points tick by tick are the rows interpolated at `n x tick`, for T_f of
/// 1, 3 and 2.5 ticks (fine interpolation, also at a ratio that is not a whole number).
#[test]
fn set_points_interpolate_the_rows() {
    for t_f_ms in [1.0, 3.0, 2.5, 0.4] {
        let mut run = machine(instant(64, t_f_ms));
        integrate(&mut run);
        let rows = contour(40);
        assert_eq!(write(&mut run, &rows, false).error_id, 0);
        assert_eq!(start(&mut run).error_id, 0);
        let ratio = TICK / (t_f_ms * 1e-3);
        let ticks = ((rows.len() - 1) as f64 / ratio).ceil() as usize;
        for n in 1..=ticks {
            run.step();
            for axis in 0..3 {
                let want = lerp(&rows, n as f64 * ratio, axis);
                let got = position(&run, axis);
                assert!(
                    (got - want).abs() < 1e-9,
                    "T_f {t_f_ms} ms, tick {n}, axis {axis}: {got} vs {want}"
                );
            }
        }
        let s = status(&run);
        assert_eq!(s.rows_consumed_r, rows.len() as u64 - 1, "T_f {t_f_ms}");
        assert_eq!(s.entries_r, 1, "the last row stays as the held position");
    }
}

/// Override 40 %: the job time runs at 0.4 x real time, so velocities are 0.4 x the rows'.
#[test]
fn override_scales_velocity() {
    let mut run = machine(instant(64, 1.0));
    integrate(&mut run);
    let rows: Vec<[f64; 3]> = (0..50)
        .map(|k| [k as f64 * 0.2, 0.0, -(k as f64) * 0.1])
        .collect();
    write(&mut run, &rows, false);
    let r = call(
        &mut run,
        0,
        FifoOverrideCall {
            override_ppm: 400_000,
        },
    );
    assert_eq!(r.error_id, 0, "an override may be set before the start");
    start(&mut run);
    run.steps(20);
    // Rows move X by 0.2 per ms = 200 /s, Z by -100 /s.
    assert!(
        (velocity(&run, 0) - 0.4 * 200.0).abs() < 1e-6,
        "{}",
        velocity(&run, 0)
    );
    assert!((velocity(&run, 2) + 0.4 * 100.0).abs() < 1e-6);
    assert_eq!(status(&run).override_r, 400_000);
    // 0 % stops the axes and keeps the job.
    call(&mut run, 0, FifoOverrideCall { override_ppm: 0 });
    run.step();
    let held = position(&run, 0);
    run.steps(5);
    assert_eq!((position(&run, 0), velocity(&run, 0)), (held, 0.0));
    assert_eq!(status(&run).group_state_r, FifoGroupState::Running.raw());
    // Above 100 % is refused.
    let r = call(
        &mut run,
        0,
        FifoOverrideCall {
            override_ppm: 1_000_001,
        },
    );
    assert_eq!(r.error_id, FifoError::Override.raw());
}

fn pt2(run: &mut Harness, t0_s: f64) {
    let r = call(
        run,
        0,
        FifoParametersCall {
            fifo_cycle_s: 0.001,
            pt2_t0_s: t0_s,
            override_type: FifoOverrideType::Pt2.raw(),
            reserved: 0,
        },
    );
    assert_eq!(r.error_id, 0);
}

/// PT-2: an override step from 100 % to 20 % changes the velocity without a step (the
/// largest change per tick is a fraction of the instant override's one jump) and settles.
#[test]
fn pt2_override_is_continuous_and_settles() {
    let rows: Vec<[f64; 3]> = (0..2000).map(|k| [k as f64 * 0.1, 0.0, 0.0]).collect();
    let mut jumps = Vec::new();
    for kind in [FifoOverrideType::Instant.raw(), FifoOverrideType::Pt2.raw()] {
        let mut run = machine(instant(4000, 1.0));
        if kind == FifoOverrideType::Pt2.raw() {
            pt2(&mut run, 0.02);
        }
        integrate(&mut run);
        write(&mut run, &rows, false);
        start(&mut run);
        run.steps(10);
        call(
            &mut run,
            0,
            FifoOverrideCall {
                override_ppm: 200_000,
            },
        );
        let mut before = velocity(&run, 0);
        let mut largest: f64 = 0.0;
        for _ in 0..400 {
            run.step();
            largest = largest.max((velocity(&run, 0) - before).abs());
            before = velocity(&run, 0);
        }
        assert!(
            (velocity(&run, 0) - 20.0).abs() < 1e-6,
            "settled at 20 % of 100 /s"
        );
        assert_eq!(status(&run).override_r, 200_000);
        jumps.push(largest);
    }
    // Instant: one jump of 80 /s. PT-2 (T0 = 20 ticks): at most 80 / (e x 20) ~ 1.5 /s.
    assert!((jumps[0] - 80.0).abs() < 1e-6, "{jumps:?}");
    assert!(jumps[1] < 1.6, "{jumps:?}");
}

/// A block is queued whole or refused whole; the fill level is in the image every tick.
#[test]
fn a_block_that_does_not_fit_is_refused_whole() {
    let mut run = machine(instant(10, 1.0));
    let rows = vec![[0.0; 3]; 8];
    let r = write(&mut run, &rows, false);
    assert_eq!((r.error_id, r.entries, r.free), (0, 8, 2));
    let r = write(&mut run, &rows[..3], false);
    assert_eq!((r.error_id, r.entries), (FifoError::Full.raw(), 8));
    assert_eq!(write(&mut run, &rows[..2], false).entries, 10);
    run.step();
    let s = status(&run);
    assert_eq!((s.entries_r, s.free_r, s.capacity_r), (10, 0, 10));
    assert_eq!(s.group_state_r, FifoGroupState::Filling.raw());
    assert_eq!(s.rows_written_r, 10);
}

/// FiFoOverwrite keeps the pair the group interpolates between and replaces the rest.
#[test]
fn overwrite_replaces_the_queued_rows() {
    let mut run = machine(instant(16, 2.0));
    integrate(&mut run);
    write(
        &mut run,
        &[[0.0; 3], [1.0; 3], [2.0; 3], [3.0; 3], [4.0; 3]],
        false,
    );
    start(&mut run);
    run.step(); // half way between rows 0 and 1
    let r = write(&mut run, &[[1.5; 3], [2.0; 3]], true);
    assert_eq!((r.error_id, r.entries), (0, 4));
    let mut seen = Vec::new();
    for _ in 0..6 {
        run.step();
        seen.push(position(&run, 0));
    }
    assert_eq!(seen, [1.0, 1.25, 1.5, 1.75, 2.0, 2.0]);
}

/// The FIFO runs dry while moving: the axes hold the last row, the group keeps running
/// and goes on when rows come; rows that end at rest are the normal end.
#[test]
fn underrun_holds_then_resumes() {
    let mut run = machine(instant(16, 1.0));
    integrate(&mut run);
    write(&mut run, &[[0.0; 3], [0.5; 3], [1.0; 3]], false);
    start(&mut run);
    run.steps(4);
    let s = status(&run);
    assert_eq!(s.flags_r & FIFO_FLAG_UNDERRUN, FIFO_FLAG_UNDERRUN);
    assert_eq!(s.group_state_r, FifoGroupState::Running.raw());
    assert_eq!(s.underrun_ticks_r, 2);
    assert_eq!((position(&run, 1), velocity(&run, 1)), (1.0, 0.0));
    write(&mut run, &[[1.5; 3], [2.0; 3], [2.0; 3]], false);
    run.step();
    assert_eq!(position(&run, 1), 1.5, "goes on from the held row, no jump");
    run.steps(3);
    let s = status(&run);
    assert_eq!(
        s.flags_r & (FIFO_FLAG_UNDERRUN | FIFO_FLAG_AT_END),
        FIFO_FLAG_AT_END
    );
    assert_eq!(s.rows_consumed_r, 5);
}

/// FiFoStop: instant ends the job in the next tick (rows dropped, Idle, axes standing);
/// PT-2 brings the axes down smoothly first. No override change is taken while stopping;
/// the override set before the stop is in effect again for the next job.
#[test]
fn stop_ends_the_job() {
    for pt2_t0 in [None, Some(0.01)] {
        let mut run = machine(instant(600, 1.0));
        if let Some(t0) = pt2_t0 {
            pt2(&mut run, t0);
        }
        integrate(&mut run);
        let rows: Vec<[f64; 3]> = (0..500).map(|k| [k as f64 * 0.05; 3]).collect();
        write(&mut run, &rows, false);
        call(
            &mut run,
            0,
            FifoOverrideCall {
                override_ppm: 800_000,
            },
        );
        start(&mut run);
        run.steps(20);
        assert_eq!(call(&mut run, 0, FifoStopCall::default()).error_id, 0);
        let r = call(
            &mut run,
            0,
            FifoOverrideCall {
                override_ppm: 500_000,
            },
        );
        assert_eq!(r.error_id, FifoError::Stopping.raw());
        let r = write(&mut run, &rows[..1], false);
        assert_eq!(r.error_id, FifoError::Stopping.raw());
        let mut ticks = 0;
        let mut before = velocity(&run, 0);
        let mut largest: f64 = 0.0;
        while status(&run).group_state_r != FifoGroupState::Idle.raw() {
            run.step();
            largest = largest.max((velocity(&run, 0) - before).abs());
            before = velocity(&run, 0);
            ticks += 1;
            assert!(ticks < 2000, "the stop never ended");
        }
        let s = status(&run);
        assert_eq!((s.entries_r, s.rows_written_r), (0, 0));
        assert_eq!(s.override_r, 800_000, "the override before the stop");
        assert_eq!(velocity(&run, 0), 0.0);
        match pt2_t0 {
            None => assert_eq!(ticks, 1),
            Some(_) => {
                assert!(ticks > 50, "{ticks}");
                assert!(
                    largest < 1.5,
                    "no velocity step (40 /s before the stop): {largest}"
                );
            }
        }
        // A restart after the stop (the manual: stop, then the group may go on or be
        // dissolved): new rows from where the axes stand, FiFoStart, the job runs to its
        // end at the override set before the stop, its counters from 0.
        let here: Vec<f64> = (0..3).map(|c| position(&run, c)).collect();
        let again: Vec<[f64; 3]> = (0..60)
            .map(|k| core::array::from_fn(|c| here[c] + (k.min(50) as f64) * 0.02))
            .collect();
        assert_eq!(write(&mut run, &again, false).error_id, 0);
        assert_eq!(start(&mut run).error_id, 0);
        let mut ticks = 0;
        while status(&run).flags_r & FIFO_FLAG_AT_END == 0 {
            run.step();
            ticks += 1;
            assert!(ticks < 2000, "the restarted job never ended");
        }
        assert!((position(&run, 0) - (here[0] + 1.0)).abs() < 1e-9);
        let s = status(&run);
        assert_eq!(s.override_r, 800_000);
        assert_eq!(s.group_state_r, FifoGroupState::Running.raw());
    }
}

/// Refusals, each with its code; the queued rows stay as they were.
#[test]
fn refusals_leave_the_rows_alone() {
    let mut run = machine(instant(16, 1.0));
    assert_eq!(start(&mut run).error_id, FifoError::GroupIncomplete.raw());
    integrate(&mut run);
    assert_eq!(start(&mut run).error_id, FifoError::Empty.raw());
    write(&mut run, &[[0.0; 3], [1.0; 3]], false);
    let entries = |run: &mut Harness| call(run, 0, FifoDimensionCall::default()).entries;
    assert_eq!(entries(&mut run), 2);

    let mut bad = [[2.0; 3], [3.0; 3]];
    bad[1][2] = f64::NAN;
    let r = write(&mut run, &bad, false);
    assert_eq!(
        (r.error_id, r.row, r.column),
        (FifoError::NonFinite.raw(), 1, 2)
    );
    assert_eq!(entries(&mut run), 2);
    bad[1][2] = f64::INFINITY;
    assert_eq!(
        write(&mut run, &bad, true).error_id,
        FifoError::NonFinite.raw()
    );
    assert_eq!(entries(&mut run), 2, "a refused overwrite drops nothing");
    let header = rows_header(0, 2, 3, false);
    let r = bulk(&mut run, &header, &[0.0; 6]);
    assert_eq!(r.error_id, FifoError::Columns.raw());
    assert_eq!(entries(&mut run), 2);
    let header = BulkHeader {
        target: 5,
        ..header
    };
    let r = bulk(&mut run, &header, &[0.0; 6]);
    assert_eq!(r.error_id, FifoError::NoSuchGroup.raw());
    assert_eq!(
        write(&mut run, &[], false).error_id,
        FifoError::BlockSize.raw()
    );
    assert_eq!(entries(&mut run), 2);
    let r = call(&mut run, 3, FifoStartCall::default());
    assert_eq!(r.error_id, FifoError::NoSuchGroup.raw());
    for (t_f, t0, kind) in [
        (0.0, 0.01, 0),
        (-1.0, 0.01, 0),
        (f64::NAN, 0.01, 0),
        (0.001, 0.0, 1),
        (0.001, 0.01, 7),
        (0.001, 1e-300, 1),
        (0.001, 1e20, 1),
    ] {
        let r = call(
            &mut run,
            0,
            FifoParametersCall {
                fifo_cycle_s: t_f,
                pt2_t0_s: t0,
                override_type: kind,
                reserved: 0,
            },
        );
        assert_eq!(r.error_id, FifoError::Parameter.raw(), "{t_f} {t0} {kind}");
    }
    assert_eq!(entries(&mut run), 2);

    // Integration: taken positions, a group member, a coupled axis, a moving axis, no axis.
    let integrate_call = |axis, group_position| FifoIntegrateCall {
        axis,
        group_position,
    };
    let r = call(&mut run, 0, integrate_call(FREE as u32, 2));
    assert_eq!(r.error_id, FifoError::PositionTaken.raw());
    let r = call(&mut run, 0, integrate_call(FREE as u32, 4));
    assert_eq!(r.error_id, FifoError::GroupPosition.raw());
    let r = call(&mut run, 0, integrate_call(1, 2));
    assert_eq!(r.error_id, FifoError::AxisInGroup.raw());
    let r = call(&mut run, 0, integrate_call(GEAR_SLAVE as u32, 1));
    assert_eq!(r.error_id, FifoError::AxisCoupled.raw());
    let r = call(&mut run, 0, integrate_call(17, 1));
    assert_eq!(r.error_id, FifoError::NoSuchAxis.raw());

    // The first row must be where the axes stand.
    call(&mut run, 0, FifoStopCall::default()); // drops the rows of a group not started
    write(&mut run, &[[0.0, 0.5, 0.0], [1.0; 3]], false);
    let r = start(&mut run);
    assert_eq!((r.error_id, r.column), (FifoError::StartMismatch.raw(), 1));
    assert_eq!(entries(&mut run), 2);

    // Running: no integration, no parameters, no second start.
    write(&mut run, &[[0.0; 3], [0.0; 3]], true);
    assert_eq!(start(&mut run).error_id, 0);
    assert_eq!(start(&mut run).error_id, FifoError::Running.raw());
    let r = call(&mut run, 0, FifoDisintegrateCall::default());
    assert_eq!(r.error_id, FifoError::Running.raw());
    let r = call(
        &mut run,
        0,
        FifoParametersCall {
            fifo_cycle_s: 0.002,
            pt2_t0_s: 0.0,
            override_type: 0,
            reserved: 0,
        },
    );
    assert_eq!(r.error_id, FifoError::Running.raw());
}

mod manual_gaps;
mod members;
