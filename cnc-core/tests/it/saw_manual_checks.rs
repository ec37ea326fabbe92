//! The flying saw's planner against the remaining points of the seed (001) the audit found
//! untested: the `ST_SyncMode` bit values and the slave `nAxisState` numbers as the seed's
//! tables give them; a limit refuses only when its check bit is set (chapter 5); the step 2
//! fallback to the plain P5 (chapter 7); the optimisations only for a master **and** a slave
//! without acceleration at coupling (chapter 7); the characteristic values at the extremes and
//! the NOT SUPPORTED ones of velocity example 1 (chapter 6).

use cnc_core::saw::{self, Limits, Plan, Shape, SyncOn};
use cnc_core::setpoint::Kinematic;
use hli::calls::saw::sync_mask as m;
use hli::calls::saw::SawError;
use hli::enums::AxisState;

use super::saw_plan::{kin, limits, request, CHECK_BITS, LIMIT_CHECKS};

/// Seed 001, chapter 5 (the table of the SyncMode bit masks) and 12.3.1: every check and
/// operation bit has the seed's decimal value; the two bits the seed names without a value
/// have ours (docs/flying-saw.md). A renumbering fails here.
#[test]
fn the_sync_mode_bits_have_the_numbers_of_the_seeds_table() {
    let checks = CHECK_BITS;
    assert_eq!(
        checks,
        [1, 2, 4, 8, 16, 32, 256, 512, 1024, 2048, 4096, 8192]
    );
    let operations = [
        m::ROLLBACKLOCK,
        m::INSTANTSTOPONROLLBACK,
        m::PREFERCONSTVELO,
        m::IGNOREMASTERACC,
    ];
    assert_eq!(operations, [65536, 131072, 1048576, 2097152]);
    // Ours (the seed gives no value).
    assert_eq!(
        [m::IGNORESLAVEACC, m::DETAILEDERRORCODES],
        [0x40_0000, 0x80_0000]
    );
    // The masks are exactly the union of their bits (an unknown bit is refused as Mode).
    assert_eq!(checks.iter().fold(0u32, |a, &b| a | b), m::CHECKS);
    assert_eq!(m::CHECKS, 0x3F3F);
    let ours = m::IGNORESLAVEACC | m::DETAILEDERRORCODES;
    assert_eq!(operations.iter().fold(ours, |a, &b| a | b), m::OPERATIONS);
}

/// Seed 001, chapter 9 (table "nAxisState"): 0 inactive, 11 pre-phase, 12 synchronising,
/// 13 synchronous; every slave state at or above 10, the states below it are masters'.
#[test]
fn the_slave_states_are_11_12_and_13() {
    assert_eq!(AxisState::Inactive.raw(), 0);
    assert_eq!(AxisState::SlavePrephase.raw(), 11);
    assert_eq!(AxisState::SlaveSynchronizing.raw(), 12);
    assert_eq!(AxisState::SlaveSynchronous.raw(), 13);
    assert_eq!(AxisState::decode(11), Ok(AxisState::SlavePrephase));
    assert_eq!(AxisState::decode(12), Ok(AxisState::SlaveSynchronizing));
    assert_eq!(AxisState::decode(13), Ok(AxisState::SlaveSynchronous));
    assert!(AxisState::decode(10).is_err() && AxisState::decode(14).is_err());
    for s in AxisState::ALL {
        assert_eq!(s.is_slave(), s.raw() >= 10, "{s:?}");
    }
}

/// Peak |velocity| of a plan.
fn peak_velocity(p: &Plan) -> f64 {
    let c = &p.charac.values;
    c.fSlaveVeloMax.abs().max(c.fSlaveVeloMin.abs())
}

/// Peak |jerk| of a plan.
fn peak_jerk(p: &Plan) -> f64 {
    let c = &p.charac.values;
    c.fSlaveJerkMax.abs().max(c.fSlaveJerkMin.abs())
}

