//! `channel.kinematics`: which transformation a channel runs and its geometry, and the tool
//! the channel puts on its flange ([`ToolKinematics`]: the active `D` record).
//!
//! * `id = 0`: Cartesian (X Y Z A B C map 1:1), `tool` the offset of the tool point;
//! * `id = 45`: a six-axis robot with a spherical wrist. A `preset` names a known robot;
//!   `geometry` (the seven OPW lengths), `zero_offsets` (joints 2 and 3), `directions` and
//!   `joint_limits` give any other robot, or override the preset's values. A geometry is
//!   accepted only if the closed-form inverse reproduces its forward kinematics;
//! * `id = 201`: a serial chain of 1..=6 joints given by its Denavit-Hartenberg rows (`chain`),
//!   numerical inverse.
//!
//! `tool` (X Y Z mm, A B C degrees, Z-Y-X) is the flange-to-tool frame of every kinematic.

use kinematics::cartesian::Cartesian;
use kinematics::chain::{DhJoint, JointKind, SerialChain};
use kinematics::opw::{Robot45, Robot45Params};
use kinematics::RotationOrder;
use kinematics::{JointLimit, Joints, KinError, KinematicId, Kinematics, PoseWords, Solutions};
use nalgebra::Isometry3;
use serde::Deserialize;

/// `channel.kinematics`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KinematicsConfig {
    /// Kinematic id: 0 Cartesian, 45 six-axis robot, 201 DH chain.
    #[serde(default)]
    pub id: u32,
    /// For id 45: a known robot (`kr6r900sixx`, `kr6r700sixx`, `irb2400`); the default when no
    /// `geometry` is given.
    #[serde(default)]
    pub preset: Option<String>,
    /// Flange to tool: X Y Z (mm) A B C (degrees, Z-Y-X).
    #[serde(default)]
    pub tool: [f64; 6],
    /// For id 45: the seven lengths (mm).
    #[serde(default)]
    pub geometry: Option<OpwGeometry>,
    /// For id 45: the zero-angle offsets of joints 2 and 3 (degrees).
    #[serde(default)]
    pub zero_offsets: Option<[f64; 2]>,
    /// For id 45: the rotation direction of each joint, +1 or -1.
    #[serde(default)]
    pub directions: Option<[f64; 6]>,
    /// For ids 45 and 201: `[min, max]` of each joint (degrees, or mm for a sliding joint).
    #[serde(default)]
    pub joint_limits: Option<Vec<[f64; 2]>>,
    /// For id 201: the DH rows, base first.
    #[serde(default)]
    pub chain: Vec<DhRow>,
}

/// The seven lengths of kinematic 45 (mm), named after where they run.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct OpwGeometry {
    pub base_to_j2_z: f64,
    pub base_to_j2_x: f64,
    pub j2_to_j3_z: f64,
    pub j3_to_j5_x: f64,
    pub j3_to_j5_z: f64,
    #[serde(default)]
    pub lateral_offset: f64,
    pub j5_to_flange: f64,
}

/// One DH row of kinematic 201: `Rz(theta + q) Tz(d) Tx(a) Rx(alpha)` (a sliding joint adds
/// `q` to `d` instead).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct DhRow {
    pub a: f64,
    pub alpha: f64,
    pub d: f64,
    #[serde(default)]
    pub theta: f64,
    /// A sliding (prismatic) joint.
    #[serde(default)]
    pub prismatic: bool,
}

impl KinematicsConfig {
    /// The kinematics this configures, checked; an error names the key and the reason.
    pub fn build(&self, order: RotationOrder) -> Result<Box<dyn Kinematics + Send>, String> {
        let id = KinematicId::from_raw(self.id).map_err(|e| format!("id: {e}"))?;
        let only = |present: bool, key: &str, ids: &str| match present {
            true => Err(format!("{key} is given for kinematic {ids} only")),
            false => Ok(()),
        };
        only(
            self.preset.is_some() && id != KinematicId::Robot45,
            "preset",
            "45",
        )?;
        only(
            self.geometry.is_some() && id != KinematicId::Robot45,
            "geometry",
            "45",
        )?;
        only(
            !self.chain.is_empty() && id != KinematicId::GenericChain,
            "chain",
            "201",
        )?;
        let t = self.tool;
        let tool = PoseWords {
            xyz: [t[0], t[1], t[2]],
            abc: [t[3], t[4], t[5]],
        };
        fn key(k: &'static str) -> impl Fn(KinError) -> String {
            move |e| format!("{k}: {e}")
        }
        match id {
            KinematicId::Cartesian => Ok(Box::new(
                Cartesian::new(order, &tool, [JointLimit::NONE; 6]).map_err(key("tool"))?,
            )),
            KinematicId::Robot45 => {
                let robot = Robot45::new(self.robot45(tool)?).map_err(key("geometry"))?;
                closed_form_check(&robot)?;
                Ok(Box::new(robot))
            }
            KinematicId::GenericChain => {
                let rows = self.dh_rows()?;
                Ok(Box::new(
                    SerialChain::new(&rows, &tool).map_err(key("chain"))?,
                ))
            }
            other => Err(format!(
                "kinematic {} is not available in channels (0, 45 and 201 are)",
                other.raw()
            )),
        }
    }

