//! Pieces in one plane whose curvature turns with the path, for a small arc between tangent
//! straight blocks ([`super::fillet`]): the arc itself (an exact circle, or the block's
//! spiral when its end radius differs from its start's) and the parts of the transitions
//! into it and out of it, each a quintic in the path parameter, and the clothoid whose points
//! the quintics join.
//!
//! A quintic matches a point, a first and a second derivative at each end, so at both ends
//! position, direction and curvature equal the neighbours' (no step in any axis's velocity or
//! acceleration), and its curvature turns with the path (unlike a corner curve's, whose plane
//! of curvature is fixed). With the path parameter `λ` over `0..L` and `t = λ / L`,
//! `p(λ) = Σ c_k t^k`; the bounds on its axes' derivatives over `λ` are exact for the second
//! and third, and for the first the largest of 32 samples plus what the second can add
//! between them; they are found once, when the piece is made.

use super::super::circle::Circle;

/// Samples the first derivative's bound is taken over (between them it moves by at most the
/// second's bound times half their distance: a few thousandths here).
const SAMPLES: usize = 32;

/// The shape of a plane piece.
#[derive(Debug, Clone, Copy)]
pub(super) enum PlaneShape {
    /// The arc block's circle (or spiral) over `s = λ / L`.
    Circle(Circle),
    /// A quintic per plane axis, in `t = λ / L`.
    Quintic([[f64; 6]; 2]),
}

/// A piece in the plane of `axes`, its path parameter over `0..length`.
#[derive(Debug, Clone, Copy)]
pub(super) struct PlaneCurve {
    pub axes: [usize; 2],
    pub shape: PlaneShape,
    pub length: f64,
    /// [`Self::bounds`] and [`Self::stretch`], found when it is made.
    bounds: [[f64; 3]; 2],
    stretch: f64,
}

/// A point with its first and second derivative over the path parameter (plane axes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Jet {
    pub point: [f64; 2],
    pub tangent: [f64; 2],
    pub curvature: [f64; 2],
}

impl PlaneCurve {
    /// The circle piece of `circle` (its length in the plane `length`).
    pub fn circle(circle: Circle, length: f64) -> Self {
        Self::made(circle.axes, PlaneShape::Circle(circle), length)
    }

    /// The piece with its bounds found.
    fn made(axes: [usize; 2], shape: PlaneShape, length: f64) -> Self {
        let mut curve = Self {
            axes,
            shape,
            length,
            bounds: [[0.0; 3]; 2],
            stretch: 1.0,
        };
        curve.bounds = curve.find_bounds();
        curve.stretch = curve.find_stretch();
        curve
    }

    /// The quintic of `length` from `from` to `to` (their derivatives over the path
    /// parameter).
    pub fn quintic(axes: [usize; 2], from: &Jet, to: &Jet, length: f64) -> Self {
        let mut coef = [[0.0; 6]; 2];
        for (k, c) in coef.iter_mut().enumerate() {
            let (p0, v0, a0) = (
                from.point[k],
                from.tangent[k] * length,
                from.curvature[k] * length * length,
            );
            let (p1, v1, a1) = (
                to.point[k],
                to.tangent[k] * length,
                to.curvature[k] * length * length,
            );
            let (c0, c1, c2) = (p0, v0, 0.5 * a0);
            // The rest of the end conditions, met by c3..c5.
            let d = p1 - (c0 + c1 + c2);
            let e = v1 - (c1 + 2.0 * c2);
            let f = a1 - 2.0 * c2;
            *c = [
                c0,
                c1,
                c2,
                10.0 * d - 4.0 * e + 0.5 * f,
                -15.0 * d + 7.0 * e - f,
                6.0 * d - 3.0 * e + 0.5 * f,
            ];
        }
        Self::made(axes, PlaneShape::Quintic(coef), length)
    }

    /// Whether it is a transition (a quintic), not the arc.
    pub fn is_transition(&self) -> bool {
        matches!(self.shape, PlaneShape::Quintic(_))
    }

    /// The point and its derivatives at `lambda` (clamped to the piece).
    pub fn at(&self, lambda: f64) -> Jet {
        let l = self.length;
        let s = (lambda / l).clamp(0.0, 1.0);
        match &self.shape {
            PlaneShape::Circle(c) => {
                let (d1, d2) = c.rates(s, 1.0, 0.0);
                Jet {
                    point: c.point(s),
                    tangent: [d1[0] / l, d1[1] / l],
                    curvature: [d2[0] / (l * l), d2[1] / (l * l)],
                }
            }
            PlaneShape::Quintic(coef) => {
                let axis = |c: &[f64; 6]| {
                    let p = c[0] + s * (c[1] + s * (c[2] + s * (c[3] + s * (c[4] + s * c[5]))));
                    let d1 = c[1]
                        + s * (2.0 * c[2] + s * (3.0 * c[3] + s * (4.0 * c[4] + s * 5.0 * c[5])));
                    let d2 = 2.0 * c[2] + s * (6.0 * c[3] + s * (12.0 * c[4] + s * 20.0 * c[5]));
                    (p, d1 / l, d2 / (l * l))
                };
                let (x, y) = (axis(&coef[0]), axis(&coef[1]));
                Jet {
                    point: [x.0, y.0],
                    tangent: [x.1, y.1],
                    curvature: [x.2, y.2],
                }
            }
        }
    }

