//! Position tables: support points, cubic reproduction, cyclic continuation, edges, the
//! seed's interval conventions, the binary file.

use cnc_core::cam::file::{self, BinaryOptions};
use cnc_core::cam::table::TableCursor;
use cnc_core::cam::{CamError, CamProfile, PositionTable, TableErrorCode, TableType};
use hli::calls::cam::CamInterpolation;

const ALL: [CamInterpolation; 3] = [
    CamInterpolation::Linear,
    CamInterpolation::FourPoint,
    CamInterpolation::Spline,
];

fn cubic(x: f64) -> (f64, f64) {
    (
        0.02 * x * x * x - 0.3 * x * x + 0.5 * x + 1.0,
        0.06 * x * x - 0.6 * x + 0.5,
    )
}

fn rows_of(masters: &[f64], f: impl Fn(f64) -> f64) -> Vec<[f64; 2]> {
    masters.iter().map(|m| [*m, f(*m)]).collect()
}

fn equidistant(n: usize, step: f64) -> Vec<f64> {
    (0..n).map(|i| i as f64 * step).collect()
}

fn uneven(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| i as f64 + 0.3 * ((i * 7 % 5) as f64) / 5.0)
        .collect()
}

#[test]
fn every_interpolation_reproduces_its_support_points() {
    let wavy = |x: f64| (0.7 * x).sin() * 3.0 + 0.1 * x;
    for periodic in [false, true] {
        for interpolation in ALL {
            let types: &[TableType] = if interpolation == CamInterpolation::FourPoint {
                &[TableType::Equidistant]
            } else {
                &[TableType::Equidistant, TableType::NonEquidistant]
            };
            for ty in types {
                let masters = if *ty == TableType::Equidistant {
                    equidistant(25, 0.5)
                } else {
                    uneven(25)
                };
                let rows = rows_of(&masters, wavy);
                let t = PositionTable::new(&rows, *ty, interpolation, periodic).unwrap();
                let mut c = TableCursor::default();
                for r in &rows {
                    let s = t.eval(r[0], &mut c).sample;
                    assert!(
                        (s.position - r[1]).abs() < 1e-12,
                        "{interpolation:?} {ty:?} periodic {periodic} at {}",
                        r[0]
                    );
                }
            }
        }
    }
}

#[test]
fn four_point_and_spline_reproduce_a_cubic() {
    for (interpolation, masters, ty) in [
        (
            CamInterpolation::FourPoint,
            equidistant(30, 0.4),
            TableType::Equidistant,
        ),
        (
            CamInterpolation::Spline,
            equidistant(30, 0.4),
            TableType::Equidistant,
        ),
        (
            CamInterpolation::Spline,
            uneven(30),
            TableType::NonEquidistant,
        ),
    ] {
        let t = PositionTable::new(&rows_of(&masters, |x| cubic(x).0), ty, interpolation, false)
            .unwrap();
        let mut c = TableCursor::default();
        let (lo, hi) = t.master_range();
        for i in 0..=1000 {
            let x = lo + (hi - lo) * i as f64 / 1000.0;
            let s = t.eval(x, &mut c).sample;
            let (y, v) = cubic(x);
            assert!(
                (s.position - y).abs() < 1e-9,
                "{interpolation:?} {ty:?} y({x}) = {} != {y}",
                s.position
            );
            assert!(
                (s.velocity - v).abs() < 1e-8,
                "{interpolation:?} {ty:?} v({x}) = {} != {v}",
                s.velocity
            );
            assert!(
                (s.acceleration - (0.12 * x - 0.6)).abs() < 1e-7,
                "{interpolation:?} {ty:?} a({x})"
            );
        }
    }
    // Linear interpolation does not (it is exact for lines only).
    let t = PositionTable::new(
        &rows_of(&equidistant(30, 0.4), |x| cubic(x).0),
        TableType::Equidistant,
        CamInterpolation::Linear,
        false,
    )
    .unwrap();
    let s = t.eval(1.0, &mut TableCursor::default()).sample;
    assert!((s.position - cubic(1.0).0).abs() > 1e-4);
}

