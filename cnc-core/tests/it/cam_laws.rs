//! Every motion law: boundary conditions for each pair of point types, characteristic values
//! against the published ones and against a fine numerical sweep, symmetry.

use cnc_core::cam::law::EndKind;
use cnc_core::cam::motion_function::Cursor;
use cnc_core::cam::{
    CamError, CamProfile, CharacValues, FunctionType, MotionFunction, MotionFunctionPoint,
    PointType, Sample, TableErrorCode,
};
use std::f64::consts::PI;

const TYPES: [PointType; 4] = [
    PointType::Rest,
    PointType::Velocity,
    PointType::Turn,
    PointType::Motion,
];

/// Two points: the law from (10, 5) to (60, 25) (rise 20 over 50), user values everywhere.
fn two_points(law: FunctionType, a: PointType, b: PointType) -> [MotionFunctionPoint; 2] {
    let mut p = MotionFunctionPoint::new(1, law, a, 10.0, 5.0);
    let mut q = MotionFunctionPoint::new(2, FunctionType::Polynom1, b, 60.0, 25.0);
    for (point, v, acc, j) in [(&mut p, 0.3, -0.01, 0.001), (&mut q, 0.2, -0.02, -0.002)] {
        point.velocity = v;
        point.acceleration = acc;
        point.jerk = if law.has_symmetry() { 0.0 } else { j };
    }
    [p, q]
}

fn at(f: &MotionFunction, x: f64) -> Sample {
    f.eval(x, &mut Cursor::new())
}

fn near(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))
}

/// Whether the controller must accept a law end at a point of this type: a turn end
/// produces an acceleration that rest and velocity points forbid; a line's slope (0.4 here)
/// contradicts the zero velocity of rest and turn points.
fn accepted(kind: EndKind, ty: PointType) -> bool {
    match kind {
        EndKind::Turn => matches!(ty, PointType::Turn | PointType::Motion),
        EndKind::Line => matches!(ty, PointType::Velocity | PointType::Motion),
        _ => true,
    }
}

#[test]
fn every_law_meets_its_boundary_conditions_for_every_point_type_pair() {
    let mut accepted_pairs = 0;
    for law in FunctionType::all() {
        let (start_kind, end_kind) = law.ends();
        for a in TYPES {
            for b in TYPES {
                let points = two_points(*law, a, b);
                let result = MotionFunction::new(&points);
                let expect = accepted(start_kind, a) && accepted(end_kind, b);
                let f = match (result, expect) {
                    (Ok(f), true) => f,
                    (Err(e), false) => {
                        assert!(
                            matches!(e, CamError::BoundaryConflict { .. }),
                            "{law:?} {a:?}->{b:?}: {e}"
                        );
                        assert_eq!(e.code(), TableErrorCode::PointIdInvalid);
                        continue;
                    }
                    (Ok(_), false) => panic!("{law:?} {a:?}->{b:?} accepted, must be refused"),
                    (Err(e), true) => panic!("{law:?} {a:?}->{b:?} refused: {e}"),
                };
                accepted_pairs += 1;
                let (s, e) = (at(&f, 10.0), f.segments()[0].end);
                let end = at(&f, 60.0);
                assert!(
                    near(s.position, 5.0) && near(end.position, 25.0),
                    "{law:?} positions"
                );
                // Values at the ends from the pieces themselves (just inside the segment).
                let s_in = at(&f, 10.0);
                let e_in = at(&f, 60.0 - 1e-12);
                for (kind, ty, sample, user_v, user_a) in [
                    (start_kind, a, s_in, 0.3, -0.01),
                    (end_kind, b, e_in, 0.2, -0.02),
                ] {
                    let name = format!("{law:?} {a:?}->{b:?} {kind:?} end at {ty:?}");
                    let check = |got: f64, want: f64, what: &str| {
                        assert!(
                            (got - want).abs() < 1e-6 * (1.0 + want.abs()),
                            "{name}: {what} {got} != {want}"
                        );
                    };
                    // What the point type fixes.
                    // (A 3rd-order polynomial cannot end with zero acceleration: it keeps
                    // its own, 6 h / L^2, as the seed's rest-to-rest law of that order must.)
                    let p3 = *law == FunctionType::Polynom3;
                    match ty {
                        PointType::Rest => {
                            check(sample.velocity, 0.0, "velocity");
                            if !p3 {
                                check(sample.acceleration, 0.0, "acceleration");
                            }
                        }
                        PointType::Velocity if !p3 => {
                            check(sample.acceleration, 0.0, "acceleration")
                        }
                        PointType::Velocity => {}
                        PointType::Turn => check(sample.velocity, 0.0, "velocity"),
                        _ => {}
                    }
                    // What the law fixes, and user values where nothing else does.
                    match kind {
                        EndKind::Rest | EndKind::Turn => check(sample.velocity, 0.0, "velocity"),
                        EndKind::Line => {
                            check(sample.velocity, 0.4, "slope");
                            check(sample.acceleration, 0.0, "acceleration");
                        }
                        EndKind::Velocity => {
                            check(sample.acceleration, 0.0, "acceleration");
                            if matches!(ty, PointType::Velocity | PointType::Motion) {
                                check(sample.velocity, user_v, "user velocity");
                            }
                        }
                        EndKind::Motion => {
                            if ty == PointType::Motion {
                                check(sample.velocity, user_v, "user velocity");
                                check(sample.acceleration, user_a, "user acceleration");
                            }
                        }
                    }
                    if kind == EndKind::Turn && ty == PointType::Motion {
                        // The law's own acceleration replaces the user's.
                        assert!((sample.acceleration - user_a).abs() > 1e-6, "{name}");
                    }
                }
                // The settled end state is what the function does.
                assert!(
                    (e.v - e_in.velocity).abs() < 1e-6,
                    "{law:?} settled end velocity"
                );
            }
        }
    }
    assert!(accepted_pairs > 250, "{accepted_pairs} pairs accepted");
}

