//! Motion laws: the function types of the seed's `MC_MotionFunctionType` and how each one
//! fills a segment between two points.
//!
//! Rest-to-rest laws are normalised shapes `f` on `z in [0, 1]` with `f(0) = 0`, `f(1) = 1`
//! and zero velocity and acceleration at both ends; a segment scales them to its master length
//! and slave stroke. Laws with velocity, turn or motion ends take their boundary values from
//! the points. Where the seed gives no formula, `docs/cams.md` names the definition used.

use super::piece::{shape, Piece, Wave};
use std::f64::consts::PI;

/// The pattern of the laws that are one normalised rest-to-rest shape ([`rest_to_rest`])
/// stretched over a segment with a symmetry: every rest-to-rest law but the step. One list
/// for [`FunctionType::ends`], [`FunctionType::has_symmetry`] and [`build`].
macro_rules! shaped_rest_to_rest {
    () => {
        FunctionType::Polynom3
            | FunctionType::Polynom5
            | FunctionType::Polynom8
            | FunctionType::SineLine
            | FunctionType::ModifiedSineLine
            | FunctionType::Bestehorn
            | FunctionType::AccelerationTrapezoid
            | FunctionType::SineStraightCombination
    };
}

/// `MC_MotionFunctionType`: the law between a point and the next one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FunctionType {
    /// 1, `POLYNOM1`: a straight line (synchronous motion); its velocity is computed.
    Polynom1,
    /// 3, `POLYNOM3`: rest to rest, 3rd order.
    Polynom3,
    /// 5, `POLYNOM5`: rest to rest, 5th order.
    Polynom5,
    /// 8, `POLYNOM8`: rest to rest with zero jerk at both ends (see docs/cams.md).
    Polynom8,
    /// 10, `SINUSLINIE`: the inclined sine (cycloid).
    SineLine,
    /// 11, `MODSINUSLINIE`: the modified sine.
    ModifiedSineLine,
    /// 12, `BESTEHORN`: Bestehorn's sinoid (see docs/cams.md).
    Bestehorn,
    /// 13, `BESCHLTRAPEZ`: trapezoidal acceleration, rest to rest.
    AccelerationTrapezoid,
    /// 15, `POLYNOM5_MM`: 5th order with position, velocity and acceleration at both ends.
    Polynom5Motion,
    /// 16, `SINUS_GERADE_KOMBI`: sine ramps joined by a straight line, rest to rest.
    SineStraightCombination,
    /// 17, `HARMONIC_KOMBI_RT`: harmonic combination, rest to turn.
    HarmonicRestTurn,
    /// 18, `HARMONIC_KOMBI_TR`: harmonic combination, turn to rest.
    HarmonicTurnRest,
    /// 19, `HARMONIC_KOMBI_VT`: harmonic combination, velocity to turn.
    HarmonicVelocityTurn,
    /// 20, `HARMONIC_KOMBI_TV`: harmonic combination, turn to velocity.
    HarmonicTurnVelocity,
    /// 21, `BESCHLTRAPEZ_RT`: trapezoidal acceleration, rest to turn.
    AccelerationTrapezoidRestTurn,
    /// 22, `BESCHLTRAPEZ_TR`: trapezoidal acceleration, turn to rest.
    AccelerationTrapezoidTurnRest,
    /// 23, `MODSINUSLINIE_VV`: modified sine between two velocities.
    ModifiedSineLineVelocity,
    /// 24, `POLYNOM7_MM`: 7th order with position to jerk at both ends.
    Polynom7Motion,
    /// 27, `POLYNOM6STP`: 6th order, motion ends plus the start point's jerk.
    Polynom6StartJerk,
    /// 28, `POLYNOM6WDP`: 6th order, motion ends plus an inflection point mid-segment.
    Polynom6Inflection,
    /// 99, `STEPFUNCTION`: the slave holds, then steps at the segment's end.
    Step,
}

