//! Motion functions: points joined by motion laws (seed chapter 3).
//!
//! A point carries the master and slave position, its type (rest, velocity, turn, motion or
//! ignore), its boundary values and the law of the segment that starts at it. Loading checks
//! the points, drops the ignored ones, settles the boundary values every point ends up with
//! (point type, user values and what neighbouring laws fix, in that order of authority) and
//! builds each segment's pieces once. Evaluation is then a lookup and a closed formula.

use super::error::{CamError, Demand, Field};
use super::law::{self, EndKind, EndState, FunctionType, SegmentSpec};
use super::piece::Piece;
use super::Sample;

/// `MC_MotionPointType`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PointType {
    /// 0x0000: the point takes no part; the segments close over it.
    Ignore,
    /// 0x0001: velocity and acceleration zero.
    Rest,
    /// 0x0002: acceleration zero, the velocity given.
    Velocity,
    /// 0x0004: velocity zero, the acceleration given.
    Turn,
    /// 0x0008: velocity, acceleration and jerk given.
    Motion,
}

impl PointType {
    /// The seed's numeric value.
    pub fn raw(self) -> u32 {
        match self {
            PointType::Ignore => 0x0000,
            PointType::Rest => 0x0001,
            PointType::Velocity => 0x0002,
            PointType::Turn => 0x0004,
            PointType::Motion => 0x0008,
        }
    }

    /// From the seed's numeric value.
    pub fn from_raw(raw: u32) -> Option<PointType> {
        PointType::all().iter().copied().find(|t| t.raw() == raw)
    }

    /// Every point type.
    pub fn all() -> &'static [PointType] {
        &[
            PointType::Ignore,
            PointType::Rest,
            PointType::Velocity,
            PointType::Turn,
            PointType::Motion,
        ]
    }

    /// The seed's name without the `MOTIONPOINTTYPE_` prefix.
    pub fn name(self) -> &'static str {
        match self {
            PointType::Ignore => "IGNORE",
            PointType::Rest => "REST",
            PointType::Velocity => "VELOCITY",
            PointType::Turn => "TURN",
            PointType::Motion => "MOTION",
        }
    }

    /// From a name (with or without the `MOTIONPOINTTYPE_` prefix) or a number.
    pub fn from_name(name: &str) -> Option<PointType> {
        let upper = name.trim().to_ascii_uppercase();
        let bare = upper.strip_prefix("MOTIONPOINTTYPE_").unwrap_or(&upper);
        if let Ok(raw) = bare.parse::<u32>() {
            return PointType::from_raw(raw);
        }
        PointType::all().iter().copied().find(|t| t.name() == bare)
    }
}

/// `MC_MotionFunctionPoint` with the function and point type still raw, as a PLC or a file
/// hands them over.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionFunctionPoint {
    /// Absolute index, 1, 2, 3, ...
    pub index: u32,
    /// Raw `MC_MotionFunctionType` of the segment that starts here.
    pub function: u32,
    /// Raw `MC_MotionPointType`.
    pub point_type: u32,
    /// Relative index of the next point (0 means 1).
    pub rel_index_next: i64,
    /// Master position.
    pub master: f64,
    /// Slave position.
    pub slave: f64,
    /// Slave velocity (per master unit).
    pub velocity: f64,
    /// Slave acceleration.
    pub acceleration: f64,
    /// Slave jerk, or the segment's symmetry for laws that have one.
    pub jerk: f64,
}

impl MotionFunctionPoint {
    /// A point with typed function and point type.
    pub fn new(
        index: u32,
        function: FunctionType,
        point_type: PointType,
        master: f64,
        slave: f64,
    ) -> MotionFunctionPoint {
        MotionFunctionPoint {
            index,
            function: function.raw(),
            point_type: point_type.raw(),
            rel_index_next: 0,
            master,
            slave,
            velocity: 0.0,
            acceleration: 0.0,
            jerk: 0.0,
        }
    }
}

