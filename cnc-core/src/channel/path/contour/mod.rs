//! Continuous path: straight blocks run one after the other without stopping, their corners
//! rounded within a tolerance, over a look-ahead of decoded blocks.
//!
//! The window holds [`Piece`]s: the straight parts of the blocks and the curves between them
//! ([`piece`], [`corner`]). Consecutive pieces with similar caps and dynamics form a unit
//! ([`plan`]): a jerk-limited profile ([`profile`]) runs the path parameter over a run of
//! pieces, from the velocity at the run's start to the one planned for the end of its unit,
//! the acceleration carried through the pieces' boundaries; the next run takes over the rest
//! of the tick, so the velocity has no dip at a boundary.
//!
//! Planning, at three moments:
//! * when a block comes in, a backward sweep bounds the velocity at every piece's end so that
//!   the path can always come to rest at the end of what it has seen (`bound_hard` with the
//!   axes' caps, `bound_soft` also with the feed and the override), one velocity change per
//!   unit; the sweep stops at a unit before the new pieces whose bounds did not change;
//! * when a run starts, its end velocity is the highest its length allows from its start
//!   velocity within `bound_soft`, at least the lowest that braking over it can reach, and at
//!   most `bound_hard` (which braking over it always reaches);
//! * on the way, where the profile has no acceleration (its cruise, its peak), after new
//!   blocks or new factors: the run is planned again to the end of its unit as it now is, so
//!   a run that began before the window reached further is not braked for the end it saw
//!   then. A plan that does not fit, or ends above the hard bound, keeps the one under way.
//!
//! Feed hold and a stop make every soft bound 0: the pieces ahead brake as hard as their
//! limits let them, and the run under way brakes within itself where its rest of length
//! allows. The override changes the soft bounds; the run under way takes them at its next
//! point without acceleration.

mod arc;
#[cfg(test)]
mod arc_tests;
mod chamfer;
mod corner;
mod fillet;
mod piece;
mod plan;
mod planar;
mod profile;
mod shape;
#[cfg(test)]
mod tests;

pub use arc::{ArcBlock, MAX_ARC_CHORDS};
pub use piece::Piece;
pub use profile::{Dynamics, PathState};

