//! The multi-table slave of chapter 4.6 by hand: profile tables in series by their ranges and
//! in parallel with weights (the sum the seed defines), a correction started at once and one
//! at a position (each keeps what it added when it has run through), a cyclic work table
//! ended at its cycle boundary with the stop table taking over without a jump, and the
//! refusals.

use cnc_core::cam::multi_table::{MultiTableError, MultiTableLaw, TableSpec, TableWeight};
use cnc_core::cam::online::CamStore;
use cnc_core::cam::{CamProfile, PositionTable, TableType};
use cnc_core::setpoint::Kinematic;
use hli::calls::cam::CamInterpolation;

fn table(rows: &[[f64; 2]]) -> CamProfile {
    CamProfile::Table(
        PositionTable::new(
            rows,
            TableType::NonEquidistant,
            CamInterpolation::Linear,
            false,
        )
        .unwrap(),
    )
}

/// 1: ramp 0..100 -> 0..50; 2: ramp 0..100 -> 0..10 (a cyclic work table: stroke 10);
/// 3: a correction bump 0..10 -> 0..2; 4: a stop table 0..50 -> 0..5.
fn store() -> CamStore {
    let mut s = CamStore::new();
    s.insert(1, table(&[[0.0, 0.0], [100.0, 50.0]])).unwrap();
    s.insert(2, table(&[[0.0, 0.0], [100.0, 10.0]])).unwrap();
    s.insert(3, table(&[[0.0, 0.0], [10.0, 2.0]])).unwrap();
    s.insert(4, table(&[[0.0, 0.0], [50.0, 5.0]])).unwrap();
    s
}

fn at(position: f64) -> Kinematic {
    Kinematic {
        position,
        velocity: 10.0,
        ..Kinematic::default()
    }
}

fn spec<'a>(
    store: &'a CamStore,
    id: u32,
    profile: bool,
    periodic: bool,
    w: TableWeight,
) -> TableSpec<'a> {
    TableSpec {
        table: id,
        profile,
        periodic,
        weight: w,
        cam: store.get(id).unwrap(),
    }
}

#[test]
fn profile_tables_in_series_and_in_parallel_give_the_weighted_sum() {
    let s = store();
    // Table 1 on [0, 100) scaled: u = 10 + 0.5 Pm, Ps = 2 (1 + 3 T(u)), weight 2.
    let first = TableWeight {
        weight: 2.0,
        master_offset: 10.0,
        master_slope: 0.5,
        slave_offset: 1.0,
        slave_slope: 3.0,
        range_low: 0.0,
        range_high: 100.0,
    };
    // Table 2 on [100, 200), plain, beside table 1 half-weighted from 150 on.
    let second = TableWeight {
        range_low: 100.0,
        range_high: 200.0,
        master_offset: -100.0,
        ..TableWeight::default()
    };
    let mut law = MultiTableLaw::new(
        &[
            spec(&s, 1, true, false, first),
            spec(&s, 2, true, false, second),
        ],
        0.0,
        0.0,
    )
    .unwrap();
    // Pm = 40: u = 30, T = 15, Ps = 2 (1 + 45) = 92; velocity 2 * 3 * 0.5 * 0.5 * 10.
    let p = law.slave(&s, &at(40.0));
    assert_eq!(p.position, 92.0);
    assert!((p.velocity - 15.0).abs() < 1e-12);
    // Pm = 130: only table 2: u = 30, T = 3.
    assert_eq!(law.slave(&s, &at(130.0)).position, 3.0);
    // Parallel: two tables over the same range with weights 0.25 and 0.75.
    let a = TableWeight {
        weight: 0.25,
        ..TableWeight::default()
    };
    let b = TableWeight {
        weight: 0.75,
        ..TableWeight::default()
    };
    let mut law = MultiTableLaw::new(
        &[spec(&s, 1, true, false, a), spec(&s, 2, true, false, b)],
        0.0,
        0.0,
    )
    .unwrap();
    // Pm = 60: 0.25 * 30 + 0.75 * 6.
    assert_eq!(law.slave(&s, &at(60.0)).position, 0.25 * 30.0 + 0.75 * 6.0);
    // Outside every range the slave stands where the profile left it.
    let narrow = TableWeight {
        range_low: 0.0,
        range_high: 50.0,
        ..TableWeight::default()
    };
    let mut law = MultiTableLaw::new(&[spec(&s, 1, true, false, narrow)], 0.0, 0.0).unwrap();
    let last = law.slave(&s, &at(49.0)).position;
    let beyond = law.slave(&s, &at(80.0));
    assert_eq!((beyond.position, beyond.velocity), (last, 0.0));
}