    /// The largest `|p'|` (the path's speed per unit of the parameter's): 1 on the circle;
    /// on a transition the largest of its samples plus what `p''` can add between them.
    pub fn stretch(&self) -> f64 {
        self.stretch
    }

    fn find_stretch(&self) -> f64 {
        match self.shape {
            PlaneShape::Circle(_) => 1.0,
            PlaneShape::Quintic(_) => {
                let g = self.bounds;
                let second = g[0][1].hypot(g[1][1]);
                let step = self.length / SAMPLES as f64;
                (0..=SAMPLES)
                    .map(|i| {
                        let t = self.at(i as f64 * step).tangent;
                        t[0].hypot(t[1])
                    })
                    .fold(0.0, f64::max)
                    + 0.5 * second * step
            }
        }
    }

    /// Per plane axis, bounds on `|p'|`, `|p''|`, `|p'''|` over the piece (`λ` units).
    pub fn bounds(&self) -> [[f64; 3]; 2] {
        self.bounds
    }

    fn find_bounds(&self) -> [[f64; 3]; 2] {
        let l = self.length;
        match &self.shape {
            PlaneShape::Circle(c) => {
                // p = r(s) (cos, sin)(a0 + sweep s): each derivative over s is bounded by the
                // sum of its terms' magnitudes.
                let (w, dr) = (c.sweep.abs(), (c.r1 - c.r0).abs());
                let r = c.r0.max(c.r1);
                let g1 = (dr + r * w) / l;
                let g2 = (2.0 * dr * w + r * w * w) / (l * l);
                let g3 = (3.0 * dr * w * w + r * w * w * w) / (l * l * l);
                [[g1, g2, g3]; 2]
            }
            PlaneShape::Quintic(coef) => {
                let mut out = [[0.0; 3]; 2];
                for (k, c) in coef.iter().enumerate() {
                    let (g2, g3) = quintic_higher(c);
                    let mut g1 = 0.0f64;
                    for i in 0..=SAMPLES {
                        let s = i as f64 / SAMPLES as f64;
                        let d1 = c[1]
                            + s * (2.0 * c[2]
                                + s * (3.0 * c[3] + s * (4.0 * c[4] + s * 5.0 * c[5])));
                        g1 = g1.max(d1.abs());
                    }
                    // Between samples the first derivative moves by at most g2 h / 2.
                    g1 += 0.5 * g2 / SAMPLES as f64;
                    out[k] = [g1 / l, g2 / (l * l), g3 / (l * l * l)];
                }
                out
            }
        }
    }
}

/// Steps of Simpson's rule per part of a clothoid.
const CLOTHOID_STEPS: usize = 8;

/// A clothoid leaving `from` (its point and unit tangent) with no curvature, turning left
/// (`sign` 1) or right (-1), its curvature growing linearly to `kappa` over `length`: its
/// point, tangent and curvature vector at `K` points `length / (K - 1)` apart (the first is
/// `from`'s, the last its end), its positions integrated by Simpson's rule.
pub(super) fn clothoid<const K: usize>(
    (point, u): ([f64; 2], [f64; 2]),
    sign: f64,
    kappa: f64,
    length: f64,
) -> [Jet; K] {
    let heading = |s: f64| sign * kappa * s * s / (2.0 * length);
    let dir = |s: f64| {
        let (sn, cs) = heading(s).sin_cos();
        [cs * u[0] - sn * u[1], sn * u[0] + cs * u[1]]
    };
    let jet = |at: [f64; 2], s: f64| {
        let t = dir(s);
        let k = sign * kappa * s / length;
        Jet {
            point: at,
            tangent: t,
            curvature: [-k * t[1], k * t[0]],
        }
    };
    let part = length / (K - 1) as f64;
    let mut out = [jet(point, 0.0); K];
    for i in 1..K {
        let (a, h) = (part * (i - 1) as f64, part / CLOTHOID_STEPS as f64);
        let mut sum = [0.0; 2];
        for j in 0..=CLOTHOID_STEPS {
            let w = if j == 0 || j == CLOTHOID_STEPS {
                1.0
            } else if j % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let d = dir(a + h * j as f64);
            sum = [sum[0] + w * d[0], sum[1] + w * d[1]];
        }
        let p = out[i - 1].point;
        out[i] = jet([p[0] + sum[0] * h / 3.0, p[1] + sum[1] * h / 3.0], a + part);
    }
    out
}

