//! Increments of the process image: the encoder's counter is 32 or 16 bits wide and wraps; the
//! NC counts the wraps to get an unbounded position, and turns set-points back into wrapped
//! increments for the drive.

use serde::{Deserialize, Serialize};

/// Width of an encoder's (or a position-mode drive's) increment counter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum CounterWidth {
    /// DINT, the whole `nInData1`.
    #[default]
    Bits32,
    /// INT, the low 16 bits of `nInData1`.
    Bits16,
}

impl CounterWidth {
    /// The counter value as the image carries it: the low bits of `count`, for 16 bits as an
    /// unsigned word (a 16-bit terminal counts 0..65535).
    pub fn wrap(self, count: i64) -> i32 {
        match self {
            CounterWidth::Bits32 => count as i32,
            CounterWidth::Bits16 => i32::from(count as u16),
        }
    }

    /// The signed difference `new - old` of two raw counter values, assuming the counter moved
    /// less than half its range in between.
    pub fn delta(self, old: i32, new: i32) -> i64 {
        match self {
            CounterWidth::Bits32 => i64::from(new.wrapping_sub(old)),
            CounterWidth::Bits16 => i64::from((new as u16).wrapping_sub(old as u16) as i16),
        }
    }
}

/// Counts the wraps of an encoder's raw increments into an unbounded count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IncrementCounter {
    width: CounterWidth,
    last_raw: Option<i32>,
    count: i64,
}

impl IncrementCounter {
    /// A counter that takes its first reading as the start.
    pub fn new(width: CounterWidth) -> Self {
        Self {
            width,
            last_raw: None,
            count: 0,
        }
    }

    /// Feeds a raw reading; returns the unbounded count. The first reading counts from the
    /// raw value itself (sign-extended for 16 bits: an absolute encoder's position).
    pub fn update(&mut self, raw: i32) -> i64 {
        match self.last_raw {
            None => {
                self.count = match self.width {
                    CounterWidth::Bits32 => i64::from(raw),
                    CounterWidth::Bits16 => i64::from(raw as u16 as i16),
                };
            }
            Some(old) => self.count += self.width.delta(old, raw),
        }
        self.last_raw = Some(raw);
        self.count
    }

    /// Starts from a known `count` whose raw image is `raw` (instead of taking the first
    /// reading as the start).
    pub fn seed(&mut self, count: i64, raw: i32) {
        self.count = count;
        self.last_raw = Some(raw);
    }

    /// Whether a reading has been taken.
    pub fn started(&self) -> bool {
        self.last_raw.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn sixteen_bit_wrap_both_ways() {
        let mut c = IncrementCounter::new(CounterWidth::Bits16);
        assert_eq!(c.update(65_530), -6);
        assert_eq!(c.update(4), 4); // +10 across the wrap
        assert_eq!(c.update(65_535), -1); // -5 back across it
    }

    #[test]
    fn thirty_two_bit_wrap() {
        let mut c = IncrementCounter::new(CounterWidth::Bits32);
        assert_eq!(c.update(i32::MAX - 1), i64::from(i32::MAX) - 1);
        assert_eq!(c.update(i32::MIN + 1), i64::from(i32::MAX) + 2);
    }

    proptest! {
        /// A counter fed the wrapped image of any walk (steps below half the range) recovers
        /// the walk exactly, over many wraps in both directions and for both widths.
        #[test]
        fn recovers_any_walk(start in -(1i64 << 40)..(1i64 << 40),
                             steps in proptest::collection::vec(-30_000i64..30_000, 1..400),
                             scale in 1i64..70_000, sixteen in any::<bool>()) {
            let width = if sixteen { CounterWidth::Bits16 } else { CounterWidth::Bits32 };
            let limit = match width {
                CounterWidth::Bits32 => (1i64 << 31) - 1,
                CounterWidth::Bits16 => (1i64 << 15) - 1,
            };
            let mut c = IncrementCounter::new(width);
            let mut truth = match width {
                CounterWidth::Bits32 => i64::from(start as i32),
                CounterWidth::Bits16 => i64::from(start as i16),
            };
            prop_assert_eq!(c.update(width.wrap(truth)), truth);
            for s in steps {
                let step = (s * scale).clamp(-limit, limit);
                truth += step;
                prop_assert_eq!(c.update(width.wrap(truth)), truth);
            }
        }
    }
}
