//! The flying-saw engine in the machine tick (seed 001): position sync exactly at the sync
//! positions, to the tick; MC_GearOut leaves the slave at its velocity; the eight rollback
//! cases of chapter 8 and the new synchronisation after one; refusals that leave the slave
//! moving as before; the internal table rule; the characteristic values over the call; the
//! diagonal saw; the time-based phase.

use super::{command, machine, phase, saw_axis, set, started, velocity_call, MASTER, SAW, TICK};
use crate::axis::config::AxisConfig;
use crate::cam::machine::CamEngine;
use crate::cam::online::CamStore;
use crate::gear::{GearEngine, GearSpec};
use crate::harness::Harness;
use crate::machine::Engine;
use crate::saw;
use crate::saw::machine::SawEngine;
use hli::calls::axis::AxisCommandCall;
use hli::calls::saw::SawError;
use hli::calls::saw::{
    sync_mask as m, SawCharacCall, SawGearInCall, SawGearOutCall, SawSyncMode, SawSyncTarget,
};
use hli::enums::{AxisError, AxisState, CouplingState};
use hli::layout::HliAxisLrState;

const LIMITS: [f64; 4] = [2000.0, 10000.0, 10000.0, 1e6];

/// Master (ID 1), Saw (ID 2) and `third`, with the gear engine of `gears` (none without),
/// the cam engine holding `cams` and the saw engine, in the engine set's order; after its
/// first tick.
fn three_axes(third: AxisConfig, gears: &[GearSpec], cams: CamStore) -> Harness {
    let axes = vec![saw_axis("Master", 1), saw_axis("Saw", 2), third];
    let n = axes.len();
    let mut engines: Vec<Box<dyn Engine>> = Vec::new();
    if !gears.is_empty() {
        engines.push(Box::new(GearEngine::new(gears, n).unwrap()));
    }
    engines.push(Box::new(CamEngine::new(cams, n)));
    engines.push(Box::new(SawEngine::new(n, TICK)));
    started(Harness::new(TICK, axes, engines).unwrap())
}

/// The machine with a third axis "Other" of ID 254 and the cam table
/// `scenarios/cams/stroke_table.json` under the ID its file gives.
fn with_stroke_table() -> Harness {
    let path = tests::cli::repo_root().join("scenarios/cams/stroke_table.json");
    let cam = crate::cam::file::parse(&std::fs::read(path).unwrap(), Default::default()).unwrap();
    let mut cams = CamStore::new();
    cams.insert(cam.id.expect("the file gives its ID"), cam.profile)
        .unwrap();
    three_axes(saw_axis("Other", 254), &[], cams)
}

/// The machine with a third axis "Geared" (ID 3) geared to the master with ratio 2.
fn with_gear() -> Harness {
    let gear = GearSpec {
        master: MASTER,
        slave: 2,
        ratio: 2.0,
    };
    three_axes(saw_axis("Geared", 3), &[gear], CamStore::new())
}

fn gear_in(run: &mut Harness, slave: usize, call: SawGearInCall) -> u32 {
    run.call(slave as u32, &call).unwrap().error_id
}

fn gear_out(run: &mut Harness, slave: usize) -> u32 {
    run.call(slave as u32, &SawGearOutCall::default())
        .unwrap()
        .error_id
}

fn image(run: &Harness, axis: usize) -> HliAxisLrState {
    run.plc_view().axis_state(axis).unwrap()
}

/// Master at +500 mm/s, the saw at `slave_velocity`, both at constant velocity.
fn moving(slave_velocity: f64) -> Harness {
    let mut run = machine();
    assert_eq!(
        command(
            &mut run,
            MASTER,
            AxisCommandCall::move_velocity(1, [500.0, 10000.0, 10000.0, 1e6])
        ),
        0
    );
    let dir = if slave_velocity < 0.0 { -1 } else { 1 };
    if slave_velocity != 0.0 {
        let limits = [slave_velocity.abs(), 10000.0, 10000.0, 1e6];
        assert_eq!(
            command(&mut run, SAW, AxisCommandCall::move_velocity(dir, limits)),
            0
        );
    }
    run.until(2000, |r| {
        set(r, MASTER).acceleration == 0.0
            && set(r, SAW).acceleration == 0.0
            && set(r, MASTER).velocity == 500.0
    });
    run
}

