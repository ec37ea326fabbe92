//! Kinematic 45: a 6-axis articulated robot with a spherical wrist, solved in closed form.
//!
//! The geometry is the "ortho-parallel basis and spherical wrist" (OPW) model of Brandstötter,
//! Angerer and Hofbaur (2014). Its seven lengths map onto the controller-style parameter list
//! ([`Robot45Params`]) like this, with the arm stretched out horizontally at the manufacturer's
//! zero position:
//!
//! ```text
//!   c1 = base -> joint 2, along Z        a1 = base -> joint 2, along X
//!   c2 = joint 2 -> joint 3, along Z     (upper arm)
//!   c3 = joint 3 -> joint 5, along X     (forearm)      a2 = -(joint 3 -> joint 5, along Z)
//!   c4 = joint 5 -> flange               b  = lateral offset of the forearm (usually 0)
//! ```
//!
//! Joint values are converted into the model's angles as `model = sign * joint - offset`
//! (degrees), where `offset` holds the zero-angle offsets of joints 2 and 3 and `sign` the
//! rotation direction per joint. The inverse yields up to 8 solutions: two shoulder (joint 1)
//! choices, two elbow choices, two wrist flips.
//!
//! Singularities are resolved towards the current configuration instead of failing:
//! * wrist (joint 5 = 0): joints 4 and 6 turn about the same axis; joint 4 keeps its current
//!   value and joint 6 takes the rest;
//! * shoulder (wrist centre on the joint-1 axis): joint 1 keeps its current value.

use crate::error::KinError;
use crate::frame::{check_finite, PoseWords, RotationOrder};
use crate::joints::{distance_sq, nearest_turn, JointLimit, Joints, Solutions};
use crate::Kinematics;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// Parameters of kinematic 45, in the order of the controller's `trafo[0].param[i]` list
/// (see [`Robot45Params::to_param_list`]). Lengths in mm, angles in degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Robot45Params {
    /// Base to joint 2 along Z (`c1`).
    pub base_to_j2_z: f64,
    /// Base to joint 2 along X (`a1`).
    pub base_to_j2_x: f64,
    /// Joint 2 to joint 3 along Z: the upper arm (`c2`).
    pub j2_to_j3_z: f64,
    /// Joint 3 to joint 5 along X: the forearm (`c3`).
    pub j3_to_j5_x: f64,
    /// Joint 3 to joint 5 along Z (`-a2`).
    pub j3_to_j5_z: f64,
    /// Lateral offset of the forearm (`b`).
    pub lateral_offset: f64,
    /// Joint 5 to the flange (`c4`).
    pub j5_to_flange: f64,
    /// Tool offset from the flange: X, Y, Z (mm) and A, B, C (degrees, Z-Y-X).
    pub tool: PoseWords,
    /// Zero-angle offset of joint 2 (degrees).
    pub j2_zero_offset: f64,
    /// Zero-angle offset of joint 3 (degrees).
    pub j3_zero_offset: f64,
    /// Rotation direction per joint: +1 or -1.
    pub directions: [f64; 6],
    /// Joint limits (degrees).
    pub limits: [JointLimit; 6],
}

impl Robot45Params {
    /// KUKA KR 6 R900 sixx (KR AGILUS), KUKA joint convention (A2 = 0: upper arm horizontal).
    /// At all joints 0 the flange is at (980, 0, 435) mm pointing along +X.
    pub fn kuka_kr6_r900_sixx() -> Self {
        Self {
            base_to_j2_z: 400.0,
            base_to_j2_x: 25.0,
            j2_to_j3_z: 455.0,
            j3_to_j5_x: 420.0,
            j3_to_j5_z: 35.0,
            lateral_offset: 0.0,
            j5_to_flange: 80.0,
            tool: PoseWords::default(),
            j2_zero_offset: -90.0,
            j3_zero_offset: 0.0,
            directions: [-1.0, 1.0, 1.0, -1.0, 1.0, -1.0],
            limits: limits([
                (-170.0, 170.0),
                (-190.0, 45.0),
                (-120.0, 156.0),
                (-185.0, 185.0),
                (-120.0, 120.0),
                (-350.0, 350.0),
            ]),
        }
    }

    /// KUKA KR 6 R700 sixx (KR AGILUS), KUKA joint convention.
    pub fn kuka_kr6_r700_sixx() -> Self {
        Self {
            j2_to_j3_z: 315.0,
            j3_to_j5_x: 365.0,
            ..Self::kuka_kr6_r900_sixx()
        }
    }

