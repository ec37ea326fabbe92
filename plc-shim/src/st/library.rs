//! The block library in Structured Text: every block of the timeline registry
//! ([`crate::timeline::registry::blocks`]) whose inputs ST can give is a FUNCTION_BLOCK under
//! its manual's name, its inputs read from the block's one declaration (its `InputSpec`
//! list), and an ST instance runs the same block kernel as the Rust programs and timelines.
//!
//! * The axis: `Axis : AXIS_REF` (a flying-saw block's `Slave`; a master `Master`), the
//!   AXIS_REF holding the axis's index in `gpAx` (`AxisIndex`); a channel's block takes
//!   `Channel : UDINT` (its index in `gpCh`).
//! * Execute (a block that has it), then the block's inputs: BOOL, LREAL for numbers, UDINT
//!   for counts, IDs and modes (a wire enum's raw value), DINT for signed ranges and choices,
//!   DWORD for flag masks.
//! * Outputs: Done, Busy, Active, CommandAborted, Error, ErrorID, InVelocity, InSync,
//!   StartSync, Status (MC_Power's).
//!
//! As in a timeline, an Execute block takes its inputs at the rising edge of Execute; a
//! block without Execute (MC_Power) takes them every call. An input no call of the instance
//! has given is not passed on, so the block keeps its own default (MC_CamIn's scalings 1.0,
//! MC_MoveVelocity's Direction 1), as when a timeline's call does not give it; once given,
//! it keeps its value from call to call, as an FB input does. A value outside its input's kind
//! (a range, a positive time, one of a list) is not passed on: that command ends at once with
//! Error and [`INVALID_INPUT`] (held while Execute stays TRUE). Inputs ST cannot give yet
//! (tables, lists, NC program names, the saw's SyncMode) are left out; a block that needs
//! one is not in the library ([`unavailable`]).

use crate::kernel::Outputs;
use crate::runtime::PlcIo;
use crate::timeline::registry::{
    blocks, folded, BlockSpec, InputSpec, Kind, Target, TimelineBlock, Value,
};
use plc_st::vm::{BlockIo, Fault, Host};
use std::fmt::Write as _;

/// The error id of a command whose input was outside its kind (AxisError::InvalidParameter).
pub const INVALID_INPUT: u32 = hli::enums::AxisError::InvalidParameter as u32;

/// The name the library's declarations are loaded under.
pub const LIBRARY: &str = "<blocks>";

/// The outputs of every library block, in their order after the inputs.
const OUTPUTS: [&str; 10] = [
    "Done",
    "Busy",
    "Active",
    "CommandAborted",
    "Error",
    "ErrorID",
    "InVelocity",
    "InSync",
    "StartSync",
    "Status",
];

/// How a block's ST declaration meets its spec: the index of each variable.
#[derive(Debug, Clone)]
struct Binding {
    spec: &'static BlockSpec,
    /// The axis (or channel) variable.
    target: Option<usize>,
    /// Execute.
    execute: Option<usize>,
    /// Each input the declaration has: its variable, its spec, whether it is an AXIS_REF.
    inputs: Vec<(usize, InputSpec, bool)>,
    /// The first output's variable.
    outputs: usize,
}

/// Whether ST can give an input of `kind`.
fn expressible(kind: &Kind) -> bool {
    !matches!(kind, Kind::Parsed { .. } | Kind::Room)
}

/// An input's name in ST: its key in PascalCase (`master_offset` is `MasterOffset`).
fn st_name(key: &str) -> String {
    key.split('_')
        .map(|part| {
            let mut c = part.chars();
            c.next()
                .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
                .unwrap_or_default()
        })
        .collect()
}

/// Whether an input names an axis (a master or a slave): an AXIS_REF in ST.
fn is_axis(spec: &InputSpec) -> bool {
    matches!(folded(spec.key).as_str(), "master" | "slave")
        && matches!(spec.kind, Kind::Count | Kind::Range(..))
}

