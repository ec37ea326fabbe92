//! `cnc plot`: SVG line plots of CSV traces (plotters' SVG backend), shared by the cam and saw
//! tools and the demo.
//!
//! A figure is a stack of panels, one per unit: signals that share a unit share a panel, with
//! a legend naming each curve and the unit on the y axis. Trace columns named by an ST path
//! hold raw HLI values (0.1 um, 0.0001 degree, ...); [`Unit::infer`] turns them into mm,
//! degree, mm/s from the leaf's name, and `PATH=UNIT` in `--signals` overrides it (a rotary
//! axis's position is `=deg`). Long traces are thinned to the minimum and maximum per pixel
//! column, so peaks stay in the picture; the y range covers every drawn value with a margin,
//! so no curve is clipped.

use std::path::{Path, PathBuf};

/// Arguments of `cnc plot`.
#[derive(Debug, Clone, clap::Args)]
pub struct PlotArgs {
    /// Trace CSV (a header line, then numbers; `tick` and `time` columns are the x axis).
    pub trace: PathBuf,
    /// Columns to draw, comma-separated, each optionally `NAME=UNIT` (mm, deg, mm/s, deg/s,
    /// mm/s2, %, or `raw`). Default: every column but tick and time.
    #[arg(long, value_delimiter = ',')]
    pub signals: Vec<String>,
    /// Output SVG.
    #[arg(short = 'o', long, default_value = "plot.svg")]
    pub out: PathBuf,
    /// Title over the figure (default: the trace's file name).
    #[arg(long)]
    pub title: Option<String>,
    /// Column for the x axis (default: `time` if present, else the first column).
    #[arg(long)]
    pub x: Option<String>,
}

/// Why a plot could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The trace could not be read.
    #[error("{file}: {message}")]
    Read {
        /// The file.
        file: String,
        /// The OS error.
        message: String,
    },
    /// A cell is not a number.
    #[error("{file}:{line}:{column}: `{cell}` is not a number")]
    NotANumber {
        /// The file.
        file: String,
        /// Line, 1-based.
        line: usize,
        /// Column, 1-based.
        column: usize,
        /// The cell.
        cell: String,
    },
    /// A row has fewer or more cells than the header.
    #[error("{file}:{line}: {found} cells, the header has {expected}")]
    Ragged {
        /// The file.
        file: String,
        /// Line, 1-based.
        line: usize,
        /// Cells found.
        found: usize,
        /// Cells in the header.
        expected: usize,
    },
    /// A requested column is not in the trace.
    #[error("no column `{0}` in the trace (its columns: {1})")]
    UnknownColumn(String, String),
    /// A unit name that is not known.
    #[error("unknown unit `{0}` (known: mm, deg, mm/s, deg/s, mm/s2, %, raw)")]
    UnknownUnit(String),
    /// Nothing to draw.
    #[error("the trace has no rows")]
    Empty,
    /// The SVG could not be written.
    #[error("{file}: {message}")]
    Draw {
        /// The output file.
        file: String,
        /// What plotters reported.
        message: String,
    },
}

/// The unit a curve is drawn in: its label and the factor from the column's values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    /// Axis label, e.g. `mm`.
    pub label: &'static str,
    /// Drawn value = column value x `scale`.
    pub scale: f64,
}

impl Unit {
    /// The column's own values, unscaled.
    pub const RAW: Unit = Unit {
        label: "value",
        scale: 1.0,
    };

    /// A unit by name; the HLI units are 0.1 um, 0.0001 degree, 1 um/s^2 and 0.1 %.
    pub fn named(name: &str) -> Result<Unit, PlotError> {
        let (label, scale) = match name {
            "mm" => ("mm", 1e-4),
            "deg" => ("degree", 1e-4),
            "mm/s" => ("mm/s", 1e-4),
            "deg/s" => ("degree/s", 1e-4),
            "mm/s2" => ("mm/s²", 1e-3),
            "%" => ("%", 0.1),
            "raw" => return Ok(Unit::RAW),
            other => return Err(PlotError::UnknownUnit(other.to_string())),
        };
        Ok(Unit { label, scale })
    }