/// A rest-to-rest law over master 0..1 with stroke 1: its characteristic values are the
/// law's dimensionless coefficients.
fn unit(law: FunctionType, symmetry: f64) -> CamProfile {
    let mut p = MotionFunctionPoint::new(1, law, PointType::Rest, 0.0, 0.0);
    p.jerk = symmetry;
    let q = MotionFunctionPoint::new(2, FunctionType::Polynom1, PointType::Rest, 1.0, 1.0);
    CamProfile::MotionFunction(MotionFunction::new(&[p, q]).expect("unit law"))
}

#[test]
fn characteristic_values_match_the_published_coefficients() {
    // (law, Cv, Ca, Cj) from the motion-law literature (VDI 2143 tables).
    let published = [
        (FunctionType::Polynom5, 1.875, 10.0 / 3f64.sqrt(), 60.0),
        (FunctionType::SineLine, 2.0, 2.0 * PI, 4.0 * PI * PI),
        (
            FunctionType::ModifiedSineLine,
            4.0 * PI / (4.0 + PI),
            4.0 * PI * PI / (4.0 + PI),
            16.0 * PI * PI * PI / (4.0 + PI),
        ),
        (FunctionType::Polynom3, 1.5, 6.0, 12.0),
    ];
    for (law, cv, ca, cj) in published {
        let c = CharacValues::normed(&unit(law, 0.0));
        assert!(
            (c.fSlaveVeloMax - cv).abs() < 1e-9,
            "{law:?} Cv {}",
            c.fSlaveVeloMax
        );
        assert!(
            (c.fSlaveAccMax - ca).abs() < 1e-9,
            "{law:?} Ca {}",
            c.fSlaveAccMax
        );
        assert!(
            (c.fSlaveAccMin + ca).abs() < 1e-9,
            "{law:?} -Ca {}",
            c.fSlaveAccMin
        );
        if cj > 0.0 {
            let peak = c.fSlaveJerkMax.abs().max(c.fSlaveJerkMin.abs());
            assert!((peak - cj).abs() < 1e-9, "{law:?} Cj {peak}");
        }
        assert!(
            (c.fMPosAtSVeloMax - 0.5).abs() < 1e-9,
            "{law:?} peak velocity mid-way"
        );
        assert!(
            (c.fSlaveVeloMean - 1.0).abs() < 1e-9,
            "{law:?} mean |v| = stroke / range"
        );
    }
    // The rounded figures the issue quotes.
    let m = CharacValues::normed(&unit(FunctionType::ModifiedSineLine, 0.0));
    assert!((m.fSlaveVeloMax - 1.7596).abs() < 5e-5 && (m.fSlaveAccMax - 5.5280).abs() < 5e-5);
    // RMS acceleration of POLYNOM5: sqrt(integral of (60z - 180z^2 + 120z^3)^2) = sqrt(120/7).
    let p5 = CharacValues::normed(&unit(FunctionType::Polynom5, 0.0));
    assert!(
        (p5.fSlaveAccEff - (120.0f64 / 7.0).sqrt()).abs() < 1e-9,
        "{}",
        p5.fSlaveAccEff
    );
}

