//! Frames (`Isometry3<f64>`, mm and radians inside) and the controller's orientation
//! conventions for A/B/C words (degrees).
//!
//! | convention | rotation | where |
//! | --- | --- | --- |
//! | [`RotationOrder::YawPitchRoll`] | `Rz(C) * Ry(-B) * Rx(A)` | channel parameter `ori_rotation_angle` = 0 (default) |
//! | [`RotationOrder::EulerZyz`] | `Rz(A) * Ry(B) * Rz(C)` | `ori_rotation_angle` = 1 (Euler Z-Y'-Z'') |
//! | [`RotationOrder::Cba`] | `Rz(A) * Ry(B) * Rx(C)` | `ori_rotation_angle` = 2 |
//! | [`RotationOrder::Zyx`] | `Rz(C) * Ry(B) * Rx(A)` | static offsets of `#TRACK CS` (always Z, then Y, then X), `#CS` frames, HLI frames |
//!
//! Note the default convention's negated B: a frame given in it is reproduced by a Z-Y-X frame
//! with `-B`, which is why NC programs write `#CS ON [..., -V.G.TRACK_CS.B, ...]`.

use crate::error::KinError;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// How three angles A, B, C (degrees) make a rotation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RotationOrder {
    /// `Rz(C) * Ry(-B) * Rx(A)`, the channel default.
    #[default]
    YawPitchRoll,
    /// `Rz(A) * Ry(B) * Rz(C)`.
    EulerZyz,
    /// `Rz(A) * Ry(B) * Rx(C)`.
    Cba,
    /// `Rz(C) * Ry(B) * Rx(A)`.
    Zyx,
}

impl RotationOrder {
    /// The convention selected by the channel parameter `ori_rotation_angle`.
    pub fn from_channel_parameter(value: u32) -> Result<Self, KinError> {
        match value {
            0 => Ok(RotationOrder::YawPitchRoll),
            1 => Ok(RotationOrder::EulerZyz),
            2 => Ok(RotationOrder::Cba),
            other => Err(KinError::BadParameter {
                name: "ori_rotation_angle",
                value: f64::from(other),
                reason: "must be 0, 1 or 2",
            }),
        }
    }

    /// The rotation of angles `[a, b, c]` in degrees.
    pub fn rotation(self, abc_deg: [f64; 3]) -> Rotation3<f64> {
        let [a, b, c] = abc_deg.map(f64::to_radians);
        let (rx, ry, rz) = (
            |t: f64| Rotation3::from_axis_angle(&Vector3::x_axis(), t),
            |t: f64| Rotation3::from_axis_angle(&Vector3::y_axis(), t),
            |t: f64| Rotation3::from_axis_angle(&Vector3::z_axis(), t),
        );
        match self {
            RotationOrder::YawPitchRoll => rz(c) * ry(-b) * rx(a),
            RotationOrder::EulerZyz => rz(a) * ry(b) * rz(c),
            RotationOrder::Cba => rz(a) * ry(b) * rx(c),
            RotationOrder::Zyx => rz(c) * ry(b) * rx(a),
        }
    }

    /// The angles `[a, b, c]` in degrees of a rotation. In a gimbal-locked position (the middle
    /// rotation at +-90 degree, or 0/180 for Z-Y-Z) the first angle is set to 0.
    pub fn angles(self, rotation: &Rotation3<f64>) -> [f64; 3] {
        let m = rotation.matrix();
        let deg = |v: [f64; 3]| v.map(f64::to_degrees);
        match self {
            RotationOrder::YawPitchRoll => {
                let [x, y, z] = zyx_angles(m);
                deg([x, -y, z])
            }
            RotationOrder::Zyx => deg(zyx_angles(m)),
            RotationOrder::Cba => {
                let [x, y, z] = zyx_angles(m);
                deg([z, y, x])
            }
            RotationOrder::EulerZyz => {
                let sb = m[(0, 2)].hypot(m[(1, 2)]);
                let b = sb.atan2(m[(2, 2)]);
                if sb < GIMBAL_EPS {
                    deg([0.0, b, m[(1, 0)].atan2(m[(1, 1)])])
                } else {
                    deg([m[(1, 2)].atan2(m[(0, 2)]), b, m[(2, 1)].atan2(-m[(2, 0)])])
                }
            }
        }
    }
}

