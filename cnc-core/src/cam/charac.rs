//! Characteristic values of a cam (seed 3.4, `MC_TableCharacValues`) and the value table of
//! `MC_ReadMotionFunctionValues`.
//!
//! Values are computed for a master moving at constant velocity 1.0 ("normed"): velocity is
//! then dy/dx, acceleration d2y/dx2, jerk d3y/dx3. `rescaled` converts to another constant
//! master velocity V (velocity x V, acceleration x V^2, jerk x V^3). Extremes come from the
//! closed-form pieces: each piece is sampled and every sign change of the next derivative is
//! bisected to its root, so a maximum inside a piece is found to machine precision.

use super::error::CamError;
use super::CamProfile;

/// `MC_TableCharacValues`, fields 1 to 31 (the two dynamic-momentum fields are not
/// supported by the seed either and stay 0).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[allow(non_snake_case, missing_docs)]
pub struct CharacValues {
    pub fMasterVeloNom: f64,
    pub fMasterPosStart: f64,
    pub fSlavePosStart: f64,
    pub fSlaveVeloStart: f64,
    pub fSlaveAccStart: f64,
    pub fSlaveJerkStart: f64,
    pub fMasterPosEnd: f64,
    pub fSlavePosEnd: f64,
    pub fSlaveVeloEnd: f64,
    pub fSlaveAccEnd: f64,
    pub fSlaveJerkEnd: f64,
    pub fMPosAtSPosMin: f64,
    pub fSlavePosMin: f64,
    pub fMPosAtSVeloMin: f64,
    pub fSlaveVeloMin: f64,
    pub fMPosAtSAccMin: f64,
    pub fSlaveAccMin: f64,
    pub fSVeloAtSAccMin: f64,
    pub fSlaveJerkMin: f64,
    pub fSlaveDynMomMin: f64,
    pub fMPosAtSPosMax: f64,
    pub fSlavePosMax: f64,
    pub fMPosAtSVeloMax: f64,
    pub fSlaveVeloMax: f64,
    pub fMPosAtSAccMax: f64,
    pub fSlaveAccMax: f64,
    pub fSVeloAtSAccMax: f64,
    pub fSlaveJerkMax: f64,
    pub fSlaveDynMomMax: f64,
    pub fSlaveVeloMean: f64,
    pub fSlaveAccEff: f64,
}

/// Samples per piece before bisection (tables: per row interval).
const SAMPLES_PER_PIECE: usize = 64;
const SAMPLES_PER_ROW: usize = 4;

/// An extreme of one slave quantity: its value, the master position where it occurs and
/// the slave velocity there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extreme {
    /// The value.
    pub value: f64,
    /// Master position.
    pub at: f64,
    /// Slave velocity there.
    pub velocity: f64,
}

