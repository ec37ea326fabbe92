//! Position tables (seed chapter 4.2): master/slave rows, equidistant or not, evaluated
//! linearly or as a cyclic continuation, with linear, 4-point or spline interpolation.

use super::error::{CamError, Field};
use super::Sample;
use hli::calls::cam::CamInterpolation;

/// Most rows a table may hold (the binary file counts rows in an unsigned short; tables sent
/// by a PLC may be larger).
pub const MAX_ROWS: usize = 10_000_000;

/// `MC_TableType` of a position table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableType {
    /// 10, `TABULARTYPE_EQUIDIST`: master positions rise in equal steps.
    Equidistant,
    /// 11, `TABULARTYPE_NONEQUIDIST`: master positions rise strictly.
    NonEquidistant,
}

/// A checked position table.
#[derive(Debug, Clone, PartialEq)]
pub struct PositionTable {
    master: Vec<f64>,
    slave: Vec<f64>,
    table_type: TableType,
    interpolation: CamInterpolation,
    periodic: bool,
    /// 1 / equidistant step (0 for non-equidistant tables).
    inverse_step: f64,
    /// Second derivatives at the rows for the spline.
    curvature: Vec<f64>,
}

/// Where the last evaluation found its row.
#[derive(Debug, Clone, Copy, Default)]
pub struct TableCursor {
    row: usize,
}

/// A table sample with the cycle counter of a periodic table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableSample {
    /// Position and derivatives per master unit.
    pub sample: Sample,
    /// Completed master periods (negative below the table; 0 for linear tables).
    pub cycle: i64,
}

impl PositionTable {
    /// Checks rows (`[master, slave]`) and builds the table.
    pub fn new(
        rows: &[[f64; 2]],
        table_type: TableType,
        interpolation: CamInterpolation,
        periodic: bool,
    ) -> Result<PositionTable, CamError> {
        if rows.is_empty() {
            return Err(CamError::NoData);
        }
        let min = match interpolation {
            CamInterpolation::Linear => 2,
            CamInterpolation::FourPoint | CamInterpolation::Spline => 4,
        };
        if rows.len() < min || rows.len() > MAX_ROWS {
            return Err(CamError::Rows {
                rows: rows.len(),
                min,
                max: MAX_ROWS,
            });
        }
        if interpolation == CamInterpolation::FourPoint && table_type != TableType::Equidistant {
            return Err(CamError::InterpolationNeedsEquidistant);
        }
        for (row, r) in rows.iter().enumerate() {
            for (value, field) in [(r[0], Field::Master), (r[1], Field::Slave)] {
                if !value.is_finite() {
                    return Err(CamError::RowNotFinite { row, field });
                }
            }
            // Both finite here (earlier rows were checked first).
            if row > 0 && r[0] <= rows[row - 1][0] {
                return Err(CamError::RowNotAscending {
                    row,
                    master: r[0],
                    previous: rows[row - 1][0],
                });
            }
        }
        let master: Vec<f64> = rows.iter().map(|r| r[0]).collect();
        let slave: Vec<f64> = rows.iter().map(|r| r[1]).collect();
        let n = master.len();
        let step = match table_type {
            TableType::NonEquidistant => 0.0,
            TableType::Equidistant => {
                let step = (master[n - 1] - master[0]) / (n - 1) as f64;
                for row in 1..n {
                    let expected = master[0] + step * row as f64;
                    if (master[row] - expected).abs() > equidistance_tolerance(step, expected) {
                        return Err(CamError::NotEquidistant {
                            row,
                            step: master[row] - master[row - 1],
                            expected: step,
                        });
                    }
                }
                step
            }
        };
        let mut table = PositionTable {
            master,
            slave,
            table_type,
            interpolation,
            periodic,
            inverse_step: if step > 0.0 { 1.0 / step } else { 0.0 },
            curvature: Vec::new(),
        };
        // Rows so close (or a range so wide) that a slope, the step or the period is not a
        // finite number cannot be interpolated.
        let degenerate = |row: usize| CamError::NotInterpolable { row };
        for (k, w) in table.master.windows(2).enumerate() {
            let slope = (table.slave[k + 1] - table.slave[k]) / (w[1] - w[0]);
            if !(slope.is_finite() && (w[1] - w[0]).is_finite()) {
                return Err(degenerate(k + 1));
            }
        }
        if !(table.period().is_finite() && table.stroke().is_finite()) {
            return Err(degenerate(n - 1));
        }
        if table_type == TableType::Equidistant && !table.inverse_step.is_finite() {
            return Err(degenerate(1));
        }
        if interpolation == CamInterpolation::Spline {
            table.curvature = if periodic {
                table.periodic_curvature()
            } else {
                table.clamped_curvature()
            };
            if let Some(row) = table.curvature.iter().position(|c| !c.is_finite()) {
                return Err(degenerate(row));
            }
        }
        Ok(table)
    }