/// Seed 001, chapter 11 (Velocity, Acceleration, Deceleration, Jerk are checked only when
/// SyncMode switches their check on): a phase that breaks one
/// limit is accepted without its bit, also with the three other limit checks on, and refused
/// with it: the general code, or the check's own with DETAILEDERRORCODES.
#[test]
fn a_broken_limit_is_accepted_without_its_check_bit_and_refused_with_it() {
    let example_1 = SyncOn::Position {
        master: 1000.0,
        slave: 1000.0,
    };
    let wide = Limits {
        velocity: 5000.0,
        acceleration: 1e9,
        deceleration: 1e9,
        jerk: 1e9,
    };
    type Case = (
        &'static str,
        SyncOn,
        Kinematic,
        Kinematic,
        Limits,
        u32,
        SawError,
        fn(&Plan) -> f64,
        f64,
    );
    let cases: [Case; 4] = [
        // Velocity example 1: from -250 to 500 mm/s, the velocity limit 100.
        (
            "velocity",
            SyncOn::Velocity,
            kin(0.0, 500.0, 0.0),
            kin(0.0, -250.0, 0.0),
            Limits {
                velocity: 100.0,
                ..limits(2500.0, 5000.0)
            },
            m::MAXVELO,
            SawError::CheckMaxVelo,
            peak_velocity,
            100.0,
        ),
        // Position example 1: the slave speeds up from 250 to 500 mm/s, the limit 1 mm/s^2.
        (
            "acceleration",
            example_1,
            kin(-500.0, 500.0, 0.0),
            kin(-250.0, 250.0, 0.0),
            Limits {
                acceleration: 1.0,
                ..wide
            },
            m::MAXACC,
            SawError::CheckMaxAcc,
            |p| p.charac.speed_up,
            1.0,
        ),
        // A slave at 1000 mm/s slows down to the master's 500 (mean slope 1.5 between the
        // start slope 2 and the sync slope 1), the deceleration limit 1 mm/s^2.
        (
            "deceleration",
            SyncOn::Position {
                master: 1000.0,
                slave: 2500.0,
            },
            kin(-500.0, 500.0, 0.0),
            kin(250.0, 1000.0, 0.0),
            Limits {
                deceleration: 1.0,
                ..wide
            },
            m::MAXDEC,
            SawError::CheckMaxDec,
            |p| p.charac.slow_down,
            1.0,
        ),
        // Position example 1, the jerk limit 1 mm/s^3.
        (
            "jerk",
            example_1,
            kin(-500.0, 500.0, 0.0),
            kin(-250.0, 250.0, 0.0),
            Limits { jerk: 1.0, ..wide },
            m::MAXJERK,
            SawError::CheckMaxJerk,
            peak_jerk,
            1.0,
        ),
    ];
    for (what, on, master, slave, lim, bit, code, peak, limit) in cases {
        let free = saw::plan(&request(on, 1.0, lim, 0), &master, &slave, None)
            .unwrap_or_else(|e| panic!("{what}: refused without any check bit: {e:?}"));
        assert!(
            peak(&free) > 2.0 * limit,
            "{what}: the accepted phase breaks the limit {limit}: {}",
            peak(&free)
        );
        let others = LIMIT_CHECKS & !bit;
        let unchecked = saw::plan(&request(on, 1.0, lim, others), &master, &slave, None);
        assert!(
            unchecked.is_ok(),
            "{what}: the other checks ({others:#x}) let it pass: {unchecked:?}"
        );
        assert_eq!(
            saw::plan(&request(on, 1.0, lim, bit), &master, &slave, None).unwrap_err(),
            SawError::Limit,
            "{what}"
        );
        let detailed = request(on, 1.0, lim, bit | m::DETAILEDERRORCODES);
        assert_eq!(
            saw::plan(&detailed, &master, &slave, None).unwrap_err(),
            code,
            "{what}"
        );
    }
}