#[test]
fn characteristic_values_agree_with_a_fine_sweep_for_every_law() {
    for law in FunctionType::all() {
        for (a, b) in [
            (PointType::Motion, PointType::Motion),
            (PointType::Rest, PointType::Rest),
            (PointType::Velocity, PointType::Turn),
            (PointType::Turn, PointType::Velocity),
            (PointType::Velocity, PointType::Velocity),
        ] {
            let Ok(f) = MotionFunction::new(&two_points(*law, a, b)) else {
                continue;
            };
            let profile = CamProfile::MotionFunction(f);
            let c = CharacValues::normed(&profile);
            let n = 200_000;
            let mut cursor = Default::default();
            let (mut vmax, mut vmin, mut amax, mut amin) = (f64::MIN, f64::MAX, f64::MIN, f64::MAX);
            let (mut pmax, mut pmin) = (f64::MIN, f64::MAX);
            for i in 0..=n {
                let x = 10.0 + 50.0 * i as f64 / n as f64;
                let s = profile.eval(x, &mut cursor);
                assert!(
                    s.position.is_finite()
                        && s.velocity.is_finite()
                        && s.acceleration.is_finite()
                        && s.jerk.is_finite()
                );
                pmax = pmax.max(s.position);
                pmin = pmin.min(s.position);
                vmax = vmax.max(s.velocity);
                vmin = vmin.min(s.velocity);
                amax = amax.max(s.acceleration);
                amin = amin.min(s.acceleration);
            }
            let name = format!("{law:?} {a:?}->{b:?}");
            // The sweep can only find less extreme values, and not much less.
            for (exact, swept, what) in [
                (c.fSlavePosMax, pmax, "pos max"),
                (c.fSlaveVeloMax, vmax, "velo max"),
                (c.fSlaveAccMax, amax, "acc max"),
            ] {
                assert!(
                    exact >= swept - 1e-12 && exact - swept < 1e-6 * (1.0 + exact.abs()),
                    "{name} {what}: {exact} vs {swept}"
                );
            }
            for (exact, swept, what) in [
                (c.fSlavePosMin, pmin, "pos min"),
                (c.fSlaveVeloMin, vmin, "velo min"),
                (c.fSlaveAccMin, amin, "acc min"),
            ] {
                assert!(
                    exact <= swept + 1e-12 && swept - exact < 1e-6 * (1.0 + exact.abs()),
                    "{name} {what}: {exact} vs {swept}"
                );
            }
        }
    }
}

#[test]
fn rescaling_to_a_master_velocity_scales_each_order() {
    let c = CharacValues::normed(&unit(FunctionType::Polynom5, 0.0));
    let r = c.rescaled(3.0).unwrap();
    assert!(c.rescaled(0.0).is_none() && c.rescaled(f64::NAN).is_none());
    assert_eq!(r.fMasterVeloNom, 3.0);
    assert!((r.fSlaveVeloMax - 3.0 * c.fSlaveVeloMax).abs() < 1e-12);
    assert!((r.fSlaveAccMax - 9.0 * c.fSlaveAccMax).abs() < 1e-12);
    assert!((r.fSlaveJerkMax - 27.0 * c.fSlaveJerkMax).abs() < 1e-9);
    assert_eq!(r.fMPosAtSAccMax, c.fMPosAtSAccMax);
    assert!((r.fSlaveAccEff - 9.0 * c.fSlaveAccEff).abs() < 1e-12);
}

