//! The pieces of a contour: the straight parts of its blocks and the curves that round their
//! corners, each with the limits its path parameter moves within.
//!
//! A corner between two straight blocks with directions `u1` and `u2` (unit in X, Y, Z; the
//! other axes move in proportion) is rounded by a curve that leaves the first block `d`
//! before the corner and joins the second `d` after it, run by a parameter `λ` from 0 to `2d`
//! (`t = λ / 2d`):
//!
//! `p(λ) = C - d u1 + λ u1 + 2d W(t) (u2 - u1)`, `W(t) = ∫ w`,
//! `w(t) = 2t²` up to the middle, `1 - 2(1 - t)²` after it.
//!
//! So `p' = u1 + w (u2 - u1)` turns from `u1` to `u2` without a kink; `p''` rises linearly
//! from 0 to `(u2 - u1)/d` at the middle and back to 0 (the curvature starts and ends at 0:
//! no step in any axis's acceleration); `p'''` is `±(u2 - u1)/d²`, the smallest third
//! derivative any such curve of this length can have, since at the short corners of a dense
//! polyline the jerk is what limits the speed. The curve's middle lies `d/6 (u2 - u1)` from the
//! corner: the corner deviation is `d/3 sin(θ/2)` for a turn by `θ`, and no point of the curve
//! is farther from the programmed path. `d` is the largest that keeps this within the
//! tolerance, and at most half of each block (so the curves of a block's two ends never
//! overlap).
//!
//! Per axis `i` the piece bounds `|p'_i| ≤ g1`, `|p''_i| ≤ g2` and `|p'''_i| ≤ g3`; an axis
//! then moves at `p' λ̇`, accelerates at `p' λ̈ + p'' λ̇²` and jerks at
//! `p' λ⃛ + 3 p'' λ̇ λ̈ + p''' λ̇³`. On a straight piece `g2 = g3 = 0` and the path parameter
//! may use every axis's limits in full. On a curve the path's speed is capped where the
//! curvature terms would take more than the axes have, and the path parameter's own
//! acceleration and jerk get what is left at 90 % of the highest speed the curve allows: a
//! curve is mostly run at a steady speed, so its speed matters more than how fast the speed
//! can change on it.

use super::profile::Dynamics;
use crate::channel::path::AxisLimits;
use crate::setpoint::AxisValues;

/// Share of the axes' jerk the path parameter's own jerk may use on a corner curve.
const TANGENTIAL_JERK_SHARE: f64 = 0.1;
/// A curve runs at up to this share of the speed its curvature alone would allow; what that
/// leaves of the axes' acceleration and jerk is the path parameter's.
const CURVE_SPEED_SHARE: f64 = 0.9;
/// The path parameter's acceleration on a curve is at most this share of the axes'.
const TANGENTIAL_ACC_MAX: f64 = 0.5;

/// One piece of a contour.
#[derive(Debug, Clone, Copy)]
pub struct Piece {
    /// Start point (of a curve: where it leaves the first block).
    pub origin: AxisValues,
    /// Direction per unit of path (of a curve: the first block's).
    pub dir: AxisValues,
    /// Of a curve: `u2 - u1`; zeros for a straight piece.
    pub turn: AxisValues,
    /// The path parameter's range.
    pub length: f64,
    /// Of a curve: `d`; 0 for a straight piece.
    pub half: f64,
    /// Velocity the axes allow (and, on a curve, its curvature).
    pub hard_cap: f64,
    /// Programmed feed (path units/s); infinite for rapid.
    pub feed: f64,
    /// A rapid (G0) piece: the rapid override scales it, not the feed override.
    pub rapid: bool,
    /// The path parameter's acceleration and jerk limits.
    pub dynamics: Dynamics,
    /// The path rests at the piece's end (exact stop).
    pub rest_after: bool,
    /// The block's source line.
    pub line: u32,
    /// The block's full length (a straight piece gives at most half of it to each corner).
    pub block_length: f64,
    /// Look-ahead bounds on the velocity at the piece's end: with the axes' caps only, and
    /// with the feed and override too.
    pub bound_hard: f64,
    /// See `bound_hard`.
    pub bound_soft: f64,
}

