//! Online changes of motion-function points: validated whole against the function they
//! change, queued, applied when their activation mode says, refused whole otherwise; the
//! cam store keeps a table unchanged when a write is refused.

use cnc_core::cam::online::{ActivationMode, CamStore, MasterNow, OnlineChangeQueue, WriteOutcome};
use cnc_core::cam::{
    CamError, CamProfile, FunctionType, MotionFunction, MotionFunctionPoint, PointType,
    TableErrorCode,
};

/// Rest 0..100, rise to 10 by 200 (POLYNOM5), rest to 300, fall back by 400.
fn cam() -> MotionFunction {
    MotionFunction::new(&[
        MotionFunctionPoint::new(1, FunctionType::Polynom1, PointType::Rest, 0.0, 0.0),
        MotionFunctionPoint::new(2, FunctionType::Polynom5, PointType::Rest, 100.0, 0.0),
        MotionFunctionPoint::new(3, FunctionType::Polynom1, PointType::Rest, 200.0, 10.0),
        MotionFunctionPoint::new(4, FunctionType::Polynom5, PointType::Rest, 300.0, 10.0),
        MotionFunctionPoint::new(5, FunctionType::Polynom1, PointType::Rest, 400.0, 0.0),
    ])
    .unwrap()
}

/// The stroke of the last fall changed: point 5 slave 0 -> -5.
fn change() -> MotionFunctionPoint {
    MotionFunctionPoint::new(5, FunctionType::Polynom1, PointType::Rest, 400.0, -5.0)
}

fn moving(from: f64, to: f64) -> MasterNow {
    MasterNow {
        axis: (from, to),
        cam: (from, to),
        cycle_changed: false,
        edge: None,
    }
}

#[test]
fn as_soon_as_possible_waits_for_an_untouched_segment() {
    let f = cam();
    let mut q = OnlineChangeQueue::default();
    q.set_mode(ActivationMode::AsSoonAsPossible);
    assert_eq!(
        q.write(&f, 5, &[change()], moving(340.0, 350.0)).unwrap(),
        WriteOutcome::Queued
    );
    assert!(q.is_queued());
    assert_eq!(q.changed_ranges(), &[(300.0, 400.0)]);
    // The slave is in the changed fall: not yet.
    assert!(q.take_due(moving(350.0, 360.0)).is_none());
    // Next cycle, in the first rest: applied.
    let (g, _) = q.take_due(moving(5.0, 10.0)).expect("safe segment");
    assert!(!q.is_queued());
    assert_eq!(g.segments()[3].end.y, -5.0);
}

#[test]
fn at_master_positions_the_change_waits_for_the_crossing() {
    let f = cam();
    let mut q = OnlineChangeQueue::default();
    q.set_mode(ActivationMode::AtMasterAxisPos(250.0));
    q.write(&f, 5, &[change()], moving(100.0, 101.0)).unwrap();
    assert!(q.take_due(moving(240.0, 249.0)).is_none());
    assert!(q.take_due(moving(249.0, 251.0)).is_some());
    // Passed already: refused with the increment code, nothing queued.
    q.set_mode(ActivationMode::AtMasterAxisPos(250.0));
    let e = q
        .write(&f, 5, &[change()], moving(250.0, 260.0))
        .unwrap_err();
    assert_eq!(
        e,
        CamError::ActivationPassed {
            position: 250.0,
            master: 260.0
        }
    );
    assert!(!q.is_queued());
    // Written in the very tick the master crosses the position: passed already (the
    // crossing would never be seen again).
    let e = q
        .write(&f, 5, &[change()], moving(249.0, 251.0))
        .unwrap_err();
    assert!(matches!(e, CamError::ActivationPassed { .. }), "{e}");
    // A falling master has passed 250 once it is below it.
    q.write(&f, 5, &[change()], moving(300.0, 290.0)).unwrap();
    assert!(q.take_due(moving(251.0, 249.0)).is_some());
    q.set_mode(ActivationMode::AtMasterAxisPos(250.0));
    assert!(q.write(&f, 5, &[change()], moving(251.0, 249.0)).is_err());
    // Cam position: taken at the crossing within a later cycle too.
    q.set_mode(ActivationMode::AtMasterCamPos(50.0));
    q.write(&f, 5, &[change()], moving(300.0, 301.0)).unwrap();
    assert!(q.take_due(moving(301.0, 302.0)).is_none());
    let wrap = MasterNow {
        axis: (799.0, 801.0),
        cam: (399.0, 1.0),
        cycle_changed: true,
        edge: None,
    };
    assert!(
        q.take_due(wrap).is_none(),
        "50 not yet reached after the wrap"
    );
    assert!(q.take_due(moving(49.0, 51.0)).is_some());
    // A falling master wraps from the start of the cam to its end: 200 is not crossed by
    // the wrap 1 -> 399, 390 is.
    q.set_mode(ActivationMode::AtMasterCamPos(200.0));
    q.write(&f, 5, &[change()], moving(10.0, 9.0)).unwrap();
    let falling_wrap = MasterNow {
        axis: (401.0, 399.0),
        cam: (1.0, 399.0),
        cycle_changed: true,
        edge: None,
    };
    assert!(
        q.take_due(falling_wrap).is_none(),
        "200 not crossed by a falling wrap"
    );
    q.delete_queued();
    q.set_mode(ActivationMode::AtMasterCamPos(399.5));
    q.write(&f, 5, &[change()], moving(10.0, 9.0)).unwrap();
    assert!(
        q.take_due(falling_wrap).is_some(),
        "399.5 crossed by the falling wrap"
    );
    // Next cycle: at the wrap.
    q.set_mode(ActivationMode::NextCycle);
    q.write(&f, 5, &[change()], moving(0.0, 1.0)).unwrap();
    assert!(q.take_due(moving(1.0, 2.0)).is_none());
    assert!(q.take_due(wrap).is_some());
}

