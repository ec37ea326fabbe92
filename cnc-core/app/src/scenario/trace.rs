//! The trace: chosen leaves of the image sampled once per tick into a buffer sized before the
//! run (recording does not allocate), written as CSV afterwards: `tick,time` then one column
//! per signal in the order given, as raw HLI values (a DINT position in 0.1 um).

use hli::access::{Leaf, Value};
use hli::ImageMemory;
use std::io::Write;

/// Samples of a run.
#[derive(Debug, Clone)]
pub struct Trace {
    names: Vec<String>,
    leaves: Vec<Leaf>,
    ticks: Vec<u64>,
    times: Vec<f64>,
    values: Vec<Value>,
    capacity: usize,
    dropped: u64,
}

impl Trace {
    /// A trace of `signals` with room for `rows` ticks.
    pub fn new(signals: &[(String, Leaf)], rows: usize) -> Self {
        Self {
            names: signals.iter().map(|(n, _)| n.clone()).collect(),
            leaves: signals.iter().map(|(_, l)| *l).collect(),
            ticks: Vec::with_capacity(rows),
            times: Vec::with_capacity(rows),
            values: Vec::with_capacity(rows * signals.len()),
            capacity: rows,
            dropped: 0,
        }
    }

    /// Samples every signal. Beyond the room given at creation rows are counted, not kept.
    pub fn record(&mut self, memory: &ImageMemory, tick: u64, time_s: f64) {
        if self.ticks.len() >= self.capacity {
            self.dropped += 1;
            return;
        }
        self.ticks.push(tick);
        self.times.push(time_s);
        for leaf in &self.leaves {
            self.values.push(leaf.read(memory));
        }
    }

    /// Rows recorded.
    pub fn len(&self) -> usize {
        self.ticks.len()
    }

    /// Whether nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.ticks.is_empty()
    }

    /// Rows that did not fit.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// The samples of signal `name`, one per row.
    pub fn column(&self, name: &str) -> Option<impl Iterator<Item = Value> + '_> {
        let k = self.names.iter().position(|n| n == name)?;
        let n = self.names.len();
        Some(self.values.iter().skip(k).step_by(n).copied())
    }

    /// Writes the CSV.
    pub fn write_csv(&self, out: &mut impl Write) -> std::io::Result<()> {
        write!(out, "tick,time")?;
        for name in &self.names {
            write!(out, ",{name}")?;
        }
        writeln!(out)?;
        let n = self.names.len();
        for (row, (tick, time)) in self.ticks.iter().zip(&self.times).enumerate() {
            write!(out, "{tick},{time:.6}")?;
            for v in &self.values[row * n..(row + 1) * n] {
                write!(out, ",{v}")?;
            }
            writeln!(out)?;
        }
        Ok(())
    }

    /// Writes the CSV to `path` (creating its folder).
    pub fn save(&self, path: &std::path::Path) -> Result<(), String> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut out = std::io::BufWriter::new(file);
        self.write_csv(&mut out)
            .and_then(|()| out.flush())
            .map_err(|e| format!("{}: {e}", path.display()))
    }
}
