//! The library's blocks on an ST program's instances ([`plc_st::vm::Host`]): one
//! `TimelineBlock` per instance, made at load; each call reads the instance's inputs, runs
//! the block kernel for one cycle, and writes its outputs back.
//!
//! As in a timeline, an Execute block takes its inputs at the rising edge of Execute; a
//! block without Execute (MC_Power) takes them every call. An input no call of the instance
//! has given is not passed on, so the block keeps its own default (MC_CamIn's scalings 1.0,
//! MC_MoveVelocity's Direction 1), as when a timeline's call does not give it; once given,
//! it keeps its value from call to call, as an FB input does. A value outside its input's
//! kind (a range, a positive time, one of a list), or rows (or an MC_CAM_REF's array)
//! through a pointer that is NULL or reaches beyond the program's memory (or the room made
//! at load), or holding a value that is not finite, is not passed on: that command ends at once with
//! Error and [`INVALID_INPUT`] (held while Execute stays TRUE). Nothing here allocates after
//! the load (the rows' room is made with the instance).

use super::library::{Binding, Bound, Library, CAM_REF_FIELDS};
use crate::kernel::Outputs;
use crate::runtime::PlcIo;
use crate::timeline::registry::{CamRefIn, InputSpec, Kind, StStyle, TimelineBlock, Value};
use plc_st::types::Elem;
use plc_st::vm::{BlockIo, Fault, Host};

/// The error id of a command whose input was outside its kind (AxisError::InvalidParameter).
pub const INVALID_INPUT: u32 = hli::enums::AxisError::InvalidParameter as u32;

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
    /// Rows read through a pointer (room made at load).
    rows: Vec<f64>,
    /// tTimeout given by a call once.
    timeout_given: bool,
    /// The call site of the last call (a site gives the same inputs every time).
    site: usize,
    /// The outputs as the instance's variables hold them (written when they change: the
    /// program cannot write them, see `Blocks::forget_outputs` for a tool).
    shown: Option<(Outputs, bool)>,
    /// The program's array (address, bytes) a read's answer goes into when it is Done.
    destination: Option<(i64, usize)>,
    /// Done in the last call (a read's answer is copied when it rises).
    last_done: bool,
    /// Two edges of their own (bCoupleOn, bCoupleOff): each input's last level, which one
    /// rose last, and a command held for one cycle with Execute low so that the block sees
    /// the new edge.
    edges: TwoEdges,
}

/// A block's two edges ([`crate::timeline::registry::StForm::Edges`]).
#[derive(Debug, Default)]
struct TwoEdges {
    last_on: bool,
    last_off: bool,
    /// The last edge was `on`'s (the input the block is given).
    on: bool,
    /// A new edge came while the block's Execute was high: low for this cycle, high the next.
    rearm: bool,
}

impl TwoEdges {
    /// The block's Execute for inputs `on` and `off`, its Execute in the last call `held`:
    /// high while either is, with a low cycle before a new edge of either while it is high.
    fn execute(&mut self, on: bool, off: bool, held: bool) -> bool {
        let (rose_on, rose_off) = (on && !self.last_on, off && !self.last_off);
        (self.last_on, self.last_off) = (on, off);
        if rose_on || rose_off {
            self.on = rose_on;
        }
        if std::mem::take(&mut self.rearm) {
            return true;
        }
        if (rose_on || rose_off) && held {
            self.rearm = true;
            return false;
        }
        on || off
    }
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
            .map(|(_, k)| {
                let binding = &library.bindings[*k];
                let mut block = (binding.spec.make)(binding.read_room());
                // Room for table data (an MC_CAM_REF's array, or rows through a pointer a
                // block keeps: the compatibility blocks'; FiFoWrite keeps its own).
                let room = binding.cam_ref_room().max(binding.rows_room() * 8);
                if room > 0 {
                    block.reserve_cam_ref(room);
                }
                Instance {
                    block,
                    last_execute: false,
                    refused: false,
                    given: vec![false; binding.inputs.len()],
                    rows: Vec::with_capacity(binding.rows_room()),
                    timeout_given: false,
                    site: usize::MAX,
                    shown: None,
                    destination: None,
                    last_done: false,
                    edges: TwoEdges::default(),
                }
            })
            .collect();
        Blocks { library, instances }
    }

    /// Writes every instance's outputs at its next call (a tool wrote the program's
    /// memory: it may have written one).
    pub fn forget_outputs(&mut self) {
        for inst in &mut self.instances {
            inst.shown = None;
        }
    }

    /// The host for one cycle on `io`, the PLC's cycle `cycle_ns` long (tTimeout counts in
    /// cycles).
    pub fn host<'a, 'b>(&'a mut self, io: &'a mut PlcIo<'b>, cycle_ns: u64) -> BlockHost<'a, 'b> {
        BlockHost {
            blocks: self,
            io,
            // Not announced yet: the default cycle of 1 ms.
            cycle_ns: if cycle_ns == 0 { 1_000_000 } else { cycle_ns },
        }
    }
}

