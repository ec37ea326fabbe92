//! The polynomial pieces a synchronising phase is made of, and how long a velocity change
//! must take to keep the limits.
//!
//! Pieces are [`Piece`]s of the cam module: a polynomial in the local coordinate `u` (master
//! travel for the position-based profile, time for the time-based one). Velocity below means
//! the first derivative in that coordinate.

use crate::cam::piece::Piece;

/// Dynamic limits of the synchronising phase (all > 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// |velocity|.
    pub velocity: f64,
    /// Acceleration while the slave speeds up (|v| grows).
    pub acceleration: f64,
    /// Deceleration while the slave slows down (|v| shrinks).
    pub deceleration: f64,
    /// |jerk|.
    pub jerk: f64,
}

/// The inverse of the smooth step `h(u) = 3u^2 - 2u^3` on [0, 1].
fn smooth_step_inverse(r: f64) -> f64 {
    0.5 - ((1.0 - 2.0 * r.clamp(0.0, 1.0)).asin() / 3.0).sin()
}

/// The peak of the shape `6u(1-u)` over `[a, b]` inside [0, 1].
fn shape_peak(a: f64, b: f64) -> f64 {
    let u = 0.5f64.clamp(a, b);
    6.0 * u * (1.0 - u)
}

/// How much of a smooth velocity change from `va` to `vb` (velocity `va + (vb-va) h(u)`)
/// speeds the slave up and how much slows it down: the peaks of the acceleration shape
/// `6u(1-u)` over the part where |v| grows and over the part where it shrinks.
fn speed_up_and_down(va: f64, vb: f64) -> (f64, f64) {
    if va * vb >= 0.0 {
        return if vb.abs() >= va.abs() {
            (1.5, 0.0)
        } else {
            (0.0, 1.5)
        };
    }
    // Through zero: slows down until v = 0 at u_z, speeds up after.
    let u_z = smooth_step_inverse(-va / (vb - va));
    (shape_peak(u_z, 1.0), shape_peak(0.0, u_z))
}

/// The shortest duration of a smooth velocity change from `va` to `vb` (zero acceleration
/// at both ends) that keeps acceleration, deceleration and jerk.
///
/// With `v = va + dv h(t/T)` the acceleration is `dv/T 6u(1-u)` (peak 1.5 dv/T) and the jerk
/// `dv/T^2 6(1-2u)` (peak 6 dv/T^2 at the ends).
pub fn change_time(va: f64, vb: f64, limits: &Limits) -> f64 {
    let dv = (vb - va).abs();
    if dv == 0.0 {
        return 0.0;
    }
    let (up, down) = speed_up_and_down(va, vb);
    let by_acc = dv * up / limits.acceleration;
    let by_dec = dv * down / limits.deceleration;
    let by_jerk = (6.0 * dv / limits.jerk).sqrt();
    by_acc.max(by_dec).max(by_jerk)
}

/// The shortest duration of a smooth velocity change from `va` with acceleration `a0` to
/// `vb` (acceleration 0 at the end) that keeps the jerk, and acceleration and deceleration
/// as [`change_time`] sizes them. The jerk of such a change is linear in time, from
/// `(6 dv - 4 a0 T) / T^2` at the start to `(2 a0 T - 6 dv) / T^2` at the end, so each end
/// bounds T from below by the larger root of `J T^2 -+ (c1 T + c0) = 0`.
pub fn change_time_from(va: f64, a0: f64, vb: f64, limits: &Limits) -> f64 {
    let dv = vb - va;
    let j = limits.jerk;
    // J T^2 >= |c0 + c1 T| for both ends.
    let mut t = change_time(va, vb, limits);
    for (c0, c1) in [(6.0 * dv, -4.0 * a0), (-6.0 * dv, 2.0 * a0)] {
        for sign in [1.0, -1.0] {
            // J T^2 - sign (c1 T + c0) >= 0: the larger root of J T^2 - b T - c.
            let (b, c) = (sign * c1, sign * c0);
            let disc = b * b + 4.0 * j * c;
            if disc >= 0.0 {
                t = t.max((b + disc.sqrt()) / (2.0 * j));
            }
        }
    }
    t
}