#[test]
fn symmetry_moves_the_turning_point_and_keeps_velocity_and_acceleration_continuous() {
    for law in FunctionType::all().iter().filter(|l| l.has_symmetry()) {
        let f = unit(*law, 0.2);
        let CamProfile::MotionFunction(mf) = &f else {
            unreachable!()
        };
        let turn = at(mf, 0.7);
        assert!(
            (turn.position - 0.7).abs() < 1e-12,
            "{law:?}: y(0.7) = {}",
            turn.position
        );
        let c = CharacValues::normed(&f);
        // Laws with a constant-velocity stretch reach their peak velocity over a range.
        if *law != FunctionType::SineStraightCombination {
            assert!(
                (c.fMPosAtSVeloMax - 0.7).abs() < 1e-9,
                "{law:?} peak at {}",
                c.fMPosAtSVeloMax
            );
        }
        let (l, r) = (at(mf, 0.7 - 1e-9), at(mf, 0.7 + 1e-9));
        assert!(
            (l.velocity - r.velocity).abs() < 1e-6
                && (l.acceleration - r.acceleration).abs() < 1e-5,
            "{law:?}"
        );
        // The symmetric law differs.
        assert!((at(mf, 0.5).position - 0.5).abs() > 1e-3, "{law:?}");
    }
    // Outside (-0.5, 0.5) it is refused with the offending point.
    let mut p = MotionFunctionPoint::new(1, FunctionType::Polynom5, PointType::Rest, 0.0, 0.0);
    p.jerk = 0.5;
    let q = MotionFunctionPoint::new(2, FunctionType::Polynom1, PointType::Rest, 1.0, 1.0);
    let e = MotionFunction::new(&[p, q]).unwrap_err();
    assert_eq!(
        e,
        CamError::Symmetry {
            point: 1,
            value: 0.5
        }
    );
    assert_eq!(e.code(), TableErrorCode::PointIdInvalid);
}

#[test]
fn the_step_function_holds_then_steps_at_the_segment_end() {
    let p = MotionFunctionPoint::new(1, FunctionType::Step, PointType::Rest, 0.0, 1.0);
    let q = MotionFunctionPoint::new(2, FunctionType::Polynom1, PointType::Rest, 10.0, 4.0);
    let r = MotionFunctionPoint::new(3, FunctionType::Polynom1, PointType::Rest, 20.0, 4.0);
    let f = MotionFunction::new(&[p, q, r]).unwrap();
    assert_eq!(at(&f, 9.999).position, 1.0);
    assert_eq!(at(&f, 10.0).position, 4.0);
    assert_eq!(at(&f, 5.0).velocity, 0.0);
}

#[test]
fn falling_master_positions_mirror_the_rising_function() {
    let rising = [
        MotionFunctionPoint::new(1, FunctionType::ModifiedSineLine, PointType::Rest, 0.0, 0.0),
        MotionFunctionPoint::new(2, FunctionType::Polynom1, PointType::Rest, 100.0, 30.0),
    ];
    let falling = [
        MotionFunctionPoint::new(1, FunctionType::ModifiedSineLine, PointType::Rest, 0.0, 0.0),
        MotionFunctionPoint::new(2, FunctionType::Polynom1, PointType::Rest, -100.0, 30.0),
    ];
    let (f, g) = (
        MotionFunction::new(&rising).unwrap(),
        MotionFunction::new(&falling).unwrap(),
    );
    for x in [0.0, 12.5, 40.0, 99.0] {
        let (a, b) = (at(&f, x), at(&g, -x));
        assert!(
            near(a.position, b.position)
                && near(a.velocity, -b.velocity)
                && near(a.acceleration, b.acceleration)
                && near(a.jerk, -b.jerk),
            "at {x}"
        );
    }
}

#[test]
fn the_value_table_selects_its_columns_by_mask() {
    use cnc_core::cam::charac::value_table;
    let p = unit(FunctionType::Polynom5, 0.0);
    // Position and acceleration: master plus two columns.
    let rows = value_table(&p, 1 | 4, 0.0, 1.0, 0.25).unwrap();
    assert_eq!(rows.len(), 5);
    assert!(rows.iter().all(|r| r.len() == 3));
    assert_eq!(rows[2][0], 0.5);
    assert!((rows[2][1] - 0.5).abs() < 1e-12 && rows[2][2].abs() < 1e-9);
    // Jerk alone; a falling sweep.
    let rows = value_table(&p, 8, 1.0, 0.0, -0.5).unwrap();
    assert_eq!(
        rows.iter().map(|r| r[0]).collect::<Vec<_>>(),
        vec![1.0, 0.5, 0.0]
    );
    assert!(
        (rows[1][1] + 30.0).abs() < 1e-9,
        "P5 jerk at the middle is -30"
    );
    for (mask, from, to, inc) in [
        (0, 0.0, 1.0, 0.1),
        (16, 0.0, 1.0, 0.1),
        (1, 0.0, 1.0, 0.0),
        (1, 0.0, 1.0, -0.1),
        (1, 0.0, 1e9, 1e-3),
    ] {
        let e = value_table(&p, mask, from, to, inc).unwrap_err();
        let want = if mask == 0 || mask > 15 {
            TableErrorCode::NumColumnsInvalid
        } else {
            TableErrorCode::IncrementInvalid
        };
        assert_eq!(e.code(), want, "{mask} {from} {to} {inc}");
    }
}