#[test]
fn a_refused_write_leaves_the_queue_as_it_was() {
    let f = cam();
    let mut q = OnlineChangeQueue::default();
    q.set_mode(ActivationMode::AsSoonAsPossible);
    q.write(&f, 5, &[change()], MasterNow::standing(0.0))
        .unwrap();
    let before = q.clone();
    // Master position of point 4 moved behind point 3: not monotonic.
    let bad = MotionFunctionPoint::new(4, FunctionType::Polynom5, PointType::Rest, 150.0, 10.0);
    let mut bad2 = bad;
    bad2.master = 190.0;
    let bad3 = MotionFunctionPoint::new(5, FunctionType::Polynom1, PointType::Rest, 180.0, 0.0);
    let e = q
        .write(&f, 4, &[bad2, bad3], MasterNow::standing(0.0))
        .unwrap_err();
    assert_eq!(e.code(), TableErrorCode::IncrementInvalid);
    assert_eq!(q, before);
    // A wrong index inside the block and a block past the end.
    assert_eq!(
        q.write(&f, 3, &[bad], MasterNow::standing(0.0))
            .unwrap_err(),
        CamError::PointIndex {
            found: 4,
            expected: 3
        }
    );
    assert!(matches!(
        q.write(&f, 5, &[change(), change()], MasterNow::standing(0.0))
            .unwrap_err(),
        CamError::WriteRange { .. }
    ));
    assert_eq!(q, before);
    // Delete queued data: the running cam is untouched, nothing is queued.
    q.delete_queued();
    assert!(!q.is_queued());
    // Off: writes are not taken.
    q.set_mode(ActivationMode::Off);
    assert_eq!(
        q.write(&f, 5, &[change()], MasterNow::standing(0.0))
            .unwrap(),
        WriteOutcome::Ignored
    );
    assert!(!q.is_queued());
    assert!(matches!(
        ActivationMode::from_raw(4, 0.0),
        Err(CamError::ActivationMode { mode: 4 })
    ));
}

#[test]
fn writes_build_on_what_is_queued() {
    let f = cam();
    let mut q = OnlineChangeQueue::default();
    q.set_mode(ActivationMode::NextCycle);
    q.write(&f, 5, &[change()], MasterNow::standing(0.0))
        .unwrap();
    let higher = MotionFunctionPoint::new(3, FunctionType::Polynom1, PointType::Rest, 200.0, 12.0);
    let mut four =
        MotionFunctionPoint::new(4, FunctionType::Polynom5, PointType::Rest, 300.0, 12.0);
    four.jerk = 0.0;
    q.write(&f, 3, &[higher, four], MasterNow::standing(0.0))
        .unwrap();
    let wrap = MasterNow {
        axis: (399.0, 401.0),
        cam: (399.0, 1.0),
        cycle_changed: true,
        edge: None,
    };
    let (g, _) = q.take_due(wrap).unwrap();
    let ys: Vec<f64> = g.points().iter().map(|p| p.slave).collect();
    assert_eq!(
        ys,
        vec![0.0, 0.0, 12.0, 12.0, -5.0],
        "both writes applied together"
    );
}

#[test]
fn the_store_checks_ids_and_keeps_a_table_whose_write_is_refused() {
    let mut store = CamStore::new();
    for id in [0, 256] {
        let e = store
            .insert(id, CamProfile::MotionFunction(cam()))
            .unwrap_err();
        assert_eq!(e.code(), TableErrorCode::CamTableIdInvalid);
    }
    store.insert(7, CamProfile::MotionFunction(cam())).unwrap();
    let before = store.get(7).unwrap().clone();
    let mut nan = change();
    nan.slave = f64::NAN;
    let e = store
        .write_points(7, 5, &[nan], MasterNow::standing(0.0))
        .unwrap_err();
    assert_eq!(e.code(), TableErrorCode::PointIdInvalid);
    assert_eq!(store.get(7).unwrap(), &before);
    assert!(!store.queue_mut(7).unwrap().is_queued());
    // A good write, instantaneous by default: applied in the next tick.
    store
        .write_points(7, 5, &[change()], MasterNow::standing(0.0))
        .unwrap();
    assert_eq!(store.get(7).unwrap(), &before, "not before the tick");
    assert!(store
        .apply_due(7, MasterNow::standing(0.0))
        .unwrap()
        .is_some());
    assert_ne!(store.get(7).unwrap(), &before);
    assert_eq!(store.get(8).unwrap_err(), CamError::NoSuchTable { id: 8 });
}
