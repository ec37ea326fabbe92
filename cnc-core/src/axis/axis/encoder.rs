//! MC_SetPosition and the answers of the encoder's register (`super::super::encoder_reg`).

use super::*;

impl Axis {
    /// MC_SetPosition: at standstill the encoder is asked to count from `position`; the
    /// command ends when it answered (`sense`).
    pub(super) fn set_position(&mut self, position: f64) -> Result<u32, AxisError> {
        let cfg = &self.config;
        if !cfg.io.encoder_set_counter {
            return Err(AxisError::SetPositionNotSupported);
        }
        if self.error.is_some() {
            return Err(AxisError::AxisInError);
        }
        if self.coupling.is_some() {
            return Err(AxisError::Coupled);
        }
        if self.generator.goal() != Goal::Hold || self.last_set.velocity != 0.0 {
            return Err(AxisError::SetPositionWhileMoving);
        }
        let count = position * cfg.increments_per_unit;
        if !count.is_finite() || count.abs() > f64::from(i32::MAX) {
            return Err(AxisError::TargetOutsideLimits);
        }
        let value = cfg.encoder_width.wrap(count.round() as i64);
        if !self.encoder_reg.set_counter(value) {
            return Err(AxisError::EncoderNotReady);
        }
        self.new_count = Some(count.round() as i64);
        Ok(self.book.begin(AxisCommandKind::SetPosition))
    }

    fn finish_set_position(&mut self, result: CommandResult, error: Option<AxisError>) {
        if self.book.active().map(|a| a.kind) == Some(AxisCommandKind::SetPosition) {
            self.book.finish(result, error);
        }
    }

    /// Asks the encoder for its absolute position again (MC_Reset after it did not answer).
    pub(super) fn reread_absolute(&mut self) {
        if self.config.io.encoder_absolute && self.error == Some(AxisError::EncoderNotReady) {
            self.encoder_reg.read_absolute();
        }
    }

    /// An answer of the encoder's register: the counter re-based (`true`) to the absolute
    /// position read, or to the position MC_SetPosition gave.
    pub(super) fn encoder_answer(&mut self, enc_in: &NcEncoderIn) -> bool {
        match self.encoder_reg.sense(enc_in.nStatus2, enc_in.nInData2) {
            Some(EncoderEvent::Absolute(abs)) => {
                // The absolute value and nInData1 are of the same sample.
                self.counter.seed(i64::from(abs), enc_in.nInData1);
                true
            }
            Some(EncoderEvent::CounterSet(_)) => {
                let count = self.new_count.take().unwrap_or(0);
                self.counter.seed(count, enc_in.nInData1);
                self.finish_set_position(CommandResult::Done, None);
                true
            }
            Some(EncoderEvent::NoAnswer(bit)) => {
                self.new_count = None;
                if bit == crate::axis::encoder_reg::READ_ABSOLUTE {
                    // The axis does not know where it stands: it stays off, in error
                    // (MC_Reset asks again).
                    self.fault(AxisError::EncoderNotReady);
                } else {
                    let error = Some(AxisError::EncoderNotReady);
                    self.finish_set_position(CommandResult::Error, error);
                }
                false
            }
            None => false,
        }
    }
}
