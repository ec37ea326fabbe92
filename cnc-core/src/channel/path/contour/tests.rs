//! The contour against its promises: every tick within the tolerance of the programmed path
//! and within every axis's velocity, acceleration and jerk; at rest at the end; braking on
//! the path for feed hold and a stop.

use super::*;
use proptest::prelude::*;

pub(super) const CYCLE: f64 = 0.001;

pub(super) fn limits(n: usize) -> Vec<AxisLimits> {
    vec![
        AxisLimits {
            velocity: 200.0,
            acceleration: 2000.0,
            jerk: 40_000.0,
        };
        n
    ]
}

/// The polyline's corners.
fn zigzag(n: usize, length: f64, turn_deg: f64) -> Vec<[f64; 3]> {
    let mut points = vec![[0.0; 3]];
    for k in 0..n {
        let phi = if k % 2 == 0 {
            0.0
        } else {
            turn_deg.to_radians()
        };
        let [x, y, z] = points[k];
        points.push([x + length * phi.cos(), y + length * phi.sin(), z]);
    }
    points
}

fn values(p: [f64; 3]) -> AxisValues {
    AxisValues::from_slice(&p)
}

/// What a run gave, tick by tick: the position and the block under way (its index in the
/// polyline: block `k` runs from point `k - 1` to point `k`).
pub(super) struct Trace {
    pub(super) positions: Vec<AxisValues>,
    pub(super) blocks: Vec<usize>,
}

/// Runs `points` at `feed` (mm/s) with `tolerance` (None: exact stop), feeding blocks as the
/// window takes them; `hold` = (tick it starts, ticks it lasts).
fn run(
    points: &[[f64; 3]],
    feed: f64,
    tolerance: Option<f64>,
    hold: Option<(usize, usize)>,
) -> Trace {
    let schedule = match hold {
        Some((at, len)) => vec![(at, 0.0), (at + len, 1.0)],
        None => Vec::new(),
    };
    run_with(points, feed, tolerance, &schedule)
}

/// [`run`] with the feed and rapid override set to `factor` at each `(tick, factor)`.
fn run_with(
    points: &[[f64; 3]],
    feed: f64,
    tolerance: Option<f64>,
    schedule: &[(usize, f64)],
) -> Trace {
    let lim = limits(3);
    let mut c = Contour::new(&lim, CYCLE, 16);
    let mut next = 1;
    let mut pos = values(points[0]);
    let (mut vel, mut acc) = (AxisValues::zeros(3), AxisValues::zeros(3));
    let mut positions = vec![pos];
    let mut blocks = vec![1];
    for tick in 0..2_000_000 {
        while next < points.len() && c.has_room() {
            let seg = Segment {
                start: values(points[next - 1]),
                end: values(points[next]),
                feed,
                rapid: false,
                line: next as u32,
                blend: tolerance,
                chamfer: true,
                on_arc: false,
            };
            c.push(&seg, &mut |_| {}).expect("a straight block");
            next += 1;
        }
        if next == points.len() {
            c.close();
        }
        for &(_, factor) in schedule.iter().filter(|(at, _)| *at == tick) {
            c.set_factors(factor, factor);
        }
        let moving = c.step(&mut pos, &mut vel, &mut acc).expect("no fault");
        positions.push(pos);
        blocks.push(c.line().map_or(*blocks.last().unwrap(), |l| l as usize));
        if !moving && next == points.len() {
            return Trace { positions, blocks };
        }
    }
    panic!("did not finish");
}

