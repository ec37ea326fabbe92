//! A PLC program written as a timeline: a list of steps, each firing when its tick or its
//! condition is reached, writing leaves of the image by their ST paths and driving the
//! semaphores of the control units. Scenarios use it instead of compiled PLC code.
//!
//! ```toml
//! [[step]]                        # fires once, at CNC tick 5
//! at_tick = 5
//! set = { "gpCh[0]^channel_mc_control.dyn_cs.enable_w" = true }
//!
//! [[step]]                        # armed from now on: fires in every cycle it is ready
//! when = "gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state == 2"
//! repeat = true
//! set = { "gpCh[0]^channel_mc_control.dyn_cs.command_w.rotation[2]" = "-gpAx[6]^lr_state.current_position_acs_r" }
//! commit = "gpCh[0]^channel_mc_control.dyn_cs.command_semaphore_rw"
//! ```
//!
//! Steps fire in order; a step is ready when the CNC has done `at_tick` ticks, `when` holds,
//! the `commit` semaphore is FALSE (the previous datum was taken) and the `take` semaphore is
//! TRUE (a datum is offered). Firing reads every value first, then sets `take` FALSE, writes
//! the values in the order given and finally sets `commit` TRUE, each write with release
//! ordering, as the handshake protocol asks. A `repeat` step stays armed after it was reached
//! and the sequence goes on past it. A value is a number, a boolean, or a string naming a
//! leaf, optionally negated (`"-PATH"`).

use hli::access::{AccessError, Leaf, Value};
use hli::desc::Scalar;
use hli::ImageMemory;
use serde::Deserialize;

pub mod instances;
pub mod registry;

