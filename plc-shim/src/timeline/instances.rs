//! The block instances of a timeline: each `call` checked against its block's
//! [`BlockSpec`] (the registry, [`super::registry`]), an instance made on a name's first call,
//! every instance called once per PLC cycle like a PLC program calls its instances, and the
//! edges of its outputs recorded for the report.
//!
//! ```toml
//! [[step]]
//! call = { block = "MC_Power", instance = "power_x", axis = 0, enable = true }
//! [[step]]
//! wait = "power_x.Status"                  # ready once this output is TRUE
//! call = { block = "MC_CamIn", instance = "cam", axis = 1, master = 0, table = 1,
//!          start_mode = "absolute", slave_scaling = 2.0 }
//! ```
//!
//! A call sets the given inputs and a rising edge on Execute (`execute = false` lowers it
//! instead, which releases MC_Stop). An instance called again while Execute is TRUE sees it
//! FALSE for one cycle first, so every call is a new edge.

use super::registry::{find, folded, number, BlockSpec, Kind, Target, TimelineBlock, Value};
use crate::runtime::PlcIo;

/// A call of an instance, checked.
#[derive(Debug, Clone)]
pub struct Call {
    instance: usize,
    inputs: Vec<(&'static str, Value)>,
    execute: bool,
    /// tTimeout in PLC cycles, if the call gives it.
    timeout: Option<u64>,
    /// The master's NC axis ID, if the call gives it (`master_id`).
    master_id: Option<u32>,
}

/// An NC axis ID of key `key` in a call, if given: 1..=u32::MAX.
fn id_of(table: &toml::Table, key: &str) -> Result<Option<u32>, String> {
    let Some(value) = table.get(key) else {
        return Ok(None);
    };
    let id = value
        .as_integer()
        .filter(|i| (1..=i64::from(u32::MAX)).contains(i))
        .ok_or_else(|| format!("call: `{key}` = {value}: an NC axis ID 1..={}", u32::MAX))?;
    Ok(Some(id as u32))
}

/// The `master_id` of a call of `spec`, checked: only for a block with a master.
fn master_id_of(spec: &BlockSpec, table: &toml::Table) -> Result<Option<u32>, String> {
    let id = id_of(table, "master_id")?;
    if id.is_some() && !(spec.make)(None).set_master(0) {
        return Err(format!("call: {} has no master: no `master_id`", spec.name));
    }
    // `master` or `Master` (any spelling) beside it would be overridden: one or the other.
    let index = |k: &String| k.eq_ignore_ascii_case("master");
    if id.is_some() && table.keys().any(index) {
        return Err(format!(
            "call: {}: `master_id` or the master's index, not both",
            spec.name
        ));
    }
    Ok(id)
}

/// The longest tTimeout a call may give, in PLC cycles (about three hours at 1 ms).
pub const MAX_TIMEOUT_CYCLES: i64 = 10_000_000;

/// The `timeout_cycles` of a call of `spec`, checked: 1..=[`MAX_TIMEOUT_CYCLES`], and only for
/// a block with tTimeout.
fn timeout_of(spec: &BlockSpec, table: &toml::Table) -> Result<Option<u64>, String> {
    let Some(value) = table.get("timeout_cycles") else {
        return Ok(None);
    };
    let cycles = value
        .as_integer()
        .filter(|c| (1..=MAX_TIMEOUT_CYCLES).contains(c))
        .ok_or_else(|| {
            format!("call: `timeout_cycles` = {value}: PLC cycles 1..={MAX_TIMEOUT_CYCLES}")
        })?;
    // Asked of a fresh instance, made here (never in a cycle).
    if !(spec.make)(None).timeout_cycles(cycles as u64) {
        return Err(format!(
            "call: {} has no tTimeout: no `timeout_cycles`",
            spec.name
        ));
    }
    Ok(Some(cycles as u64))
}

/// The outputs a `wait` can name.
pub const OUTPUTS: [&str; 8] = [
    "Done",
    "Busy",
    "Active",
    "CommandAborted",
    "Error",
    "InVelocity",
    "Status",
    "InSync",
];

/// A boolean output of a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Output(usize);

/// Where an output rose first, and how often.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Edge {
    /// CNC tick of the first rising edge.
    pub first: Option<u64>,
    /// Rising edges seen.
    pub count: u64,
}