#[test]
fn a_falling_master_starts_at_its_first_point_in_the_characteristic_values() {
    let points = [
        MotionFunctionPoint::new(1, FunctionType::Polynom5, PointType::Rest, 0.0, 0.0),
        MotionFunctionPoint::new(2, FunctionType::Polynom1, PointType::Rest, -100.0, 30.0),
    ];
    let c = CharacValues::normed(&CamProfile::MotionFunction(
        MotionFunction::new(&points).unwrap(),
    ));
    assert_eq!((c.fMasterPosStart, c.fSlavePosStart), (0.0, 0.0));
    assert_eq!((c.fMasterPosEnd, c.fSlavePosEnd), (-100.0, 30.0));
    // Peak velocity mid-way, negative: the slave rises while the master falls.
    assert!(
        (c.fSlaveVeloMin + 1.875 * 30.0 / 100.0).abs() < 1e-9,
        "{}",
        c.fSlaveVeloMin
    );
    assert!((c.fMPosAtSVeloMin + 50.0).abs() < 1e-9);
    assert!((c.fSlaveVeloMean - 0.3).abs() < 1e-9);
}

#[test]
fn ignored_points_are_ignored_completely() {
    let mut points = vec![
        MotionFunctionPoint::new(1, FunctionType::Polynom5, PointType::Rest, 0.0, 0.0),
        MotionFunctionPoint::new(2, FunctionType::Polynom5, PointType::Ignore, 50.0, 10.0),
        MotionFunctionPoint::new(3, FunctionType::Polynom1, PointType::Rest, 100.0, 1.0),
    ];
    // An ignored point with an undefined function type and a NaN takes no part.
    points[1].function = 0;
    points[1].slave = f64::NAN;
    // The last point's function type is not used either.
    points[2].function = 0;
    let f = MotionFunction::new(&points).expect("the ignored point does not count");
    assert_eq!(f.segments().len(), 1);
    assert!((at(&f, 50.0).position - 0.5).abs() < 1e-12);
}

/// A negative master velocity (seed 000 3.4: any constant master velocity): the cam runs
/// backwards, so velocities and jerks turn over (minimum and maximum trade places with their
/// master positions) and accelerations scale with the square, their places kept. Checked
/// against the cam sampled backwards at 2 units/s.
#[test]
fn rescaling_to_a_negative_master_velocity_turns_velocities_and_jerks_over() {
    let p = unit(FunctionType::Polynom5, 0.0);
    let c = CharacValues::normed(&p);
    let r = c.rescaled(-2.0).unwrap();
    assert_eq!(r.fMasterVeloNom, -2.0);
    assert!((r.fSlaveVeloMax - -2.0 * c.fSlaveVeloMin).abs() < 1e-12);
    assert!((r.fSlaveVeloMin - -2.0 * c.fSlaveVeloMax).abs() < 1e-12);
    assert_eq!(r.fMPosAtSVeloMax, c.fMPosAtSVeloMin);
    assert_eq!(r.fMPosAtSVeloMin, c.fMPosAtSVeloMax);
    assert!((r.fSlaveAccMax - 4.0 * c.fSlaveAccMax).abs() < 1e-12);
    assert_eq!(r.fMPosAtSAccMax, c.fMPosAtSAccMax);
    assert!((r.fSlaveJerkMax - -8.0 * c.fSlaveJerkMin).abs() < 1e-9);
    assert_eq!(r.fSlavePosMax, c.fSlavePosMax);
    // Sampled: slave velocity = T'(x) * v, acceleration = T''(x) * v^2 with v = -2.
    let mut cursor = cnc_core::cam::ProfileCursor::default();
    let (mut v_lo, mut v_hi, mut a_hi) = (f64::MAX, f64::MIN, f64::MIN);
    for k in 0..=10_000 {
        let s = p.eval(f64::from(k) * 1e-4, &mut cursor);
        v_lo = v_lo.min(-2.0 * s.velocity);
        v_hi = v_hi.max(-2.0 * s.velocity);
        a_hi = a_hi.max(4.0 * s.acceleration);
    }
    assert!((r.fSlaveVeloMin - v_lo).abs() < 1e-6 && (r.fSlaveVeloMax - v_hi).abs() < 1e-6);
    assert!((r.fSlaveAccMax - a_hi).abs() < 1e-3 * (1.0 + a_hi.abs()));
}
