//! Evaluating a cam while the master sweeps allocates nothing: motion functions and tables
//! with every interpolation, linear and cyclic.

use cnc_core::cam::{
    CamProfile, FunctionType, Interpolation, MotionFunction, MotionFunctionPoint, PointType,
    PositionTable, ProfileCursor, TableType,
};

#[path = "../../tests/support/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocations;

#[test]
fn sweeping_the_master_through_every_kind_of_profile_allocates_nothing() {
    let laws = FunctionType::all();
    let points: Vec<MotionFunctionPoint> = (0..40)
        .map(|i| {
            let law = if i % 2 == 0 {
                FunctionType::Polynom1
            } else {
                laws[i % laws.len()]
            };
            let law = if law.ends().0 == cnc_core::cam::law::EndKind::Turn
                || law.ends().1 == cnc_core::cam::law::EndKind::Turn
            {
                FunctionType::Polynom5
            } else {
                law
            };
            MotionFunctionPoint::new(i as u32 + 1, law, PointType::Motion, i as f64 * 10.0, 0.0)
        })
        .collect();
    let mut profiles = vec![CamProfile::MotionFunction(
        MotionFunction::new(&points).expect("valid"),
    )];
    let rows: Vec<[f64; 2]> = (0..1000)
        .map(|i| [i as f64 * 0.4, (i as f64 * 0.01).sin()])
        .collect();
    for interpolation in [
        Interpolation::Linear,
        Interpolation::FourPoint,
        Interpolation::Spline,
    ] {
        for periodic in [false, true] {
            for ty in [TableType::Equidistant, TableType::NonEquidistant] {
                if let Ok(t) = PositionTable::new(&rows, ty, interpolation, periodic) {
                    profiles.push(CamProfile::Table(t));
                }
            }
        }
    }
    assert_eq!(profiles.len(), 11);
    let before = allocations();
    let mut sum = 0.0;
    for p in &profiles {
        let mut cursor = ProfileCursor::default();
        for i in 0..100_000 {
            // Beyond both ends too (cyclic continuation, edge values).
            let x = -50.0 + i as f64 * 0.006;
            sum += p.eval(x, &mut cursor).position;
        }
    }
    assert_eq!(allocations() - before, 0, "allocations while evaluating");
    assert!(sum.is_finite());
}