/// What a law fixes at one end of its segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndKind {
    /// Velocity and acceleration zero.
    Rest,
    /// Acceleration zero; the velocity comes from the point.
    Velocity,
    /// Velocity zero; the law produces the acceleration.
    Turn,
    /// Velocity and acceleration (and jerk where the law has the order) come from the point.
    Motion,
    /// The straight line's own slope, acceleration zero.
    Line,
}

const ALL: [FunctionType; 21] = [
    FunctionType::Polynom1,
    FunctionType::Polynom3,
    FunctionType::Polynom5,
    FunctionType::Polynom8,
    FunctionType::SineLine,
    FunctionType::ModifiedSineLine,
    FunctionType::Bestehorn,
    FunctionType::AccelerationTrapezoid,
    FunctionType::Polynom5Motion,
    FunctionType::SineStraightCombination,
    FunctionType::HarmonicRestTurn,
    FunctionType::HarmonicTurnRest,
    FunctionType::HarmonicVelocityTurn,
    FunctionType::HarmonicTurnVelocity,
    FunctionType::AccelerationTrapezoidRestTurn,
    FunctionType::AccelerationTrapezoidTurnRest,
    FunctionType::ModifiedSineLineVelocity,
    FunctionType::Polynom7Motion,
    FunctionType::Polynom6StartJerk,
    FunctionType::Polynom6Inflection,
    FunctionType::Step,
];

impl FunctionType {
    /// Every function type.
    pub fn all() -> &'static [FunctionType] {
        &ALL
    }

    /// The seed's numeric value.
    pub fn raw(self) -> u32 {
        use FunctionType::*;
        match self {
            Polynom1 => 1,
            Polynom3 => 3,
            Polynom5 => 5,
            Polynom8 => 8,
            SineLine => 10,
            ModifiedSineLine => 11,
            Bestehorn => 12,
            AccelerationTrapezoid => 13,
            Polynom5Motion => 15,
            SineStraightCombination => 16,
            HarmonicRestTurn => 17,
            HarmonicTurnRest => 18,
            HarmonicVelocityTurn => 19,
            HarmonicTurnVelocity => 20,
            AccelerationTrapezoidRestTurn => 21,
            AccelerationTrapezoidTurnRest => 22,
            ModifiedSineLineVelocity => 23,
            Polynom7Motion => 24,
            Polynom6StartJerk => 27,
            Polynom6Inflection => 28,
            Step => 99,
        }
    }

    /// From the seed's numeric value.
    pub fn from_raw(raw: u32) -> Option<FunctionType> {
        ALL.iter().copied().find(|t| t.raw() == raw)
    }

    /// The seed's enumerator name without the `MOTIONFUNCTYPE_` prefix.
    pub fn name(self) -> &'static str {
        use FunctionType::*;
        match self {
            Polynom1 => "POLYNOM1",
            Polynom3 => "POLYNOM3",
            Polynom5 => "POLYNOM5",
            Polynom8 => "POLYNOM8",
            SineLine => "SINUSLINIE",
            ModifiedSineLine => "MODSINUSLINIE",
            Bestehorn => "BESTEHORN",
            AccelerationTrapezoid => "BESCHLTRAPEZ",
            Polynom5Motion => "POLYNOM5_MM",
            SineStraightCombination => "SINUS_GERADE_KOMBI",
            HarmonicRestTurn => "HARMONIC_KOMBI_RT",
            HarmonicTurnRest => "HARMONIC_KOMBI_TR",
            HarmonicVelocityTurn => "HARMONIC_KOMBI_VT",
            HarmonicTurnVelocity => "HARMONIC_KOMBI_TV",
            AccelerationTrapezoidRestTurn => "BESCHLTRAPEZ_RT",
            AccelerationTrapezoidTurnRest => "BESCHLTRAPEZ_TR",
            ModifiedSineLineVelocity => "MODSINUSLINIE_VV",
            Polynom7Motion => "POLYNOM7_MM",
            Polynom6StartJerk => "POLYNOM6STP",
            Polynom6Inflection => "POLYNOM6WDP",
            Step => "STEPFUNCTION",
        }
    }

    /// From a name: the seed's enumerator (with or without `MOTIONFUNCTYPE_`), the English
    /// names of the seed's function-type table (`SINELINE`, `ACCTRAPEZ`, ...), or a number.
    pub fn from_name(name: &str) -> Option<FunctionType> {
        let upper = name.trim().to_ascii_uppercase();
        let bare = upper.strip_prefix("MOTIONFUNCTYPE_").unwrap_or(&upper);
        if let Ok(raw) = bare.parse::<u32>() {
            return FunctionType::from_raw(raw);
        }
        let alias = match bare {
            "SINELINE" => "SINUSLINIE",
            "MODSINELINE" => "MODSINUSLINIE",
            "ACCTRAPEZ" => "BESCHLTRAPEZ",
            "SINE_LINE_COMBI" => "SINUS_GERADE_KOMBI",
            "HARMONIC_COMBI_RT" => "HARMONIC_KOMBI_RT",
            "HARMONIC_COMBI_TR" => "HARMONIC_KOMBI_TR",
            "HARMONIC_COMBI_VT" => "HARMONIC_KOMBI_VT",
            "HARMONIC_COMBI_TV" => "HARMONIC_KOMBI_TV",
            "ACCTRAPEZ_RT" => "BESCHLTRAPEZ_RT",
            "ACCTRAPEZ_TR" => "BESCHLTRAPEZ_TR",
            "MODSINELINE_VV" => "MODSINUSLINIE_VV",
            "BESTEHOORN" => "BESTEHORN",
            other => other,
        };
        ALL.iter().copied().find(|t| t.name() == alias)
    }

    /// What the law fixes at its start and at its end.
    pub fn ends(self) -> (EndKind, EndKind) {
        use EndKind::*;
        use FunctionType::*;
        match self {
            Polynom1 => (Line, Line),
            shaped_rest_to_rest!() | Step => (Rest, Rest),
            Polynom5Motion | Polynom7Motion | Polynom6StartJerk | Polynom6Inflection => {
                (Motion, Motion)
            }
            HarmonicRestTurn | AccelerationTrapezoidRestTurn => (Rest, Turn),
            HarmonicTurnRest | AccelerationTrapezoidTurnRest => (Turn, Rest),
            HarmonicVelocityTurn => (Velocity, Turn),
            HarmonicTurnVelocity => (Turn, Velocity),
            ModifiedSineLineVelocity => (Velocity, Velocity),
        }
    }

    /// Whether the start point's jerk field sets the law's symmetry (seed: the rest-to-rest
    /// laws whose jerk at the ends is not a boundary value; every one but the step).
    pub fn has_symmetry(self) -> bool {
        matches!(self, shaped_rest_to_rest!())
    }
}

