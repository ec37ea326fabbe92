//! Chords through the middles of short blocks: where short blocks turn by small angles one way
//! and the other (noise around a line, as CAM output has), a corner is cut by the chord from
//! the middle of the block before to the middle of the block after, when that chord stays
//! within most of the tolerance ([`CHAMFER_SHARE`]); the chords' own corners (at the blocks'
//! middles, on the programmed path) are then rounded within what the chords leave of it. Such
//! a zigzag becomes a nearly straight chain of chords and runs at its feed. The chords of a
//! smooth curve (turning one way) would keep its turns: those corners are rounded as they
//! are, their curves sharing their curvature ([`super::corner`]).
//!
//! A block is held back until the next one shows whether its end corner is cut: a contour
//! always holds its last block unpushed (`pending`); [`Contour::close`] pushes it. Not under a
//! transformation (the segment says so): there the joints' limits are taken per block. Never
//! an arc's chords ([`super::arc`]): at an inflection their turns alternate too, but they lie
//! on the circle.

use super::{Contour, Piece, PushError, Segment};
use crate::setpoint::AxisValues;

/// A corner is cut by its chord when the chord lies within this share of the tolerance.
const CHAMFER_SHARE: f64 = 0.9;

/// The sharpest corner that is cut (degrees).
const MAX_CUT_TURN_DEG: f64 = 30.0;
/// A chord may leave at most this share of the corner's turn at either of its ends.
const SPLIT_SHARE: f64 = 0.75;

/// The block held back.
#[derive(Debug, Clone, Copy)]
pub(super) struct Pending {
    segment: Segment,
    /// Its length in X, Y, Z and its direction.
    length: f64,
    dir: AxisValues,
    /// Its first half was taken by the chord of the corner at its start (the path is pushed up
    /// to its middle).
    from_mid: bool,
    /// How far that chord lies from the programmed path.
    chord_dev: f64,
    /// The turn at its start (`u2 - u1`, zeros for none) and whether that corner was small
    /// and short enough to be cut (so a zigzag's cutting can start at its next corner).
    start_turn: AxisValues,
    start_small: bool,
}

impl Contour {
    /// Takes a straight block with chords: the block before (held back) is pushed up to its
    /// middle and the chord to this one's middle when its end corner is cut, else to its end.
    pub(super) fn push_staged(
        &mut self,
        segment: &Segment,
        (length, dir): (f64, &AxisValues),
        limit: &mut dyn FnMut(&mut Piece),
    ) -> Result<(), PushError> {
        let mut next = Pending {
            segment: *segment,
            length,
            dir: *dir,
            from_mid: false,
            chord_dev: 0.0,
            start_turn: AxisValues::zeros(dir.len()),
            start_small: false,
        };
        let Some(held) = self.pending else {
            self.pending = Some(next);
            return Ok(());
        };
        for i in 0..dir.len() {
            next.start_turn[i] = dir[i] - held.dir[i];
        }
        next.start_small = small_corner(&held, &next);
        match chord_deviation(&held, &next) {
            Some(dev) => {
                let mid = midpoint(&held.segment);
                if !held.from_mid {
                    let mut half = held.segment;
                    half.end = mid;
                    self.push_segment(&half, limit)?;
                }
                let mut chord = held.segment;
                chord.start = mid;
                chord.end = midpoint(segment);
                chord.feed = held.segment.feed.min(segment.feed);
                // Shown as the block it ends in (its corner curve reaches into the one after).
                chord.line = segment.line;
                // Its corner at the block's middle (on the programmed path) keeps what the
                // chords there leave of the tolerance.
                let tolerance = segment.blend.unwrap_or(0.0);
                chord.blend = Some(tolerance - dev.max(held.chord_dev));
                self.push_segment(&chord, limit)?;
                self.pending = Some(Pending {
                    from_mid: true,
                    chord_dev: dev,
                    ..next
                });
            }
            None => {
                self.push_rest(&held, limit)?;
                self.pending = Some(next);
            }
        }
        Ok(())
    }