fn unlimited() -> AxisLimits {
    AxisLimits {
        velocity: f64::INFINITY,
        acceleration: f64::INFINITY,
        jerk: f64::INFINITY,
    }
}

impl Piece {
    /// The straight piece from `origin` along `dir` for `length`, of a block of
    /// `block_length`.
    pub fn straight(
        origin: AxisValues,
        dir: AxisValues,
        length: f64,
        block_length: f64,
        limits: &[AxisLimits],
    ) -> Self {
        let (mut cap, mut acc, mut jerk) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        for (i, u) in dir.iter().enumerate() {
            let g1 = u.abs();
            if g1 <= 1e-12 {
                continue;
            }
            let l = limits.get(i).copied().unwrap_or_else(unlimited);
            cap = cap.min(l.velocity / g1);
            acc = acc.min(l.acceleration / g1);
            jerk = jerk.min(l.jerk / g1);
        }
        Self {
            origin,
            dir,
            turn: AxisValues::zeros(dir.len()),
            length,
            half: 0.0,
            hard_cap: cap,
            feed: f64::INFINITY,
            rapid: false,
            dynamics: Dynamics {
                acceleration: acc,
                jerk,
            },
            rest_after: false,
            line: 0,
            block_length,
            bound_hard: 0.0,
            bound_soft: 0.0,
        }
    }

    /// The curve rounding `corner` from direction `u1` to `u2` with half-size `d`.
    pub fn curve(
        corner: &AxisValues,
        u1: &AxisValues,
        u2: &AxisValues,
        d: f64,
        limits: &[AxisLimits],
    ) -> Self {
        let mut origin = *corner;
        let mut turn = *u1;
        for i in 0..corner.len() {
            origin[i] = corner[i] - d * u1[i];
            turn[i] = u2[i] - u1[i];
        }
        let n = corner.len();
        let axis = |i: usize| {
            let limit = limits.get(i).copied().unwrap_or_else(unlimited);
            Bounds::new(u1[i], u2[i], d, limit)
        };
        // The path parameter's jerk first, then the speed the curvature leaves room for,
        // then the path parameter's acceleration at 90 % of that speed.
        let jerk = (0..n)
            .map(|i| axis(i).tangential_jerk())
            .fold(f64::INFINITY, f64::min);
        let top = (0..n)
            .map(|i| axis(i).speed(jerk, 0.0))
            .fold(f64::INFINITY, f64::min);
        let speed = CURVE_SPEED_SHARE * top;
        let acceleration = (0..n)
            .map(|i| axis(i).tangential_acc(speed, jerk))
            .fold(f64::INFINITY, f64::min);
        let dynamics = Dynamics { acceleration, jerk };
        let cap = (0..n)
            .map(|i| axis(i).speed(jerk, acceleration))
            .fold(f64::INFINITY, f64::min);
        Self {
            origin,
            dir: *u1,
            turn,
            length: 2.0 * d,
            half: d,
            hard_cap: cap,
            feed: f64::INFINITY,
            rapid: false,
            dynamics,
            rest_after: false,
            line: 0,
            block_length: 0.0,
            bound_hard: 0.0,
            bound_soft: 0.0,
        }
    }

    /// The velocity cap under `feed_factor` (feed override for G1, rapid override for G0; 0
    /// under feed hold).
    pub fn soft_cap(&self, feed_factor: f64, rapid_factor: f64) -> f64 {
        if self.rapid {
            self.hard_cap * rapid_factor
        } else {
            self.hard_cap.min(self.feed * feed_factor)
        }
    }

    /// The point at `lambda`.
    pub fn point(&self, lambda: f64, out: &mut AxisValues) {
        let w = if self.half > 0.0 {
            let t = (lambda / (2.0 * self.half)).clamp(0.0, 1.0);
            let r = 1.0 - t;
            let big_w = if t <= 0.5 {
                2.0 / 3.0 * t * t * t
            } else {
                t - 0.5 + 2.0 / 3.0 * r * r * r
            };
            2.0 * self.half * big_w
        } else {
            0.0
        };
        for (i, p) in out.iter_mut().enumerate() {
            *p = self.origin[i] + self.dir[i] * lambda + self.turn[i] * w;
        }
    }