/// Position and derivatives of the slave at one end of a segment (per master unit).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EndState {
    /// Slave position.
    pub y: f64,
    /// Velocity dy/dx.
    pub v: f64,
    /// Acceleration d2y/dx2.
    pub a: f64,
    /// Jerk d3y/dx3.
    pub j: f64,
}

/// One segment to build: master range, end states, symmetry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentSpec {
    /// The law.
    pub law: FunctionType,
    /// Master position at the start (below `x1`).
    pub x0: f64,
    /// Master position at the end.
    pub x1: f64,
    /// Start state (what the law does not fix is taken from here).
    pub start: EndState,
    /// End state.
    pub end: EndState,
    /// Symmetry in (-0.5, 0.5); 0 is symmetric.
    pub symmetry: f64,
}

/// The pieces of one segment in absolute master positions, or `None` when the law's
/// equations are singular for these values.
pub fn build(spec: &SegmentSpec) -> Option<Vec<Piece>> {
    use FunctionType::*;
    let length = spec.x1 - spec.x0;
    let (y0, y1) = (spec.start.y, spec.end.y);
    let h = y1 - y0;
    // Velocities in slave units per unit of z (z = (x - x0) / length).
    let (v0, v1) = (spec.start.v * length, spec.end.v * length);
    let in_z: Vec<Piece> = match spec.law {
        Polynom1 => vec![Piece::poly(0.0, 1.0, &[y0, h])],
        Step => vec![Piece::poly(0.0, 1.0, &[y0])],
        shaped_rest_to_rest!() => {
            let base = rest_to_rest(spec.law);
            shape::scaled(&asymmetric(&base, 0.5 + spec.symmetry)?, h, y0)
        }
        HarmonicRestTurn => shape::scaled(&harmonic_rest_turn(), h, y0),
        HarmonicTurnRest => shape::scaled(&mirrored(&harmonic_rest_turn()), h, y0),
        AccelerationTrapezoidRestTurn => shape::scaled(&trapezoid_rest_turn(), h, y0),
        AccelerationTrapezoidTurnRest => shape::scaled(&mirrored(&trapezoid_rest_turn()), h, y0),
        HarmonicVelocityTurn => shape::scaled(&velocity_turn(h, v0)?, 1.0, y0),
        HarmonicTurnVelocity => {
            // Time-reversed velocity-to-turn: Y(z) = h - Q(1 - z), Q starting at v1.
            let q = velocity_turn(h, v1)?;
            shape::scaled(&shape::reparametrised(&q, 1.0, -1.0), -1.0, y0 + h)
        }
        ModifiedSineLineVelocity => shape::scaled(&velocity_velocity(h, v0, v1)?, 1.0, y0),
        Polynom5Motion | Polynom7Motion | Polynom6StartJerk | Polynom6Inflection => {
            let l2 = length * length;
            let s = &spec.start;
            let e = &spec.end;
            let a = [y0, v0, s.a * l2, s.j * l2 * length];
            let b = [y1, v1, e.a * l2, e.j * l2 * length];
            let coefficients = motion_polynomial(spec.law, a, b)?;
            vec![Piece::poly(0.0, 1.0, &coefficients)]
        }
    };
    // z = (x - x0) / length
    let pieces = shape::reparametrised(&in_z, -spec.x0 / length, 1.0 / length);
    pieces
        .iter()
        .all(|p| p.poly.iter().all(|c| c.is_finite()))
        .then_some(pieces)
}

