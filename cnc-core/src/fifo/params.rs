//! A FIFO group's parameters (seed 002, chapter 4): dimension N >= 1 axes, length Z >= 2
//! rows, FIFO cycle T_f > 0 (the time between two rows, independent of the NC tick), and the
//! override type. Bounds above the seed's are ours: they size the ring and the block calls.

use super::override_filter::OverrideType;
use hli::calls::fifo::{FIFO_MAX_DIMENSION, FIFO_MAX_ROWS};

/// Smallest PT-2 time constant, s.
pub const PT2_T0_MIN_S: f64 = 1e-4;
/// Largest PT-2 time constant, s (a stop then takes about 115 s).
pub const PT2_T0_MAX_S: f64 = 10.0;

/// The parameters of one FIFO group, checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FifoParams {
    /// N: axes of the group, columns of every row.
    pub dimension: usize,
    /// Z: rows the FIFO holds.
    pub rows: usize,
    /// T_f, s.
    pub fifo_cycle_s: f64,
    /// Instant or PT-2.
    pub override_type: OverrideType,
}

/// A parameter out of range.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// N outside 1..=16.
    #[error("FIFO dimension {0}: a group has 1 to {FIFO_MAX_DIMENSION} axes")]
    Dimension(usize),
    /// Z outside 2..=2^20.
    #[error("FIFO length {0}: a FIFO holds 2 to {FIFO_MAX_ROWS} rows")]
    Rows(usize),
    /// T_f not a positive finite number.
    #[error("FIFO cycle {0} s: T_f must be a positive finite time")]
    FifoCycle(f64),
    /// T0 outside 0.1 ms..=10 s.
    #[error("PT-2 time constant {0} s: T0 must lie in 0.0001..=10 s")]
    TimeConstant(f64),
}

impl FifoParams {
    /// Checked parameters.
    pub fn new(
        dimension: usize,
        rows: usize,
        fifo_cycle_s: f64,
        override_type: OverrideType,
    ) -> Result<FifoParams, ParamError> {
        if !(1..=FIFO_MAX_DIMENSION as usize).contains(&dimension) {
            return Err(ParamError::Dimension(dimension));
        }
        if !(2..=FIFO_MAX_ROWS as usize).contains(&rows) {
            return Err(ParamError::Rows(rows));
        }
        check_time(fifo_cycle_s).map_err(|_| ParamError::FifoCycle(fifo_cycle_s))?;
        // T0 bounded both ways: tiny values overflow the filter's poles, huge ones make a
        // stop (the override decaying to 0) last for ever.
        if let OverrideType::Pt2 { t0_s } = override_type {
            if !(PT2_T0_MIN_S..=PT2_T0_MAX_S).contains(&t0_s) {
                return Err(ParamError::TimeConstant(t0_s));
            }
        }
        Ok(FifoParams {
            dimension,
            rows,
            fifo_cycle_s,
            override_type,
        })
    }
}

fn check_time(t: f64) -> Result<(), ()> {
    if t.is_finite() && t > 0.0 {
        Ok(())
    } else {
        Err(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds() {
        let ok = FifoParams::new(3, 2, 0.002, OverrideType::Instant);
        assert!(ok.is_ok());
        assert_eq!(
            FifoParams::new(0, 10, 0.002, OverrideType::Instant),
            Err(ParamError::Dimension(0))
        );
        assert_eq!(
            FifoParams::new(17, 10, 0.002, OverrideType::Instant),
            Err(ParamError::Dimension(17))
        );
        assert_eq!(
            FifoParams::new(1, 1, 0.002, OverrideType::Instant),
            Err(ParamError::Rows(1))
        );
        for t in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-300, 5e-5, 11.0, 1e20] {
            if t <= 0.0 || !t.is_finite() {
                assert!(matches!(
                    FifoParams::new(1, 2, t, OverrideType::Instant),
                    Err(ParamError::FifoCycle(_))
                ));
            }
            assert!(matches!(
                FifoParams::new(1, 2, 0.001, OverrideType::Pt2 { t0_s: t }),
                Err(ParamError::TimeConstant(_))
            ));
        }
    }
}