/// The library's blocks during one PLC cycle.
pub struct BlockHost<'a, 'b> {
    blocks: &'a mut Blocks,
    io: &'a mut PlcIo<'b>,
    cycle_ns: u64,
}

/// tTimeout (ms) as PLC cycles of `cycle_ns`, rounded up: `None` unless above 0 and within
/// the timelines' most cycles.
fn timeout_cycles(ms: i64, cycle_ns: u64) -> Option<u64> {
    let ns = u64::try_from(ms).ok()?.checked_mul(1_000_000)?;
    let cycles = ns.div_ceil(cycle_ns);
    let most = crate::timeline::instances::MAX_TIMEOUT_CYCLES as u64;
    (1..=most).contains(&cycles).then_some(cycles)
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
        Kind::ZeroOr(lo, hi) => int()
            .filter(|v| *v == 0 || (lo..=hi).contains(v))
            .map(Value::Int),
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

/// Passes input `bound` of the instance to its block; `false` if its value is refused.
fn pass(io: &BlockIo<'_>, inst: &mut Instance, (bound, spec): &(Bound, InputSpec)) -> bool {
    match *bound {
        Bound::Value { var, axis } => match input_value(io, var, spec, axis) {
            Some(v) => {
                inst.block.set(spec.key, &v);
                true
            }
            None => false,
        },
        Bound::Rows {
            data,
            columns,
            rows,
            size,
            max,
        } => {
            let count = |v| io.int(v).and_then(|n| u32::try_from(n).ok());
            let (Some(c), Some(r)) = (count(columns), count(rows)) else {
                return false;
            };
            // More values than a call takes, or than the array's size holds: none read, the
            // block refuses them with its own code.
            let n = (c as usize).saturating_mul(r as usize);
            let bytes = (n as u64).saturating_mul(8);
            let beyond = size
                .is_some_and(|s| io.int(s).unwrap_or(0) < i64::try_from(bytes).unwrap_or(i64::MAX));
            if n > max || beyond {
                inst.rows.clear();
                return inst.block.set_rows(&inst.rows, c, r);
            }
            io.lreals(data, n, &mut inst.rows) && inst.block.set_rows(&inst.rows, c, r)
        }
        Bound::CamRef { var, max_bytes } => pass_cam_ref(io, inst, var, max_bytes),
        Bound::ReadAt { data, size } => {
            let size = io.int(size).and_then(|n| u32::try_from(n).ok());
            let array = size.map(|array_size| CamRefIn {
                bytes: &[],
                array_size,
                table_type: 0,
                rows: 0,
                columns: 0,
            });
            destination(io, inst, io.int(data), array)
        }
        Bound::Edges { .. } => {
            inst.block.set(spec.key, &Value::Bool(inst.edges.on));
            true
        }
        Bound::Ids { count, first, len } => match ids(io, count, first, len) {
            Some(v) => {
                inst.block.set(spec.key, &v);
                true
            }
            None => false,
        },
        Bound::ReadInto { var } => {
            destination(io, inst, io.field(var, 0, Elem::LWord), cam_ref(io, var))
        }
        Bound::Text { var, len } => match io.text(var, len as usize + 1) {
            Some(text) => inst.block.set_text(spec.key, text),
            None => false,
        },
        Bound::Struct { var, read } => {
            let field = |at: u32, bytes: u8| {
                let t = match bytes {
                    1 => Elem::USInt,
                    2 => Elem::Int,
                    4 => Elem::DInt,
                    _ => Elem::LInt,
                };
                io.field(var, at, t)
            };
            read(&field, &mut |key, value| inst.block.set(key, value))
        }
    }
}

/// The array a read's answer goes into (where `p` points, as `array` describes it): checked
/// to lie in the program's memory (refused otherwise), its description to the block.
fn destination(
    io: &BlockIo<'_>,
    inst: &mut Instance,
    p: Option<i64>,
    array: Option<CamRefIn>,
) -> bool {
    inst.destination = None;
    let (Some(p), Some(array)) = (p, array) else {
        return false;
    };
    let size = array.array_size as usize;
    if io.memory_at(p, size).is_none() {
        return false;
    }
    inst.destination = Some((p, size));
    inst.block.set_destination(&array)
}

/// An `MC_CAM_REF`'s description (its bytes empty).
fn cam_ref(io: &BlockIo<'_>, var: usize) -> Option<CamRefIn<'static>> {
    let [size, table_type, rows, columns] =
        CAM_REF_FIELDS.map(|at| io.field(var, at, Elem::UDInt).map(|v| v as u32));
    Some(CamRefIn {
        bytes: &[],
        array_size: size?,
        table_type: table_type?,
        rows: rows?,
        columns: columns?,
    })
}

/// An `MC_CAM_REF` to its block: its array read where `pArray` points, `nArraySize` bytes of
/// the program's memory; `false` (refused) for a NULL pointer or one into the image, an
/// array beyond the memory or larger than the room made at load, or a value not finite.
fn pass_cam_ref(io: &BlockIo<'_>, inst: &mut Instance, var: usize, max_bytes: usize) -> bool {
    let (Some(p), Some(table)) = (io.field(var, 0, Elem::LWord), cam_ref(io, var)) else {
        return false;
    };
    if table.array_size as usize > max_bytes {
        return false;
    }
    let Some(bytes) = io.memory_at(p, table.array_size as usize) else {
        return false;
    };
    inst.block.set_cam_ref(&CamRefIn { bytes, ..table })
}

/// A list of `len` IDs from variable `first` on, as many as variable `count` says (1 to
/// `len`, each 1 to 255): `None` otherwise.
fn ids(io: &BlockIo<'_>, count: usize, first: usize, len: usize) -> Option<Value> {
    let n = usize::try_from(io.int(count)?)
        .ok()
        .filter(|n| (1..=len).contains(n))?;
    let mut ids = [0u32; 8];
    for (k, slot) in ids.iter_mut().enumerate().take(n.min(8)) {
        *slot = io.int(first + k).filter(|v| (1..=255).contains(v))? as u32;
    }
    Some(Value::Ids(ids, n as u32))
}

/// Whether this call gives input `bound`.
fn given(io: &BlockIo<'_>, bound: &Bound) -> bool {
    match *bound {
        Bound::Value { var, .. } => io.given(var),
        Bound::Rows {
            data,
            columns,
            rows,
            ..
        } => io.given(data) || io.given(columns) || io.given(rows),
        Bound::ReadAt { data, size } => io.given(data) || io.given(size),
        Bound::Edges { on, off } => io.given(on) || io.given(off),
        Bound::Ids { count, .. } => io.given(count),
        Bound::CamRef { var, .. }
        | Bound::Struct { var, .. }
        | Bound::Text { var, .. }
        | Bound::ReadInto { var } => io.given(var),
    }
}

/// Writes `out` (and Status) to the outputs from variable `first` on, as `style` names them.
fn write_outputs(io: &mut BlockIo<'_>, first: usize, style: StStyle, out: &Outputs, status: bool) {
    let flag = |v: bool| f64::from(u8::from(v));
    let all: &[f64] = match style {
        StStyle::Hungarian => &[flag(out.busy), flag(out.error), f64::from(out.error_id)],
        StStyle::PlcOpen => &[
            flag(out.done),
            flag(out.busy),
            flag(out.active),
            flag(out.command_aborted),
            flag(out.error),
            f64::from(out.error_id),
            flag(out.in_velocity),
            flag(out.in_sync),
            flag(out.start_sync),
            flag(status),
        ],
    };
    for (k, v) in all.iter().enumerate() {
        io.set(first + k, *v);
    }
}

/// Writes `out` to the instance's output variables if they hold something else.
fn show(io: &mut BlockIo<'_>, binding: &Binding, inst: &mut Instance, out: (Outputs, bool)) {
    if inst.shown != Some(out) {
        write_outputs(io, binding.outputs, binding.spec.style, &out.0, out.1);
        inst.shown = Some(out);
    }
}

impl Host for BlockHost<'_, '_> {
    fn call(&mut self, block: usize, io: &mut BlockIo<'_>) -> Result<(), Fault> {
        let binding: &Binding = &self.blocks.library.bindings[block];
        let inst = self
            .blocks
            .instances
            .get_mut(io.slot())
            .ok_or(Fault::BadPointer)?;
        let high = |v: usize| io.int(v).unwrap_or(0) != 0;
        // Two edges of their own (bCoupleOn, bCoupleOff): a rising edge of either is a command.
        let execute = match binding.edges {
            Some((on, off)) => Some(inst.edges.execute(high(on), high(off), inst.last_execute)),
            None => binding.execute.map(high),
        };
        let takes_inputs = match execute {
            Some(e) => e && !inst.last_execute,
            None => true,
        };
        // An input counts as given from the first call that names it, edge or not (a
        // call from the site of the last gives the same).
        if inst.site != io.site() {
            inst.site = io.site();
            for (k, input) in binding.inputs.iter().enumerate() {
                inst.given[k] |= given(io, &input.0);
            }
            inst.timeout_given |= binding.timeout.is_some_and(|v| io.given(v));
        }
        if takes_inputs {
            inst.refused = false;
            for (k, input) in binding.inputs.iter().enumerate() {
                // Never given by a call: the block keeps its own default.
                if inst.given[k] && !pass(io, inst, input) {
                    inst.refused = true;
                }
            }
            if let Some(var) = binding.timeout.filter(|_| inst.timeout_given) {
                match io.int(var).and_then(|ms| timeout_cycles(ms, self.cycle_ns)) {
                    Some(cycles) => {
                        inst.block.timeout_cycles(cycles);
                    }
                    None => inst.refused = true,
                }
            }
        }
        inst.last_execute = execute.unwrap_or(false);
        let axis = axis_of(io, binding);
        // Refused: while Execute stays TRUE, or in this call of a block without Execute.
        if inst.refused && (inst.last_execute || execute.is_none()) {
            // Execute stays FALSE for the block: its command never starts.
            if let Some(e) = inst.block.execute() {
                *e = false;
            }
            let _ = inst.block.cycle(self.io, axis);
            let failed = (Outputs::failed(INVALID_INPUT), false);
            show(io, binding, inst, failed);
            return Ok(());
        }
        if let (Some(e), Some(x)) = (inst.block.execute(), execute) {
            *e = x;
        }
        let was_done = std::mem::replace(&mut inst.last_done, false);
        let out = inst.block.cycle(self.io, axis);
        inst.last_done = out.0.done;
        // A read's answer into the program's array and the block's outputs of its own, once
        // when it is Done (a block without Execute, every cycle it is valid).
        if out.0.done && (!was_done || binding.execute.is_none()) {
            if let Some(array) = inst.destination.and_then(|(p, n)| io.memory_at_mut(p, n)) {
                inst.block.read_bytes(array);
            }
            if let Some((first, n)) = binding.results {
                let mut values = [0.0; 64];
                let count = inst.block.result_values(&mut values);
                let mut used = 0;
                for k in first..first + n {
                    used += io.set_leaves(k, &values[used..count]);
                }
            }
        }
        show(io, binding, inst, out);
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
    use super::TwoEdges;

    /// bCoupleOn and bCoupleOff: each rising edge is a command, the later one's input given;
    /// an edge while the other is held lowers Execute for one cycle so that the block sees it.
    #[test]
    fn either_edge_is_a_command_even_while_the_other_is_held() {
        let mut e = TwoEdges::default();
        let mut held = false;
        let mut step = |on, off| {
            let x = e.execute(on, off, held);
            held = x;
            (x, e.on)
        };
        assert_eq!(step(true, false), (true, true), "bCoupleOn rises");
        assert_eq!(step(true, false), (true, true), "held");
        assert_eq!(
            step(true, true),
            (false, false),
            "bCoupleOff rises: one low cycle"
        );
        assert_eq!(
            step(true, true),
            (true, false),
            "then its edge, FALSE given"
        );
        assert_eq!(step(false, false), (false, false));
        assert_eq!(step(false, true), (true, false), "bCoupleOff alone");
    }
}
