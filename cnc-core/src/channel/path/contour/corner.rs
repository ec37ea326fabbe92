//! Rounding a corner between two straight blocks as they join the window: the curve, its
//! shape where it meets the curve before, and the pieces it shortens ([`super::piece`] has
//! the curve's geometry).

use super::plan::similar;
use super::profile::{change_distance, change_time, max_reach};
use super::shape::share_limits;
use super::{tag, Contour, Mode, Piece, Segment, MAX_TURN_DEG};
use crate::channel::path::AxisLimits;
use crate::setpoint::AxisValues;

/// Neighbour curves share their curvature where their turns' directions differ by at most
/// this (degrees).
const JUNCTION_MAX_TWIST_DEG: f64 = 30.0;
/// Share of an axis's jerk (over one cycle) the step in curvature direction where two curves
/// meet may take; the curves' own jerk keeps to the rest ([`super::piece`]).
pub(super) const JUNCTION_JERK_SHARE: f64 = 0.25;
/// A corner is rounded when passing it loses at most this share of the time stopping at it
/// loses (against running at the feed): the comparison is local (it cannot see how the path
/// runs through the blocks' other halves), so a corner that would gain very little is
/// stopped at.
const PASS_GAIN: f64 = 0.85;
/// A straight piece left over by less than this share of its block is taken by the curve.
const SNAP: f64 = 1e-4;
/// Where a straight block meets an arc's chords, the straight's leg of the corner curve is up
/// to this many times the chord's (the curvature then ramps linearly into the arc's).
const TRANSITION_LEG_RATIO: f64 = 2.0;

impl Contour {
    /// Rounds the corner into `segment` when it may be: shortens the last straight piece,
    /// adds the curve and the block's straight piece. `false` (nothing changed) when not.
    pub(super) fn round_corner(
        &mut self,
        segment: &Segment,
        u2: &AxisValues,
        length: f64,
        limit: &mut dyn FnMut(&mut Piece),
    ) -> bool {
        let (Some(tolerance), Some((end, u1))) = (segment.blend, self.last_end) else {
            return false;
        };
        let n = self.pieces.len();
        let under_way = !matches!(self.mode, Mode::Idle);
        let Some(last) = self.pieces.back().copied() else {
            return false;
        };
        // The run under way must not cover the piece to be shortened.
        // Never after a small arc's piece on its own (it ends at rest).
        let curved = last.is_curve() || last.is_plane();
        if (under_way && n <= self.run_pieces) || curved || tolerance <= 0.0 {
            return false;
        }
        let joined = end
            .iter()
            .zip(segment.start.iter())
            .all(|(a, b)| (a - b).abs() <= 1e-9);
        let cos = (0..3).map(|i| u1[i] * u2[i]).sum::<f64>().clamp(-1.0, 1.0);
        let turn = cos.acos();
        if !joined || turn > MAX_TURN_DEG.to_radians() {
            return false;
        }
        let sin_half = (0.5 * turn).sin();
        let by_tolerance = if sin_half > 1e-12 {
            3.0 * tolerance / sin_half
        } else {
            f64::INFINITY
        };
        let mut d = by_tolerance
            .min(0.5 * last.block_length)
            .min(last.length)
            .min(0.5 * length);
        // Blocks of a polyline differ in length by their rounding: a straight piece of a
        // rounding's length is no straight piece (the curves on both sides meet).
        let leftover = last.length - d;
        if leftover > 0.0
            && leftover <= SNAP * last.block_length
            && last.length <= by_tolerance
            && last.length <= 0.5 * length * (1.0 + SNAP)
        {
            d = last.length;
        }
        if d <= 1e-9 {
            return false;
        }
        let triangle = self.corner_curve(segment, (&u1, u2), [d, d], [0.0, 0.0], &last);
        if !worth_rounding(&last, &triangle, (segment, u2), length, &self.limits) {
            return false;
        }
        // The curve as it is before any sharing: the triangle, or a transition into an arc.
        let unshared = self
            .transition(segment, (&u1, u2), d, length, &last)
            .unwrap_or(triangle);
        let [d1, d2] = unshared.legs;
        let saved = last;
        let saved_before = (n >= 2).then(|| self.pieces[n - 2]);
        let committed = self.v_end;
        let corner = segment.start;
        let back = self.pieces.back_mut().expect("checked");
        back.length -= d1;
        back.rest_after = false;
        let (mut curve, junction_cap) = self
            .share_junction((segment, &u1, u2), &unshared, &saved, limit)
            .unwrap_or((unshared, f64::INFINITY));
        curve.junction_cap = junction_cap;
        curve.hard_cap = curve.hard_cap.min(junction_cap);
        let mut origin = corner;
        for i in 0..origin.len() {
            origin[i] += d2 * u2[i];
        }
        let mut straight = Piece::straight(origin, *u2, length - d2, length, &self.limits);
        tag(&mut straight, segment);
        limit(&mut curve);
        limit(&mut straight);
        self.pieces.push_back(curve);
        self.pieces.push_back(straight);
        for k in n.saturating_sub(3)..n + 2 {
            self.rechain(k);
        }
        self.sweep_back();
        // A short window's run may cover it nearly to its end: the new corner's curves can
        // lower the bounds there below what the run committed to.
        if !self.run_still_fits(under_way, committed) {
            self.pieces.pop_back();
            self.pieces.pop_back();
            *self.pieces.back_mut().expect("kept") = saved;
            if let Some(before) = saved_before {
                self.pieces[n - 2] = before;
            }
            self.sweep_back();
            return false;
        }
        true
    }