#[derive(Debug)]
struct Instance {
    name: String,
    spec: &'static BlockSpec,
    /// The gpAx index the block addresses (resolved from `axis_id` if given).
    axis: u32,
    /// The axis's NC axis ID, when the calls address it so.
    axis_id: Option<u32>,
    /// The master's NC axis ID, when the last call gave one.
    master_id: Option<u32>,
    block: Box<dyn TimelineBlock>,
    raise_next_cycle: bool,
    last: [bool; 8],
    edges: [Edge; 8],
    error_id: u32,
    /// Room of a read block's answer (made with the instance, never in a cycle).
    room: Option<usize>,
}

impl Instance {
    fn new(name: String, spec: &'static BlockSpec, axis: AxisRef, room: Option<usize>) -> Self {
        Instance {
            name,
            spec,
            axis: axis.0,
            axis_id: axis.1,
            master_id: None,
            block: (spec.make)(room),
            raise_next_cycle: false,
            last: [false; 8],
            edges: [Edge::default(); 8],
            error_id: 0,
            room,
        }
    }

    fn uses_axis(&self) -> bool {
        !matches!(self.spec.target, Target::Group | Target::Channel)
    }
}

/// The instances of a timeline.
#[derive(Debug, Default)]
pub struct Instances {
    list: Vec<Instance>,
}

/// What an instance addresses: the gpAx index (0 for a group's block, the gpCh index for a
/// channel's block; [`UNRESOLVED`] until an NC axis ID is found), and the NC axis ID if the
/// call gave `axis_id`.
type AxisRef = (u32, Option<u32>);

/// The index of an axis given by an NC axis ID the image does not (yet) show: calls to it are
/// refused by the CNC, so the block ends in Error.
pub const UNRESOLVED: u32 = u32::MAX;

/// The axis a call of `spec` addresses: `axis_id` (an NC axis ID) or as [`index_of`] reads it.
fn axis_of(spec: &BlockSpec, table: &toml::Table) -> Result<AxisRef, String> {
    let Some(id) = id_of(table, "axis_id")? else {
        return index_of(spec, table).map(|i| (i, None));
    };
    let given = match spec.target {
        _ if table.contains_key("channel") => {
            return Err(format!("call: {} addresses an axis, no channel", spec.name))
        }
        Target::Group | Target::Channel => {
            return Err(format!(
                "call: {} addresses no axis: no `axis_id`",
                spec.name
            ))
        }
        Target::AxisNamed(name) => table.get("axis").or_else(|| named(table, name)),
        Target::Axis => table.get("axis"),
    };
    match given {
        Some(_) => Err(format!(
            "call: {}: `axis_id` or the axis index, not both",
            spec.name
        )),
        None => Ok((UNRESOLVED, Some(id))),
    }
}

/// The gpAx index a call of `spec` gives (0 for a group's block; the gpCh index for a
/// channel's block).
fn index_of(spec: &BlockSpec, table: &toml::Table) -> Result<u32, String> {
    if let Target::Channel = spec.target {
        return match table.get("channel").map(toml::Value::as_integer) {
            Some(Some(c)) if (0..hli::layout::HLI_MAX_CHANNELS as i64).contains(&c) => Ok(c as u32),
            Some(_) => Err(format!(
                "call: {}: `channel` must be a gpCh index 0..{}",
                spec.name,
                hli::layout::HLI_MAX_CHANNELS
            )),
            None => Err(format!(
                "call: {}: `channel` (the gpCh index) is missing",
                spec.name
            )),
        };
    }
    if table.contains_key("channel") {
        return Err(format!(
            "call: {} addresses no channel: no `channel`",
            spec.name
        ));
    }
    let given = match (table.get("axis"), spec.target) {
        (Some(a), Target::AxisNamed(name)) => match named(table, name) {
            Some(n) if n != a => {
                return Err(format!(
                    "call: {}: `{name}` = {n} and `axis` = {a} differ",
                    spec.name
                ))
            }
            _ => Some(a),
        },
        (None, Target::AxisNamed(name)) => named(table, name),
        (given, _) => given,
    };
    let uses_axis = !matches!(spec.target, Target::Group);
    match given.and_then(toml::Value::as_integer) {
        Some(a) if (0..i64::from(u32::MAX)).contains(&a) && uses_axis => Ok(a as u32),
        Some(a) if uses_axis => Err(format!("call: axis {a} is not an axis index")),
        Some(_) => Err(format!(
            "call: {} addresses a FIFO group: no `axis`",
            spec.name
        )),
        None if uses_axis => Err("call: `axis` (the gpAx index) is missing".into()),
        None => Ok(0),
    }
}