/// A smooth change of slope from `ka` (with curvature `ca`) to `kb` (curvature 0) over
/// `[start, start + len]`, starting at value `sa`: the slope is the cubic Hermite curve
/// between the two ends, the value its integral (a polynomial of degree 4, the 5th-order
/// family with its top coefficient 0: the end value is free).
pub fn slope_change(start: f64, len: f64, sa: f64, ka: f64, ca: f64, kb: f64) -> Piece {
    let l = len;
    let delta = kb - ka - ca * l;
    let beta = (-ca - 2.0 * delta / l) / (l * l);
    let alpha = (delta - beta * l * l * l) / (l * l);
    Piece::poly(
        start,
        start + len,
        &[sa, ka, 0.5 * ca, alpha / 3.0, beta / 4.0],
    )
}

/// The value a [`slope_change`] without start curvature gains over `len`.
pub fn slope_change_travel(len: f64, ka: f64, kb: f64) -> f64 {
    0.5 * len * (ka + kb)
}

/// A straight piece: value `sa` at `start`, slope `k`.
pub fn straight(start: f64, len: f64, sa: f64, k: f64) -> Piece {
    Piece::poly(start, start + len, &[sa, k])
}

/// The quintic from value, slope and curvature `(p0, v0, a0)` to `(p1, v1, a1)` over
/// `[start, start + len]`: the one polynomial of degree 5 that meets all six.
pub fn quintic(start: f64, len: f64, from: [f64; 3], to: [f64; 3]) -> Piece {
    let [p0, v0, a0] = from;
    let [p1, v1, a1] = to;
    let l = len;
    let (l2, l3) = (l * l, l * l * l);
    let c3 = (20.0 * (p1 - p0) - (8.0 * v1 + 12.0 * v0) * l - (3.0 * a0 - a1) * l2) / (2.0 * l3);
    let c4 = (30.0 * (p0 - p1) + (14.0 * v1 + 16.0 * v0) * l + (3.0 * a0 - 2.0 * a1) * l2)
        / (2.0 * l3 * l);
    let c5 = (12.0 * (p1 - p0) - 6.0 * (v1 + v0) * l - (a0 - a1) * l2) / (2.0 * l3 * l2);
    Piece::poly(start, start + len, &[p0, v0, 0.5 * a0, c3, c4, c5])
}

/// Phases of constant jerk: `(duration, jerk)`.
pub type JerkPhases = [(f64, f64); 3];

