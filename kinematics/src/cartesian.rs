//! Kinematic 0: Cartesian. The axes X Y Z A B C are the tool pose's words 1:1 (A/B/C in the
//! channel's orientation convention), followed by the tool offset.

use crate::error::KinError;
use crate::frame::{check_finite, offset_frame, PoseWords, RotationOrder};
use crate::joints::{nearest_turn, JointLimit, Joints, Solutions};
use crate::opw::check_pose;
use crate::Kinematics;
use nalgebra::Isometry3;

/// Kinematic 0.
#[derive(Debug, Clone)]
pub struct Cartesian {
    order: RotationOrder,
    tool: Isometry3<f64>,
    tool_inverse: Isometry3<f64>,
    limits: [JointLimit; 6],
}

impl Cartesian {
    /// Cartesian axes with orientation words in `order` and a tool offset (Z-Y-X angles).
    pub fn new(
        order: RotationOrder,
        tool: &PoseWords,
        limits: [JointLimit; 6],
    ) -> Result<Self, KinError> {
        let tool = offset_frame(tool, false)?;
        Ok(Self {
            order,
            tool,
            tool_inverse: tool.inverse(),
            limits,
        })
    }
}

impl Default for Cartesian {
    fn default() -> Self {
        Self::new(
            RotationOrder::default(),
            &PoseWords::default(),
            [JointLimit::NONE; 6],
        )
        .expect("zero tool is valid")
    }
}

impl Kinematics for Cartesian {
    fn axis_count(&self) -> usize {
        6
    }

    fn forward(&self, joints: &Joints) -> Result<Isometry3<f64>, KinError> {
        check_finite(joints)?;
        let words = PoseWords {
            xyz: [joints[0], joints[1], joints[2]],
            abc: [joints[3], joints[4], joints[5]],
        };
        Ok(words.to_frame(self.order)? * self.tool)
    }

    fn inverse_all(&self, pose: &Isometry3<f64>, current: &Joints) -> Result<Solutions, KinError> {
        check_pose(pose)?;
        check_finite(current)?;
        let words = PoseWords::from_frame(&(pose * self.tool_inverse), self.order);
        let [a, b, c] = words.abc;
        // Every orientation has a second angle triple; both are offered.
        let alternative = match self.order {
            RotationOrder::EulerZyz => [a + 180.0, -b, c + 180.0],
            // B enters negated: Rz(C) Ry(-B) Rx(A).
            RotationOrder::YawPitchRoll => [a + 180.0, -180.0 - b, c + 180.0],
            RotationOrder::Cba | RotationOrder::Zyx => [a + 180.0, 180.0 - b, c + 180.0],
        };
        let mut solutions = Solutions::default();
        let mut violation = None;
        for abc in [[a, b, c], alternative] {
            let mut joints = [
                words.xyz[0],
                words.xyz[1],
                words.xyz[2],
                abc[0],
                abc[1],
                abc[2],
            ];
            let mut ok = true;
            for i in 0..6 {
                let fitted = if i < 3 {
                    self.limits[i].contains(joints[i]).then_some(joints[i])
                } else {
                    nearest_turn(joints[i], current[i], &self.limits[i])
                };
                match fitted {
                    Some(v) => joints[i] = v,
                    None => {
                        violation = Some(KinError::JointLimit {
                            joint: i + 1,
                            value: joints[i],
                            min: self.limits[i].min,
                            max: self.limits[i].max,
                        });
                        ok = false;
                        break;
                    }
                }
            }
            if ok {
                solutions.push(joints);
            }
        }
        if solutions.is_empty() {
            return Err(violation.unwrap_or(KinError::Unreachable {
                reason: "no solution",
            }));
        }
        Ok(solutions)
    }
}