    /// Pushes the block held back (the window's end): `false` when there is no room yet.
    pub(super) fn flush(&mut self) -> bool {
        let Some(held) = self.pending else {
            return true;
        };
        if !self.has_room_for(1) {
            return false;
        }
        if self.push_rest(&held, &mut |_| {}).is_err() {
            return false;
        }
        self.pending = None;
        true
    }

    /// The held block from where the path stands on it (its start, or its middle after a
    /// chord) to its end.
    fn push_rest(
        &mut self,
        held: &Pending,
        limit: &mut dyn FnMut(&mut Piece),
    ) -> Result<(), PushError> {
        let mut rest = held.segment;
        if held.from_mid {
            rest.start = midpoint(&held.segment);
            rest.blend = held.segment.blend.map(|t| t - held.chord_dev);
        }
        self.push_segment(&rest, limit)
    }
}

impl Pending {
    /// The held block's source line.
    pub(super) fn line(&self) -> u32 {
        self.segment.line
    }
}

/// The middle of a block (all its axes).
fn midpoint(segment: &Segment) -> AxisValues {
    let mut m = segment.start;
    for (i, v) in m.iter_mut().enumerate() {
        *v = 0.5 * (*v + segment.end[i]);
    }
    m
}

/// The cosine and angle of the turn from `held`'s direction to `next`'s (in X, Y, Z).
fn turn_between(held: &Pending, next: &Pending) -> (f64, f64) {
    let cos = (0..3)
        .map(|i| held.dir[i] * next.dir[i])
        .sum::<f64>()
        .clamp(-1.0, 1.0);
    (cos, cos.acos())
}

/// Whether the corner between `held` and `next` is one a zigzag of noise has: rounded by
/// `next`'s tolerance, turning by at most [`MAX_CUT_TURN_DEG`], so short that rounding it
/// would take all of both halves.
fn small_corner(held: &Pending, next: &Pending) -> bool {
    let Some(tolerance) = next.segment.blend else {
        return false;
    };
    let (_, turn) = turn_between(held, next);
    let rounding = 3.0 * tolerance / (0.5 * turn).sin().max(1e-12);
    tolerance > 0.0
        && turn > 1e-9
        && turn <= MAX_CUT_TURN_DEG.to_radians()
        && rounding >= 0.5 * held.length.min(next.length)
}

/// How far the chord from `held`'s middle to `next`'s middle lies from the corner between
/// them, when that corner is to be cut: both blocks straight and joined, of the same kind
/// (rapid or not), a small corner ([`small_corner`]) turning against the one before, which
/// was small too or cut (noise around a line, not a curve's chords: those keep their turns
/// whichever way they are cut), the turn split between the chord's ends and the chord within
/// [`CHAMFER_SHARE`] of the tolerance.
fn chord_deviation(held: &Pending, next: &Pending) -> Option<f64> {
    let tolerance = next.segment.blend?;
    let against = (0..held.dir.len())
        .map(|i| held.start_turn[i] * next.start_turn[i])
        .sum::<f64>()
        < 0.0;
    if !(held.from_mid || held.start_small) || !against || !next.start_small {
        return None;
    }
    let joined = held
        .segment
        .end
        .iter()
        .zip(next.segment.start.iter())
        .all(|(a, b)| (a - b).abs() <= 1e-9);
    let long_enough = held.length.min(next.length) > 1e-6;
    if tolerance <= 0.0 || !joined || !long_enough || held.segment.rapid != next.segment.rapid {
        return None;
    }
    let (cos, turn) = turn_between(held, next);
    let (a, b) = (0.5 * held.length, 0.5 * next.length);
    let chord = (a * a + b * b + 2.0 * a * b * cos).sqrt();
    // The chord splits the turn between its two ends (by the triangle's angles at the
    // middles); cut only where neither end keeps most of it: a long block's chord to a short
    // one's middle would leave nearly the whole turn at the short one's middle.
    let at_start = (b * turn.sin() / chord).clamp(-1.0, 1.0).asin();
    let kept = at_start.max(turn - at_start);
    if kept > SPLIT_SHARE * turn {
        return None;
    }
    let dev = a * b * turn.sin() / chord;
    (dev <= CHAMFER_SHARE * tolerance).then_some(dev)
}
