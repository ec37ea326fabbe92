//! The PLC master's frames between its cycles. A PLC task that runs every N-th NC tick
//! (`plc --period-ticks N`) writes a new frame only every N ticks; held in between, a moving
//! master would reach the tracking as a staircase (standing, then jumping N ticks' travel)
//! that no axis can follow within its limits. For the ticks until the next frame is due the
//! frame is extrapolated along the last two frames' motion (translation and rotation, at their
//! spacing); a frame that does not come in time is not extrapolated further: the master is
//! taken where the PLC last put it (the catch-up takes the small step back).

use nalgebra::{Isometry3, Translation3, UnitQuaternion};

/// Frames further apart than this many ticks are not a periodic writer: held, not
/// extrapolated.
pub(super) const MAX_PERIOD_TICKS: u64 = 16;

/// The last two frames the PLC wrote and when.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct PlcFrames {
    tick: u64,
    last: Option<(Isometry3<f64>, u64)>,
    previous: Option<(Isometry3<f64>, u64)>,
    /// The PLC let go of the master since its last frame: the next one starts anew.
    let_go: bool,
}

impl PlcFrames {
    /// A new tick: call before [`PlcFrames::take`] and [`PlcFrames::now`].
    pub(super) fn advance(&mut self) {
        self.tick += 1;
    }

    /// The PLC wrote `frame` this tick.
    pub(super) fn take(&mut self, frame: Isometry3<f64>) {
        self.previous = if core::mem::take(&mut self.let_go) {
            None
        } else {
            self.last
        };
        self.last = Some((frame, self.tick));
    }

    /// The PLC no longer commands (enable_w fell): the next frames are not carried on from
    /// the ones before.
    pub(super) fn forget_motion(&mut self) {
        self.let_go = true;
    }

    /// The master's frame this tick: the one written now, or the last one carried on along
    /// the motion of the last two until the next is due. A frame late by up to one more
    /// period (a task's jitter) holds where the carrying on stood, so the master does not
    /// step back and forth; later still, the master is where the PLC last put it.
    pub(super) fn now(&self) -> Option<Isometry3<f64>> {
        let (last, at) = self.last?;
        let since = self.tick.saturating_sub(at);
        let Some((before, then)) = self.previous.filter(|_| !self.let_go) else {
            return Some(last);
        };
        let period = at.saturating_sub(then);
        if since == 0 || period == 0 || period > MAX_PERIOD_TICKS || since >= 2 * period {
            return Some(last);
        }
        let carried = since.min(period - 1);
        Some(extrapolated(&before, &last, carried as f64 / period as f64))
    }
}

/// `last` carried on by `share` of the motion from `before` to `last`.
fn extrapolated(before: &Isometry3<f64>, last: &Isometry3<f64>, share: f64) -> Isometry3<f64> {
    let step = last.translation.vector - before.translation.vector;
    let turn: UnitQuaternion<f64> = last.rotation * before.rotation.inverse();
    let turned = turn.powf(share) * last.rotation;
    let frame = Isometry3::from_parts(
        Translation3::from(last.translation.vector + step * share),
        turned,
    );
    let finite = frame.translation.vector.iter().all(|v| v.is_finite())
        && frame.rotation.coords.iter().all(|v| v.is_finite());
    if finite {
        frame
    } else {
        *last
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn frame(x: f64, deg: f64) -> Isometry3<f64> {
        Isometry3::new(Vector3::new(x, 0.0, 0.0), Vector3::z() * deg.to_radians())
    }

    /// Every third tick a frame 3 mm and 3 degree on: the ticks between lie on the line.
    #[test]
    fn frames_of_a_slower_task_are_carried_on_between_its_cycles() {
        let mut f = PlcFrames::default();
        for tick in 0..12u32 {
            f.advance();
            if tick % 3 == 0 {
                f.take(frame(f64::from(tick), f64::from(tick)));
            }
            let now = f.now().unwrap();
            if tick >= 3 {
                let want = frame(f64::from(tick), f64::from(tick));
                assert!((now.translation.vector - want.translation.vector).norm() < 1e-12);
                assert!(now.rotation.angle_to(&want.rotation) < 1e-12, "tick {tick}");
            }
        }
    }

    /// A frame that does not come when due: up to one more period it holds where the
    /// carrying on stood (no step back), later the master is where the PLC last put it (a
    /// PLC that stopped writing); frames far apart (a single step) and frames after the PLC
    /// let go of the master are never carried on.
    #[test]
    fn a_late_frame_holds_then_the_last_counts_and_rare_frames_are_not_carried_on() {
        let mut f = PlcFrames::default();
        for tick in 0..4u32 {
            f.advance();
            if tick % 2 == 0 {
                f.take(frame(f64::from(tick), 0.0));
            }
        }
        // Frames at ticks 0 and 2; tick 3 carried on to 3.
        assert!((f.now().unwrap().translation.x - 3.0).abs() < 1e-12);
        f.advance(); // tick 4: the frame due is late: held at 3
        assert!((f.now().unwrap().translation.x - 3.0).abs() < 1e-12);
        f.advance(); // tick 5: still held
        assert!((f.now().unwrap().translation.x - 3.0).abs() < 1e-12);
        f.advance(); // tick 6: two periods without a frame: the last one
        assert_eq!(f.now().unwrap().translation.x, 2.0);
        let mut g = PlcFrames::default();
        g.advance();
        g.take(frame(0.0, 0.0));
        for _ in 0..20 {
            g.advance();
        }
        g.take(frame(0.1, 0.0));
        g.advance();
        assert_eq!(g.now().unwrap().translation.x, 0.1);
        // Let go of, then written again: not carried on from the frames before.
        let mut h = PlcFrames::default();
        h.advance();
        h.take(frame(0.0, 0.0));
        h.advance();
        h.forget_motion();
        h.advance();
        h.take(frame(2.0, 0.0));
        h.advance();
        assert_eq!(h.now().unwrap().translation.x, 2.0);
    }
}