    /// ABB IRB 2400/10, ABB joint convention (axis 3 measured from the upper arm, hence its
    /// -90 degree zero offset).
    pub fn abb_irb2400() -> Self {
        Self {
            base_to_j2_z: 615.0,
            base_to_j2_x: 100.0,
            j2_to_j3_z: 705.0,
            j3_to_j5_x: 755.0,
            j3_to_j5_z: 135.0,
            lateral_offset: 0.0,
            j5_to_flange: 85.0,
            tool: PoseWords::default(),
            j2_zero_offset: 0.0,
            j3_zero_offset: -90.0,
            directions: [1.0; 6],
            limits: limits([
                (-180.0, 180.0),
                (-100.0, 110.0),
                (-60.0, 65.0),
                (-200.0, 200.0),
                (-120.0, 120.0),
                (-400.0, 400.0),
            ]),
        }
    }

    /// A preset by its CLI name: `kr6r900sixx`, `kr6r700sixx`, `irb2400`.
    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "kr6r900sixx" => Some(Self::kuka_kr6_r900_sixx()),
            "kr6r700sixx" => Some(Self::kuka_kr6_r700_sixx()),
            "irb2400" => Some(Self::abb_irb2400()),
            _ => None,
        }
    }

    /// The flat parameter list, index by index: 0 c1, 1 a1, 2 c2, 3 c3, 4 joint3->5 Z, 5 b,
    /// 6 c4, 7..=12 tool X Y Z A B C, 13 joint-2 zero offset, 14 joint-3 zero offset,
    /// 15..=20 directions.
    pub fn to_param_list(&self) -> [f64; 21] {
        let mut list = [0.0; 21];
        list[..7].copy_from_slice(&[
            self.base_to_j2_z,
            self.base_to_j2_x,
            self.j2_to_j3_z,
            self.j3_to_j5_x,
            self.j3_to_j5_z,
            self.lateral_offset,
            self.j5_to_flange,
        ]);
        list[7..10].copy_from_slice(&self.tool.xyz);
        list[10..13].copy_from_slice(&self.tool.abc);
        list[13] = self.j2_zero_offset;
        list[14] = self.j3_zero_offset;
        list[15..21].copy_from_slice(&self.directions);
        list
    }
}

fn limits(pairs: [(f64, f64); 6]) -> [JointLimit; 6] {
    pairs.map(|(min, max)| JointLimit { min, max })
}

/// The OPW lengths in mm plus conversions, validated.
#[derive(Debug, Clone, Copy)]
struct Geometry {
    a1: f64,
    a2: f64,
    b: f64,
    c1: f64,
    c2: f64,
    c3: f64,
    c4: f64,
    offsets_rad: [f64; 6],
    signs: [f64; 6],
}

/// Kinematic 45.
#[derive(Debug, Clone)]
pub struct Robot45 {
    params: Robot45Params,
    geometry: Geometry,
    tool: Isometry3<f64>,
    tool_inverse: Isometry3<f64>,
}

