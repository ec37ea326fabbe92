//! Cost of one cam evaluation while the master sweeps (what a cam slave pays per tick):
//! a motion function of 100 points and position tables of 1,000 and 100,000 rows, beside a
//! plain binary search with linear interpolation over the same rows in the same run (the
//! in-run baseline). Each figure is the median of interleaved repeats of one full sweep;
//! it includes the segment lookup and position, velocity, acceleration and jerk.
//! Run: `cargo bench -p cnc-core --bench cam`.

use bench_kit::{median, scaled};
use cnc_core::cam::{
    CamProfile, FunctionType, MotionFunction, MotionFunctionPoint, PointType, PositionTable,
    ProfileCursor, TableType,
};
use hli::calls::cam::CamInterpolation;
use std::hint::black_box;
use std::time::Instant;

const EVALS: usize = 1_000_000;
const REPEATS: usize = 9;

fn motion_function(points: usize) -> CamProfile {
    // Rest points with alternating strokes; polynomial and trigonometric laws mixed.
    let laws = [
        FunctionType::Polynom5,
        FunctionType::SineLine,
        FunctionType::ModifiedSineLine,
        FunctionType::Polynom5Motion,
        FunctionType::AccelerationTrapezoid,
        FunctionType::Polynom7Motion,
    ];
    let p: Vec<MotionFunctionPoint> = (0..points)
        .map(|i| {
            let slave = if i % 2 == 0 { 0.0 } else { 10.0 };
            MotionFunctionPoint::new(
                i as u32 + 1,
                laws[i % laws.len()],
                PointType::Rest,
                i as f64 * 3.6,
                slave,
            )
        })
        .collect();
    CamProfile::MotionFunction(MotionFunction::new(&p).expect("bench cam"))
}

fn rows(n: usize, even: bool) -> Vec<[f64; 2]> {
    (0..n)
        .map(|i| {
            let x = if even {
                i as f64
            } else {
                i as f64 + 0.25 * ((i * 7 % 3) as f64)
            };
            [x, (x * 0.001).sin() * 50.0]
        })
        .collect()
}

/// One sweep over the profile's master range with `evals` evaluations; ns per evaluation.
fn sweep(profile: &CamProfile, evals: usize) -> f64 {
    let (lo, hi) = profile.master_range();
    let step = (hi - lo) / evals as f64;
    let mut cursor = ProfileCursor::default();
    let t = Instant::now();
    let mut acc = 0.0;
    for i in 0..evals {
        let s = profile.eval(lo + step * i as f64, &mut cursor);
        acc += s.position + s.velocity;
    }
    black_box(acc);
    t.elapsed().as_nanos() as f64 / evals as f64
}

/// The baseline: binary search for the row, then linear interpolation (position, slope).
fn sweep_binary_search(rows: &[[f64; 2]], evals: usize) -> f64 {
    let masters: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let (lo, hi) = (masters[0], masters[masters.len() - 1]);
    let step = (hi - lo) / evals as f64;
    let t = Instant::now();
    let mut acc = 0.0;
    for i in 0..evals {
        let x = lo + step * i as f64;
        let k = masters
            .partition_point(|m| *m <= x)
            .clamp(1, masters.len() - 1)
            - 1;
        let slope = (rows[k + 1][1] - rows[k][1]) / (rows[k + 1][0] - rows[k][0]);
        acc += rows[k][1] + slope * (x - rows[k][0]) + slope;
    }
    black_box(acc);
    t.elapsed().as_nanos() as f64 / evals as f64
}

fn main() {
    let mf_rows: Vec<[f64; 2]> = (0..100).map(|i| [i as f64 * 3.6, 0.0]).collect();
    let mut cases: Vec<(String, CamProfile, Vec<[f64; 2]>)> = vec![(
        "motion function, 100 points".into(),
        motion_function(100),
        mf_rows,
    )];
    for n in [1_000, 100_000] {
        for (name, ty, even, interpolation) in [
            (
                "non-equidistant, linear",
                TableType::NonEquidistant,
                false,
                CamInterpolation::Linear,
            ),
            (
                "equidistant, linear",
                TableType::Equidistant,
                true,
                CamInterpolation::Linear,
            ),
            (
                "equidistant, 4-point",
                TableType::Equidistant,
                true,
                CamInterpolation::FourPoint,
            ),
            (
                "non-equidistant, spline",
                TableType::NonEquidistant,
                false,
                CamInterpolation::Spline,
            ),
        ] {
            let r = rows(n, even);
            let t = PositionTable::new(&r, ty, interpolation, false).expect("bench table");
            cases.push((format!("table {n} rows, {name}"), CamProfile::Table(t), r));
        }
    }
    println!("cam evaluation while the master sweeps its range ({EVALS} evaluations per sweep, median of {REPEATS} interleaved repeats)");
    println!(
        "{:<46} {:>10} {:>16} {:>7}",
        "profile", "ns/eval", "binary search ns", "ratio"
    );
    let mut ours: Vec<Vec<f64>> = vec![Vec::new(); cases.len()];
    let mut base: Vec<Vec<f64>> = vec![Vec::new(); cases.len()];
    for _ in 0..scaled(REPEATS) {
        for (i, (_, profile, r)) in cases.iter().enumerate() {
            ours[i].push(sweep(profile, scaled(EVALS)));
            base[i].push(sweep_binary_search(r, scaled(EVALS)));
        }
    }
    // Like for like: the baseline interpolates linearly, so the linear tables are judged.
    let mut worst = f64::INFINITY;
    for (i, (name, _, _)) in cases.iter().enumerate() {
        let (o, b) = (median(ours[i].clone()), median(base[i].clone()));
        println!("{name:<46} {o:>10.1} {b:>16.1} {:>6.2}x", b / o);
        if name.ends_with(", linear") {
            worst = worst.min(b / o);
        }
    }
    println!(
        "TARGET | linear position tables no slower than a binary search with linear interpolation | worst {worst:.2}x faster | {}",
        if worst >= 1.0 { "met" } else { "MISSED" }
    );
    // Fast masters skip rows between ticks: 20 rows per evaluation on the large table.
    let r = rows(100_000, false);
    let t = CamProfile::Table(
        PositionTable::new(
            &r,
            TableType::NonEquidistant,
            CamInterpolation::Linear,
            false,
        )
        .unwrap(),
    );
    let (o, b) = (
        median((0..scaled(REPEATS)).map(|_| sweep(&t, 5_000)).collect()),
        median(
            (0..scaled(REPEATS))
                .map(|_| sweep_binary_search(&r, 5_000))
                .collect(),
        ),
    );
    println!(
        "{:<46} {o:>10.1} {b:>16.1} {:>6.2}x",
        "table 100000 rows, 20 rows per evaluation",
        b / o
    );
}
