//! The FIFO override (seed 002, chapter 6): a factor in [0, 1] on the speed at which the job
//! time runs. *Instant* takes a new value at once (the user ramps it); *PT-2* pulls the
//! factor from where it is to the new value through a second-order lag
//!
//! ```text
//! T0² y'' + 2 D T0 y' + y = u,     D = 1.001 (fixed, just over-damped), T0 > 0 (a parameter)
//! ```
//!
//! so the speed changes continuously differentiably and never overshoots a step. The lag is
//! discretised exactly for the tick (a zero-order hold on `u`): `[y - u, y']` advances by the
//! matrix `e^(A tick)`, computed once from the two real poles (Sylvester's formula). A
//! change that decays exponentially never ends by itself: once the remaining difference and
//! its rate are below [`CUT_OFF`] (0.01 % of the reference speed, so no axis's velocity
//! steps by more than 1e-4 of its reference velocity) the filter takes the target.

/// How the override follows a new value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OverrideType {
    /// At once.
    Instant,
    /// Through the PT-2 lag with time constant `t0_s`.
    Pt2 {
        /// T0, s.
        t0_s: f64,
    },
}

/// The PT-2's damping (the seed fixes it at 1.001).
pub const PT2_DAMPING: f64 = 1.001;

/// Remaining difference (and rate x T0) below which a PT-2 change is cut off.
pub const CUT_OFF: f64 = 1e-4;

/// The override value, its rate and its target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OverrideFilter {
    kind: OverrideType,
    /// `e^(A tick)` of the PT-2 (identity for Instant).
    phi: [[f64; 2]; 2],
    value: f64,
    rate: f64,
    target: f64,
}

impl OverrideFilter {
    /// A filter at 100 % for a tick of `tick_s`.
    pub fn new(kind: OverrideType, tick_s: f64) -> OverrideFilter {
        let phi = match kind {
            OverrideType::Instant => [[1.0, 0.0], [0.0, 1.0]],
            OverrideType::Pt2 { t0_s } => transition(t0_s, tick_s),
        };
        OverrideFilter {
            kind,
            phi,
            value: 1.0,
            rate: 0.0,
            target: 1.0,
        }
    }

    /// A new target in [0, 1] (the caller checks the range).
    pub fn set_target(&mut self, target: f64) {
        self.target = target;
    }

    /// Value and target both `value`, at rest (before a start the override is simply the
    /// value set: a job starts at it).
    pub fn reset(&mut self, value: f64) {
        self.value = value;
        self.target = value;
        self.rate = 0.0;
    }

    /// One tick; the value in effect for it.
    pub fn step(&mut self) -> f64 {
        match self.kind {
            OverrideType::Instant => {
                self.value = self.target;
                self.rate = 0.0;
            }
            OverrideType::Pt2 { t0_s } => {
                if self.settled() {
                    return self.value;
                }
                let e = self.value - self.target;
                let [[a, b], [c, d]] = self.phi;
                let (e, rate) = (a * e + b * self.rate, c * e + d * self.rate);
                self.value = self.target + e;
                self.rate = rate;
                if e.abs() <= CUT_OFF && (rate * t0_s).abs() <= CUT_OFF {
                    self.value = self.target;
                    self.rate = 0.0;
                }
            }
        }
        self.value
    }

    /// The value in effect.
    pub fn value(&self) -> f64 {
        self.value
    }

    /// The target.
    pub fn target(&self) -> f64 {
        self.target
    }

    /// Whether the value has reached the target.
    pub fn settled(&self) -> bool {
        self.value == self.target && self.rate == 0.0
    }
}

