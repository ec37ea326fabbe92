//! Forward and inverse calls and the tracking composition do not allocate.

use kinematics::cartesian::Cartesian;
use kinematics::chain::{DhJoint, JointKind, SerialChain};
use kinematics::joints::JointLimit;
use kinematics::opw::{Robot45, Robot45Params};
use kinematics::tracking::{Tracking, TrackingMode, TrackingOption};
use kinematics::{Kinematics, PoseWords};

use crate::counting_alloc;
use counting_alloc::allocations;

#[test]
fn kinematic_calls_do_not_allocate() {
    let robot = Robot45::new(Robot45Params::kuka_kr6_r900_sixx()).unwrap();
    let cartesian = Cartesian::default();
    let row = |a, alpha, d| DhJoint {
        a,
        alpha,
        d,
        theta: 0.0,
        kind: JointKind::Revolute,
        limit: JointLimit::NONE,
    };
    let chain = SerialChain::new(
        &[
            row(25.0, -90.0, 400.0),
            row(455.0, 0.0, 0.0),
            row(35.0, -90.0, 0.0),
            row(0.0, 90.0, 420.0),
            row(0.0, -90.0, 0.0),
            row(0.0, 0.0, 80.0),
        ],
        &PoseWords::default(),
    )
    .unwrap();
    let tracking = Tracking::new(
        TrackingMode::MovingWorkpiece,
        TrackingOption::Full,
        &PoseWords::default(),
        false,
        None,
    )
    .unwrap();
    let joints = [10.0, -80.0, 70.0, 20.0, 30.0, 40.0];

    let before = allocations();
    let mut checksum = 0.0;
    for i in 0..1000 {
        let mut q = joints;
        q[0] += f64::from(i) * 0.01;
        let pose = robot.forward(&q).unwrap();
        checksum += robot.inverse(&pose, &q).unwrap()[0];
        checksum += robot.inverse_all(&pose, &q).unwrap().len() as f64;
        let c = cartesian.forward(&q).unwrap();
        checksum += cartesian.inverse(&c, &q).unwrap()[0];
        let t = chain.forward(&q).unwrap();
        checksum += chain.inverse(&t, &q).unwrap()[0];
        checksum += tracking.compose(&pose, &c).translation.vector.x;
    }
    let after = allocations();
    assert!(checksum.is_finite());
    assert_eq!(after - before, 0, "allocations in forward/inverse/compose");
}