fn position_call(ms: f64, ss: f64, ratio: f64, mask: u32) -> SawGearInCall {
    SawGearInCall {
        target: SawSyncTarget::Position.raw(),
        master_sync_position: ms,
        slave_sync_position: ss,
        ..velocity_call(ratio, mask)
    }
}

#[test]
fn position_sync_is_exact_at_the_tick_the_master_reaches_its_sync_position() {
    // Seed 001, position sync example 1, relative to where the axes are.
    let mut run = moving(250.0);
    let (m0, s0) = (set(&run, MASTER).position, set(&run, SAW).position);
    let (ms, ss) = (m0 + 1500.0, s0 + 1250.0);
    assert_eq!(
        gear_in(
            &mut run,
            SAW,
            position_call(ms, ss, 1.0, m::MAXACC | m::MAXDEC | m::MAXJERK)
        ),
        0
    );
    run.step();
    assert_eq!(
        image(&run, SAW).coupling_state_r,
        CouplingState::GearPosition.raw()
    );
    // Up to the last tick before the master reaches its sync position: synchronising.
    let k = run.until(4000, |r| {
        set(r, MASTER).position + 500.0 * TICK >= ms - 1e-9
    });
    assert!(k > 2900, "three seconds of master travel: {k} ticks");
    assert_eq!(phase(&run, SAW), AxisState::SlaveSynchronizing.raw());
    assert!(set(&run, SAW).position < ss);
    run.step();
    let (mp, sp) = (set(&run, MASTER), set(&run, SAW));
    assert!(mp.position >= ms - 1e-9);
    assert_eq!(phase(&run, SAW), AxisState::SlaveSynchronous.raw());
    assert!(
        (sp.position - (ss + (mp.position - ms))).abs() < 1e-9,
        "{sp:?} {mp:?}"
    );
    assert!((sp.velocity - 500.0).abs() < 1e-9);
}

#[test]
fn gear_out_leaves_the_slave_at_its_velocity_until_halted() {
    let mut run = moving(-250.0);
    assert_eq!(gear_in(&mut run, SAW, velocity_call(1.5, 0)), 0);
    run.until(5000, |r| phase(r, SAW) == AxisState::SlaveSynchronous.raw());
    assert!((set(&run, SAW).velocity - 750.0).abs() < 1e-9);
    assert_eq!(gear_out(&mut run, SAW), 0);
    assert_eq!(gear_out(&mut run, SAW), SawError::NotCoupled.raw());
    assert_eq!(
        command(&mut run, MASTER, AxisCommandCall::halt(10000.0, 1e6)),
        0
    );
    run.steps(300);
    assert_eq!(set(&run, MASTER).velocity, 0.0);
    assert_eq!(
        image(&run, SAW).coupling_state_r,
        CouplingState::Uncoupled.raw()
    );
    assert_eq!(phase(&run, SAW), AxisState::ConstantVelocity.raw());
    assert!((set(&run, SAW).velocity - 750.0).abs() < 1e-9);
    assert_eq!(
        command(&mut run, SAW, AxisCommandCall::halt(10000.0, 1e6)),
        0
    );
    run.until(2000, |r| set(r, SAW).velocity == 0.0);
}