/// The value of key `name` under any spelling (ASCII case and underscores ignored).
fn named<'t>(table: &'t toml::Table, name: &str) -> Option<&'t toml::Value> {
    let name = folded(name);
    table
        .iter()
        .find(|(key, _)| folded(key) == name)
        .map(|(_, value)| value)
}

/// The inputs of a call of `spec`, the room it gives, and whether it raises Execute.
pub(crate) type Checked = (Vec<(&'static str, Value)>, Option<usize>, bool);

/// The keys of a call that are not the block's inputs: what it addresses and how it runs.
const ADDRESSING: [&str; 7] = [
    "block",
    "instance",
    "axis",
    "channel",
    "axis_id",
    "master_id",
    "timeout_cycles",
];

/// The inputs of a `call` table of `spec` checked against its declarations.
pub(crate) fn inputs_of(spec: &BlockSpec, table: &toml::Table) -> Result<Checked, String> {
    let (mut inputs, mut room, mut execute) = (Vec::new(), None, true);
    let mut given: Vec<String> = Vec::new();
    for (key, value) in table {
        if ADDRESSING.contains(&key.as_str()) {
            continue;
        }
        if key == "execute" && spec.execute {
            execute = value
                .as_bool()
                .ok_or("call: `execute` must be true or false")?;
            continue;
        }
        let fold = folded(key);
        if matches!(spec.target, Target::AxisNamed(name) if folded(name) == fold) {
            continue; // the axis, read by `index_of`
        }
        if given.contains(&fold) {
            return Err(format!("call: {} input `{key}` is given twice", spec.name));
        }
        given.push(fold.clone());
        let Some(input) = spec.inputs.iter().find(|i| folded(i.key) == fold) else {
            return Err(unknown_input(spec, key));
        };
        match (&input.kind, input.kind.check(spec.name, key, value)?) {
            (Kind::Room, Value::Int(r)) => room = Some(r as usize),
            (_, value) => inputs.push((input.key, value)),
        }
    }
    // A call that lowers Execute sends nothing: it needs no inputs.
    for input in spec.inputs.iter().filter(|i| i.required && execute) {
        let master = folded(input.key) == "master" && table.contains_key("master_id");
        if !given.contains(&folded(input.key)) && !master {
            return Err(format!("call: {} needs `{}`", spec.name, input.key));
        }
    }
    Ok((inputs, room, execute))
}

/// A call's key that `spec` does not declare.
fn unknown_input(spec: &BlockSpec, key: &str) -> String {
    let known: Vec<&str> = spec.inputs.iter().map(|i| i.key).collect();
    let known = if known.is_empty() {
        "none".into()
    } else {
        known.join(", ")
    };
    format!("call: {} has no input `{key}` (inputs: {known})", spec.name)
}

impl Kind {
    /// `value` checked for input `key` of `block`.
    fn check(&self, block: &str, key: &str, value: &toml::Value) -> Result<Value, String> {
        let bad = || format!("call: {block} input `{key}` = {value} is not valid");
        let range = |lo: i64, hi: i64| {
            value
                .as_integer()
                .filter(|v| (lo..=hi).contains(v))
                .map(Value::Int)
                .ok_or_else(|| format!("call: `{key}` = {value}: {lo}..={hi}"))
        };
        match self {
            Kind::Bool => value.as_bool().map(Value::Bool).ok_or_else(bad),
            Kind::Real => number(value)
                .filter(|v| v.is_finite())
                .map(Value::Real)
                .ok_or_else(bad),
            Kind::Count => value
                .as_integer()
                .filter(|v| (0..i64::from(u32::MAX)).contains(v))
                .map(Value::Int)
                .ok_or_else(bad),
            Kind::Range(lo, hi) => range(*lo, *hi),
            Kind::ZeroOr(lo, hi) => value
                .as_integer()
                .filter(|v| *v == 0 || (*lo..=*hi).contains(v))
                .map(Value::Int)
                .ok_or_else(|| {
                    format!(
                        "call: {block} input `{key}` = {value}: 0 (the default) or {lo} to {hi}"
                    )
                }),
            Kind::Between(lo, hi) => number(value)
                .filter(|v| (*lo..=*hi).contains(v))
                .map(Value::Real)
                .ok_or_else(|| format!("call: {block} input `{key}` = {value}: {lo} to {hi}")),
            Kind::Positive => number(value)
                .filter(|v| v.is_finite() && *v > 0.0)
                .map(Value::Real)
                .ok_or_else(|| format!("call: {block} input `{key}` = {value}: a number above 0")),
            Kind::Flags { flags, prefixes } => flag_bits(value, flags, prefixes)
                .map(|bits| Value::Int(bits.into()))
                .map_err(|e| format!("call: {block} input `{key}` = {value}: {e}")),
            Kind::Room => range(1, 1 << 20),
            Kind::OneOf(choices) => {
                let text = value.to_string();
                let found = choices
                    .iter()
                    .find(|(c, _)| c.split(' ').next() == Some(&text));
                found.map(|(_, v)| Value::Int(*v)).ok_or_else(|| {
                    let texts: Vec<&str> = choices.iter().map(|(c, _)| *c).collect();
                    format!("call: `{key}` = {value}: {}", texts.join(" or "))
                })
            }
            Kind::Mode(m) => match value {
                toml::Value::String(name) => (m.from_name)(name)
                    .map(|v| Value::Int(v.into()))
                    .ok_or_else(|| format!("call: `{key}` = {name:?}: known are {}", (m.names)())),
                toml::Value::Integer(i) if u32::try_from(*i).is_ok_and(m.valid) => {
                    Ok(Value::Int(*i))
                }
                _ => Err(format!(
                    "call: `{key}` = {value}: known are {}",
                    (m.names)()
                )),
            },
            Kind::Parsed { parse, .. } => parse(value),
        }
    }
}

/// A mask: the raw bits, or a list of names from `flags` (each may carry one of the
/// `prefixes`; case and underscores do not matter).
fn flag_bits(value: &toml::Value, flags: &[(&str, u32)], prefixes: &[&str]) -> Result<u32, String> {
    let names = || {
        let names: Vec<&str> = flags.iter().map(|(n, _)| *n).collect();
        names.join(", ")
    };
    let bit = |item: &toml::Value| -> Result<u32, String> {
        let name = item
            .as_str()
            .ok_or_else(|| format!("flag names ({})", names()))?;
        let short = folded(name);
        let short = prefixes
            .iter()
            .find_map(|p| short.strip_prefix(&folded(p)))
            .unwrap_or(&short);
        let found = flags.iter().find(|(n, _)| folded(n) == short);
        found
            .map(|(_, bit)| *bit)
            .ok_or_else(|| format!("unknown flag {name:?} (known: {})", names()))
    };
    match value {
        toml::Value::Integer(bits) => u32::try_from(*bits).map_err(|_| "a 32-bit mask".to_string()),
        toml::Value::Array(list) => list.iter().try_fold(0, |bits, item| Ok(bits | bit(item)?)),
        _ => Err(format!("an integer or a list of flag names ({})", names())),
    }
}

impl Instances {
    /// Checks a `call` table and registers its instance (created on its first call); `Err`
    /// says which key is wrong.
    pub fn parse_call(&mut self, table: &toml::Table) -> Result<Call, String> {
        let block = table
            .get("block")
            .and_then(toml::Value::as_str)
            .ok_or("call: `block` (a string) is missing")?;
        let spec = find(block)?;
        let name = table
            .get("instance")
            .and_then(toml::Value::as_str)
            .unwrap_or(spec.name);
        let axis = axis_of(spec, table)?;
        let (inputs, room, execute) = inputs_of(spec, table)?;
        let timeout = timeout_of(spec, table)?;
        let master_id = master_id_of(spec, table)?;
        let instance = match self.list.iter().position(|i| i.name == name) {
            Some(i) => {
                let inst = &mut self.list[i];
                if inst.spec.name != spec.name || (inst.axis, inst.axis_id) != axis {
                    return Err(format!(
                        "call: instance {name:?} is a {} on {}, not a {} on {}",
                        inst.spec.name,
                        axis_text((inst.axis, inst.axis_id)),
                        spec.name,
                        axis_text(axis)
                    ));
                }
                // The room of a read's answer is the instance's, made now (never in a cycle).
                if let Some(r) = room.filter(|r| Some(*r) > inst.room) {
                    inst.room = Some(r);
                    inst.block = (spec.make)(Some(r));
                }
                i
            }
            None => {
                self.list
                    .push(Instance::new(name.to_string(), spec, axis, room));
                self.list.len() - 1
            }
        };
        Ok(Call {
            instance,
            inputs,
            execute,
            timeout,
            master_id,
        })
    }

    /// Checks a `wait` (`INSTANCE.OUTPUT`) against the instances called so far.
    pub fn parse_wait(&self, text: &str) -> Result<(usize, Output), String> {
        let (name, output) = text
            .trim()
            .split_once('.')
            .ok_or_else(|| format!("wait {text:?}: INSTANCE.OUTPUT"))?;
        let instance = self
            .list
            .iter()
            .position(|i| i.name == name)
            .ok_or_else(|| format!("wait: no instance {name:?} is called before this step"))?;
        let output = OUTPUTS
            .iter()
            .position(|o| o.eq_ignore_ascii_case(output))
            .ok_or_else(|| {
                let known = OUTPUTS.join(", ");
                format!("wait: unknown output {output:?} (known: {known})")
            })?;
        Ok((instance, Output(output)))
    }

    /// Whether there are any.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The axes the instances use, with their instance names.
    pub fn axes(&self) -> impl Iterator<Item = (&str, u32)> {
        self.list
            .iter()
            .filter(|i| i.uses_axis() && i.axis_id.is_none())
            .map(|i| (i.name.as_str(), i.axis))
    }

    /// The NC axis IDs the calls name, with the instance's name and whether the ID is the
    /// block's own axis (`axis_id`; else a master, `master_id`).
    pub fn axis_ids<'c>(&self, calls: impl Iterator<Item = &'c Call>) -> Vec<(String, u32, bool)> {
        let own = self.list.iter().filter_map(|i| {
            let id = i.axis_id?;
            Some((i.name.clone(), id, true))
        });
        let masters = calls.filter_map(|c| {
            let id = c.master_id?;
            Some((self.list[c.instance].name.clone(), id, false))
        });
        own.chain(masters).collect()
    }

    /// The channel (gpCh index) of every instance of a channel's block, with its name.
    pub fn channels(&self) -> impl Iterator<Item = (&str, u32)> {
        self.list
            .iter()
            .filter(|i| matches!(i.spec.target, Target::Channel))
            .map(|i| (i.name.as_str(), i.axis))
    }

    /// Whether `output` of `instance` was TRUE after the last cycle.
    pub fn holds(&self, (instance, Output(output)): (usize, Output)) -> bool {
        self.list[instance].last[output]
    }

    /// Applies a fired call: inputs now, the Execute edge in this or the next cycle. The
    /// outputs seen so far are forgotten, so a later `wait` sees only this call's.
    pub fn apply(&mut self, call: &Call) {
        let inst = &mut self.list[call.instance];
        for (key, value) in &call.inputs {
            inst.block.set(key, value);
        }
        if let Some(cycles) = call.timeout {
            inst.block.timeout_cycles(cycles);
        }
        inst.master_id = call.master_id;
        inst.last = [false; 8];
        match inst.block.execute() {
            // Execute is (or is about to be) TRUE: hold it FALSE for a cycle, then raise it.
            Some(execute) if call.execute && (*execute || inst.raise_next_cycle) => {
                *execute = false;
                inst.raise_next_cycle = true;
            }
            Some(execute) => {
                *execute = call.execute;
                inst.raise_next_cycle = false;
            }
            None => {}
        }
    }

    /// Raises the Execute edges due from the last cycle (call before the steps fire).
    pub fn begin_cycle(&mut self) {
        for inst in &mut self.list {
            if inst.raise_next_cycle {
                inst.raise_next_cycle = false;
                if let Some(e) = inst.block.execute() {
                    *e = true;
                }
            }
        }
    }

    /// Calls every instance once and records its output edges at CNC tick `tick`.
    pub fn call_all(&mut self, io: &mut PlcIo<'_>, tick: u64) {
        for inst in &mut self.list {
            if let Some(id) = inst.axis_id {
                inst.axis = resolve(&io.view, inst.axis, id);
            }
            if let Some(id) = inst.master_id {
                inst.block.set_master(resolve(&io.view, UNRESOLVED, id));
            }
            let (out, status) = inst.block.cycle(io, inst.axis);
            let now = [
                out.done,
                out.busy,
                out.active,
                out.command_aborted,
                out.error,
                out.in_velocity,
                status,
                out.in_sync,
            ];
            for ((is, was), edge) in now.iter().zip(inst.last).zip(inst.edges.iter_mut()) {
                if *is && !was {
                    edge.count += 1;
                    edge.first.get_or_insert(tick);
                }
            }
            if out.error {
                inst.error_id = out.error_id;
            }
            inst.last = now;
        }
    }

    /// One line per instance: its block and axis, and the first rising edge of every output
    /// that rose (`Busy 12 (x1), Done 341 (x1)`), with the last error id; then what a read
    /// block read.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        for inst in &self.list {
            let edges: Vec<String> = OUTPUTS
                .iter()
                .zip(&inst.edges)
                .filter_map(|(name, e)| e.first.map(|t| format!("{name} {t} (x{})", e.count)))
                .collect();
            let target = match (inst.uses_axis(), inst.axis_id, inst.axis) {
                (true, Some(id), UNRESOLVED) => format!(" on axis ID {id} (not found)"),
                (true, Some(id), axis) => format!(" on gpAx[{axis}] (axis ID {id})"),
                (true, None, axis) => format!(" on gpAx[{axis}]"),
                (false, ..) => String::new(),
            };
            let edges = match edges.is_empty() {
                true => "no output rose".to_string(),
                false => edges.join(", "),
            };
            let error = match inst.error_id {
                0 => String::new(),
                id => format!(", ErrorID {id:#06x}"),
            };
            let (name, kind) = (&inst.name, inst.spec.name);
            out.push_str(&format!("block {name} ({kind}{target}): {edges}{error}\n"));
            if let Some(values) = inst.block.read().filter(|v| !v.is_empty()) {
                let shown: Vec<String> = values.iter().take(12).map(|v| format!("{v}")).collect();
                let more = if values.len() > 12 { ", ..." } else { "" };
                let (n, shown) = (values.len(), shown.join(", "));
                out.push_str(&format!("  read {n} value(s): {shown}{more}\n"));
            }
        }
        out
    }
}

/// The gpAx index of NC axis ID `id`: `known` if the image still shows that ID there, else
/// found anew ([`UNRESOLVED`] if no axis has it). No allocation.
fn resolve(view: &hli::views::PlcView<'_>, known: u32, id: u32) -> u32 {
    let there = view.axis_state(known as usize);
    if there.is_ok_and(|s| s.nc_axis_id_r == id) {
        return known;
    }
    view.axis_index_by_id(id).map_or(UNRESOLVED, |i| i as u32)
}

/// How an instance's axis reads in a message.
fn axis_text((axis, id): AxisRef) -> String {
    match id {
        Some(id) => format!("axis ID {id}"),
        None => format!("axis {axis}"),
    }
}

/// A clone has the same instances with fresh block states (a timeline is cloned before it
/// runs).
impl Clone for Instances {
    fn clone(&self) -> Self {
        let list = self.list.iter();
        let fresh = |i: &Instance| {
            let axis = (i.axis, i.axis_id);
            Instance::new(i.name.clone(), i.spec, axis, i.room)
        };
        Instances {
            list: list.map(fresh).collect(),
        }
    }
}

#[cfg(test)]
mod tests;