#[test]
fn cyclic_tables_continue_with_stroke_and_cycle_counter_without_drift() {
    // One master period of 360 with a slave stroke of 10 per period.
    let masters = equidistant(37, 10.0);
    let rows = rows_of(&masters, |x| x / 36.0 + 2.0 * (x.to_radians()).sin());
    for interpolation in ALL {
        let t = PositionTable::new(&rows, TableType::Equidistant, interpolation, true).unwrap();
        assert_eq!((t.period(), t.stroke()), (360.0, 10.0));
        let mut c = TableCursor::default();
        let base = t.eval(5.0, &mut c);
        let next = t.eval(365.0, &mut c);
        assert_eq!(next.cycle, 1);
        assert!((next.sample.position - base.sample.position - 10.0).abs() < 1e-12);
        let before = t.eval(-355.0, &mut c);
        assert_eq!(before.cycle, -1);
        assert!((before.sample.position - base.sample.position + 10.0).abs() < 1e-12);
        // Ten thousand periods on: the counter counts them, the position does not drift.
        let far = t.eval(5.0 + 360.0 * 10_000.0, &mut c);
        assert_eq!(far.cycle, 10_000);
        assert!(
            (far.sample.position - base.sample.position - 100_000.0).abs() < 1e-8,
            "{interpolation:?}"
        );
        assert!((far.sample.velocity - base.sample.velocity).abs() < 1e-9);
    }
    // The periodic spline is smooth across the period boundary.
    let t = PositionTable::new(
        &rows,
        TableType::Equidistant,
        CamInterpolation::Spline,
        true,
    )
    .unwrap();
    let mut c = TableCursor::default();
    let (l, r) = (
        t.eval(360.0 - 1e-9, &mut c).sample,
        t.eval(360.0 + 1e-9, &mut c).sample,
    );
    assert!(
        (l.velocity - r.velocity).abs() < 1e-9 && (l.acceleration - r.acceleration).abs() < 1e-7
    );
}

#[test]
fn linear_tables_hold_their_edge_values_outside() {
    let rows = [[0.0, 1.0], [10.0, 3.0], [20.0, 2.0]];
    let t = PositionTable::new(
        &rows,
        TableType::Equidistant,
        CamInterpolation::Linear,
        false,
    )
    .unwrap();
    let mut c = TableCursor::default();
    for (x, y) in [(-5.0, 1.0), (25.0, 2.0), (5.0, 2.0), (15.0, 2.5)] {
        let s = t.eval(x, &mut c);
        assert_eq!((s.sample.position, s.cycle), (y, 0), "at {x}");
    }
    assert_eq!(t.eval(-5.0, &mut c).sample.velocity, 0.0);
}

#[test]
fn a_support_point_belongs_to_the_interval_the_seed_names() {
    // Equidistant: T[k] <= x < T[k+1]; non-equidistant: T[k] < x <= T[k+1].
    let rows = [[0.0, 0.0], [1.0, 1.0], [2.0, 3.0]];
    let mut c = TableCursor::default();
    let eq = PositionTable::new(
        &rows,
        TableType::Equidistant,
        CamInterpolation::Linear,
        false,
    )
    .unwrap();
    assert_eq!(
        eq.eval(1.0, &mut c).sample.velocity,
        2.0,
        "equidistant: the interval above"
    );
    let ne = PositionTable::new(
        &rows,
        TableType::NonEquidistant,
        CamInterpolation::Linear,
        false,
    )
    .unwrap();
    assert_eq!(
        ne.eval(1.0, &mut c).sample.velocity,
        1.0,
        "non-equidistant: the interval below"
    );
}

#[test]
fn the_binary_file_round_trips() {
    let rows = rows_of(&uneven(200), |x| x.sqrt());
    let bytes = file::write_binary(&rows).unwrap();
    assert_eq!(bytes.len(), 4 + 200 * 16);
    assert_eq!(
        &bytes[..4],
        &[200, 0, 2, 0],
        "header: rows, columns as unsigned shorts"
    );
    assert_eq!(file::read_binary(&bytes).unwrap(), rows);
    let loaded = file::parse(&bytes, BinaryOptions::default()).unwrap();
    let CamProfile::Table(t) = loaded.profile else {
        panic!("a table")
    };
    assert_eq!(t.table_type(), TableType::NonEquidistant);
    assert_eq!(t.rows().collect::<Vec<_>>(), rows);
    let even = file::write_binary(&rows_of(&equidistant(5, 2.0), |x| x)).unwrap();
    let CamProfile::Table(t) = file::parse(&even, BinaryOptions::default())
        .unwrap()
        .profile
    else {
        panic!()
    };
    assert_eq!(t.table_type(), TableType::Equidistant);
}