#[test]
fn corrections_start_at_their_first_row_and_keep_what_they_added() {
    let s = store();
    let mut law = MultiTableLaw::new(
        &[
            spec(&s, 1, true, false, TableWeight::default()),
            spec(&s, 3, false, false, TableWeight::default()),
        ],
        0.0,
        0.0,
    )
    .unwrap();
    let base = |pm: f64| pm / 2.0;
    assert_eq!(law.slave(&s, &at(20.0)).position, base(20.0));
    // At once, at Pm = 30: from here the bump adds 0.2 per master unit for 10 units.
    law.enable_correction(3, None).unwrap();
    assert_eq!(law.slave(&s, &at(30.0)).position, base(30.0));
    assert!((law.slave(&s, &at(35.0)).position - (base(35.0) + 1.0)).abs() < 1e-12);
    // Run through: the 2 it added stays.
    assert!((law.slave(&s, &at(45.0)).position - (base(45.0) + 2.0)).abs() < 1e-12);
    assert!((law.slave(&s, &at(60.0)).position - (base(60.0) + 2.0)).abs() < 1e-12);
    // At a position: armed for 70, nothing before.
    law.enable_correction(3, Some(70.0)).unwrap();
    assert!((law.slave(&s, &at(69.0)).position - (base(69.0) + 2.0)).abs() < 1e-12);
    assert!((law.slave(&s, &at(75.0)).position - (base(75.0) + 2.0 + 1.0)).abs() < 1e-12);
    assert!((law.slave(&s, &at(90.0)).position - (base(90.0) + 4.0)).abs() < 1e-12);
    // Only the coupling's corrections.
    assert_eq!(
        law.enable_correction(1, None),
        Err(MultiTableError::NotInCoupling(1, "correction table"))
    );
}

#[test]
fn a_cyclic_work_table_ends_at_its_boundary_and_the_stop_table_takes_over() {
    let s = store();
    // The stop table counts from where the work table hands over (set then).
    let stop = TableWeight {
        range_low: 1e12,
        ..TableWeight::default()
    };
    let mut law = MultiTableLaw::new(
        &[
            spec(&s, 2, true, true, TableWeight::default()),
            spec(&s, 4, true, false, stop),
        ],
        0.0,
        0.0,
    )
    .unwrap();
    // Cyclic with stroke 10 per 100: Pm / 10.
    let mut pm = 0.0;
    while pm < 250.0 {
        assert!(
            (law.slave(&s, &at(pm)).position - pm / 10.0).abs() < 1e-9,
            "{pm}"
        );
        pm += 1.0;
    }
    assert_eq!(
        law.stop_cyclic(4),
        Err(MultiTableError::NotInCoupling(4, "cyclic profile table"))
    );
    law.stop_cyclic(2).unwrap();
    let mut last = law.slave(&s, &at(pm)).position;
    let mut steps = Vec::new();
    while pm < 400.0 {
        pm += 1.0;
        let p = law.slave(&s, &at(pm)).position;
        steps.push(p - last);
        last = p;
    }
    // Up to 300 the work table (0.1 per unit); from its boundary the stop table (0.1 per
    // unit too) from the position reached, 30, up to 35 at 350, then it holds.
    assert!(
        steps.iter().all(|d| (0.0..=0.1 + 1e-9).contains(d)),
        "{steps:?}"
    );
    assert!((law.slave(&s, &at(320.0)).position - 32.0).abs() < 1e-9);
    assert!((law.slave(&s, &at(400.0)).position - 35.0).abs() < 1e-9);
}

#[test]
fn bad_weights_and_counts_are_refused() {
    let s = store();
    for (w, what) in [
        (
            TableWeight {
                weight: 0.0,
                ..TableWeight::default()
            },
            "weight",
        ),
        (
            TableWeight {
                master_slope: 0.0,
                ..TableWeight::default()
            },
            "master slope",
        ),
        (
            TableWeight {
                slave_offset: f64::NAN,
                ..TableWeight::default()
            },
            "slave offset",
        ),
        (
            TableWeight {
                range_low: 5.0,
                range_high: 5.0,
                ..TableWeight::default()
            },
            "range low",
        ),
    ] {
        match MultiTableLaw::new(&[spec(&s, 1, true, false, w)], 0.0, 0.0) {
            Err(MultiTableError::Parameter { what: got, .. }) => assert_eq!(got, what),
            other => panic!("{what}: {other:?}"),
        }
    }
    assert!(matches!(
        MultiTableLaw::new(
            &[spec(&s, 3, false, false, TableWeight::default())],
            0.0,
            0.0
        ),
        Err(MultiTableError::Count {
            tables: 1,
            profiles: 0
        })
    ));
}