    /// The axes' velocity and acceleration at `lambda` moving at `v` and accelerating at `a`.
    pub fn rates(
        &self,
        lambda: f64,
        (v, a): (f64, f64),
        velocity: &mut AxisValues,
        acceleration: &mut AxisValues,
    ) {
        let (w1, w2) = if self.half > 0.0 {
            let t = (lambda / (2.0 * self.half)).clamp(0.0, 1.0);
            let r = 1.0 - t;
            if t <= 0.5 {
                (2.0 * t * t, 4.0 * t / (2.0 * self.half))
            } else {
                (1.0 - 2.0 * r * r, 4.0 * r / (2.0 * self.half))
            }
        } else {
            (0.0, 0.0)
        };
        for i in 0..velocity.len() {
            let d1 = self.dir[i] + self.turn[i] * w1;
            velocity[i] = d1 * v;
            acceleration[i] = d1 * a + self.turn[i] * w2 * v * v;
        }
    }

    /// The end point.
    pub fn end(&self, out: &mut AxisValues) {
        self.point(self.length, out);
    }
}

/// One axis on a curve: its bounds `g1`, `g2`, `g3` and its limits.
struct Bounds {
    g1: f64,
    g2: f64,
    g3: f64,
    limit: AxisLimits,
}

impl Bounds {
    fn new(u1: f64, u2: f64, d: f64, limit: AxisLimits) -> Self {
        let du = (u2 - u1).abs();
        Self {
            g1: u1.abs().max(u2.abs()),
            g2: du / d,
            g3: du / (d * d),
            limit,
        }
    }

    /// The path parameter's jerk this axis allows.
    fn tangential_jerk(&self) -> f64 {
        if self.g1 <= 1e-12 {
            return f64::INFINITY;
        }
        TANGENTIAL_JERK_SHARE * self.limit.jerk / self.g1
    }

    /// The path parameter's acceleration this axis allows at `speed` with path jerk `jerk`.
    fn tangential_acc(&self, speed: f64, jerk: f64) -> f64 {
        if self.g1 <= 1e-12 {
            return f64::INFINITY;
        }
        let l = self.limit;
        let mut a = TANGENTIAL_ACC_MAX * l.acceleration / self.g1;
        a = a.min((l.acceleration - self.g2 * speed * speed) / self.g1);
        if self.g2 > 1e-12 {
            let room = l.jerk - self.g1 * jerk - self.g3 * speed.powi(3);
            a = a.min(room / (3.0 * self.g2 * speed.max(1e-12)));
        }
        a.max(0.0)
    }

    /// The highest speed with path acceleration `acc` and jerk `jerk` within the limits.
    fn speed(&self, jerk: f64, acc: f64) -> f64 {
        let l = self.limit;
        let mut cap = if self.g1 > 1e-12 {
            l.velocity / self.g1
        } else {
            f64::INFINITY
        };
        if self.g2 <= 1e-12 {
            return cap;
        }
        let acc_room = (l.acceleration - self.g1 * acc).max(0.0);
        cap = cap.min((acc_room / self.g2).sqrt());
        // 3 g2 a v + g3 v³ ≤ J - g1 j: increasing and convex in v, so Newton from an upper
        // bound comes down onto the root; then one step below it if rounding left it above.
        let jerk_room = (l.jerk - self.g1 * jerk).max(0.0);
        let (lin, cub) = (3.0 * self.g2 * acc, self.g3);
        let needs = |v: f64| lin * v + cub * v * v * v;
        let mut hi = (jerk_room / cub).cbrt().min(cap);
        if lin > 0.0 {
            hi = hi.min(jerk_room / lin);
        }
        for _ in 0..40 {
            let f = needs(hi) - jerk_room;
            if f <= 0.0 {
                break;
            }
            let next = hi - f / (lin + 3.0 * cub * hi * hi);
            // At the root within rounding: one step below it.
            hi = if next < hi { next } else { hi * (1.0 - 1e-12) };
        }
        cap.min(hi)
    }
}
