//! Small arcs between tangent straight blocks (a pocket's fillets, a slot's ends): where an
//! arc's chords would run it slower than it runs on its own ([`super::arc`]), an arc that a
//! straight block meets tangentially is held back until the next block shows how the path
//! leaves it. When that is a straight block leaving it tangentially, the path runs through the
//! arc without stopping: a transition from the straight into the circle, the circle, and a
//! transition out of it ([`super::planar`]).
//!
//! A transition is a clothoid: its curvature ramps linearly from 0 to the circle's over a
//! length `L`, so it starts about `L/2` before the point where the straight meets the arc and
//! ends about `L/2` after it; the circle between the two transitions keeps the arc's centre
//! and has its radius shifted inward by about `L²/(24 r')`, the shift such a ramp needs (both
//! found from the clothoid's end point, integrated numerically). `L` is the longest that keeps
//! that shift within [`SHIFT_SHARE`] of the tolerance, the arc's sweep and both straights'
//! room, and no longer than the arc's speed needs (the curvature's rate of change at the
//! circle's speed within half the axes' jerk). The path runs a transition as [`PARTS`]
//! quintics between points of the clothoid, each meeting the clothoid's point, direction and
//! curvature vector at both ends (the first the straight's, the last the circle's), so no
//! axis's velocity or acceleration steps anywhere on the way and the third derivative stays
//! near the clothoid's constant one. Every point of the transitions is checked against the
//! programmed lines and circle; a shorter `L` is tried when one leaves the tolerance.
//!
//! Otherwise (the block after is no tangent straight, the program ends there, the path
//! already runs on the straight's end, or the transitions would run it much slower than it
//! runs on its own) the arc is one piece on its exact circle, the path at rest before and
//! after it: as the arc on its own, inside the contour.

use super::super::circle::Circle;
use super::arc::{own_speed, ArcBlock};
use super::planar::{clothoid, Jet, PlaneCurve};
use super::{Contour, Mode, Piece, PushError, Segment};
use crate::setpoint::AxisValues;

/// Share of the tolerance the circle's shift (and so every point of the transitions) may
/// take; the transitions are checked against [`CHECK_SHARE`] of it.
const SHIFT_SHARE: f64 = 0.8;
/// Share of the tolerance every sampled point of a transition must keep (what lies between
/// the samples moves by far less than the rest).
const CHECK_SHARE: f64 = 0.98;
/// The largest angle (rad) between a straight block and the arc's tangent where they meet for
/// them to count as tangent (a program's rounded coordinates; the transitions take it up).
const TANGENT_MAX: f64 = 0.01;
/// Quintics a transition is made of, each between points of a clothoid.
const PARTS: usize = 3;
/// A transition's largest third derivative against a clothoid's of the same length (what
/// its length is chosen by).
const RAMP_PEAK: f64 = 1.2;
/// Share of the axes' jerk the transitions' change of curvature is chosen to take at the
/// circle's speed.
const RAMP_JERK_SHARE: f64 = 0.5;
/// The transitions run the arc when their slowest piece keeps at least this share of the
/// speed the arc runs at on its own (stopping before and after it).
const CHAIN_SPEED_KEPT: f64 = 0.3;
/// Shorter transitions tried (each 0.7 of the last) when one leaves the tolerance.
const TRIES: usize = 6;
/// Pieces the window keeps free while an arc is held: its transitions and circle, and the
/// straight after (with a corner curve).
pub(super) const HELD_ROOM: usize = 2 * PARTS + 3;
/// The smallest window an arc is held in (with fewer pieces the room for it would come only
/// once the path has run to the straight's end, where the transitions cannot start).
const HOLD_MIN_CAPACITY: usize = 2 * HELD_ROOM;

/// A small arc held back until the block after it comes.
#[derive(Debug, Clone, Copy)]
pub(super) struct HeldArc {
    block: ArcBlock,
    circle: Circle,
    /// Its length in the plane.
    length: f64,
}

impl HeldArc {
    pub(super) fn line(&self) -> u32 {
        self.block.line
    }
}

/// Pieces of a chain: the transitions' and the circle's.
const CHAIN_PIECES: usize = 2 * PARTS + 1;

/// The pieces that run a held arc with transitions, and how much of the straights they take.
struct Chain {
    /// Taken from the end of the straight before and from the start of the one after.
    x0: f64,
    ramp_in: [PlaneCurve; PARTS],
    body: Option<PlaneCurve>,
    ramp_out: [PlaneCurve; PARTS],
    /// Where the straight after now starts, and its direction.
    exit: AxisValues,
    exit_dir: AxisValues,
    /// The window's pieces of the curves, once made.
    built: [Option<Piece>; CHAIN_PIECES],
}