    /// The curve before the corner being rounded shares its curvature where the two meet,
    /// when the block between them is all curves, both turn the same way (within
    /// [`JUNCTION_MAX_TWIST_DEG`]), the curve before is not under way and both stay within
    /// their tolerances: its end and the new curve's start take the smaller of the two mean
    /// curvatures, each times what its shape allows at that end (`shape::share_limits`: twice
    /// a transition's mean at its chord's end), so a dense polyline's curvature does not fall
    /// to 0 and rise again at every
    /// block (which caps the speed through its rate of change). The curvature's direction
    /// still steps by the angle between the turns: both curves' speed is capped where that
    /// step, over a cycle, would take more than [`JUNCTION_JERK_SHARE`] of an axis's jerk.
    /// `unshared` is the new curve as it is without sharing, `last` the block before's
    /// straight piece. The new curve with its shared start and that cap; `None` when they do
    /// not share.
    fn share_junction(
        &mut self,
        (segment, u1, u2): (&Segment, &AxisValues, &AxisValues),
        unshared: &Piece,
        last: &Piece,
        limit: &mut dyn FnMut(&mut Piece),
    ) -> Option<(Piece, f64)> {
        const NONE: Option<(Piece, f64)> = None;
        let legs = unshared.legs;
        let n = self.pieces.len();
        let under_way = !matches!(self.mode, Mode::Idle);
        let a_corner = n >= 2 && self.pieces[n - 2].is_curve() && !self.pieces[n - 2].is_plane();
        if !a_corner || self.pieces[n - 1].length > 1e-9 {
            return NONE;
        }
        if under_way && n - 2 < self.run_pieces {
            return NONE;
        }
        let a = self.pieces[n - 2];
        let mut turn = *u2;
        for i in 0..turn.len() {
            turn[i] -= u1[i];
        }
        let (na, nb) = (norm(&a.turn), norm(&turn));
        if na <= 1e-12 || nb <= 1e-12 {
            return NONE;
        }
        let cos = (0..turn.len()).map(|i| a.turn[i] * turn[i]).sum::<f64>() / (na * nb);
        if cos < JUNCTION_MAX_TWIST_DEG.to_radians().cos() {
            return NONE;
        }
        let (ka, kb) = (na / a.length, nb / unshared.length);
        let mu = |p: &Piece| p.legs[1] / p.length;
        let k = (share_limits(mu(&a))[1] * ka).min(share_limits(mu(unshared))[0] * kb);
        if k <= 0.0 {
            return NONE;
        }
        let (ca, cb) = (k / ka, k / kb);
        let mut cap = f64::INFINITY;
        for i in 0..turn.len() {
            let step = (ca * a.turn[i] / a.length - cb * turn[i] / unshared.length).abs();
            let jerk = self.limits.get(i).map_or(f64::INFINITY, |l| l.jerk);
            if step > 1e-15 {
                cap = cap.min((JUNCTION_JERK_SHARE * jerk * self.cycle_s / step).sqrt());
            }
        }
        let (corner, ua1, ua2) = a.corner();
        let mut new_a = Piece::curve(
            &corner,
            (&ua1, &ua2),
            a.legs,
            [a.shape.ends()[0], ca],
            (&self.limits, a.feed),
        );
        new_a.feed = a.feed;
        new_a.rapid = a.rapid;
        new_a.line = a.line;
        new_a.tolerance = a.tolerance;
        new_a.junction_cap = a.junction_cap.min(cap);
        new_a.hard_cap = new_a.hard_cap.min(new_a.junction_cap);
        let shared = self.corner_curve(segment, (u1, u2), legs, [cb, 0.0], last);
        if new_a.deviation() > a.tolerance || shared.deviation() > unshared.tolerance {
            return NONE;
        }
        // Not where the step in the curvature's direction would cap the curves below what
        // they have apart (turns far apart: a coarse polyline, not a dense curve's chords).
        if cap < a.hard_cap.min(unshared.hard_cap) {
            return NONE;
        }
        limit(&mut new_a);
        self.pieces[n - 2] = new_a;
        Some((shared, cap))
    }