/// The ST type of an input of `kind`.
fn st_type(kind: &Kind) -> &'static str {
    match kind {
        Kind::Bool => "BOOL",
        Kind::Real | Kind::Between(..) | Kind::Positive => "LREAL",
        Kind::Range(lo, hi) if *lo >= 0 && *hi <= i64::from(u32::MAX) => "UDINT",
        Kind::Range(lo, hi) if *lo >= i64::from(i32::MIN) && *hi <= i64::from(i32::MAX) => "DINT",
        Kind::Range(..) => "LINT",
        Kind::Flags { .. } => "DWORD",
        Kind::OneOf(_) => "DINT",
        _ => "UDINT",
    }
}

/// The constants of the blocks' modes and flags under the manuals' names
/// (`MC_STARTMODE_ABSOLUTE`, `GearInSync_CheckMask_MAXACC`), as one VAR_GLOBAL CONSTANT list.
fn constants(specs: &[&'static BlockSpec]) -> String {
    let mut all = std::collections::BTreeMap::new();
    for input in specs.iter().flat_map(|b| b.inputs.iter()) {
        match input.kind {
            Kind::Mode(m) => {
                for (name, raw) in (m.st_names)() {
                    all.insert(name.to_string(), format!("UDINT := {raw}"));
                }
            }
            Kind::Flags { flags, prefixes } => {
                // The prefix that names this input (`GearInSync_CheckMask_` for CheckMask).
                let key = folded(input.key);
                let prefix = prefixes.iter().find(|p| folded(p).contains(&key));
                for (name, bits) in flags {
                    let name = format!("{}{name}", prefix.or(prefixes.first()).unwrap_or(&""));
                    all.insert(name, format!("DWORD := 16#{bits:X}"));
                }
            }
            _ => {}
        }
    }
    let mut text = String::from("VAR_GLOBAL CONSTANT\n");
    for (name, value) in all {
        let _ = writeln!(text, "    {name} : {value};");
    }
    text + "END_VAR\n"
}

/// The blocks ST cannot call yet, each with the input it cannot give.
pub fn unavailable() -> Vec<(&'static str, &'static str)> {
    blocks()
        .filter_map(|b| {
            let missing = b
                .inputs
                .iter()
                .find(|i| i.required && !expressible(&i.kind));
            missing.map(|i| (b.name, i.key))
        })
        .collect()
}

/// The library: its declarations as ST, and how each block meets them.
#[derive(Debug, Clone)]
pub struct Library {
    text: String,
    bindings: Vec<Binding>,
}

impl Library {
    /// Every block of the registry that ST can call.
    pub fn new() -> Library {
        let mut lib = Library {
            text: "(* The block library, generated from the blocks' declarations. *)\n\
                   TYPE\n    AXIS_REF :\n    STRUCT\n        \
                   AxisIndex : UDINT; (* the axis's index in gpAx *)\n    END_STRUCT\n\
                   END_TYPE\n"
                .into(),
            bindings: Vec::new(),
        };
        let missing = unavailable();
        let specs: Vec<&'static BlockSpec> = blocks()
            .filter(|b| !missing.iter().any(|(n, _)| *n == b.name))
            .collect();
        lib.text.push_str(&constants(&specs));
        for spec in specs {
            lib.declare(spec);
        }
        lib
    }

    fn declare(&mut self, spec: &'static BlockSpec) {
        let mut vars: Vec<(String, &str)> = Vec::new();
        let target = match spec.target {
            Target::Axis => Some(("Axis".to_string(), "AXIS_REF")),
            Target::AxisNamed(name) => Some((st_name(name), "AXIS_REF")),
            Target::Channel => Some(("Channel".to_string(), "UDINT")),
            Target::Group => None,
        };
        let target = target.map(|t| {
            vars.push(t);
            vars.len() - 1
        });
        let execute = spec.execute.then(|| {
            vars.push(("Execute".into(), "BOOL"));
            vars.len() - 1
        });
        let mut inputs = Vec::new();
        for input in spec.inputs.iter().filter(|i| expressible(&i.kind)) {
            let name = st_name(input.key);
            if vars.iter().any(|(n, _)| folded(n) == folded(&name)) {
                continue;
            }
            let axis = is_axis(input);
            vars.push((
                name,
                if axis {
                    "AXIS_REF"
                } else {
                    st_type(&input.kind)
                },
            ));
            inputs.push((vars.len() - 1, *input, axis));
        }
        let outputs = vars.len();
        let _ = writeln!(self.text, "FUNCTION_BLOCK {}\nVAR_INPUT", spec.name);
        for (name, ty) in &vars {
            let _ = writeln!(self.text, "    {name} : {ty};");
        }
        self.text.push_str("END_VAR\nVAR_OUTPUT\n");
        for name in OUTPUTS {
            let ty = if name == "ErrorID" { "UDINT" } else { "BOOL" };
            let _ = writeln!(self.text, "    {name} : {ty};");
        }
        self.text.push_str("END_VAR\nEND_FUNCTION_BLOCK\n");
        self.bindings.push(Binding {
            spec,
            target,
            execute,
            inputs,
            outputs,
        });
    }

    /// The declarations, as ST.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The blocks' names, in the order a [`Host`] numbers them.
    pub fn names(&self) -> Vec<&'static str> {
        self.bindings.iter().map(|b| b.spec.name).collect()
    }
}

