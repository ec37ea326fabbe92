//! One closed-form piece of a cam: a polynomial plus up to two sinusoids in the local master
//! coordinate `u = x - start`. Every motion law is a short list of such pieces, so position,
//! velocity, acceleration and jerk are the exact derivatives of one definition, and the
//! operations the laws need (stretch, mirror, shift, scale, add, integrate) stay closed-form.

/// Polynomial coefficients kept per piece (degree at most 9).
pub const POLY: usize = 10;

/// `sin * sin(omega * u) + cos * cos(omega * u)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wave {
    /// Angular frequency in radians per master unit (local coordinate).
    pub omega: f64,
    /// Amplitude of the sine term.
    pub sin: f64,
    /// Amplitude of the cosine term.
    pub cos: f64,
}

impl Wave {
    fn is_zero(&self) -> bool {
        self.sin == 0.0 && self.cos == 0.0
    }
}

/// A closed-form function on `[start, end]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// First master position of the piece.
    pub start: f64,
    /// Last master position of the piece.
    pub end: f64,
    /// Polynomial coefficients in `u = x - start`, lowest order first.
    pub poly: [f64; POLY],
    /// Sinusoids in `u`; unused ones are zero.
    pub waves: [Wave; 2],
}

/// Value and the first four derivatives with respect to the master position.
pub type Derivs5 = [f64; 5];

impl Piece {
    /// A polynomial piece.
    pub fn poly(start: f64, end: f64, coefficients: &[f64]) -> Piece {
        let mut poly = [0.0; POLY];
        poly[..coefficients.len()].copy_from_slice(coefficients);
        Piece {
            start,
            end,
            poly,
            waves: [Wave::default(); 2],
        }
    }

    /// A piece with one sinusoid and a polynomial.
    pub fn with_wave(start: f64, end: f64, coefficients: &[f64], wave: Wave) -> Piece {
        let mut piece = Piece::poly(start, end, coefficients);
        piece.waves[0] = wave;
        piece
    }

    fn degree(&self) -> usize {
        self.poly.iter().rposition(|c| *c != 0.0).unwrap_or(0)
    }

    /// Value and derivatives 1..=4 at master position `x` (the formula, also outside the range).
    #[inline]
    pub fn eval(&self, x: f64) -> Derivs5 {
        let u = x - self.start;
        // Horner for a polynomial and its derivatives in one pass; d[k] ends as p^(k)/k!.
        let mut d = [0.0f64; 5];
        for i in (0..POLY).rev() {
            d[4] = d[4] * u + d[3];
            d[3] = d[3] * u + d[2];
            d[2] = d[2] * u + d[1];
            d[1] = d[1] * u + d[0];
            d[0] = d[0] * u + self.poly[i];
        }
        d[2] *= 2.0;
        d[3] *= 6.0;
        d[4] *= 24.0;
        for w in &self.waves {
            if w.is_zero() {
                continue;
            }
            let (s, c) = (w.omega * u).sin_cos();
            let even = w.sin * s + w.cos * c;
            let odd = w.sin * c - w.cos * s;
            let (w1, w2) = (w.omega, w.omega * w.omega);
            d[0] += even;
            d[1] += w1 * odd;
            d[2] -= w2 * even;
            d[3] -= w2 * w1 * odd;
            d[4] += w2 * w2 * even;
        }
        d
    }