/// `e^(A dt)` for `A = [[0, 1], [-1/T0², -2D/T0]]`: with its poles `l1 != l2`,
/// `e^(A dt) = c0 I + c1 A`, `c1 = (e^(l1 dt) - e^(l2 dt)) / (l1 - l2)`,
/// `c0 = (l1 e^(l2 dt) - l2 e^(l1 dt)) / (l1 - l2)`.
fn transition(t0: f64, dt: f64) -> [[f64; 2]; 2] {
    let root = (PT2_DAMPING * PT2_DAMPING - 1.0).sqrt();
    let (l1, l2) = ((-PT2_DAMPING + root) / t0, (-PT2_DAMPING - root) / t0);
    let (x1, x2) = ((l1 * dt).exp(), (l2 * dt).exp());
    let c1 = (x1 - x2) / (l1 - l2);
    let c0 = (l1 * x2 - l2 * x1) / (l1 - l2);
    let a = [[0.0, 1.0], [-1.0 / (t0 * t0), -2.0 * PT2_DAMPING / t0]];
    [
        [c0 + c1 * a[0][0], c1 * a[0][1]],
        [c1 * a[1][0], c0 + c1 * a[1][1]],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The continuous step response from rest: `y(t) = u + (y0 - u) (l1 e^(l2 t) - l2
    /// e^(l1 t)) / (l1 - l2)`.
    fn step_response(y0: f64, u: f64, t0: f64, t: f64) -> f64 {
        let root = (PT2_DAMPING * PT2_DAMPING - 1.0).sqrt();
        let (l1, l2) = ((-PT2_DAMPING + root) / t0, (-PT2_DAMPING - root) / t0);
        u + (y0 - u) * (l1 * (l2 * t).exp() - l2 * (l1 * t).exp()) / (l1 - l2)
    }

    #[test]
    fn pt2_samples_the_continuous_lag_and_cuts_off() {
        let (t0, dt) = (0.05, 0.001);
        let mut f = OverrideFilter::new(OverrideType::Pt2 { t0_s: t0 }, dt);
        f.set_target(0.25);
        let mut k = 0;
        while !f.settled() {
            k += 1;
            let y = f.step();
            if !f.settled() {
                let exact = step_response(1.0, 0.25, t0, k as f64 * dt);
                assert!((y - exact).abs() < 1e-12, "tick {k}: {y} vs {exact}");
            }
            assert!(k < 10_000, "the change never ended");
        }
        assert_eq!(f.value(), 0.25);
        // Nearly critically damped, the rest decays as (1 + t/T0) e^(-t/T0): it is 1e-4 of
        // a 0.75 step after about 11.5 T0 = 575 ticks.
        assert!((550..600).contains(&k), "cut off after {k} ticks");
    }

    #[test]
    fn instant_takes_the_value_at_once() {
        let mut f = OverrideFilter::new(OverrideType::Instant, 0.001);
        f.set_target(0.3);
        assert_eq!(f.step(), 0.3);
        assert!(f.settled());
    }

    proptest! {
        /// A PT-2 step never overshoots and never jumps: the value moves monotonically from
        /// its start to the target, by at most (step x tick / T0) per tick.
        #[test]
        fn pt2_is_monotone_and_smooth(y0 in 0.0f64..=1.0, u in 0.0f64..=1.0,
                                      t0 in 0.005f64..0.5) {
            let dt = 0.001;
            let mut f = OverrideFilter::new(OverrideType::Pt2 { t0_s: t0 }, dt);
            f.reset(y0);
            f.set_target(u);
            let mut before = y0;
            for _ in 0..20_000 {
                let y = f.step();
                prop_assert!((y - before) * (u - y0) >= 0.0, "moves away from the target");
                prop_assert!((y - u) * (y0 - u) >= 0.0, "overshoots");
                // The cut-off may close the last 1e-4 at once.
                let snap = if f.settled() { CUT_OFF } else { 0.0 };
                prop_assert!((y - before).abs() <= (u - y0).abs() * dt / t0 + snap + 1e-12);
                before = y;
                if f.settled() {
                    break;
                }
            }
            prop_assert!(f.settled());
            prop_assert_eq!(f.value(), u);
        }
    }
}