impl Default for Library {
    fn default() -> Self {
        Library::new()
    }
}

/// One instance's block and what the host remembers of its last call.
#[derive(Debug)]
struct Instance {
    block: Box<dyn TimelineBlock>,
    /// Execute in the last call.
    last_execute: bool,
    /// The command of the current Execute was refused (an input outside its kind).
    refused: bool,
    /// Per input: given by a call of the program once (then passed at every edge).
    given: Vec<bool>,
}

/// The blocks of a program's instances (one per instance, made at load).
#[derive(Debug)]
pub struct Blocks {
    library: Library,
    instances: Vec<Instance>,
}

impl Blocks {
    /// A block for each of `instances` (address and block index, as
    /// `plc_st::vm::Program::library_instances` lists them).
    pub fn new(library: Library, instances: &[(u32, usize)]) -> Blocks {
        let instances = instances
            .iter()
            .map(|(_, k)| Instance {
                block: (library.bindings[*k].spec.make)(None),
                last_execute: false,
                refused: false,
                given: vec![false; library.bindings[*k].inputs.len()],
            })
            .collect();
        Blocks { library, instances }
    }

    /// The host for one cycle on `io`.
    pub fn host<'a, 'b>(&'a mut self, io: &'a mut PlcIo<'b>) -> BlockHost<'a, 'b> {
        BlockHost { blocks: self, io }
    }
}

/// The library's blocks during one PLC cycle.
pub struct BlockHost<'a, 'b> {
    blocks: &'a mut Blocks,
    io: &'a mut PlcIo<'b>,
}

/// Input `var` of `spec`'s kind from the instance, or `None` if it is outside the kind.
fn input_value(io: &BlockIo<'_>, var: usize, spec: &InputSpec, axis: bool) -> Option<Value> {
    let int = || io.int(var);
    let real = || io.real(var).filter(|v| v.is_finite());
    if axis {
        return int().map(Value::Int);
    }
    match spec.kind {
        Kind::Bool => int().map(|v| Value::Bool(v != 0)),
        Kind::Real => real().map(Value::Real),
        Kind::Between(lo, hi) => real().filter(|v| (lo..=hi).contains(v)).map(Value::Real),
        Kind::Positive => real().filter(|v| *v > 0.0).map(Value::Real),
        Kind::Range(lo, hi) => int().filter(|v| (lo..=hi).contains(v)).map(Value::Int),
        Kind::OneOf(choices) => int()
            .filter(|v| choices.iter().any(|(_, c)| c == v))
            .map(Value::Int),
        Kind::Mode(m) => int()
            .filter(|v| u32::try_from(*v).is_ok_and(m.valid))
            .map(Value::Int),
        Kind::Count | Kind::Flags { .. } => int().map(Value::Int),
        Kind::Room | Kind::Parsed { .. } => None,
    }
}