#[test]
fn bad_tables_are_refused_with_the_seed_codes_and_the_row() {
    let code = |e: CamError| e.code();
    let good = rows_of(&equidistant(5, 1.0), |x| x);
    let mut bytes = file::write_binary(&good).unwrap();
    bytes.pop();
    assert_eq!(
        code(file::read_binary(&bytes).unwrap_err()),
        TableErrorCode::ArraySizeInvalid
    );
    let mut three = file::write_binary(&good).unwrap();
    three[2] = 3;
    assert_eq!(
        file::read_binary(&three).unwrap_err(),
        CamError::Columns { row: 0, cols: 3 }
    );
    assert_eq!(
        code(file::read_binary(&[]).unwrap_err()),
        TableErrorCode::PointerInvalid
    );

    let mut back = good.clone();
    back[3][0] = 1.5;
    let e = PositionTable::new(
        &back,
        TableType::NonEquidistant,
        CamInterpolation::Linear,
        false,
    )
    .unwrap_err();
    assert_eq!(
        e,
        CamError::RowNotAscending {
            row: 3,
            master: 1.5,
            previous: 2.0
        }
    );
    assert_eq!(e.code(), TableErrorCode::IncrementInvalid);

    let e = PositionTable::new(
        &rows_of(&uneven(6), |x| x),
        TableType::Equidistant,
        CamInterpolation::Linear,
        false,
    )
    .unwrap_err();
    assert!(matches!(e, CamError::NotEquidistant { .. }), "{e}");

    let mut nan = good.clone();
    nan[2][1] = f64::NAN;
    let e = PositionTable::new(
        &nan,
        TableType::Equidistant,
        CamInterpolation::Linear,
        false,
    )
    .unwrap_err();
    assert_eq!(e.code(), TableErrorCode::NumRowsInvalid);
    assert!(e.to_string().contains("row 2"));

    let e = PositionTable::new(
        &good[..3],
        TableType::Equidistant,
        CamInterpolation::FourPoint,
        false,
    )
    .unwrap_err();
    assert_eq!(e.code(), TableErrorCode::NumRowsInvalid);
    let e = PositionTable::new(
        &rows_of(&uneven(6), |x| x),
        TableType::NonEquidistant,
        CamInterpolation::FourPoint,
        false,
    )
    .unwrap_err();
    assert_eq!(e.code(), TableErrorCode::McTableTypeInvalid);

    let json = br#"{"kind":"table","table_type":"equidistant","rows":[[0,0],[1,1,5]]}"#;
    let e = file::parse(json, BinaryOptions::default()).unwrap_err();
    assert!(
        e.to_string().contains("0x4B37") && e.to_string().contains("row 1"),
        "{e}"
    );
    let json = br#"{"kind":"table","id":256,"table_type":"equidistant","rows":[[0,0],[1,1]]}"#;
    let e = file::parse(json, BinaryOptions::default()).unwrap_err();
    assert!(e.to_string().contains("0x4B32"), "{e}");
}

mod lookup {
    use cnc_core::cam::table::TableCursor;
    use cnc_core::cam::{PositionTable, TableType};
    use hli::calls::cam::CamInterpolation;
    use proptest::prelude::*;

    proptest! {
        /// However the master jumps, the cursor's walk and gallop find the interval a plain
        /// scan finds (the seed's convention: T[k] < x <= T[k+1]), so the value agrees.
        #[test]
        fn a_kept_cursor_finds_what_a_scan_finds(
            steps in proptest::collection::vec(0.01f64..5.0, 2..400),
            queries in proptest::collection::vec(-0.1f64..1.1, 1..200),
        ) {
            let mut x = 0.0;
            let rows: Vec<[f64; 2]> = steps.iter().enumerate().map(|(i, s)| { x += s; [x, (i as f64 * 0.37).sin()] }).collect();
            let t = PositionTable::new(&rows, TableType::NonEquidistant, CamInterpolation::Linear, false).unwrap();
            let (lo, hi) = t.master_range();
            let mut cursor = TableCursor::default();
            for q in queries {
                let x = (lo + (hi - lo) * q).clamp(lo, hi);
                let got = t.eval(x, &mut cursor).sample;
                let k = rows.windows(2).position(|w| w[0][0] < x && x <= w[1][0]).unwrap_or(0);
                let slope = (rows[k + 1][1] - rows[k][1]) / (rows[k + 1][0] - rows[k][0]);
                prop_assert!((got.velocity - slope).abs() < 1e-12, "interval at {}", x);
                prop_assert!((got.position - (rows[k][1] + slope * (x - rows[k][0]))).abs() < 1e-9);
            }
        }
    }
}

