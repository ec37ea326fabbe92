//! Planning units: consecutive pieces with similar caps and dynamics (the curves of a dense
//! polyline, a long straight's parts) are planned as one unit, so the path parameter's
//! acceleration carries through their boundaries; a unit's caps and dynamics are the lowest
//! of its pieces'. The look-ahead's bounds and the runs along the path both go unit by unit.

use super::profile::{self, max_reach, min_reach, Dynamics};
use super::{Contour, Piece};

/// Pieces whose velocity caps are within this ratio of each other may share a unit.
const CAP_RATIO: f64 = 1.25;
/// Pieces whose acceleration and jerk limits are within this ratio may share a unit.
const DYNAMICS_RATIO: f64 = 2.0;

/// A unit's lowest caps and dynamics, and its length.
#[derive(Debug, Clone, Copy)]
pub(super) struct Unit {
    pub cap_hard: f64,
    pub cap_soft: f64,
    pub dynamics: Dynamics,
    pub length: f64,
}

/// Whether `b`, coming after `a`, may be planned in one unit with it.
pub(super) fn similar(a: &Piece, b: &Piece) -> bool {
    let key = |p: &Piece| {
        if p.rapid {
            p.hard_cap
        } else {
            p.hard_cap.min(p.feed)
        }
    };
    let close = |x: f64, y: f64, r: f64| x <= y * r && y <= x * r;
    let (da, db) = (a.dynamics, b.dynamics);
    if a.length <= 1e-9 {
        // A straight piece the corners took all of.
        return a.rapid == b.rapid;
    }
    a.rapid == b.rapid
        && close(key(a), key(b), CAP_RATIO)
        && close(da.acceleration, db.acceleration, DYNAMICS_RATIO)
        && close(da.jerk, db.jerk, DYNAMICS_RATIO)
}

/// The bounds the group after the one being swept hands back to it.
#[derive(Clone, Copy)]
struct Right {
    hard: f64,
    soft: f64,
    unit: Unit,
}

impl Contour {
    /// Whether piece `i` is planned in one unit with piece `i - 1`. The window's last piece is
    /// a unit of its own until the window closes and an arc's last chord has joined: the next
    /// block or chord may still shorten it.
    pub(super) fn joins(&self, i: usize) -> bool {
        i > 0
            && i < self.pieces.len()
            && self.pieces[i].chain
            && !self.pieces[i - 1].rest_after
            && ((self.closed && self.arc.is_none()) || i + 1 < self.pieces.len())
    }

    /// The last piece of the unit that piece `i` belongs to.
    pub(super) fn unit_end(&self, i: usize) -> usize {
        let mut e = i;
        while self.joins(e + 1) {
            e += 1;
        }
        e
    }

    /// Pieces `start..=end` as one unit under the factors in effect.
    pub(super) fn unit(&self, start: usize, end: usize) -> Unit {
        let (ff, rf) = self.factors;
        let mut u = Unit {
            cap_hard: f64::INFINITY,
            cap_soft: f64::INFINITY,
            dynamics: Dynamics {
                acceleration: f64::INFINITY,
                jerk: f64::INFINITY,
            },
            length: 0.0,
        };
        for p in self.pieces.range(start..=end) {
            u.cap_hard = u.cap_hard.min(p.hard_cap);
            u.cap_soft = u.cap_soft.min(p.soft_cap(ff, rf));
            u.dynamics.acceleration = u.dynamics.acceleration.min(p.dynamics.acceleration);
            u.dynamics.jerk = u.dynamics.jerk.min(p.dynamics.jerk);
            u.length += p.length;
        }
        u.cap_soft = u.cap_soft.min(u.cap_hard);
        u
    }

    /// Recomputes the look-ahead bounds unit by unit from the window's end, stopping at a unit
    /// before the last pushed pieces whose bounds did not change. The bound at a piece's end
    /// is the highest velocity from which the path can still come to rest at the end of the
    /// window, within every cap on the way: inside a unit one velocity change to the bound at
    /// its end, at a unit's end the bound the next unit allows at its start.
    pub(super) fn sweep_back(&mut self) {
        let n = self.pieces.len();
        if n == 0 {
            return;
        }
        let mut right: Option<Right> = None;
        let mut end = n - 1;
        loop {
            let mut start = end;
            while self.joins(start) {
                start -= 1;
            }
            let unit = self.unit(start, end);
            let (end_hard, end_soft) = match right {
                None => (0.0, 0.0),
                Some(_) if self.pieces[end].rest_after => (0.0, 0.0),
                Some(r) => {
                    let cap_hard = unit.cap_hard.min(r.unit.cap_hard);
                    let cap_soft = unit.cap_soft.min(r.unit.cap_soft).min(cap_hard);
                    let d = r.unit.dynamics;
                    (
                        max_reach(r.hard, r.unit.length, cap_hard, d),
                        max_reach(r.soft, r.unit.length, cap_soft, d).min(cap_soft),
                    )
                }
            };
            let mut changed = self.set_bounds(end, end_hard, end_soft);
            let (mut dist, mut capped) = (0.0, false);
            for k in (start..end).rev() {
                dist += self.pieces[k + 1].length;
                let d = unit.dynamics;
                // Farther from the unit's end the bounds only grow: once at the caps, the
                // pieces before are at them too.
                let (hard, soft) = if capped {
                    (unit.cap_hard, unit.cap_soft)
                } else {
                    let hard = max_reach(end_hard, dist, unit.cap_hard, d);
                    let soft = max_reach(end_soft, dist, unit.cap_soft, d).min(unit.cap_soft);
                    capped = hard >= unit.cap_hard && soft >= unit.cap_soft;
                    (hard, soft)
                };
                changed |= self.set_bounds(k, hard, soft);
            }
            if start == 0 || (!changed && end + 4 < n) {
                return;
            }
            right = Some(Right {
                hard: end_hard,
                soft: end_soft,
                unit,
            });
            end = start - 1;
        }
    }

    /// Sets piece `k`'s bounds; whether they changed.
    fn set_bounds(&mut self, k: usize, hard: f64, soft: f64) -> bool {
        let p = &mut self.pieces[k];
        let unchanged = p.bound_hard == hard && p.bound_soft == soft;
        p.bound_hard = hard;
        p.bound_soft = soft;
        !unchanged
    }
}

/// The end velocity of a run entered at `v0` with `rest` of it to go, within `d` and the
/// bounds at its end: the highest its length allows within the soft bound, at least the
/// lowest braking reaches, at most the hard bound, and always one the length can reach.
/// Braking part of the way can take longer than braking to rest (the distance
/// `(v0 + v) T(v0 - v) / 2` first grows as `v` falls from `v0`, then shrinks), so a velocity
/// between the bounds may not fit: then the highest below it that does, or the hard bound
/// (which the look-ahead made reachable from every entry velocity up to the one before's hard
/// bound).
pub(super) fn feasible_end(v0: f64, rest: f64, d: Dynamics, soft: f64, hard: f64) -> f64 {
    let fits = |v: f64| profile::change_distance(v0, v, d) <= rest * (1.0 + 1e-12) + 1e-15;
    let reach_low = min_reach(v0, rest, d);
    let reach_soft = max_reach(v0, rest, soft.max(0.0), d);
    let v1 = reach_soft.max(reach_low).min(hard.max(reach_low));
    if fits(v1) {
        return v1;
    }
    if fits(0.0) {
        // Between 0 (fits) and v1 (does not): the highest that fits.
        return profile::bisect(0.0, v1, fits);
    }
    v0.min(hard)
}