impl RotationOrder {
    /// The angles of `rotation` nearest to `near` (degrees): of the two solutions each
    /// convention has (the middle angle mirrored, the outer ones turned by 180 degree) and,
    /// in a gimbal-locked position, the one whose first angle stays `near`'s, the one closest
    /// to `near` with every angle taken to within 180 degree of it. Axes that follow a turning
    /// frame word by word so pass a middle angle of 0 (Z-Y-Z) or +-90 degree without their
    /// outer axes flipping, and never wrap by 360 degree.
    pub fn angles_near(self, rotation: &Rotation3<f64>, near: [f64; 3]) -> [f64; 3] {
        let [a, b, c] = self.angles(rotation);
        let fits =
            |v: &[f64; 3]| (self.rotation(*v).matrix() - rotation.matrix()).abs().max() <= 1e-9;
        let turn = near[0] - a;
        let candidates = [
            [a, b, c],
            [a + 180.0, -b, c + 180.0],
            [a + 180.0, 180.0 - b, c + 180.0],
            [a + 180.0, -180.0 - b, c + 180.0],
            [near[0], b, c + turn],
            [near[0], b, c - turn],
        ];
        let unwrap = |v: [f64; 3]| {
            let mut out = v;
            for (x, n) in out.iter_mut().zip(near) {
                *x = n + (*x - n + 180.0).rem_euclid(360.0) - 180.0;
            }
            out
        };
        let distance = |v: &[f64; 3]| v.iter().zip(near).map(|(x, n)| (x - n).abs()).sum::<f64>();
        candidates
            .into_iter()
            .filter(|v| v.iter().all(|x| x.is_finite()) && fits(v))
            .map(unwrap)
            .min_by(|x, y| distance(x).total_cmp(&distance(y)))
            .unwrap_or_else(|| unwrap([a, b, c]))
    }
}

const GIMBAL_EPS: f64 = 1e-12;

/// Angles `[x, y, z]` (radians) of `Rz(z) * Ry(y) * Rx(x)`.
fn zyx_angles(m: &Matrix3<f64>) -> [f64; 3] {
    let cy = m[(0, 0)].hypot(m[(1, 0)]);
    let y = (-m[(2, 0)]).atan2(cy);
    if cy < GIMBAL_EPS {
        // x and z turn about the same axis: put everything into z.
        [0.0, y, (-m[(0, 1)]).atan2(m[(1, 1)])]
    } else {
        [m[(2, 1)].atan2(m[(2, 2)]), y, m[(1, 0)].atan2(m[(0, 0)])]
    }
}

/// A pose as the NC writes it: X, Y, Z in mm and A, B, C in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PoseWords {
    /// Translation, mm.
    pub xyz: [f64; 3],
    /// Orientation angles, degrees, in some [`RotationOrder`].
    pub abc: [f64; 3],
}

impl PoseWords {
    /// The frame of these words.
    pub fn to_frame(&self, order: RotationOrder) -> Result<Isometry3<f64>, KinError> {
        check_finite(&self.xyz)?;
        check_finite(&self.abc)?;
        Ok(Isometry3::from_parts(
            Translation3::new(self.xyz[0], self.xyz[1], self.xyz[2]),
            UnitQuaternion::from_rotation_matrix(&order.rotation(self.abc)),
        ))
    }