/// MC_GearOut while the slave still accelerates (its synchronising phase): it keeps the
/// velocity it reaches once its acceleration is taken out with its jerk, without overshooting
/// and coming back (before, it ran past that velocity and returned to the one of the
/// decoupling tick).
#[test]
fn gear_out_while_accelerating_keeps_the_velocity_reached_without_overshoot() {
    let mut run = moving(-250.0);
    assert_eq!(gear_in(&mut run, SAW, velocity_call(1.5, 0)), 0);
    run.until(5000, |r| set(r, SAW).acceleration.abs() > 1000.0);
    let at = set(&run, SAW);
    let reached = at.velocity + at.acceleration * at.acceleration.abs() / (2.0 * 1e7);
    assert_eq!(gear_out(&mut run, SAW), 0);
    let rising = at.acceleration > 0.0;
    let mut last = at.velocity;
    for _ in 0..300 {
        run.step();
        let v = set(&run, SAW).velocity;
        assert!(
            if rising {
                v >= last - 1e-9
            } else {
                v <= last + 1e-9
            },
            "{last} -> {v}"
        );
        assert!(
            if rising {
                v <= reached + 1e-9
            } else {
                v >= reached - 1e-9
            },
            "past {reached}: {v}"
        );
        last = v;
    }
    assert!((last - reached).abs() < 1e-6, "{last} vs {reached}");
}

/// Rollback, chapter 8: `(lock, instant, synchron reached)` and what must happen when the
/// master runs back over the coupling position.
#[derive(Debug, PartialEq)]
enum Outcome {
    /// The coupling holds: the slave runs back with the master.
    Follows,
    /// The slave's velocity is taken down along a polynomial.
    SmoothStop,
    /// The slave stops within the tick.
    InstantStop,
}

#[test]
fn the_eight_rollback_cases_of_chapter_8() {
    use Outcome::*;
    let cases = [
        (false, false, true, Follows),     // 1
        (false, false, false, SmoothStop), // 2
        (false, true, false, InstantStop), // 3
        (false, true, true, Follows),      // 4
        (true, false, false, SmoothStop),  // 5
        (true, false, true, SmoothStop),   // 6
        (true, true, false, InstantStop),  // 7
        (true, true, true, InstantStop),   // 8
    ];
    for (n, (lock, instant, synced, want)) in cases.into_iter().enumerate() {
        let mask = if lock { m::ROLLBACKLOCK } else { 0 }
            | if instant { m::INSTANTSTOPONROLLBACK } else { 0 };
        let mut run = moving(250.0);
        let m0 = set(&run, MASTER).position;
        let call = if synced {
            velocity_call(1.0, mask)
        } else {
            position_call(m0 + 1e5, set(&run, SAW).position + 1e5, 1.0, mask)
        };
        assert_eq!(gear_in(&mut run, SAW, call), 0, "case {}", n + 1);
        if synced {
            run.until(5000, |r| phase(r, SAW) == AxisState::SlaveSynchronous.raw());
        } else {
            run.steps(200);
            assert_eq!(phase(&run, SAW), AxisState::SlaveSynchronizing.raw());
        }
        // Back slowly (300 mm/s^2 towards 2000 mm/s): the master still accelerates when it
        // runs over the coupling position, so a stop starts from an acceleration.
        let back = AxisCommandCall::move_velocity(-1, [2000.0, 300.0, 300.0, 1e6]);
        assert_eq!(command(&mut run, MASTER, back), 0);
        // Up to the tick the master is back over the coupling position.
        let mut before = set(&run, SAW);
        for k in 0.. {
            assert!(k < 20000, "case {}: the master never came back", n + 1);
            if set(&run, MASTER).position < m0 {
                break;
            }
            before = set(&run, SAW);
            run.step();
        }
        let s = set(&run, SAW);
        let got = match phase(&run, SAW) {
            p if p == AxisState::SlaveSynchronous.raw() => {
                assert!((s.velocity - set(&run, MASTER).velocity).abs() < 1e-9);
                Follows
            }
            p if p == AxisState::SlavePrephase.raw() && s.velocity == 0.0 => InstantStop,
            p if p == AxisState::SlavePrephase.raw() => {
                // Braking from where it was: the first tick of the stop moves on.
                assert!(s.position != before.position, "case {}: a stall", n + 1);
                assert!(
                    before.acceleration.abs() > 100.0,
                    "case {}: {before:?}",
                    n + 1
                );
                // Comes to rest with its jerk bounded and stands in the pre-phase.
                let mut jerk: f64 = 0.0;
                let mut k = 0;
                while set(&run, SAW).velocity != 0.0 {
                    jerk = jerk.max(set(&run, SAW).jerk.abs());
                    run.step();
                    k += 1;
                    assert!(k < 5000, "case {}: no standstill", n + 1);
                }
                assert!(k > 10, "case {}: stopped in {k} ticks", n + 1);
                // The stop keeps the command's jerk (5000 mm/s^3) from its start acceleration.
                assert!(jerk <= 5000.0 * (1.0 + 1e-9), "case {}: jerk {jerk}", n + 1);
                assert_eq!(phase(&run, SAW), AxisState::SlavePrephase.raw());
                SmoothStop
            }
            p => panic!("case {}: phase {p}", n + 1),
        };
        assert_eq!(got, want, "case {}", n + 1);
        if got != Follows {
            // The master comes forward again over the coupling position: a new sync.
            let standing = set(&run, SAW).position;
            for _ in 0..50 {
                run.step();
                assert_eq!(
                    set(&run, SAW).position,
                    standing,
                    "case {}: stands while the master is behind",
                    n + 1
                );
            }
            assert_eq!(
                command(
                    &mut run,
                    MASTER,
                    AxisCommandCall::move_velocity(1, [500.0, 10000.0, 10000.0, 1e6])
                ),
                0
            );
            run.until(20000, |r| {
                phase(r, SAW) == AxisState::SlaveSynchronizing.raw()
            });
            assert!(set(&run, MASTER).position >= m0);
        }
    }
}