/// The largest `|p''|` and `|p'''|` of a quintic over `t` in 0..=1: `p'''` is a quadratic (its
/// largest magnitude at an end or its vertex), `p''` a cubic (at an end or where `p'''` is 0).
fn quintic_higher(c: &[f64; 6]) -> (f64, f64) {
    let d2 = |s: f64| 2.0 * c[2] + s * (6.0 * c[3] + s * (12.0 * c[4] + s * 20.0 * c[5]));
    let (qa, qb, qc) = (60.0 * c[5], 24.0 * c[4], 6.0 * c[3]);
    let d3 = |s: f64| qc + s * (qb + s * qa);
    let inside = |s: f64| (0.0..=1.0).contains(&s);
    let mut g3 = d3(0.0).abs().max(d3(1.0).abs());
    if qa.abs() > 1e-300 {
        let vertex = -qb / (2.0 * qa);
        if inside(vertex) {
            g3 = g3.max(d3(vertex).abs());
        }
    }
    let mut g2 = d2(0.0).abs().max(d2(1.0).abs());
    let mut roots = [f64::NAN; 2];
    if qa.abs() > 1e-300 {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            roots = [(-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)];
        }
    } else if qb.abs() > 1e-300 {
        roots[0] = -qc / qb;
    }
    for s in roots.into_iter().filter(|s| inside(*s)) {
        g2 = g2.max(d2(s).abs());
    }
    (g2, g3)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn jet(p: [f64; 2], u: [f64; 2], k: [f64; 2]) -> Jet {
        Jet {
            point: p,
            tangent: u,
            curvature: k,
        }
    }

    /// A clothoid's points against its series (Fresnel's integrals for a small turn; within
    /// Simpson's error, 1e-9 here), and
    /// its tangent and curvature at its end.
    #[test]
    fn a_clothoid_has_the_points_of_its_series() {
        let (kappa, length) = (0.2, 1.5);
        let jets = clothoid::<4>(([1.0, 2.0], [1.0, 0.0]), 1.0, kappa, length);
        let a = kappa / (2.0 * length);
        for (k, j) in jets.iter().enumerate() {
            let s = length * k as f64 / 3.0;
            let x = s - a * a * s.powi(5) / 10.0 + a.powi(4) * s.powi(9) / 216.0
                - a.powi(6) * s.powi(13) / 9360.0;
            let y = a * s.powi(3) / 3.0 - a.powi(3) * s.powi(7) / 42.0
                + a.powi(5) * s.powi(11) / 1320.0
                - a.powi(7) * s.powi(15) / 75600.0;
            assert!((j.point[0] - 1.0 - x).abs() < 1e-8, "{k}");
            assert!((j.point[1] - 2.0 - y).abs() < 1e-8, "{k}");
        }
        let end = jets[3];
        let psi = kappa * length / 2.0;
        assert!((end.tangent[0] - psi.cos()).abs() < 1e-15);
        assert!((end.curvature[1] - kappa * psi.cos()).abs() < 1e-15);
        let right = clothoid::<2>(([0.0, 0.0], [0.0, 1.0]), -1.0, kappa, length);
        assert!(right[1].point[0] > 0.0 && right[1].curvature[0] > 0.0);
    }

    proptest! {
        /// A quintic meets its ends' point, tangent and curvature, and its bounds hold at
        /// every point (its derivatives checked against differences of its points).
        #[test]
        fn a_quintic_meets_its_ends_and_keeps_its_bounds(
            p1 in (0.5f64..2.0, -0.5f64..0.5),
            angle in -1.0f64..1.0,
            k1 in -1.0f64..1.0,
            length in 0.5f64..2.0,
        ) {
            let from = jet([0.0, 0.0], [1.0, 0.0], [0.0, 0.0]);
            let u = [angle.cos(), angle.sin()];
            let to = jet([p1.0, p1.1], u, [-u[1] * k1, u[0] * k1]);
            let q = PlaneCurve::quintic([0, 1], &from, &to, length);
            let (a, b) = (q.at(0.0), q.at(length));
            for (x, y) in [(a, from), (b, to)] {
                for k in 0..2 {
                    prop_assert!((x.point[k] - y.point[k]).abs() < 1e-12);
                    prop_assert!((x.tangent[k] - y.tangent[k]).abs() < 1e-12);
                    prop_assert!((x.curvature[k] - y.curvature[k]).abs() < 1e-9);
                }
            }
            let g = q.bounds();
            let h = length / 2000.0;
            for i in 0..2000 {
                let (j0, j1) = (q.at(i as f64 * h), q.at((i + 1) as f64 * h));
                for (k, [g1, g2, g3]) in g.iter().copied().enumerate() {
                    prop_assert!(j0.tangent[k].abs() <= g1 * (1.0 + 1e-12));
                    prop_assert!(j0.curvature[k].abs() <= g2 * (1.0 + 1e-12));
                    let third = (j1.curvature[k] - j0.curvature[k]) / h;
                    prop_assert!(third.abs() <= g3 * (1.0 + 1e-6) + 1e-9);
                    let slope = (j1.point[k] - j0.point[k]) / h;
                    // The trapezoid rule's error: at most h² max|p'''| / 12.
                    let error = (slope - 0.5 * (j0.tangent[k] + j1.tangent[k])).abs();
                    prop_assert!(error <= h * h * g3 / 12.0 + 1e-9);
                }
            }
        }
    }
}