/// The normalised rest-to-rest shape of a law (symmetric, `f(1/2) = 1/2`).
pub fn rest_to_rest(law: FunctionType) -> Vec<Piece> {
    use FunctionType::*;
    match law {
        Polynom3 => vec![Piece::poly(0.0, 1.0, &[0.0, 0.0, 3.0, -2.0])],
        Polynom5 => vec![Piece::poly(0.0, 1.0, &[0.0, 0.0, 0.0, 10.0, -15.0, 6.0])],
        Polynom8 => vec![Piece::poly(
            0.0,
            1.0,
            &[0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0],
        )],
        SineLine | Bestehorn => vec![Piece::with_wave(
            0.0,
            1.0,
            &[0.0, 1.0],
            Wave {
                omega: 2.0 * PI,
                sin: -1.0 / (2.0 * PI),
                cos: 0.0,
            },
        )],
        ModifiedSineLine => modified_sine(),
        AccelerationTrapezoid => from_jerk(
            &[0.0, 0.125, 0.375, 0.625, 0.875, 1.0],
            &[1.0, 0.0, -1.0, 0.0, 1.0],
        ),
        SineStraightCombination => sine_straight(0.25),
        _ => vec![Piece::poly(0.0, 1.0, &[0.0, 1.0])],
    }
}

/// The modified sine: sine ramps of 1/8 around a long sine of the other half-period.
fn modified_sine() -> Vec<Piece> {
    let k = 1.0 / (4.0 + PI);
    let ramp = Wave {
        omega: 4.0 * PI,
        sin: -k / 4.0,
        cos: 0.0,
    };
    // -9/4 k sin(pi/3 + 4 pi z / 3) written as sine and cosine of 4 pi z / 3.
    let middle = Wave {
        omega: 4.0 * PI / 3.0,
        sin: -2.25 * k * (PI / 3.0).cos(),
        cos: -2.25 * k * (PI / 3.0).sin(),
    };
    vec![
        Piece::with_wave(0.0, 0.125, &[0.0, k * PI], ramp),
        Piece::with_wave(0.0, 1.0, &[2.0 * k, k * PI], middle).restricted(0.125, 0.875),
        Piece::with_wave(0.0, 1.0, &[4.0 * k, k * PI], ramp).restricted(0.875, 1.0),
    ]
}