/// Seed 001, chapter 7, step 2: the plain P5 passes MAXVELO, so the planner tries P5-P1-P5
/// with the constant part at the limit; when that phase cannot be had, step 2 is dropped
/// and the plain P5 is what is checked, and refused by MAXVELO.
///
/// The slave runs at the master's 500 mm/s and must make up 600 mm over 1000 mm of master
/// travel: the plain P5 peaks at 1062.5 mm/s (acceleration 866 mm/s^2). Capped at 900 mm/s
/// (slope 1.8) the plateau and its two changes must cover the 600 mm, which needs
/// `0.8 x 1000 - 0.4 (l1 + l3) = 600`, so `l1 + l3 = 500` mm of master travel. With 5000
/// mm/s^2 each change needs only 60 mm: P5-P1-P5. With 1000 mm/s^2 each needs 300 mm, which
/// is too long: no capped phase, the plain P5 (which keeps 1000 mm/s^2) breaks MAXVELO.
/// (The capped phase's changes are sized by the same acceleration and deceleration, so the
/// capped phase does not break the acceleration checks itself; not fitting is how step 2 is
/// dropped.)
#[test]
fn step_2_without_room_for_the_capped_phase_falls_back_to_the_plain_p5_and_maxvelo_refuses() {
    let on = SyncOn::Position {
        master: 1000.0,
        slave: 1600.0,
    };
    let (master, slave) = (kin(0.0, 500.0, 0.0), kin(0.0, 500.0, 0.0));
    let lim = |acc: f64| Limits {
        velocity: 900.0,
        acceleration: acc,
        deceleration: acc,
        jerk: 1e9,
    };
    let plan =
        |acc: f64, mask: u32| saw::plan(&request(on, 1.0, lim(acc), mask), &master, &slave, None);
    let checks = m::MAXVELO | m::MAXACC | m::MAXDEC | m::DETAILEDERRORCODES;
    // Room enough: the capped phase, at the limit and within the accelerations.
    let capped = plan(5000.0, checks).expect("capped at 900 mm/s");
    assert_eq!(capped.profile.shape, Shape::P5P1P5);
    assert!((capped.charac.values.fSlaveVeloMax - 900.0).abs() < 1e-6);
    assert!(capped.charac.speed_up <= 5000.0 * (1.0 + 1e-9));
    assert!((capped.charac.values.fSlavePosEnd - 1600.0).abs() < 1e-9);
    // No room: the plain P5 remains, and its velocity peak is refused.
    assert_eq!(plan(1000.0, checks).unwrap_err(), SawError::CheckMaxVelo);
    // The same phase is the plain P5 that keeps both acceleration limits: without MAXVELO
    // it is accepted, with its velocity peak of 1062.5 mm/s.
    let plain = plan(1000.0, m::MAXACC | m::MAXDEC).unwrap();
    assert_eq!(plain.profile.shape, Shape::P5);
    let c = &plain.charac;
    assert!(c.speed_up <= 1000.0 && c.slow_down <= 1000.0, "{c:?}");
    assert!((c.values.fSlaveVeloMax - 1062.5).abs() < 1e-6, "{c:?}");
}

/// Seed 001, chapter 7: the optimisations apply only when master and slave are both free of
/// acceleration at the coupling. Position example 1 from a standing slave is step 1 (P5+P1)
/// under a master at constant velocity; under a master that accelerates at coupling it is the
/// plain P5, also for a slave that accelerates in proportion to it (its curvature over master
/// travel is 0 then too). IGNOREMASTERACC (and IGNORESLAVEACC) open the optimisations again.
#[test]
fn an_accelerating_master_gets_the_plain_p5_even_for_a_standing_slave() {
    let on = SyncOn::Position {
        master: 1000.0,
        slave: 1000.0,
    };
    let req = |mask| request(on, 1.0, limits(2500.0, 5000.0), mask);
    let steady = kin(-500.0, 500.0, 0.0);
    let speeding = kin(-500.0, 500.0, 1000.0);
    let standing = kin(-250.0, 0.0, 0.0);
    // Slope 0.5 at coupling, accelerating with 0.5 x the master's 1000 mm/s^2.
    let along = kin(-250.0, 250.0, 500.0);
    let shape = |mask: u32, master: &Kinematic, slave: &Kinematic| {
        saw::plan(&req(mask), master, slave, None)
            .expect("planned")
            .profile
            .shape
    };
    // Both unaccelerated: optimised (mean slope 1250/1500 nearer the sync slope 1).
    assert_eq!(shape(0, &steady, &standing), Shape::P5P1);
    // The master accelerates: not optimised.
    assert_eq!(shape(0, &speeding, &standing), Shape::P5);
    assert_eq!(shape(0, &speeding, &along), Shape::P5);
    // A slave at constant velocity under an accelerating master was a P5 already.
    assert_eq!(shape(0, &speeding, &kin(-250.0, 250.0, 0.0)), Shape::P5);
    // The master's acceleration ignored: optimised again.
    assert_eq!(shape(m::IGNOREMASTERACC, &speeding, &standing), Shape::P5P1);
    assert_eq!(
        shape(m::IGNOREMASTERACC | m::IGNORESLAVEACC, &speeding, &along),
        Shape::P5P1
    );
    // The P5 still meets the sync point exactly.
    let p5 = saw::plan(&req(LIMIT_CHECKS), &speeding, &standing, None).unwrap();
    assert_eq!(p5.profile.shape, Shape::P5);
    let c = p5.charac.values;
    assert!((c.fMasterPosEnd - 1000.0).abs() < 1e-9, "{c:?}");
    assert!((c.fSlavePosEnd - 1000.0).abs() < 1e-9, "{c:?}");
    assert!((c.fSlaveVeloEnd - 500.0).abs() < 1e-9, "{c:?}");
}

