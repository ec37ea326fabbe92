//! Kinematic 201 (our choice; the specification names the ID without defining it): a generic
//! serial chain of up to six joints given as a Denavit-Hartenberg table, with a
//! damped-least-squares numerical inverse.
//!
//! Joint `i` contributes `Rz(theta_i) * Tz(d_i) * Tx(a_i) * Rx(alpha_i)`, where `theta_i` is the
//! joint value plus its offset for a revolute joint and `d_i` the joint value plus its offset
//! for a prismatic one. The inverse iterates
//! `dq = J^T (J J^T + lambda^2 I)^-1 e` from the current configuration, with `e` the position
//! error (mm) and the orientation error (axis-angle, scaled by [`ORIENTATION_SCALE`] mm/rad),
//! and returns the one configuration it converges to. It does not allocate.

use crate::error::KinError;
use crate::frame::{check_finite, offset_frame, PoseWords};
use crate::joints::{JointLimit, Joints, Solutions};
use crate::opw::check_pose;
use crate::Kinematics;
use nalgebra::{Isometry3, Matrix6, Translation3, UnitQuaternion, Vector3, Vector6};

/// Weight of orientation errors against position errors, mm per radian.
pub const ORIENTATION_SCALE: f64 = 1000.0;
const MAX_ITERATIONS: usize = 200;
const POSITION_TOLERANCE: f64 = 1e-10;
const DAMPING_SQ: f64 = 1e-6;

/// Kind of a chain joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// Rotates about its Z axis; value in degrees.
    Revolute,
    /// Slides along its Z axis; value in mm.
    Prismatic,
}

/// One row of the DH table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DhJoint {
    /// Link length along X, mm.
    pub a: f64,
    /// Link twist about X, degrees.
    pub alpha: f64,
    /// Link offset along Z, mm.
    pub d: f64,
    /// Joint angle offset, degrees.
    pub theta: f64,
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// Joint limits (degrees or mm).
    pub limit: JointLimit,
}

/// Kinematic 201.
#[derive(Debug, Clone)]
pub struct SerialChain {
    joints: [DhJoint; 6],
    count: usize,
    tool: Isometry3<f64>,
}

impl SerialChain {
    /// A chain of 1..=6 joints with a tool offset (Z-Y-X angles).
    pub fn new(rows: &[DhJoint], tool: &PoseWords) -> Result<Self, KinError> {
        if rows.is_empty() || rows.len() > 6 {
            return Err(KinError::BadParameter {
                name: "joints",
                value: rows.len() as f64,
                reason: "a chain has 1 to 6 joints",
            });
        }
        for row in rows {
            check_finite(&[row.a, row.alpha, row.d, row.theta])?;
        }
        let mut joints = [DhJoint {
            a: 0.0,
            alpha: 0.0,
            d: 0.0,
            theta: 0.0,
            kind: JointKind::Revolute,
            limit: JointLimit::NONE,
        }; 6];
        joints[..rows.len()].copy_from_slice(rows);
        Ok(Self {
            joints,
            count: rows.len(),
            tool: offset_frame(tool, false)?,
        })
    }

    /// Frames of every joint axis (the frame before joint i) and the tool frame.
    fn frames(&self, q: &Joints) -> ([Isometry3<f64>; 6], Isometry3<f64>) {
        let mut axes = [Isometry3::identity(); 6];
        let mut t = Isometry3::identity();
        for (i, row) in self.joints[..self.count].iter().enumerate() {
            axes[i] = t;
            let (theta, d) = match row.kind {
                JointKind::Revolute => ((q[i] + row.theta).to_radians(), row.d),
                JointKind::Prismatic => (row.theta.to_radians(), row.d + q[i]),
            };
            t =
                t * Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), theta),
                ) * Isometry3::from_parts(
                    Translation3::new(row.a, 0.0, d),
                    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), row.alpha.to_radians()),
                );
        }
        (axes, t * self.tool)
    }

    fn error(target: &Isometry3<f64>, actual: &Isometry3<f64>) -> Vector6<f64> {
        let dp = target.translation.vector - actual.translation.vector;
        let dr = (target.rotation * actual.rotation.inverse()).scaled_axis() * ORIENTATION_SCALE;
        Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z)
    }
}

impl Kinematics for SerialChain {
    fn axis_count(&self) -> usize {
        self.count
    }

    fn forward(&self, joints: &Joints) -> Result<Isometry3<f64>, KinError> {
        check_finite(joints)?;
        Ok(self.frames(joints).1)
    }

    fn inverse_all(&self, pose: &Isometry3<f64>, current: &Joints) -> Result<Solutions, KinError> {
        check_pose(pose)?;
        check_finite(current)?;
        let mut q = *current;
        for _ in 0..MAX_ITERATIONS {
            let (axes, tip) = self.frames(&q);
            let e = Self::error(pose, &tip);
            if e.fixed_rows::<3>(0).norm() < POSITION_TOLERANCE
                && e.fixed_rows::<3>(3).norm() < POSITION_TOLERANCE
            {
                for (i, row) in self.joints[..self.count].iter().enumerate() {
                    if !row.limit.contains(q[i]) {
                        return Err(KinError::JointLimit {
                            joint: i + 1,
                            value: q[i],
                            min: row.limit.min,
                            max: row.limit.max,
                        });
                    }
                }
                let mut solutions = Solutions::default();
                solutions.push(q);
                return Ok(solutions);
            }
            // Geometric Jacobian in (mm, mm-scaled rad) per (rad | mm); unused columns stay 0.
            let mut jac = Matrix6::<f64>::zeros();
            for (i, row) in self.joints[..self.count].iter().enumerate() {
                let z = axes[i].rotation * Vector3::z();
                let column = match row.kind {
                    JointKind::Revolute => {
                        let r = tip.translation.vector - axes[i].translation.vector;
                        let v = z.cross(&r);
                        let w = z * ORIENTATION_SCALE;
                        Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z)
                    }
                    JointKind::Prismatic => Vector6::new(z.x, z.y, z.z, 0.0, 0.0, 0.0),
                };
                jac.set_column(i, &column);
            }
            let jjt = jac * jac.transpose() + Matrix6::identity() * DAMPING_SQ;
            let Some(step) = jjt.cholesky().map(|c| jac.transpose() * c.solve(&e)) else {
                return Err(KinError::Singular {
                    reason: "damped normal equations not positive definite",
                });
            };
            for (i, row) in self.joints[..self.count].iter().enumerate() {
                q[i] += match row.kind {
                    JointKind::Revolute => step[i].to_degrees(),
                    JointKind::Prismatic => step[i],
                };
            }
            if !q.iter().all(|v| v.is_finite()) {
                return Err(KinError::Singular {
                    reason: "iteration diverged",
                });
            }
        }
        Err(KinError::Unreachable {
            reason: "numerical inverse did not converge (target outside the workspace?)",
        })
    }
}
