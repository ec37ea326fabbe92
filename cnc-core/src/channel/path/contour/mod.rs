//! Continuous path: straight blocks run one after the other without stopping, their corners
//! rounded within a tolerance, over a look-ahead of decoded blocks.
//!
//! The window holds [`Piece`]s: the straight parts of the blocks and the curves between them
//! ([`piece`]). A jerk-limited profile runs the path parameter over one piece at a time from
//! the velocity at its start to the velocity planned for its end ([`profile`]); the next
//! piece takes over the rest of the tick, so the velocity has no dip at a boundary.
//!
//! Planning, at two moments:
//! * when a block comes in, a backward sweep bounds the velocity at every piece's end so that
//!   the path can always come to rest at the end of what it has seen (`bound_hard` with the
//!   axes' caps, `bound_soft` also with the feed and the override); the sweep stops where the
//!   bounds no longer change;
//! * when a piece starts, its end velocity is the highest its own length allows from its
//!   start velocity within `bound_soft`, at least the lowest that braking over it can reach,
//!   and at most `bound_hard` (which braking over it always reaches).
//!
//! Feed hold and a stop make every soft bound 0: the pieces ahead brake as hard as their
//! limits let them, and the piece under way brakes within itself where its rest of length
//! allows. The override changes the soft bounds; the piece under way takes a new cruise
//! velocity once it cruises.

mod piece;
mod profile;
#[cfg(test)]
mod tests;

pub use piece::Piece;
pub use profile::{Dynamics, PathState};

use super::AxisLimits;
use crate::axis::generator::{Progress, SetpointGenerator};
use crate::setpoint::AxisValues;
use profile::{max_reach, min_reach, PieceProfile};
use std::collections::VecDeque;

/// Most blocks a look-ahead may hold.
pub const MAX_LOOKAHEAD: usize = 128;
/// Default look-ahead (blocks).
pub const DEFAULT_LOOKAHEAD: usize = 32;
/// The largest turn a corner is rounded at (degrees); a sharper one is an exact stop.
pub const MAX_TURN_DEG: f64 = 135.0;

/// One straight block handed to the contour.
#[derive(Debug, Clone, Copy)]
pub struct Segment {
    /// Start and end (channel axes).
    pub start: AxisValues,
    /// End (the block's target).
    pub end: AxisValues,
    /// Feed in path units/s; infinite for rapid (G0).
    pub feed: f64,
    /// G0.
    pub rapid: bool,
    /// Source line.
    pub line: u32,
    /// The corner with the block before may be rounded by at most this (mm); `None`: exact
    /// stop there.
    pub blend: Option<f64>,
}

/// Why the contour did not take a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PushError {
    /// The window is full.
    Full,
    /// The block does not move X, Y or Z (it runs on its own, with exact stop).
    NotStraight,
}

/// Why the contour cannot go on (the channel then fails and its guard brakes the axes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum ContourError {
    /// A piece's planned end velocity is out of its reach (never seen).
    #[error("no velocity profile for a piece of the contour")]
    NoProfile,
}

/// How the piece under way runs.
#[derive(Debug)]
enum Mode {
    /// Nothing under way (empty window, or not started).
    Idle,
    /// Along its planned profile, `t` into it, from `offset`.
    Profile,
    /// Braking within the piece (feed hold, stop) on the generator, in path units.
    Braking,
    /// At rest at `lambda` on the piece.
    Resting,
}

/// The look-ahead window and the motion along it.
#[derive(Debug)]
pub struct Contour {
    pieces: VecDeque<Piece>,
    capacity: usize,
    /// Blocks in the window.
    blocks: usize,
    lookahead: usize,
    limits: Vec<AxisLimits>,
    cycle_s: f64,
    mode: Mode,
    profile: PieceProfile,
    /// Time into the profile and where on the piece it starts.
    t: f64,
    offset: f64,
    /// Committed velocity at the end of the piece under way.
    v_end: f64,
    state: PathState,
    brake: SetpointGenerator,
    /// Override factors in effect (feed, rapid); (0, 0) under hold or stop.
    factors: (f64, f64),
    /// The cruise of the piece under way is to be re-planned for new factors.
    retarget: bool,
    /// No more blocks will come: the window's end is the program's.
    closed: bool,
    /// A stop: at rest, the window is emptied.
    stopping: bool,
    /// Where the last block ended (its exact end point) and its direction.
    last_end: Option<(AxisValues, AxisValues)>,
    /// Where the path stands once the window has run empty.
    rest_point: AxisValues,
}