/// Why a timeline was refused.
#[derive(Debug, thiserror::Error)]
pub enum TimelineError {
    /// The TOML did not parse or has unknown fields.
    #[error("{file}: {message}")]
    Syntax {
        /// The file.
        file: String,
        /// What the parser said.
        message: String,
    },
    /// A step is not valid.
    #[error("{file}: step {step}: {reason}")]
    Step {
        /// The file.
        file: String,
        /// 1-based step number.
        step: usize,
        /// What is wrong.
        reason: String,
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TimelineFile {
    #[serde(default)]
    step: Vec<StepFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StepFile {
    at_tick: Option<u64>,
    when: Option<String>,
    #[serde(default)]
    set: toml::Table,
    commit: Option<String>,
    take: Option<String>,
    #[serde(default)]
    repeat: bool,
    call: Option<toml::Table>,
    wait: Option<String>,
}

/// A value source: a constant or a leaf read when the step fires.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Operand {
    Constant(Value),
    Leaf { leaf: Leaf, negate: bool },
}

impl Operand {
    fn parse(text: &str) -> Result<Operand, AccessError> {
        let t = text.trim();
        match t.to_ascii_uppercase().as_str() {
            "TRUE" => return Ok(Operand::Constant(Value::Unsigned(1))),
            "FALSE" => return Ok(Operand::Constant(Value::Unsigned(0))),
            _ => {}
        }
        if let Ok(v) = t.parse::<i64>() {
            return Ok(Operand::Constant(Value::Int(v)));
        }
        if let Ok(v) = t.parse::<f64>() {
            return Ok(Operand::Constant(Value::Real(v)));
        }
        let (negate, path) = match t.strip_prefix('-') {
            Some(rest) => (true, rest.trim()),
            None => (false, t),
        };
        Ok(Operand::Leaf {
            leaf: Leaf::resolve(path)?,
            negate,
        })
    }

    fn value(&self, memory: &ImageMemory) -> Value {
        match *self {
            Operand::Constant(v) => v,
            Operand::Leaf { leaf, negate } => {
                let v = leaf.read(memory);
                if !negate {
                    return v;
                }
                match v {
                    Value::Int(i) => Value::Int(i.wrapping_neg()),
                    Value::Unsigned(u) => Value::Int((u as i64).wrapping_neg()),
                    Value::Real(r) => Value::Real(-r),
                }
            }
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Compare {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

#[derive(Debug, Clone, Copy)]
struct Comparison {
    left: Operand,
    op: Compare,
    right: Operand,
}

impl Comparison {
    fn holds(&self, memory: &ImageMemory) -> bool {
        let (a, b) = (
            self.left.value(memory).as_f64(),
            self.right.value(memory).as_f64(),
        );
        match self.op {
            Compare::Eq => a == b,
            Compare::Ne => a != b,
            Compare::Lt => a < b,
            Compare::Le => a <= b,
            Compare::Gt => a > b,
            Compare::Ge => a >= b,
        }
    }
}

/// `A == 2 && B != 0`: comparisons joined by `&&` (or `AND`).
fn parse_condition(text: &str) -> Result<Vec<Comparison>, String> {
    let normalised = text.replace(" AND ", " && ").replace(" and ", " && ");
    let mut out = Vec::new();
    for part in normalised.split("&&") {
        // Two-character operators first so `<=` is not read as `<`.
        let ops = [
            ("==", Compare::Eq),
            ("!=", Compare::Ne),
            ("<>", Compare::Ne),
            ("<=", Compare::Le),
            (">=", Compare::Ge),
            ("<", Compare::Lt),
            (">", Compare::Gt),
            ("=", Compare::Eq),
        ];
        let (at, len, op) = ops
            .iter()
            .find_map(|(sym, op)| part.find(sym).map(|at| (at, sym.len(), *op)))
            .ok_or_else(|| {
                format!(
                    "`{}` compares nothing (use ==, !=, <, <=, >, >=)",
                    part.trim()
                )
            })?;
        let left = Operand::parse(&part[..at]).map_err(|e| e.to_string())?;
        let right = Operand::parse(&part[at + len..]).map_err(|e| e.to_string())?;
        out.push(Comparison { left, op, right });
    }
    Ok(out)
}

/// A leaf to write and where its value comes from.
#[derive(Debug, Clone)]
struct Assignment {
    path: String,
    leaf: Leaf,
    source: Operand,
}

#[derive(Debug, Clone)]
struct Step {
    at_tick: Option<u64>,
    when: Vec<Comparison>,
    set: Vec<Assignment>,
    commit: Option<Leaf>,
    take: Option<Leaf>,
    repeat: bool,
    call: Option<instances::Call>,
    wait: Option<(usize, instances::Output)>,
}

/// What happened to one step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepRecord {
    /// CNC tick at which the step fired first.
    pub first_fired_at: Option<u64>,
    /// How often it fired.
    pub fired: u64,
    /// Values that did not fit their leaf when fired (not written).
    pub refused_values: u64,
}

/// A loaded timeline and its progress.
#[derive(Debug, Clone)]
pub struct Timeline {
    steps: Vec<Step>,
    next: usize,
    armed: Vec<usize>,
    records: Vec<StepRecord>,
    values: Vec<Value>,
    cnc_tick: Leaf,
    cnc_cycle: Leaf,
    /// `at_tick` counts ticks of this cycle (ns); taken at the first cycle (see
    /// [`Timeline::count_ticks_of`]).
    tick_reference_ns: Option<u64>,
    instances: instances::Instances,
}

impl Timeline {
    /// Parses a timeline; `file` names it in errors.
    pub fn parse(file: &str, text: &str) -> Result<Timeline, TimelineError> {
        let parsed: TimelineFile = toml::from_str(text).map_err(|e| TimelineError::Syntax {
            file: file.to_string(),
            message: e.to_string(),
        })?;
        let mut steps = Vec::with_capacity(parsed.step.len());
        let mut instances = instances::Instances::default();
        for (i, s) in parsed.step.into_iter().enumerate() {
            let fail = |reason: String| TimelineError::Step {
                file: file.to_string(),
                step: i + 1,
                reason,
            };
            // The wait names instances called by earlier steps; then this step's call.
            let wait = match &s.wait {
                Some(w) => Some(instances.parse_wait(w).map_err(fail)?),
                None => None,
            };
            let call = match &s.call {
                Some(table) => Some(instances.parse_call(table).map_err(fail)?),
                None => None,
            };
            let mut step = Step::build(s).map_err(fail)?;
            step.wait = wait;
            step.call = call;
            steps.push(step);
        }
        let most_values = steps.iter().map(|s| s.set.len()).max().unwrap_or(0);
        let n = steps.len();
        Ok(Timeline {
            steps,
            next: 0,
            armed: Vec::with_capacity(n),
            records: vec![StepRecord::default(); n],
            values: Vec::with_capacity(most_values),
            cnc_tick: Leaf::resolve("header.cnc_heartbeat").expect("the header has a heartbeat"),
            cnc_cycle: Leaf::resolve("header.cnc_cycle_ns").expect("the header has a cycle"),
            tick_reference_ns: None,
            instances,
        })
    }

    /// Reads and parses a timeline file.
    pub fn load(path: &std::path::Path) -> Result<Timeline, TimelineError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| TimelineError::Syntax {
            file: file.clone(),
            message: e.to_string(),
        })?;
        Timeline::parse(&file, &text)
    }

    /// The steps' `at_tick` count ticks of `cycle_ns` (the scenario's `cycle_ms`): at its first
    /// cycle the timeline reads the CNC's cycle from the segment's header and, when it differs,
    /// waits the same time in the CNC's ticks (rounded to the nearest), so a timeline keeps its
    /// meaning when a run changes the cycle (`cnc run --cycle-ms`).
    pub fn count_ticks_of(&mut self, cycle_ns: u64) {
        self.tick_reference_ns = (cycle_ns > 0).then_some(cycle_ns);
    }

    /// The `at_tick` of every step, in the order of the file.
    pub fn at_ticks(&self) -> impl Iterator<Item = Option<u64>> + '_ {
        self.steps.iter().map(|s| s.at_tick)
    }

    /// `at_tick` from ticks of the reference cycle to ticks of the CNC's (once).
    fn rescale_ticks(&mut self, memory: &ImageMemory) {
        let Some(reference) = self.tick_reference_ns.take() else {
            return;
        };
        let cnc = match self.cnc_cycle.read(memory) {
            Value::Unsigned(ns) => ns,
            other => other.as_f64() as u64,
        };
        if cnc == 0 || cnc == reference {
            return;
        }
        let (from, to) = (u128::from(reference), u128::from(cnc));
        for step in &mut self.steps {
            if let Some(t) = step.at_tick.as_mut() {
                let scaled = (u128::from(*t) * from + to / 2) / to;
                *t = u64::try_from(scaled).unwrap_or(u64::MAX);
            }
        }
    }

    /// What happened to each step, in order.
    pub fn records(&self) -> &[StepRecord] {
        &self.records
    }

    /// Steps reached so far (fired once, or armed).
    pub fn reached(&self) -> usize {
        self.next
    }

    /// Number of steps.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// Whether the timeline has no steps.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// Whether steps call function blocks (they need the PLC process's acyclic service).
    pub fn calls_blocks(&self) -> bool {
        !self.instances.is_empty()
    }

    /// The axis (gpAx index) of every block instance, with the instance name.
    pub fn block_axes(&self) -> impl Iterator<Item = (&str, u32)> {
        self.instances.axes()
    }

    /// The NC axis IDs the block calls name (`axis_id`, `master_id`), with the instance name
    /// and whether it is the block's own axis.
    pub fn block_axis_ids(&self) -> Vec<(String, u32, bool)> {
        let calls = self.steps.iter().filter_map(|s| s.call.as_ref());
        self.instances.axis_ids(calls)
    }

    /// The channel (gpCh index) of every channel block instance, with the instance name.
    pub fn block_channels(&self) -> impl Iterator<Item = (&str, u32)> {
        self.instances.channels()
    }

    /// One PLC cycle with block calls: Execute edges due, the steps, then every instance.
    /// Does not allocate.
    pub fn cycle_io(&mut self, io: &mut crate::runtime::PlcIo<'_>) {
        self.instances.begin_cycle();
        let tick = self.cycle(io.memory);
        self.instances.call_all(io, tick);
    }

    /// One PLC cycle against `memory` without block calls (in-process runs of timelines that
    /// call no blocks; [`Timeline::cycle_io`] runs the blocks too); returns the CNC tick it
    /// saw. Does not allocate.
    pub fn cycle(&mut self, memory: &ImageMemory) -> u64 {
        self.rescale_ticks(memory);
        let tick = match self.cnc_tick.read(memory) {
            Value::Unsigned(t) => t,
            other => other.as_f64() as u64,
        };
        for k in 0..self.armed.len() {
            let i = self.armed[k];
            self.try_fire(i, memory, tick);
        }
        while self.next < self.steps.len() {
            let i = self.next;
            let fired = self.try_fire(i, memory, tick);
            if self.steps[i].repeat {
                self.armed.push(i);
            } else if !fired {
                break;
            }
            self.next += 1;
        }
        tick
    }

    fn try_fire(&mut self, i: usize, memory: &ImageMemory, tick: u64) -> bool {
        let step = &self.steps[i];
        if !step.ready(memory, tick) || !step.wait.is_none_or(|w| self.instances.holds(w)) {
            return false;
        }
        self.values.clear();
        self.values
            .extend(step.set.iter().map(|a| a.source.value(memory)));
        let record = &mut self.records[i];
        if let Some(take) = step.take {
            take.write(memory, Value::Unsigned(0));
        }
        for (a, &v) in step.set.iter().zip(&self.values) {
            match a.leaf.check(&a.path, v) {
                Ok(v) => a.leaf.write(memory, v),
                Err(_) => record.refused_values += 1,
            }
        }
        if let Some(commit) = step.commit {
            commit.write(memory, Value::Unsigned(1));
        }
        if let Some(call) = &step.call {
            self.instances.apply(call);
        }
        record.fired += 1;
        record.first_fired_at.get_or_insert(tick);
        true
    }

    /// One line per step: when it fired first and how often.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        for (i, r) in self.records.iter().enumerate() {
            let first = r
                .first_fired_at
                .map_or("never".to_string(), |t| format!("at tick {t}"));
            out.push_str(&format!(
                "timeline step {}: fired {} time(s), first {first}{}\n",
                i + 1,
                r.fired,
                if r.refused_values > 0 {
                    format!(", {} value(s) refused", r.refused_values)
                } else {
                    String::new()
                }
            ));
        }
        out.push_str(&self.instances.summary());
        out
    }
}