impl Chain {
    /// Its pieces in the path's order.
    fn pieces(&self) -> impl Iterator<Item = PlaneCurve> + '_ {
        self.ramp_in
            .iter()
            .copied()
            .chain(self.body)
            .chain(self.ramp_out.iter().copied())
    }
}

/// A 2-vector rotated by `angle`.
fn rot(v: [f64; 2], angle: f64) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn axpy(a: [f64; 2], k: f64, b: [f64; 2]) -> [f64; 2] {
    [a[0] + k * b[0], a[1] + k * b[1]]
}

impl Contour {
    /// An arc whose chords would be slow (`circle`, `length` in its plane): held back when
    /// the block before is a straight in its plane meeting it tangentially (the block before
    /// joins the window now). [`PushError::NotStraight`] when not: it runs on its own.
    pub(super) fn hold_small_arc(
        &mut self,
        block: &ArcBlock,
        circle: Circle,
        length: f64,
    ) -> Result<(), PushError> {
        let planar = (0..block.start.len())
            .filter(|i| !circle.axes.contains(i))
            .all(|i| block.end[i] == block.start[i]);
        let busy = self.held.is_some() || self.arc.is_some();
        if !planar || block.blend.is_none() || busy || self.capacity < HOLD_MIN_CAPACITY {
            return Err(PushError::NotStraight);
        }
        if !self.flush() {
            return Err(PushError::Full);
        }
        let Some((end, dir)) = self.last_end else {
            return Err(PushError::NotStraight);
        };
        let joined = end
            .iter()
            .zip(block.start.iter())
            .all(|(a, b)| (a - b).abs() <= 1e-9);
        let straight = self
            .pieces
            .back()
            .is_some_and(|p| !p.is_curve() && !p.is_plane());
        let start = tangent(&circle, 0.0);
        if !joined || !straight || !meets(&dir, circle.axes, start) {
            return Err(PushError::NotStraight);
        }
        self.held = Some(HeldArc {
            block: *block,
            circle,
            length,
        });
        Ok(())
    }

    /// The held arc joins the window: with transitions when `next` leaves it tangentially
    /// (then `Some`: where `next` now starts), else as one piece between rests. `Full` (and
    /// the arc still held) when the window has no room for it.
    pub(super) fn release_arc(
        &mut self,
        next: Option<&Segment>,
    ) -> Result<Option<AxisValues>, PushError> {
        let Some(held) = self.held else {
            return Ok(None);
        };
        if self.pieces.len() + HELD_ROOM > self.capacity {
            return Err(PushError::Full);
        }
        self.held = None;
        if let Some(chain) = next.and_then(|s| self.chain(&held, s)) {
            if self.push_chain(&chain) {
                self.smooth_from = Some(chain.exit);
                return Ok(Some(chain.exit));
            }
        }
        self.push_alone(&held);
        Ok(None)
    }

    /// The arc on its exact circle, the path at rest before it (and, as the block after
    /// cannot be rounded with it, after it).
    fn push_alone(&mut self, held: &HeldArc) {
        if let Some(last) = self.pieces.back_mut() {
            last.rest_after = true;
        }
        let curve = PlaneCurve::circle(held.circle, held.length);
        let piece = self.plane_piece(held, curve);
        self.pieces.push_back(piece);
        self.blocks += 1;
        let dir = direction_of(
            &held.block.start,
            held.circle.axes,
            tangent(&held.circle, 1.0),
        );
        self.last_end = Some((held.block.end, dir));
        self.sweep_back();
        self.replan = true;
    }

