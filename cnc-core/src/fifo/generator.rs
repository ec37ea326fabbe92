//! The FIFO set-point generator (seed 002, chapter 5): each tick the job time advances by
//! `tick x override`; the generator passes the rows whose time is over, interpolates the
//! position linearly between the pair of rows around the job time, and takes the velocity as
//! the difference of its own set-points over the tick (so it integrates exactly to the
//! positions: the velocity feed-forward). The acceleration is not the difference of those
//! velocities, which the seed warns is coarse (with T_f two ticks it alternates between 0 and
//! twice the real value): it is the rows' own second difference, `(p[i+1] - 2 p[i] +
//! p[i-1]) / T_f^2` at each row, interpolated linearly between the pair of rows like the
//! position and scaled by the override squared. Rows of a constant acceleration give it
//! exactly on every tick.
//!
//! When the job time reaches the last queued row the axes hold its positions and the
//! job time waits there: if the rows asked for motion beyond it, that is an *underrun* (the
//! axes stop at once, the group goes on as soon as rows come); if the last rows stand, the
//! content has brought the axes to rest: the *end* of the job.

use super::ring::RowRing;

/// Rows closer than this (per axis, in position units) stand: a file's rounding noise is
/// not motion.
pub const AT_REST: f64 = 1e-9;

fn moving(a: Option<&[f64]>, b: Option<&[f64]>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => a.iter().zip(b).any(|(x, y)| (x - y).abs() > AT_REST),
        _ => false,
    }
}

/// What one step found.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GeneratorStatus {
    /// Rows passed in this step.
    pub rows_passed: u32,
    /// The FIFO ran dry while the rows asked for motion: the axes hold the last row.
    pub underrun: bool,
    /// Every queued row is executed and the last ones stand: the axes are at rest.
    pub at_end: bool,
}

/// Set-points of the N axes of a group.
#[derive(Debug, Clone)]
pub struct FifoGenerator {
    tick_s: f64,
    fifo_cycle_s: f64,
    /// Job time past the front row, s, in [0, T_f).
    offset: f64,
    rows_passed: u64,
    last_segment_moving: bool,
    position: Vec<f64>,
    velocity: Vec<f64>,
    acceleration: Vec<f64>,
    /// The row before the front row (the front row itself at the start).
    previous: Vec<f64>,
}

impl FifoGenerator {
    /// A generator for `dimension` axes (allocates here, never in a step).
    pub fn new(dimension: usize, tick_s: f64, fifo_cycle_s: f64) -> FifoGenerator {
        FifoGenerator {
            tick_s,
            fifo_cycle_s,
            offset: 0.0,
            rows_passed: 0,
            last_segment_moving: false,
            position: vec![0.0; dimension],
            velocity: vec![0.0; dimension],
            acceleration: vec![0.0; dimension],
            previous: vec![0.0; dimension],
        }
    }

    /// A new T_f (between jobs).
    pub fn set_fifo_cycle(&mut self, fifo_cycle_s: f64) {
        self.fifo_cycle_s = fifo_cycle_s;
    }

    /// A job starts at the front row (which the caller has checked against the axes):
    /// positions there, at rest, job time 0.
    pub fn start(&mut self, ring: &RowRing) {
        self.offset = 0.0;
        self.rows_passed = 0;
        self.last_segment_moving = false;
        if let Some(row) = ring.row(0) {
            self.position.copy_from_slice(row);
            self.previous.copy_from_slice(row);
        }
        self.velocity.fill(0.0);
        self.acceleration.fill(0.0);
    }

