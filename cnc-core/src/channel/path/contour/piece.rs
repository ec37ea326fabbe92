//! The pieces of a contour: the straight parts of its blocks and the curves that round their
//! corners, each with the limits its path parameter moves within.
//!
//! A corner between two straight blocks with directions `u1` and `u2` (unit in X, Y, Z; the
//! other axes move in proportion) is rounded by a curve that leaves the first block `d1`
//! before the corner and joins the second `d2` after it (its legs), run by a parameter `λ`
//! from 0 to `L = d1 + d2` (`t = λ / L`):
//!
//! `p(λ) = C - d1 u1 + λ u1 + L W(t) (u2 - u1)`, `W(t) = ∫ w`, `w` from the curve's
//! [`Shape`] with `W(1) = d2 / L`.
//!
//! So `p' = u1 + w (u2 - u1)` turns from `u1` to `u2` without a kink, `p''` is
//! `w'/L (u2 - u1)` and `p'''` is `w''/L² (u2 - u1)`. The legs are equal (`d`) except
//! where a straight block meets an arc's chords: there the straight's leg is up to twice the
//! chord's and the curvature ramps from 0 into the arc's (a transition). Between two straight pieces
//! the shape is the triangle: the curvature rises linearly from 0 to `(u2 - u1)/d` at the
//! middle and back to 0 (no step in any axis's acceleration), and `p'''` is `±(u2 - u1)/d²`,
//! the smallest third derivative any such curve of this length can have. Its middle lies
//! `d/6 (u2 - u1)` from the corner: the corner deviation is `d/3 sin(θ/2)` for a turn by
//! `θ`. `d` is the largest that keeps this within the tolerance, and at most half of each
//! block (so the curves of a block's two ends never overlap). Where two curves meet in the
//! middle of a block they took all of, they may share their curvature there
//! ([`super::corner`]); a shape other than the triangle is checked against the tolerance
//! point by point.
//!
//! Per axis `i` the piece bounds `|p'_i| ≤ g1`, `|p''_i| ≤ g2` and `|p'''_i| ≤ g3`; an axis
//! then moves at `p' λ̇`, accelerates at `p' λ̈ + p'' λ̇²` and jerks at
//! `p' λ⃛ + 3 p'' λ̇ λ̈ + p''' λ̇³`. On a straight piece `g2 = g3 = 0` and the path parameter
//! may use every axis's limits in full. On a curve the path's speed is capped where the
//! curvature terms would take more than the axes have, and the path parameter's own
//! acceleration and jerk get what is left at the speed the curve will run at (its feed, or
//! 90 % of the highest speed its curvature allows when that is lower).

use super::planar::PlaneCurve;
use super::profile::Dynamics;
use super::shape::Shape;
use crate::channel::path::AxisLimits;
use crate::setpoint::AxisValues;