    /// The words of a frame.
    pub fn from_frame(frame: &Isometry3<f64>, order: RotationOrder) -> Self {
        let t = frame.translation.vector;
        Self {
            xyz: [t.x, t.y, t.z],
            abc: order.angles(&frame.rotation.to_rotation_matrix()),
        }
    }
}

/// Refuses NaN and infinities.
pub fn check_finite(values: &[f64]) -> Result<(), KinError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(KinError::NotFinite { index }),
        None => Ok(()),
    }
}

/// A static offset frame as `#TRACK CS` and `#CS` give it: translation X, Y, Z (mm) and
/// rotation A, B, C (degrees) about Z, then Y, then X. By default the translation is measured
/// in the unrotated frame (`Trans * Rot`); with `rotated_translation` (ROT_TRANS) it is measured
/// in the already rotated frame (`Rot * Trans`).
pub fn offset_frame(
    words: &PoseWords,
    rotated_translation: bool,
) -> Result<Isometry3<f64>, KinError> {
    let frame = words.to_frame(RotationOrder::Zyx)?;
    if rotated_translation {
        Ok(Isometry3::from_parts(
            Translation3::from(frame.rotation * frame.translation.vector),
            frame.rotation,
        ))
    } else {
        Ok(frame)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const ORDERS: [RotationOrder; 4] = [
        RotationOrder::YawPitchRoll,
        RotationOrder::EulerZyz,
        RotationOrder::Cba,
        RotationOrder::Zyx,
    ];

    /// A frame tilting through the middle angle's zero (Z-Y-Z) and through +-90 degree
    /// (the Z-Y-X conventions) in one plane, word by word from the last words: the middle
    /// angle passes continuously, the outer ones stay (no 180 degree flip), and a turn past
    /// 180 degree goes on past it instead of wrapping to -180.
    #[test]
    fn angles_near_the_last_ones_pass_the_singular_positions_continuously() {
        for (order, (a, c), middles) in [
            (
                RotationOrder::EulerZyz,
                (90.0, 10.0),
                [3.0, 1.0, 0.0, -1.0, -3.0],
            ),
            (
                RotationOrder::Zyx,
                (20.0, 30.0),
                [87.0, 89.0, 90.0, 91.0, 93.0],
            ),
            (
                RotationOrder::YawPitchRoll,
                (20.0, 30.0),
                [-87.0, -89.0, -90.0, -91.0, -93.0],
            ),
        ] {
            let mut last = [a, middles[0], c];
            for m in middles {
                let r = order.rotation([a, m, c]);
                let got = order.angles_near(&r, last);
                assert!(
                    rot_close(&order.rotation(got), &r, 1e-9),
                    "{order:?} {got:?}"
                );
                if m.abs() != 90.0 && m != 0.0 {
                    for (g, w) in got.iter().zip([a, m, c]) {
                        assert!((g - w).abs() < 1e-6, "{order:?} at {m}: {got:?}");
                    }
                }
                last = got;
            }
        }
        // Past 180 degree about Z without a wrap.
        let r = RotationOrder::Zyx.rotation([0.0, 0.0, -179.0]);
        let got = RotationOrder::Zyx.angles_near(&r, [0.0, 0.0, 179.5]);
        assert!((got[2] - 181.0).abs() < 1e-9, "{got:?}");
    }

    fn rot_close(a: &Rotation3<f64>, b: &Rotation3<f64>, tol: f64) -> bool {
        (a.matrix() - b.matrix()).abs().max() <= tol
    }

    #[test]
    fn default_convention_negates_b() {
        // B = 90 in yaw-pitch-roll turns +X down onto -Z... by Ry(-90): x -> +z.
        let r = RotationOrder::YawPitchRoll.rotation([0.0, 90.0, 0.0]);
        let x = r * Vector3::x();
        assert!((x - Vector3::z()).norm() < 1e-15, "{x}");
        // The same frame in Z-Y-X order needs -B.
        let r2 = RotationOrder::Zyx.rotation([10.0, -30.0, 45.0]);
        let r1 = RotationOrder::YawPitchRoll.rotation([10.0, 30.0, 45.0]);
        assert!(rot_close(&r1, &r2, 1e-15));
    }

    #[test]
    fn known_rotations() {
        let c90 = RotationOrder::Zyx.rotation([0.0, 0.0, 90.0]);
        assert!(((c90 * Vector3::x()) - Vector3::y()).norm() < 1e-15);
        let zyz = RotationOrder::EulerZyz.rotation([90.0, 90.0, 0.0]);
        // Ry(90) takes +Z to +X, then Rz(90) takes +X to +Y.
        assert!(((zyz * Vector3::z()) - Vector3::y()).norm() < 1e-15);
        let cba = RotationOrder::Cba.rotation([90.0, 0.0, 0.0]);
        assert!(rot_close(&cba, &c90, 1e-15));
    }

    #[test]
    fn channel_parameter_selects_the_convention() {
        assert_eq!(
            RotationOrder::from_channel_parameter(0).unwrap(),
            RotationOrder::YawPitchRoll
        );
        assert_eq!(
            RotationOrder::from_channel_parameter(1).unwrap(),
            RotationOrder::EulerZyz
        );
        assert_eq!(
            RotationOrder::from_channel_parameter(2).unwrap(),
            RotationOrder::Cba
        );
        assert!(RotationOrder::from_channel_parameter(3).is_err());
    }

    #[test]
    fn gimbal_lock_keeps_the_rotation() {
        for order in ORDERS {
            for mid in [90.0, -90.0, 0.0, 180.0] {
                let r = order.rotation([25.0, mid, -40.0]);
                let back = order.rotation(order.angles(&r));
                assert!(rot_close(&r, &back, 1e-12), "{order:?} {mid}");
            }
        }
    }

    #[test]
    fn offsets_with_and_without_rot_trans() {
        let words = PoseWords {
            xyz: [400.0, 700.0, 0.0],
            abc: [0.0, 0.0, -90.0],
        };
        let plain = offset_frame(&words, false).unwrap();
        assert!((plain.translation.vector - Vector3::new(400.0, 700.0, 0.0)).norm() < 1e-12);
        let rotated = offset_frame(&words, true).unwrap();
        // Translation measured in the frame turned by -90 about Z: (400, 700) -> (700, -400).
        assert!((rotated.translation.vector - Vector3::new(700.0, -400.0, 0.0)).norm() < 1e-9);
        assert!(offset_frame(
            &PoseWords {
                xyz: [f64::NAN, 0.0, 0.0],
                abc: [0.0; 3]
            },
            false
        )
        .is_err());
    }

    proptest! {
        #[test]
        fn angles_round_trip_in_principal_ranges(a in -179.0f64..179.0, b in -89.0f64..89.0, c in -179.0f64..179.0, zb in 1.0f64..179.0) {
            for order in [RotationOrder::YawPitchRoll, RotationOrder::Cba, RotationOrder::Zyx] {
                let back = order.angles(&order.rotation([a, b, c]));
                for (x, y) in back.iter().zip([a, b, c]) {
                    prop_assert!((x - y).abs() < 1e-12, "{:?}: {:?} vs {:?}", order, back, [a, b, c]);
                }
            }
            let back = RotationOrder::EulerZyz.angles(&RotationOrder::EulerZyz.rotation([a, zb, c]));
            for (x, y) in back.iter().zip([a, zb, c]) {
                prop_assert!((x - y).abs() < 1e-12, "zyz {:?}", back);
            }
        }

        #[test]
        fn rotations_round_trip_everywhere(a in -360.0f64..360.0, b in -360.0f64..360.0, c in -360.0f64..360.0) {
            for order in ORDERS {
                let r = order.rotation([a, b, c]);
                prop_assert!(rot_close(&r, &order.rotation(order.angles(&r)), 1e-12));
            }
        }
    }
}
