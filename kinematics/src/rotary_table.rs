//! A workpiece rotary table (the seed's example 4): Cartesian axes X Y Z that carry the tool
//! and a table axis C turning the workpiece about a vertical axis through `centre`.
//!
//! The pose is the tool's pose in the workpiece frame (the frame that turns with the table):
//! `pose = Rz(-C) * Trans(xyz - centre)`, orientation `Rz(-C)`. The inverse accepts only
//! rotations about Z (an X Y Z C machine cannot tilt the tool) and takes the table angle from
//! the pose's rotation, on the turn nearest to the current table angle.

use crate::error::KinError;
use crate::frame::check_finite;
use crate::joints::{nearest_turn, JointLimit, Joints, Solutions};
use crate::opw::check_pose;
use crate::Kinematics;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// The rotary-table kinematic (project id 9001); axes X, Y, Z, C.
#[derive(Debug, Clone)]
pub struct RotaryTable {
    centre: Vector3<f64>,
    table_limit: JointLimit,
}

impl RotaryTable {
    /// A table whose axis passes through `centre` (mm, machine coordinates).
    pub fn new(centre: [f64; 3], table_limit: JointLimit) -> Result<Self, KinError> {
        check_finite(&centre)?;
        Ok(Self {
            centre: Vector3::from(centre),
            table_limit,
        })
    }
}

impl Kinematics for RotaryTable {
    fn axis_count(&self) -> usize {
        4
    }

    fn forward(&self, joints: &Joints) -> Result<Isometry3<f64>, KinError> {
        check_finite(joints)?;
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -joints[3].to_radians());
        let relative = Vector3::new(joints[0], joints[1], joints[2]) - self.centre;
        Ok(Isometry3::from_parts(
            Translation3::from(turn * relative),
            turn,
        ))
    }

    fn inverse_all(&self, pose: &Isometry3<f64>, current: &Joints) -> Result<Solutions, KinError> {
        check_pose(pose)?;
        check_finite(current)?;
        let axis = pose.rotation * Vector3::z();
        if (axis - Vector3::z()).norm() > 1e-9 {
            return Err(KinError::Unreachable {
                reason: "an X Y Z C table kinematic realises rotations about Z only",
            });
        }
        let m = pose.rotation.to_rotation_matrix();
        let yaw = m[(1, 0)].atan2(m[(0, 0)]).to_degrees();
        let table =
            nearest_turn(-yaw, current[3], &self.table_limit).ok_or(KinError::JointLimit {
                joint: 4,
                value: -yaw,
                min: self.table_limit.min,
                max: self.table_limit.max,
            })?;
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), table.to_radians());
        let machine = self.centre + turn * pose.translation.vector;
        let mut solutions = Solutions::default();
        solutions.push([machine.x, machine.y, machine.z, table, 0.0, 0.0]);
        Ok(solutions)
    }
}
