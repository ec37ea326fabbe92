//! Kinematic 45 per call, against `rs-opw-kinematics` on the same poses in the same run.
//!
//! Run: `cargo bench -p kinematics --bench kinematics`. Each measurement times a batch of
//! calls over 1000 poses; the batches of all methods are interleaved and repeated, and the
//! table reports the median time per call and the ratio to the peer's median.

use bench_kit::{median, scaled};
use kinematics::opw::{Robot45, Robot45Params};
use kinematics::{Joints, Kinematics};
use rs_opw_kinematics::glam::{DQuat, DVec3};
use rs_opw_kinematics::kinematic_traits::{Kinematics as _, Pose};
use rs_opw_kinematics::kinematics_impl::OPWKinematics;
use rs_opw_kinematics::parameters::opw_kinematics::Parameters;
use std::hint::black_box;
use std::time::Instant;

const POSES: usize = 1000;
const REPEATS: usize = 15;

fn sample_joints() -> Vec<Joints> {
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..scaled(POSES))
        .map(|_| {
            [
                -160.0 + 320.0 * next(),
                -170.0 + 200.0 * next(),
                -110.0 + 250.0 * next(),
                -170.0 + 340.0 * next(),
                -110.0 + 220.0 * next(),
                -170.0 + 340.0 * next(),
            ]
        })
        .collect()
}

fn time_per_call(f: &mut dyn FnMut() -> f64) -> f64 {
    let start = Instant::now();
    black_box(f());
    start.elapsed().as_nanos() as f64 / scaled(POSES) as f64
}

fn main() {
    // KR 6 R700 sixx: a preset both libraries ship with identical geometry.
    let ours = Robot45::new(Robot45Params::kuka_kr6_r700_sixx()).unwrap();
    let peer = OPWKinematics::new(Parameters::kuka_kr6_r700_sixx());
    let joints = sample_joints();
    let poses: Vec<_> = joints.iter().map(|j| ours.forward(j).unwrap()).collect();
    let peer_joints: Vec<[f64; 6]> = joints.iter().map(|j| j.map(f64::to_radians)).collect();
    let peer_poses: Vec<Pose> = poses
        .iter()
        .map(|p| {
            let t = p.translation.vector / 1000.0;
            let q = p.rotation.coords;
            Pose::from_parts(
                DVec3::new(t.x, t.y, t.z),
                DQuat::from_xyzw(q.x, q.y, q.z, q.w),
            )
        })
        .collect();

    let mut results: Vec<(&str, Vec<f64>)> = vec![
        ("FK ours", vec![]),
        ("FK rs-opw-kinematics", vec![]),
        ("IK all solutions ours", vec![]),
        ("IK all solutions rs-opw-kinematics", vec![]),
        ("IK nearest ours", vec![]),
        ("IK nearest rs-opw-kinematics (inverse_continuing)", vec![]),
    ];
    for _ in 0..scaled(REPEATS) {
        let runs: [&mut dyn FnMut() -> f64; 6] = [
            &mut || {
                joints
                    .iter()
                    .map(|j| ours.forward(black_box(j)).unwrap().translation.x)
                    .sum()
            },
            &mut || {
                peer_joints
                    .iter()
                    .map(|j| peer.forward(black_box(j)).translation.x)
                    .sum()
            },
            &mut || {
                poses
                    .iter()
                    .zip(&joints)
                    .map(|(p, j)| {
                        ours.inverse_all(black_box(p), j)
                            .map(|s| s.len())
                            .unwrap_or(0) as f64
                    })
                    .sum()
            },
            &mut || {
                peer_poses
                    .iter()
                    .map(|p| peer.inverse(black_box(p)).len() as f64)
                    .sum()
            },
            &mut || {
                poses
                    .iter()
                    .zip(&joints)
                    .map(|(p, j)| ours.inverse(black_box(p), j).map(|s| s[0]).unwrap_or(0.0))
                    .sum()
            },
            &mut || {
                peer_poses
                    .iter()
                    .zip(&peer_joints)
                    .map(|(p, j)| {
                        peer.inverse_continuing(black_box(p), j)
                            .first()
                            .map(|s| s[0])
                            .unwrap_or(0.0)
                    })
                    .sum()
            },
        ];
        for (i, run) in runs.into_iter().enumerate() {
            results[i].1.push(time_per_call(run));
        }
    }
    let medians: Vec<f64> = results.iter().map(|(_, v)| median(v.clone())).collect();
    println!(
        "kinematic 45 (KR 6 R700 sixx), {POSES} poses, median of {REPEATS} interleaved repeats"
    );
    println!("| call | ns per call | ratio to peer |\n|---|---:|---:|");
    for (i, (name, _)) in results.iter().enumerate() {
        let peer = medians[i | 1];
        let ratio = if i % 2 == 0 {
            format!("{:.2}", medians[i] / peer)
        } else {
            "1.00".into()
        };
        println!("| {name} | {:.1} | {ratio} |", medians[i]);
    }
    let ik = medians[4];
    let verdict = |ok: bool| if ok { "met" } else { "MISSED" };
    println!(
        "TARGET | IK nearest <= 1000 ns per call | {ik:.1} ns | {}",
        verdict(ik <= 1000.0)
    );
    println!(
        "TARGET | IK nearest not slower than rs-opw-kinematics | {:.2}x its {:.1} ns | {}",
        ik / medians[5],
        medians[5],
        verdict(ik <= medians[5])
    );
}
