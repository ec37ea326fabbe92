//! The path interpolator of a channel: one block at a time, straight (G0/G1) or an arc
//! (G2/G3, helical when the plane's normal or other axes move too), all channel axes moving
//! together, with a jerk-limited velocity profile along the path.
//!
//! The profile runs the path parameter `s` from 0 to the block's length `L` with the set-point
//! generator of the axis layer (rsruckig: time-optimal, jerk-limited, at rest at both ends;
//! blocks do not blend). Every axis `i` then moves `Δ_i * s / L`, so its velocity,
//! acceleration and jerk are the path's times `|Δ_i| / L`. The path limits are therefore the
//! channel's per-axis limits scaled by `L / |Δ_i|`, the smallest over the moving axes, and for
//! G1 also the feed:
//!
//! * `L` is the length in X, Y, Z (mm) when they move, else the largest other move (degrees
//!   or mm), so a pure orientation or auxiliary-axis move runs at the feed in its own units;
//! * G1 caps the path velocity at `F` (mm/min -> mm/s); G0 runs at the axis limits.
//!
//! An arc runs its path parameter over the length of the helix. Every set-point lies on the
//! circle (the radius blends linearly from start to end when the end point was within the arc
//! tolerance of it), and the block ends exactly at its end point. Its path limits are the
//! smallest of the plane axes' (and the helix axis's share), taken at half for acceleration and
//! jerk because the turning adds as much again, and three arc limits:
//!
//! * centripetal acceleration `v²/r` within half the axes' acceleration;
//! * the jerk of turning, `v³/r²`, within half the axes' jerk;
//! * the chordal error: the straight line between two set-points strays from the arc by
//!   `r(1 - cos(vT/2r)) ≈ (vT)²/8r`, kept within the channel's chordal tolerance `e`:
//!   `v ≤ sqrt(8 r e) / T`.
//!
//! The channel owns one generator for its path and hands it to every block: building a
//! generator allocates (rsruckig's buffers), re-targeting one does not.
//!
//! The PLC's override acts on the block under way ([`PathMove::set_override`]): a new value
//! re-targets the generator from its current state to the block's end with the velocity
//! limit scaled (feed override on `F` for G1 and arcs, capped by the axes' and the arc's own
//! limits; rapid override on the axis limits for G0), so the speed changes jerk-limited, never
//! by a step. Feed hold, or 0 %, brakes along the path with the block's deceleration and jerk
//! and keeps the block: a later value lets it go on to its end.

use crate::axis::generator::{MoveLimits, Progress, SetpointGenerator};
use crate::nc::arc::ArcMove;
use crate::nc::MotionMode;
use crate::setpoint::AxisValues;
use circle::Circle;

mod circle;
pub mod contour;

/// Per-axis dynamic limits of a channel's programmed coordinates (mm or degrees, per second).
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisLimits {
    /// Velocity.
    pub velocity: f64,
    /// Acceleration.
    pub acceleration: f64,
    /// Jerk.
    pub jerk: f64,
}

/// The limits of axis `i`, unlimited for an axis without any.
fn axis_limits(limits: &[AxisLimits], i: usize) -> AxisLimits {
    limits.get(i).copied().unwrap_or(AxisLimits {
        velocity: f64::INFINITY,
        acceleration: f64::INFINITY,
        jerk: f64::INFINITY,
    })
}

/// Lowers `path` to what every axis moving `delta` along a path of `length` allows: an axis
/// moving a share `|Δ|/L` of the path moves at that share of the path's velocity (and
/// acceleration and jerk).
fn limit_by_axes(path: &mut MoveLimits, delta: &[f64], length: f64, limits: &[AxisLimits]) {
    for (i, d) in delta.iter().enumerate() {
        let share = d.abs() / length;
        if share <= 1e-12 {
            continue;
        }
        let limit = axis_limits(limits, i);
        path.velocity = path.velocity.min(limit.velocity / share);
        path.acceleration = path.acceleration.min(limit.acceleration / share);
        path.jerk = path.jerk.min(limit.jerk / share);
    }
}

/// Runs the path parameter from 0 to `length` on `generator` within `path` (decelerating as
/// it accelerates); no profile for limits that are not positive numbers.
fn start_profile(
    path: &mut MoveLimits,
    length: f64,
    generator: &mut SetpointGenerator,
) -> Result<(), PathError> {
    path.deceleration = path.acceleration;
    let finite = [path.velocity, path.acceleration, path.jerk]
        .iter()
        .all(|v| v.is_finite() && *v > 0.0);
    if !finite {
        return Err(PathError::NoProfile);
    }
    generator.hold(0.0);
    generator
        .move_to(length, *path)
        .map_err(|_| PathError::NoProfile)
}