    /// One tick at `override_value` (0..=1); `ring` loses the rows passed.
    pub fn step(&mut self, ring: &mut RowRing, override_value: f64) -> GeneratorStatus {
        let mut status = GeneratorStatus::default();
        self.offset += self.tick_s * override_value;
        while ring.len() >= 2 && self.offset >= self.fifo_cycle_s {
            self.last_segment_moving = moving(ring.row(0), ring.row(1));
            if let Some(front) = ring.row(0) {
                self.previous.copy_from_slice(front);
            }
            ring.pop_front();
            self.offset -= self.fifo_cycle_s;
            self.rows_passed += 1;
            status.rows_passed += 1;
        }
        if ring.len() <= 1 {
            // Nothing ahead: hold the last row; the job time waits for rows.
            if self.offset > 0.0 {
                status.underrun = self.last_segment_moving;
                self.offset = 0.0;
            }
            status.at_end = !self.last_segment_moving;
        }
        let fraction = self.offset / self.fifo_cycle_s;
        let (Some(low), high) = (ring.row(0), ring.row(1)) else {
            return status;
        };
        let next = ring.row(2);
        let second =
            |a: f64, b: f64, c: f64| (c - 2.0 * b + a) / (self.fifo_cycle_s * self.fifo_cycle_s);
        for c in 0..self.position.len() {
            let (p, a) = match high {
                Some(high) => {
                    let at_low = second(self.previous[c], low[c], high[c]);
                    // No row after `high` yet (a short queue, or the last row): the
                    // acceleration stays the one at `low` instead of guessing a stop.
                    let at_high = next.map_or(at_low, |n| second(low[c], high[c], n[c]));
                    let a = at_low + fraction * (at_high - at_low);
                    (
                        low[c] + fraction * (high[c] - low[c]),
                        a * override_value * override_value,
                    )
                }
                // Holding the last row.
                None => (low[c], 0.0),
            };
            self.velocity[c] = (p - self.position[c]) / self.tick_s;
            self.acceleration[c] = a;
            self.position[c] = p;
        }
        status
    }

    /// Job time, s on the FIFO's time base.
    pub fn job_time(&self) -> f64 {
        self.rows_passed as f64 * self.fifo_cycle_s + self.offset
    }

    /// Rows passed since the start.
    pub fn rows_passed(&self) -> u64 {
        self.rows_passed
    }

    /// Position set-points.
    pub fn position(&self) -> &[f64] {
        &self.position
    }

    /// Velocity set-points (position difference over the tick).
    pub fn velocity(&self) -> &[f64] {
        &self.velocity
    }

