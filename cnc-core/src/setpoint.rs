//! It sits below the axis layer and the engines: the axis layer's generator produces a
//! [`Kinematic`], a coupled axis takes one from its channel or engine
//! (`Axis::drive_coupled`), and the cam laws, the multi-table slave, the flying saw, the
//! gears and the FIFO groups compute one from their master's, without depending on the
//! generator that made it.

/// Position, velocity, acceleration and jerk of a set-point.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Kinematic {
    /// Position (mm or degree).
    pub position: f64,
    /// Velocity per second.
    pub velocity: f64,
    /// Acceleration per second squared.
    pub acceleration: f64,
    /// Jerk per second cubed.
    pub jerk: f64,
}

impl Kinematic {
    /// The slave of a linear coupling to this master set-point: `s0 + ratio (m - m0)`,
    /// velocity, acceleration and jerk scaled alike (gears, the flying saw's synchronous
    /// phase).
    pub fn geared(&self, ratio: f64, (m0, s0): (f64, f64)) -> Kinematic {
        Kinematic {
            position: s0 + ratio * (self.position - m0),
            velocity: ratio * self.velocity,
            acceleration: ratio * self.acceleration,
            jerk: ratio * self.jerk,
        }
    }
}
