//! Frames to and from the HLI's coordinate systems (`HLI_COORDINATE_SYSTEM_INT`: translation
//! in 0.1 um, rotation in 0.0001 degree): the wire's side of the kinematics' frames, kept here
//! so that the `kinematics` crate needs no HLI.

use hli::layout::HliCoordinateSystemInt;
use hli::units::{deg_from_hli, deg_to_hli, mm_from_hli, mm_to_hli, UnitError};
use kinematics::{PoseWords, RotationOrder};
use nalgebra::Isometry3;

/// The frame of an HLI coordinate system (translation 0.1 um, rotation 0.0001 degree, angles
/// in `order`; the dynamic CS uses [`RotationOrder::Zyx`]).
pub fn frame_from_hli(cs: &HliCoordinateSystemInt, order: RotationOrder) -> Isometry3<f64> {
    let words = PoseWords {
        xyz: cs.translation.map(mm_from_hli),
        abc: cs.rotation.map(deg_from_hli),
    };
    words.to_frame(order).expect("integers are finite")
}

/// The HLI coordinate system of a frame, rounded to the HLI units.
pub fn frame_to_hli(
    frame: &Isometry3<f64>,
    order: RotationOrder,
) -> Result<HliCoordinateSystemInt, UnitError> {
    let words = PoseWords::from_frame(frame, order);
    let mut cs = HliCoordinateSystemInt {
        translation: [0; 3],
        fill_up_2: 0,
        rotation: [0; 3],
        fill_up_1: 0,
    };
    for i in 0..3 {
        cs.translation[i] = mm_to_hli(words.xyz[i])?;
        cs.rotation[i] = deg_to_hli(words.abc[i])?;
    }
    Ok(cs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hli_integers_round_trip_exactly() {
        let cs = HliCoordinateSystemInt {
            translation: [13_059_200, -1, 8_000_000],
            fill_up_2: 0,
            rotation: [100_000, -450_000, 1_799_999],
            fill_up_1: 0,
        };
        let frame = frame_from_hli(&cs, RotationOrder::Zyx);
        assert_eq!(frame_to_hli(&frame, RotationOrder::Zyx).unwrap(), cs);
        assert!((frame.translation.vector.x - 1305.92).abs() < 1e-12);
    }
}