impl Step {
    fn build(s: StepFile) -> Result<Step, String> {
        let when = match &s.when {
            Some(text) => parse_condition(text)?,
            None => Vec::new(),
        };
        let mut set = Vec::with_capacity(s.set.len());
        for (path, value) in &s.set {
            let leaf = Leaf::resolve(path).map_err(|e| e.to_string())?;
            if !leaf.plc_writable() {
                return Err(format!(
                    "`{path}` is written by the {}, not the PLC",
                    leaf.writer.label()
                ));
            }
            let source = match value {
                toml::Value::Integer(v) => Operand::Constant(Value::Int(*v)),
                toml::Value::Float(v) => Operand::Constant(Value::Real(*v)),
                toml::Value::Boolean(b) => Operand::Constant(Value::Unsigned(u64::from(*b))),
                toml::Value::String(text) => Operand::parse(text).map_err(|e| e.to_string())?,
                other => return Err(format!("`{path}`: {other} is not a value")),
            };
            if let Operand::Constant(v) = source {
                leaf.check(path, v).map_err(|e| e.to_string())?;
            }
            set.push(Assignment {
                path: path.clone(),
                leaf,
                source,
            });
        }
        let semaphore = |path: &Option<String>| -> Result<Option<Leaf>, String> {
            let Some(path) = path else { return Ok(None) };
            let leaf = Leaf::resolve(path).map_err(|e| e.to_string())?;
            if leaf.scalar != Scalar::Bool || leaf.writer != hli::SymbolWriter::Both {
                return Err(format!(
                    "`{path}` is not a semaphore (a BOOL both sides write)"
                ));
            }
            Ok(Some(leaf))
        };
        let commit = semaphore(&s.commit)?;
        let take = semaphore(&s.take)?;
        if s.at_tick.is_none()
            && when.is_empty()
            && commit.is_none()
            && take.is_none()
            && s.wait.is_none()
            && s.repeat
        {
            return Err(
                "a repeating step needs `at_tick`, `when`, `wait`, `commit` or `take`".into(),
            );
        }
        Ok(Step {
            at_tick: s.at_tick,
            when,
            set,
            commit,
            take,
            repeat: s.repeat,
            call: None,
            wait: None,
        })
    }

