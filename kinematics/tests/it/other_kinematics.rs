//! Cartesian, rotary-table and generic-chain kinematics.

use kinematics::cartesian::Cartesian;
use kinematics::chain::{DhJoint, JointKind, SerialChain};
use kinematics::joints::JointLimit;
use kinematics::rotary_table::RotaryTable;
use kinematics::{Joints, KinError, KinematicId, Kinematics, PoseWords, RotationOrder};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use proptest::prelude::*;

fn pose_close(a: &Isometry3<f64>, b: &Isometry3<f64>, tol_mm: f64) -> bool {
    (a.translation.vector - b.translation.vector).norm() <= tol_mm
        && a.rotation.angle_to(&b.rotation) <= 1e-10
}

fn kuka_like_chain() -> SerialChain {
    let row = |a, alpha, d| DhJoint {
        a,
        alpha,
        d,
        theta: 0.0,
        kind: JointKind::Revolute,
        limit: JointLimit::NONE,
    };
    SerialChain::new(
        &[
            row(25.0, -90.0, 400.0),
            row(455.0, 0.0, 0.0),
            row(35.0, -90.0, 0.0),
            row(0.0, 90.0, 420.0),
            row(0.0, -90.0, 0.0),
            row(0.0, 0.0, 80.0),
        ],
        &PoseWords {
            xyz: [0.0, 0.0, 50.0],
            abc: [0.0, 0.0, 0.0],
        },
    )
    .unwrap()
}

#[test]
fn ids_decode() {
    for id in [
        KinematicId::Cartesian,
        KinematicId::Robot45,
        KinematicId::GenericChain,
        KinematicId::RotaryTable,
    ] {
        assert_eq!(KinematicId::from_raw(id.raw()).unwrap(), id);
    }
    assert!(KinematicId::from_raw(46).is_err());
}

