//! Cross-check of kinematic 45 against the `rs-opw-kinematics` crate on its published test
//! cases (`src/tests/data/cases.yaml` of the crate, read from cargo's registry at run time;
//! nothing of it is copied here): our forward kinematics reproduces each case's pose, and our
//! eight inverse solutions equal the crate's, to 1e-9.

use kinematics::joints::JointLimit;
use kinematics::opw::{Robot45, Robot45Params};
use kinematics::{Joints, Kinematics};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use rs_opw_kinematics::glam::{DQuat, DVec3};
use rs_opw_kinematics::kinematic_traits::{Kinematics as _, Pose};
use rs_opw_kinematics::kinematics_impl::OPWKinematics;
use rs_opw_kinematics::parameters::opw_kinematics::Parameters;
use std::path::PathBuf;

struct Case {
    id: u32,
    robot: String,
    joints: [f64; 6],
    translation_m: [f64; 3],
    quaternion_xyzw: [f64; 4],
}

fn numbers(text: &str) -> Vec<f64> {
    text.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e' || c == 'E'))
        .filter(|t| !t.is_empty() && *t != "-" && *t != "e")
        .filter_map(|t| t.parse().ok())
        .collect()
}

fn cases_file() -> PathBuf {
    let home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(std::env::var_os("HOME").expect("HOME")).join(".cargo"));
    let registry = home.join("registry").join("src");
    for index in std::fs::read_dir(&registry).expect("cargo registry sources") {
        let path = index
            .unwrap()
            .path()
            .join("rs-opw-kinematics-3.0.0/src/tests/data/cases.yaml");
        if path.exists() {
            return path;
        }
    }
    panic!(
        "rs-opw-kinematics 3.0.0 sources not found under {}",
        registry.display()
    );
}

fn load_cases() -> Vec<Case> {
    let text = std::fs::read_to_string(cases_file()).unwrap();
    let mut cases = Vec::new();
    let mut lines = text.lines().map(str::trim);
    while let Some(line) = lines.next() {
        let Some(id) = line.strip_prefix("- id:") else {
            continue;
        };
        let robot = lines
            .next()
            .unwrap()
            .trim_start_matches("parameters:")
            .trim()
            .to_string();
        let joints = numbers(lines.next().unwrap());
        let pose_line = lines.next().unwrap();
        let (t, q) = pose_line.split_once("quaternion").unwrap();
        let t = numbers(t);
        let q = numbers(q);
        cases.push(Case {
            id: id.trim().parse().unwrap(),
            robot,
            joints: joints[..6].try_into().unwrap(),
            translation_m: t[..3].try_into().unwrap(),
            quaternion_xyzw: q[..4].try_into().unwrap(),
        });
    }
    cases
}

fn ours(robot: &str) -> Robot45 {
    let params = match robot {
        "Irb2400_10" => Robot45Params::abb_irb2400(),
        "KukaKR6_R700_sixx" => Robot45Params::kuka_kr6_r700_sixx(),
        other => panic!("unexpected robot {other}"),
    };
    // The published cases ignore joint limits.
    Robot45::new(Robot45Params {
        limits: [JointLimit::NONE; 6],
        ..params
    })
    .unwrap()
}

fn theirs(robot: &str) -> OPWKinematics {
    OPWKinematics::new(match robot {
        "Irb2400_10" => Parameters::irb2400_10(),
        "KukaKR6_R700_sixx" => Parameters::kuka_kr6_r700_sixx(),
        other => panic!("unexpected robot {other}"),
    })
}

fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

#[test]
fn forward_and_inverse_agree_with_rs_opw_kinematics_on_its_cases() {
    let cases = load_cases();
    assert_eq!(cases.len(), 2048, "the crate publishes 2 x 1024 cases");
    let mut compared_solutions = 0;
    let mut singular_cases = 0;
    for case in &cases {
        let robot = ours(&case.robot);
        let peer = theirs(&case.robot);

        // Forward: our pose (mm) against the published pose (m).
        let pose = robot.forward(&case.joints).unwrap();
        let t = pose.translation.vector / 1000.0;
        for (i, expected) in case.translation_m.iter().enumerate() {
            assert!(
                (t[i] - expected).abs() < 1e-9,
                "case {}: translation {t} vs {:?}",
                case.id,
                case.translation_m
            );
        }
        let [x, y, z, w] = case.quaternion_xyzw;
        let published = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
        assert!(
            pose.rotation.angle_to(&published) < 1e-9,
            "case {}: rotation",
            case.id
        );

        // Inverse: our solution set against the crate's, both from the published pose.
        let target = Isometry3::from_parts(
            Translation3::new(
                case.translation_m[0] * 1000.0,
                case.translation_m[1] * 1000.0,
                case.translation_m[2] * 1000.0,
            ),
            published,
        );
        let mine = robot.inverse_all(&target, &[0.0; 6]).unwrap();
        let peer_pose = Pose::from_parts(
            DVec3::from_array(case.translation_m),
            DQuat::from_xyzw(x, y, z, w),
        );
        let peer_solutions: Vec<Joints> = peer
            .inverse(&peer_pose)
            .into_iter()
            .map(|s| s.map(f64::to_degrees))
            .collect();
        let wrist_singular = peer_solutions
            .iter()
            .any(|p| p[4].to_radians().sin().abs() < 1e-6);
        if wrist_singular {
            // Joints 4 and 6 share (or nearly share) an axis: infinitely many solutions, each
            // solver picks its own representatives, and the problem is ill-conditioned. Ours
            // must reproduce the pose to 1e-7 mm and 1e-9 rad.
            singular_cases += 1;
            for m in mine.as_slice() {
                let back = robot.forward(m).unwrap();
                assert!(
                    (back.translation.vector - target.translation.vector).norm() < 1e-7,
                    "case {}: {m:?} gives {} vs {}",
                    case.id,
                    back.translation.vector,
                    target.translation.vector
                );
                assert!(
                    back.rotation.angle_to(&target.rotation) < 1e-9,
                    "case {}",
                    case.id
                );
            }
            continue;
        }
        assert_eq!(
            mine.len(),
            peer_solutions.len(),
            "case {}: solution count, ours {:?} theirs {:?}",
            case.id,
            mine.as_slice(),
            peer_solutions
        );
        for p in &peer_solutions {
            let matched = mine
                .as_slice()
                .iter()
                .any(|m| m.iter().zip(p).all(|(a, b)| angle_diff(*a, *b) < 1e-9));
            assert!(
                matched,
                "case {}: peer solution {p:?} not among ours {:?}",
                case.id,
                mine.as_slice()
            );
            compared_solutions += 1;
        }
    }
    assert!(compared_solutions > 10_000, "{compared_solutions}");
    assert!(singular_cases < 50, "{singular_cases} wrist-singular cases");
    println!("{compared_solutions} solutions equal to 1e-9 deg; {singular_cases} wrist-singular cases checked by FK");
}
