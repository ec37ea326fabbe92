//! The circle of an arc block: planning the block on it, and the points of the circle along
//! the path parameter.

use super::{axis_limits, limit_by_axes, ArcSpec, AxisLimits, PathError, PathMove};
use crate::axis::generator::{MoveLimits, SetpointGenerator};
use crate::setpoint::AxisValues;

/// The circle part of an arc block.
#[derive(Debug, Clone, Copy)]
pub(super) struct Circle {
    /// Plane axes (first, second).
    pub(super) axes: [usize; 2],
    pub(super) center: [f64; 2],
    /// Start angle (rad) and signed sweep (positive counter-clockwise).
    pub(super) angle0: f64,
    pub(super) sweep: f64,
    /// Start and end radius.
    pub(super) r0: f64,
    pub(super) r1: f64,
}

impl Circle {
    /// The point at `s` of the way (0..=1) in the plane's two axes: the angle runs linearly
    /// over the sweep, the radius from the start's to the end's.
    pub(super) fn point(&self, s: f64) -> [f64; 2] {
        let angle = self.angle0 + self.sweep * s;
        let r = self.r0 + (self.r1 - self.r0) * s;
        [
            self.center[0] + r * angle.cos(),
            self.center[1] + r * angle.sin(),
        ]
    }
}

impl PathMove {
    pub(super) fn plan_arc(
        start: &AxisValues,
        target: &AxisValues,
        mut delta: AxisValues,
        feed_mm_min: f64,
        spec: ArcSpec,
        limits: &[AxisLimits],
        generator: &mut SetpointGenerator,
    ) -> Result<Self, PathError> {
        let arc = spec.arc;
        let [a, b, _] = arc.plane.axes();
        let (p0, p1) = ([start[a], start[b]], [target[a], target[b]]);
        let c = arc.center;
        let r0 = (p0[0] - c[0]).hypot(p0[1] - c[1]);
        let r1 = (p1[0] - c[0]).hypot(p1[1] - c[1]);
        let sweep = arc.sweep(p0, p1);
        let signed = if arc.ccw { sweep } else { -sweep };
        delta[a] = 0.0;
        delta[b] = 0.0;
        let circle_length = sweep * (r0 + r1) / 2.0;
        let linear = delta.iter().take(3).map(|d| d * d).sum::<f64>();
        let length = (circle_length * circle_length + linear).sqrt();
        if length.is_nan() || length <= 1e-12 || !length.is_finite() {
            return Err(PathError::NoProfile);
        }
        let limit = |i: usize| axis_limits(limits, i);
        let (la, lb) = (limit(a), limit(b));
        let plane_v = la.velocity.min(lb.velocity);
        let plane_a = la.acceleration.min(lb.acceleration);
        let plane_j = la.jerk.min(lb.jerk);
        let share = circle_length / length;
        let r = r0.min(r1).max(1e-9);
        let mut path = MoveLimits {
            velocity: (plane_v / share.max(1e-12))
                .min((plane_a * r / 2.0).sqrt())
                .min((plane_j * r * r / 2.0).cbrt())
                .min((8.0 * r * spec.chordal_tolerance).sqrt() / spec.cycle_s),
            acceleration: plane_a / 2.0 / share.max(1e-12),
            deceleration: 0.0,
            jerk: plane_j / 2.0 / share.max(1e-12),
        };
        limit_by_axes(&mut path, &delta, length, limits);
        let circle = Circle {
            axes: [a, b],
            center: c,
            angle0: (p0[1] - c[1]).atan2(p0[0] - c[0]),
            sweep: signed,
            r0,
            r1,
        };
        let geometry = (*start, delta, Some(circle), *target, length);
        Self::start(geometry, path, feed_mm_min / 60.0, generator)
    }
}