/// Seed 001, chapter 6 / 12.3.2, for velocity example 1 (master 500 mm/s, slave -250 mm/s,
/// ratio 1, acc/dec 2500, jerk 5000). The phase is the smooth change `v = -250 + 750 h(u)`,
/// `h = 3u^2 - 2u^3`, bound by the jerk: `T = sqrt(6 x 750 / 5000)` = 0.9487 s over 500 T =
/// 474.3 mm of master travel; the jerk `750/T^2 6(1-2u)` is +5000 at the start and -5000 at
/// the end; the acceleration `750/T 6u(1-u)` peaks at mid-phase (master at 250 T = 237.2 mm)
/// with 1125/T = 1185.9 mm/s^2, where the slave runs at (-250 + 500) / 2 = 125 mm/s; the
/// velocity is lowest at the start and highest at the end; the position is lowest where the
/// slave turns (v = 0) and highest at the end. The fields the seed marks NOT SUPPORTED are 0.
#[test]
fn velocity_example_1_has_its_characteristic_values_at_the_extremes() {
    let req = request(SyncOn::Velocity, 1.0, limits(2500.0, 5000.0), LIMIT_CHECKS);
    let plan = saw::plan(&req, &kin(0.0, 500.0, 0.0), &kin(0.0, -250.0, 0.0), None).unwrap();
    let c = plan.charac.values;
    let t = (6.0f64 * 750.0 / 5000.0).sqrt();
    let near = |got: f64, want: f64, tol: f64, name: &str| {
        assert!((got - want).abs() <= tol, "{name}: {got} != {want}; {c:?}");
    };
    assert_eq!(c.fMasterVeloNom, 500.0);
    near(c.fMasterPosStart, 0.0, 1e-12, "fMasterPosStart");
    near(c.fMasterPosEnd, 500.0 * t, 1e-6, "fMasterPosEnd");
    // Jerk at start and end, and its extremes.
    near(c.fSlaveJerkStart, 5000.0, 1e-6, "fSlaveJerkStart");
    near(c.fSlaveJerkEnd, -5000.0, 1e-6, "fSlaveJerkEnd");
    near(c.fSlaveJerkMax, 5000.0, 1e-6, "fSlaveJerkMax");
    near(c.fSlaveJerkMin, -5000.0, 1e-6, "fSlaveJerkMin");
    // Velocity extremes and the master positions at them.
    near(c.fSlaveVeloMin, -250.0, 1e-9, "fSlaveVeloMin");
    near(c.fMPosAtSVeloMin, 0.0, 1e-9, "fMPosAtSVeloMin");
    near(c.fSlaveVeloMax, 500.0, 1e-9, "fSlaveVeloMax");
    near(c.fMPosAtSVeloMax, c.fMasterPosEnd, 1e-6, "fMPosAtSVeloMax");
    // Acceleration maximum: where, how much, and the slave velocity there.
    near(c.fSlaveAccMax, 1125.0 / t, 1e-6, "fSlaveAccMax");
    near(c.fMPosAtSAccMax, 250.0 * t, 1e-6, "fMPosAtSAccMax");
    near(c.fSVeloAtSAccMax, 125.0, 1e-6, "fSVeloAtSAccMax");
    // Acceleration minimum: 0, at one of the ends (start -250 mm/s or end 500 mm/s).
    near(c.fSlaveAccMin, 0.0, 1e-9, "fSlaveAccMin");
    let v = c.fSVeloAtSAccMin;
    assert!(
        (v + 250.0).abs() < 1e-6 || (v - 500.0).abs() < 1e-6,
        "fSVeloAtSAccMin {v}"
    );
    // Position: lowest where the slave turns (v = 0 there), highest at the end.
    assert!(c.fSlavePosMin < 0.0, "{c:?}");
    let turning = plan
        .profile
        .slave_at(&kin(c.fMPosAtSPosMin, 500.0, 0.0), 0.0);
    assert!(turning.velocity.abs() < 1e-6, "{turning:?}");
    near(turning.position, c.fSlavePosMin, 1e-9, "fSlavePosMin");
    near(c.fMPosAtSPosMax, c.fMasterPosEnd, 1e-6, "fMPosAtSPosMax");
    near(c.fSlavePosMax, c.fSlavePosEnd, 1e-9, "fSlavePosMax");
    // NOT SUPPORTED (the seed's structure, fields 20, 29, 30, 31): 0.
    let unsupported = [
        c.fSlaveDynMomMin,
        c.fSlaveDynMomMax,
        c.fSlaveVeloMean,
        c.fSlaveAccEff,
    ];
    assert_eq!(unsupported, [0.0; 4]);
}