#[test]
fn planar_chain_forward_by_hand() {
    let link = |a| DhJoint {
        a,
        alpha: 0.0,
        d: 0.0,
        theta: 0.0,
        kind: JointKind::Revolute,
        limit: JointLimit::NONE,
    };
    let chain = SerialChain::new(&[link(100.0), link(50.0)], &PoseWords::default()).unwrap();
    let pose = chain.forward(&[90.0, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
    assert!((pose.translation.vector - Vector3::new(0.0, 150.0, 0.0)).norm() < 1e-12);
    let pose = chain.forward(&[90.0, -90.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
    assert!((pose.translation.vector - Vector3::new(50.0, 100.0, 0.0)).norm() < 1e-12);
    let slide = DhJoint {
        a: 0.0,
        alpha: 0.0,
        d: 10.0,
        theta: 0.0,
        kind: JointKind::Prismatic,
        limit: JointLimit {
            min: 0.0,
            max: 500.0,
        },
    };
    let lift = SerialChain::new(&[slide], &PoseWords::default()).unwrap();
    let up = Isometry3::from_parts(
        Translation3::new(0.0, 0.0, 210.0),
        UnitQuaternion::identity(),
    );
    let q = lift.inverse(&up, &[0.0; 6]).unwrap();
    assert!((q[0] - 200.0).abs() < 1e-9);
    let too_high = Isometry3::from_parts(
        Translation3::new(0.0, 0.0, 900.0),
        UnitQuaternion::identity(),
    );
    assert!(matches!(
        lift.inverse(&too_high, &[0.0; 6]),
        Err(KinError::JointLimit { joint: 1, .. })
    ));
}

#[test]
fn chain_refuses_bad_tables_and_unreachable_targets() {
    assert!(matches!(
        SerialChain::new(&[], &PoseWords::default()),
        Err(KinError::BadParameter { .. })
    ));
    let chain = kuka_like_chain();
    let far = Isometry3::from_parts(
        Translation3::new(4000.0, 0.0, 0.0),
        UnitQuaternion::identity(),
    );
    assert!(chain.inverse(&far, &[0.0; 6]).is_err());
}

/// From a start within 5 degree of a random configuration the numerical inverse converges to
/// the pose (to 1e-9 mm) in nearly every case and never returns a wrong answer.
#[test]
fn chain_inverse_converges_near_the_current_configuration() {
    let chain = kuka_like_chain();
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut converged, mut gave_up) = (0, 0);
    for _ in 0..500 {
        let q: Joints = core::array::from_fn(|_| -120.0 + 240.0 * next());
        let start: Joints = core::array::from_fn(|i| q[i] - 5.0 + 10.0 * next());
        let pose = chain.forward(&q).unwrap();
        match chain.inverse(&pose, &start) {
            Ok(solution) => {
                assert!(pose_close(&chain.forward(&solution).unwrap(), &pose, 1e-9));
                converged += 1;
            }
            Err(KinError::Unreachable { .. } | KinError::Singular { .. }) => gave_up += 1,
            Err(e) => panic!("unexpected {e:?}"),
        }
    }
    assert!(converged >= 490, "converged {converged}, gave up {gave_up}");
}

#[test]
fn rotary_table_by_hand() {
    let table = RotaryTable::new([1000.0, 0.0, 0.0], JointLimit::NONE).unwrap();
    let pose = table.forward(&[1100.0, 0.0, 50.0, 90.0, 0.0, 0.0]).unwrap();
    assert!((pose.translation.vector - Vector3::new(0.0, -100.0, 50.0)).norm() < 1e-12);
    let back = table
        .inverse(&pose, &[0.0, 0.0, 0.0, 80.0, 0.0, 0.0])
        .unwrap();
    assert!(
        (back[0] - 1100.0).abs() < 1e-9 && back[1].abs() < 1e-9 && (back[3] - 90.0).abs() < 1e-9,
        "{back:?}"
    );
    // Multi-turn table: the nearest turn to the current angle.
    let back = table
        .inverse(&pose, &[0.0, 0.0, 0.0, 440.0, 0.0, 0.0])
        .unwrap();
    assert!((back[3] - 450.0).abs() < 1e-9);
    let tilted = Isometry3::from_parts(
        Translation3::new(0.0, 0.0, 0.0),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.1),
    );
    assert!(matches!(
        table.inverse(&tilted, &[0.0; 6]),
        Err(KinError::Unreachable { .. })
    ));
}

proptest! {
    #[test]
    fn cartesian_round_trips_in_every_convention(
        xyz in prop::array::uniform3(-2000.0f64..2000.0),
        abc in prop::array::uniform3(-170.0f64..170.0),
        conv in 0usize..4,
    ) {
        let order = [RotationOrder::YawPitchRoll, RotationOrder::EulerZyz, RotationOrder::Cba, RotationOrder::Zyx][conv];
        // Within 0.01 degree of gimbal lock (the middle angle at +-90, or 0 for Z-Y-Z) the
        // angles are ill-conditioned (their error grows as 1 / cos of the distance) and no
        // fixed tolerance holds; the singular poses themselves have their own tests.
        let singular = if conv == 1 { 0.0 } else { 90.0 };
        prop_assume!((abc[1].abs() - singular).abs() > 0.01);
        let tool = PoseWords { xyz: [10.0, -5.0, 120.0], abc: [0.0, 30.0, 0.0] };
        let kin = Cartesian::new(order, &tool, [JointLimit::NONE; 6]).unwrap();
        let joints: Joints = [xyz[0], xyz[1], xyz[2], abc[0], abc[1], abc[2]];
        let pose = kin.forward(&joints).unwrap();
        let all = kin.inverse_all(&pose, &joints).unwrap();
        prop_assert_eq!(all.len(), 2);
        for s in all.as_slice() {
            prop_assert!(pose_close(&kin.forward(s).unwrap(), &pose, 1e-9));
        }
        let nearest = kin.inverse(&pose, &joints).unwrap();
        prop_assert!(pose_close(&kin.forward(&nearest).unwrap(), &pose, 1e-9));
    }

    #[test]
    fn rotary_table_round_trips(x in -500.0f64..2500.0, y in -800.0f64..800.0, z in 0.0f64..400.0, c in -720.0f64..720.0) {
        let table = RotaryTable::new([1305.92, 0.0, 0.0], JointLimit::NONE).unwrap();
        let joints = [x, y, z, c, 0.0, 0.0];
        let pose = table.forward(&joints).unwrap();
        let back = table.inverse(&pose, &joints).unwrap();
        for i in 0..4 {
            prop_assert!((back[i] - joints[i]).abs() < 1e-9, "{back:?} vs {joints:?}");
        }
    }
}