    /// Shortens the straight before by the transition's share and adds the transitions and
    /// the circle; `false` (nothing changed) when the run under way could no longer keep its
    /// committed end velocity.
    fn push_chain(&mut self, chain: &Chain) -> bool {
        let n = self.pieces.len();
        let Some(saved) = self.pieces.back().copied() else {
            return false;
        };
        let committed = self.v_end;
        let under_way = !matches!(self.mode, Mode::Idle);
        let back = self.pieces.back_mut().expect("checked");
        back.length -= chain.x0;
        back.rest_after = false;
        for piece in chain.built.iter().flatten() {
            self.pieces.push_back(*piece);
        }
        // The circle is the block's own piece (popping it counts the block out); without
        // one (its transitions meet) the block is not counted.
        let counted = usize::from(chain.body.is_some());
        self.blocks += counted;
        for k in n.saturating_sub(1)..self.pieces.len() {
            self.rechain(k);
        }
        self.sweep_back();
        if !self.run_still_fits(under_way, committed) {
            self.pieces.truncate(n);
            *self.pieces.back_mut().expect("kept") = saved;
            self.blocks -= counted;
            self.sweep_back();
            return false;
        }
        // The window now ends where the straight after starts (it may be held back).
        self.last_end = Some((chain.exit, chain.exit_dir));
        self.replan = true;
        true
    }

    /// A piece of the held arc (its other axes at the block's start).
    fn plane_piece(&self, held: &HeldArc, curve: PlaneCurve) -> Piece {
        let b = &held.block;
        // The path moves at |p'| times the parameter's speed: the feed holds for the path.
        let feed = b.feed / curve.stretch().max(1.0);
        let mut p = Piece::planar(b.start, curve, (&self.limits, feed));
        p.feed = feed;
        p.line = b.line;
        p.tolerance = b.tolerance;
        p
    }