/// A segment of a built function.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// The point the segment starts at (its index).
    pub from_point: u32,
    /// The point it ends at.
    pub to_point: u32,
    /// Its law.
    pub law: FunctionType,
    /// Settled boundary values at the start.
    pub start: EndState,
    /// Settled boundary values at the end.
    pub end: EndState,
    /// Master range in the original direction.
    pub master: (f64, f64),
    /// Its pieces: indices into the function's piece list.
    pub pieces: std::ops::Range<usize>,
}

/// A checked motion function, ready to evaluate.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionFunction {
    points: Vec<MotionFunctionPoint>,
    segments: Vec<Segment>,
    /// Pieces over the rising master coordinate `sign * x`.
    pieces: Vec<Piece>,
    /// +1 for rising master positions, -1 for falling ones.
    sign: f64,
}

/// Where evaluation found its piece last time; evaluating a sweeping master from the same
/// cursor costs O(1) per call.
#[derive(Debug, Clone, Copy, Default)]
pub struct Cursor {
    index: usize,
}

impl Cursor {
    /// A cursor at the start.
    pub fn new() -> Cursor {
        Cursor::default()
    }
}

const TOLERANCE: f64 = 1e-9;

fn agree(a: f64, b: f64) -> bool {
    (a - b).abs() <= TOLERANCE * (1.0 + a.abs().max(b.abs()))
}

/// What is known of one quantity at a point while settling it.
#[derive(Debug, Clone, Copy)]
enum Known {
    /// Fixed by the point type.
    Fixed(f64),
    /// Given by the user, replaceable by a law's demand.
    User(f64),
    /// Demanded by a neighbouring law.
    Demanded(f64),
}

impl Known {
    fn value(self) -> f64 {
        match self {
            Known::Fixed(v) | Known::User(v) | Known::Demanded(v) => v,
        }
    }

    fn demand(&mut self, value: f64, by: Demand, point: u32, field: Field) -> Result<(), CamError> {
        match *self {
            Known::User(_) => {
                *self = Known::Demanded(value);
                Ok(())
            }
            Known::Fixed(other) | Known::Demanded(other) if agree(value, other) => Ok(()),
            Known::Fixed(other) | Known::Demanded(other) => Err(CamError::BoundaryConflict {
                point,
                field,
                demanded: value,
                by,
                other,
            }),
        }
    }
}

impl MotionFunction {
    /// Checks the points and builds the function. `Err` names the first offending point.
    pub fn new(points: &[MotionFunctionPoint]) -> Result<MotionFunction, CamError> {
        if points.is_empty() {
            return Err(CamError::TooFewPoints { active: 0 });
        }
        let kept = kept_points(points)?;
        if kept.len() < 2 {
            return Err(CamError::TooFewPoints { active: kept.len() });
        }
        let active = with_laws(&kept)?;
        let sign = if active[1].0.master > active[0].0.master {
            1.0
        } else {
            -1.0
        };
        check_monotonic(&active, sign)?;
        let ends = settle(&active, sign)?;
        let (pieces, segments) = build_segments(&active, sign, &ends)?;
        Ok(MotionFunction {
            points: points.to_vec(),
            segments,
            pieces,
            sign,
        })
    }

    /// The points as given (ignored ones included).
    pub fn points(&self) -> &[MotionFunctionPoint] {
        &self.points
    }

    /// The segments between active points.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// The pieces of one of this function's segments.
    pub fn segment_pieces(&self, segment: &Segment) -> &[Piece] {
        &self.pieces[segment.pieces.clone()]
    }

    /// First and last master position (in the function's own direction).
    pub fn master_range(&self) -> (f64, f64) {
        (
            self.segments[0].master.0,
            self.segments[self.segments.len() - 1].master.1,
        )
    }

    /// Slave position and derivatives at master position `x`; outside the range the slave
    /// holds the end position with zero derivatives.
    #[inline]
    pub fn eval(&self, x: f64, cursor: &mut Cursor) -> Sample {
        let xr = self.sign * x;
        let first = &self.pieces[0];
        let last = &self.pieces[self.pieces.len() - 1];
        if xr < first.start {
            return Sample::at_rest(first.eval(first.start)[0]);
        }
        if xr > last.end {
            return Sample::at_rest(self.end_position());
        }
        let i = locate(&self.pieces, xr, cursor.index);
        cursor.index = i;
        let d = self.pieces[i].eval(xr);
        let y = if xr == last.end {
            self.end_position()
        } else {
            d[0]
        };
        Sample {
            position: y,
            velocity: self.sign * d[1],
            acceleration: d[2],
            jerk: self.sign * d[3],
        }
    }

