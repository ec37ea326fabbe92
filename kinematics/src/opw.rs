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
    b: f64,
    c1: f64,
    c2: f64,
    c4: f64,
    /// Distance joint 3 -> wrist centre, and its angle against the forearm.
    k: f64,
    psi3: f64,
    sin_psi3: f64,
    cos_psi3: f64,
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
            if l.min > l.max || l.min.is_nan() || l.max.is_nan() {
                return Err(KinError::BadParameter {
                    name: "limits",
                    value: l.min,
                    reason: "lower limit above upper limit",
                });
            }
        }
        let a2 = -params.j3_to_j5_z;
        let k = a2.hypot(params.j3_to_j5_x);
        let geometry = Geometry {
            k,
            psi3: a2.atan2(params.j3_to_j5_x),
            sin_psi3: a2 / k,
            cos_psi3: params.j3_to_j5_x / k,
            a1: params.base_to_j2_x,
            b: params.lateral_offset,
            c1: params.base_to_j2_z,
            c2: params.j2_to_j3_z,
            c4: params.j5_to_flange,
            offsets_rad: [
                0.0,
                params.j2_zero_offset,
                params.j3_zero_offset,
                0.0,
                0.0,
                0.0,
            ]
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

    fn model_of_joints(&self, joints: &Joints) -> [f64; 6] {
        let g = &self.geometry;
        core::array::from_fn(|i| joints[i].to_radians() * g.signs[i] - g.offsets_rad[i])
    }

    fn joints_of_model(&self, model: &[f64; 6]) -> Joints {
        let g = &self.geometry;
        core::array::from_fn(|i| ((model[i] + g.offsets_rad[i]) * g.signs[i]).to_degrees())
    }

    /// Flange pose of model angles (radians).
    fn flange(&self, q: &[f64; 6]) -> Isometry3<f64> {
        let g = &self.geometry;
        let (sin2, cos2) = q[1].sin_cos();
        let (sin_w, cos_w) = (q[1] + q[2] + g.psi3).sin_cos();
        let cx1 = g.c2 * sin2 + g.k * sin_w + g.a1;
        let cy1 = g.b;
        let cz1 = g.c2 * cos2 + g.k * cos_w;
        let (s1, c1) = q[0].sin_cos();
        let centre = Vector3::new(cx1 * c1 - cy1 * s1, cx1 * s1 + cy1 * c1, cz1 + g.c1);
        let r = arm_rotation(q[0], q[1], q[2]) * wrist_rotation(q[3], q[4], q[5]);
        let position = centre + g.c4 * r.column(2);
        Isometry3::from_parts(
            Translation3::from(position),
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)),
        )
    }

    /// The up to four arm configurations (joints 1-3, model radians) that put the wrist
    /// centre of `flange` in place; `current` (model angles) resolves the shoulder singularity.
    ///
    /// Speed: sines and cosines of the arm angles come from the triangle's sides by the
    /// angle-addition formulas instead of trigonometric calls; only the output angles
    /// themselves cost an `acos`/`atan2`.
    fn arm_configs(
        &self,
        flange: &Isometry3<f64>,
        current: &[f64; 6],
        out: &mut [ArmConfig; 4],
    ) -> usize {
        let g = &self.geometry;
        let centre = flange.translation.vector - g.c4 * (flange.rotation * Vector3::z());
        let (cx, cy, cz) = (centre.x, centre.y, centre.z);

        let rho = (cx * cx + cy * cy).sqrt();
        let radial_sq = rho * rho - g.b * g.b;
        if radial_sq < 0.0 {
            return 0;
        }
        let nx1 = radial_sq.sqrt() - g.a1;
        // Joint 1 of the first shoulder configuration, with its sine and cosine; the second
        // configuration is turned by a further 2*lateral - pi.
        let (theta1_i, sin1, cos1, theta1_ii, sin1_ii, cos1_ii) = if rho < 1e-9 && g.b.abs() < 1e-12
        {
            let (s, c) = current[0].sin_cos();
            (current[0], s, c, current[0] - core::f64::consts::PI, -s, -c)
        } else if g.b == 0.0 {
            let (s, c) = (cy / rho, cx / rho);
            let t = cy.atan2(cx);
            (t, s, c, t - core::f64::consts::PI, -s, -c)
        } else {
            let base = cy.atan2(cx);
            let lateral = g.b.atan2(nx1 + g.a1);
            let (t1, t2) = (base - lateral, base + lateral - core::f64::consts::PI);
            let ((s1, c1), (s2, c2)) = (t1.sin_cos(), t2.sin_cos());
            (t1, s1, c1, t2, s2, c2)
        };

        let dz = cz - g.c1;
        let k_sq = g.k * g.k;
        let mut n = 0;
        let arms = [
            (theta1_i, sin1, cos1, nx1, 1.0),
            (theta1_ii, sin1_ii, cos1_ii, nx1 + 2.0 * g.a1, -1.0),
        ];
        for (theta1, sin_t1, cos_t1, reach_x, side) in arms {
            let s_sq = reach_x * reach_x + dz * dz;
            let s = s_sq.sqrt();
            if s < 1e-12 {
                continue; // wrist centre on joint 2: not a configuration of this arm
            }
            let cos_alpha = (s_sq + g.c2 * g.c2 - k_sq) / (2.0 * s * g.c2);
            let cos_beta = (s_sq - g.c2 * g.c2 - k_sq) / (2.0 * g.c2 * g.k);
            // Tolerate rounding at the workspace boundary; beyond it there is no solution.
            if cos_alpha.abs() > 1.0 + 1e-12 || cos_beta.abs() > 1.0 + 1e-12 {
                continue;
            }
            let (cos_alpha, cos_beta) = (cos_alpha.clamp(-1.0, 1.0), cos_beta.clamp(-1.0, 1.0));
            let sin_alpha = (1.0 - cos_alpha * cos_alpha).sqrt();
            let sin_beta = (1.0 - cos_beta * cos_beta).sqrt();
            let (alpha, beta) = (cos_alpha.acos(), cos_beta.acos());
            let phi = reach_x.atan2(dz);
            let (sin_phi, cos_phi) = (side * reach_x / s, dz / s); // of side * phi
            for elbow in [-1.0, 1.0] {
                // theta2 + theta3 = elbow * (alpha - beta) + side * phi - psi3
                let sin_d = elbow * (sin_alpha * cos_beta - cos_alpha * sin_beta);
                let cos_d = cos_alpha * cos_beta + sin_alpha * sin_beta;
                let (sin_e, cos_e) = (
                    sin_d * cos_phi + cos_d * sin_phi,
                    cos_d * cos_phi - sin_d * sin_phi,
                );
                out[n] = ArmConfig {
                    angles: [theta1, elbow * alpha + side * phi, -elbow * beta - g.psi3],
                    rotation: arm_rotation_sc(
                        sin_t1,
                        cos_t1,
                        sin_e * g.cos_psi3 - cos_e * g.sin_psi3,
                        cos_e * g.cos_psi3 + sin_e * g.sin_psi3,
                    ),
                };
                n += 1;
            }
        }
        n
    }

    /// Joint values of model angles, each turned to lie nearest `current` within its limits;
    /// `Err((joint index, value))` for the first joint that fits no turn.
    fn finish(&self, model: &[f64; 6], current: &Joints) -> Result<Joints, (usize, f64)> {
        let mut joints = self.joints_of_model(model);
        for i in 0..6 {
            joints[i] = nearest_turn(joints[i], current[i], &self.params.limits[i])
                .ok_or((i, joints[i]))?;
        }
        Ok(joints)
    }

    fn limit_error(&self, (joint, value): (usize, f64)) -> KinError {
        let l = self.params.limits[joint];
        KinError::JointLimit {
            joint: joint + 1,
            value,
            min: l.min,
            max: l.max,
        }
    }

    /// Shared start of both inverses: validated input, flange pose, arm configurations.
    fn prepare(&self, pose: &Isometry3<f64>, current: &Joints) -> Result<Prepared, KinError> {
        check_pose(pose)?;
        check_finite(current)?;
        let flange = pose * self.tool_inverse;
        let current_model = self.model_of_joints(current);
        let mut arms = [ArmConfig::default(); 4];
        let count = self.arm_configs(&flange, &current_model, &mut arms);
        if count == 0 {
            return Err(KinError::Unreachable {
                reason: "outside the arm's reach",
            });
        }
        Ok(Prepared {
            rotation: flange.rotation.to_rotation_matrix().into_inner(),
            current4: current_model[3],
            arms,
            count,
        })
    }
}

