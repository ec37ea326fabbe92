//! The path interpolator of a channel: one straight block at a time (G0/G1), all channel axes
//! moving together, with a jerk-limited velocity profile along the path.
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
//! The channel owns one generator for its path and hands it to every block: building a
//! generator allocates (rsruckig's buffers), re-targeting one does not.

use crate::axis::generator::{MoveLimits, Progress, SetpointGenerator};
use crate::nc::decode::AxisValues;
use crate::nc::MotionMode;

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

/// A straight block being interpolated.
#[derive(Debug)]
pub struct PathMove {
    start: AxisValues,
    delta: AxisValues,
    length: f64,
    done: bool,
    /// Stopped by `brake`: the block ends where the path stands.
    braked: bool,
    /// The path limits the block was planned with.
    limits: MoveLimits,
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
    /// path parameter from 0. `None` when nothing moves.
    pub fn plan(
        start: &AxisValues,
        target: &AxisValues,
        motion: MotionMode,
        feed_mm_min: f64,
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
        for (i, d) in delta.iter().enumerate() {
            let share = d.abs() / length;
            if share <= 1e-12 {
                continue;
            }
            let limit = limits.get(i).copied().unwrap_or(AxisLimits {
                velocity: f64::INFINITY,
                acceleration: f64::INFINITY,
                jerk: f64::INFINITY,
            });
            path.velocity = path.velocity.min(limit.velocity / share);
            path.acceleration = path.acceleration.min(limit.acceleration / share);
            path.jerk = path.jerk.min(limit.jerk / share);
        }
        if motion == MotionMode::Linear {
            path.velocity = path.velocity.min(feed_mm_min / 60.0);
        }
        path.deceleration = path.acceleration;
        let finite = [path.velocity, path.acceleration, path.jerk]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0);
        if !finite {
            return Err(PathError::NoProfile);
        }
        generator.hold(0.0);
        generator
            .move_to(length, path)
            .map_err(|_| PathError::NoProfile)?;
        Ok(Some(Self {
            start: *start,
            delta,
            length,
            done: false,
            braked: false,
            limits: path,
        }))
    }

    /// One tick of `generator` (the one the block was planned on): writes the interpolated
    /// position into `position`; `true` when the block has ended (the position is then
    /// exactly the target).
    pub fn step(&mut self, generator: &mut SetpointGenerator, position: &mut AxisValues) -> bool {
        if !self.done {
            self.done = matches!(generator.step(), Progress::Reached | Progress::Idle);
        }
        let s = if self.done && !self.braked {
            1.0
        } else {
            (generator.state().position / self.length).clamp(0.0, 1.0)
        };
        for (i, p) in position.iter_mut().enumerate() {
            *p = if self.done && !self.braked {
                self.start[i] + self.delta[i]
            } else {
                self.start[i] + self.delta[i] * s
            };
        }
        self.done
    }

    /// Brakes along the block to a standstill with the block's own deceleration and jerk;
    /// the block then ends where the path came to rest, short of its target. When the rest of
    /// the block is shorter than the braking distance, the block runs to its end (where it
    /// comes to rest anyway) instead of being cut off.
    pub fn brake(&mut self, generator: &mut SetpointGenerator) {
        if self.done {
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

    /// Block length.
    pub fn length(&self) -> f64 {
        self.length
    }
}