/// Sine half-waves of acceleration over `[0, ramp]` and `[1 - ramp, 1]`, constant velocity
/// between.
fn sine_straight(ramp: f64) -> Vec<Piece> {
    let w = PI / ramp;
    let accel = [
        Piece::with_wave(
            0.0,
            ramp,
            &[],
            Wave {
                omega: w,
                sin: 1.0,
                cos: 0.0,
            },
        ),
        Piece::poly(ramp, 1.0 - ramp, &[]),
        Piece::with_wave(
            1.0 - ramp,
            1.0,
            &[],
            Wave {
                omega: w,
                sin: -1.0,
                cos: 0.0,
            },
        ),
    ];
    normalised(&twice_integrated(&accel))
}

/// Rest to turn, harmonic: a quarter sine of acceleration up to its peak, then a cosine
/// through zero that brings the velocity to zero at `z = 1` with the acceleration at
/// `cos(5 pi / 4)` of its peak.
fn harmonic_rest_turn() -> Vec<Piece> {
    let phi = 1.25 * PI;
    let beta = -PI * phi.sin() / (2.0 * phi - PI * phi.sin());
    let omega = phi / (1.0 - beta);
    let accel = [
        Piece::with_wave(
            0.0,
            beta,
            &[],
            Wave {
                omega: PI / (2.0 * beta),
                sin: 1.0,
                cos: 0.0,
            },
        ),
        Piece::with_wave(
            beta,
            1.0,
            &[],
            Wave {
                omega,
                sin: 0.0,
                cos: 1.0,
            },
        ),
    ];
    normalised(&twice_integrated(&accel))
}

/// Rest to turn with a trapezoidal acceleration: ramp 1/8, hold, ramp down through zero over
/// 1/4, hold the negative acceleration until the velocity is zero.
fn trapezoid_rest_turn() -> Vec<Piece> {
    let (r, hold) = (0.125, 9.0 / 32.0);
    from_jerk(
        &[0.0, r, r + hold, 3.0 * r + hold, 1.0],
        &[1.0, 0.0, -1.0, 0.0],
    )
}

/// Velocity `v0` (per unit z, acceleration zero) to a turn after the rise `h`: a quarter
/// cosine of velocity plus the harmonic rest-to-turn shape for the remaining stroke.
fn velocity_turn(h: f64, v0: f64) -> Option<Vec<Piece>> {
    let bleed = [Piece::with_wave(
        0.0,
        1.0,
        &[],
        Wave {
            omega: PI / 2.0,
            sin: 2.0 / PI,
            cos: 0.0,
        },
    )];
    let rest = h - v0 * 2.0 / PI;
    shape::sum(
        &shape::scaled(&bleed, v0, 0.0),
        &shape::scaled(&harmonic_rest_turn(), rest, 0.0),
    )
}

/// From velocity `v0` to `v1` (per unit z, acceleration zero at both ends) with the rise `h`:
/// the velocity changes along a modified sine, and a modified-sine rest-to-rest part makes up
/// the stroke.
fn velocity_velocity(h: f64, v0: f64, v1: f64) -> Option<Vec<Piece>> {
    let g = modified_sine();
    let ramp = shape::integrated(&g)?;
    let ramp_end = shape::eval(&ramp, 1.0)[0];
    let line = [Piece::poly(0.0, 1.0, &[0.0, v0])];
    let stroke = h - v0 - (v1 - v0) * ramp_end;
    let sum = shape::sum(&line, &shape::scaled(&ramp, v1 - v0, 0.0))?;
    shape::sum(&sum, &shape::scaled(&g, stroke, 0.0))
}