    /// The rows.
    pub fn rows(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        self.master.iter().zip(&self.slave).map(|(m, s)| [*m, *s])
    }

    /// Row `i`, if there is one.
    pub fn row_at(&self, i: usize) -> Option<[f64; 2]> {
        Some([*self.master.get(i)?, *self.slave.get(i)?])
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.master.len()
    }

    /// Always false: a table has at least two rows.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Table type.
    pub fn table_type(&self) -> TableType {
        self.table_type
    }

    /// Interpolation.
    pub fn interpolation(&self) -> CamInterpolation {
        self.interpolation
    }

    /// Whether the table continues cyclically.
    pub fn periodic(&self) -> bool {
        self.periodic
    }

    /// First and last master position.
    pub fn master_range(&self) -> (f64, f64) {
        (self.master[0], self.master[self.master.len() - 1])
    }

    /// Master period (last minus first master position).
    pub fn period(&self) -> f64 {
        self.master[self.master.len() - 1] - self.master[0]
    }

    /// Slave stroke per master period (last minus first slave position).
    pub fn stroke(&self) -> f64 {
        self.slave[self.slave.len() - 1] - self.slave[0]
    }

    /// Slave position and derivatives at master `x`, with the cycle counter.
    #[inline]
    pub fn eval(&self, x: f64, cursor: &mut TableCursor) -> TableSample {
        let (first, last) = self.master_range();
        if self.periodic {
            let period = last - first;
            let mut cycle = ((x - first) / period).floor();
            let mut local = x - cycle * period;
            // Rounding may put `local` a hair outside the table.
            if local >= last {
                cycle += 1.0;
                local -= period;
            } else if local < first {
                cycle -= 1.0;
                local += period;
            }
            let mut s = self.eval_inside(local, cursor);
            s.position += cycle * self.stroke();
            return TableSample {
                sample: s,
                cycle: cycle as i64,
            };
        }
        let sample = if x < first {
            Sample::at_rest(self.slave[0])
        } else if x > last {
            Sample::at_rest(self.slave[self.slave.len() - 1])
        } else {
            self.eval_inside(x, cursor)
        };
        TableSample { sample, cycle: 0 }
    }

    fn eval_inside(&self, x: f64, cursor: &mut TableCursor) -> Sample {
        let k = self.interval(x, cursor);
        cursor.row = k;
        self.eval_on(k, x)
    }

    /// The interpolant of the interval that holds `inside`, evaluated at `x` (the formula
    /// of one interval, also at its ends; characteristic values use it).
    pub(crate) fn eval_interval_of(&self, inside: f64, x: f64, cursor: &mut TableCursor) -> Sample {
        let k = self.interval(inside, cursor);
        self.eval_on(k, x)
    }

    fn eval_on(&self, k: usize, x: f64) -> Sample {
        match self.interpolation {
            CamInterpolation::Linear => {
                let h = self.master[k + 1] - self.master[k];
                let slope = (self.slave[k + 1] - self.slave[k]) / h;
                Sample {
                    position: self.slave[k] + slope * (x - self.master[k]),
                    velocity: slope,
                    acceleration: 0.0,
                    jerk: 0.0,
                }
            }
            CamInterpolation::FourPoint => self.four_point(k, x),
            CamInterpolation::Spline => self.spline(k, x),
        }
    }

