//! The path parameter's motion along one piece of a contour: a jerk-limited velocity change
//! at each end of the piece with a cruise between (closed form, so a piece can be evaluated at
//! any time and the next one takes over the rest of a tick without a dip), and the reach
//! functions the look-ahead plans with.
//!
//! A velocity change from `va` to `vb` at acceleration 0 on both ends, with acceleration
//! limit `A` and jerk limit `J`, takes `T = |Δv|/A + A/J` when the acceleration reaches `A`
//! (`|Δv| ≥ A²/J`), else `T = 2 sqrt(|Δv|/J)`. Its acceleration is symmetric in time, so it
//! covers `(va + vb) T / 2`: the same distance accelerating from `va` to `vb` as braking from
//! `vb` to `va`, which is what makes the look-ahead's backward and forward bounds one function.

/// Relative rounding within which braking to rest counts as fitting for [`min_reach`] (a
/// plan met again at its peak brakes over exactly its rest; the profile's own fit is
/// stricter, so a velocity found this way that does not fit is not planned).
const REST_SLACK: f64 = 1e-9;

/// The limits the path parameter moves with on one piece (all positive).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dynamics {
    /// Acceleration limit (path units/s²).
    pub acceleration: f64,
    /// Jerk limit (path units/s³).
    pub jerk: f64,
}

/// Time of a velocity change by `dv` (either sign) within `d`.
pub fn change_time(dv: f64, d: Dynamics) -> f64 {
    let dv = dv.abs();
    let (a, j) = (d.acceleration, d.jerk);
    if dv * j >= a * a {
        dv / a + a / j
    } else {
        2.0 * (dv / j).sqrt()
    }
}

/// Distance the velocity change from `va` to `vb` covers.
pub fn change_distance(va: f64, vb: f64, d: Dynamics) -> f64 {
    0.5 * (va + vb) * change_time(vb - va, d)
}

/// The highest velocity reachable from `v0` within `length` (and the highest velocity from
/// which `v0` is reachable by braking), capped at `cap`. In closed form: the look-ahead's
/// backward sweep calls this for every piece it passes.
pub fn max_reach(v0: f64, length: f64, cap: f64, d: Dynamics) -> f64 {
    if cap <= v0 {
        return cap.max(0.0);
    }
    if length <= 0.0 {
        return v0;
    }
    if change_distance(v0, cap, d) <= length {
        return cap;
    }
    let (a, j) = (d.acceleration, d.jerk);
    // Reaching the acceleration limit: (2 v0 + dv)(dv/a + a/j) = 2 length, a quadratic
    // A dv² + B dv + C = 0 (C < 0), its root in the form without cancellation.
    let (qa, qb, qc) = (
        1.0 / a,
        2.0 * v0 / a + a / j,
        2.0 * v0 * a / j - 2.0 * length,
    );
    let dv = -2.0 * qc / (qb + (qb * qb - 4.0 * qa * qc).max(0.0).sqrt());
    let dv = if dv * j >= a * a {
        dv
    } else {
        // Below it: (2 v0 + s²) s = length sqrt(j) with s = sqrt(dv), the cubic
        // f(s) = s³ + 2 v0 s - length sqrt(j), increasing and convex for s ≥ 0: Newton from
        // an upper bound comes down onto the root.
        let (p, q) = (2.0 * v0, length * j.sqrt());
        let mut s = q.cbrt().min(if p > 0.0 { q / p } else { f64::INFINITY });
        for _ in 0..8 {
            s -= (s * s * s + p * s - q) / (3.0 * s * s + p);
        }
        s * s
    };
    // Never above what fits (the root may round up).
    let mut v = (v0 + dv).min(cap);
    for _ in 0..16 {
        let covered = change_distance(v0, v, d);
        if covered <= length {
            return v;
        }
        let shrunk = v0 + (v - v0) * (length / covered) * (1.0 - 1e-12);
        // Rounding may give the same value back: one step below it then.
        v = if shrunk < v {
            shrunk
        } else {
            f64::from_bits(v.to_bits() - 1)
        };
    }
    v0
}