impl CharacValues {
    /// The names and values in the seed's order (for JSON and tables).
    pub fn fields(&self) -> [(&'static str, f64); 31] {
        [
            ("fMasterVeloNom", self.fMasterVeloNom),
            ("fMasterPosStart", self.fMasterPosStart),
            ("fSlavePosStart", self.fSlavePosStart),
            ("fSlaveVeloStart", self.fSlaveVeloStart),
            ("fSlaveAccStart", self.fSlaveAccStart),
            ("fSlaveJerkStart", self.fSlaveJerkStart),
            ("fMasterPosEnd", self.fMasterPosEnd),
            ("fSlavePosEnd", self.fSlavePosEnd),
            ("fSlaveVeloEnd", self.fSlaveVeloEnd),
            ("fSlaveAccEnd", self.fSlaveAccEnd),
            ("fSlaveJerkEnd", self.fSlaveJerkEnd),
            ("fMPosAtSPosMin", self.fMPosAtSPosMin),
            ("fSlavePosMin", self.fSlavePosMin),
            ("fMPosAtSVeloMin", self.fMPosAtSVeloMin),
            ("fSlaveVeloMin", self.fSlaveVeloMin),
            ("fMPosAtSAccMin", self.fMPosAtSAccMin),
            ("fSlaveAccMin", self.fSlaveAccMin),
            ("fSVeloAtSAccMin", self.fSVeloAtSAccMin),
            ("fSlaveJerkMin", self.fSlaveJerkMin),
            ("fSlaveDynMomMin", self.fSlaveDynMomMin),
            ("fMPosAtSPosMax", self.fMPosAtSPosMax),
            ("fSlavePosMax", self.fSlavePosMax),
            ("fMPosAtSVeloMax", self.fMPosAtSVeloMax),
            ("fSlaveVeloMax", self.fSlaveVeloMax),
            ("fMPosAtSAccMax", self.fMPosAtSAccMax),
            ("fSlaveAccMax", self.fSlaveAccMax),
            ("fSVeloAtSAccMax", self.fSVeloAtSAccMax),
            ("fSlaveJerkMax", self.fSlaveJerkMax),
            ("fSlaveDynMomMax", self.fSlaveDynMomMax),
            ("fSlaveVeloMean", self.fSlaveVeloMean),
            ("fSlaveAccEff", self.fSlaveAccEff),
        ]
    }

    /// The normed values (master velocity 1.0) of a profile over its master range (one
    /// period for a periodic table).
    pub fn normed(profile: &CamProfile) -> CharacValues {
        let mut lo = [None::<Extreme>; 4];
        let mut hi = [None::<Extreme>; 4];
        let mut travel = 0.0;
        let mut acc_square = 0.0;
        let mut piece_end = [0.0; 5];
        let samples = match profile {
            CamProfile::MotionFunction(_) => SAMPLES_PER_PIECE,
            CamProfile::Table(_) => SAMPLES_PER_ROW,
        };
        profile.for_each_piece(&mut |a: f64, b: f64, eval: &dyn Fn(f64) -> [f64; 5]| {
            let start = eval(a);
            piece_end = eval(b);
            let mut note = |x: f64, d: &[f64; 5]| {
                for k in 0..4 {
                    let e = Extreme {
                        value: d[k],
                        at: x,
                        velocity: d[1],
                    };
                    if lo[k].is_none_or(|m| d[k] < m.value) {
                        lo[k] = Some(e);
                    }
                    if hi[k].is_none_or(|m| d[k] > m.value) {
                        hi[k] = Some(e);
                    }
                }
            };
            let dx = (b - a) / samples as f64;
            let mut prev_x = a;
            let mut prev = start;
            // Position at the last root of the velocity, for the travelled distance.
            let mut turn_y = start[0];
            note(a, &start);
            for i in 1..=samples {
                let x = if i == samples { b } else { a + dx * i as f64 };
                let d = eval(x);
                note(x, &d);
                // A velocity that is exactly zero at a sample is a turn there.
                if d[1] == 0.0 && prev[1] != 0.0 {
                    travel += (d[0] - turn_y).abs();
                    turn_y = d[0];
                }
                for k in 0..4 {
                    // A sign change of derivative k+1: derivative k has an extreme inside.
                    if prev[k + 1] * d[k + 1] < 0.0 {
                        let root = bisect(eval, k + 1, prev_x, x);
                        let dr = eval(root);
                        note(root, &dr);
                        if k == 0 {
                            travel += (dr[0] - turn_y).abs();
                            turn_y = dr[0];
                        }
                    }
                }
                acc_square += gauss_square(eval, prev_x, x);
                prev_x = x;
                prev = d;
            }
            travel += (piece_end[0] - turn_y).abs();
        });
        let (m0, m1) = profile.master_range();
        let span = (m1 - m0).abs();
        // Start and end in the profile's own direction (a falling master starts high).
        let mut cursor = super::ProfileCursor::default();
        let at = |x: f64, cursor: &mut super::ProfileCursor| {
            let s = profile.eval(x, cursor);
            [s.position, s.velocity, s.acceleration, s.jerk, 0.0]
        };
        let (first, last) = (at(m0, &mut cursor), at(m1, &mut cursor));
        // A step at the very end is a position the last piece's formula does not reach.
        let end = Extreme {
            value: last[0],
            at: m1,
            velocity: last[1],
        };
        if lo[0].is_none_or(|m| end.value < m.value) {
            lo[0] = Some(end);
        }
        if hi[0].is_none_or(|m| end.value > m.value) {
            hi[0] = Some(end);
        }
        let four = |d: [f64; 5]| [d[0], d[1], d[2], d[3]];
        let mut values =
            CharacValues::from_extremes(1.0, [m0, m1], four(first), four(last), lo, hi);
        if span > 0.0 {
            values.fSlaveVeloMean = travel / span;
            values.fSlaveAccEff = (acc_square / span).sqrt();
        }
        values
    }

    /// The values from the master range, the slave's `[position, velocity, acceleration,
    /// jerk]` at its start and end, and the lowest and highest of each of the four (none
    /// seen: 0 at the start); mean and effective values 0, as the dynamic momentum.
    pub fn from_extremes(
        master_velocity: f64,
        [m0, m1]: [f64; 2],
        first: [f64; 4],
        last: [f64; 4],
        lo: [Option<Extreme>; 4],
        hi: [Option<Extreme>; 4],
    ) -> CharacValues {
        let get = |e: Option<Extreme>| {
            e.unwrap_or(Extreme {
                value: 0.0,
                at: m0,
                velocity: 0.0,
            })
        };
        let (p_lo, v_lo, a_lo, j_lo) = (get(lo[0]), get(lo[1]), get(lo[2]), get(lo[3]));
        let (p_hi, v_hi, a_hi, j_hi) = (get(hi[0]), get(hi[1]), get(hi[2]), get(hi[3]));
        CharacValues {
            fMasterVeloNom: master_velocity,
            fMasterPosStart: m0,
            fSlavePosStart: first[0],
            fSlaveVeloStart: first[1],
            fSlaveAccStart: first[2],
            fSlaveJerkStart: first[3],
            fMasterPosEnd: m1,
            fSlavePosEnd: last[0],
            fSlaveVeloEnd: last[1],
            fSlaveAccEnd: last[2],
            fSlaveJerkEnd: last[3],
            fMPosAtSPosMin: p_lo.at,
            fSlavePosMin: p_lo.value,
            fMPosAtSVeloMin: v_lo.at,
            fSlaveVeloMin: v_lo.value,
            fMPosAtSAccMin: a_lo.at,
            fSlaveAccMin: a_lo.value,
            fSVeloAtSAccMin: a_lo.velocity,
            fSlaveJerkMin: j_lo.value,
            fSlaveDynMomMin: 0.0,
            fMPosAtSPosMax: p_hi.at,
            fSlavePosMax: p_hi.value,
            fMPosAtSVeloMax: v_hi.at,
            fSlaveVeloMax: v_hi.value,
            fMPosAtSAccMax: a_hi.at,
            fSlaveAccMax: a_hi.value,
            fSVeloAtSAccMax: a_hi.velocity,
            fSlaveJerkMax: j_hi.value,
            fSlaveDynMomMax: 0.0,
            fSlaveVeloMean: 0.0,
            fSlaveAccEff: 0.0,
        }
    }

    /// The same values for a master at constant velocity `v`, also a negative one (the
    /// normed values scale with powers of `v`; positions do not change). A negative velocity
    /// turns velocities and jerks over: their minimum and maximum trade places with the master
    /// positions they lie at; accelerations keep theirs. `None` for a velocity that is 0 or
    /// not finite.
    pub fn rescaled(&self, v: f64) -> Option<CharacValues> {
        if !(v.is_finite() && v != 0.0 && self.fMasterVeloNom > 0.0) {
            return None;
        }
        let mut c = self.rescaled_by_magnitude(v.abs());
        if v < 0.0 {
            c.turn_over();
        }
        c.fMasterVeloNom = v;
        Some(c)
    }

    /// The velocities and jerks of a master running backwards: signs turned, minimum and
    /// maximum traded (with the master positions they lie at).
    fn turn_over(&mut self) {
        for f in [
            &mut self.fSlaveVeloStart,
            &mut self.fSlaveVeloEnd,
            &mut self.fSVeloAtSAccMin,
            &mut self.fSVeloAtSAccMax,
            &mut self.fSlaveJerkStart,
            &mut self.fSlaveJerkEnd,
        ] {
            *f = -*f;
        }
        let (lo, hi) = (-self.fSlaveVeloMax, -self.fSlaveVeloMin);
        (self.fSlaveVeloMin, self.fSlaveVeloMax) = (lo, hi);
        (self.fMPosAtSVeloMin, self.fMPosAtSVeloMax) = (self.fMPosAtSVeloMax, self.fMPosAtSVeloMin);
        let (lo, hi) = (-self.fSlaveJerkMax, -self.fSlaveJerkMin);
        (self.fSlaveJerkMin, self.fSlaveJerkMax) = (lo, hi);
    }

    /// [`CharacValues::rescaled`] for a velocity above 0.
    fn rescaled_by_magnitude(&self, v: f64) -> CharacValues {
        let k = v / self.fMasterVeloNom;
        let (k2, k3) = (k * k, k * k * k);
        let mut c = *self;
        c.fMasterVeloNom = v;
        for f in [
            &mut c.fSlaveVeloStart,
            &mut c.fSlaveVeloEnd,
            &mut c.fSlaveVeloMin,
            &mut c.fSlaveVeloMax,
            &mut c.fSVeloAtSAccMin,
            &mut c.fSVeloAtSAccMax,
            &mut c.fSlaveVeloMean,
        ] {
            *f *= k;
        }
        for f in [
            &mut c.fSlaveAccStart,
            &mut c.fSlaveAccEnd,
            &mut c.fSlaveAccMin,
            &mut c.fSlaveAccMax,
            &mut c.fSlaveAccEff,
        ] {
            *f *= k2;
        }
        for f in [
            &mut c.fSlaveJerkStart,
            &mut c.fSlaveJerkEnd,
            &mut c.fSlaveJerkMin,
            &mut c.fSlaveJerkMax,
        ] {
            *f *= k3;
        }
        c
    }
}

/// The root of derivative `order` between `a` and `b` (a sign change is known).
pub(crate) fn bisect(eval: &dyn Fn(f64) -> [f64; 5], order: usize, mut a: f64, mut b: f64) -> f64 {
    let mut fa = eval(a)[order];
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        let fm = eval(m)[order];
        if fm == 0.0 {
            return m;
        }
        if (fm < 0.0) == (fa < 0.0) {
            a = m;
            fa = fm;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// Integral of the squared acceleration over `[a, b]` (5-point Gauss-Legendre).
fn gauss_square(eval: &dyn Fn(f64) -> [f64; 5], a: f64, b: f64) -> f64 {
    const NODES: [(f64, f64); 5] = [
        (0.0, 0.568_888_888_888_888_9),
        (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
        (0.906_179_845_938_664, 0.236_926_885_056_189_1),
    ];
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    NODES
        .iter()
        .map(|(t, w)| {
            let acc = eval(mid + half * t)[2];
            w * acc * acc
        })
        .sum::<f64>()
        * half
}

/// `MC_ValueSelectType` bits.
pub mod value_mask {
    /// Slave position.
    pub const POSITION: u32 = 1;
    /// Slave velocity.
    pub const VELOCITY: u32 = 2;
    /// Slave acceleration.
    pub const ACCELERATION: u32 = 4;
    /// Slave jerk.
    pub const JERK: u32 = 8;
}

/// Most rows of a value table.
pub const MAX_VALUE_ROWS: usize = 1_000_000;

/// Master positions from `from` to `to` (inclusive) in steps of `increment`: how many, or
/// the refusal (zero step, a step away from `to`, more than `max_rows`).
pub fn sample_count(
    from: f64,
    to: f64,
    increment: f64,
    max_rows: usize,
) -> Result<usize, CamError> {
    let bad = CamError::Increment {
        from,
        to,
        increment,
        max_rows,
    };
    if !(from.is_finite() && to.is_finite() && increment.is_finite()) || increment == 0.0 {
        return Err(bad);
    }
    let steps = (to - from) / increment;
    if steps < -1e-9 || steps + 1.0 > max_rows as f64 {
        return Err(bad);
    }
    Ok((steps + 1e-9).floor() as usize + 1)
}

/// `MC_ReadMotionFunctionValues`: rows `[master, selected values...]` from `from` to `to`
/// (inclusive) in steps of `increment`; the columns are those of `mask`, in the order
/// position, velocity, acceleration, jerk.
pub fn value_table(
    profile: &CamProfile,
    mask: u32,
    from: f64,
    to: f64,
    increment: f64,
) -> Result<Vec<Vec<f64>>, CamError> {
    if mask == 0 || mask > 15 {
        return Err(CamError::ValueMask { mask });
    }
    let rows = sample_count(from, to, increment, MAX_VALUE_ROWS)?;
    let mut cursor = super::ProfileCursor::default();
    Ok((0..rows)
        .map(|i| {
            let x = from + increment * i as f64;
            let s = profile.eval(x, &mut cursor);
            let mut row = vec![x];
            for (bit, value) in [
                (value_mask::POSITION, s.position),
                (value_mask::VELOCITY, s.velocity),
                (value_mask::ACCELERATION, s.acceleration),
                (value_mask::JERK, s.jerk),
            ] {
                if mask & bit != 0 {
                    row.push(value);
                }
            }
            row
        })
        .collect())
}