    fn robot45(&self, tool: PoseWords) -> Result<Robot45Params, String> {
        let mut p = match (&self.preset, &self.geometry) {
            (Some(name), _) => Robot45Params::preset(name).ok_or_else(|| {
                format!("preset \"{name}\" is not known (known: kr6r900sixx, kr6r700sixx, irb2400)")
            })?,
            (None, _) => Robot45Params::kuka_kr6_r900_sixx(),
        };
        if let Some(g) = self.geometry {
            p.base_to_j2_z = g.base_to_j2_z;
            p.base_to_j2_x = g.base_to_j2_x;
            p.j2_to_j3_z = g.j2_to_j3_z;
            p.j3_to_j5_x = g.j3_to_j5_x;
            p.j3_to_j5_z = g.j3_to_j5_z;
            p.lateral_offset = g.lateral_offset;
            p.j5_to_flange = g.j5_to_flange;
        }
        if let Some([j2, j3]) = self.zero_offsets {
            p.j2_zero_offset = j2;
            p.j3_zero_offset = j3;
        }
        if let Some(d) = self.directions {
            p.directions = d;
        }
        if let Some(limits) = self.joint_limits()? {
            p.limits = limits;
        }
        p.tool = tool;
        Ok(p)
    }

    fn joint_limits(&self) -> Result<Option<[JointLimit; 6]>, String> {
        let Some(list) = &self.joint_limits else {
            return Ok(None);
        };
        let wanted = if self.id == 201 { self.chain.len() } else { 6 };
        if list.len() != wanted {
            return Err(format!(
                "joint_limits: {} entries for {wanted} joints",
                list.len()
            ));
        }
        let mut out = [JointLimit::NONE; 6];
        for (i, [min, max]) in list.iter().copied().enumerate() {
            if min.is_nan() || max.is_nan() || min > max {
                return Err(format!(
                    "joint_limits[{i}] = [{min}, {max}]: the lower limit must not be above the upper"
                ));
            }
            out[i] = JointLimit { min, max };
        }
        Ok(Some(out))
    }

    fn dh_rows(&self) -> Result<Vec<DhJoint>, String> {
        if self.chain.is_empty() || self.chain.len() > 6 {
            return Err(format!(
                "chain: {} rows, kinematic 201 needs 1 to 6",
                self.chain.len()
            ));
        }
        let limits = self.joint_limits()?.unwrap_or([JointLimit::NONE; 6]);
        Ok(self
            .chain
            .iter()
            .zip(limits)
            .map(|(r, limit)| DhJoint {
                a: r.a,
                alpha: r.alpha,
                d: r.d,
                theta: r.theta,
                kind: if r.prismatic {
                    JointKind::Prismatic
                } else {
                    JointKind::Revolute
                },
                limit,
            })
            .collect())
    }
}

/// Joint sets the closed-form check solves (degrees), clamped into the joint limits.
const CHECK_POSES: [Joints; 4] = [
    [10.0, -70.0, 80.0, 20.0, 40.0, 30.0],
    [-35.0, -45.0, 100.0, -40.0, -60.0, 90.0],
    [60.0, -100.0, 60.0, 70.0, 25.0, -45.0],
    [0.0, -80.0, 95.0, 0.0, 35.0, 0.0],
];

/// A geometry kinematic 45 can run: for a few configurations inside the joint limits, one of
/// the closed-form inverse's solutions reproduces the forward pose.
fn closed_form_check(robot: &Robot45) -> Result<(), String> {
    let limits = robot.params().limits;
    for pose in CHECK_POSES {
        let q: Joints = core::array::from_fn(|i| pose[i].clamp(limits[i].min, limits[i].max));
        let refused = || {
            format!(
                "geometry: the closed-form inverse of kinematic 45 does not reproduce the \
                 forward pose at joints {q:?} (no ortho-parallel arm with a spherical wrist?)"
            )
        };
        let target = robot.forward(&q).map_err(|_| refused())?;
        let solutions = robot.inverse_all(&target, &q).unwrap_or_default();
        let found = solutions.as_slice().iter().any(|s| {
            robot.forward(s).is_ok_and(|f| {
                (f.translation.vector - target.translation.vector).norm() < 1e-6
                    && f.rotation.angle_to(&target.rotation) < 1e-9
            })
        });
        if !found {
            return Err(refused());
        }
    }
    Ok(())
}

/// A channel's kinematics with the active tool record on the flange: forward gives the tool
/// point of the record, inverse takes it back off.
pub struct ToolKinematics {
    inner: Box<dyn Kinematics + Send>,
    tool: Isometry3<f64>,
    tool_inverse: Isometry3<f64>,
}

impl ToolKinematics {
    /// `inner` without a tool record.
    pub fn new(inner: Box<dyn Kinematics + Send>) -> Self {
        Self {
            inner,
            tool: Isometry3::identity(),
            tool_inverse: Isometry3::identity(),
        }
    }

    /// Puts the tool record `frame` (flange-side tool point to the record's tool point) on.
    pub fn set_tool(&mut self, frame: Isometry3<f64>) {
        self.tool = frame;
        self.tool_inverse = frame.inverse();
    }
}

impl Kinematics for ToolKinematics {
    fn axis_count(&self) -> usize {
        self.inner.axis_count()
    }

    fn forward(&self, joints: &Joints) -> Result<Isometry3<f64>, KinError> {
        Ok(self.inner.forward(joints)? * self.tool)
    }

    fn inverse_all(&self, pose: &Isometry3<f64>, current: &Joints) -> Result<Solutions, KinError> {
        self.inner.inverse_all(&(pose * self.tool_inverse), current)
    }

    // The inner kinematics' own nearest-solution inverse (kinematic 45 prunes its branches).
    fn inverse(&self, pose: &Isometry3<f64>, current: &Joints) -> Result<Joints, KinError> {
        self.inner.inverse(&(pose * self.tool_inverse), current)
    }
}