    /// The unit of a column named by an ST path, from the leaf's name; other columns are
    /// drawn as they are.
    pub fn infer(column: &str) -> Unit {
        let Some((_, leaf)) = column.rsplit_once('^') else {
            return Unit::RAW;
        };
        let last = leaf.rsplit('.').next().unwrap_or(leaf);
        let name = |n: &str| Unit::named(n).unwrap_or(Unit::RAW);
        if last.contains("state") || last.contains("id") || last.contains("flags") {
            Unit::RAW
        } else if last.contains("velocity") {
            name("mm/s")
        } else if last.contains("acceleration") {
            name("mm/s2")
        } else if leaf.contains("rotation") {
            name("deg")
        } else if last.contains("torque") {
            name("%")
        } else if last.contains("position")
            || last.contains("error")
            || leaf.contains("translation")
        {
            name("mm")
        } else {
            Unit::RAW
        }
    }
}

/// A CSV trace in memory: its column names and its values, row by row.
#[derive(Debug, Clone)]
pub struct Table {
    /// Column names from the header.
    pub columns: Vec<String>,
    /// `rows x columns` values.
    pub values: Vec<f64>,
}

impl Table {
    /// Reads a CSV trace.
    pub fn read(path: &Path) -> Result<Table, PlotError> {
        let text = std::fs::read_to_string(path).map_err(|e| PlotError::Read {
            file: path.display().to_string(),
            message: e.to_string(),
        })?;
        Table::parse(&path.display().to_string(), &text)
    }

    /// Parses CSV text (`file` names it in errors).
    pub fn parse(file: &str, text: &str) -> Result<Table, PlotError> {
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let Some((_, header)) = lines.next() else {
            return Err(PlotError::Empty);
        };
        let columns: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
        let mut values = Vec::new();
        for (index, line) in lines {
            let cells: Vec<&str> = line.split(',').collect();
            if cells.len() != columns.len() {
                return Err(PlotError::Ragged {
                    file: file.to_string(),
                    line: index + 1,
                    found: cells.len(),
                    expected: columns.len(),
                });
            }
            for (k, cell) in cells.iter().enumerate() {
                let v: f64 = cell.trim().parse().map_err(|_| PlotError::NotANumber {
                    file: file.to_string(),
                    line: index + 1,
                    column: k + 1,
                    cell: cell.trim().to_string(),
                })?;
                values.push(v);
            }
        }
        if values.is_empty() {
            return Err(PlotError::Empty);
        }
        Ok(Table { columns, values })
    }

    /// Rows.
    pub fn rows(&self) -> usize {
        self.values.len() / self.columns.len().max(1)
    }

    /// The values of column `name`.
    pub fn column(&self, name: &str) -> Result<Vec<f64>, PlotError> {
        let k =
            self.columns.iter().position(|c| c == name).ok_or_else(|| {
                PlotError::UnknownColumn(name.to_string(), self.columns.join(", "))
            })?;
        Ok(self
            .values
            .iter()
            .skip(k)
            .step_by(self.columns.len())
            .copied()
            .collect())
    }
}

/// One curve.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Unit (panels group curves by its label).
    pub unit: Unit,
    /// (x, value in the column's units) points.
    pub points: Vec<(f64, f64)>,
}

/// A figure: curves over one x axis, stacked in one panel per unit.
#[derive(Debug, Clone)]
pub struct Figure {
    /// Caption over the figure.
    pub title: String,
    /// X axis label with its unit.
    pub x_label: String,
    /// The curves.
    pub series: Vec<Series>,
}

/// Line colours, dark enough on white and told apart by colour-blind readers (Tableau 10).
const PALETTE: [plotters::style::RGBColor; 8] = [
    plotters::style::RGBColor(31, 119, 180),
    plotters::style::RGBColor(214, 39, 40),
    plotters::style::RGBColor(44, 160, 44),
    plotters::style::RGBColor(255, 127, 14),
    plotters::style::RGBColor(148, 103, 189),
    plotters::style::RGBColor(140, 86, 75),
    plotters::style::RGBColor(227, 119, 194),
    plotters::style::RGBColor(23, 190, 207),
];

