//! The dynamic-CS composition formulas against hand-computed cases.

use kinematics::tracking::{track_cs_abs, track_cs_values, Tracking, TrackingMode, TrackingOption};
use kinematics::{PoseWords, RotationOrder};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use proptest::prelude::*;

fn at(x: f64, y: f64, z: f64) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::new(x, y, z), UnitQuaternion::identity())
}

fn rz(deg: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), deg.to_radians())
}

fn close(a: &Isometry3<f64>, b: &Isometry3<f64>) -> bool {
    (a.translation.vector - b.translation.vector).norm() < 1e-9
        && a.rotation.angle_to(&b.rotation) < 1e-12
}

#[test]
fn moving_workpiece_absolute_applies_the_master_frame() {
    let tracking = Tracking::new(
        TrackingMode::MovingWorkpiece,
        TrackingOption::Full,
        &PoseWords::default(),
        false,
        None,
    )
    .unwrap();
    let master = Isometry3::from_parts(Translation3::new(100.0, 0.0, 0.0), rz(90.0));
    let out = tracking.compose(&master, &at(10.0, 0.0, 0.0));
    assert!(
        close(
            &out,
            &Isometry3::from_parts(Translation3::new(100.0, 10.0, 0.0), rz(90.0))
        ),
        "{out}"
    );
}

#[test]
fn set_zero_follows_only_the_motion_since_switch_on() {
    let m0 = Isometry3::from_parts(Translation3::new(720.0, 0.0, 450.0), rz(45.0));
    let tracking = Tracking::new(
        TrackingMode::MovingWorkpiece,
        TrackingOption::Full,
        &PoseWords::default(),
        false,
        Some(&m0),
    )
    .unwrap();
    let p = at(300.0, 20.0, 100.0);
    // At switch-on nothing moves: no setpoint jump.
    assert!(close(&tracking.compose(&m0, &p), &p));
    // The master moves 50 mm along X: so does the slave's point.
    let m1 = Isometry3::from_parts(Translation3::new(770.0, 0.0, 450.0), rz(45.0));
    assert!(close(&tracking.compose(&m1, &p), &at(350.0, 20.0, 100.0)));
    // The master turns 90 degree about its own TCP: the point turns about that TCP.
    let m2 = Isometry3::from_parts(Translation3::new(720.0, 0.0, 450.0), rz(135.0));
    let out = tracking.compose(&m2, &p);
    let expected = Point3::new(720.0, 0.0, 450.0)
        + rz(90.0) * (Vector3::new(300.0, 20.0, 100.0) - Vector3::new(720.0, 0.0, 450.0));
    assert!(
        (out.translation.vector - expected.coords).norm() < 1e-9,
        "{out}"
    );
}

#[test]
fn static_offset_maps_master_motion_into_slave_coordinates() {
    // The seed's example 3: the master's base seen from the slave at X=400 Y=700 C=-90.
    let offset = PoseWords {
        xyz: [400.0, 700.0, 0.0],
        abc: [0.0, 0.0, -90.0],
    };
    let m0 = at(720.0, 0.0, 450.0);
    let tracking = Tracking::new(
        TrackingMode::MovingWorkpiece,
        TrackingOption::Full,
        &offset,
        false,
        Some(&m0),
    )
    .unwrap();
    let p = at(1000.0, 300.0, 450.0);
    // The master moves +100 along its Y: in the slave's frame, turned by -90, that is +100 X.
    let out = tracking.compose(&at(720.0, 100.0, 450.0), &p);
    assert!(close(&out, &at(1100.0, 300.0, 450.0)), "{out}");
}

#[test]
fn kin_base_holds_the_tool_against_a_base_rotation_about_the_error_point() {
    // The seed's turntable: the kinematic base lies 1305.92 mm in -X seen from the table's
    // centre (the error point), so the centre is at +1305.92 in the base. Error: 10 degree
    // about Z.
    let base_seen_from_error_point = PoseWords {
        xyz: [-1305.92, 0.0, 0.0],
        abc: [0.0; 3],
    };
    let tracking = Tracking::new(
        TrackingMode::KinematicBase,
        TrackingOption::Full,
        &base_seen_from_error_point,
        false,
        None,
    )
    .unwrap();
    let error = Isometry3::from_parts(Translation3::identity(), rz(10.0));
    let p = at(1305.92 + 100.0, 0.0, 0.0);
    let out = tracking.compose(&error, &p);
    let a = 10f64.to_radians();
    let expected = at(1305.92 + 100.0 * a.cos(), -100.0 * a.sin(), 0.0);
    assert!(
        (out.translation.vector - expected.translation.vector).norm() < 1e-9,
        "{out}"
    );
    // Physically: the displaced base S E S^-1 carries the commanded pose back onto P.
    let s = at(1305.92, 0.0, 0.0);
    let actual_base = s * error * s.inverse();
    assert!(
        (actual_base * out)
            .translation
            .vector
            .metric_distance(&p.translation.vector)
            < 1e-9
    );
}