/// Joints 1-3 of one arm configuration (model radians) and their rotation.
#[derive(Debug, Clone, Copy, Default)]
struct ArmConfig {
    angles: [f64; 3],
    rotation: Matrix3<f64>,
}

#[derive(Debug)]
struct Prepared {
    rotation: Matrix3<f64>,
    current4: f64,
    arms: [ArmConfig; 4],
    count: usize,
}

impl Prepared {
    /// The two complete model-angle solutions (both wrist flips) of one arm configuration.
    fn complete(&self, arm: &ArmConfig) -> [[f64; 6]; 2] {
        wrist_solutions(&arm.rotation, &self.rotation, self.current4).map(|w| {
            [
                arm.angles[0],
                arm.angles[1],
                arm.angles[2],
                w[0],
                w[1],
                w[2],
            ]
        })
    }
}

/// The two wrist solutions (theta4, theta5, theta6) for an arm rotation.
fn wrist_solutions(arm: &Matrix3<f64>, r: &Matrix3<f64>, current4: f64) -> [[f64; 3]; 2] {
    let r_ce = arm.transpose() * r;
    let m = r_ce[(2, 2)].clamp(-1.0, 1.0);
    // |sin(theta5)| from the other two entries of the column: sqrt(1 - m^2) would lose half
    // the digits near the wrist singularity.
    let sin5 = (r_ce[(0, 2)] * r_ce[(0, 2)] + r_ce[(1, 2)] * r_ce[(1, 2)]).sqrt();
    if sin5 < 1e-9 {
        // Wrist singular: joints 4 and 6 share an axis. Keep joint 4, give joint 6 the rest.
        let phi = r_ce[(1, 0)].atan2(r_ce[(0, 0)]);
        let (t5, t6) = if m > 0.0 {
            (0.0, phi - current4)
        } else {
            (
                core::f64::consts::PI,
                current4 - phi + core::f64::consts::PI,
            )
        };
        return [[current4, t5, t6], [current4, t5, t6]];
    }
    let t5 = sin5.atan2(m);
    let t4 = r_ce[(1, 2)].atan2(r_ce[(0, 2)]);
    let t6 = r_ce[(2, 1)].atan2(-r_ce[(2, 0)]);
    [
        [t4, t5, t6],
        [t4 + core::f64::consts::PI, -t5, t6 - core::f64::consts::PI],
    ]
}