impl Contour {
    /// An empty contour for a channel of `axes` axes with `limits`, ticking every `cycle_s`,
    /// looking ahead `lookahead` blocks (1..=[`MAX_LOOKAHEAD`]); allocates here only.
    pub fn new(limits: &[AxisLimits], cycle_s: f64, lookahead: usize) -> Self {
        let lookahead = lookahead.clamp(1, MAX_LOOKAHEAD);
        let capacity = 2 * lookahead + 2;
        Self {
            pieces: VecDeque::with_capacity(capacity),
            capacity,
            blocks: 0,
            lookahead,
            limits: limits.to_vec(),
            cycle_s,
            mode: Mode::Idle,
            profile: PieceProfile::default(),
            t: 0.0,
            offset: 0.0,
            v_end: 0.0,
            state: PathState::default(),
            brake: SetpointGenerator::new(cycle_s, 0.0),
            factors: (1.0, 1.0),
            retarget: false,
            closed: false,
            stopping: false,
            last_end: None,
            rest_point: AxisValues::zeros(limits.len()),
        }
    }

    /// Whether the path is under way or blocks are waiting in the window.
    pub fn active(&self) -> bool {
        !self.pieces.is_empty()
    }

    /// Whether another block fits into the window.
    pub fn has_room(&self) -> bool {
        self.blocks < self.lookahead && self.pieces.len() + 2 <= self.capacity
    }

    /// Whether the window ends where the program stops (no more blocks join it).
    pub fn closed(&self) -> bool {
        self.closed
    }

    /// No more blocks join this run: the path comes to rest at the end of the last one.
    pub fn close(&mut self) {
        self.closed = true;
    }

    /// The source line of the piece under way.
    pub fn line(&self) -> Option<u32> {
        self.pieces.front().map(|p| p.line)
    }

    /// The path parameter's state on the piece under way.
    pub fn path_state(&self) -> PathState {
        self.state
    }

    /// Adds a straight block. Its corner with the block before is rounded when both move X,
    /// Y or Z, the turn is at most [`MAX_TURN_DEG`], the block before is not under way yet and
    /// `segment.blend` allows it; else the path rests between them. `limit` may lower each new
    /// piece's caps and dynamics before the look-ahead plans with them (the joints' limits
    /// under a transformation).
    pub fn push(
        &mut self,
        segment: &Segment,
        limit: &mut dyn FnMut(&mut Piece),
    ) -> Result<(), PushError> {
        if !self.has_room() {
            return Err(PushError::Full);
        }
        let mut dir = segment.end;
        for (i, d) in dir.iter_mut().enumerate() {
            *d -= segment.start[i];
        }
        let length = dir.iter().take(3).map(|d| d * d).sum::<f64>().sqrt();
        if length <= 1e-9 || !length.is_finite() {
            return Err(PushError::NotStraight);
        }
        dir.iter_mut().for_each(|d| *d /= length);
        if self.pieces.is_empty() {
            self.closed = false;
            self.last_end = None;
        }
        let rounded = self.round_corner(segment, &dir, length, limit);
        if !rounded {
            if let Some(last) = self.pieces.back_mut() {
                last.rest_after = true;
            }
            let mut p = Piece::straight(segment.start, dir, length, length, &self.limits);
            tag(&mut p, segment);
            limit(&mut p);
            self.pieces.push_back(p);
        }
        self.blocks += 1;
        self.last_end = Some((segment.end, dir));
        self.sweep_back(self.pieces.len() - 1);
        Ok(())
    }