    /// Where a straight block meets an arc's chords (or they meet one), the corner curve at
    /// `segment`'s start (of `length`) after `last` before any sharing, its straight's leg up
    /// to [`TRANSITION_LEG_RATIO`] times the chord's `d` (within its room and the tolerance),
    /// so the curvature can ramp into the arc's once the chord's next corner shares it. `None`
    /// elsewhere, or where the longer leg finds no room or leaves the tolerance (the legs are
    /// then `d` both).
    fn transition(
        &self,
        segment: &Segment,
        units: (&AxisValues, &AxisValues),
        d: f64,
        length: f64,
        last: &Piece,
    ) -> Option<Piece> {
        let long = TRANSITION_LEG_RATIO * d;
        let legs = match (last.on_arc, segment.on_arc) {
            (false, true) => [long.min(0.5 * last.block_length).min(last.length), d],
            (true, false) => [d, long.min(0.5 * length)],
            _ => return None,
        };
        if legs[0] <= d && legs[1] <= d {
            return None;
        }
        let curve = self.corner_curve(segment, units, legs, [0.0, 0.0], last);
        (curve.deviation() <= curve.tolerance).then_some(curve)
    }

    /// The curve rounding the corner at `segment`'s start from `u1` to `u2` with legs `legs`
    /// and end curvatures `shape`, after `last` (the block before's straight piece): the
    /// lower of the two blocks' feeds, the line of the block before, rapid when both are,
    /// `segment`'s tolerance.
    fn corner_curve(
        &self,
        segment: &Segment,
        (u1, u2): (&AxisValues, &AxisValues),
        legs: [f64; 2],
        shape: [f64; 2],
        last: &Piece,
    ) -> Piece {
        let feed = segment.feed.min(last.feed);
        let mut curve = Piece::curve(&segment.start, (u1, u2), legs, shape, (&self.limits, feed));
        tag(&mut curve, segment);
        curve.feed = feed;
        curve.line = last.line;
        curve.rapid = last.rapid && segment.rapid;
        curve.tolerance = segment.blend.unwrap_or(0.0);
        curve
    }
}

impl Contour {
    /// After pieces joined the window: whether the run under way still reaches its
    /// committed end velocity's bound; else, when it cruises, it is planned again from where
    /// it stands (a plan it adopts ends within its bound).
    pub(super) fn run_still_fits(&mut self, under_way: bool, committed: f64) -> bool {
        let run_end = self.run_pieces.max(1) - 1;
        !under_way || self.pieces[run_end].bound_hard >= committed - 1e-9 || self.replan_now()
    }

    /// Whether piece `k` may be planned in one unit with the piece before: when they are
    /// alike; a straight piece the corners took all of, when the pieces on both sides are.
    pub(super) fn rechain(&mut self, k: usize) {
        let p = &self.pieces;
        let chain = match k {
            0 => false,
            _ if p[k].length <= 1e-9 && !p[k].is_curve() => {
                k + 1 < p.len() && similar(&p[k - 1], &p[k + 1])
            }
            _ => similar(&p[k - 1], &p[k]),
        };
        self.pieces[k].chain = chain;
    }
}

/// Whether passing the corner on a curve of half-size `d` is quicker than stopping at it: a
/// sharp corner within a small tolerance is passed so slowly that stopping there and
/// starting again at the full acceleration takes less time. Compared over the half of each
/// block next to the corner, at 100 % feed, from and to rest at the blocks' middles, with the
/// curve's shape between straight pieces (a dense polyline's curves share their curvature
/// later and only get faster).
fn worth_rounding(
    last: &Piece,
    curve: &Piece,
    (segment, u2): (&Segment, &AxisValues),
    length: f64,
    limits: &[AxisLimits],
) -> bool {
    let [d1, d2] = curve.legs;
    let mut next = Piece::straight(segment.start, *u2, length, length, limits);
    tag(&mut next, segment);
    let (h1, h2) = (last.length.min(0.5 * last.block_length), 0.5 * length);
    // No faster at the blocks' middles than their other halves could brake from (the
    // stop's legs reach no more there either).
    let corner = curve
        .soft_cap(1.0, 1.0)
        .min(max_reach(0.0, h1, last.soft_cap(1.0, 1.0), last.dynamics))
        .min(max_reach(0.0, h2, next.soft_cap(1.0, 1.0), next.dynamics));
    if corner <= 1e-9 {
        return false;
    }
    let stop = leg_time(h1, 0.0, last) + leg_time(h2, 0.0, &next);
    let pass =
        leg_time(h1 - d1, corner, last) + curve.length / corner + leg_time(h2 - d2, corner, &next);
    // What each loses against running the halves at their caps.
    let ideal = h1 / last.soft_cap(1.0, 1.0) + h2 / next.soft_cap(1.0, 1.0);
    pass - ideal < PASS_GAIN * (stop - ideal)
}

/// The time along `h` of piece `p` from `v0`, as fast as its limits allow (the same back to
/// `v0`: a velocity change covers the same distance both ways).
fn leg_time(h: f64, v0: f64, p: &Piece) -> f64 {
    if h <= 1e-12 {
        return 0.0;
    }
    let cap = p.soft_cap(1.0, 1.0);
    let v0 = v0.min(cap);
    let peak = max_reach(v0, h, cap, p.dynamics);
    if peak <= 1e-12 {
        return f64::INFINITY;
    }
    let ramp = change_distance(v0, peak, p.dynamics);
    change_time(peak - v0, p.dynamics) + (h - ramp).max(0.0) / peak
}

fn norm(v: &AxisValues) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}