/// Writes `out` (and Status) to the outputs from variable `first` on.
fn write_outputs(io: &mut BlockIo<'_>, first: usize, out: &Outputs, status: bool) {
    let flags = [
        out.done,
        out.busy,
        out.active,
        out.command_aborted,
        out.error,
    ];
    for (k, v) in flags.iter().enumerate() {
        io.set(first + k, f64::from(u8::from(*v)));
    }
    io.set(first + 5, f64::from(out.error_id));
    let more = [out.in_velocity, out.in_sync, out.start_sync, status];
    for (k, v) in more.iter().enumerate() {
        io.set(first + 6 + k, f64::from(u8::from(*v)));
    }
}

impl Host for BlockHost<'_, '_> {
    fn call(&mut self, block: usize, io: &mut BlockIo<'_>) -> Result<(), Fault> {
        let binding = &self.blocks.library.bindings[block];
        let inst = self
            .blocks
            .instances
            .get_mut(io.slot())
            .ok_or(Fault::BadPointer)?;
        let execute = binding.execute.map(|v| io.int(v).unwrap_or(0) != 0);
        let takes_inputs = match execute {
            Some(e) => e && !inst.last_execute,
            None => true,
        };
        if takes_inputs {
            inst.refused = false;
            for (k, (var, spec, axis)) in binding.inputs.iter().enumerate() {
                // Never given by a call: the block keeps its own default.
                inst.given[k] |= io.given(*var);
                if !inst.given[k] {
                    continue;
                }
                match input_value(io, *var, spec, *axis) {
                    Some(v) => inst.block.set(spec.key, &v),
                    None => inst.refused = execute.is_some(),
                }
            }
        }
        inst.last_execute = execute.unwrap_or(false);
        if inst.refused && inst.last_execute {
            // Execute stays FALSE for the block: its command never starts.
            if let Some(e) = inst.block.execute() {
                *e = false;
            }
            let _ = inst.block.cycle(self.io, axis_of(io, binding));
            write_outputs(io, binding.outputs, &Outputs::failed(INVALID_INPUT), false);
            return Ok(());
        }
        if let (Some(e), Some(x)) = (inst.block.execute(), execute) {
            *e = x;
        }
        let (out, status) = inst.block.cycle(self.io, axis_of(io, binding));
        write_outputs(io, binding.outputs, &out, status);
        Ok(())
    }
}

/// The axis (or channel) an instance addresses: 0 for a group's block.
fn axis_of(io: &BlockIo<'_>, binding: &Binding) -> u32 {
    match binding.target {
        Some(v) => io
            .int(v)
            .and_then(|v| u32::try_from(v).ok())
            .unwrap_or(u32::MAX),
        None => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_block_st_can_give_the_inputs_of_is_declared_and_loads() {
        let lib = Library::new();
        let (declared, missing) = (lib.names().len(), unavailable().len());
        assert_eq!(
            declared + missing,
            blocks().count(),
            "every block is one or the other"
        );
        assert!(declared >= 40, "{declared} blocks: {:?}", unavailable());
        let p = crate::st::StProgram::from_texts(&[], 1).unwrap();
        assert_eq!(p.program().library_instances().len(), 0);
        assert!(lib.text().contains(
            "FUNCTION_BLOCK MC_MoveAbsolute\nVAR_INPUT\n    Axis : AXIS_REF;\n    Execute : BOOL;\n"
        ));
        let left_out: Vec<(&str, &str)> = blocks()
            .flat_map(|b| b.inputs.iter().map(move |i| (b.name, i)))
            .filter(|(_, i)| !expressible(&i.kind) && !i.required)
            .map(|(b, i)| (b, i.key))
            .collect();
        eprintln!("{left_out:?}");
    }
}