    /// The interval `k` (rows k, k+1) that holds `x`: `T[k] <= x < T[k+1]` for equidistant
    /// tables, `T[k] < x <= T[k+1]` for the others (the seed's conventions).
    #[inline]
    fn interval(&self, x: f64, cursor: &TableCursor) -> usize {
        let n = self.master.len();
        if self.table_type == TableType::Equidistant {
            // Truncation is floor for the non-negative offsets inside the table; a row the
            // multiplication rounds below belongs to the interval above it.
            let k = (x - self.master[0]) * self.inverse_step;
            let k = if k > 0.0 { (k as usize).min(n - 2) } else { 0 };
            return if k + 2 < n && x >= self.master[k + 1] {
                k + 1
            } else if k > 0 && x < self.master[k] {
                k - 1
            } else {
                k
            };
        }
        let m = &self.master;
        let fits = |k: usize| (m[k] < x || k == 0) && x <= m[k + 1];
        let mut k = cursor.row.min(n - 2);
        // Walk a few rows from the last one (a sweeping master); re-seed by bisection.
        for _ in 0..4 {
            if fits(k) {
                return k;
            }
            if x <= m[k] && k > 0 {
                k -= 1;
            } else if x > m[k + 1] && k + 2 < n {
                k += 1;
            } else {
                break;
            }
        }
        if fits(k) {
            return k;
        }
        // Gallop from the cursor (cost grows with the log of the distance), then bisect.
        let (mut lo, mut hi) = if x > m[k + 1] {
            let mut step = 1;
            while k + step + 1 < n - 1 && m[k + step + 1] < x {
                step *= 2;
            }
            (k + step / 2, (k + step + 1).min(n - 1))
        } else {
            let mut step = 1;
            while step < k && m[k - step] >= x {
                step *= 2;
            }
            (k.saturating_sub(step), k)
        };
        // Invariant: the wanted interval lies within rows lo..=hi.
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if m[mid] < x {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo.min(n - 2)
    }

    /// Row `i` (may lie outside the table for a periodic one: continued by period and stroke).
    fn row(&self, i: isize) -> (f64, f64) {
        let n = self.master.len() as isize;
        if (0..n).contains(&i) {
            return (self.master[i as usize], self.slave[i as usize]);
        }
        // Row n-1 and row 0 of the next period coincide.
        let cycles = if i < 0 {
            -((-i + n - 2) / (n - 1))
        } else {
            i / (n - 1)
        };
        let j = (i - cycles * (n - 1)) as usize;
        (
            self.master[j] + cycles as f64 * self.period(),
            self.slave[j] + cycles as f64 * self.stroke(),
        )
    }

    /// The cubic through rows k-1..=k+2 (shifted inward at the ends of a linear table,
    /// continued by period and stroke for a cyclic one), in closed form for equal steps.
    fn four_point(&self, k: usize, x: f64) -> Sample {
        let n = self.master.len();
        let first = if self.periodic {
            k as isize - 1
        } else {
            (k as isize - 1).clamp(0, n as isize - 4)
        };
        let y: [f64; 4] = if first >= 0 && first as usize + 3 < n {
            let f = first as usize;
            [
                self.slave[f],
                self.slave[f + 1],
                self.slave[f + 2],
                self.slave[f + 3],
            ]
        } else {
            std::array::from_fn(|i| self.row(first + i as isize).1)
        };
        // t = 0 at row first+1; the cubic through t = -1, 0, 1, 2.
        let origin = self.row(first + 1).0;
        let t = (x - origin) * self.inverse_step;
        let a1 = -y[0] / 3.0 - y[1] / 2.0 + y[2] - y[3] / 6.0;
        let a2 = (y[0] + y[2]) / 2.0 - y[1];
        let a3 = (y[3] - y[0]) / 6.0 + (y[1] - y[2]) / 2.0;
        let k1 = self.inverse_step;
        Sample {
            position: y[1] + t * (a1 + t * (a2 + t * a3)),
            velocity: (a1 + t * (2.0 * a2 + 3.0 * t * a3)) * k1,
            acceleration: (2.0 * a2 + 6.0 * t * a3) * k1 * k1,
            jerk: 6.0 * a3 * k1 * k1 * k1,
        }
    }

    fn spline(&self, k: usize, x: f64) -> Sample {
        let (x0, x1) = (self.master[k], self.master[k + 1]);
        let (y0, y1) = (self.slave[k], self.slave[k + 1]);
        let (m0, m1) = (self.curvature[k], self.curvature[k + 1]);
        let h = x1 - x0;
        let (a, b) = (x1 - x, x - x0);
        Sample {
            position: (m0 * a * a * a + m1 * b * b * b) / (6.0 * h)
                + (y0 / h - m0 * h / 6.0) * a
                + (y1 / h - m1 * h / 6.0) * b,
            velocity: (-m0 * a * a + m1 * b * b) / (2.0 * h) + (y1 - y0) / h - (m1 - m0) * h / 6.0,
            acceleration: (m0 * a + m1 * b) / h,
            jerk: (m1 - m0) / h,
        }
    }

    /// Second derivatives of the spline with end slopes taken from the cubic through the
    /// first (last) four rows: exact for data from a cubic.
    fn clamped_curvature(&self) -> Vec<f64> {
        let n = self.master.len();
        let row = |i: usize| (self.master[i], self.slave[i]);
        let start_slope = lagrange4(&[row(0), row(1), row(2), row(3)], self.master[0]).velocity;
        let end_slope = lagrange4(
            &[row(n - 4), row(n - 3), row(n - 2), row(n - 1)],
            self.master[n - 1],
        )
        .velocity;
        let h: Vec<f64> = self.master.windows(2).map(|w| w[1] - w[0]).collect();
        let d: Vec<f64> = (0..n - 1)
            .map(|i| (self.slave[i + 1] - self.slave[i]) / h[i])
            .collect();
        let mut lower = vec![0.0; n];
        let mut diag = vec![0.0; n];
        let mut upper = vec![0.0; n];
        let mut rhs = vec![0.0; n];
        diag[0] = 2.0 * h[0];
        upper[0] = h[0];
        rhs[0] = 6.0 * (d[0] - start_slope);
        for i in 1..n - 1 {
            lower[i] = h[i - 1];
            diag[i] = 2.0 * (h[i - 1] + h[i]);
            upper[i] = h[i];
            rhs[i] = 6.0 * (d[i] - d[i - 1]);
        }
        lower[n - 1] = h[n - 2];
        diag[n - 1] = 2.0 * h[n - 2];
        rhs[n - 1] = 6.0 * (end_slope - d[n - 2]);
        thomas(&lower, &diag, &upper, &rhs)
    }

    /// Second derivatives of the periodic spline: slope and curvature agree at both ends
    /// (the slave data continued by the stroke).
    fn periodic_curvature(&self) -> Vec<f64> {
        let n = self.master.len();
        let m = n - 1; // unknowns: rows 0..n-2, row n-1 repeats row 0
        let h: Vec<f64> = self.master.windows(2).map(|w| w[1] - w[0]).collect();
        let d: Vec<f64> = (0..n - 1)
            .map(|i| (self.slave[i + 1] - self.slave[i]) / h[i])
            .collect();
        let mut lower = vec![0.0; m];
        let mut diag = vec![0.0; m];
        let mut upper = vec![0.0; m];
        let mut rhs = vec![0.0; m];
        for i in 0..m {
            let prev = (i + m - 1) % m;
            lower[i] = h[prev];
            diag[i] = 2.0 * (h[prev] + h[i]);
            upper[i] = h[i];
            rhs[i] = 6.0 * (d[i] - d[prev]);
        }
        let mut c = cyclic_thomas(&lower, &diag, &upper, &rhs);
        c.push(c[0]);
        c
    }
}

/// How far an equidistant table's master position may lie from `first + row * step`: a
/// billionth of the step, plus a few rounding steps of the position itself.
pub(crate) fn equidistance_tolerance(step: f64, expected: f64) -> f64 {
    1e-9 * step + 4.0 * f64::EPSILON * expected.abs()
}

/// The cubic through four points and its derivatives at `x`.
fn lagrange4(p: &[(f64, f64); 4], x: f64) -> Sample {
    // Newton's divided differences, then the polynomial and its derivatives by Horner.
    let xs = [p[0].0, p[1].0, p[2].0, p[3].0];
    let mut c = [p[0].1, p[1].1, p[2].1, p[3].1];
    for level in 1..4 {
        for i in (level..4).rev() {
            c[i] = (c[i] - c[i - 1]) / (xs[i] - xs[i - level]);
        }
    }
    // p(x) = c0 + (x-x0)(c1 + (x-x1)(c2 + (x-x2) c3))
    let mut d = [c[3], 0.0, 0.0, 0.0];
    for i in (0..3).rev() {
        let t = x - xs[i];
        d[3] = d[3] * t + d[2];
        d[2] = d[2] * t + d[1];
        d[1] = d[1] * t + d[0];
        d[0] = d[0] * t + c[i];
    }
    Sample {
        position: d[0],
        velocity: d[1],
        acceleration: 2.0 * d[2],
        jerk: 6.0 * d[3],
    }
}

/// Tridiagonal solve (Thomas algorithm).
fn thomas(lower: &[f64], diag: &[f64], upper: &[f64], rhs: &[f64]) -> Vec<f64> {
    let n = diag.len();
    let mut c = vec![0.0; n];
    let mut d = vec![0.0; n];
    c[0] = upper[0] / diag[0];
    d[0] = rhs[0] / diag[0];
    for i in 1..n {
        let m = diag[i] - lower[i] * c[i - 1];
        c[i] = upper[i] / m;
        d[i] = (rhs[i] - lower[i] * d[i - 1]) / m;
    }
    let mut x = vec![0.0; n];
    x[n - 1] = d[n - 1];
    for i in (0..n - 1).rev() {
        x[i] = d[i] - c[i] * x[i + 1];
    }
    x
}

/// Cyclic tridiagonal solve (Sherman-Morrison on top of Thomas); `lower[0]` couples row 0 to
/// the last unknown, `upper[n-1]` the last row to the first.
fn cyclic_thomas(lower: &[f64], diag: &[f64], upper: &[f64], rhs: &[f64]) -> Vec<f64> {
    let n = diag.len();
    let (alpha, beta) = (upper[n - 1], lower[0]);
    let gamma = -diag[0];
    let mut d = diag.to_vec();
    d[0] -= gamma;
    d[n - 1] -= alpha * beta / gamma;
    let x = thomas(lower, &d, upper, rhs);
    let mut u = vec![0.0; n];
    u[0] = gamma;
    u[n - 1] = alpha;
    let z = thomas(lower, &d, upper, &u);
    let factor = (x[0] + beta * x[n - 1] / gamma) / (1.0 + z[0] + beta * z[n - 1] / gamma);
    x.iter().zip(&z).map(|(xi, zi)| xi - factor * zi).collect()
}
