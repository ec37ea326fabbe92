//! The set-point vocabulary the axis layer, the channels and the engines share.
//!
//! [`AxisValues`] carries one value per channel axis (a decoded block's targets, a channel's
//! set-points handed to its axes).
//!
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

/// Most axes one channel can have.
pub const MAX_CHANNEL_AXES: usize = 16;

/// One value per channel axis, in channel order, stored inline: a decoded block needs no heap
/// allocation, and the channel's tick can copy targets freely.
#[derive(Clone, Copy, PartialEq)]
pub struct AxisValues {
    len: u8,
    /// Slots beyond `len` stay 0, so the derived equality compares only the used ones.
    values: [f64; MAX_CHANNEL_AXES],
}

impl AxisValues {
    /// `n` zeros; `n` is cut to [`MAX_CHANNEL_AXES`] ([`crate::nc::decode::check_channel_axes`] refuses more).
    pub fn zeros(n: usize) -> Self {
        Self {
            len: n.min(MAX_CHANNEL_AXES) as u8,
            values: [0.0; MAX_CHANNEL_AXES],
        }
    }

    /// The values of `slice` (cut to [`MAX_CHANNEL_AXES`]).
    pub fn from_slice(slice: &[f64]) -> Self {
        let mut v = Self::zeros(slice.len());
        let n = v.len();
        v.values[..n].copy_from_slice(&slice[..n]);
        v
    }
}

impl core::ops::Deref for AxisValues {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.values[..self.len as usize]
    }
}

impl core::ops::DerefMut for AxisValues {
    fn deref_mut(&mut self) -> &mut [f64] {
        &mut self.values[..self.len as usize]
    }
}

impl core::fmt::Debug for AxisValues {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}