/// Pixel columns a curve is thinned to (min and max each).
const WIDTH: u32 = 1100;

impl Figure {
    /// The figure of `args.signals` over `args.x` in `table`.
    pub fn from_table(table: &Table, args: &PlotArgs, title: &str) -> Result<Figure, PlotError> {
        let x_name = match &args.x {
            Some(x) => x.clone(),
            None if table.columns.iter().any(|c| c == "time") => "time".into(),
            None => table.columns[0].clone(),
        };
        let xs = table.column(&x_name)?;
        let requested: Vec<String> = if args.signals.is_empty() {
            table
                .columns
                .iter()
                .filter(|c| *c != "tick" && *c != "time" && **c != x_name)
                .cloned()
                .collect()
        } else {
            args.signals.clone()
        };
        let mut series = Vec::new();
        for spec in requested {
            let (name, unit) = match spec.split_once('=') {
                Some((name, unit)) => (name.to_string(), Unit::named(unit)?),
                None => (spec.clone(), Unit::infer(&spec)),
            };
            let ys = table.column(&name)?;
            series.push(Series {
                name,
                unit,
                points: xs.iter().copied().zip(ys).collect(),
            });
        }
        let x_label = match x_name.as_str() {
            "time" => "time [s]".to_string(),
            "tick" => "tick".to_string(),
            other => other.to_string(),
        };
        Ok(Figure {
            title: title.to_string(),
            x_label,
            series,
        })
    }

    /// Draws the figure as SVG into `out` (creating its folder).
    pub fn save_svg(&self, out: &Path) -> Result<(), PlotError> {
        use plotters::prelude::*;
        let draw = |e: &dyn std::fmt::Display| PlotError::Draw {
            file: out.display().to_string(),
            message: e.to_string(),
        };
        if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| draw(&e))?;
        }
        let mut units: Vec<&'static str> = Vec::new();
        for s in &self.series {
            if !units.contains(&s.unit.label) {
                units.push(s.unit.label);
            }
        }
        if units.is_empty() {
            return Err(PlotError::Empty);
        }
        let (x0, x1) = range(
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.0)),
        )
        .ok_or(PlotError::Empty)?;
        let height = 60 + 300 * units.len() as u32;
        let root = SVGBackend::new(out, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw(&e))?;
        let root = root
            .titled(&self.title, ("sans-serif", 20))
            .map_err(|e| draw(&e))?;
        let panels = root.split_evenly((units.len(), 1));
        let mut colour = 0;
        for (panel, unit) in panels.iter().zip(&units) {
            let curves: Vec<(&Series, Vec<(f64, f64)>)> = self
                .series
                .iter()
                .filter(|s| s.unit.label == *unit)
                .map(|s| (s, thin(&s.points, s.unit.scale, x0, x1)))
                .collect();
            let (y0, y1) =
                range(curves.iter().flat_map(|(_, p)| p.iter().map(|q| q.1))).unwrap_or((0.0, 1.0));
            // Head room above the curves for the legend, one line per curve, so it covers
            // none of them.
            let span = (y1 - y0).max(y1.abs().max(1.0) * 1e-6);
            let bottom = y0 - 0.06 * span;
            let top = y1 + span * (0.08 + 0.09 * curves.len() as f64);
            let mut chart = ChartBuilder::on(panel)
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(80)
                .build_cartesian_2d(x0..x1.max(x0 + 1e-9), bottom..top)
                .map_err(|e| draw(&e))?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(*unit)
                .draw()
                .map_err(|e| draw(&e))?;
            for (s, points) in curves {
                let c = PALETTE[colour % PALETTE.len()];
                colour += 1;
                chart
                    .draw_series(LineSeries::new(points, c.stroke_width(2)))
                    .map_err(|e| draw(&e))?
                    .label(s.name.clone())
                    .legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 18, y)], c.stroke_width(3))
                    });
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()
                .map_err(|e| draw(&e))?;
        }
        root.present().map_err(|e| draw(&e))
    }
}

