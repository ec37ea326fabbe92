//! Arcs and helices in a contour, as their chords: an arc block joins the window as chords
//! whose points lie on the arc and whose sagitta is at most half of the corner tolerance;
//! their corners are rounded within the other half like any polyline's, so the neighbouring
//! curves share the arc's curvature ([`super::corner`]) and the path runs round the arc at
//! the speed its radius allows, its curvature ramping from 0 where a line meets it (no step in
//! any axis's acceleration at a tangent transition). A corner between a line and an arc is the
//! corner with the arc's first chord, rounded within the tolerance as between two lines.
//!
//! The chords join the window as room frees: while an arc's chords are still coming, no
//! block joins after it. Not under a transformation (the joints' limits are taken per block).

use super::super::circle::Circle;
use super::corner::JUNCTION_JERK_SHARE;
use super::{Contour, PushError, Segment};
use crate::channel::path::AxisLimits;
use crate::nc::arc::ArcMove;
use crate::setpoint::AxisValues;

/// An arc joins as chords when they run it at least at this share of its own speed.
const CHORD_SPEED_KEPT: f64 = 0.9;
/// The shortest chord (mm): a smaller circle runs on its own.
const MIN_CHORD: f64 = 1e-6;
/// Most chords an arc may take (a longer one runs on its own at exact stop).
pub const MAX_ARC_CHORDS: u32 = 4096;
/// The largest angle a chord spans (degrees): neighbouring chords' corner curves share their
/// curvature up to a twist of 30 degrees.
const MAX_CHORD_DEG: f64 = 15.0;

/// An arc block handed to the contour.
#[derive(Debug, Clone, Copy)]
pub struct ArcBlock {
    /// Start and end (channel axes).
    pub start: AxisValues,
    /// See `start`.
    pub end: AxisValues,
    /// The decoded arc.
    pub arc: ArcMove,
    /// Feed (path units/s).
    pub feed: f64,
    /// Source line.
    pub line: u32,
    /// The corner with the block before may be rounded by at most this (mm); `None`: exact
    /// stop there.
    pub blend: Option<f64>,
    /// The arc's own tolerance: its chords and their corners keep within it (mm).
    pub tolerance: f64,
}

/// An arc whose chords are still joining the window.
#[derive(Debug, Clone, Copy)]
pub(super) struct ArcChords {
    block: ArcBlock,
    circle: Circle,
    /// The other axes' travel (the plane's two are zero).
    delta: AxisValues,
    chords: u32,
    next: u32,
    /// Where the last chord pushed ends.
    at: AxisValues,
    /// A chord did not join (never seen: chords are long enough when the arc joins); the
    /// contour fails at its next tick, and no block joins after the arc.
    failed: bool,
}

impl Contour {
    /// Adds an arc block as its chords (as many as fit now, the rest as room frees). Where
    /// chords would run it slower than it runs on its own, or it would take more than
    /// [`MAX_ARC_CHORDS`] of them, it is a small arc ([`super::fillet`]): held back when a
    /// straight meets it tangentially. [`PushError::NotStraight`] when it cannot join: no
    /// finite circle, no tolerance, or a small arc not held.
    pub fn push_arc(&mut self, block: &ArcBlock) -> Result<(), PushError> {
        if !self.has_room() {
            return Err(PushError::Full);
        }
        // A small arc held back ends before this one (no transition into an arc).
        self.release_arc(None)?;
        let (circle, length) =
            Circle::of(&block.start, &block.end, &block.arc).ok_or(PushError::NotStraight)?;
        let radius = circle.r0.max(circle.r1);
        if block.tolerance <= 0.0 || length <= 1e-9 || !radius.is_finite() || radius <= 1e-9 {
            return Err(PushError::NotStraight);
        }
        // Sagitta r (1 - cos(φ/2)) within half the tolerance.
        let half = 0.5 * block.tolerance;
        let by_sagitta = if half >= radius {
            f64::INFINITY
        } else {
            2.0 * (1.0 - half / radius).acos()
        };
        let step = by_sagitta.min(MAX_CHORD_DEG.to_radians());
        let chords = (circle.sweep.abs() / step).ceil().max(1.0);
        let step = circle.sweep.abs() / chords;
        let chord = 2.0 * circle.r0.min(circle.r1) * (0.5 * step).sin();
        let fine = chords.is_finite() && chords <= f64::from(MAX_ARC_CHORDS) && chord > MIN_CHORD;
        if !fine || !self.chords_keep_speed(&circle, step, block.feed) {
            // Between tangent straights it may still run with transitions.
            return self.hold_small_arc(block, circle, length);
        }
        let mut delta = block.end;
        for (i, d) in delta.iter_mut().enumerate() {
            *d -= block.start[i];
        }
        for i in circle.axes {
            delta[i] = 0.0;
        }
        self.reopen_if_idle();
        self.arc = Some(ArcChords {
            block: *block,
            circle,
            delta,
            chords: chords as u32,
            next: 1,
            at: block.start,
            failed: false,
        });
        self.feed_arc();
        Ok(())
    }