/// How an arc block is to be run: the circle, the channel's cycle and chordal tolerance.
#[derive(Debug, Clone, Copy)]
pub struct ArcSpec {
    /// The decoded arc.
    pub arc: ArcMove,
    /// The channel's cycle (s).
    pub cycle_s: f64,
    /// The chordal tolerance (mm).
    pub chordal_tolerance: f64,
}

/// A block being interpolated.
#[derive(Debug)]
pub struct PathMove {
    start: AxisValues,
    delta: AxisValues,
    /// For an arc: the circle; `delta` then holds the linear part of the other axes.
    circle: Option<Circle>,
    /// The exact end point.
    end: AxisValues,
    length: f64,
    done: bool,
    /// Stopped by `brake`: the block ends where the path stands.
    braked: bool,
    /// The path limits the block was planned with.
    limits: MoveLimits,
    /// The velocity limit apart from the feed (axes; for an arc also its geometry).
    free_velocity: f64,
    /// `F` in path units per second; infinite for G0.
    feed: f64,
    /// The override factor in effect (1 at planning).
    factor: f64,
    /// Held by feed hold or 0 %: braking or standing, the block not ended.
    held: bool,
}

/// Why a block cannot be interpolated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PathError {
    /// No profile for the block (limits or length out of the generator's range).
    #[error("no velocity profile for the block")]
    NoProfile,
    /// A target is not finite.
    #[error("block target is not finite")]
    NotFinite,
}

impl PathMove {
    /// Plans the block from `start` to `target` (same axes) on `generator`, which runs the
    /// path parameter from 0; an arc with `arc`. `None` when nothing moves.
    pub fn plan(
        start: &AxisValues,
        target: &AxisValues,
        motion: MotionMode,
        feed_mm_min: f64,
        arc: Option<ArcSpec>,
        limits: &[AxisLimits],
        generator: &mut SetpointGenerator,
    ) -> Result<Option<Self>, PathError> {
        let mut delta = *start;
        for (i, d) in delta.iter_mut().enumerate() {
            *d = target[i] - start[i];
        }
        if delta.iter().any(|d| !d.is_finite()) {
            return Err(PathError::NotFinite);
        }
        if let Some(spec) = arc {
            return Self::plan_arc(start, target, delta, feed_mm_min, spec, limits, generator)
                .map(Some);
        }
        let xyz = delta.iter().take(3).map(|d| d * d).sum::<f64>().sqrt();
        let length = if xyz > 1e-12 {
            xyz
        } else {
            delta.iter().skip(3).fold(0.0f64, |m, d| m.max(d.abs()))
        };
        if length <= 1e-12 {
            return Ok(None);
        }
        let mut path = MoveLimits {
            velocity: f64::INFINITY,
            acceleration: f64::INFINITY,
            deceleration: f64::INFINITY,
            jerk: f64::INFINITY,
        };
        limit_by_axes(&mut path, &delta, length, limits);
        let feed = if motion == MotionMode::Linear {
            feed_mm_min / 60.0
        } else {
            f64::INFINITY
        };
        let geometry = (*start, delta, None, *target, length);
        Self::start(geometry, path, feed, generator).map(Some)
    }

    /// Caps `path` at the `feed` (path units/s) and starts the block's profile; the velocity
    /// limit without the feed is kept for the override.
    fn start(
        (start, delta, circle, end, length): (
            AxisValues,
            AxisValues,
            Option<Circle>,
            AxisValues,
            f64,
        ),
        mut path: MoveLimits,
        feed: f64,
        generator: &mut SetpointGenerator,
    ) -> Result<Self, PathError> {
        let free_velocity = path.velocity;
        path.velocity = path.velocity.min(feed);
        start_profile(&mut path, length, generator)?;
        Ok(Self {
            start,
            delta,
            circle,
            end,
            length,
            done: false,
            braked: false,
            limits: path,
            free_velocity,
            feed,
            factor: 1.0,
            held: false,
        })
    }