    fn ready(&self, memory: &ImageMemory, tick: u64) -> bool {
        self.at_tick.is_none_or(|t| tick >= t)
            && self.when.iter().all(|c| c.holds(memory))
            && self
                .commit
                .is_none_or(|c| c.read(memory) == Value::Unsigned(0))
            && self
                .take
                .is_none_or(|t| t.read(memory) == Value::Unsigned(1))
    }
}

impl crate::runtime::PlcProgram for Timeline {
    fn cycle(&mut self, io: &mut crate::runtime::PlcIo<'_>) {
        self.cycle_io(io);
    }
    fn summary(&self) -> String {
        Timeline::summary(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hli::image::heap_image;

    const SEM: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_semaphore_rw";
    const ROT: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_w.rotation[2]";
    const AXIS: &str = "gpAx[6]^lr_state.current_position_acs_r";

    fn beat(memory: &ImageMemory) {
        let leaf = Leaf::resolve("header.cnc_heartbeat").unwrap();
        let t = leaf.read(memory).as_f64() as u64;
        memory.place::<u64>(leaf.offset).store(t + 1);
    }

    #[test]
    fn steps_fire_in_order_and_repeating_steps_respect_the_semaphore() {
        let text = format!(
            r#"
[[step]]
at_tick = 2
set = {{ "gpCh[0]^channel_mc_control.dyn_cs.enable_w" = true }}
[[step]]
repeat = true
set = {{ "{ROT}" = "-{AXIS}" }}
commit = "{SEM}"
"#
        );
        let mut t = Timeline::parse("t.toml", &text).unwrap();
        let memory = heap_image(1, 8);
        let axis = Leaf::resolve(AXIS).unwrap();
        axis.write(&memory, Value::Int(1234));
        t.cycle(&memory); // tick 0: nothing
        assert_eq!(t.records()[0].fired, 0);
        beat(&memory);
        beat(&memory);
        t.cycle(&memory); // tick 2: both
        assert_eq!(t.records()[0].first_fired_at, Some(2));
        assert_eq!(Leaf::resolve(ROT).unwrap().read(&memory), Value::Int(-1234));
        t.cycle(&memory); // semaphore still TRUE: no second command
        assert_eq!(t.records()[1].fired, 1);
        Leaf::resolve(SEM)
            .unwrap()
            .write(&memory, Value::Unsigned(0)); // CNC took it
        t.cycle(&memory);
        assert_eq!(t.records()[1].fired, 2);
    }

    /// A timeline written for 1 ms ticks on a CNC at 0.25 ms waits the same time: 4x the
    /// ticks; without a reference its ticks are the CNC's.
    #[test]
    fn at_tick_keeps_its_time_on_a_cnc_of_another_cycle() {
        let text = "[[step]]\nat_tick = 3\n[[step]]\nat_tick = 5\n";
        let memory = heap_image(1, 8);
        let at = core::mem::offset_of!(hli::layout::HliSegmentHeader, cnc_cycle_ns);
        memory.place::<u32>(at).store(250_000);
        let mut scaled = Timeline::parse("t.toml", text).unwrap();
        scaled.count_ticks_of(1_000_000);
        let mut plain = Timeline::parse("t.toml", text).unwrap();
        for _ in 0..20 {
            beat(&memory);
            scaled.cycle(&memory);
            plain.cycle(&memory);
        }
        let fired = |t: &Timeline| {
            t.records()
                .iter()
                .map(|r| r.first_fired_at)
                .collect::<Vec<_>>()
        };
        assert_eq!(fired(&scaled), [Some(12), Some(20)]);
        assert_eq!(scaled.at_ticks().collect::<Vec<_>>(), [Some(12), Some(20)]);
        assert_eq!(fired(&plain), [Some(3), Some(5)]);
    }

    #[test]
    fn bad_timelines_are_refused_with_the_step() {
        let cnc_owned = r#"
[[step]]
set = { "gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state" = 2 }
"#;
        let e = Timeline::parse("t.toml", cnc_owned)
            .unwrap_err()
            .to_string();
        assert!(e.contains("step 1") && e.contains("CNC"), "{e}");
        let bad_cond = "[[step]]\nwhen = \"gpCh[0]^nothing == 1\"\n";
        assert!(Timeline::parse("t.toml", bad_cond).is_err());
        let out_of_range = format!("[[step]]\nset = {{ \"{ROT}\" = 1e12 }}\n");
        assert!(Timeline::parse("t.toml", &out_of_range).is_err());
        let not_sem = format!("[[step]]\ncommit = \"{ROT}\"\n");
        assert!(Timeline::parse("t.toml", &not_sem).is_err());
        assert!(Timeline::parse("t.toml", "[[step]]\nfoo = 1\n").is_err());
    }
}
