//! Bad motion functions are refused with the seed's error code and the offending point.

use cnc_core::cam::file::{self, BinaryOptions};
use cnc_core::cam::{
    CamError, Field, FunctionType, MotionFunction, MotionFunctionPoint, PointType, TableErrorCode,
};

fn line(n: u32) -> Vec<MotionFunctionPoint> {
    (1..=n)
        .map(|i| {
            MotionFunctionPoint::new(
                i,
                FunctionType::Polynom1,
                PointType::Motion,
                i as f64 * 10.0,
                i as f64,
            )
        })
        .collect()
}

fn refused(points: &[MotionFunctionPoint]) -> CamError {
    MotionFunction::new(points).expect_err("must be refused")
}

#[test]
fn each_bad_point_names_itself_and_its_code() {
    let mut p = line(4);
    p[2].master = 15.0;
    let e = refused(&p);
    assert_eq!(
        e,
        CamError::MasterNotMonotonic {
            point: 3,
            master: 15.0,
            previous: 20.0
        }
    );
    assert_eq!(e.code(), TableErrorCode::IncrementInvalid);

    let mut p = line(4);
    p[1].master = 10.0;
    assert!(
        matches!(refused(&p), CamError::MasterNotMonotonic { point: 2, .. }),
        "standing still is not monotonic"
    );

    let mut p = line(4);
    p[3].index = 5;
    assert_eq!(
        refused(&p),
        CamError::PointIndex {
            found: 5,
            expected: 4
        }
    );
    assert_eq!(refused(&p).code(), TableErrorCode::PointIdInvalid);

    let mut p = line(3);
    p[1].function = 2;
    assert_eq!(
        refused(&p),
        CamError::UnknownFunctionType { point: 2, raw: 2 }
    );
    let mut p = line(3);
    p[2].point_type = 3;
    assert_eq!(refused(&p), CamError::UnknownPointType { point: 3, raw: 3 });

    for (field, set) in [
        (
            Field::Master,
            &(|p: &mut MotionFunctionPoint| p.master = f64::NAN)
                as &dyn Fn(&mut MotionFunctionPoint),
        ),
        (Field::Slave, &|p: &mut MotionFunctionPoint| {
            p.slave = f64::INFINITY
        }),
        (Field::Velocity, &|p: &mut MotionFunctionPoint| {
            p.velocity = f64::NEG_INFINITY
        }),
        (Field::Acceleration, &|p: &mut MotionFunctionPoint| {
            p.acceleration = f64::NAN
        }),
        (Field::Jerk, &|p: &mut MotionFunctionPoint| {
            p.jerk = f64::NAN
        }),
    ] {
        let mut p = line(3);
        set(&mut p[1]);
        assert_eq!(refused(&p), CamError::PointNotFinite { point: 2, field });
    }

    assert_eq!(refused(&line(1)), CamError::TooFewPoints { active: 1 });
    assert_eq!(refused(&line(1)).code(), TableErrorCode::NumPointsInvalid);
    let mut p = line(3);
    p[0].point_type = PointType::Ignore.raw();
    p[2].point_type = PointType::Ignore.raw();
    assert_eq!(refused(&p), CamError::TooFewPoints { active: 1 });

    // A relative index that jumps over an active point (a slide point, not supported).
    let mut p = line(4);
    p[0].rel_index_next = 2;
    assert_eq!(refused(&p), CamError::RelIndex { point: 1, rel: 2 });
    // Over an ignored point it is fine, and so is 0 (= 1).
    p[1].point_type = PointType::Ignore.raw();
    MotionFunction::new(&p).expect("rel index over an ignored point");
}

#[test]
fn json_files_name_the_point_and_the_code() {
    let text = br#"{"kind":"motion_function","id":3,"points":[
        {"index":1,"function":"POLYNOM1","point_type":"REST","master":0,"slave":0},
        {"index":2,"function":"POLYNOM9","point_type":"REST","master":1,"slave":0}]}"#;
    let e = file::parse(text, BinaryOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("error 0x4B33 (MC_ERROR_POINTID_INVALID): point 2: unknown function type"),
        "{e}"
    );
    let text = br#"{"kind":"motion_function","points":[
        {"index":1,"function":1,"point_type":"RAST","master":0,"slave":0},
        {"index":2,"function":1,"point_type":"REST","master":1,"slave":0}]}"#;
    let e = file::parse(text, BinaryOptions::default()).unwrap_err();
    assert!(e.to_string().contains("point 1: unknown point type"), "{e}");
    let text = br#"{"kind":"curve","points":[]}"#;
    assert!(matches!(
        file::parse(text, BinaryOptions::default()),
        Err(file::LoadError::Json(_))
    ));
    let text = br#"{"kind":"motion_function","id":3,"points":[
        {"index":1,"function":"POLYNOM5","point_type":"REST","master":0,"slave":0},
        {"index":2,"function":"POLYNOM1","point_type":"REST","master":90,"slave":20}]}"#;
    let f = file::parse(text, BinaryOptions::default()).unwrap();
    assert_eq!(f.id, Some(3));
}