use super::AxisLimits;
use crate::axis::generator::{Progress, SetpointGenerator};
use crate::setpoint::AxisValues;
use plan::feasible_end;
use profile::PieceProfile;
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
    /// Short blocks' corners may be cut by chords through their middles (not under a
    /// transformation: the block is then held back until the next one comes, see
    /// [`chamfer`]).
    pub chamfer: bool,
    /// One of an arc's chords ([`arc`]).
    pub on_arc: bool,
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
    /// A chord of an arc did not join the window (never seen).
    #[error("an arc's chord did not join the contour")]
    ArcChord,
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
    /// The run under way is to be planned again at its next point without acceleration (new
    /// blocks, new factors).
    replan: bool,
    /// Pieces the run under way covers (from the front), and its length from the profile's
    /// start.
    run_pieces: usize,
    run_rest: f64,
    /// No more blocks will come: the window's end is the program's.
    closed: bool,
    /// A stop: at rest, the window is emptied.
    stopping: bool,
    /// Where the last block ended (its exact end point) and its direction.
    last_end: Option<(AxisValues, AxisValues)>,
    /// Where the path stands once the window has run empty.
    rest_point: AxisValues,
    /// The last block, held back until the next one shows whether its end corner is cut.
    pending: Option<chamfer::Pending>,
    /// An arc whose chords are still joining the window.
    arc: Option<arc::ArcChords>,
    /// A small arc held back until the block after it comes ([`fillet`]).
    held: Option<fillet::HeldArc>,
    /// Where the straight after a small arc's transitions starts: it joins them without a
    /// corner.
    smooth_from: Option<AxisValues>,
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
            replan: false,
            run_pieces: 0,
            run_rest: 0.0,
            closed: false,
            stopping: false,
            last_end: None,
            rest_point: AxisValues::zeros(limits.len()),
            pending: None,
            arc: None,
            held: None,
            smooth_from: None,
        }
    }

    /// Whether the path is under way or blocks are waiting in the window.
    pub fn active(&self) -> bool {
        !self.pieces.is_empty()
            || self.pending.is_some()
            || self.arc.is_some()
            || self.held.is_some()
    }

    /// Whether another block fits into the window (with a small arc held back: its pieces
    /// too).
    pub fn has_room(&self) -> bool {
        let room = if self.held.is_some() {
            self.pieces.len() + fillet::HELD_ROOM <= self.capacity
        } else {
            self.has_room_for(2)
        };
        self.arc.is_none() && self.blocks < self.lookahead && room
    }

    /// Whether `segments` more segments (two pieces each) fit into the window.
    fn has_room_for(&self, segments: usize) -> bool {
        self.pieces.len() + 2 * segments <= self.capacity
    }

    /// Whether the window ends where the program stops (no more blocks join it).
    pub fn closed(&self) -> bool {
        self.closed
    }

    /// No more blocks join this run: the path comes to rest at the end of the last one.
    pub fn close(&mut self) {
        if !self.closed {
            self.closed = true;
            // The block held back ends the window (when there is no room yet, a later tick
            // pushes it).
            self.feed_window();
            // The window's last piece may now join its unit.
            self.sweep_back();
            self.replan = true;
        }
    }

    /// The source line of the piece under way.
    pub fn line(&self) -> Option<u32> {
        self.pieces
            .front()
            .map(|p| p.line)
            .or(self.pending.as_ref().map(|p| p.line()))
            .or(self.held.as_ref().map(|h| h.line()))
    }

    /// The path parameter's state on the piece under way.
    pub fn path_state(&self) -> PathState {
        self.state
    }

    /// Adds a straight block. Its corner with the block before is rounded when both move X,
    /// Y or Z, the turn is at most [`MAX_TURN_DEG`], the block before is not under way yet,
    /// `segment.blend` allows it and passing is quicker than stopping; else the path rests
    /// between them. With `segment.chamfer` the block is held back until the next one comes
    /// ([`chamfer`]). `limit` may lower each new
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
        if let Some(start) = self.release_arc(Some(segment))? {
            // After a small arc's transitions: from where they end.
            let rest = Segment { start, ..*segment };
            return self.push_block(&rest, limit);
        }
        self.push_block(segment, limit)
    }

    /// [`Self::push`] once its room is known (an arc's chords come this way).
    fn push_block(
        &mut self,
        segment: &Segment,
        limit: &mut dyn FnMut(&mut Piece),
    ) -> Result<(), PushError> {
        let (length, dir) = direction(segment).ok_or(PushError::NotStraight)?;
        self.reopen_if_idle();
        if segment.chamfer {
            return self.push_staged(segment, (length, &dir), limit);
        }
        if !self.flush() {
            return Err(PushError::Full);
        }
        self.push_segment(segment, limit)
    }

    /// A block joining a contour with nothing under way and nothing waiting starts a new one:
    /// open, no corner with what ran before.
    fn reopen_if_idle(&mut self) {
        if !self.active() {
            self.closed = false;
            self.last_end = None;
        }
    }

    /// Adds a segment to the window (a block, or a part of blocks cut by chords).
    fn push_segment(
        &mut self,
        segment: &Segment,
        limit: &mut dyn FnMut(&mut Piece),
    ) -> Result<(), PushError> {
        if !self.has_room_for(1) {
            return Err(PushError::Full);
        }
        let (length, dir) = direction(segment).ok_or(PushError::NotStraight)?;
        if self.pieces.is_empty() {
            self.last_end = None;
        }
        let smooth = self.smooth_from.take() == Some(segment.start);
        let rounded = !smooth && self.round_corner(segment, &dir, length, limit);
        if !rounded {
            if let Some(last) = self.pieces.back_mut().filter(|_| !smooth) {
                last.rest_after = true;
            }
            let mut p = Piece::straight(segment.start, dir, length, length, &self.limits);
            tag(&mut p, segment);
            limit(&mut p);
            self.pieces.push_back(p);
            if smooth {
                self.rechain(self.pieces.len() - 1);
            }
        }
        self.blocks += 1;
        self.last_end = Some((segment.end, dir));
        self.sweep_back();
        self.replan = true;
        Ok(())
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
            self.sweep_back();
        }
        if holding {
            self.brake_within();
        }
        self.replan = true;
    }

    /// A controlled stop: the path brakes as for feed hold and the window is emptied at rest.
    pub fn stop(&mut self) {
        self.closed = true;
        self.pending = None;
        self.arc = None;
        self.held = None;
        self.smooth_from = None;
        self.set_factors(0.0, 0.0);
        self.stopping = true;
    }

    /// Brakes the run under way within its rest of length, when that fits.
    fn brake_within(&mut self) {
        if self.pieces.is_empty() || !matches!(self.mode, Mode::Profile) {
            return;
        }
        let unit = self.unit(0, self.run_pieces.max(1) - 1);
        let s = self.state;
        self.brake.resume_from(crate::setpoint::Kinematic {
            position: s.position,
            velocity: s.velocity,
            acceleration: s.acceleration,
            jerk: 0.0,
        });
        let d = unit.dynamics;
        let run_end = self.offset + self.run_rest;
        if self.brake.brake(d.acceleration, d.jerk).is_ok() && self.brake.end_position() <= run_end
        {
            // The generator's positions are the front piece's; `offset` follows the pieces
            // passed.
            self.offset = 0.0;
            self.v_end = 0.0;
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
        self.feed_window();
        if self.arc.is_some_and(|a| a.failed()) {
            return Err(ContourError::ArcChord);
        }
        if self.pieces.is_empty() {
            return Ok(false);
        }
        if matches!(self.mode, Mode::Idle) {
            self.start_run(0.0, 0.0)?;
        }
        match self.mode {
            Mode::Profile => self.advance_profile()?,
            Mode::Braking => {
                let done = matches!(self.brake.step(), Progress::Reached | Progress::Idle);
                let k = self.brake.state();
                self.state = PathState {
                    position: k.position + self.offset,
                    velocity: k.velocity,
                    acceleration: k.acceleration,
                };
                self.pass_boundaries();
                if done {
                    self.rest_here();
                }
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
        self.replan = false;
        self.run_pieces = 0;
        self.run_rest = 0.0;
        self.pending = None;
        self.arc = None;
        self.held = None;
        self.smooth_from = None;
    }

    /// Pushes what waits outside the window as room frees: an arc's chords, then (once the
    /// window is closed) the block held back.
    fn feed_window(&mut self) {
        if self.arc.is_some() {
            self.feed_arc();
        }
        if self.closed && self.held.is_some() && self.release_arc(None).is_err() {
            return;
        }
        if self.closed && self.arc.is_none() && self.pending.is_some() {
            self.flush();
        }
    }

    /// Plans the run from `offset` on the front piece at velocity `v0` (acceleration 0) to the
    /// end of the front piece's unit; a single piece when the unit's plan does not fit.
    fn start_run(&mut self, offset: f64, v0: f64) -> Result<(), ContourError> {
        let end = self.unit_end(0);
        let planned = self
            .plan_run(offset, v0, end)
            .or_else(|| (end > 0).then(|| self.plan_run(offset, v0, 0)).flatten());
        let (profile, v1, pieces, rest) = planned.ok_or(ContourError::NoProfile)?;
        self.adopt(profile, v1, pieces, rest, offset);
        self.t = 0.0;
        self.mode = Mode::Profile;
        self.state = PathState {
            position: offset,
            velocity: v0,
            acceleration: 0.0,
        };
        Ok(())
    }

    /// The profile from `offset` on the front piece at `v0` to the end of piece `end`, its end
    /// velocity, the pieces it covers and its length.
    fn plan_run(
        &self,
        offset: f64,
        v0: f64,
        end: usize,
    ) -> Option<(PieceProfile, f64, usize, f64)> {
        let unit = self.unit(0, end);
        let last = &self.pieces[end];
        let rest = (unit.length - offset).max(0.0);
        let d = unit.dynamics;
        let v1 = if rest <= 1e-12 {
            v0
        } else {
            feasible_end(v0, rest, d, last.bound_soft, last.bound_hard)
        };
        let profile = PieceProfile::plan(rest, v0, v1, unit.cap_soft, d)?;
        Some((profile, v1, end + 1, rest))
    }

    fn adopt(&mut self, profile: PieceProfile, v1: f64, pieces: usize, rest: f64, offset: f64) {
        self.profile = profile;
        self.v_end = v1;
        self.run_pieces = pieces;
        self.run_rest = rest;
        self.offset = offset;
        self.replan = false;
    }

    /// Advances along the profile by one tick, into the next runs as far as the tick goes.
    fn advance_profile(&mut self) -> Result<(), ContourError> {
        let before = self.t;
        self.t += self.cycle_s;
        loop {
            if self.replan {
                let _ = self.replan_on_the_way(before);
            }
            let duration = self.profile.duration();
            if self.t <= duration {
                let s = self.profile.at(self.t);
                self.state = PathState {
                    position: self.offset + s.position,
                    ..s
                };
                self.pass_boundaries();
                return Ok(());
            }
            let v0 = self.v_end;
            let leftover = self.t - duration;
            if self.profile.reach() < self.run_rest - 1e-9 {
                // Braked to rest short of the run's end (feed hold, stop).
                self.state = PathState {
                    position: self.offset + self.profile.reach(),
                    velocity: 0.0,
                    acceleration: 0.0,
                };
                self.pass_boundaries();
                self.rest_here();
                return Ok(());
            }
            for _ in 0..self.run_pieces.max(1) {
                self.pop_piece();
            }
            self.state = PathState::default();
            if self.pieces.is_empty() {
                self.mode = Mode::Idle;
                self.blocks = 0;
            }
            if v0 <= 1e-12 {
                // At rest at a run's end: an exact stop, the window's end, or feed hold.
                // The next run starts on a later tick.
                if !self.pieces.is_empty() {
                    self.rest_here();
                }
                return Ok(());
            }
            if self.pieces.is_empty() {
                // Moving at the window's end cannot happen (its bound is 0).
                return Err(ContourError::NoProfile);
            }
            self.start_run(0.0, v0)?;
            self.t = leftover;
        }
    }

    /// At rest on the front piece: nothing beyond it is committed.
    fn rest_here(&mut self) {
        self.mode = Mode::Resting;
        self.run_pieces = 1;
        self.v_end = 0.0;
    }

    /// Moves the pieces the path has passed within the run out of the window.
    fn pass_boundaries(&mut self) {
        while self.run_pieces > 1 {
            let Some(length) = self.pieces.front().map(|p| p.length) else {
                return;
            };
            if self.state.position <= length {
                return;
            }
            self.pop_piece();
            self.offset -= length;
            self.state.position -= length;
            self.run_pieces -= 1;
        }
    }

    /// The front piece is done; at the end of the window, where the path stands is kept.
    fn pop_piece(&mut self) {
        if let Some(p) = self.pieces.pop_front() {
            if !p.is_curve() {
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
    }

    /// New blocks or factors: the run is planned again where the profile has no acceleration
    /// (on its cruise, or at its peak or the cruise's end passed during this tick), from
    /// there to the end of the front's unit as it now is. A plan that does not fit keeps the
    /// one under way (its bounds still hold). Whether a new plan took its place.
    fn replan_on_the_way(&mut self, before: f64) -> bool {
        let (start, end) = self.profile.cruise();
        let at = if self.t >= start && self.t <= end {
            self.t
        } else if before < end && end <= self.t {
            end
        } else {
            return false;
        };
        self.replan = false;
        let s = self.profile.at(at);
        let here = self.offset + s.position;
        let last = self.unit_end(0);
        if let Some((profile, v1, pieces, rest)) = self.plan_run(here, s.velocity, last) {
            // Never an end velocity above what the look-ahead can still brake from.
            if v1 <= self.pieces[last].bound_hard {
                self.adopt(profile, v1, pieces, rest, here);
                self.t -= at;
                return true;
            }
        }
        false
    }

    /// Between ticks, while the run under way cruises (no acceleration where it stands): the
    /// run planned again from there over the window as it now is ([`Self::replan_on_the_way`]
    /// at the present time). Whether a new plan, ending within its bound, took its place.
    pub(super) fn replan_now(&mut self) -> bool {
        matches!(self.mode, Mode::Profile) && self.replan_on_the_way(self.t)
    }

    /// At rest on the front piece: goes on once the factors let it.
    fn resume(&mut self) -> Result<(), ContourError> {
        let moving = self.factors.0 > 0.0 || self.factors.1 > 0.0;
        if !moving {
            return Ok(());
        }
        let here = self.state.position;
        self.start_run(here, 0.0)?;
        self.advance_profile()
    }
}

/// A segment's length in X, Y, Z and its direction per unit of that length; `None` when it
/// does not move X, Y or Z.
fn direction(segment: &Segment) -> Option<(f64, AxisValues)> {
    let mut dir = segment.end;
    for (i, d) in dir.iter_mut().enumerate() {
        *d -= segment.start[i];
    }
    let length = dir.iter().take(3).map(|d| d * d).sum::<f64>().sqrt();
    if length <= 1e-9 || !length.is_finite() {
        return None;
    }
    dir.iter_mut().for_each(|d| *d /= length);
    Some((length, dir))
}

/// Copies the block's feed, mode and line onto a piece.
fn tag(piece: &mut Piece, segment: &Segment) {
    piece.feed = segment.feed;
    piece.rapid = segment.rapid;
    piece.line = segment.line;
    piece.on_arc = segment.on_arc;
}
