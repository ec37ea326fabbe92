//! How the machine tick grows with the machine: channels (1..12 tracking robots), single
//! axes (1..32, all moving), cam slaves (1..16 on one conveyor, each on its own 1,000-row
//! table), the size of a cam slave's table (10..10^5 rows), the depth of a running 6-axis
//! FIFO group (10..10^5 queued rows) and flying-saw couplings (1..8 slaves in their
//! synchronous phase).
//!
//! Each figure is the median over interleaved repeats (every point of one dimension in turn,
//! so a slow phase of the VM hits all of them alike) of the whole machine tick, hot (no sleep
//! between ticks). The expected shape: linear in channels, axes, slaves and couplings (a
//! straight line, cost = per unit x count + fixed part, explains >= 95 % of the variance,
//! R² >= 0.95, and the last step costs at most 1.35 times the line's slope per unit: no
//! growth faster at the top), flat in table size and FIFO depth (a line through the cost
//! over log10 of the size changes by at most 5 % of the mean cost per decade, either way).
//! The cam slaves' tables are swept at 360 rows per second (the 10^5-row table in part).
//!
//! Writes `scaling.md` (the table) and `scaling.svg` (one panel per dimension) into
//! `$CNC_BENCH_OUT` (default `out/bench` in the workspace).
//! Run: `cargo bench -p cnc-app --bench scaling`.

mod machines;

use bench_kit::{median, scaled, smoke};
use machines::{axes, cam_slaves, cam_table, channels, fifo_depth, saw, Tick};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

const TICKS: usize = 4_000;
const REPEATS: usize = 9;

/// What a dimension's cost should look like.
#[derive(Clone, Copy, PartialEq)]
enum Shape {
    Linear,
    Flat,
}

/// One dimension: its points (x, ns per tick) once measured.
struct Dimension {
    name: &'static str,
    x_label: &'static str,
    shape: Shape,
    xs: Vec<usize>,
    build: fn(usize) -> Tick,
    ns: Vec<f64>,
}

impl Dimension {
    fn new(
        name: &'static str,
        x_label: &'static str,
        shape: Shape,
        xs: &[usize],
        build: fn(usize) -> Tick,
    ) -> Dimension {
        Dimension {
            name,
            x_label,
            shape,
            xs: xs.to_vec(),
            build,
            ns: Vec::new(),
        }
    }

    /// Median ns per tick of every point, the repeats interleaved across the points.
    fn measure(&mut self) {
        let mut ticks: Vec<Tick> = self.xs.iter().map(|&x| (self.build)(x)).collect();
        let mut samples = vec![Vec::new(); ticks.len()];
        for _ in 0..scaled(REPEATS) {
            for (k, tick) in ticks.iter_mut().enumerate() {
                samples[k].push(time(tick));
            }
        }
        self.ns = samples.into_iter().map(median).collect();
    }

    fn points(&self) -> Vec<(f64, f64)> {
        let xs = self.xs.iter().map(|&x| x as f64);
        xs.zip(self.ns.iter().copied()).collect()
    }

    /// The verdict on the shape, with its figure.
    fn verdict(&self) -> (bool, String) {
        match self.shape {
            Shape::Flat => {
                // The cost over log10(size): its change per decade, relative to its mean,
                // either way.
                let logs: Vec<(f64, f64)> =
                    self.points().iter().map(|&(x, y)| (x.log10(), y)).collect();
                let (per_decade, _, _) = fit(&logs);
                let mean = self.ns.iter().sum::<f64>() / self.ns.len() as f64;
                let r = per_decade / mean;
                let text = format!(
                    "{per_decade:+.0} ns per decade of size = {:+.1} % of its mean {mean:.0} ns (within 5 %)",
                    r * 100.0
                );
                (r.abs() <= 0.05, text)
            }
            Shape::Linear => {
                let points = self.points();
                let (slope, fixed, r2) = fit(&points);
                // Not growing faster at the top: the last step's cost per unit against the
                // line's (x² over these sizes gives 1.45).
                let [.., (x0, y0), (x1, y1)] = points[..] else {
                    return (false, "fewer than two sizes".into());
                };
                let top = (y1 - y0) / (x1 - x0) / slope;
                let text = format!(
                    "{slope:.0} ns per unit + {fixed:.0} ns, R² {r2:.3} (>= 0.95), last step / line {top:.2} (<= 1.35)"
                );
                (r2 >= 0.95 && top <= 1.35, text)
            }
        }
    }
}

/// Least-squares line through `p`: (slope, intercept, R²).
fn fit(p: &[(f64, f64)]) -> (f64, f64, f64) {
    let n = p.len() as f64;
    let mx = p.iter().map(|q| q.0).sum::<f64>() / n;
    let my = p.iter().map(|q| q.1).sum::<f64>() / n;
    let sxy: f64 = p.iter().map(|q| (q.0 - mx) * (q.1 - my)).sum();
    let sxx: f64 = p.iter().map(|q| (q.0 - mx).powi(2)).sum();
    let syy: f64 = p.iter().map(|q| (q.1 - my).powi(2)).sum();
    let slope = sxy / sxx;
    let r2 = if syy > 0.0 {
        sxy * sxy / (sxx * syy)
    } else {
        1.0
    };
    (slope, my - slope * mx, r2)
}