/// Shares of the axes' jerk the path parameter's own jerk may use on a corner curve, tried, largest first: the largest that keeps [`CAP_KEPT`] of the speed the
/// smallest allows (a curve whose curvature changes little, as a dense polyline's, lends the
/// path parameter most of the jerk; a sharp corner's curve needs it for its speed).
const TANGENTIAL_JERK_SHARES: [f64; 3] = [0.5, 0.25, 0.1];
/// See [`TANGENTIAL_JERK_SHARES`].
const CAP_KEPT: f64 = 0.99;
/// A curve runs at up to this share of the speed its curvature alone would allow; what that
/// leaves of the axes' acceleration and jerk is the path parameter's.
const CURVE_SPEED_SHARE: f64 = 0.9;
/// The path parameter's acceleration on a curve is at most this share of the axes'.
const TANGENTIAL_ACC_MAX: f64 = 0.9;

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
    /// Of a curve: its legs `d1`, `d2` (before and after the corner); zeros for a straight
    /// piece.
    pub legs: [f64; 2],
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
    /// The piece may be planned in one unit with the piece before ([`super::plan`]).
    pub chain: bool,
    /// Of a curve: how its tangent turns ([`Shape`]; its curvature at its ends is 0 where it
    /// meets a straight piece).
    pub shape: Shape,
    /// Of a curve: the speed at which the step in curvature where it meets its neighbour
    /// curves stays within the axes' jerk over a cycle.
    pub junction_cap: f64,
    /// Of a curve: the corner tolerance it was made for.
    pub tolerance: f64,
    /// The block's source line.
    pub line: u32,
    /// Part of an arc's chords (a straight block meeting them gets a transition).
    pub on_arc: bool,
    /// The block's full length (a straight piece gives at most half of it to each corner).
    pub block_length: f64,
    /// Look-ahead bounds on the velocity at the piece's end: with the axes' caps only, and
    /// with the feed and override too.
    pub bound_hard: f64,
    /// See `bound_hard`.
    pub bound_soft: f64,
    /// A piece in a plane whose curvature turns with the path (a small arc between tangent
    /// straights and its transitions, [`super::fillet`]): its shape there; the other axes
    /// stay at `origin`.
    pub(super) plane: Option<PlaneCurve>,
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
            legs: [0.0, 0.0],
            hard_cap: cap,
            feed: f64::INFINITY,
            rapid: false,
            dynamics: Dynamics {
                acceleration: acc,
                jerk,
            },
            rest_after: false,
            chain: false,
            shape: Shape::default(),
            junction_cap: f64::INFINITY,
            tolerance: 0.0,
            line: 0,
            on_arc: false,
            block_length,
            bound_hard: 0.0,
            bound_soft: 0.0,
            plane: None,
        }
    }

    /// The curve rounding `corner` from direction `u1` to `u2` with legs `legs`, its
    /// curvature at its ends `shape` of its mean, for axes with `limits` and a path at up to
    /// `feed` (infinite for rapid): the path parameter's acceleration is shared out at the
    /// speed the curve will run at.
    pub fn curve(
        corner: &AxisValues,
        (u1, u2): (&AxisValues, &AxisValues),
        legs: [f64; 2],
        shape: [f64; 2],
        (limits, feed): (&[AxisLimits], f64),
    ) -> Self {
        let mut origin = *corner;
        let mut turn = *u1;
        for i in 0..corner.len() {
            origin[i] = corner[i] - legs[0] * u1[i];
            turn[i] = u2[i] - u1[i];
        }
        let length = legs[0] + legs[1];
        let form = Shape::new(shape, legs[1] / length);
        let n = corner.len();
        // A curve meeting another keeps a share of the jerk for the step where they meet.
        let shared = shape[0] > 0.0 || shape[1] > 0.0;
        let axis = |i: usize| {
            let mut limit = limits.get(i).copied().unwrap_or_else(unlimited);
            if shared {
                limit.jerk *= 1.0 - super::corner::JUNCTION_JERK_SHARE;
            }
            Bounds::new(u1[i], u2[i], length, &form, limit)
        };
        let (cap, dynamics) = caps(n, &axis, feed);
        Self {
            origin,
            dir: *u1,
            turn,
            length,
            legs,
            hard_cap: cap,
            feed: f64::INFINITY,
            rapid: false,
            dynamics,
            rest_after: false,
            chain: false,
            shape: form,
            junction_cap: f64::INFINITY,
            tolerance: 0.0,
            line: 0,
            on_arc: false,
            block_length: 0.0,
            bound_hard: 0.0,
            bound_soft: 0.0,
            plane: None,
        }
    }

    /// The piece `curve` in a plane (its other axes at `origin`'s values) for axes with
    /// `limits` and a path at up to `feed`.
    pub(super) fn planar(
        origin: AxisValues,
        curve: PlaneCurve,
        (limits, feed): (&[AxisLimits], f64),
    ) -> Self {
        let g = curve.bounds();
        let axis = |i: usize| {
            let limit = limits.get(i).copied().unwrap_or_else(unlimited);
            match curve.axes.iter().position(|&a| a == i) {
                Some(k) => Bounds::raw(g[k], limit),
                None => Bounds::raw([0.0; 3], limit),
            }
        };
        let (cap, dynamics) = caps(origin.len(), &axis, feed);
        let start = curve.at(0.0);
        let mut dir = AxisValues::zeros(origin.len());
        for (k, &a) in curve.axes.iter().enumerate() {
            dir[a] = start.tangent[k];
        }
        let mut piece = Self::straight(origin, dir, curve.length, curve.length, limits);
        piece.hard_cap = cap;
        piece.dynamics = dynamics;
        piece.plane = Some(curve);
        piece
    }

    /// Whether the piece lies in a plane with its curvature turning ([`super::planar`]).
    pub fn is_plane(&self) -> bool {
        self.plane.is_some()
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

    /// Whether the piece is a curve (a corner's, or a transition into a small arc): it is no
    /// block's own piece.
    pub fn is_curve(&self) -> bool {
        self.legs[0] > 0.0 || self.plane.is_some_and(|c| c.is_transition())
    }

    /// The point at `lambda`.
    pub fn point(&self, lambda: f64, out: &mut AxisValues) {
        if let Some(curve) = &self.plane {
            out.copy_from_slice(&self.origin);
            let jet = curve.at(lambda);
            for (k, &a) in curve.axes.iter().enumerate() {
                out[a] = jet.point[k];
            }
            return;
        }
        let w = if self.is_curve() {
            let t = (lambda / self.length).clamp(0.0, 1.0);
            self.length * self.shape.at(t).0
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
        if let Some(curve) = &self.plane {
            velocity.fill(0.0);
            acceleration.fill(0.0);
            let jet = curve.at(lambda);
            for (k, &i) in curve.axes.iter().enumerate() {
                velocity[i] = jet.tangent[k] * v;
                acceleration[i] = jet.tangent[k] * a + jet.curvature[k] * v * v;
            }
            return;
        }
        let (w1, w2) = if self.is_curve() {
            let t = (lambda / self.length).clamp(0.0, 1.0);
            let (_, w, dw) = self.shape.at(t);
            (w, dw / self.length)
        } else {
            (0.0, 0.0)
        };
        for i in 0..velocity.len() {
            let d1 = self.dir[i] + self.turn[i] * w1;
            velocity[i] = d1 * v;
            acceleration[i] = d1 * a + self.turn[i] * w2 * v * v;
        }
    }

    /// Of a curve: the corner it rounds, and the directions before and after it.
    pub fn corner(&self) -> (AxisValues, AxisValues, AxisValues) {
        let (mut corner, mut u2) = (self.origin, self.dir);
        for i in 0..corner.len() {
            corner[i] += self.legs[0] * self.dir[i];
            u2[i] += self.turn[i];
        }
        (corner, self.dir, u2)
    }

    /// Of a curve: the largest distance of its points (sampled) from the two legs of the
    /// corner it rounds (in X, Y, Z).
    pub fn deviation(&self) -> f64 {
        let (corner, u1, u2) = self.corner();
        let mut point = self.origin;
        let mut worst = 0.0f64;
        for k in 1..DEVIATION_SAMPLES {
            self.point(
                self.length * k as f64 / DEVIATION_SAMPLES as f64,
                &mut point,
            );
            let leg = |u: &AxisValues, sign: f64| {
                let rel = |i: usize| point[i] - corner[i];
                let d = self.legs[usize::from(sign > 0.0)];
                let along = ((0..3).map(|i| rel(i) * u[i]).sum::<f64>() * sign).clamp(0.0, d);
                (0..3)
                    .map(|i| (rel(i) - sign * along * u[i]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            };
            worst = worst.max(leg(&u1, -1.0).min(leg(&u2, 1.0)));
        }
        worst
    }

    /// The end point.
    pub fn end(&self, out: &mut AxisValues) {
        self.point(self.length, out);
    }
}

/// The speed cap and the path parameter's dynamics of a curve over `n` axes (`axis` gives
/// each one's bounds) at up to `feed`: for each share of the jerk, the path parameter's jerk
/// first, then the speed the curvature leaves room for, then the path parameter's
/// acceleration at 90 % of that speed, and the speed with both; the largest share that keeps
/// [`CAP_KEPT`] of the smallest's speed.
fn caps(n: usize, axis: &dyn Fn(usize) -> Bounds, feed: f64) -> (f64, Dynamics) {
    let plan = |share: f64| {
        let jerk = (0..n)
            .map(|i| axis(i).tangential_jerk(share))
            .fold(f64::INFINITY, f64::min);
        let top = (0..n)
            .map(|i| axis(i).speed(jerk, 0.0))
            .fold(f64::INFINITY, f64::min);
        let speed = (CURVE_SPEED_SHARE * top).min(feed);
        let acceleration = (0..n)
            .map(|i| axis(i).tangential_acc(speed, jerk))
            .fold(f64::INFINITY, f64::min);
        let cap = (0..n)
            .map(|i| axis(i).speed(jerk, acceleration))
            .fold(f64::INFINITY, f64::min);
        (cap, Dynamics { acceleration, jerk })
    };
    let smallest = plan(TANGENTIAL_JERK_SHARES[2]);
    TANGENTIAL_JERK_SHARES[..2]
        .iter()
        .map(|&share| plan(share))
        .find(|(cap, _)| *cap >= CAP_KEPT * smallest.0)
        .unwrap_or(smallest)
}

/// Samples a curve's deviation is taken at (its points between them lie closer than the
/// tolerance's margin to the sampled ones: the curve's deviation changes slowly).
const DEVIATION_SAMPLES: usize = 32;

/// One axis on a curve: its bounds `g1`, `g2`, `g3` and its limits.
struct Bounds {
    g1: f64,
    g2: f64,
    g3: f64,
    limit: AxisLimits,
}

impl Bounds {
    /// From bounds `[g1, g2, g3]` found elsewhere.
    fn raw([g1, g2, g3]: [f64; 3], limit: AxisLimits) -> Self {
        Self { g1, g2, g3, limit }
    }

    fn new(u1: f64, u2: f64, length: f64, shape: &Shape, limit: AxisLimits) -> Self {
        let du = (u2 - u1).abs();
        Self {
            g1: u1.abs().max(u2.abs()),
            g2: shape.peak() * du / length,
            g3: shape.steepest() * du / (length * length),
            limit,
        }
    }

    /// The path parameter's jerk this axis allows.
    fn tangential_jerk(&self, share: f64) -> f64 {
        if self.g1 <= 1e-12 {
            return f64::INFINITY;
        }
        share * self.limit.jerk / self.g1
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