    fn end_position(&self) -> f64 {
        self.segments[self.segments.len() - 1].end.y
    }

    /// The pieces with their master ranges in the original direction, each with a function
    /// that evaluates it (value and four derivatives), for characteristic values.
    pub(crate) fn for_each_piece(&self, f: &mut super::PieceVisitor<'_>) {
        let s = self.sign;
        let mut ordered: Vec<&Piece> = self.pieces.iter().collect();
        if s < 0.0 {
            ordered.reverse();
        }
        for p in ordered {
            let eval = move |x: f64| {
                let d = p.eval(s * x);
                [d[0], s * d[1], d[2], s * d[3], d[4]]
            };
            let (a, b) = (s * p.start, s * p.end);
            f(a.min(b), a.max(b), &eval);
        }
    }
}

/// The points in order with their types, checked (index, type, finite values, relative
/// index); an IGNORE point takes no part beyond its index and type.
fn kept_points(
    points: &[MotionFunctionPoint],
) -> Result<Vec<(MotionFunctionPoint, PointType)>, CamError> {
    let mut kept: Vec<(MotionFunctionPoint, PointType)> = Vec::new();
    for (i, p) in points.iter().enumerate() {
        let expected = 1 + i as u32;
        if p.index != expected {
            return Err(CamError::PointIndex {
                found: p.index,
                expected,
            });
        }
        let point_type = PointType::from_raw(p.point_type).ok_or(CamError::UnknownPointType {
            point: p.index,
            raw: p.point_type,
        })?;
        if point_type == PointType::Ignore {
            continue;
        }
        for (value, field) in [
            (p.master, Field::Master),
            (p.slave, Field::Slave),
            (p.velocity, Field::Velocity),
            (p.acceleration, Field::Acceleration),
            (p.jerk, Field::Jerk),
        ] {
            if !value.is_finite() {
                return Err(CamError::PointNotFinite {
                    point: p.index,
                    field,
                });
            }
        }
        check_rel_index(points, i)?;
        kept.push((*p, point_type));
    }
    Ok(kept)
}

/// The active points with the law each starts: every active point but the last starts a
/// segment, its law must be known; the last one's function type is not used.
fn with_laws(
    kept: &[(MotionFunctionPoint, PointType)],
) -> Result<Vec<(MotionFunctionPoint, FunctionType, PointType)>, CamError> {
    let mut active: Vec<(MotionFunctionPoint, FunctionType, PointType)> =
        Vec::with_capacity(kept.len());
    for (k, (p, point_type)) in kept.iter().enumerate() {
        let function = match FunctionType::from_raw(p.function) {
            Some(f) => f,
            None if k + 1 == kept.len() => FunctionType::Polynom1,
            None => {
                return Err(CamError::UnknownFunctionType {
                    point: p.index,
                    raw: p.function,
                })
            }
        };
        active.push((*p, function, *point_type));
    }
    Ok(active)
}

/// The master positions run strictly in the direction `sign`.
fn check_monotonic(
    active: &[(MotionFunctionPoint, FunctionType, PointType)],
    sign: f64,
) -> Result<(), CamError> {
    for w in active.windows(2) {
        // Finite by now: a plain comparison is exact.
        if (w[1].0.master - w[0].0.master) * sign <= 0.0 {
            return Err(CamError::MasterNotMonotonic {
                point: w[1].0.index,
                master: w[1].0.master,
                previous: w[0].0.master,
            });
        }
    }
    Ok(())
}

