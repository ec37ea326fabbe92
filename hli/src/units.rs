//! Units as they cross the HLI (0.1 um, 0.0001 degree, DINT) and as the engines use them
//! (f64 mm, degree, radian). Conversions into the integer units round to nearest and refuse
//! NaN, infinities and values outside the DINT range with a typed error.

/// Increments of the HLI length unit per millimetre (the unit is 0.1 um).
pub const HLI_LENGTH_PER_MM: f64 = 10_000.0;
/// Increments of the HLI angle unit per degree (the unit is 0.0001 degree).
pub const HLI_ANGLE_PER_DEG: f64 = 10_000.0;

/// A value that cannot be represented in an HLI integer unit.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum UnitError {
    /// NaN or an infinity.
    #[error("{quantity} is not finite ({value})")]
    NotFinite {
        /// What was converted.
        quantity: &'static str,
        /// The value.
        value: f64,
    },
    /// Outside the DINT range after scaling.
    #[error("{quantity} {value} is outside the HLI range (+-{limit})")]
    OutOfRange {
        /// What was converted.
        quantity: &'static str,
        /// The value in engine units.
        value: f64,
        /// The largest magnitude representable, in engine units.
        limit: f64,
    },
}

fn to_dint(quantity: &'static str, value: f64, scale: f64) -> Result<i32, UnitError> {
    if !value.is_finite() {
        return Err(UnitError::NotFinite { quantity, value });
    }
    let scaled = (value * scale).round();
    if scaled < f64::from(i32::MIN) || scaled > f64::from(i32::MAX) {
        return Err(UnitError::OutOfRange {
            quantity,
            value,
            limit: f64::from(i32::MAX) / scale,
        });
    }
    Ok(scaled as i32)
}

/// 0.1 um -> mm.
pub fn mm_from_hli(raw: i32) -> f64 {
    f64::from(raw) / HLI_LENGTH_PER_MM
}

/// mm -> 0.1 um, rounded to nearest.
pub fn mm_to_hli(mm: f64) -> Result<i32, UnitError> {
    to_dint("length [mm]", mm, HLI_LENGTH_PER_MM)
}

/// 0.0001 degree -> degree.
pub fn deg_from_hli(raw: i32) -> f64 {
    f64::from(raw) / HLI_ANGLE_PER_DEG
}

/// degree -> 0.0001 degree, rounded to nearest.
pub fn deg_to_hli(deg: f64) -> Result<i32, UnitError> {
    to_dint("angle [deg]", deg, HLI_ANGLE_PER_DEG)
}

/// 0.0001 degree -> radian.
pub fn rad_from_hli(raw: i32) -> f64 {
    deg_from_hli(raw).to_radians()
}

/// radian -> 0.0001 degree, rounded to nearest.
pub fn rad_to_hli(rad: f64) -> Result<i32, UnitError> {
    to_dint("angle [rad]", rad.to_degrees(), HLI_ANGLE_PER_DEG)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn known_values() {
        assert_eq!(mm_to_hli(1.0), Ok(10_000));
        assert_eq!(mm_to_hli(-0.00005), Ok(-1)); // rounds half away from zero
        assert_eq!(mm_from_hli(3200), 0.32);
        assert_eq!(deg_to_hli(-90.0), Ok(-900_000));
        assert_eq!(deg_from_hli(1_800_000), 180.0);
        assert_eq!(rad_to_hli(core::f64::consts::PI), Ok(1_800_000));
    }

    #[test]
    fn refuses_what_does_not_fit() {
        assert!(matches!(
            mm_to_hli(f64::NAN),
            Err(UnitError::NotFinite { .. })
        ));
        assert!(matches!(
            deg_to_hli(f64::INFINITY),
            Err(UnitError::NotFinite { .. })
        ));
        assert!(matches!(
            mm_to_hli(214_749.0),
            Err(UnitError::OutOfRange { .. })
        ));
        assert!(mm_to_hli(214_748.0).is_ok());
    }

    proptest! {
        #[test]
        fn integer_round_trip_is_exact(raw in any::<i32>()) {
            prop_assert_eq!(mm_to_hli(mm_from_hli(raw)), Ok(raw));
            prop_assert_eq!(deg_to_hli(deg_from_hli(raw)), Ok(raw));
        }

        #[test]
        fn float_round_trip_within_half_a_unit(mm in -200_000.0f64..200_000.0) {
            let back = mm_from_hli(mm_to_hli(mm).unwrap());
            prop_assert!((back - mm).abs() <= 0.5 / HLI_LENGTH_PER_MM + 1e-12);
        }
    }
}