#[test]
fn a_refused_command_leaves_the_slave_moving_as_before() {
    let mut run = moving(250.0);
    let m0 = set(&run, MASTER).position;
    let s0 = set(&run, SAW).position;
    let refusals = [
        (
            position_call(m0 - 10.0, s0 + 100.0, 1.0, 0),
            SawError::MasterSyncNotAhead.raw(),
        ),
        (
            position_call(m0 + 100.0, s0 - 100.0, 1.0, 0),
            SawError::SlaveSyncNotAhead.raw(),
        ),
        (velocity_call(0.0, 0), SawError::RatioZero.raw()),
        (
            SawGearInCall {
                ratio_denominator: 0,
                ..velocity_call(1.0, 0)
            },
            SawError::RatioZero.raw(),
        ),
        (
            SawGearInCall {
                jerk: -1.0,
                ..velocity_call(1.0, 0)
            },
            SawError::NegativeLimit.raw(),
        ),
        (
            SawGearInCall {
                sync_mode: 7,
                ..velocity_call(1.0, 0)
            },
            SawError::Mode.raw(),
        ),
        (
            SawGearInCall {
                sync_mode: SawSyncMode::TimeBased.raw(),
                ..position_call(m0 + 1e3, s0 + 1e3, 1.0, 0)
            },
            SawError::TimeBasedPosition.raw(),
        ),
        (
            SawGearInCall {
                master: SAW as u32,
                ..velocity_call(1.0, 0)
            },
            SawError::NoSuchMaster.raw(),
        ),
        (
            SawGearInCall {
                master: 9,
                ..velocity_call(1.0, 0)
            },
            SawError::NoSuchMaster.raw(),
        ),
        // A limit that cannot be kept: sync 10 mm away in 10 mm of master travel from 250
        // to 500 mm/s with 1 mm/s^2.
        (
            SawGearInCall {
                acceleration: 1.0,
                ..position_call(m0 + 10.0, s0 + 10.0, 1.0, m::MAXACC)
            },
            SawError::Limit.raw(),
        ),
    ];
    for (call, code) in refusals {
        assert_eq!(gear_in(&mut run, SAW, call), code, "{call:?}");
        run.step();
        assert_eq!(
            image(&run, SAW).coupling_state_r,
            CouplingState::Uncoupled.raw()
        );
        assert_eq!(set(&run, SAW).velocity, 250.0);
        assert_eq!(phase(&run, SAW), AxisState::ConstantVelocity.raw());
    }
}