/// The pieces of every segment between active points, built from the settled `ends`, and
/// the segments over them.
fn build_segments(
    active: &[(MotionFunctionPoint, FunctionType, PointType)],
    sign: f64,
    ends: &[EndState],
) -> Result<(Vec<Piece>, Vec<Segment>), CamError> {
    let mut pieces = Vec::new();
    let mut segments = Vec::new();
    for (k, w) in active.windows(2).enumerate() {
        let (p, law, _) = w[0];
        let q = w[1].0;
        let symmetry = if law.has_symmetry() { p.jerk } else { 0.0 };
        if law.has_symmetry() && symmetry.abs() >= 0.5 {
            return Err(CamError::Symmetry {
                point: p.index,
                value: p.jerk,
            });
        }
        let spec = SegmentSpec {
            law,
            x0: sign * p.master,
            x1: sign * q.master,
            start: ends[k],
            end: ends[k + 1],
            symmetry,
        };
        let built = law::build(&spec).ok_or(CamError::Unbuildable { point: p.index })?;
        let first = pieces.len();
        pieces.extend(built);
        segments.push(Segment {
            from_point: p.index,
            to_point: q.index,
            law,
            start: unflip(ends[k], sign),
            end: unflip(ends[k + 1], sign),
            master: (p.master, q.master),
            pieces: first..pieces.len(),
        });
    }
    Ok((pieces, segments))
}

fn unflip(e: EndState, sign: f64) -> EndState {
    EndState {
        y: e.y,
        v: sign * e.v,
        a: e.a,
        j: sign * e.j,
    }
}

/// The piece that holds `x`, starting the search at `hint` (pieces are `[start, end)`).
#[inline]
fn locate(pieces: &[Piece], x: f64, hint: usize) -> usize {
    let n = pieces.len();
    let mut i = hint.min(n - 1);
    // A few steps cover a sweeping master; a jump falls back to bisection.
    for _ in 0..4 {
        if x < pieces[i].start && i > 0 {
            i -= 1;
        } else if x >= pieces[i].end && i + 1 < n {
            i += 1;
        } else {
            return i;
        }
    }
    pieces.partition_point(|p| p.end <= x).min(n - 1)
}

/// The relative index of an active point must reach the next active point over ignored ones
/// only (0 means 1); the last active point's relative index is not used.
fn check_rel_index(points: &[MotionFunctionPoint], i: usize) -> Result<(), CamError> {
    let p = &points[i];
    let Some(next_active) = points[i + 1..]
        .iter()
        .position(|q| q.point_type != PointType::Ignore.raw())
    else {
        return Ok(());
    };
    let rel = if p.rel_index_next == 0 {
        1
    } else {
        p.rel_index_next
    };
    // Relative indices may name the next point or an ignored one before the next active one;
    // either way the chain continues at the next active point.
    if rel >= 1 && rel <= next_active as i64 + 1 {
        Ok(())
    } else {
        Err(CamError::RelIndex {
            point: p.index,
            rel: p.rel_index_next,
        })
    }
}

/// Settles position, velocity, acceleration and jerk at every active point in the rising
/// master coordinate (velocity and jerk change sign with the direction).
fn settle(
    active: &[(MotionFunctionPoint, FunctionType, PointType)],
    sign: f64,
) -> Result<Vec<EndState>, CamError> {
    let mut known = Settling::at_points(active, sign);
    // Velocities (and the line's zero jerk) do not depend on anything else.
    known.law_ends(active, sign)?;
    // Turn ends produce their acceleration from the settled velocities.
    known.turn_ends(active, sign)?;
    Ok((0..active.len())
        .map(|k| EndState {
            y: active[k].0.slave,
            v: known.v[k].value(),
            a: known.a[k].value(),
            j: known.j[k].value(),
        })
        .collect())
}

/// Velocity, acceleration and jerk at each active point while they are settled.
struct Settling {
    v: Vec<Known>,
    a: Vec<Known>,
    j: Vec<Known>,
}