/// The time-optimal jerk-limited change from velocity `v0` and acceleration `a0` to
/// velocity `v1` at acceleration 0: at most three phases of constant jerk (build up, hold,
/// take down). The acceleration peak is the deceleration limit where the change only slows
/// the slave down, the acceleration limit where it only speeds it up, and the smaller of
/// the two where the velocity passes zero.
pub fn jerk_limited_change(v0: f64, a0: f64, v1: f64, limits: &Limits) -> JerkPhases {
    let j = limits.jerk;
    let peak_limit = if v0 * v1 < 0.0 {
        limits.acceleration.min(limits.deceleration)
    } else if v1.abs() >= v0.abs() {
        limits.acceleration
    } else {
        limits.deceleration
    };
    // Where the velocity ends if the acceleration is taken to zero at once.
    let v_stop = v0 + a0 * a0.abs() / (2.0 * j);
    let gap = v1 - v_stop;
    if gap == 0.0 {
        return [(a0.abs() / j, -a0.signum() * j), (0.0, 0.0), (0.0, 0.0)];
    }
    let sigma = gap.signum();
    // Triangle: up to a_p with jerk sigma*j, down to 0 with -sigma*j.
    let peak_sq = sigma * j * (v1 - v0) + 0.5 * a0 * a0;
    let a_p = sigma * peak_sq.max(0.0).sqrt();
    if a_p.abs() <= peak_limit {
        return [
            ((a_p - a0) / (sigma * j), sigma * j),
            (0.0, 0.0),
            (a_p.abs() / j, -sigma * j),
        ];
    }
    // Trapezoid: hold sigma*limit in between.
    let a_p = sigma * peak_limit;
    let j1 = if a_p >= a0 { j } else { -j };
    let dv1 = (a_p * a_p - a0 * a0) / (2.0 * j1);
    let dv3 = a_p * a_p / (2.0 * sigma * j);
    let hold = (v1 - v0 - dv1 - dv3) / a_p;
    if hold < 0.0 {
        // Only when the start acceleration is beyond the limit already: keep the triangle
        // (the checks report the limit).
        let a_p = sigma * peak_sq.max(0.0).sqrt();
        return [
            ((a_p - a0) / (sigma * j), sigma * j),
            (0.0, 0.0),
            (a_p.abs() / j, -sigma * j),
        ];
    }
    [
        ((a_p - a0) / j1, j1),
        (hold, 0.0),
        (a_p.abs() / j, -sigma * j),
    ]
}