#[test]
fn the_saws_internal_table_and_a_cam_table_exclude_each_other() {
    // The stroke table has ID 2: the saw's table of axis ID 254.
    let mut run = with_stroke_table();
    assert_eq!(
        command(&mut run, MASTER, AxisCommandCall::move_velocity(1, LIMITS)),
        0
    );
    run.steps(100);
    assert_eq!(
        gear_in(&mut run, 2, velocity_call(1.0, 0)),
        SawError::TableInUse.raw()
    );
    // Axis ID 2 (table 254) is free.
    assert_eq!(gear_in(&mut run, SAW, velocity_call(1.0, 0)), 0);
    // The other way round: while the saw drives axis ID 2, no cam table 254 can be loaded;
    // once the saw has let it go, it can.
    let rows = |run: &mut Harness| {
        let mut call = hli::calls::cam::CamRowsWriteCall {
            count: 2,
            flags: hli::calls::cam::CAM_CHUNK_FIRST | hli::calls::cam::CAM_CHUNK_LAST,
            total: 2,
            table_type: 10,
            ..Default::default()
        };
        call.rows[..2].copy_from_slice(&[[0.0, 0.0], [360.0, 10.0]]);
        run.call(254, &call).unwrap().error_id
    };
    let in_use = hli::calls::cam::CamCouplingError::TableInUse.raw();
    assert_eq!(rows(&mut run), in_use, "the saw plans in table 254");
    assert_eq!(gear_out(&mut run, SAW), 0);
    run.step();
    assert_eq!(rows(&mut run), 0, "free again");
}

#[test]
fn a_gear_slave_cannot_be_a_saw_slave() {
    let mut run = with_gear();
    run.step();
    assert_eq!(
        gear_in(&mut run, 2, velocity_call(1.0, 0)),
        AxisError::Coupled.raw()
    );
}

/// MC_GearOut releases a gear coupling too (issue 37 item 7): the geared slave goes on free at
/// its velocity, without a jump, and the gear stays out until the slave has been disabled;
/// enabled again, it couples anew.
#[test]
fn mc_gear_out_releases_a_gear_slave_until_it_is_disabled() {
    const GEARED: usize = 2;
    let mut run = with_gear();
    assert_eq!(gear_out(&mut run, SAW), SawError::NotCoupled.raw());
    let fast = AxisCommandCall::move_velocity(1, [500.0, 10000.0, 10000.0, 1e6]);
    assert_eq!(command(&mut run, MASTER, fast), 0);
    run.until(2000, |r| set(r, GEARED).velocity == 1000.0);
    let coupled = |r: &Harness| r.axis(GEARED).coupling().is_some();
    assert!(coupled(&run));
    let before = set(&run, GEARED);
    assert_eq!(gear_out(&mut run, GEARED), 0);
    run.step();
    let after = set(&run, GEARED);
    assert!(!coupled(&run), "free after MC_GearOut");
    assert_eq!(after.velocity, 1000.0, "it keeps its velocity");
    assert!(
        (after.position - (before.position + 1.0)).abs() < 1e-9,
        "no jump"
    );
    for _ in 0..100 {
        run.step();
        assert!(
            !coupled(&run),
            "the gear stays out while the slave is enabled"
        );
    }
    assert_eq!(gear_out(&mut run, GEARED), SawError::NotCoupled.raw());
    // Stopped and disabled, then enabled: the gear takes the slave again.
    assert_eq!(
        command(&mut run, GEARED, AxisCommandCall::halt(1e4, 1e6)),
        0
    );
    run.until(2000, |r| set(r, GEARED).velocity == 0.0);
    assert_eq!(command(&mut run, GEARED, AxisCommandCall::power(false)), 0);
    run.step();
    run.step();
    assert!(!coupled(&run));
    assert_eq!(command(&mut run, GEARED, AxisCommandCall::power(true)), 0);
    run.until(100, coupled);
    run.until(2000, |r| set(r, GEARED).velocity == 1000.0);
}