    /// Pushes the arc's next chords while the window has room; the arc is done after its
    /// last.
    pub(super) fn feed_arc(&mut self) {
        while let Some(arc) = self.arc {
            if arc.failed || !(self.blocks < self.lookahead && self.has_room_for(2)) {
                return;
            }
            let segment = arc.chord(arc.next);
            if self.push_block(&segment, &mut |_| {}).is_err() {
                self.arc = Some(ArcChords {
                    failed: true,
                    ..arc
                });
                return;
            }
            let done = arc.next >= arc.chords;
            self.arc = (!done).then_some(ArcChords {
                next: arc.next + 1,
                at: segment.end,
                ..arc
            });
        }
    }
}

impl Contour {
    /// Whether the circle's chords (each turning by `step`) run it at least nearly as fast
    /// as the arc runs on its own: where two chords' curves meet, the curvature's direction
    /// steps by `step`, an acceleration step of `v² step / r` that over a cycle may take
    /// [`JUNCTION_JERK_SHARE`] of the plane axes' jerk; on its own the arc runs at its feed
    /// within half its axes' acceleration and jerk, as `path::circle` plans it. A small circle
    /// at a short cycle runs on its own (its chords would be slower than the stops they save).
    fn chords_keep_speed(&self, circle: &Circle, step: f64, feed: f64) -> bool {
        let (alone, jerk) = own_speed(&self.limits, circle, feed);
        let r = circle.r0.min(circle.r1);
        let chords = (JUNCTION_JERK_SHARE * jerk * self.cycle_s * r / step).sqrt();
        chords >= CHORD_SPEED_KEPT * alone
    }
}

/// The speed an arc of `circle` runs at on its own at `feed` (within half its plane axes'
/// acceleration and jerk, as `path::circle` plans it) and its plane axes' jerk (infinite
/// without limits).
pub(super) fn own_speed(limits: &[AxisLimits], circle: &Circle, feed: f64) -> (f64, f64) {
    let limit = |i: usize| limits.get(i).copied();
    let (Some(la), Some(lb)) = (limit(circle.axes[0]), limit(circle.axes[1])) else {
        return (feed, f64::INFINITY);
    };
    let r = circle.r0.min(circle.r1);
    let (v, a, j) = (
        la.velocity.min(lb.velocity),
        la.acceleration.min(lb.acceleration),
        la.jerk.min(lb.jerk),
    );
    let alone = feed
        .min(v)
        .min((a * r / 2.0).sqrt())
        .min((j * r * r / 2.0).cbrt());
    (alone, j)
}

impl ArcChords {
    /// Whether a chord failed to join.
    pub(super) fn failed(&self) -> bool {
        self.failed
    }

    /// Chord `k` (1..=chords): from where the last ended to the arc's point `k / chords` of
    /// the way (the block's exact end for the last).
    fn chord(&self, k: u32) -> Segment {
        let b = &self.block;
        let end = if k >= self.chords {
            b.end
        } else {
            let s = f64::from(k) / f64::from(self.chords);
            let mut p = b.start;
            for (i, v) in p.iter_mut().enumerate() {
                *v += self.delta[i] * s;
            }
            let [x, y] = self.circle.point(s);
            p[self.circle.axes[0]] = x;
            p[self.circle.axes[1]] = y;
            p
        };
        Segment {
            start: self.at,
            end,
            feed: b.feed,
            rapid: false,
            line: b.line,
            // Every corner on the arc's side keeps half the tolerance: the chords lie up to
            // the other half inside the circle.
            blend: if k == 1 {
                b.blend.map(|t| 0.5 * t.min(b.tolerance))
            } else {
                Some(0.5 * b.tolerance)
            },
            // Never cut by chords through the blocks' middles (the noise rule): at an
            // inflection the chords' turns alternate, but they lie on a circle.
            chamfer: false,
            on_arc: true,
        }
    }
}
