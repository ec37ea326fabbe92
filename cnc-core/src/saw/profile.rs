//! A synchronising phase: up to three pieces over master travel (position-based) or time
//! (time-based), how it is evaluated in the tick, and its characteristic values
//! (`MC_FlyingSawCharacValues`) for a master at constant velocity.

use crate::cam::charac::{bisect, Extreme};
use crate::cam::piece::Piece;
use crate::cam::CharacValues;
use crate::setpoint::Kinematic;

/// What the pieces are a function of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Domain {
    /// Master travel `tau = (m - m0) * dir` from the coupling position (`dir` = the master's
    /// direction at coupling, +1 or -1); slope is slave units per master unit of travel.
    Master {
        /// Master position at coupling.
        m0: f64,
        /// +1 or -1.
        dir: f64,
    },
    /// Time since coupling, s.
    Time,
}

/// Which polynomials make the phase (the seed's names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// The slave is on the synchronous line already: no synchronising phase.
    Immediate,
    /// One 5th-order polynomial.
    P5,
    /// Constant velocity, then a 5th-order polynomial (velocity overshoot-free).
    P1P5,
    /// A 5th-order polynomial, then constant (sync) velocity (velocity overshoot-free).
    P5P1,
    /// Polynomial, constant velocity, polynomial.
    P5P1P5,
    /// Time-based: jerk-limited phases of constant jerk.
    JerkLimited,
    /// A stop after a rollback: the velocity taken to 0.
    Stop,
}

/// The synchronising phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    pieces: [Piece; 3],
    count: usize,
    /// What the pieces are a function of.
    pub domain: Domain,
    /// Which polynomials.
    pub shape: Shape,
    /// Length of the phase in its domain (master travel or time); 0 for `Immediate`.
    pub length: f64,
}

impl Profile {
    /// A phase from pieces that join and start at 0 of the domain (at least one: an
    /// `Immediate` phase is one piece of length 0 holding the start).
    pub fn new(domain: Domain, shape: Shape, pieces: &[Piece]) -> Profile {
        let mut store = [Piece::poly(0.0, 0.0, &[0.0]); 3];
        let pieces = &pieces[..pieces.len().min(3)];
        store[..pieces.len()].copy_from_slice(pieces);
        let length = pieces.last().map_or(0.0, |p| p.end);
        Profile {
            pieces: store,
            count: pieces.len(),
            domain,
            shape,
            length,
        }
    }

    /// The pieces.
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces[..self.count]
    }

    /// Value and derivatives 1..4 at `x` of the domain (clamped to the phase).
    #[inline]
    pub fn eval(&self, x: f64) -> [f64; 5] {
        let x = x.clamp(0.0, self.length);
        // The first piece that reaches x, else the last (at least the first slot).
        let pieces = &self.pieces[..self.count.max(1)];
        let last = pieces.len() - 1;
        let i = pieces.iter().position(|p| x <= p.end).unwrap_or(last);
        pieces[i].eval(x)
    }

    /// The slave set-point at the master set-point `m` (position-based) or at time `t`
    /// (time-based): the chain rule turns slope and curvature into velocity, acceleration
    /// and jerk with the master's actual motion.
    #[inline]
    pub fn slave_at(&self, m: &Kinematic, t: f64) -> Kinematic {
        match self.domain {
            Domain::Master { m0, dir } => {
                let d = self.eval((m.position - m0) * dir);
                let (v, a, j) = (m.velocity * dir, m.acceleration * dir, m.jerk * dir);
                Kinematic {
                    position: d[0],
                    velocity: d[1] * v,
                    acceleration: d[2] * v * v + d[1] * a,
                    jerk: d[3] * v * v * v + 3.0 * d[2] * v * a + d[1] * j,
                }
            }
            Domain::Time => {
                let d = self.eval(t);
                Kinematic {
                    position: d[0],
                    velocity: d[1],
                    acceleration: d[2],
                    jerk: d[3],
                }
            }
        }
    }

    /// The slave's position, velocity, acceleration and jerk over time at the end of the
    /// phase for a master at constant velocity `vm`.
    pub fn end_state(&self, vm: f64) -> [f64; 4] {
        let d = self.eval(self.length);
        to_time(self.domain, &d, vm)
    }
}

