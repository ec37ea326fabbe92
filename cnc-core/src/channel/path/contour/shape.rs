//! The shape of a corner curve: how its tangent turns along it. With `t` running from 0 to 1
//! over the curve, the tangent is `u1 + w(t) (u2 - u1)`; `w'` (the curvature, in shares of
//! the curve's mean) is piecewise linear through a few knots, and `w` must run from 0 to 1
//! with `∫ w = μ` so that the curve ends on the second leg where the legs say: a curve leaving
//! the first leg `d1` before the corner and joining the second `d2` after it has
//! `μ = d2 / (d1 + d2)` (1/2 for equal legs).
//!
//! * Between two straight pieces with equal legs (`c0 = c1 = 0`, `μ = 1/2`): the triangle
//!   `0, 2, 0` (knots at 0, 1/2, 1), the steepest slope of all shapes that start and end at 0.
//! * Otherwise (`c0` or `c1` > 0, the neighbours' shared curvature, or unequal legs): knots at
//!   0, 1/3, 2/3, 1 with values `c0, m1, m2, c1`; both conditions are linear in `m1`, `m2`:
//!   `m1 + m2 = (6 - c0 - c1) / 2` and `4 c0 + 6 m1 + 3 m2 + c1 / 2 = 27 μ` (the knots'
//!   weights in `∫ w = ∫ (1 - t) w'`). With `μ = 1/2`: `m1 = (9 - 5 c0 + 2 c1) / 6`,
//!   `m2 = (9 + 2 c0 - 5 c1) / 6`, and `c0 = c1 = 1` is constant curvature. With `μ = 1/3`,
//!   `c0 = 0` and `c1 = 2` the curvature ramps linearly from 0 (a transition from a straight
//!   into a curve: [`end_share_limit`]).

/// One knot: where it is, `w'` there, and `w`, `W` there.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Knot {
    t: f64,
    dw: f64,
    w: f64,
    big_w: f64,
}

/// A corner curve's shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shape {
    knots: [Knot; 4],
}

impl Default for Shape {
    fn default() -> Self {
        Self::new([0.0, 0.0], 0.5)
    }
}

/// The largest curvature share a curve of `∫ w = mu` may have at the end whose leg is the
/// shorter (1 with equal legs; 2 with `mu = 1/3` (or 2/3 at its start), where the curvature
/// ramps linearly from the other end's 0): what the neighbour sharing that end may ask of it.
pub fn end_share_limit(mu: f64) -> f64 {
    1.0 + 6.0 * (0.5 - mu.min(1.0 - mu)).clamp(0.0, 1.0 / 6.0)
}

/// The largest curvature shares a curve of `∫ w = mu` may take at its start and end from its
/// neighbours: none at a longer leg's end (it meets a straight piece).
pub fn share_limits(mu: f64) -> [f64; 2] {
    let limit = end_share_limit(mu);
    if mu < 0.5 {
        [0.0, limit]
    } else if mu > 0.5 {
        [limit, 0.0]
    } else {
        [1.0, 1.0]
    }
}

impl Shape {
    /// The shape with curvature shares `c0` at its start and `c1` at its end (each at most
    /// [`end_share_limit`]) and `∫ w = mu` (1/3..=2/3).
    pub fn new([c0, c1]: [f64; 2], mu: f64) -> Self {
        let points = if c0 <= 0.0 && c1 <= 0.0 && mu == 0.5 {
            [(0.0, 0.0), (0.5, 2.0), (0.5, 2.0), (1.0, 0.0)]
        } else {
            let (m1, m2) = if mu == 0.5 {
                (
                    (9.0 - 5.0 * c0 + 2.0 * c1) / 6.0,
                    (9.0 + 2.0 * c0 - 5.0 * c1) / 6.0,
                )
            } else {
                let m1 = (27.0 * mu - 9.0 - 2.5 * c0 + c1) / 3.0;
                (m1, (6.0 - c0 - c1) / 2.0 - m1)
            };
            [(0.0, c0), (1.0 / 3.0, m1), (2.0 / 3.0, m2), (1.0, c1)]
        };
        let mut knots = [Knot::default(); 4];
        knots[0] = Knot {
            t: 0.0,
            dw: points[0].1,
            w: 0.0,
            big_w: 0.0,
        };
        for k in 1..4 {
            let (t, dw) = points[k];
            let (w, big_w) = integrate(&knots[k - 1], t, dw, t);
            knots[k] = Knot { t, dw, w, big_w };
        }
        Self { knots }
    }

