//! Continuous path under `#TRAFO`: the joints' limits on the contour's pieces.
//!
//! The contour plans in the programmed (Cartesian) coordinates with the channel's `limits`;
//! under a transformation the axes are the robot's joints, with their own `axis_limits`. Before
//! the look-ahead plans with a new piece, the channel samples it at five points (its ends,
//! quarters and middle): at each, the inverse kinematics at `λ - h`, `λ` and `λ + h` give
//! each joint's rate per unit of path `q'` and its curvature `q''` by central differences.
//! Then, for every joint `j` with limits `V`, `A`, `J`:
//!
//! * the path's velocity is capped at `V / |q'|` and at `sqrt(A / 2 |q''|)`;
//! * the path parameter's acceleration at `A / 2 |q'|`, its jerk at `J / 2 |q'|` (half of
//!   each for the path parameter). The joints' jerk from the joint path's own curvature
//!   (`3 q'' v a + q''' v³`) is not bounded beyond that.
//!
//! Where the joints turn fast for little path (near a singularity) the path slows down there
//! instead of asking them more than they have. The sampling sees the piece at five points: a
//! joint rate peaking between them is seen only as far as the neighbouring samples show it.
//! Decoding ahead under a transformation takes at most [`TRAFO_BLOCKS_PER_TICK`] blocks a
//! tick: each costs some thirty inverse kinematics.

use super::*;
use crate::channel::path::contour::{Dynamics, Piece};
use kinematics::{Joints, PoseWords};

/// Blocks the look-ahead joins in one tick under a transformation.
pub(super) const TRAFO_BLOCKS_PER_TICK: usize = 2;

/// Samples along a piece, as shares of its length.
const SAMPLES: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// What the joints ask of a piece: its caps lowered to theirs.
pub(super) struct JointCaps<'a> {
    pub(super) kinematics: &'a ToolKinematics,
    pub(super) order: RotationOrder,
    pub(super) cs: Isometry3<f64>,
    pub(super) seed: Joints,
    pub(super) limits: [AxisLimits; 6],
}

impl JointCaps<'_> {
    /// The joints at `lambda` on `piece`, from the last solution.
    fn joints(&mut self, piece: &Piece, lambda: f64) -> Option<Joints> {
        let mut p = piece.origin;
        piece.point(lambda, &mut p);
        let frame = PoseWords {
            xyz: [p[0], p[1], p[2]],
            abc: [p[3], p[4], p[5]],
        }
        .to_frame(self.order)
        .ok()?;
        let q = self
            .kinematics
            .inverse(&(self.cs * frame), &self.seed)
            .ok()?;
        self.seed = q;
        Some(q)
    }

    /// Lowers `piece`'s caps to the joints'. A pose that cannot be reached is left to the
    /// pose pipeline (it fails the channel there).
    pub(super) fn apply(&mut self, piece: &mut Piece) {
        let length = piece.length;
        if length <= 1e-9 {
            return;
        }
        // The difference step: small against the piece, never more than a quarter of it.
        let h = (length * 1e-3).max(1e-4).min(length / 4.0);
        let (mut cap, mut acc, mut jerk) = (piece.hard_cap, f64::INFINITY, f64::INFINITY);
        for share in SAMPLES {
            let at = (share * length).clamp(h, length - h);
            let (Some(a), Some(b), Some(c)) = (
                self.joints(piece, at - h),
                self.joints(piece, at),
                self.joints(piece, at + h),
            ) else {
                return;
            };
            for (j, limit) in self.limits.iter().enumerate() {
                let d1 = ((c[j] - a[j]) / (2.0 * h)).abs();
                let d2 = ((c[j] - 2.0 * b[j] + a[j]) / (h * h)).abs();
                if d1 > 1e-9 {
                    cap = cap.min(limit.velocity / d1);
                    acc = acc.min(0.5 * limit.acceleration / d1);
                    jerk = jerk.min(0.5 * limit.jerk / d1);
                }
                if d2 > 1e-9 {
                    cap = cap.min((0.5 * limit.acceleration / d2).sqrt());
                }
            }
        }
        piece.hard_cap = cap;
        piece.dynamics = Dynamics {
            acceleration: piece.dynamics.acceleration.min(acc),
            jerk: piece.dynamics.jerk.min(jerk),
        };
    }
}

/// The joint caps for the contour's next pieces of a channel with `pose`, `config` and `layout` (only
/// under a transformation), the inverse kinematics starting from `seed` (the joints of the
/// last piece sampled, so a piece far ahead resolves to the configuration the path follows).
pub(super) fn joint_caps<'a>(
    pose: &'a Pose,
    config: &ChannelConfig,
    layout: &AxisLayout,
    seed: Joints,
) -> Option<JointCaps<'a>> {
    if !pose.trafo {
        return None;
    }
    // The joints are the pose slots (a transformation needs all six).
    let mut limits = [config.limits; 6];
    for (i, &slot) in layout.slots().iter().enumerate() {
        if let Some(l) = limits.get_mut(slot) {
            *l = config.axis_limits(i);
        }
    }
    let cs = pose.cs_stack[..pose.cs_len]
        .iter()
        .fold(Isometry3::identity(), |acc, f| acc * f);
    Some(JointCaps {
        kinematics: &pose.kinematics,
        order: pose.order,
        cs,
        seed,
        limits,
    })
}