    /// One tick of `generator` (the one the block was planned on): writes the interpolated
    /// position into `position`; `true` when the block has ended (the position is then
    /// exactly the target).
    pub fn step(&mut self, generator: &mut SetpointGenerator, position: &mut AxisValues) -> bool {
        if !self.done {
            let progress = generator.step();
            // Held, the generator comes to rest short of the end: the block goes on later.
            self.done = !self.held && matches!(progress, Progress::Reached | Progress::Idle);
        }
        let s = if self.done && !self.braked {
            1.0
        } else {
            (generator.state().position / self.length).clamp(0.0, 1.0)
        };
        for (i, p) in position.iter_mut().enumerate() {
            *p = self.start[i] + self.delta[i] * s;
        }
        if let Some(c) = &self.circle {
            let [x, y] = c.point(s);
            position[c.axes[0]] = x;
            position[c.axes[1]] = y;
        }
        if self.done && !self.braked {
            // Exactly at the end point (the arithmetic above may miss it by a rounding).
            for (i, p) in position.iter_mut().enumerate() {
                *p = self.end[i];
            }
        }
        self.done
    }

    /// The velocity and acceleration of every axis at the position the last [`Self::step`]
    /// wrote, from the path's own (`generator`'s) velocity and acceleration: the exact
    /// derivatives of the interpolated position, 0 once the block has ended at its target.
    pub fn rates(
        &self,
        generator: &SetpointGenerator,
        velocity: &mut AxisValues,
        acceleration: &mut AxisValues,
    ) {
        if self.done && !self.braked {
            velocity.fill(0.0);
            acceleration.fill(0.0);
            return;
        }
        let state = generator.state();
        let s = (state.position / self.length).clamp(0.0, 1.0);
        let (ds, dds) = (
            state.velocity / self.length,
            state.acceleration / self.length,
        );
        for (i, d) in self.delta.iter().enumerate() {
            velocity[i] = d * ds;
            acceleration[i] = d * dds;
        }
        if let Some(c) = &self.circle {
            let (v, a) = c.rates(s, ds, dds);
            for (k, &axis) in c.axes.iter().enumerate() {
                velocity[axis] = v[k];
                acceleration[axis] = a[k];
            }
        }
    }

    /// Brakes along the block to a standstill with the block's own deceleration and jerk;
    /// the block then ends where the path came to rest, short of its target. When the rest of
    /// the block is shorter than the braking distance, the block runs to its end (where it
    /// comes to rest anyway) instead of being cut off.
    pub fn brake(&mut self, generator: &mut SetpointGenerator) {
        if self.done {
            return;
        }
        if self.held {
            // Feed hold brakes (or stands) already: the block ends where the path comes to
            // rest, and no override resumes it.
            self.held = false;
            self.braked = true;
            return;
        }
        let s = generator.state();
        let (dec, jerk) = (self.limits.deceleration, self.limits.jerk);
        let v = s.velocity.abs();
        let braking = v * v / (2.0 * dec) + v * dec / jerk;
        if self.length - s.position <= braking {
            return;
        }
        if generator.brake(dec, jerk).is_ok() {
            self.braked = true;
        }
    }

    /// Applies an override `factor` (1 = 100 %, 0 = hold) to the rest of the block: `feed`
    /// for G1 and arcs, `rapid` for G0, each in [0, 2]. A change re-targets the generator from
    /// its current state; nothing changes once the block ends or is braked for a stop.
    pub fn set_override(&mut self, feed: f64, rapid: f64, generator: &mut SetpointGenerator) {
        let factor = if self.feed.is_finite() { feed } else { rapid };
        if self.done || self.braked || factor == self.factor {
            return;
        }
        if factor <= 0.0 {
            self.factor = factor;
            if !self.held {
                self.held = true;
                if generator
                    .brake(self.limits.deceleration, self.limits.jerk)
                    .is_err()
                {
                    // No braking profile (never seen): stand where the path is.
                    let here = generator.state().position;
                    generator.hold(here);
                }
            }
            return;
        }
        let velocity = if self.feed.is_finite() {
            self.free_velocity.min(self.feed * factor)
        } else {
            self.free_velocity * factor
        };
        let limits = MoveLimits {
            velocity,
            ..self.limits
        };
        // Without a profile the old value stays in effect and the next tick tries again.
        if generator.move_to(self.length, limits).is_ok() {
            self.factor = factor;
            self.held = false;
        }
    }

    /// Block length.
    pub fn length(&self) -> f64 {
        self.length
    }
}
