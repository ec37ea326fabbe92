//! The circle of an arc block: planning the block on it, and the points of the circle along
//! the path parameter.

use super::{axis_limits, limit_by_axes, ArcSpec, AxisLimits, PathError, PathMove};
use crate::axis::generator::{MoveLimits, SetpointGenerator};
use crate::nc::arc::ArcMove;
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
    /// The circle of `arc` from `start` to `target` (channel axes), and the length of its
    /// part in the plane; `None` when that is not finite.
    pub(super) fn of(
        start: &AxisValues,
        target: &AxisValues,
        arc: &ArcMove,
    ) -> Option<(Self, f64)> {
        let [a, b, _] = arc.plane.axes();
        let (p0, p1) = ([start[a], start[b]], [target[a], target[b]]);
        let c = arc.center;
        let r0 = (p0[0] - c[0]).hypot(p0[1] - c[1]);
        let r1 = (p1[0] - c[0]).hypot(p1[1] - c[1]);
        let sweep = arc.sweep(p0, p1);
        let circle = Self {
            axes: [a, b],
            center: c,
            angle0: (p0[1] - c[1]).atan2(p0[0] - c[0]),
            sweep: if arc.ccw { sweep } else { -sweep },
            r0,
            r1,
        };
        let length = sweep * (r0 + r1) / 2.0;
        length.is_finite().then_some((circle, length))
    }

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

    /// The velocity and acceleration of the point at `s` in the plane's two axes, when `s`
    /// changes at `ds` per second with `dds` per second squared.
    pub(super) fn rates(&self, s: f64, ds: f64, dds: f64) -> ([f64; 2], [f64; 2]) {
        let angle = self.angle0 + self.sweep * s;
        let r = self.r0 + (self.r1 - self.r0) * s;
        let dr = self.r1 - self.r0;
        let (sin, cos) = angle.sin_cos();
        // First and second derivatives of the point over s.
        let d1 = [
            dr * cos - r * self.sweep * sin,
            dr * sin + r * self.sweep * cos,
        ];
        let w2 = self.sweep * self.sweep;
        let d2 = [
            -2.0 * dr * self.sweep * sin - r * w2 * cos,
            2.0 * dr * self.sweep * cos - r * w2 * sin,
        ];
        let velocity = [d1[0] * ds, d1[1] * ds];
        let acceleration = [d2[0] * ds * ds + d1[0] * dds, d2[1] * ds * ds + d1[1] * dds];
        (velocity, acceleration)
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
        let (circle, circle_length) =
            Circle::of(start, target, &spec.arc).ok_or(PathError::NoProfile)?;
        let ([a, b], r0, r1) = (circle.axes, circle.r0, circle.r1);
        delta[a] = 0.0;
        delta[b] = 0.0;
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
        let geometry = (*start, delta, Some(circle), *target, length);
        Self::start(geometry, path, feed_mm_min / 60.0, generator)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{ArcSpec, AxisLimits, PathMove};
    use crate::axis::generator::SetpointGenerator;
    use crate::nc::arc::{ArcMove, Plane};
    use crate::nc::MotionMode;
    use crate::setpoint::AxisValues;

    /// Runs `path` to its end; at every tick compares the rates with the central differences
    /// of the positions (and velocities) around it. Returns the largest velocity and
    /// acceleration seen on the first axis.
    fn rates_match_differences(
        mut path: PathMove,
        generator: &mut SetpointGenerator,
    ) -> (f64, f64) {
        let dt = 0.001;
        let n = 4;
        let (mut p, mut v, mut a) = (
            AxisValues::zeros(n),
            AxisValues::zeros(n),
            AxisValues::zeros(n),
        );
        let mut samples = Vec::new();
        loop {
            let ended = path.step(generator, &mut p);
            path.rates(generator, &mut v, &mut a);
            samples.push((p, v, a));
            if ended {
                break;
            }
        }
        let mut top = (0.0f64, 0.0f64);
        for w in samples.windows(3) {
            let ((p0, v0, _), (_, v1, a1), (p2, v2, _)) = (w[0], w[1], w[2]);
            for i in 0..n {
                let dv = (p2[i] - p0[i]) / (2.0 * dt);
                let da = (v2[i] - v0[i]) / (2.0 * dt);
                // A difference misses the exact derivative by up to jerk x dt^2 (velocity)
                // and jerk x dt (acceleration) where the jerk switches.
                let (ev, ea) = ((v1[i] - dv).abs(), (a1[i] - da).abs());
                assert!(ev < 0.1 + 1e-3 * dv.abs(), "v{i}: {} vs {dv}", v1[i]);
                assert!(ea < 100.0 + 1e-2 * da.abs(), "a{i}: {} vs {da}", a1[i]);
            }
            top.0 = top.0.max(v1[0].abs());
            top.1 = top.1.max(a1[0].abs());
        }
        let (_, v_end, a_end) = samples[samples.len() - 1];
        assert!(v_end.iter().chain(a_end.iter()).all(|x| *x == 0.0));
        top
    }

    fn limits() -> [AxisLimits; 4] {
        [AxisLimits {
            velocity: 200.0,
            acceleration: 2000.0,
            jerk: 50_000.0,
        }; 4]
    }

    #[test]
    fn the_rates_of_a_straight_block_and_an_arc_are_the_derivatives_of_their_points() {
        let mut g = SetpointGenerator::new(0.001, 0.0);
        let start = AxisValues::from_slice(&[0.0, 0.0, 0.0, 0.0]);
        let target = AxisValues::from_slice(&[30.0, -40.0, 5.0, 90.0]);
        let line = PathMove::plan(
            &start,
            &target,
            MotionMode::Linear,
            6000.0,
            None,
            &limits(),
            &mut g,
        )
        .unwrap()
        .unwrap();
        let (v, a) = rates_match_differences(line, &mut g);
        assert!(v > 10.0 && a > 500.0, "{v} {a}");
        // A helical quarter circle about (0, 20) from (0, 0) to (20, 20), Z and the fourth
        // axis moving along.
        let arc = ArcSpec {
            arc: ArcMove {
                plane: Plane::Xy,
                center: [0.0, 20.0],
                ccw: true,
                full_turn: false,
            },
            cycle_s: 0.001,
            chordal_tolerance: 0.01,
        };
        let target = AxisValues::from_slice(&[20.0, 20.0, 3.0, 10.0]);
        let arc = PathMove::plan(
            &start,
            &target,
            MotionMode::ArcCcw,
            3000.0,
            Some(arc),
            &limits(),
            &mut g,
        )
        .unwrap()
        .unwrap();
        let (v, a) = rates_match_differences(arc, &mut g);
        assert!(v > 10.0 && a > 500.0, "{v} {a}");
    }
}