#[test]
fn the_characteristic_values_arrive_in_three_parts() {
    let mut run = moving(250.0);
    let none = run.call(SAW as u32, &SawCharacCall { part: 0 }).unwrap();
    assert_eq!(none.error_id, SawError::NotCoupled.raw());
    let (m0, s0) = (set(&run, MASTER).position, set(&run, SAW).position);
    assert_eq!(
        gear_in(
            &mut run,
            SAW,
            position_call(m0 + 1500.0, s0 + 1250.0, 1.0, 0)
        ),
        0
    );
    let a = run.call(SAW as u32, &SawCharacCall { part: 0 }).unwrap();
    let b = run.call(SAW as u32, &SawCharacCall { part: 1 }).unwrap();
    assert_eq!((a.error_id, a.part, b.part), (0, 0, 1));
    // fMasterVeloNom, fMasterPosStart, fSlavePosStart, fSlaveVeloStart ... fMasterPosEnd,
    // fSlavePosEnd, fSlaveVeloEnd.
    assert_eq!(a.values[0], 500.0);
    assert_eq!((a.values[1], a.values[2], a.values[3]), (m0, s0, 250.0));
    assert!((a.values[6] - (m0 + 1500.0)).abs() < 1e-9);
    assert!((a.values[7] - (s0 + 1250.0)).abs() < 1e-9);
    assert!((a.values[8] - 500.0).abs() < 1e-9);
    // Part 1 starts at field 17 (fSlaveAccMin); fSlaveVeloMax is field 24.
    assert!((b.values[7] - 500.0).abs() < 1e-9, "{:?}", b.values);
    // Part 2: the organisation fields. The saw plans in table 256 - axis ID 2; a phase on
    // position is a motion function of at least two points, one column, not periodic.
    let c = run.call(SAW as u32, &SawCharacCall { part: 2 }).unwrap();
    let org = hli::calls::cam::TableOrganisation::from_values(&c.values[..5]).unwrap();
    assert_eq!((org.table_id, org.columns, org.table_type), (254, 1, 22));
    assert!((2..=4).contains(&org.rows) && !org.periodic, "{org:?}");
    assert!(run.call(SAW as u32, &SawCharacCall { part: 3 }).is_err());
}

#[test]
fn the_diagonal_saw_moves_with_the_master_along_the_master() {
    let alpha = 30f64.to_radians();
    let ratio = saw::diagonal_ratio(alpha, 1.0).unwrap();
    assert!(saw::diagonal_ratio(90f64.to_radians(), 1.0).is_err());
    let mut run = moving(0.0);
    assert_eq!(gear_in(&mut run, SAW, velocity_call(ratio, 0)), 0);
    run.until(5000, |r| phase(r, SAW) == AxisState::SlaveSynchronous.raw());
    assert!((set(&run, SAW).velocity * alpha.cos() - set(&run, MASTER).velocity).abs() < 1e-9);
}

#[test]
fn the_time_based_phase_runs_on_time_and_ends_synchronous() {
    let mut run = moving(-250.0);
    let call = SawGearInCall {
        sync_mode: SawSyncMode::TimeBased.raw(),
        ..velocity_call(1.0, m::MAXACC | m::MAXJERK)
    };
    assert_eq!(gear_in(&mut run, SAW, call), 0);
    let mut peak_acc: f64 = 0.0;
    let k = run.until(5000, |r| phase(r, SAW) == AxisState::SlaveSynchronous.raw());
    // sqrt(750/5000) twice: 775 ms (a tick more for the tick the phase ends in).
    assert!((775..=777).contains(&k), "{k} ticks");
    for _ in 0..10 {
        peak_acc = peak_acc.max(set(&run, SAW).acceleration.abs());
        run.step();
    }
    assert!((set(&run, SAW).velocity - 500.0).abs() < 1e-9);
}

#[test]
fn a_master_at_rest_at_coupling_leads_in_the_direction_it_then_moves() {
    let mut run = machine();
    assert_eq!(
        gear_in(&mut run, SAW, velocity_call(2.0, m::ROLLBACKLOCK)),
        0
    );
    run.step();
    assert_eq!(phase(&run, SAW), AxisState::SlaveSynchronous.raw());
    let limits = [300.0, 10000.0, 10000.0, 1e6];
    assert_eq!(
        command(&mut run, MASTER, AxisCommandCall::move_velocity(-1, limits)),
        0
    );
    for _ in 0..200 {
        run.step();
        assert_eq!(phase(&run, SAW), AxisState::SlaveSynchronous.raw());
    }
    assert_eq!(set(&run, SAW).velocity, -600.0);
    assert!((set(&run, SAW).position - 2.0 * set(&run, MASTER).position).abs() < 1e-9);
}