impl Settling {
    /// What each point's type fixes and its user values give.
    fn at_points(active: &[(MotionFunctionPoint, FunctionType, PointType)], sign: f64) -> Self {
        let n = active.len();
        let mut v = Vec::with_capacity(n);
        let mut a = Vec::with_capacity(n);
        let mut j = Vec::with_capacity(n);
        for (k, (p, _, ty)) in active.iter().enumerate() {
            // The jerk field of a point that starts a law with symmetry is that symmetry.
            let starts_symmetric = k + 1 < n && active[k].1.has_symmetry();
            let user_jerk = if starts_symmetric { 0.0 } else { sign * p.jerk };
            let (kv, ka, kj) = match ty {
                PointType::Rest => (Known::Fixed(0.0), Known::Fixed(0.0), Known::Fixed(0.0)),
                PointType::Velocity => (
                    Known::User(sign * p.velocity),
                    Known::Fixed(0.0),
                    Known::Fixed(0.0),
                ),
                PointType::Turn => (
                    Known::Fixed(0.0),
                    Known::User(p.acceleration),
                    Known::User(user_jerk),
                ),
                _ => (
                    Known::User(sign * p.velocity),
                    Known::User(p.acceleration),
                    Known::User(user_jerk),
                ),
            };
            v.push(kv);
            a.push(ka);
            j.push(kj);
        }
        Settling { v, a, j }
    }

    /// What each segment's law demands at its ends: a line its slope and no acceleration or
    /// jerk, rest and turn ends no velocity, velocity ends no acceleration, rest ends no
    /// acceleration (but the 3rd-order polynomial's).
    fn law_ends(
        &mut self,
        active: &[(MotionFunctionPoint, FunctionType, PointType)],
        sign: f64,
    ) -> Result<(), CamError> {
        let (v, a, j) = (&mut self.v, &mut self.a, &mut self.j);
        for k in 0..active.len() - 1 {
            let (p, law, _) = active[k];
            let q = active[k + 1].0;
            let (start, end) = law.ends();
            let slope = (q.slave - p.slave) / (sign * (q.master - p.master));
            for (kind, at, by) in [
                (start, k, Demand::SegmentAfter),
                (end, k + 1, Demand::SegmentBefore),
            ] {
                let point = active[at].0.index;
                match kind {
                    EndKind::Line => {
                        v[at].demand(slope, by, point, Field::Velocity)?;
                        a[at].demand(0.0, by, point, Field::Acceleration)?;
                        j[at].demand(0.0, by, point, Field::Jerk)?;
                    }
                    EndKind::Rest | EndKind::Turn => {
                        v[at].demand(0.0, by, point, Field::Velocity)?
                    }
                    EndKind::Velocity => a[at].demand(0.0, by, point, Field::Acceleration)?,
                    EndKind::Motion => {}
                }
                // A 3rd-order polynomial cannot also end with zero acceleration (seed: it is a
                // rest-to-rest law all the same); every other rest end demands it.
                if kind == EndKind::Rest && law != FunctionType::Polynom3 {
                    a[at].demand(0.0, by, point, Field::Acceleration)?;
                }
            }
        }
        Ok(())
    }

    /// The acceleration a turn end produces, from the law built on the settled velocities.
    fn turn_ends(
        &mut self,
        active: &[(MotionFunctionPoint, FunctionType, PointType)],
        sign: f64,
    ) -> Result<(), CamError> {
        let (v, a) = (&self.v, &mut self.a);
        for k in 0..active.len() - 1 {
            let (p, law, _) = active[k];
            let q = active[k + 1].0;
            let (start, end) = law.ends();
            if start != EndKind::Turn && end != EndKind::Turn {
                continue;
            }
            let state = |at: usize, y: f64| EndState {
                y,
                v: v[at].value(),
                a: 0.0,
                j: 0.0,
            };
            let spec = SegmentSpec {
                law,
                x0: sign * p.master,
                x1: sign * q.master,
                start: state(k, p.slave),
                end: state(k + 1, q.slave),
                symmetry: 0.0,
            };
            let pieces = law::build(&spec).ok_or(CamError::Unbuildable { point: p.index })?;
            if start == EndKind::Turn {
                let acc = pieces[0].eval(spec.x0)[2];
                a[k].demand(acc, Demand::SegmentAfter, p.index, Field::Acceleration)?;
            }
            if end == EndKind::Turn {
                let last = &pieces[pieces.len() - 1];
                let acc = last.eval(spec.x1)[2];
                a[k + 1].demand(acc, Demand::SegmentBefore, q.index, Field::Acceleration)?;
            }
        }
        Ok(())
    }
}