/// The polynomial (in z) of a motion-to-motion law from its end values
/// `[y, y', y'', y''']` (derivatives per unit z).
fn motion_polynomial(law: FunctionType, a: [f64; 4], b: [f64; 4]) -> Option<Vec<f64>> {
    // Rows: (order of derivative, z) = value.
    let mut rows: Vec<(usize, f64, f64)> = Vec::new();
    let orders = match law {
        FunctionType::Polynom7Motion => 4,
        _ => 3,
    };
    for k in 0..orders {
        rows.push((k, 0.0, a[k]));
        rows.push((k, 1.0, b[k]));
    }
    match law {
        FunctionType::Polynom6StartJerk => rows.push((3, 0.0, a[3])),
        FunctionType::Polynom6Inflection => rows.push((2, 0.5, 0.0)),
        _ => {}
    }
    let n = rows.len();
    let mut m = vec![vec![0.0; n + 1]; n];
    for (r, (order, z, value)) in rows.iter().enumerate() {
        for (i, cell) in m[r].iter_mut().enumerate().take(n).skip(*order) {
            // d^order/dz^order z^i = i!/(i-order)! z^(i-order)
            let falling: f64 = ((i - order + 1)..=i).map(|f| f as f64).product();
            *cell = falling * z.powi((i - order) as i32);
        }
        m[r][n] = *value;
    }
    solve(m)
}

/// Gaussian elimination with partial pivoting on an augmented matrix.
fn solve(mut m: Vec<Vec<f64>>) -> Option<Vec<f64>> {
    let n = m.len();
    for col in 0..n {
        let pivot = (col..n).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[pivot][col].abs() < 1e-12 {
            return None;
        }
        m.swap(col, pivot);
        let pivot_row = m[col].clone();
        for (r, row) in m.iter_mut().enumerate() {
            if r != col {
                let f = row[col] / pivot_row[col];
                for (cell, p) in row.iter_mut().zip(&pivot_row).skip(col) {
                    *cell -= f * p;
                }
            }
        }
    }
    Some((0..n).map(|i| m[i][n] / m[i][i]).collect())
}

/// `f(1 - z)` mirrored so that it rises again: `1 - f(1 - z)`.
fn mirrored(f: &[Piece]) -> Vec<Piece> {
    shape::scaled(&shape::reparametrised(f, 1.0, -1.0), -1.0, 1.0)
}

/// The shape divided by its end value.
fn normalised(f: &[Piece]) -> Vec<Piece> {
    let end = shape::eval(f, 1.0)[0];
    shape::scaled(f, 1.0 / end, 0.0)
}

fn twice_integrated(accel: &[Piece]) -> Vec<Piece> {
    let v = shape::integrated(accel).expect("acceleration shapes are low order");
    shape::integrated(&v).expect("velocity shapes are low order")
}

/// A normalised rest-to-rest shape from piecewise constant jerk between `cuts`.
fn from_jerk(cuts: &[f64], jerk: &[f64]) -> Vec<Piece> {
    let j: Vec<Piece> = cuts
        .windows(2)
        .zip(jerk)
        .map(|(w, value)| Piece::poly(w[0], w[1], &[*value]))
        .collect();
    let a = shape::integrated(&j).expect("constant jerk integrates");
    normalised(&twice_integrated(&a))
}