/// Rotation of the arm (joints 1-3) from sin/cos of joint 1 and of joints 2+3.
fn arm_rotation_sc(s1: f64, c1: f64, s23: f64, c23: f64) -> Matrix3<f64> {
    Matrix3::new(
        c1 * c23,
        -s1,
        c1 * s23, //
        s1 * c23,
        c1,
        s1 * s23, //
        -s23,
        0.0,
        c23,
    )
}

/// Rotation of the arm (joints 1-3) in the model.
fn arm_rotation(q1: f64, q2: f64, q3: f64) -> Matrix3<f64> {
    let (s1, c1) = q1.sin_cos();
    let (s23, c23) = (q2 + q3).sin_cos();
    arm_rotation_sc(s1, c1, s23, c23)
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
        Ok(self.flange(&self.model_of_joints(joints)) * self.tool)
    }

    fn inverse_all(&self, pose: &Isometry3<f64>, current: &Joints) -> Result<Solutions, KinError> {
        let prepared = self.prepare(pose, current)?;
        let mut solutions = Solutions::default();
        let mut nearest_violation: Option<(f64, (usize, f64))> = None;
        for arm in &prepared.arms[..prepared.count] {
            for model in prepared.complete(arm) {
                match self.finish(&model, current) {
                    Ok(joints) => {
                        if !solutions
                            .as_slice()
                            .iter()
                            .any(|s| distance_sq(s, &joints) < 1e-18)
                        {
                            solutions.push(joints);
                        }
                    }
                    Err(violation) => {
                        let d = distance_sq(&self.joints_of_model(&model), current);
                        if nearest_violation.is_none_or(|(best, _)| d < best) {
                            nearest_violation = Some((d, violation));
                        }
                    }
                }
            }
        }
        if solutions.is_empty() {
            return Err(match nearest_violation {
                Some((_, violation)) => self.limit_error(violation),
                None => KinError::Unreachable {
                    reason: "no solution within the joint limits",
                },
            });
        }
        Ok(solutions)
    }

    /// The nearest solution without computing every wrist: arm configurations are visited in
    /// order of their joint 1-3 distance, and one whose arm distance alone exceeds the best
    /// complete solution so far cannot win. Same result as the minimum over `inverse_all`.
    fn inverse(&self, pose: &Isometry3<f64>, current: &Joints) -> Result<Joints, KinError> {
        let prepared = self.prepare(pose, current)?;
        let mut order = [(f64::INFINITY, 0usize); 4];
        for (i, arm) in prepared.arms[..prepared.count].iter().enumerate() {
            let model = [arm.angles[0], arm.angles[1], arm.angles[2], 0.0, 0.0, 0.0];
            let joints = self.joints_of_model(&model);
            let mut d = 0.0;
            for j in 0..3 {
                d += match nearest_turn(joints[j], current[j], &self.params.limits[j]) {
                    Some(v) => (v - current[j]) * (v - current[j]),
                    None => f64::INFINITY,
                };
            }
            order[i] = (d, i);
        }
        order[..prepared.count].sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let mut best: Option<(f64, Joints)> = None;
        let mut violation = None;
        for &(arm_distance, index) in &order[..prepared.count] {
            if best.is_some_and(|(d, _)| arm_distance >= d) {
                break;
            }
            let arm = &prepared.arms[index];
            for model in prepared.complete(arm) {
                match self.finish(&model, current) {
                    Ok(joints) => {
                        let d = distance_sq(&joints, current);
                        if best.is_none_or(|(b, _)| d < b) {
                            best = Some((d, joints));
                        }
                    }
                    Err(v) => violation = violation.or(Some(v)),
                }
            }
        }
        match (best, violation) {
            (Some((_, joints)), _) => Ok(joints),
            // Fall back to the exhaustive search for its error (nearest violation).
            _ => self.inverse_all(pose, current).map(|s| s.as_slice()[0]),
        }
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