#[test]
fn translation_only_moves_the_tool_point_and_keeps_its_orientation() {
    let tracking = Tracking::new(
        TrackingMode::MovingWorkpiece,
        TrackingOption::TranslationOnly,
        &PoseWords::default(),
        false,
        None,
    )
    .unwrap();
    let master = Isometry3::from_parts(Translation3::new(5.0, 6.0, 7.0), rz(30.0));
    let out = tracking.compose(&master, &at(1.0, 0.0, 0.0));
    let c = 30f64.to_radians();
    assert!(close(&out, &at(5.0 + c.cos(), 6.0 + c.sin(), 7.0)), "{out}");
    let full = TrackingOption::Full.apply(&master, &at(1.0, 0.0, 0.0));
    assert!((full.rotation.angle() - c).abs() < 1e-12);
    assert!(TrackingOption::from_raw(2).is_err());
}

#[test]
fn rot_trans_measures_the_offset_translation_in_the_rotated_frame() {
    let offset = PoseWords {
        xyz: [100.0, 0.0, 0.0],
        abc: [0.0, 0.0, 90.0],
    };
    let plain = Tracking::new(
        TrackingMode::MovingWorkpiece,
        TrackingOption::Full,
        &offset,
        false,
        None,
    )
    .unwrap();
    let rotated = Tracking::new(
        TrackingMode::MovingWorkpiece,
        TrackingOption::Full,
        &offset,
        true,
        None,
    )
    .unwrap();
    // The master turns 90 degree about its base origin; where the slave's origin goes depends
    // on where that base origin is seen from the slave: (100, 0) or, turned, (0, 100).
    let master = Isometry3::from_parts(Translation3::identity(), rz(90.0));
    let origin = at(0.0, 0.0, 0.0);
    let a = plain.compose(&master, &origin).translation.vector;
    let b = rotated.compose(&master, &origin).translation.vector;
    assert!((a - Vector3::new(100.0, -100.0, 0.0)).norm() < 1e-9, "{a}");
    assert!((b - Vector3::new(100.0, 100.0, 0.0)).norm() < 1e-9, "{b}");
}

#[test]
fn set_zero_values_and_track_cs_abs() {
    let m0 = Isometry3::from_parts(
        Translation3::new(720.0, 0.0, 450.0),
        UnitQuaternion::from_euler_angles(0.0, 0.3, 0.785),
    );
    let v = track_cs_values(&m0, RotationOrder::YawPitchRoll);
    // `#CS ON [X, Y, Z, A, -B, C]` (Z-Y-X frame) rebuilds the master frame.
    let cs = PoseWords {
        xyz: [v[0], v[1], v[2]],
        abc: [v[3], -v[4], v[5]],
    }
    .to_frame(RotationOrder::Zyx)
    .unwrap();
    assert!(close(&cs, &m0));
    // `#TRACK CS ABS`: programming zero on every axis reaches the centre of the dynamic CS.
    assert_eq!(track_cs_abs(&[0.0; 6], &v), v);
    assert_eq!(
        track_cs_abs(
            &[1.0, 2.0, 3.0, 0.0, 0.0, 0.0],
            &[10.0, 20.0, 30.0, 0.0, 0.0, 5.0]
        ),
        [11.0, 22.0, 33.0, 0.0, 0.0, 5.0]
    );
}

proptest! {
    /// Tracking moves the programmed points rigidly (distances preserved) and does nothing
    /// while the master stands at its switch-on frame.
    #[test]
    fn composition_is_rigid_and_jump_free(
        m in prop::array::uniform6(-500.0f64..500.0),
        o in prop::array::uniform6(-300.0f64..300.0),
        p1 in prop::array::uniform3(-1000.0f64..1000.0),
        p2 in prop::array::uniform3(-1000.0f64..1000.0),
        kin_base in any::<bool>(),
    ) {
        let frame = |v: &[f64; 6]| PoseWords { xyz: [v[0], v[1], v[2]], abc: [v[3] / 5.0, v[4] / 5.0, v[5] / 5.0] }.to_frame(RotationOrder::Zyx).unwrap();
        let master = frame(&m);
        let offset = PoseWords { xyz: [o[0], o[1], o[2]], abc: [o[3] / 5.0, o[4] / 5.0, o[5] / 5.0] };
        let mode = if kin_base { TrackingMode::KinematicBase } else { TrackingMode::MovingWorkpiece };
        let t = Tracking::new(mode, TrackingOption::Full, &offset, false, Some(&master)).unwrap();
        let a = at(p1[0], p1[1], p1[2]);
        let b = at(p2[0], p2[1], p2[2]);
        prop_assert!(close(&t.compose(&master, &a), &a));
        let moved = frame(&[m[0] + 10.0, m[1], m[2] - 5.0, m[3] + 3.0, m[4], m[5]]);
        let (ma, mb) = (t.compose(&moved, &a), t.compose(&moved, &b));
        let before = (a.translation.vector - b.translation.vector).norm();
        let after = (ma.translation.vector - mb.translation.vector).norm();
        prop_assert!((before - after).abs() < 1e-8);
    }
}
