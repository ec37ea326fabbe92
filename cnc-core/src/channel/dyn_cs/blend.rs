//! The soft transition of the applied compensation: the smoothing ramp's weight and the
//! interpolation between two frames.

use nalgebra::{Isometry3, Translation3};

/// A soft transition of the applied compensation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Blend {
    pub(super) from: Isometry3<f64>,
    /// Coupling out of ACTIVE: `from` follows the compensation the master asks for.
    pub(super) follow: bool,
    /// Ticks done and total.
    pub(super) done: u32,
    pub(super) total: u32,
}

impl Blend {
    pub(super) fn weight(&self) -> f64 {
        if self.total == 0 {
            1.0
        } else {
            smooth_ramp(f64::from(self.done) / f64::from(self.total))
        }
    }

    /// Whether the transition is over. Without a filter the change is made in the first
    /// tick but ACTIVATING / DEACTIVATING stays shown for that tick (the manual's PLC-only
    /// example sees 0 -> 1 -> 2 with the filter off).
    pub(super) fn finished(&self) -> bool {
        self.done >= self.total.max(1) + u32::from(self.total == 0)
    }
}

/// The filter's weight over its progress `x` in [0, 1]: `6x^5 - 15x^4 + 10x^3`, rising from 0
/// to 1 with zero slope and zero curvature at both ends (its steepest slope, at the middle, is
/// 15/8).
pub fn smooth_ramp(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * x * (x * (6.0 * x - 15.0) + 10.0)
}

/// Interpolates between two frames: translation linearly, rotation along the shortest arc.
pub fn interpolate(a: &Isometry3<f64>, b: &Isometry3<f64>, w: f64) -> Isometry3<f64> {
    let t = a.translation.vector.lerp(&b.translation.vector, w);
    let r = a
        .rotation
        .try_slerp(&b.rotation, w, 1e-12)
        .unwrap_or(if w < 0.5 { a.rotation } else { b.rotation });
    Isometry3::from_parts(Translation3::from(t), r)
}