#[test]
fn near_equidistant_and_degenerate_rows_are_refused() {
    // Off by 0.0009 at a step of 0.001: not equidistant (the tolerance is 1e-9 of the step
    // plus rounding, not 1e-9 of the position).
    let rows = [[1e6, 0.0], [1e6 + 0.0019, 1.0], [1e6 + 0.002, 2.0]];
    let e = PositionTable::new(
        &rows,
        TableType::Equidistant,
        CamInterpolation::Linear,
        false,
    )
    .unwrap_err();
    assert!(matches!(e, CamError::NotEquidistant { row: 1, .. }), "{e}");
    let even = file::write_binary(&rows).unwrap();
    let CamProfile::Table(t) = file::parse(&even, BinaryOptions::default())
        .unwrap()
        .profile
    else {
        panic!()
    };
    assert_eq!(
        t.table_type(),
        TableType::NonEquidistant,
        "binary auto-detection agrees"
    );
    // Rows closer than the arithmetic resolves: an infinite slope is refused, not passed on.
    let e = PositionTable::new(
        &[[0.0, 0.0], [5e-324, 1.0]],
        TableType::NonEquidistant,
        CamInterpolation::Linear,
        false,
    )
    .unwrap_err();
    assert_eq!(e, CamError::NotInterpolable { row: 1 });
    assert_eq!(e.code(), TableErrorCode::IncrementInvalid);
    let e = PositionTable::new(
        &[[-1e308, 0.0], [1e308, 1.0]],
        TableType::Equidistant,
        CamInterpolation::Linear,
        true,
    )
    .unwrap_err();
    assert!(matches!(e, CamError::NotInterpolable { .. }), "{e}");
}

#[test]
fn an_equidistant_row_belongs_to_the_interval_above_it_despite_rounding() {
    // Steps of 1/3 do not add up exactly: every row must still open its own interval.
    let rows: Vec<[f64; 2]> = (0..50).map(|i| [i as f64 / 3.0, (i * i) as f64]).collect();
    let t = PositionTable::new(
        &rows,
        TableType::Equidistant,
        CamInterpolation::Linear,
        false,
    )
    .unwrap();
    let mut c = TableCursor::default();
    for k in 0..48 {
        let s = t.eval(rows[k][0], &mut c).sample;
        let slope = (rows[k + 1][1] - rows[k][1]) / (rows[k + 1][0] - rows[k][0]);
        assert!(
            (s.velocity - slope).abs() < 1e-6 * slope.abs().max(1.0),
            "row {k}: {} vs {slope}",
            s.velocity
        );
    }
}

#[test]
fn splines_are_smooth_at_every_row_and_periodic_ones_reproduce_a_periodic_function() {
    let masters = uneven(40);
    for periodic in [false, true] {
        let rows = if periodic {
            let period = masters[39] - masters[0];
            masters
                .iter()
                .map(|m| {
                    [
                        *m,
                        (2.0 * std::f64::consts::PI * (m - masters[0]) / period).sin(),
                    ]
                })
                .collect::<Vec<_>>()
        } else {
            rows_of(&masters, |x| (0.3 * x).sin())
        };
        let t = PositionTable::new(
            &rows,
            TableType::NonEquidistant,
            CamInterpolation::Spline,
            periodic,
        )
        .unwrap();
        let mut c = TableCursor::default();
        for r in &rows[1..39] {
            let (l, h) = (
                t.eval(r[0] - 1e-9, &mut c).sample,
                t.eval(r[0] + 1e-9, &mut c).sample,
            );
            assert!(
                (l.velocity - h.velocity).abs() < 1e-6,
                "velocity step at {}",
                r[0]
            );
            assert!(
                (l.acceleration - h.acceleration).abs() < 1e-5,
                "acceleration step at {}",
                r[0]
            );
        }
        if periodic {
            // Between the rows the spline stays close to the sine it samples.
            let period = masters[39] - masters[0];
            for i in 0..200 {
                let x = masters[0] + period * i as f64 / 200.0;
                let want = (2.0 * std::f64::consts::PI * (x - masters[0]) / period).sin();
                assert!(
                    (t.eval(x, &mut c).sample.position - want).abs() < 2e-3,
                    "at {x}"
                );
            }
        }
    }
}
