//! `cnc kin fk|ik`: forward and inverse kinematics from the command line, JSON on stdout.
//! Poses are X Y Z (mm) and A B C (degrees) in the default orientation convention
//! (yaw-pitch-roll, `Rz(C) * Ry(-B) * Rx(A)`); joint values in degrees.

use kinematics::cartesian::Cartesian;
use kinematics::opw::{Robot45, Robot45Params};
use kinematics::{Joints, KinError, KinematicId, Kinematics, PoseWords, RotationOrder};
use std::process::ExitCode;

/// `cnc kin ...`.
#[derive(Debug, Clone, clap::Subcommand)]
pub enum KinCommand {
    /// Joint values -> flange/tool pose as {"x","y","z","a","b","c"}.
    Fk {
        /// Kinematic ID: 45 (6-axis robot) or 0 (Cartesian).
        #[arg(long)]
        id: u32,
        /// Robot parameter set for ID 45: kr6r900sixx, kr6r700sixx, irb2400.
        #[arg(long)]
        robot: Option<String>,
        /// Joint values J1..J6 (degrees; X Y Z A B C for ID 0).
        #[arg(num_args = 6, allow_negative_numbers = true, required = true)]
        joints: Vec<f64>,
    },
    /// Pose -> the joint solution nearest to --current (or all with --all).
    Ik {
        /// Kinematic ID: 45 (6-axis robot) or 0 (Cartesian).
        #[arg(long)]
        id: u32,
        /// Robot parameter set for ID 45: kr6r900sixx, kr6r700sixx, irb2400.
        #[arg(long)]
        robot: Option<String>,
        /// Target X Y Z A B C.
        #[arg(num_args = 6, allow_negative_numbers = true, required = true)]
        pose: Vec<f64>,
        /// Current joint values J1..J6 (default all 0).
        #[arg(long, num_args = 6, allow_negative_numbers = true)]
        current: Option<Vec<f64>>,
        /// Print every solution within the joint limits.
        #[arg(long)]
        all: bool,
    },
}

fn build(id: u32, robot: Option<&str>) -> Result<Box<dyn Kinematics>, String> {
    match KinematicId::from_raw(id).map_err(|e| e.to_string())? {
        KinematicId::Robot45 => {
            let name = robot.ok_or("--robot is required for kinematic 45")?;
            let params = Robot45Params::preset(name).ok_or_else(|| {
                format!("unknown robot {name:?} (known: kr6r900sixx, kr6r700sixx, irb2400)")
            })?;
            Ok(Box::new(Robot45::new(params).map_err(|e| e.to_string())?))
        }
        KinematicId::Cartesian => Ok(Box::new(Cartesian::default())),
        other => Err(format!(
            "kinematic {} needs its parameters from a machine configuration; the CLI offers 0 and 45",
            other.raw()
        )),
    }
}

use cnc_core::nc::json::number as num;

fn joints_json(j: &Joints, count: usize) -> String {
    let items: Vec<String> = j[..count].iter().map(|v| num(*v)).collect();
    format!("[{}]", items.join(","))
}

fn to_joints(values: &[f64]) -> Joints {
    core::array::from_fn(|i| values.get(i).copied().unwrap_or(0.0))
}

fn run(command: &KinCommand) -> Result<String, String> {
    let err = |e: KinError| e.to_string();
    match command {
        KinCommand::Fk { id, robot, joints } => {
            let kin = build(*id, robot.as_deref())?;
            let pose = kin.forward(&to_joints(joints)).map_err(err)?;
            let w = PoseWords::from_frame(&pose, RotationOrder::YawPitchRoll);
            Ok(format!(
                "{{\"x\":{},\"y\":{},\"z\":{},\"a\":{},\"b\":{},\"c\":{}}}",
                num(w.xyz[0]),
                num(w.xyz[1]),
                num(w.xyz[2]),
                num(w.abc[0]),
                num(w.abc[1]),
                num(w.abc[2])
            ))
        }
        KinCommand::Ik {
            id,
            robot,
            pose,
            current,
            all,
        } => {
            let kin = build(*id, robot.as_deref())?;
            let words = PoseWords {
                xyz: [pose[0], pose[1], pose[2]],
                abc: [pose[3], pose[4], pose[5]],
            };
            let target = words.to_frame(RotationOrder::YawPitchRoll).map_err(err)?;
            let current = to_joints(current.as_deref().unwrap_or(&[]));
            let n = kin.axis_count();
            if *all {
                let solutions = kin.inverse_all(&target, &current).map_err(err)?;
                let items: Vec<String> = solutions
                    .as_slice()
                    .iter()
                    .map(|s| joints_json(s, n))
                    .collect();
                Ok(format!("[{}]", items.join(",")))
            } else {
                Ok(joints_json(
                    &kin.inverse(&target, &current).map_err(err)?,
                    n,
                ))
            }
        }
    }
}

/// Runs `cnc kin ...`: JSON on stdout and exit 0, or the error on stderr and exit 1.
pub fn main(command: KinCommand) -> ExitCode {
    match run(&command) {
        Ok(json) => {
            println!("{json}");
            ExitCode::SUCCESS
        }
        Err(message) => {
            eprintln!("cnc kin: {message}");
            ExitCode::from(1)
        }
    }
}
