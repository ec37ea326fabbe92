//! Properties of motion functions over random valid point sets: monotonic master, continuity
//! across segment joints, no NaN, derivatives that agree with finite differences. Random
//! sets the controller refuses must be refused for a stated reason (a boundary conflict of
//! the point types and laws drawn), never silently.

use cnc_core::cam::law::EndKind;
use cnc_core::cam::motion_function::Cursor;
use cnc_core::cam::{CamError, FunctionType, MotionFunction, MotionFunctionPoint, PointType};
use proptest::prelude::*;

fn law() -> impl Strategy<Value = FunctionType> {
    proptest::sample::select(FunctionType::all().to_vec())
}

fn point_type() -> impl Strategy<Value = PointType> {
    proptest::sample::select(vec![
        PointType::Rest,
        PointType::Velocity,
        PointType::Turn,
        PointType::Motion,
    ])
}

prop_compose! {
    fn points()(
        n in 2usize..7,
        laws in proptest::collection::vec(law(), 7),
        types in proptest::collection::vec(point_type(), 7),
        steps in proptest::collection::vec(0.5f64..50.0, 7),
        slaves in proptest::collection::vec(-20.0f64..20.0, 7),
        values in proptest::collection::vec((-1.0f64..1.0, -0.1f64..0.1, -0.01f64..0.01), 7),
        symmetry in proptest::collection::vec(-0.45f64..0.45, 7),
        falling in any::<bool>(),
    ) -> Vec<MotionFunctionPoint> {
        let mut master = 0.0;
        (0..n).map(|i| {
            master += steps[i];
            let mut p = MotionFunctionPoint::new(i as u32 + 1, laws[i], types[i], if falling { -master } else { master }, slaves[i]);
            p.velocity = values[i].0;
            p.acceleration = values[i].1;
            p.jerk = if laws[i].has_symmetry() { symmetry[i] } else { values[i].2 };
            p
        }).collect()
    }
}

fn sample(f: &MotionFunction, x: f64) -> [f64; 4] {
    let s = f.eval(x, &mut Cursor::new());
    [s.position, s.velocity, s.acceleration, s.jerk]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn random_point_sets_build_continuous_finite_functions(points in points()) {
        let f = match MotionFunction::new(&points) {
            Ok(f) => f,
            Err(e) => {
                // Random types and laws may contradict each other at a point: that, and only
                // that, is a reason to refuse finite, monotonic, well-indexed points.
                prop_assert!(matches!(e, CamError::BoundaryConflict { .. }), "{}", e);
                return Ok(());
            }
        };
        let segs = f.segments();
        let dir = (segs[0].master.1 - segs[0].master.0).signum();
        for s in segs {
            prop_assert!((s.master.1 - s.master.0) * dir > 0.0, "master monotonic");
        }
        // Continuity at every joint between segments.
        for w in segs.windows(2) {
            // Each side's own formula at the joint (pieces run in the rising coordinate).
            let x = w[0].master.1 * dir;
            let left = f.segment_pieces(&w[0]);
            let right = f.segment_pieces(&w[1]);
            let (l, r) = (left[left.len() - 1].eval(x), right[0].eval(x));
            let steps = w[0].law == FunctionType::Step || w[1].law == FunctionType::Step;
            if !steps {
                prop_assert!((l[0] - r[0]).abs() < 1e-5, "position at {}: {} vs {}", x, l[0], r[0]);
                prop_assert!((l[1] - r[1]).abs() < 1e-5 * (1.0 + l[1].abs()), "velocity at {}: {} vs {}", x, l[1], r[1]);
                let p3 = w[0].law == FunctionType::Polynom3 || w[1].law == FunctionType::Polynom3;
                if !p3 {
                    prop_assert!((l[2] - r[2]).abs() < 1e-4 * (1.0 + l[2].abs()), "acceleration at {}: {} vs {} ({:?} -> {:?})", x, l[2], r[2], w[0].law, w[1].law);
                }
            }
        }
        // Finite everywhere, and each derivative the slope of the order below it.
        let (lo, hi) = f.master_range();
        for i in 0..=400 {
            let x = lo + (hi - lo) * i as f64 / 400.0;
            let d = sample(&f, x);
            prop_assert!(d.iter().all(|v| v.is_finite()), "non-finite at {}: {:?}", x, d);
        }
        // The difference quotients are taken inside each piece of a segment, never across a
        // cut between pieces: the joint check above is all a cut promises (position, velocity,
        // acceleration), and many laws jump in jerk there (the ramp ends of a trapezoid, the
        // turning point of a law with a symmetry). A stencil straddling such a cut sees a kink
        // in the acceleration, whose difference quotient is a blend of the two jerks.
        for s in segs {
            if s.law == FunctionType::Step {
                continue;
            }
            let (a, b) = s.master;
            let h = 1e-5 * (b - a);
            // Pieces run in the rising coordinate. Those shorter than 10 h cannot hold the
            // stencils; the segment always has longer ones.
            let inner: Vec<(f64, f64)> = f
                .segment_pieces(s)
                .iter()
                .map(|p| (p.start * dir, p.end * dir))
                .filter(|(p0, p1)| (p1 - p0).abs() >= 10.0 * h.abs())
                .collect();
            prop_assert!(!inner.is_empty(), "no piece of {:?} to differentiate", s.law);
            let stencils = inner.iter().flat_map(|p| [0.13, 0.37, 0.61, 0.89].map(|t| (*p, t)));
            for ((p0, p1), t) in stencils {
                let x = p0 + (p1 - p0) * t;
                let (m, p, q) = (sample(&f, x - h), sample(&f, x), sample(&f, x + h));
                for k in 0..3 {
                    let fd = (q[k] - m[k]) / (2.0 * h);
                    let scale = 1.0 + p[k + 1].abs() + p[k].abs() / (b - a).abs();
                    prop_assert!((fd - p[k + 1]).abs() < 1e-4 * scale, "order {} at {} in {:?}: {} vs {}", k + 1, x, s.law, fd, p[k + 1]);
                }
            }
        }
    }

    #[test]
    fn motion_points_accept_every_law_but_turn_ends_next_to_lines(points in points()) {
        // With motion points everywhere, only two laws demanding different values at one
        // point can refuse: a line (slope) or a turn (v = 0) against another demand.
        let points: Vec<_> = points.into_iter().map(|mut p| { p.point_type = PointType::Motion.raw(); p }).collect();
        if let Err(CamError::BoundaryConflict { point, .. }) = MotionFunction::new(&points) {
            let k = point as usize - 1;
            let before = (k > 0).then(|| FunctionType::from_raw(points[k - 1].function).unwrap().ends().1);
            let after = (k + 1 < points.len()).then(|| FunctionType::from_raw(points[k].function).unwrap().ends().0);
            let demands_v = |e: Option<EndKind>| matches!(e, Some(EndKind::Line | EndKind::Rest | EndKind::Turn));
            let demands_a = |e: Option<EndKind>| e.is_some() && !matches!(e, Some(EndKind::Motion));
            prop_assert!((demands_v(before) && demands_v(after)) || (demands_a(before) && demands_a(after)));
        }
    }
}