#[test]
fn a_correction_with_a_falling_slope_runs_its_table_backwards() {
    let mut s = store();
    s.insert(5, table(&[[0.0, 0.0], [5.0, 1.0], [10.0, 0.0]]))
        .unwrap();
    let backwards = TableWeight {
        master_slope: -1.0,
        ..TableWeight::default()
    };
    let mut law = MultiTableLaw::new(
        &[
            spec(&s, 1, true, false, TableWeight::default()),
            spec(&s, 5, false, false, backwards),
        ],
        0.0,
        0.0,
    )
    .unwrap();
    law.slave(&s, &at(10.0));
    law.enable_correction(5, None).unwrap();
    // From 10 on it runs from its last row down: +0.6 after 3 units, +1 after 5, gone after 10.
    assert_eq!(law.slave(&s, &at(10.0)).position, 5.0);
    assert!((law.slave(&s, &at(13.0)).position - (6.5 + 0.6)).abs() < 1e-12);
    assert!((law.slave(&s, &at(15.0)).position - (7.5 + 1.0)).abs() < 1e-12);
    assert!((law.slave(&s, &at(21.0)).position - 10.5).abs() < 1e-12);
}

#[test]
fn coupled_outside_every_range_the_slave_stands_where_it_stood() {
    let s = store();
    let later = TableWeight {
        range_low: 100.0,
        range_high: 200.0,
        ..TableWeight::default()
    };
    let mut law = MultiTableLaw::new(&[spec(&s, 1, true, false, later)], 0.0, 7.5).unwrap();
    let p = law.slave(&s, &at(50.0));
    assert_eq!((p.position, p.velocity), (7.5, 0.0));
}

/// Seed 000 4.6.3/4.6.4: scale, then activate. While the cyclic work table runs, the stop
/// table (not active yet) takes a new slave slope, and the hand-over runs it with that slope;
/// the active work table's scaling is refused with nothing changed.
#[test]
fn a_table_not_yet_active_takes_its_scaling_and_the_active_one_refuses_it() {
    let s = store();
    let stop = TableWeight {
        range_low: 1e12,
        ..TableWeight::default()
    };
    let mut law = MultiTableLaw::new(
        &[
            spec(&s, 2, true, true, TableWeight::default()),
            spec(&s, 4, true, false, stop),
            spec(&s, 3, false, false, TableWeight::default()),
        ],
        0.0,
        0.0,
    )
    .unwrap();
    for pm in 0..250 {
        law.slave(&s, &at(f64::from(pm)));
    }
    assert!(law.is_active(2) && !law.is_active(4) && !law.is_active(3));
    let steeper = TableWeight {
        slave_slope: 2.0,
        ..stop
    };
    assert_eq!(law.set_weight(2, steeper), Err(MultiTableError::Active(2)));
    law.set_weight(4, steeper).unwrap();
    // A correction that has not started takes its scaling too; a running one refuses it.
    law.set_weight(3, TableWeight::default()).unwrap();
    law.enable_correction(3, None).unwrap();
    assert_eq!(
        law.set_weight(3, TableWeight::default()),
        Err(MultiTableError::Active(3))
    );
    assert_eq!(
        law.set_weight(9, TableWeight::default()),
        Err(MultiTableError::NotInCoupling(9, "table"))
    );
    // Without the correction's effect: compare the slave's rise over the stop table.
    law.stop_cyclic(2).unwrap();
    let mut pm = 250.0;
    let mut at_boundary = None;
    while pm < 400.0 {
        pm += 1.0;
        let p = law.slave(&s, &at(pm)).position;
        if pm == 300.0 {
            at_boundary = Some(p);
        }
    }
    let end = law.slave(&s, &at(400.0)).position;
    // The stop table, 0..50 -> 0..5, now at slave slope 2: it adds 10, not 5.
    let rise = end - at_boundary.unwrap();
    assert!(
        (rise - 10.0).abs() < 1e-9,
        "rise over the stop table {rise}"
    );
}