impl Robot45 {
    /// Validates the parameters: lengths finite, the arm lengths positive, directions +-1,
    /// limits ordered.
    pub fn new(params: Robot45Params) -> Result<Self, KinError> {
        let list = params.to_param_list();
        check_finite(&list)?;
        for (name, value) in [
            ("base_to_j2_z", params.base_to_j2_z),
            ("j2_to_j3_z", params.j2_to_j3_z),
            ("j3_to_j5_x", params.j3_to_j5_x),
            ("j5_to_flange", params.j5_to_flange),
        ] {
            if value <= 0.0 {
                return Err(KinError::BadParameter {
                    name,
                    value,
                    reason: "length must be positive",
                });
            }
        }
        if params.base_to_j2_x < 0.0 {
            return Err(KinError::BadParameter {
                name: "base_to_j2_x",
                value: params.base_to_j2_x,
                reason: "length must not be negative",
            });
        }
        for d in params.directions {
            if d != 1.0 && d != -1.0 {
                return Err(KinError::BadParameter {
                    name: "directions",
                    value: d,
                    reason: "rotation direction must be +1 or -1",
                });
            }
        }
        for l in params.limits {
            if !(l.min <= l.max) {
                return Err(KinError::BadParameter {
                    name: "limits",
                    value: l.min,
                    reason: "lower limit above upper limit",
                });
            }
        }
        let geometry = Geometry {
            a1: params.base_to_j2_x,
            a2: -params.j3_to_j5_z,
            b: params.lateral_offset,
            c1: params.base_to_j2_z,
            c2: params.j2_to_j3_z,
            c3: params.j3_to_j5_x,
            c4: params.j5_to_flange,
            offsets_rad: [0.0, params.j2_zero_offset, params.j3_zero_offset, 0.0, 0.0, 0.0]
                .map(f64::to_radians),
            signs: params.directions,
        };
        let tool = crate::frame::offset_frame(&params.tool, false)?;
        Ok(Self {
            params,
            geometry,
            tool,
            tool_inverse: tool.inverse(),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &Robot45Params {
        &self.params
    }

    fn to_model(&self, joints: &Joints) -> [f64; 6] {
        let g = &self.geometry;
        core::array::from_fn(|i| joints[i].to_radians() * g.signs[i] - g.offsets_rad[i])
    }

    fn from_model(&self, model: &[f64; 6]) -> Joints {
        let g = &self.geometry;
        core::array::from_fn(|i| ((model[i] + g.offsets_rad[i]) * g.signs[i]).to_degrees())
    }

    /// Flange pose of model angles (radians).
    fn flange(&self, q: &[f64; 6]) -> Isometry3<f64> {
        let g = &self.geometry;
        let psi3 = g.a2.atan2(g.c3);
        let k = g.a2.hypot(g.c3);
        let cx1 = g.c2 * q[1].sin() + k * (q[1] + q[2] + psi3).sin() + g.a1;
        let cy1 = g.b;
        let cz1 = g.c2 * q[1].cos() + k * (q[1] + q[2] + psi3).cos();
        let (s1, c1) = q[0].sin_cos();
        let centre = Vector3::new(cx1 * c1 - cy1 * s1, cx1 * s1 + cy1 * c1, cz1 + g.c1);
        let r = arm_rotation(q[0], q[1], q[2]) * wrist_rotation(q[3], q[4], q[5]);
        let position = centre + g.c4 * r.column(2);
        Isometry3::from_parts(
            Translation3::from(position),
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)),
        )
    }

    /// All model-angle solutions (radians) for a flange pose; `current` in model angles
    /// resolves singular configurations.
    fn solve(&self, flange: &Isometry3<f64>, current: &[f64; 6], out: &mut [[f64; 6]; 8]) -> usize {
        let g = &self.geometry;
        let r = flange.rotation.to_rotation_matrix().into_inner();
        let z = r.column(2);
        let centre = flange.translation.vector - g.c4 * z;
        let (cx, cy, cz) = (centre.x, centre.y, centre.z);

        let radial_sq = cx * cx + cy * cy - g.b * g.b;
        if radial_sq < 0.0 {
            return 0;
        }
        let nx1 = radial_sq.sqrt() - g.a1;
        let shoulder_singular = cx.hypot(cy) < 1e-9 && g.b.abs() < 1e-12;
        let (theta1_i, theta1_ii) = if shoulder_singular {
            (current[0], current[0] - core::f64::consts::PI)
        } else {
            let base = cy.atan2(cx);
            let lateral = g.b.atan2(nx1 + g.a1);
            (base - lateral, base + lateral - core::f64::consts::PI)
        };

        let dz = cz - g.c1;
        let s1_sq = nx1 * nx1 + dz * dz;
        let s2_sq = (nx1 + 2.0 * g.a1).powi(2) + dz * dz;
        let k_sq = g.a2 * g.a2 + g.c3 * g.c3;
        let (s1, s2, k) = (s1_sq.sqrt(), s2_sq.sqrt(), k_sq.sqrt());
        let psi3 = g.a2.atan2(g.c3);

        let acos_checked = |x: f64| -> Option<f64> {
            // Tolerate rounding at the workspace boundary; beyond it there is no solution.
            if x.abs() > 1.0 + 1e-12 {
                None
            } else {
                Some(x.clamp(-1.0, 1.0).acos())
            }
        };

        let mut n = 0;
        let arms = [
            (theta1_i, s1, s1_sq, nx1, 1.0),
            (theta1_ii, s2, s2_sq, nx1 + 2.0 * g.a1, -1.0),
        ];
        for (theta1, s, s_sq, reach_x, side) in arms {
            let (Some(alpha), Some(beta)) = (
                acos_checked((s_sq + g.c2 * g.c2 - k_sq) / (2.0 * s * g.c2)),
                acos_checked((s_sq - g.c2 * g.c2 - k_sq) / (2.0 * g.c2 * k)),
            ) else {
                continue;
            };
            let phi = reach_x.atan2(dz);
            for elbow in [-1.0, 1.0] {
                let theta2 = elbow * alpha + side * phi;
                let theta3 = -elbow * beta - psi3;
                for wrist in self.wrist(&r, theta1, theta2, theta3, current) {
                    out[n] = [theta1, theta2, theta3, wrist[0], wrist[1], wrist[2]];
                    n += 1;
                }
            }
        }
        n
    }

    /// The two wrist solutions (theta4, theta5, theta6) for an arm configuration.
    fn wrist(&self, r: &Matrix3<f64>, t1: f64, t2: f64, t3: f64, current: &[f64; 6]) -> [[f64; 3]; 2] {
        let r_ce = arm_rotation(t1, t2, t3).transpose() * r;
        let m = r_ce[(2, 2)].clamp(-1.0, 1.0);
        // |sin(theta5)| from the other two entries of the column: sqrt(1 - m^2) would lose half
        // the digits near the wrist singularity.
        let sin5 = r_ce[(0, 2)].hypot(r_ce[(1, 2)]);
        if sin5 < 1e-9 {
            // Wrist singular: joints 4 and 6 share an axis. Keep joint 4, give joint 6 the rest.
            let phi = r_ce[(1, 0)].atan2(r_ce[(0, 0)]);
            let t5 = if m > 0.0 { 0.0 } else { core::f64::consts::PI };
            let t4 = current[3];
            let t6 = if m > 0.0 {
                phi - t4
            } else {
                t4 - phi + core::f64::consts::PI
            };
            return [[t4, t5, t6], [t4, t5, t6]];
        }
        let t5 = sin5.atan2(m);
        let t4 = r_ce[(1, 2)].atan2(r_ce[(0, 2)]);
        let t6 = r_ce[(2, 1)].atan2(-r_ce[(2, 0)]);
        [
            [t4, t5, t6],
            [t4 + core::f64::consts::PI, -t5, t6 - core::f64::consts::PI],
        ]
    }
}

/// Rotation of the arm (joints 1-3) in the model.
fn arm_rotation(q1: f64, q2: f64, q3: f64) -> Matrix3<f64> {
    let (s1, c1) = q1.sin_cos();
    let (s23, c23) = (q2 + q3).sin_cos();
    Matrix3::new(
        c1 * c23, -s1, c1 * s23, //
        s1 * c23, c1, s1 * s23, //
        -s23, 0.0, c23,
    )
}

/// Rotation of the spherical wrist (Z-Y-Z).
fn wrist_rotation(q4: f64, q5: f64, q6: f64) -> Matrix3<f64> {
    let (s4, c4) = q4.sin_cos();
    let (s5, c5) = q5.sin_cos();
    let (s6, c6) = q6.sin_cos();
    Matrix3::new(
        c4 * c5 * c6 - s4 * s6,
        -c4 * c5 * s6 - s4 * c6,
        c4 * s5,
        s4 * c5 * c6 + c4 * s6,
        -s4 * c5 * s6 + c4 * c6,
        s4 * s5,
        -s5 * c6,
        s5 * s6,
        c5,
    )
}

impl Kinematics for Robot45 {
    fn axis_count(&self) -> usize {
        6
    }