/// ns per tick over one sample of TICKS ticks (the tick's own untimed upkeep excluded).
fn time(tick: &mut Tick) -> f64 {
    let mut total = 0u128;
    let mut done = 0;
    while done < scaled(TICKS) {
        let batch = tick.batch.min(scaled(TICKS) - done);
        let t0 = Instant::now();
        for _ in 0..batch {
            tick.run.tick();
        }
        total += t0.elapsed().as_nanos();
        tick.run.upkeep();
        done += batch;
    }
    total as f64 / done as f64
}

fn out_dir() -> PathBuf {
    match std::env::var_os("CNC_BENCH_OUT") {
        Some(d) => PathBuf::from(d),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../out/bench"),
    }
}

fn main() {
    let mut dims = [
        Dimension::new(
            "channels (tracking robots)",
            "channels",
            Shape::Linear,
            &[1, 2, 4, 8, 12],
            channels,
        ),
        Dimension::new(
            "single axes, all moving",
            "axes",
            Shape::Linear,
            &[1, 2, 4, 8, 16, 32],
            axes,
        ),
        Dimension::new(
            "cam slaves (1,000-row tables)",
            "cam slaves",
            Shape::Linear,
            &[1, 2, 4, 8, 16],
            cam_slaves,
        ),
        Dimension::new(
            "one cam slave's table",
            "table rows",
            Shape::Flat,
            &[10, 100, 1_000, 10_000, 100_000],
            cam_table,
        ),
        Dimension::new(
            "6-axis FIFO group's queue",
            "queued rows",
            Shape::Flat,
            &[10, 100, 1_000, 10_000, 100_000],
            fifo_depth,
        ),
        Dimension::new(
            "flying-saw couplings (synchronous)",
            "saw slaves",
            Shape::Linear,
            &[1, 2, 4, 8],
            saw,
        ),
    ];
    for d in dims.iter_mut() {
        d.measure();
    }
    let report = table(&dims);
    print!("{report}");
    let dir = out_dir();
    let written = std::fs::create_dir_all(&dir)
        .and_then(|()| std::fs::write(dir.join("scaling.md"), &report))
        .map_err(|e| e.to_string())
        .and_then(|()| plot(&dims, &dir.join("scaling.svg")));
    match written {
        Ok(()) => println!("written: {0}/scaling.md, {0}/scaling.svg", dir.display()),
        Err(e) => println!("not written ({}): {e}", dir.display()),
    }
}

/// The markdown table and the verdict lines.
fn table(dims: &[Dimension]) -> String {
    let mut s = String::new();
    let (runs, ticks) = (scaled(REPEATS), scaled(TICKS));
    let _ = writeln!(
        s,
        "machine tick, hot, median of {runs} interleaved runs of {ticks} ticks per point"
    );
    let _ = writeln!(s);
    let _ = writeln!(s, "| dimension | size | ns/tick | ns/tick per unit |");
    let _ = writeln!(s, "| --- | ---: | ---: | ---: |");
    for d in dims {
        for (x, ns) in d.xs.iter().zip(&d.ns) {
            let per = if d.shape == Shape::Linear {
                format!("{:.0}", ns / *x as f64)
            } else {
                "-".into()
            };
            let _ = writeln!(s, "| {} | {x} | {ns:.0} | {per} |", d.name);
        }
    }
    let _ = writeln!(s);
    for d in dims {
        let (ok, text) = d.verdict();
        let shape = if d.shape == Shape::Linear {
            "linear"
        } else {
            "flat"
        };
        let met = match (smoke(), ok) {
            (true, _) => "smoke run, no figure meant",
            (false, true) => "met",
            (false, false) => "MISSED",
        };
        let _ = writeln!(s, "TARGET | {} {shape} | {text} | {met}", d.name);
    }
    s
}

/// One panel per dimension, ns per tick over its size (over log10 of it for the flat ones).
fn plot(dims: &[Dimension], out: &std::path::Path) -> Result<(), String> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let root = SVGBackend::new(out, (1200, 760)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let panels = root.split_evenly((2, 3));
    for (d, area) in dims.iter().zip(panels.iter()) {
        let flat = d.shape == Shape::Flat;
        let x_of = |x: f64| if flat { x.log10() } else { x };
        let points: Vec<(f64, f64)> = d.points().iter().map(|&(x, y)| (x_of(x), y)).collect();
        let top = d.ns.iter().copied().fold(0.0, f64::max) * 1.15;
        let (x0, x1) = (points[0].0, points[points.len() - 1].0);
        let x_range = if flat { x0..x1 } else { 0.0..x1 * 1.05 };
        let x_desc = if flat {
            format!("log10 of {}", d.x_label)
        } else {
            d.x_label.to_string()
        };
        let mut chart = ChartBuilder::on(area)
            .caption(d.name, ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(x_range, 0.0..top)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .max_light_lines(0)
            .x_desc(x_desc)
            .y_desc("ns per tick")
            .draw()
            .map_err(|e| err(&e))?;
        let line = LineSeries::new(points, &BLUE).point_size(3);
        chart.draw_series(line).map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))
}
