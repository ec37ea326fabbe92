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
    // Rest points with alternating strokes, joined by every rest-to-rest and motion law (the
    // trigonometric ones included): a cam that really moves.
    use cnc_core::cam::law::EndKind;
    let laws: Vec<FunctionType> = FunctionType::all()
        .iter()
        .copied()
        .filter(|l| {
            matches!(
                l.ends(),
                (EndKind::Rest, EndKind::Rest) | (EndKind::Motion, EndKind::Motion)
            )
        })
        .collect();
    let points: Vec<MotionFunctionPoint> = (0..40)
        .map(|i| {
            let slave = if i % 2 == 0 { 0.0 } else { 5.0 };
            MotionFunctionPoint::new(
                i as u32 + 1,
                laws[i % laws.len()],
                PointType::Rest,
                i as f64 * 10.0,
                slave,
            )
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
