//! The encoder's register interface through `enc_out.nCtrl2` and `enc_in.nStatus2` (the seed
//! names encoder reset and reading the absolute position as what these optional bytes carry,
//! without bits; the coding here is ours, in the style of a counter terminal):
//!
//! | request (`nCtrl2`) | value | answer (`nStatus2`) | result |
//! | --- | --- | --- | --- |
//! | 0x01 set counter | `enc_out.nOutData2` (increments) | 0x01 counter set | `nInData1` counts from the value |
//! | 0x02 read absolute | - | 0x02 absolute valid | `enc_in.nInData2`: the absolute position, 32 bits |
//!
//! The NC sets the request bit, the encoder answers with the same bit, the NC takes the result
//! and clears its bit, the encoder clears its answer: then the register is free. While the
//! absolute position is read, `nInData2` is not a probe latch.

/// `nCtrl2` / `nStatus2`: set the counter / the counter is set.
pub const SET_COUNTER: u8 = 0x01;
/// `nCtrl2` / `nStatus2`: read the absolute position / it is in `nInData2`.
pub const READ_ABSOLUTE: u8 = 0x02;

/// Ticks a request waits for its answer before it is given up ([`EncoderEvent::NoAnswer`]).
pub const ANSWER_TICKS: u32 = 500;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Job {
    Idle,
    /// Waiting for the answer to `bit` (with the value set) since `ticks`.
    Requested {
        bit: u8,
        value: i32,
        ticks: u32,
    },
    /// Answered; waiting for the encoder to clear its answer.
    Releasing {
        bit: u8,
    },
}

/// What an answered request gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EncoderEvent {
    /// The counter now counts from this value (increments).
    CounterSet(i32),
    /// The absolute position (increments).
    Absolute(i32),
    /// No answer within [`ANSWER_TICKS`]: the request was withdrawn (`bit`).
    NoAnswer(u8),
}

/// One request at a time through the register.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EncoderRegister {
    job: Job,
}

impl Default for EncoderRegister {
    fn default() -> Self {
        Self { job: Job::Idle }
    }
}

impl EncoderRegister {
    /// Asks for the absolute position; `false` while the register is busy.
    pub fn read_absolute(&mut self) -> bool {
        self.request(READ_ABSOLUTE, 0)
    }

    /// Asks the encoder to count from `value`; `false` while the register is busy.
    pub fn set_counter(&mut self, value: i32) -> bool {
        self.request(SET_COUNTER, value)
    }

    fn request(&mut self, bit: u8, value: i32) -> bool {
        if self.job != Job::Idle {
            return false;
        }
        self.job = Job::Requested {
            bit,
            value,
            ticks: 0,
        };
        true
    }

    /// Whether the absolute position is still being read.
    pub fn reading_absolute(&self) -> bool {
        matches!(
            self.job,
            Job::Requested {
                bit: READ_ABSOLUTE,
                ..
            }
        )
    }

    /// Whether a counter set waits for its answer.
    pub fn setting_counter(&self) -> bool {
        matches!(
            self.job,
            Job::Requested {
                bit: SET_COUNTER,
                ..
            }
        )
    }

    /// `enc_out.nCtrl2` and `enc_out.nOutData2`.
    pub fn control(&self) -> (u8, i32) {
        match self.job {
            Job::Requested { bit, value, .. } => (bit, value),
            _ => (0, 0),
        }
    }

    /// Reads the encoder's answer (`nStatus2`, `nInData2`).
    pub fn sense(&mut self, status2: u8, data2: i32) -> Option<EncoderEvent> {
        match self.job {
            Job::Requested { bit, value, .. } if status2 & bit != 0 => {
                self.job = Job::Releasing { bit };
                Some(if bit == SET_COUNTER {
                    EncoderEvent::CounterSet(value)
                } else {
                    EncoderEvent::Absolute(data2)
                })
            }
            Job::Releasing { bit } if status2 & bit == 0 => {
                self.job = Job::Idle;
                None
            }
            Job::Requested { bit, ticks, .. } if ticks + 1 >= ANSWER_TICKS => {
                self.job = Job::Releasing { bit };
                Some(EncoderEvent::NoAnswer(bit))
            }
            Job::Requested { bit, value, ticks } => {
                self.job = Job::Requested {
                    bit,
                    value,
                    ticks: ticks + 1,
                };
                None
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_is_answered_released_and_the_register_is_free_again() {
        let mut r = EncoderRegister::default();
        assert!(r.set_counter(1234));
        assert!(!r.read_absolute(), "one request at a time");
        assert_eq!(r.control(), (SET_COUNTER, 1234));
        assert_eq!(r.sense(0, 0), None);
        assert_eq!(
            r.sense(SET_COUNTER, 0),
            Some(EncoderEvent::CounterSet(1234))
        );
        assert_eq!(r.control(), (0, 0), "the request bit falls");
        assert_eq!(r.sense(SET_COUNTER, 0), None);
        assert!(!r.read_absolute(), "busy until the answer falls");
        assert_eq!(r.sense(0, 0), None);
        assert!(r.read_absolute());
        assert!(r.reading_absolute());
        assert_eq!(
            r.sense(READ_ABSOLUTE, -77),
            Some(EncoderEvent::Absolute(-77))
        );
    }

    #[test]
    fn a_request_without_answer_is_given_up() {
        let mut r = EncoderRegister::default();
        assert!(r.set_counter(5));
        for _ in 1..ANSWER_TICKS {
            assert_eq!(r.sense(0, 0), None);
        }
        assert_eq!(r.sense(0, 0), Some(EncoderEvent::NoAnswer(SET_COUNTER)));
        assert_eq!(r.control(), (0, 0));
        assert_eq!(r.sense(0, 0), None);
        assert!(r.read_absolute(), "free again");
    }
}