/// The phases as cubic pieces in time from `(p0, v0, a0)` at `start`; the pieces and how many.
pub fn phases_to_pieces(
    start: f64,
    p0: f64,
    v0: f64,
    a0: f64,
    phases: &JerkPhases,
) -> ([Piece; 3], usize) {
    let mut out = [Piece::poly(start, start, &[p0]); 3];
    let mut n = 0;
    let (mut t, mut p, mut v, mut a) = (start, p0, v0, a0);
    for &(d, jerk) in phases {
        if d <= 0.0 {
            continue;
        }
        out[n] = Piece::poly(t, t + d, &[p, v, 0.5 * a, jerk / 6.0]);
        n += 1;
        p += v * d + 0.5 * a * d * d + jerk * d * d * d / 6.0;
        v += a * d + 0.5 * jerk * d * d;
        a += jerk * d;
        t += d;
    }
    (out, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const LIM: Limits = Limits {
        velocity: 1e9,
        acceleration: 2500.0,
        deceleration: 2500.0,
        jerk: 5000.0,
    };

    #[test]
    fn the_quintic_meets_its_six_conditions() {
        let q = quintic(2.0, 3.0, [1.0, -2.0, 0.5], [7.0, 4.0, -1.0]);
        let a = q.eval(2.0);
        let b = q.eval(5.0);
        for (got, want) in [a[0], a[1], a[2], b[0], b[1], b[2]]
            .iter()
            .zip([1.0, -2.0, 0.5, 7.0, 4.0, -1.0])
        {
            assert!((got - want).abs() < 1e-9, "{got} vs {want}");
        }
    }

    #[test]
    fn a_slope_change_ends_flat_at_its_slope_and_travels_the_mean() {
        let p = slope_change(1.0, 2.0, 5.0, -1.0, 0.0, 3.0);
        let e = p.eval(3.0);
        assert!((e[1] - 3.0).abs() < 1e-12 && e[2].abs() < 1e-12);
        assert!((e[0] - 5.0 - slope_change_travel(2.0, -1.0, 3.0)).abs() < 1e-12);
        let with_curvature = slope_change(0.0, 2.0, 0.0, 1.0, 0.7, 3.0);
        let s = with_curvature.eval(0.0);
        assert!((s[2] - 0.7).abs() < 1e-12);
        let e = with_curvature.eval(2.0);
        assert!((e[1] - 3.0).abs() < 1e-12 && e[2].abs() < 1e-12);
    }

    #[test]
    fn the_change_time_puts_the_binding_limit_exactly_at_its_value() {
        // 750 mm/s with 2500 mm/s^2 and 5000 mm/s^3: the jerk binds (sqrt(6*750/5000)).
        let t = change_time(-250.0, 500.0, &LIM);
        assert!((t - (6.0f64 * 750.0 / 5000.0).sqrt()).abs() < 1e-12);
        let p = slope_change(0.0, t, 0.0, -250.0, 0.0, 500.0);
        assert!((p.eval(0.0)[3].abs() - 5000.0).abs() < 1e-6);
    }

    #[test]
    fn a_change_from_an_acceleration_keeps_the_jerk() {
        // The seed's velocity example 3: 400 -> -500 mm/s from 1200 mm/s^2, jerk 5000.
        let t = change_time_from(400.0, 1200.0, -500.0, &LIM);
        assert!((t - 1.6247).abs() < 1e-3, "{t}");
        let p = slope_change(0.0, t, 0.0, 400.0, 1200.0, -500.0);
        let peak = (0..=1000)
            .map(|i| p.eval(t * i as f64 / 1000.0)[3].abs())
            .fold(0.0, f64::max);
        assert!((peak - 5000.0).abs() < 1e-6, "{peak}");
        // Only an acceleration to take out: 4 |a| / J.
        assert!((change_time_from(10.0, 1000.0, 10.0, &LIM) - 0.8).abs() < 1e-12);
    }

    proptest! {
        #[test]
        fn a_change_from_any_acceleration_keeps_the_jerk(
            va in -1000.0f64..1000.0, a0 in -3000.0f64..3000.0, vb in -1000.0f64..1000.0,
        ) {
            let t = change_time_from(va, a0, vb, &LIM);
            prop_assume!(t > 1e-6);
            let p = slope_change(0.0, t, 0.0, va, a0, vb);
            for i in 0..=200 {
                let d = p.eval(t * i as f64 / 200.0);
                prop_assert!(d[3].abs() <= LIM.jerk * (1.0 + 1e-9), "jerk {}", d[3]);
            }
        }

        #[test]
        fn a_smooth_change_keeps_every_limit(
            va in -1000.0f64..1000.0, vb in -1000.0f64..1000.0,
            acc in 100.0f64..5000.0, dec in 100.0f64..5000.0, jerk in 100.0f64..50000.0,
        ) {
            let lim = Limits { velocity: 1e9, acceleration: acc, deceleration: dec, jerk };
            let t = change_time(va, vb, &lim);
            prop_assume!(t > 1e-6);
            let p = slope_change(0.0, t, 0.0, va, 0.0, vb);
            for i in 0..=400 {
                let d = p.eval(t * i as f64 / 400.0);
                let limit = if d[1] * d[2] >= 0.0 { acc } else { dec };
                // v = 0 belongs to both sides.
                let limit = if d[1].abs() < 1e-9 { acc.min(dec) } else { limit };
                prop_assert!(d[2].abs() <= limit * (1.0 + 1e-9) + 1e-9, "a {} limit {}", d[2], limit);
                prop_assert!(d[3].abs() <= jerk * (1.0 + 1e-9));
            }
        }

        #[test]
        fn the_jerk_limited_change_ends_at_the_target_at_rest(
            v0 in -1000.0f64..1000.0, a0 in -3000.0f64..3000.0, v1 in -1000.0f64..1000.0,
        ) {
            let ph = jerk_limited_change(v0, a0, v1, &LIM);
            let (pieces, n) = phases_to_pieces(0.0, 0.0, v0, a0, &ph);
            prop_assert!(ph.iter().all(|(d, _)| *d >= 0.0 && d.is_finite()));
            let end = if n == 0 { [0.0, v0, a0, 0.0, 0.0] } else { pieces[n - 1].eval(pieces[n - 1].end) };
            prop_assert!((end[1] - v1).abs() < 1e-6 * (1.0 + v1.abs()), "v {} vs {}", end[1], v1);
            prop_assert!(end[2].abs() < 1e-6 * (1.0 + a0.abs()));
        }
    }
}