#[test]
fn a_new_command_on_a_coupled_slave_plans_from_where_it_is() {
    let mut run = moving(250.0);
    assert_eq!(gear_in(&mut run, SAW, velocity_call(1.0, 0)), 0);
    run.steps(100);
    let first = run.call(SAW as u32, &SawCharacCall { part: 0 }).unwrap();
    let before = set(&run, SAW);
    // Refused: the coupling stays as it was.
    let (m0, s0) = (set(&run, MASTER).position, before.position);
    let behind = position_call(m0 - 1.0, s0 + 100.0, 1.0, 0);
    assert_eq!(
        gear_in(&mut run, SAW, behind),
        SawError::MasterSyncNotAhead.raw()
    );
    run.step();
    assert_eq!(
        image(&run, SAW).coupling_state_r,
        CouplingState::GearVelocity.raw()
    );
    // Accepted: a position sync from the moving slave, continuous.
    let prev = set(&run, SAW);
    assert_eq!(
        gear_in(
            &mut run,
            SAW,
            position_call(m0 + 1000.0, s0 + 900.0, 1.0, 0)
        ),
        0
    );
    run.step();
    let now = set(&run, SAW);
    assert_eq!(
        image(&run, SAW).coupling_state_r,
        CouplingState::GearPosition.raw()
    );
    let expected = prev.position + prev.velocity * TICK;
    assert!((now.position - expected).abs() < 0.01, "{prev:?} {now:?}");
    let second = run.call(SAW as u32, &SawCharacCall { part: 0 }).unwrap();
    assert_ne!(first.plan, second.plan, "each plan has its number");
}

/// After a rollback the slave stands in the pre-phase; when the master comes forward over the
/// coupling position again the saw plans anew inside the tick, and the characteristic values
/// read then describe that new phase (its start: the master where it re-planned, the slave
/// where it stood), not the first one.
#[test]
fn the_characteristic_values_describe_the_phase_planned_after_a_rollback() {
    let mut run = moving(250.0);
    let m0 = set(&run, MASTER).position;
    assert_eq!(
        gear_in(&mut run, SAW, velocity_call(1.0, m::ROLLBACKLOCK)),
        0
    );
    run.until(5000, |r| phase(r, SAW) == AxisState::SlaveSynchronous.raw());
    let charac = |run: &mut Harness| {
        let reply = run.call(SAW as u32, &SawCharacCall { part: 0 }).unwrap();
        assert_eq!(reply.error_id, 0);
        (reply.values[1], reply.values[2])
    };
    let first = charac(&mut run);
    assert!(
        (first.0 - m0).abs() < 1.0,
        "the first phase starts at {m0}: {first:?}"
    );
    let back = AxisCommandCall::move_velocity(-1, [2000.0, 3000.0, 3000.0, 1e6]);
    assert_eq!(command(&mut run, MASTER, back), 0);
    run.until(20_000, |r| {
        set(r, MASTER).position < m0 - 100.0 && set(r, SAW).velocity == 0.0
    });
    let stood = set(&run, SAW).position;
    let forward = AxisCommandCall::move_velocity(1, [500.0, 3000.0, 3000.0, 1e6]);
    assert_eq!(command(&mut run, MASTER, forward), 0);
    run.until(20_000, |r| {
        phase(r, SAW) == AxisState::SlaveSynchronizing.raw()
    });
    let again = charac(&mut run);
    assert!(
        (again.0 - m0).abs() < 1.0,
        "the new phase starts where the master passed the coupling position: {again:?}"
    );
    assert_eq!(again.1, stood, "from where the slave stood");
    assert_ne!(again, first);
}