/// A symmetric shape made asymmetric: the first half squeezed or stretched onto
/// `[0, turning]`, the second onto `[turning, 1]`, so that velocity (its maximum, at the
/// turning point) and acceleration (zero there) stay continuous.
fn asymmetric(base: &[Piece], turning: f64) -> Option<Vec<Piece>> {
    if !(turning > 0.0 && turning < 1.0) {
        return None;
    }
    if turning == 0.5 {
        return Some(base.to_vec());
    }
    let mut first = Vec::new();
    let mut second = Vec::new();
    for p in base {
        if p.end <= 0.5 {
            first.push(*p);
        } else if p.start >= 0.5 {
            second.push(*p);
        } else {
            first.push(p.restricted(p.start, 0.5));
            second.push(p.restricted(0.5, p.end));
        }
    }
    let s1 = 2.0 * turning;
    let s2 = 2.0 * (1.0 - turning);
    let mut out = shape::scaled(&shape::reparametrised(&first, 0.0, 1.0 / s1), s1, 0.0);
    let tail = shape::reparametrised(&second, 0.5 - turning / s2, 1.0 / s2);
    out.extend(shape::scaled(&tail, s2, turning - 0.5 * s2));
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_numbers_round_trip() {
        for t in FunctionType::all() {
            assert_eq!(FunctionType::from_raw(t.raw()), Some(*t));
            assert_eq!(FunctionType::from_name(t.name()), Some(*t));
        }
        assert_eq!(
            FunctionType::from_name("MOTIONFUNCTYPE_POLYNOM5_MM"),
            Some(FunctionType::Polynom5Motion)
        );
        assert_eq!(
            FunctionType::from_name("sineline"),
            Some(FunctionType::SineLine)
        );
        assert_eq!(FunctionType::from_name("POLYNOM4"), None);
        assert_eq!(FunctionType::from_raw(2), None);
    }

    #[test]
    fn rest_to_rest_shapes_rise_by_one_and_turn_in_the_middle() {
        for t in FunctionType::all().iter().filter(|t| t.has_symmetry()) {
            let f = rest_to_rest(*t);
            let (a, m, b) = (
                shape::eval(&f, 0.0),
                shape::eval(&f, 0.5),
                shape::eval(&f, 1.0),
            );
            assert!(a[0].abs() < 1e-12 && (b[0] - 1.0).abs() < 1e-12, "{t:?}");
            assert!(a[1].abs() < 1e-12 && b[1].abs() < 1e-12, "{t:?} velocity");
            assert!(
                (m[0] - 0.5).abs() < 1e-12 && m[2].abs() < 1e-9,
                "{t:?} midpoint"
            );
        }
    }

    #[test]
    fn asymmetric_trapezoid_jumps_in_jerk_where_its_ramps_end() {
        // The property-test seed: symmetry -0.34 puts the turning point at 0.16 and stretches
        // the second half by 2 * 0.84, so the base shape's ramp end at 5/8 lands at
        // 0.16 + 0.84 / 4 = 0.37. The jerk there drops from the stretched ramp's to zero.
        let spec = SegmentSpec {
            law: FunctionType::AccelerationTrapezoid,
            x0: 0.0,
            x1: 1.0,
            start: EndState::default(),
            end: EndState {
                y: 1.0,
                ..EndState::default()
            },
            symmetry: -0.34,
        };
        let pieces = build(&spec).expect("a regular trapezoid");
        let cut = pieces
            .iter()
            .map(|p| p.start)
            .find(|c| (c - 0.37).abs() < 1e-12)
            .expect("a cut at 0.37");
        // The symmetric shape's ramp jerk is 128/3; the second half divides it by 1.68^2.
        let ramp = -128.0 / 3.0 / (1.68 * 1.68);
        let (left, right) = (
            shape::eval(&pieces, cut - 1e-3),
            shape::eval(&pieces, cut + 1e-3),
        );
        assert!((left[3] - ramp).abs() < 1e-9, "{} vs {ramp}", left[3]);
        assert!(right[3].abs() < 1e-9, "{}", right[3]);
        // The jerk reported on each side is the slope of the acceleration on that side.
        let h = 1e-6;
        for x in [cut - 1e-3, cut + 1e-3] {
            let (m, p, q) = (
                shape::eval(&pieces, x - h),
                shape::eval(&pieces, x),
                shape::eval(&pieces, x + h),
            );
            assert!(((q[2] - m[2]) / (2.0 * h) - p[3]).abs() < 1e-6, "at {x}");
        }
        // The acceleration has a kink there, not a step.
        let (a_left, a_right) = (
            pieces.iter().find(|p| p.end == cut),
            pieces.iter().find(|p| p.start == cut),
        );
        let (a_left, a_right) = (
            a_left.expect("piece before").eval(cut),
            a_right.expect("piece after").eval(cut),
        );
        assert!((a_left[2] - a_right[2]).abs() < 1e-9);
    }
}