fn dist_to_segment(p: &[f64], a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let ab: Vec<f64> = (0..3).map(|i| b[i] - a[i]).collect();
    let ap: Vec<f64> = (0..3).map(|i| p[i] - a[i]).collect();
    let len2: f64 = ab.iter().map(|v| v * v).sum();
    let t = if len2 > 0.0 {
        (ap.iter().zip(&ab).map(|(x, y)| x * y).sum::<f64>() / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..3)
        .map(|i| (ap[i] - t * ab[i]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// The largest distance of any tick from the programmed path: each tick against the block
/// under way and its neighbours (a corner's curve carries the line of the block before it), so
/// a block that passes close to another part of the path by coincidence is not taken for the
/// one under way.
fn worst_deviation(trace: &Trace, points: &[[f64; 3]]) -> f64 {
    let mut worst = 0.0f64;
    for (p, &block) in trace.positions.iter().zip(&trace.blocks) {
        let lo = block.saturating_sub(2);
        let hi = (block + 1).min(points.len() - 1);
        let best = (lo..hi)
            .map(|s| dist_to_segment(p, &points[s], &points[s + 1]))
            .fold(f64::INFINITY, f64::min);
        worst = worst.max(best);
    }
    worst
}

/// The largest |velocity|, |acceleration| and |jerk| of any axis by differences over ticks.
pub(super) fn worst_rates(trace: &Trace) -> (f64, f64, f64) {
    let p = &trace.positions;
    let (mut v, mut a, mut j) = (0.0f64, 0.0f64, 0.0f64);
    for k in 3..p.len() {
        for (((p0, p1), p2), p3) in p[k - 3].iter().zip(&*p[k - 2]).zip(&*p[k - 1]).zip(&*p[k]) {
            v = v.max(((p3 - p2) / CYCLE).abs());
            a = a.max(((p3 - 2.0 * p2 + p1) / CYCLE.powi(2)).abs());
            j = j.max(((p3 - 3.0 * p2 + 3.0 * p1 - p0) / CYCLE.powi(3)).abs());
        }
    }
    (v, a, j)
}

fn assert_within_limits(trace: &Trace) {
    let l = limits(1)[0];
    let (v, a, j) = worst_rates(trace);
    assert!(v <= l.velocity * (1.0 + 1e-6), "velocity {v}");
    assert!(a <= l.acceleration * (1.0 + 1e-6), "acceleration {a}");
    assert!(j <= l.jerk * (1.0 + 1e-6), "jerk {j}");
}

#[test]
fn a_zigzag_runs_through_its_corners_within_tolerance_and_limits() {
    let points = zigzag(200, 1.0, 10.0);
    let tol = 0.05;
    let cont = run(&points, 100.0, Some(tol), None);
    let exact = run(&points, 100.0, None, None);
    let dev = worst_deviation(&cont, &points);
    assert!(dev <= tol + 1e-9, "deviation {dev}");
    assert!(dev > 0.2 * tol, "corners are rounded: {dev}");
    assert_within_limits(&cont);
    assert_within_limits(&exact);
    assert!(worst_deviation(&exact, &points) <= 1e-9);
    let (tc, te) = (cont.positions.len(), exact.positions.len());
    assert!(3 * tc < te, "continuous {tc} ticks, exact stop {te}");
    let end = cont.positions.last().unwrap();
    assert_eq!(&end[..], &points[200][..]);
}

#[test]
fn feed_hold_brakes_on_the_path_and_goes_on() {
    let points = zigzag(60, 2.0, 30.0);
    let tol = 0.05;
    for at in [50, 137, 300] {
        let held = run(&points, 150.0, Some(tol), Some((at, 400)));
        assert!(worst_deviation(&held, &points) <= tol + 1e-9);
        assert_within_limits(&held);
        // It stood still for a while.
        let p = &held.positions;
        let still = (1..p.len()).filter(|&k| p[k] == p[k - 1]).count();
        assert!(still > 100, "held at {at}: {still} ticks still");
        assert_eq!(&p.last().unwrap()[..], &points[60][..]);
    }
}

#[test]
fn a_stop_comes_to_rest_on_the_path_and_empties_the_window() {
    let points = zigzag(100, 1.0, 20.0);
    let lim = limits(3);
    let mut c = Contour::new(&lim, CYCLE, 16);
    let mut pos = values(points[0]);
    let (mut vel, mut acc) = (AxisValues::zeros(3), AxisValues::zeros(3));
    let mut next = 1;
    let mut trace = Trace {
        positions: vec![pos],
        blocks: vec![1],
    };
    for tick in 0..100_000 {
        while next < points.len() && c.has_room() {
            let seg = Segment {
                start: values(points[next - 1]),
                end: values(points[next]),
                feed: 150.0,
                rapid: false,
                line: next as u32,
                blend: Some(0.02),
                chamfer: true,
                on_arc: false,
            };
            c.push(&seg, &mut |_| {}).unwrap();
            next += 1;
        }
        if tick == 200 {
            c.stop();
        }
        let moving = c.step(&mut pos, &mut vel, &mut acc).unwrap();
        trace.positions.push(pos);
        let last = *trace.blocks.last().unwrap();
        trace.blocks.push(c.line().map_or(last, |l| l as usize));
        if tick > 200 && !moving {
            break;
        }
    }
    assert!(!c.active());
    assert!(worst_deviation(&trace, &points) <= 0.02 + 1e-9);
    assert_within_limits(&trace);
    let n = trace.positions.len();
    let last_step = (0..3)
        .map(|i| (trace.positions[n - 1][i] - trace.positions[n - 2][i]).abs())
        .fold(0.0, f64::max);
    assert!(last_step < 1e-6, "at rest: {last_step}");
    assert!(n < 1000, "stopped early: {n}");
}

#[test]
fn a_reversal_and_a_sharp_corner_stop_exactly() {
    let points = vec![
        [0.0, 0.0, 0.0],
        [10.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [5.0, 1.5, 0.0],
    ];
    let t = run(&points, 100.0, Some(0.5), None);
    assert!(worst_deviation(&t, &points) <= 1e-9, "no rounding");
    assert!(
        t.positions.iter().any(|p| p[..] == points[1][..]),
        "rests at the turn"
    );
    assert_within_limits(&t);
}

/// Every tick within `tol` of the path and within every limit, the run ending on the last
/// point; else what broke.
fn kept_its_promises(t: &Trace, points: &[[f64; 3]], tol: f64) -> Result<(), String> {
    let dev = worst_deviation(t, points);
    let l = limits(1)[0];
    let (v, a, j) = worst_rates(t);
    let slack = 1.0 + 1e-6;
    let end = &t.positions.last().unwrap()[..];
    if dev > tol + 1e-9 {
        Err(format!("deviation {dev} > {tol}"))
    } else if v > l.velocity * slack || a > l.acceleration * slack || j > l.jerk * slack {
        Err(format!("velocity {v}, acceleration {a}, jerk {j}"))
    } else if end != &points.last().unwrap()[..] {
        Err(format!("ended at {end:?}"))
    } else {
        Ok(())
    }
}

/// The points of a walk from the origin: each step's length, turn of the heading (rad) and
/// climb in Z.
fn walk(steps: &[(f64, f64, f64)]) -> Vec<[f64; 3]> {
    let mut points = vec![[0.0, 0.0, 0.0]];
    let mut heading = 0.0f64;
    for &(len, turn, climb) in steps {
        heading += turn;
        let [x, y, z] = *points.last().unwrap();
        points.push([x + len * heading.cos(), y + len * heading.sin(), z + climb]);
    }
    points
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn random_polylines_keep_tolerance_and_limits(
        steps in proptest::collection::vec((0.05f64..8.0, -3.0f64..3.0, -1.0f64..1.0), 2..25),
        tol in 0.001f64..0.5,
        feed in 5.0f64..300.0,
    ) {
        let points = walk(&steps);
        let t = run(&points, feed, Some(tol), None);
        if let Err(e) = kept_its_promises(&t, &points, tol) {
            return Err(TestCaseError::fail(e));
        }
    }
}

/// Braking part of the way can take longer than braking to rest: entered at 100 mm/s with a
/// bound of 33 mm/s (the override just lowered) and 5.2 mm to go, 33 does not fit (5.44 mm)
/// though 0 does (5.00 mm). The end velocity chosen is one the piece can reach.
#[test]
fn an_end_velocity_between_the_bounds_that_does_not_fit_is_not_chosen() {
    let lim = limits(3);
    let mut dir = AxisValues::zeros(3);
    dir[0] = 1.0;
    let mut p = Piece::straight(AxisValues::zeros(3), dir, 5.2, 5.2, &lim);
    p.bound_soft = 33.0;
    p.bound_hard = 100.0;
    let d = p.dynamics;
    assert!(profile::change_distance(100.0, 33.0, d) > 5.2);
    assert!(profile::change_distance(100.0, 0.0, d) <= 5.2);
    let v = feasible_end(100.0, 5.2, d, p.bound_soft, p.bound_hard);
    assert!(
        profile::change_distance(100.0, v, d) <= 5.2 * (1.0 + 1e-12) + 1e-15,
        "{v}: {}",
        profile::change_distance(100.0, v, d)
    );
    assert!(v <= 33.0, "{v}");
    assert!(PieceProfile::plan(5.2, 100.0, v, 33.0, d).is_some());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Override changes at random moments (lowered, raised, held, released) never fault the
    /// contour, never leave the tolerance or a limit, and the path still ends on its last point.
    #[test]
    fn random_override_changes_keep_tolerance_and_limits(
        steps in proptest::collection::vec((0.05f64..6.0, -2.3f64..2.3), 2..20),
        changes in proptest::collection::vec((0usize..400, 0.0f64..2.0), 1..8),
        tol in 0.005f64..0.3,
        feed in 20.0f64..200.0,
    ) {
        let mut points = vec![[0.0, 0.0, 0.0]];
        let mut heading = 0.0f64;
        for (len, turn) in steps {
            heading += turn;
            let [x, y, z] = *points.last().unwrap();
            points.push([x + len * heading.cos(), y + len * heading.sin(), z]);
        }
        // Below 10 % counts as a hold; every run ends released at 100 %.
        let mut schedule: Vec<(usize, f64)> = changes
            .iter()
            .map(|&(at, f)| (at, if f < 0.1 { 0.0 } else { f }))
            .collect();
        schedule.sort_by_key(|c| c.0);
        schedule.push((401, 1.0));
        let t = run_with(&points, feed, Some(tol), &schedule);
        if let Err(e) = kept_its_promises(&t, &points, tol) {
            return Err(TestCaseError::fail(e));
        }
    }
}

/// Points on a circle of `radius` (a polygon of `n` sides), starting at angle 0.
fn polygon(n: usize, radius: f64) -> Vec<[f64; 3]> {
    (0..=n)
        .map(|k| {
            let phi = std::f64::consts::TAU * k as f64 / n as f64;
            [radius * phi.cos(), radius * phi.sin(), 0.0]
        })
        .collect()
}

fn path_length(points: &[[f64; 3]]) -> f64 {
    points
        .windows(2)
        .map(|w| {
            (0..3)
                .map(|i| (w[1][i] - w[0][i]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum()
}

/// CAM output: a circle of 1 mm chords runs close to its feed (the curves of neighbouring
/// corners share their curvature and the path accelerates through their boundaries); before,
/// each corner's curvature rose from 0 and fell back, capping the speed at 74 mm/s, and every
/// piece started and ended without acceleration (2.2x the time at the feed).
#[test]
fn a_dense_polygon_runs_close_to_its_feed() {
    let points = polygon(300, 50.0);
    let t = run(&points, 100.0, Some(0.02), None);
    kept_its_promises(&t, &points, 0.02).unwrap();
    let at_feed = path_length(&points) / 100.0 / CYCLE;
    let ratio = t.positions.len() as f64 / at_feed;
    assert!(ratio < 1.15, "{ratio:.3}x the time at the feed");
}

/// A corner passed so slowly on its curve (90 degrees within 0.02 mm) that stopping there is
/// quicker is stopped at: continuous path takes exactly exact stop's time on a zigzag of them.
#[test]
fn a_corner_quicker_to_stop_at_is_stopped_at() {
    let points: Vec<[f64; 3]> = (0..=20)
        .map(|k| [2.0 * k as f64, if k % 2 == 0 { 0.0 } else { 2.0 }, 0.0])
        .collect();
    let cont = run(&points, 100.0, Some(0.02), None);
    let exact = run(&points, 100.0, None, None);
    assert_eq!(cont.positions.len(), exact.positions.len());
    assert!(worst_deviation(&cont, &points) <= 1e-9);
    // A wider tolerance makes the curves fast enough to pass.
    let wide = run(&points, 100.0, Some(0.5), None);
    assert!(wide.positions.len() < exact.positions.len());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Continuous path never takes longer than exact stop on the same blocks.
    #[test]
    fn continuous_path_is_never_slower_than_exact_stop(
        steps in proptest::collection::vec((0.05f64..8.0, -3.0f64..3.0, -1.0f64..1.0), 2..25),
        tol in 0.001f64..0.5,
        feed in 5.0f64..300.0,
    ) {
        let points = walk(&steps);
        let cont = run(&points, feed, Some(tol), None).positions.len();
        let exact = run(&points, feed, None, None).positions.len();
        prop_assert!(cont <= exact, "continuous {cont} ticks, exact stop {exact}");
    }

    /// CAM-like polylines (chords of a curve whose curvature wanders, of uneven lengths, with
    /// the points rounded as a post-processor writes them) keep the tolerance and every limit
    /// and end on their last point.
    #[test]
    fn cam_like_polylines_keep_tolerance_and_limits(
        chords in proptest::collection::vec((0.1f64..2.0, -0.2f64..0.2), 5..60),
        tol in 0.002f64..0.1,
        feed in 20.0f64..200.0,
    ) {
        let mut points = vec![[0.0, 0.0, 0.0]];
        let (mut heading, mut bend) = (0.0f64, 0.05f64);
        for (len, wander) in chords {
            bend = (bend + 0.1 * wander).clamp(-0.3, 0.3);
            heading += bend * len;
            let [x, y, z] = *points.last().unwrap();
            let round = |v: f64| (v * 1e4).round() / 1e4;
            points.push([round(x + len * heading.cos()), round(y + len * heading.sin()), z]);
        }
        let t = run(&points, feed, Some(tol), None);
        if let Err(e) = kept_its_promises(&t, &points, tol) {
            return Err(TestCaseError::fail(e));
        }
    }
}

/// Noise around a line (a zigzag of 1 mm blocks turning by ±10 degrees, its points within
/// 0.044 mm of one straight line): the chords through the blocks' middles are nearly one line
/// within the tolerance of 0.05 mm, and the path runs at its feed; rounding each corner on its
/// own took 2.9x the time at the feed.
#[test]
fn noise_around_a_line_runs_at_the_feed_on_chords() {
    let points = zigzag(300, 1.0, 10.0);
    let t = run(&points, 100.0, Some(0.05), None);
    kept_its_promises(&t, &points, 0.05).unwrap();
    let at_feed = path_length(&points) / 100.0 / CYCLE;
    let ratio = t.positions.len() as f64 / at_feed;
    assert!(ratio < 1.1, "{ratio:.3}x the time at the feed");
}