    /// The curvature shares at the start and the end.
    pub fn ends(&self) -> [f64; 2] {
        [self.knots[0].dw, self.knots[3].dw]
    }

    /// `W(t)`, `w(t)`, `w'(t)` at `t` (clamped to 0..=1).
    pub fn at(&self, t: f64) -> (f64, f64, f64) {
        let t = t.clamp(0.0, 1.0);
        let mut k = 1;
        while k < 3 && t > self.knots[k].t {
            k += 1;
        }
        let (a, b) = (&self.knots[k - 1], &self.knots[k]);
        let (w, big_w) = integrate(a, b.t, b.dw, t);
        let dw = if b.t > a.t {
            a.dw + (b.dw - a.dw) * (t - a.t) / (b.t - a.t)
        } else {
            b.dw
        };
        (big_w, w, dw)
    }

    /// The largest `w'` (the curvature's peak, in shares of its mean).
    pub fn peak(&self) -> f64 {
        self.knots.iter().map(|k| k.dw).fold(0.0, f64::max)
    }

    /// The largest `|w''|` (how fast the curvature changes).
    pub fn steepest(&self) -> f64 {
        self.knots
            .windows(2)
            .filter(|p| p[1].t > p[0].t)
            .map(|p| ((p[1].dw - p[0].dw) / (p[1].t - p[0].t)).abs())
            .fold(0.0, f64::max)
    }
}

/// `w` and `W` at `t` on the segment from knot `a` to (`tb`, `dwb`).
fn integrate(a: &Knot, tb: f64, dwb: f64, t: f64) -> (f64, f64) {
    let h = t - a.t;
    let slope = if tb > a.t {
        (dwb - a.dw) / (tb - a.t)
    } else {
        0.0
    };
    let w = a.w + a.dw * h + 0.5 * slope * h * h;
    let big_w = a.big_w + a.w * h + 0.5 * a.dw * h * h + slope * h * h * h / 6.0;
    (w, big_w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn the_triangle_is_the_corner_curve_between_straights() {
        let s = Shape::new([0.0, 0.0], 0.5);
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            let r = 1.0 - t;
            let w = if t <= 0.5 {
                2.0 * t * t
            } else {
                1.0 - 2.0 * r * r
            };
            assert!((s.at(t).1 - w).abs() < 1e-12, "{t}");
        }
        assert_eq!((s.peak(), s.steepest()), (2.0, 4.0));
    }

    #[test]
    fn a_transition_ramps_its_curvature_linearly() {
        let s = Shape::new([0.0, end_share_limit(1.0 / 3.0)], 1.0 / 3.0);
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            assert!((s.at(t).2 - 2.0 * t).abs() < 1e-12, "{t}");
        }
        assert!((s.steepest() - 2.0).abs() < 1e-12);
        let exit = Shape::new([end_share_limit(2.0 / 3.0), 0.0], 2.0 / 3.0);
        assert!((exit.at(0.25).2 - 1.5).abs() < 1e-12);
    }

    proptest! {
        /// Every shape turns the tangent fully, ends on the second leg, rises throughout and
        /// has the curvature it was asked for at its ends: equal legs, and a transition's
        /// longer leg on either side.
        #[test]
        fn every_shape_ends_where_the_legs_say(
            c0 in 0.0f64..=1.0,
            c1 in 0.0f64..=1.0,
            mu in prop_oneof![Just(0.5), 1.0f64 / 3.0..=0.5, 0.5f64..=2.0 / 3.0],
        ) {
            // The shorter leg's end may take up to its limit.
            let limit = end_share_limit(mu);
            let (c0, c1) = if mu < 0.5 { (0.0, c1 * limit) } else if mu > 0.5 { (c0 * limit, 0.0) } else { (c0, c1) };
            let s = Shape::new([c0, c1], mu);
            let (big_w, w, _) = s.at(1.0);
            prop_assert!((w - 1.0).abs() < 1e-12);
            prop_assert!((big_w - mu).abs() < 1e-12);
            prop_assert!((s.at(0.0).2 - c0).abs() < 1e-12 && (s.at(1.0).2 - c1).abs() < 1e-12);
            let mut last = 0.0;
            for k in 1..=100 {
                let (_, w, dw) = s.at(k as f64 / 100.0);
                prop_assert!(dw >= -1e-12 && w >= last);
                last = w;
            }
        }
    }
}