    /// The same function written for the local coordinate `u' ` with `u = alpha + beta * u'`,
    /// on `[new_start, new_end]`. Used to stretch, mirror and split pieces.
    pub fn reparametrised(&self, alpha: f64, beta: f64, new_start: f64, new_end: f64) -> Piece {
        // Expand sum c_i (alpha + beta u')^i by the binomial theorem.
        let mut poly = [0.0; POLY];
        let n = self.degree();
        for (i, c) in self.poly.iter().enumerate().take(n + 1) {
            if *c == 0.0 {
                continue;
            }
            let mut binom = 1.0;
            for (k, slot) in poly.iter_mut().enumerate().take(i + 1) {
                *slot += c * binom * alpha.powi((i - k) as i32) * beta.powi(k as i32);
                binom = binom * (i - k) as f64 / (k + 1) as f64;
            }
        }
        let mut waves = self.waves;
        for w in &mut waves {
            let (s, c) = (w.omega * alpha).sin_cos();
            *w = Wave {
                omega: w.omega * beta,
                sin: w.sin * c - w.cos * s,
                cos: w.sin * s + w.cos * c,
            };
        }
        Piece {
            start: new_start,
            end: new_end,
            poly,
            waves,
        }
    }

    /// `factor * f + offset`.
    pub fn scaled(&self, factor: f64, offset: f64) -> Piece {
        let mut p = *self;
        for c in &mut p.poly {
            *c *= factor;
        }
        for w in &mut p.waves {
            w.sin *= factor;
            w.cos *= factor;
        }
        p.poly[0] += offset;
        p
    }

    /// The part of this piece on `[from, to]` (a sub-range), with its own local origin.
    pub fn restricted(&self, from: f64, to: f64) -> Piece {
        self.reparametrised(from - self.start, 1.0, from, to)
    }

    /// `f + g` where `g` covers the same range; `None` if more than two distinct frequencies
    /// would be needed or the degree would exceed the storage.
    pub fn plus(&self, other: &Piece) -> Option<Piece> {
        let g = other.reparametrised(self.start - other.start, 1.0, self.start, self.end);
        let mut sum = *self;
        for (a, b) in sum.poly.iter_mut().zip(g.poly) {
            *a += b;
        }
        for w in g.waves.iter().filter(|w| !w.is_zero()) {
            if let Some(slot) = sum.waves.iter_mut().find(|s| s.omega == w.omega) {
                slot.sin += w.sin;
                slot.cos += w.cos;
            } else if let Some(slot) = sum.waves.iter_mut().find(|s| s.is_zero()) {
                *slot = *w;
            } else {
                return None;
            }
        }
        Some(sum)
    }

    /// The antiderivative that takes the value `at_start` at `start`.
    pub fn integrated(&self, at_start: f64) -> Option<Piece> {
        if self.poly[POLY - 1] != 0.0 {
            return None;
        }
        let mut p = *self;
        p.poly = [0.0; POLY];
        for i in 0..POLY - 1 {
            p.poly[i + 1] = self.poly[i] / (i + 1) as f64;
        }
        p.poly[0] = at_start;
        for w in &mut p.waves {
            if w.is_zero() {
                continue;
            }
            // integral of s sin(wt) + c cos(wt) from 0 to u = s/w (1 - cos wu) + c/w sin wu
            p.poly[0] += w.sin / w.omega;
            *w = Wave {
                omega: w.omega,
                sin: w.cos / w.omega,
                cos: -w.sin / w.omega,
            };
        }
        Some(p)
    }
}

/// Operations on a list of pieces that covers an interval without gaps.
pub mod shape {
    use super::Piece;

    /// Value and derivatives of the piece list at `x` (clamped to its range).
    pub fn eval(pieces: &[Piece], x: f64) -> super::Derivs5 {
        let piece = pieces
            .iter()
            .find(|p| x <= p.end)
            .unwrap_or(&pieces[pieces.len() - 1]);
        piece.eval(x.clamp(pieces[0].start, pieces[pieces.len() - 1].end))
    }

    /// `g(z) = f(alpha + beta * z)` over the image of `[f.start, f.end]`, pieces in
    /// ascending order even when `beta < 0` (a mirror).
    pub fn reparametrised(pieces: &[Piece], alpha: f64, beta: f64) -> Vec<Piece> {
        let mut out: Vec<Piece> = pieces
            .iter()
            .map(|p| {
                let (a, b) = ((p.start - alpha) / beta, (p.end - alpha) / beta);
                let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
                // u = alpha + beta z - p.start, z = lo + u'
                p.reparametrised(alpha + beta * lo - p.start, beta, lo, hi)
            })
            .collect();
        out.sort_by(|a, b| a.start.total_cmp(&b.start));
        out
    }