/// Derivatives in the domain to derivatives in time for a master at constant `vm`.
fn to_time(domain: Domain, d: &[f64; 5], vm: f64) -> [f64; 4] {
    match domain {
        Domain::Master { .. } => {
            let w = vm.abs();
            [d[0], d[1] * w, d[2] * w * w, d[3] * w * w * w]
        }
        Domain::Time => [d[0], d[1], d[2], d[3]],
    }
}

/// Characteristic values of a phase and the two acceleration peaks the checks need.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Charac {
    /// `MC_FlyingSawCharacValues` fields 1-31 (the unsupported ones 0, as in the seed).
    pub values: CharacValues,
    /// Largest |acceleration| while the slave speeds up (|v| grows; v = 0 counts).
    pub speed_up: f64,
    /// Largest |acceleration| while the slave slows down (|v| shrinks; v = 0 counts).
    pub slow_down: f64,
}

/// Samples per piece before the sign changes are bisected.
const SAMPLES: usize = 24;

struct Scan {
    lo: [Option<Extreme>; 4],
    hi: [Option<Extreme>; 4],
    speed_up: f64,
    slow_down: f64,
}

impl Scan {
    fn note(&mut self, m: f64, s: &[f64; 4]) {
        for k in 0..4 {
            let e = Extreme {
                value: s[k],
                at: m,
                velocity: s[1],
            };
            if self.lo[k].is_none_or(|x| s[k] < x.value) {
                self.lo[k] = Some(e);
            }
            if self.hi[k].is_none_or(|x| s[k] > x.value) {
                self.hi[k] = Some(e);
            }
        }
        let (v, a) = (s[1], s[2]);
        let scale = 1e-12 * (1.0 + v.abs());
        if v.abs() <= scale || v * a > 0.0 {
            self.speed_up = self.speed_up.max(a.abs());
        }
        if v.abs() <= scale || v * a < 0.0 {
            self.slow_down = self.slow_down.max(a.abs());
        }
    }
}

impl Profile {
    /// The characteristic values for a master at constant velocity `vm` from `m0`, the
    /// slave at `s0` when the phase is empty. Extremes inside a piece are found where the
    /// next derivative changes sign (sampled, then bisected to machine precision).
    pub fn charac(&self, m0: f64, vm: f64, slave: [f64; 4]) -> Charac {
        let mut scan = Scan {
            lo: [None; 4],
            hi: [None; 4],
            speed_up: 0.0,
            slow_down: 0.0,
        };
        // The master position belonging to a point of the domain.
        let master_at = |x: f64| match self.domain {
            Domain::Master { m0, dir } => m0 + dir * x,
            Domain::Time => m0 + vm * x,
        };
        let state = |piece: &Piece, x: f64| to_time(self.domain, &piece.eval(x), vm);
        for piece in self.pieces() {
            let (a, b) = (piece.start, piece.end);
            let mut prev_x = a;
            let mut prev = piece.eval(a);
            scan.note(master_at(a), &state(piece, a));
            for i in 1..=SAMPLES {
                let x = if i == SAMPLES {
                    b
                } else {
                    a + (b - a) * i as f64 / SAMPLES as f64
                };
                let d = piece.eval(x);
                scan.note(master_at(x), &state(piece, x));
                for k in 1..5 {
                    if prev[k] * d[k] < 0.0 {
                        let root = bisect(&|x| piece.eval(x), k, prev_x, x);
                        scan.note(master_at(root), &state(piece, root));
                    }
                }
                prev_x = x;
                prev = d;
            }
        }
        let (first, last) = if self.count == 0 {
            (slave, slave)
        } else {
            let p = self.pieces();
            (
                state(&p[0], p[0].start),
                state(&p[self.count - 1], p[self.count - 1].end),
            )
        };
        if self.count == 0 {
            scan.note(m0, &slave);
        }
        let values = CharacValues::from_extremes(
            vm,
            [m0, master_at(self.length)],
            first,
            last,
            scan.lo,
            scan.hi,
        );
        Charac {
            values,
            speed_up: scan.speed_up,
            slow_down: scan.slow_down,
        }
    }
}