/// The finite range of `values`.
fn range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// Scales `points` and keeps, per pixel column, the first, lowest and highest value (in x
/// order), so the drawn curve has every extreme of the full one. Non-finite values are left
/// out.
pub fn thin(points: &[(f64, f64)], scale: f64, x0: f64, x1: f64) -> Vec<(f64, f64)> {
    let finite = points
        .iter()
        .map(|&(x, y)| (x, y * scale))
        .filter(|(x, y)| x.is_finite() && y.is_finite());
    if points.len() <= 3 * WIDTH as usize {
        return finite.collect();
    }
    let span = (x1 - x0).max(f64::MIN_POSITIVE);
    let bucket = |x: f64| (((x - x0) / span) * f64::from(WIDTH)) as i64;
    let mut out = Vec::with_capacity(3 * WIDTH as usize + 3);
    let mut group: Vec<(f64, f64)> = Vec::new();
    let flush = |group: &mut Vec<(f64, f64)>, out: &mut Vec<(f64, f64)>| {
        if group.is_empty() {
            return;
        }
        let first = group[0];
        let last = group[group.len() - 1];
        let lo = group
            .iter()
            .copied()
            .fold(first, |a, p| if p.1 < a.1 { p } else { a });
        let hi = group
            .iter()
            .copied()
            .fold(first, |a, p| if p.1 > a.1 { p } else { a });
        let mut keep = [first, lo, hi, last];
        keep.sort_by(|a, b| a.0.total_cmp(&b.0));
        for p in keep {
            if out.last() != Some(&p) {
                out.push(p);
            }
        }
        group.clear();
    };
    let mut current = None;
    for p in finite {
        let b = bucket(p.0);
        if current != Some(b) {
            flush(&mut group, &mut out);
            current = Some(b);
        }
        group.push(p);
    }
    flush(&mut group, &mut out);
    out
}

/// `cnc plot`.
pub fn main(args: PlotArgs) -> std::process::ExitCode {
    let result = Table::read(&args.trace).and_then(|table| {
        let title = args.title.clone().unwrap_or_else(|| {
            args.trace
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default()
        });
        let figure = Figure::from_table(&table, &args, &title)?;
        figure.save_svg(&args.out)?;
        Ok(table.rows())
    });
    match result {
        Ok(rows) => {
            println!("{}: {rows} rows drawn", args.out.display());
            std::process::ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("cnc plot: {e}");
            std::process::ExitCode::from(2)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_follow_the_leaf_name() {
        assert_eq!(
            Unit::infer("gpAx[1]^lr_state.command_position_acs_r").label,
            "mm"
        );
        assert_eq!(
            Unit::infer("gpAx[1]^lr_state.command_velocity_r").label,
            "mm/s"
        );
        assert_eq!(Unit::infer("gpAx[1]^lr_state.axis_state_r"), Unit::RAW);
        assert_eq!(
            Unit::infer("gpCh[0]^channel_mc_control.dyn_cs.command_w.rotation[2]").label,
            "degree"
        );
        assert_eq!(Unit::infer("slave_position"), Unit::RAW);
        assert!(Unit::named("furlong").is_err());
    }

    #[test]
    fn thinning_keeps_every_extreme() {
        let points: Vec<(f64, f64)> = (0..100_000)
            .map(|i| {
                (
                    i as f64,
                    if i == 54_321 {
                        9.0
                    } else {
                        (i as f64 * 0.01).sin()
                    },
                )
            })
            .collect();
        let thinned = thin(&points, 2.0, 0.0, 99_999.0);
        assert!(thinned.len() <= 4 * WIDTH as usize + 4, "{}", thinned.len());
        assert!(thinned.contains(&(54_321.0, 18.0)));
        let min = thinned.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        assert!((min + 2.0).abs() < 1e-6, "{min}");
        assert!(thinned.windows(2).all(|w| w[0].0 <= w[1].0));
    }

    #[test]
    fn bad_cells_are_located() {
        let e = Table::parse("t.csv", "time,a\n0,1\n1,x\n").unwrap_err();
        assert_eq!(e.to_string(), "t.csv:3:2: `x` is not a number");
        let e = Table::parse("t.csv", "time,a\n0,1,2\n").unwrap_err();
        assert!(matches!(e, PlotError::Ragged { line: 2, .. }));
    }
}