    /// `factor * f + offset` piece by piece.
    pub fn scaled(pieces: &[Piece], factor: f64, offset: f64) -> Vec<Piece> {
        pieces.iter().map(|p| p.scaled(factor, offset)).collect()
    }

    /// The pointwise sum of two lists that cover the same interval.
    pub fn sum(a: &[Piece], b: &[Piece]) -> Option<Vec<Piece>> {
        let mut cuts: Vec<f64> = a.iter().chain(b).flat_map(|p| [p.start, p.end]).collect();
        cuts.sort_by(f64::total_cmp);
        cuts.dedup_by(|x, y| (*x - *y).abs() <= 1e-15);
        let find = |list: &[Piece], mid: f64| -> Piece {
            *list
                .iter()
                .find(|p| mid <= p.end)
                .unwrap_or(&list[list.len() - 1])
        };
        let mut out = Vec::with_capacity(cuts.len());
        for w in cuts.windows(2) {
            let mid = 0.5 * (w[0] + w[1]);
            let pa = find(a, mid).restricted(w[0], w[1]);
            out.push(pa.plus(&find(b, mid))?);
        }
        Some(out)
    }

    /// The antiderivative that is 0 at the start and continuous across pieces.
    pub fn integrated(pieces: &[Piece]) -> Option<Vec<Piece>> {
        let mut out = Vec::with_capacity(pieces.len());
        let mut value = 0.0;
        for p in pieces {
            let q = p.integrated(value)?;
            value = q.eval(q.end)[0];
            out.push(q);
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))
    }

    fn sample() -> Piece {
        Piece::with_wave(
            0.5,
            2.0,
            &[1.0, -2.0, 0.5, 0.25, -0.125],
            Wave {
                omega: 3.0,
                sin: 0.7,
                cos: -0.2,
            },
        )
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let p = sample();
        let h = 1e-4;
        for x in [0.6, 1.0, 1.7] {
            let d = p.eval(x);
            for k in 0..4 {
                let fd = (p.eval(x + h)[k] - p.eval(x - h)[k]) / (2.0 * h);
                assert!((fd - d[k + 1]).abs() < 1e-5 * (1.0 + fd.abs()), "order {k}");
            }
        }
    }

    #[test]
    fn reparametrising_keeps_the_function() {
        let p = sample();
        // g(z) = f(3 - 0.5 z) on the mirrored range
        let g = shape::reparametrised(&[p], 3.0, -0.5);
        for z in [2.0, 3.0, 4.5] {
            assert!(close(shape::eval(&g, z)[0], p.eval(3.0 - 0.5 * z)[0]));
            assert!(close(
                shape::eval(&g, z)[1],
                -0.5 * p.eval(3.0 - 0.5 * z)[1]
            ));
        }
    }

    #[test]
    fn integral_differentiates_back() {
        let p = sample();
        let q = p.integrated(2.0).expect("room for one more degree");
        assert!(close(q.eval(p.start)[0], 2.0));
        for x in [0.7, 1.9] {
            assert!(close(q.eval(x)[1], p.eval(x)[0]));
        }
    }

    #[test]
    fn sum_splits_at_every_cut() {
        let a = [Piece::poly(0.0, 1.0, &[0.0, 1.0])];
        let b = [
            Piece::poly(0.0, 0.3, &[1.0]),
            Piece::poly(0.3, 1.0, &[0.0, 0.0, 1.0]),
        ];
        let s = shape::sum(&a, &b).expect("polynomials add");
        assert_eq!(s.len(), 2);
        assert!(close(shape::eval(&s, 0.2)[0], 1.2));
        assert!(close(shape::eval(&s, 0.5)[0], 0.5 + 0.04));
    }
}