/// The lowest velocity reachable from `v0` by braking within `length`.
pub fn min_reach(v0: f64, length: f64, d: Dynamics) -> f64 {
    // Braking to rest exactly over the length (a plan made before, met again at its peak)
    // fits within rounding.
    if change_distance(v0, 0.0, d) <= length * (1.0 + REST_SLACK) {
        return 0.0;
    }
    // `ok(v)`: braking to v fits; true at v0, false at 0.
    let (mut lo, mut hi) = (0.0, v0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if change_distance(v0, mid, d) <= length {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// The largest `v` in `[lo, hi]` with `ok(v)`, `ok(lo)` assumed.
pub(super) fn bisect(mut lo: f64, mut hi: f64, ok: impl Fn(f64) -> bool) -> f64 {
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if ok(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// One jerk-limited velocity change, from `va` to `vb`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Ramp {
    va: f64,
    /// +1 or -1.
    sign: f64,
    jerk: f64,
    /// Jerk phase, constant-acceleration phase.
    t1: f64,
    t2: f64,
}

/// Position, velocity and acceleration along the path parameter.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PathState {
    /// Path parameter from the piece's start.
    pub position: f64,
    /// Its velocity.
    pub velocity: f64,
    /// Its acceleration.
    pub acceleration: f64,
}

impl Ramp {
    fn new(va: f64, vb: f64, d: Dynamics) -> Self {
        let dv = (vb - va).abs();
        let (a, j) = (d.acceleration, d.jerk);
        let (t1, t2) = if dv * j >= a * a {
            (a / j, dv / a - a / j)
        } else {
            ((dv / j).sqrt(), 0.0)
        };
        Self {
            va,
            sign: if vb >= va { 1.0 } else { -1.0 },
            jerk: j,
            t1,
            t2,
        }
    }

    fn duration(&self) -> f64 {
        2.0 * self.t1 + self.t2
    }

    /// The state `t` into the ramp (0 ≤ t ≤ duration).
    fn at(&self, t: f64) -> PathState {
        let (s, j, t1, t2) = (self.sign, self.jerk, self.t1, self.t2);
        let peak = j * t1;
        let t = t.clamp(0.0, self.duration());
        let p1 = t.min(t1);
        let mut x = self.va * p1 + s * j * p1 * p1 * p1 / 6.0;
        let mut v = self.va + s * j * p1 * p1 / 2.0;
        let mut a = s * j * p1;
        if t > t1 {
            let p2 = (t - t1).min(t2);
            x += v * p2 + s * peak * p2 * p2 / 2.0;
            v += s * peak * p2;
            a = s * peak;
            if t > t1 + t2 {
                let p3 = t - t1 - t2;
                x += v * p3 + s * (peak * p3 * p3 / 2.0 - j * p3 * p3 * p3 / 6.0);
                v += s * (peak * p3 - j * p3 * p3 / 2.0);
                a = s * (peak - j * p3);
            }
        }
        PathState {
            position: x,
            velocity: v,
            acceleration: a,
        }
    }
}

/// The path parameter's plan over one piece: from `v0` up (or down) to a peak, a cruise,
/// down (or up) to `v1`, covering exactly the piece's length.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PieceProfile {
    first: Ramp,
    cruise_v: f64,
    cruise_t: f64,
    last: Ramp,
    /// Where the cruise starts and the last ramp starts.
    x_first: f64,
    x_cruise: f64,
    /// Where the profile ends: the piece's length, or short of it at rest.
    length: f64,
}

impl PieceProfile {
    /// Plans `length` from `v0` to `v1` (both at acceleration 0) within `cap` and `d`; `None`
    /// when `v1` cannot be reached from `v0` within `length` (the look-ahead makes sure it
    /// can). The peak is the highest that fits up to `cap`; a piece entered above `cap` (the
    /// override was lowered) brakes to it when that fits, else keeps its entry velocity.
    pub fn plan(length: f64, v0: f64, v1: f64, cap: f64, d: Dynamics) -> Option<Self> {
        let fits = |vp: f64| {
            change_distance(v0, vp, d) + change_distance(vp, v1, d)
                <= length * (1.0 + 1e-12) + 1e-15
        };
        let low = v0.max(v1);
        if !fits(low) {
            return None;
        }
        let peak = if cap <= low {
            let braked = cap.max(v1);
            if braked < v0 && fits(braked) {
                braked
            } else {
                low
            }
        } else if fits(cap) {
            cap
        } else {
            bisect(low, cap, fits)
        };
        let first = Ramp::new(v0, peak, d);
        let last = Ramp::new(peak, v1, d);
        let x_first = change_distance(v0, peak, d);
        let x_last = change_distance(peak, v1, d);
        // At a peak of 0 (braked to rest on the way) the profile ends short of the length.
        let cruise = if peak > 0.0 {
            (length - x_first - x_last).max(0.0)
        } else {
            0.0
        };
        let cruise_t = if peak > 0.0 { cruise / peak } else { 0.0 };
        Some(Self {
            first,
            cruise_v: peak,
            cruise_t,
            last,
            x_first,
            x_cruise: x_first + cruise,
            length: if peak > 0.0 { length } else { x_first + x_last },
        })
    }

    /// The profile's duration.
    pub fn duration(&self) -> f64 {
        self.first.duration() + self.cruise_t + self.last.duration()
    }

    /// The state `t` into the piece (clamped to its end, where it is exactly the length).
    pub fn at(&self, t: f64) -> PathState {
        let t1 = self.first.duration();
        if t <= t1 {
            return self.first.at(t);
        }
        if t <= t1 + self.cruise_t {
            return PathState {
                position: self.x_first + self.cruise_v * (t - t1),
                velocity: self.cruise_v,
                acceleration: 0.0,
            };
        }
        let t3 = t - t1 - self.cruise_t;
        if t3 >= self.last.duration() {
            let end = self.last.at(self.last.duration());
            return PathState {
                position: self.length,
                velocity: end.velocity,
                acceleration: 0.0,
            };
        }
        let s = self.last.at(t3);
        PathState {
            position: (self.x_cruise + s.position).min(self.length),
            ..s
        }
    }

    /// Where the profile ends (the piece's length unless it brakes to rest short of it).
    pub fn reach(&self) -> f64 {
        self.length
    }

    /// When the cruise starts and ends (acceleration 0 between the ramps; one instant, the
    /// peak, when there is no cruise).
    pub fn cruise(&self) -> (f64, f64) {
        let t1 = self.first.duration();
        (t1, t1 + self.cruise_t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const D: Dynamics = Dynamics {
        acceleration: 1000.0,
        jerk: 20_000.0,
    };

    #[test]
    fn a_ramp_lands_on_its_velocity_and_distance() {
        for (va, vb) in [(0.0, 100.0), (100.0, 0.0), (20.0, 25.0), (50.0, 49.0)] {
            let r = Ramp::new(va, vb, D);
            let end = r.at(r.duration());
            assert!((end.velocity - vb).abs() < 1e-9, "{va}->{vb}");
            assert!(end.acceleration.abs() < 1e-9);
            let expected = change_distance(va, vb, D);
            assert!((end.position - expected).abs() < 1e-9, "{va}->{vb}");
        }
    }

    #[test]
    fn a_piece_covers_its_length_within_its_limits() {
        for (len, v0, v1, cap) in [
            (10.0, 0.0, 0.0, 100.0),
            (1.0, 20.0, 10.0, 100.0),
            (100.0, 30.0, 0.0, 50.0),
            (6.0, 80.0, 0.0, 40.0),
        ] {
            let p = PieceProfile::plan(len, v0, v1, cap, D).unwrap();
            let end = p.at(p.duration());
            assert!((end.position - len).abs() < 1e-9);
            assert!((end.velocity - v1).abs() < 1e-6);
            let mut last = 0.0;
            let n = 2000;
            for k in 0..=n {
                let s = p.at(p.duration() * k as f64 / n as f64);
                assert!(s.position >= last - 1e-12, "monotone");
                assert!(s.acceleration.abs() <= D.acceleration + 1e-9);
                assert!(s.velocity <= cap.max(v0).max(v1) + 1e-9);
                assert!(s.velocity >= -1e-9);
                last = s.position;
            }
        }
    }

    #[test]
    fn the_closed_form_reach_covers_its_length() {
        for (v0, len) in [
            (0.0, 1.0),
            (10.0, 0.3),
            (0.0, 100.0),
            (300.0, 2.0),
            (5.0, 1e-6),
        ] {
            let v = max_reach(v0, len, 1e9, D);
            let covered = change_distance(v0, v, D);
            assert!(
                (covered - len).abs() <= 1e-9 * len.max(1.0),
                "{v0} {len}: {covered}"
            );
        }
    }

    #[test]
    fn reach_is_symmetric_and_bounded() {
        let v = max_reach(0.0, 1.0, 1e9, D);
        assert!((change_distance(0.0, v, D) - 1.0).abs() < 1e-9);
        assert_eq!(max_reach(0.0, 1.0, 5.0, D), 5.0);
        let low = min_reach(v, 1.0, D);
        assert!(low < 1e-6);
        let partial = min_reach(v, 0.5, D);
        assert!(partial > 0.0 && change_distance(v, partial, D) <= 0.5 + 1e-9);
    }
}