    fn forward(&self, joints: &Joints) -> Result<Isometry3<f64>, KinError> {
        check_finite(joints)?;
        Ok(self.flange(&self.to_model(joints)) * self.tool)
    }

    fn inverse_all(&self, pose: &Isometry3<f64>, current: &Joints) -> Result<Solutions, KinError> {
        check_pose(pose)?;
        check_finite(current)?;
        let flange = pose * self.tool_inverse;
        let current_model = self.to_model(current);
        let mut raw = [[0.0; 6]; 8];
        let n = self.solve(&flange, &current_model, &mut raw);
        if n == 0 {
            return Err(KinError::Unreachable {
                reason: "outside the arm's reach",
            });
        }
        let mut solutions = Solutions::default();
        let mut nearest_violation: Option<(f64, KinError)> = None;
        'candidates: for model in &raw[..n] {
            let mut joints = self.from_model(model);
            for i in 0..6 {
                match nearest_turn(joints[i], current[i], &self.params.limits[i]) {
                    Some(v) => joints[i] = v,
                    None => {
                        let d = distance_sq(&joints, current);
                        if nearest_violation.is_none_or(|(best, _)| d < best) {
                            let l = self.params.limits[i];
                            nearest_violation = Some((
                                d,
                                KinError::JointLimit {
                                    joint: i + 1,
                                    value: joints[i],
                                    min: l.min,
                                    max: l.max,
                                },
                            ));
                        }
                        continue 'candidates;
                    }
                }
            }
            if !solutions.as_slice().iter().any(|s| distance_sq(s, &joints) < 1e-18) {
                solutions.push(joints);
            }
        }
        if solutions.is_empty() {
            return Err(nearest_violation.map(|(_, e)| e).unwrap_or(KinError::Unreachable {
                reason: "no solution within the joint limits",
            }));
        }
        Ok(solutions)
    }
}

/// Refuses poses with NaN or infinite components.
pub(crate) fn check_pose(pose: &Isometry3<f64>) -> Result<(), KinError> {
    let q = pose.rotation.coords;
    let t = pose.translation.vector;
    check_finite(&[t.x, t.y, t.z, q.x, q.y, q.z, q.w])
}

/// Pose words of a frame in the default convention (for the CLI).
pub fn pose_words(pose: &Isometry3<f64>) -> PoseWords {
    PoseWords::from_frame(pose, RotationOrder::YawPitchRoll)
}