    /// Acceleration set-points (the rows' second differences, interpolated).
    pub fn acceleration(&self) -> &[f64] {
        &self.acceleration
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn ring_of(rows: &[f64]) -> RowRing {
        let mut ring = RowRing::new(1, rows.len() + 4);
        ring.push_block(rows).unwrap();
        ring
    }

    /// Rows of a constant acceleration of 5000 mm/s^2 at T_f = 2 ticks: the acceleration
    /// set-point is 5000 on every tick once the first row is passed (before: 0 and 10000 by
    /// turns), and the velocity feed-forward is the rows' slope in the middle of a pair.
    #[test]
    fn the_acceleration_of_rows_of_constant_acceleration_is_smooth_and_exact() {
        let tf = 0.002;
        let rows: Vec<f64> = (0..40)
            .map(|k| 0.5 * 5000.0 * (k as f64 * tf).powi(2))
            .collect();
        let mut ring = ring_of(&rows);
        let mut g = FifoGenerator::new(1, 0.001, tf);
        g.start(&ring);
        for tick in 1..60 {
            g.step(&mut ring, 1.0);
            let a = g.acceleration()[0];
            if tick >= 2 {
                assert!((a - 5000.0).abs() < 1e-6, "tick {tick}: {a}");
            }
            if tick % 2 == 1 {
                // Half-way between rows k and k+1: the slope of that pair.
                let k = tick / 2;
                let slope = (rows[k + 1] - rows[k]) / tf;
                assert!((g.velocity()[0] - slope).abs() < 1e-6, "tick {tick}");
            }
        }
        // At half override the same rows take twice as long: a quarter of the acceleration.
        let mut ring = ring_of(&rows);
        g.start(&ring);
        for _ in 0..8 {
            g.step(&mut ring, 0.5);
        }
        assert!((g.acceleration()[0] - 1250.0).abs() < 1e-6);
    }

    /// Rows of constant velocity whose queue holds no row after the current pair (the PLC has
    /// not refilled yet): the acceleration stays 0, no stop is guessed (before: a false
    /// deceleration of up to v / T_f).
    #[test]
    fn a_pair_without_a_row_after_it_keeps_its_acceleration() {
        let mut ring = ring_of(&[0.0, 1.0, 2.0, 3.0, 4.0]);
        let mut g = FifoGenerator::new(1, 0.001, 0.002);
        g.start(&ring);
        let mut last_pair = 0;
        for _ in 0..8 {
            g.step(&mut ring, 1.0);
            let (p, a) = (g.position()[0], g.acceleration()[0]);
            if p > 3.0 && p < 4.0 {
                last_pair += 1;
                assert!(a.abs() < 1e-9, "at {p}: {a}");
            }
        }
        assert!(last_pair > 0, "the last pair was walked");
    }

    #[test]
    fn fine_interpolation_walks_the_pair() {
        // T_f = 4 ticks: three set-points between two rows, on the straight line.
        let mut ring = ring_of(&[0.0, 4.0, 4.0]);
        let mut g = FifoGenerator::new(1, 0.001, 0.004);
        g.start(&ring);
        let mut seen = Vec::new();
        for _ in 0..6 {
            g.step(&mut ring, 1.0);
            seen.push(g.position()[0]);
        }
        for (got, want) in seen.iter().zip([1.0, 2.0, 3.0, 4.0, 4.0, 4.0]) {
            assert!((got - want).abs() < 1e-12, "{seen:?}");
        }
        assert!((g.velocity()[0] - 0.0).abs() < 1e-9);
    }

    #[test]
    fn underrun_holds_and_resumes_end_stands() {
        let mut ring = ring_of(&[0.0, 1.0]);
        let mut g = FifoGenerator::new(1, 0.001, 0.001);
        g.start(&ring);
        let s = g.step(&mut ring, 1.0);
        assert_eq!((s.rows_passed, s.underrun), (1, false));
        assert_eq!(g.position()[0], 1.0);
        let s = g.step(&mut ring, 1.0);
        assert!(s.underrun && !s.at_end, "{s:?}");
        assert_eq!((g.position()[0], g.velocity()[0]), (1.0, 0.0));
        // Rows arrive: the job goes on from the held row, no jump.
        ring.push_block(&[2.0, 2.0]).unwrap();
        g.step(&mut ring, 1.0);
        assert_eq!(g.position()[0], 2.0);
        let s = g.step(&mut ring, 1.0);
        let s2 = g.step(&mut ring, 1.0);
        assert!(!s.underrun && s.at_end && s2.at_end, "{s:?} {s2:?}");
        assert_eq!(g.rows_passed(), 3);
    }

    #[test]
    fn rounding_noise_is_not_motion() {
        let mut ring = ring_of(&[0.0, 1.0, 1.0 + 1e-13]);
        let mut g = FifoGenerator::new(1, 0.001, 0.001);
        g.start(&ring);
        for _ in 0..3 {
            g.step(&mut ring, 1.0);
        }
        let s = g.step(&mut ring, 1.0);
        assert!(s.at_end && !s.underrun, "{s:?}");
    }

    proptest! {
        /// With T_f = k x tick every k-th set-point is a row; with any ratio every set-point
        /// lies on the straight line of its pair at the job time, and the velocities sum
        /// (x tick) to the distance travelled.
        #[test]
        fn set_points_lie_on_the_rows(rows in proptest::collection::vec(-100.0f64..100.0, 2..40),
                                      ratio in 0.1f64..7.3, ov in 0.05f64..=1.0) {
            let tick = 0.001;
            let t_f = tick * ratio;
            let mut ring = ring_of(&rows);
            let mut g = FifoGenerator::new(1, tick, t_f);
            g.start(&ring);
            let mut travelled = 0.0;
            let steps = ((rows.len() - 1) as f64 * ratio / ov).ceil() as usize + 3;
            for n in 1..=steps {
                g.step(&mut ring, ov);
                travelled += g.velocity()[0] * tick;
                let t = (n as f64 * tick * ov).min((rows.len() - 1) as f64 * t_f);
                let k = ((t / t_f).floor() as usize).min(rows.len() - 1);
                let want = if k + 1 < rows.len() {
                    rows[k] + (t / t_f - k as f64) * (rows[k + 1] - rows[k])
                } else {
                    rows[k]
                };
                // Rounding of t / T_f near a row moves the pair, not the point.
                prop_assert!((g.position()[0] - want).abs() < 1e-6 * (1.0 + want.abs()),
                    "step {n}: {} vs {want}", g.position()[0]);
            }
            prop_assert!((travelled - (rows[rows.len() - 1] - rows[0])).abs() < 1e-9);
            prop_assert_eq!(g.rows_passed(), rows.len() as u64 - 1);
        }
    }
}