    /// The transitions and circle for the held arc when `next` is a straight leaving it
    /// tangentially in its plane with room for a transition, the straight before has room
    /// too and is not under way, and they keep the tolerance and most of the arc's speed.
    fn chain(&self, held: &HeldArc, next: &Segment) -> Option<Chain> {
        let (b, c) = (&held.block, &held.circle);
        let [a0, a1] = c.axes;
        // The arc's tolerance and its corner's before (the block after keeps half of it for
        // the corners of chords, which these are not); the block after must not stop there.
        next.blend?;
        let tol = b.tolerance.min(b.blend?);
        let joined = (0..b.end.len()).all(|i| (next.start[i] - b.end[i]).abs() <= 1e-9);
        let len2 = (0..3)
            .map(|i| (next.end[i] - next.start[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        if tol <= 0.0 || next.rapid || !joined || len2 <= 1e-9 {
            return None;
        }
        let mut dir2 = next.end;
        dir2.iter_mut()
            .enumerate()
            .for_each(|(i, d)| *d = (*d - next.start[i]) / len2);
        if !meets(&dir2, c.axes, tangent(c, 1.0)) {
            return None;
        }
        let n = self.pieces.len();
        let back = self.pieces.back()?;
        let under_way = !matches!(self.mode, Mode::Idle);
        if under_way && n <= self.run_pieces {
            return None;
        }
        let r = c.r0;
        let (speed, jerk) = own_speed(&self.limits, c, b.feed);
        let by_speed = if jerk.is_finite() {
            RAMP_PEAK * speed.powi(3) / (r * RAMP_JERK_SHARE * jerk)
        } else {
            f64::INFINITY
        };
        let mut l = (24.0 * r * SHIFT_SHARE * tol)
            .sqrt()
            .min(0.9 * c.sweep.abs() * r)
            .min(2.0 * back.length)
            .min(len2)
            .min(by_speed);
        let u1 = [back.dir[a0], back.dir[a1]];
        let u2 = [dir2[a0], dir2[a1]];
        for _ in 0..TRIES {
            let chain = geometry(held, (u1, u2), l, back);
            if let Some(mut chain) = chain.filter(|ch| within(held, ch, (u1, u2), tol)) {
                let mut built = [None; CHAIN_PIECES];
                let mut slowest = f64::INFINITY;
                for (slot, curve) in built.iter_mut().zip(chain.pieces()) {
                    let piece = self.plane_piece(held, curve);
                    slowest = slowest.min(piece.hard_cap);
                    *slot = Some(piece);
                }
                chain.built = built;
                return (slowest >= CHAIN_SPEED_KEPT * speed).then_some(chain);
            }
            l *= 0.7;
        }
        None
    }
}

/// The transitions of length `l` and the circle between them for the held arc between
/// straights of directions `u1` (the one before, `back`'s) and `u2` (plane axes); `None`
/// when they find no room. The transition in is a clothoid from the straight whose circle at
/// its end has the arc's centre: its radius `r'` and where it starts (`x0` before the arc)
/// follow from the clothoid's end point; the transition out is its mirror image, found from
/// the straight after backwards.
fn geometry(held: &HeldArc, (u1, u2): ([f64; 2], [f64; 2]), l: f64, back: &Piece) -> Option<Chain> {
    let (b, c) = (&held.block, &held.circle);
    let [a0, a1] = c.axes;
    let (r, sign, sweep) = (c.r0, c.sweep.signum(), c.sweep.abs());
    if l <= 1e-6 || r.is_nan() || r <= 0.0 {
        return None;
    }
    // The centre of the circle at the clothoid's end lies `r` from the straight.
    let end = |rp: f64| clothoid::<2>(([0.0, 0.0], [1.0, 0.0]), 1.0, 1.0 / rp, l)[1];
    // From the series' estimate (the shift l²/24r), a few steps (each takes the error down
    // by about (l/r)²).
    let mut rp = r - l * l / (24.0 * r);
    for _ in 0..3 {
        let e = end(rp);
        let psi = l / (2.0 * rp);
        rp -= e.point[1] + rp * psi.cos() - r;
        if rp.is_nan() || rp <= 0.0 {
            return None;
        }
    }
    let psi = l / (2.0 * rp);
    let x0 = end(rp).point[0] - rp * psi.sin();
    if 2.0 * psi > sweep || x0 > back.length || x0 <= 0.0 {
        return None;
    }
    let (t1, t2, o) = ([b.start[a0], b.start[a1]], [b.end[a0], b.end[a1]], c.center);
    let unit = |p: [f64; 2]| {
        let d = sub(p, o);
        let n = d[0].hypot(d[1]);
        [d[0] / n, d[1] / n]
    };
    let on_circle = |e: [f64; 2]| Jet {
        point: axpy(o, rp, e),
        tangent: [-sign * e[1], sign * e[0]],
        curvature: [-e[0] / rp, -e[1] / rp],
    };
    let e_in = rot(unit(t1), sign * psi);
    let e_out = rot(unit(t2), -sign * psi);
    // Where the straight before now ends (its own point, so the two meet exactly).
    let mut begin = back.origin;
    for (i, v) in begin.iter_mut().enumerate() {
        *v += back.dir[i] * (back.length - x0);
    }
    // The clothoid as the straight has it (from its point and direction) and as the circle
    // has it (from the arc's tangent where it starts, ending on the circle): where the two
    // differ (a straight not quite tangent, rounded coordinates) the transition blends from
    // the one to the other over its parts, so no part takes all of the difference.
    let kappa = 1.0 / rp;
    let tangent_at = |e: [f64; 2]| [-sign * e[1], sign * e[0]];
    let (ua1, ua2) = (tangent_at(unit(t1)), tangent_at(unit(t2)));
    let mut into = blend(
        &clothoid(([begin[a0], begin[a1]], u1), sign, kappa, l),
        &clothoid((axpy(t1, -x0, ua1), ua1), sign, kappa, l),
    );
    into[PARTS] = on_circle(e_in);
    // Out: from the straight after backwards (turning the other way), then reversed.
    let exit = axpy(t2, x0, u2);
    let backwards = |p: [f64; 2], u: [f64; 2]| {
        let mut jets = clothoid::<{ PARTS + 1 }>((p, [-u[0], -u[1]]), -sign, kappa, l);
        jets.reverse();
        for j in jets.iter_mut() {
            j.tangent = [-j.tangent[0], -j.tangent[1]];
        }
        jets
    };
    let mut out = blend(&backwards(axpy(t2, x0, ua2), ua2), &backwards(exit, u2));
    out[0] = on_circle(e_out);
    let part = l / PARTS as f64;
    let quintics = |jets: &[Jet; PARTS + 1]| {
        core::array::from_fn(|k| PlaneCurve::quintic(c.axes, &jets[k], &jets[k + 1], part))
    };
    let body_sweep = sweep - 2.0 * psi;
    let body = (body_sweep * rp > 1e-9).then(|| {
        let circle = Circle {
            axes: c.axes,
            center: o,
            angle0: e_in[1].atan2(e_in[0]),
            sweep: sign * body_sweep,
            r0: rp,
            r1: rp,
        };
        PlaneCurve::circle(circle, body_sweep * rp)
    });
    let mut exit_point = b.end;
    exit_point[a0] = exit[0];
    exit_point[a1] = exit[1];
    Some(Chain {
        x0,
        ramp_in: quintics(&into),
        body,
        ramp_out: quintics(&out),
        exit: exit_point,
        exit_dir: direction_of(&b.start, c.axes, u2),
        built: [None; CHAIN_PIECES],
    })
}

/// From `a`'s jets (at the first) to `b`'s (at the last), linearly over the parts.
fn blend(a: &[Jet; PARTS + 1], b: &[Jet; PARTS + 1]) -> [Jet; PARTS + 1] {
    core::array::from_fn(|k| {
        let w = k as f64 / PARTS as f64;
        let mix = |x: [f64; 2], y: [f64; 2]| [x[0] + w * (y[0] - x[0]), x[1] + w * (y[1] - x[1])];
        let t = mix(a[k].tangent, b[k].tangent);
        let n = t[0].hypot(t[1]);
        Jet {
            point: mix(a[k].point, b[k].point),
            tangent: [t[0] / n, t[1] / n],
            curvature: mix(a[k].curvature, b[k].curvature),
        }
    })
}

/// Whether every point of the transitions (sampled) lies within `tol` of the programmed
/// straights and circle, and the circle's shift does.
fn within(held: &HeldArc, chain: &Chain, (u1, u2): ([f64; 2], [f64; 2]), tol: f64) -> bool {
    let (b, c) = (&held.block, &held.circle);
    let [a0, a1] = c.axes;
    let t1 = [b.start[a0], b.start[a1]];
    let t2 = [b.end[a0], b.end[a1]];
    let distance = |p: [f64; 2]| {
        let along1 = dot(sub(p, t1), u1);
        let line1 = if along1 <= 0.0 {
            let d = axpy(sub(p, t1), -along1, u1);
            d[0].hypot(d[1])
        } else {
            f64::INFINITY
        };
        let along2 = dot(sub(p, t2), u2);
        let line2 = if along2 >= 0.0 {
            let d = axpy(sub(p, t2), -along2, u2);
            d[0].hypot(d[1])
        } else {
            f64::INFINITY
        };
        let d = sub(p, c.center);
        let along =
            ((d[1].atan2(d[0]) - c.angle0) * c.sweep.signum()).rem_euclid(core::f64::consts::TAU);
        let arc = if along <= c.sweep.abs() + 1e-12 {
            // A spiral's radius runs linearly over its sweep.
            let r = c.r0 + (c.r1 - c.r0) * (along / c.sweep.abs()).min(1.0);
            (d[0].hypot(d[1]) - r).abs()
        } else {
            f64::INFINITY
        };
        let ends = sub(p, t1)[0]
            .hypot(sub(p, t1)[1])
            .min(sub(p, t2)[0].hypot(sub(p, t2)[1]));
        line1.min(line2).min(arc).min(ends)
    };
    let shift = chain.body.map_or(0.0, |body| match body.shape {
        super::planar::PlaneShape::Circle(k) => (c.r0 - k.r0).abs().max((c.r1 - k.r1).abs()),
        super::planar::PlaneShape::Quintic(_) => f64::INFINITY,
    });
    // The deviation changes slowly along a part (a third of a transition): between samples
    // it moves by far less than the share of the tolerance the check leaves.
    const SAMPLES: usize = 16;
    let ramps_within = chain.ramp_in.iter().chain(&chain.ramp_out).all(|q| {
        (0..=SAMPLES).all(|k| {
            distance(q.at(q.length * k as f64 / SAMPLES as f64).point) <= CHECK_SHARE * tol
        })
    });
    shift <= tol && ramps_within
}

/// The circle's unit tangent at `s` of the way (plane axes).
fn tangent(c: &Circle, s: f64) -> [f64; 2] {
    let (d1, _) = c.rates(s, 1.0, 0.0);
    let n = d1[0].hypot(d1[1]);
    [d1[0] / n, d1[1] / n]
}

/// Whether a straight of direction `dir` moves only in the plane of `axes` and along
/// `tangent` there (within [`TANGENT_MAX`]).
fn meets(dir: &AxisValues, axes: [usize; 2], tangent: [f64; 2]) -> bool {
    let in_plane = (0..dir.len())
        .filter(|i| !axes.contains(i))
        .all(|i| dir[i] == 0.0);
    let u = [dir[axes[0]], dir[axes[1]]];
    let cos = dot(u, tangent) / u[0].hypot(u[1]).max(1e-300);
    in_plane && cos >= TANGENT_MAX.cos()
}

/// A direction in the channel's axes from one in the plane of `axes`.
fn direction_of(like: &AxisValues, axes: [usize; 2], u: [f64; 2]) -> AxisValues {
    let mut d = AxisValues::zeros(like.len());
    d[axes[0]] = u[0];
    d[axes[1]] = u[1];
    d
}
