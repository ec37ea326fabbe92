//! Geometry of the CNC: frames in HLI units and NC orientation conventions ([`frame`]), the
//! [`Kinematics`] trait and its implementations selected by the controller's kinematic ID
//! ([`KinematicId`]), and the frame composition of the dynamic coordinate system
//! ([`tracking`]). No channels, programs or shared memory here.
//!
//! Units: mm and degrees at the interfaces (joint values, pose words), `Isometry3<f64>` in mm
//! for poses. Every computation refuses NaN/inf input and returns a typed [`KinError`] instead
//! of NaN. Forward and inverse calls do not allocate.

#![forbid(unsafe_code)]

pub mod cartesian;
pub mod chain;
pub mod error;
pub mod frame;
pub mod joints;
pub mod opw;
pub mod rotary_table;
pub mod tracking;

pub use error::KinError;
pub use frame::{PoseWords, RotationOrder};
pub use joints::{JointLimit, Joints, Solutions};

use nalgebra::Isometry3;

/// A kinematic transformation between axis values and the tool pose.
pub trait Kinematics {
    /// Number of axes used in [`Joints`].
    fn axis_count(&self) -> usize;

    /// Axis values -> tool pose (tool offset included).
    fn forward(&self, joints: &Joints) -> Result<Isometry3<f64>, KinError>;

    /// Tool pose -> every solution within the joint limits; `current` picks the turn of
    /// endless or multi-turn joints and resolves singular configurations.
    fn inverse_all(&self, pose: &Isometry3<f64>, current: &Joints) -> Result<Solutions, KinError>;

    /// Tool pose -> the solution nearest to `current` (Euclidean distance in axis space).
    fn inverse(&self, pose: &Isometry3<f64>, current: &Joints) -> Result<Joints, KinError> {
        let solutions = self.inverse_all(pose, current)?;
        solutions
            .as_slice()
            .iter()
            .copied()
            .min_by(|a, b| {
                joints::distance_sq(a, current).total_cmp(&joints::distance_sq(b, current))
            })
            .ok_or(KinError::Unreachable {
                reason: "no solution",
            })
    }
}

/// The controller's kinematic IDs this crate implements.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KinematicId {
    /// 0: Cartesian, axes map 1:1 (X Y Z A B C).
    Cartesian,
    /// 45: 6-axis articulated robot with spherical wrist, closed form.
    Robot45,
    /// 201: generic serial chain (DH table), numerical inverse. The specification names the ID
    /// without defining it; this meaning is our choice.
    GenericChain,
    /// Workpiece rotary table (X Y Z + table C). Not a controller ID: project number 9001.
    RotaryTable,
}

impl KinematicId {
    /// The numeric ID.
    pub fn raw(self) -> u32 {
        match self {
            KinematicId::Cartesian => 0,
            KinematicId::Robot45 => 45,
            KinematicId::GenericChain => 201,
            KinematicId::RotaryTable => 9001,
        }
    }

    /// Decodes a numeric ID.
    pub fn from_raw(raw: u32) -> Result<Self, KinError> {
        match raw {
            0 => Ok(KinematicId::Cartesian),
            45 => Ok(KinematicId::Robot45),
            201 => Ok(KinematicId::GenericChain),
            9001 => Ok(KinematicId::RotaryTable),
            other => Err(KinError::BadParameter {
                name: "kinematic id",
                value: f64::from(other),
                reason: "known ids: 0, 45, 201, 9001",
            }),
        }
    }
}