    /// Rounds the corner into `segment` when it may be: shortens the last straight piece,
    /// adds the curve and the block's straight piece. `false` (nothing changed) when not.
    fn round_corner(
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
        if (n == 1 && under_way) || last.half > 0.0 || tolerance <= 0.0 {
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
        let d = by_tolerance
            .min(0.5 * last.block_length)
            .min(last.length)
            .min(0.5 * length);
        if d <= 1e-9 {
            return false;
        }
        let saved = last;
        let committed = self.v_end;
        let corner = segment.start;
        let back = self.pieces.back_mut().expect("checked");
        back.length -= d;
        back.rest_after = false;
        let mut curve = Piece::curve(&corner, &u1, u2, d, &self.limits);
        tag(&mut curve, segment);
        curve.feed = curve.feed.min(saved.feed);
        curve.line = saved.line;
        curve.rapid = saved.rapid && segment.rapid;
        let mut origin = corner;
        for i in 0..origin.len() {
            origin[i] += d * u2[i];
        }
        let mut straight = Piece::straight(origin, *u2, length - d, length, &self.limits);
        tag(&mut straight, segment);
        limit(&mut curve);
        limit(&mut straight);
        self.pieces.push_back(curve);
        self.pieces.push_back(straight);
        self.sweep_back(self.pieces.len() - 1);
        // The piece under way must still reach its committed end velocity's bound.
        let front_ok = !under_way || self.pieces[0].bound_hard >= committed - 1e-9;
        if !front_ok {
            self.pieces.pop_back();
            self.pieces.pop_back();
            *self.pieces.back_mut().expect("kept") = saved;
            self.sweep_back(self.pieces.len() - 1);
            return false;
        }
        true
    }

    /// Recomputes the look-ahead bounds from piece `from` back to the piece under way,
    /// stopping where they no longer change.
    fn sweep_back(&mut self, from: usize) {
        let (ff, rf) = self.factors;
        let mut next: Option<Next> = None;
        for k in (0..=from.min(self.pieces.len().saturating_sub(1))).rev() {
            let (hard, soft) = match next {
                None => (0.0, 0.0),
                Some(_) if self.pieces[k].rest_after => (0.0, 0.0),
                Some(Next {
                    hard: nh,
                    soft: ns,
                    length: len,
                    caps: (next_hard, next_soft),
                    dynamics,
                }) => {
                    let p = &self.pieces[k];
                    let cap_hard = p.hard_cap.min(next_hard);
                    let cap_soft = p.soft_cap(ff, rf).min(next_soft).min(cap_hard);
                    (
                        max_reach(nh, len, cap_hard, dynamics),
                        max_reach(ns, len, cap_soft, dynamics).min(cap_soft),
                    )
                }
            };
            let p = &mut self.pieces[k];
            let unchanged = p.bound_hard == hard && p.bound_soft == soft;
            p.bound_hard = hard;
            p.bound_soft = soft;
            if unchanged && k < from {
                break;
            }
            next = Some(Next {
                hard,
                soft,
                length: p.length,
                caps: (p.hard_cap, p.soft_cap(ff, rf)),
                dynamics: p.dynamics,
            });
        }
    }

    /// Feed and rapid override factors (0 for feed hold or a stop): new soft bounds, and the
    /// piece under way brakes within itself when it can.
    pub fn set_factors(&mut self, feed: f64, rapid: f64) {
        let factors = if self.stopping {
            (0.0, 0.0)
        } else {
            (feed, rapid)
        };
        if factors == self.factors {
            return;
        }
        // The piece under way is held when its own factor is 0 (feed for G1, rapid for G0).
        let front_rapid = self.pieces.front().is_some_and(|p| p.rapid);
        let holding = if front_rapid {
            factors.1 <= 0.0
        } else {
            factors.0 <= 0.0
        };
        self.factors = factors;
        if !self.pieces.is_empty() {
            // Every bound may change: sweep the whole window.
            for p in self.pieces.iter_mut() {
                p.bound_soft = f64::NAN;
            }
            self.sweep_back(self.pieces.len() - 1);
        }
        if holding {
            self.brake_within();
        } else {
            self.retarget = true;
        }
    }

    /// A controlled stop: the path brakes as for feed hold and the window is emptied at rest.
    pub fn stop(&mut self) {
        self.closed = true;
        self.set_factors(0.0, 0.0);
        self.stopping = true;
    }

    /// Brakes the piece under way within its rest of length, when that fits.
    fn brake_within(&mut self) {
        let Some(p) = self.pieces.front() else {
            return;
        };
        if !matches!(self.mode, Mode::Profile) {
            return;
        }
        let s = self.state;
        self.brake.resume_from(crate::setpoint::Kinematic {
            position: s.position,
            velocity: s.velocity,
            acceleration: s.acceleration,
            jerk: 0.0,
        });
        let d = p.dynamics;
        if self.brake.brake(d.acceleration, d.jerk).is_ok() && self.brake.end_position() <= p.length
        {
            self.mode = Mode::Braking;
        }
    }

    /// One tick: the position on the path into `position`, the axes' velocity and
    /// acceleration into `velocity` and `acceleration`. `Ok(true)` while the path moves or
    /// blocks wait in the window.
    pub fn step(
        &mut self,
        position: &mut AxisValues,
        velocity: &mut AxisValues,
        acceleration: &mut AxisValues,
    ) -> Result<bool, ContourError> {
        if self.pieces.is_empty() {
            return Ok(false);
        }
        if matches!(self.mode, Mode::Idle) {
            self.start_piece(0.0, 0.0)?;
        }
        match self.mode {
            Mode::Profile => self.advance_profile()?,
            Mode::Braking => {
                if matches!(self.brake.step(), Progress::Reached | Progress::Idle) {
                    self.mode = Mode::Resting;
                }
                let k = self.brake.state();
                self.state = PathState {
                    position: k.position,
                    velocity: k.velocity,
                    acceleration: k.acceleration,
                };
            }
            Mode::Resting => self.resume()?,
            Mode::Idle => {}
        }
        if self.stopping && self.at_rest() {
            self.output(position, velocity, acceleration);
            velocity.fill(0.0);
            acceleration.fill(0.0);
            self.clear();
            self.rest_point = *position;
            return Ok(false);
        }
        if self.pieces.is_empty() {
            position.copy_from_slice(&self.rest_point);
            velocity.fill(0.0);
            acceleration.fill(0.0);
            return Ok(false);
        }
        self.output(position, velocity, acceleration);
        Ok(true)
    }

    fn at_rest(&self) -> bool {
        matches!(self.mode, Mode::Resting)
    }

    fn output(&self, position: &mut AxisValues, velocity: &mut AxisValues, acc: &mut AxisValues) {
        let Some(p) = self.pieces.front() else {
            return;
        };
        let s = self.state;
        p.point(s.position, position);
        p.rates(s.position, (s.velocity, s.acceleration), velocity, acc);
    }

    /// Empties the window (a stop at rest, or a reset).
    pub fn clear(&mut self) {
        self.pieces.clear();
        self.blocks = 0;
        self.mode = Mode::Idle;
        self.stopping = false;
        self.closed = false;
        self.last_end = None;
        self.state = PathState::default();
        self.v_end = 0.0;
        self.factors = (1.0, 1.0);
    }

    /// Plans the front piece from `offset` on it at velocity `v0`.
    fn start_piece(&mut self, offset: f64, v0: f64) -> Result<(), ContourError> {
        let (ff, rf) = self.factors;
        let p = self.pieces.front().expect("a piece");
        let rest = (p.length - offset).max(0.0);
        let v1 = if rest <= 1e-12 {
            v0
        } else {
            feasible_end(v0, rest, p)
        };
        let cap = p.soft_cap(ff, rf);
        self.profile =
            PieceProfile::plan(rest, v0, v1, cap, p.dynamics).ok_or(ContourError::NoProfile)?;
        self.offset = offset;
        self.t = 0.0;
        self.v_end = v1;
        self.mode = Mode::Profile;
        self.retarget = false;
        self.state = PathState {
            position: offset,
            velocity: v0,
            acceleration: 0.0,
        };
        Ok(())
    }

    /// Advances along the profile by one tick, into the next pieces as far as the tick goes.
    fn advance_profile(&mut self) -> Result<(), ContourError> {
        self.t += self.cycle_s;
        loop {
            if self.retarget && self.profile.cruising(self.t) {
                self.replan_cruise();
            }
            let duration = self.profile.duration();
            if self.t <= duration {
                let s = self.profile.at(self.t);
                self.state = PathState {
                    position: self.offset + s.position,
                    ..s
                };
                return Ok(());
            }
            let v0 = self.v_end;
            let leftover = self.t - duration;
            let length = self.pieces.front().map_or(0.0, |p| p.length);
            if self.offset + self.profile.reach() < length - 1e-9 {
                // Braked to rest short of the piece's end (feed hold, stop).
                self.state = PathState {
                    position: self.offset + self.profile.reach(),
                    velocity: 0.0,
                    acceleration: 0.0,
                };
                self.mode = Mode::Resting;
                return Ok(());
            }
            self.finish_front();
            if v0 <= 1e-12 {
                // At rest at a piece's end: an exact stop, the window's end, or feed hold.
                // The next piece starts on a later tick.
                if !self.pieces.is_empty() {
                    self.mode = Mode::Resting;
                }
                return Ok(());
            }
            if self.pieces.is_empty() {
                // Moving at the window's end cannot happen (its bound is 0).
                return Err(ContourError::NoProfile);
            }
            self.start_piece(0.0, v0)?;
            self.t = leftover;
        }
    }

    /// The front piece is done; at the end of the window, where the path stands is kept.
    fn finish_front(&mut self) {
        if let Some(p) = self.pieces.pop_front() {
            if p.half == 0.0 {
                self.blocks = self.blocks.saturating_sub(1);
            }
            if self.pieces.is_empty() {
                // The piece ran to its end: the block's exact end point, unless a stop cut
                // the window short.
                match self.last_end {
                    Some((end, _)) if !self.stopping => self.rest_point = end,
                    _ => p.end(&mut self.rest_point),
                }
            }
        }
        self.state = PathState::default();
        if self.pieces.is_empty() {
            self.mode = Mode::Idle;
            self.blocks = 0;
        }
    }

    /// New override factors during a cruise: the rest of the piece is planned again from the
    /// cruise to the committed end velocity with the new cap.
    fn replan_cruise(&mut self) {
        self.retarget = false;
        let (ff, rf) = self.factors;
        let p = self.pieces.front().expect("a piece");
        let s = self.profile.at(self.t);
        let here = self.offset + s.position;
        let rest = p.length - here;
        if let Some(profile) =
            PieceProfile::plan(rest, s.velocity, self.v_end, p.soft_cap(ff, rf), p.dynamics)
        {
            self.profile = profile;
            self.offset = here;
            self.t = 0.0;
        }
    }

    /// At rest on the front piece: goes on once the factors let it.
    fn resume(&mut self) -> Result<(), ContourError> {
        let moving = self.factors.0 > 0.0 || self.factors.1 > 0.0;
        if !moving {
            return Ok(());
        }
        let here = self.state.position;
        self.start_piece(here, 0.0)?;
        self.advance_profile()
    }
}

/// The end velocity of a piece entered at `v0` with `rest` of it to go: the highest its length
/// allows within its soft bound, at least the lowest braking reaches, at most its hard bound,
/// and always one the piece's length can reach. Braking part of the way can take longer than
/// braking to rest (the distance `(v0 + v) T(v0 - v) / 2` first grows as `v` falls from
/// `v0`, then shrinks), so a velocity between the bounds may not fit: then the highest below
/// it that does, or the hard bound (which the look-ahead made reachable from every entry
/// velocity up to the one before's hard bound).
fn feasible_end(v0: f64, rest: f64, p: &Piece) -> f64 {
    let d = p.dynamics;
    let fits = |v: f64| profile::change_distance(v0, v, d) <= rest * (1.0 + 1e-12) + 1e-15;
    let reach_low = min_reach(v0, rest, d);
    let soft = max_reach(v0, rest, p.bound_soft.max(0.0), d);
    let v1 = soft.max(reach_low).min(p.bound_hard.max(reach_low));
    if fits(v1) {
        return v1;
    }
    if fits(0.0) {
        // Between 0 (fits) and v1 (does not): the highest that fits.
        return profile::bisect(0.0, v1, fits);
    }
    v0.min(p.bound_hard)
}

/// What the backward sweep carries from a piece to the one before: its bounds, length,
/// caps (hard, soft) and dynamics.
struct Next {
    hard: f64,
    soft: f64,
    length: f64,
    caps: (f64, f64),
    dynamics: Dynamics,
}

/// Copies the block's feed, mode and line onto a piece.
fn tag(piece: &mut Piece, segment: &Segment) {
    piece.feed = segment.feed;
    piece.rapid = segment.rapid;
    piece.line = segment.line;
}
