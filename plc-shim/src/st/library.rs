//! The block library in Structured Text: every block of the timeline registry
//! ([`crate::timeline::registry::blocks`]) whose inputs ST can give is a FUNCTION_BLOCK under
//! its manual's name, its inputs read from the block's one declaration (its `InputSpec`
//! list, with each input's [`StForm`] and the block's [`StStyle`]), and an ST instance runs
//! the same block kernel as the Rust programs and timelines ([`super::host`]).
//!
//! * PLCopen blocks: the axis `Axis : AXIS_REF` (a flying-saw block's `Slave`, a master
//!   `Master`), the AXIS_REF holding the axis's index in `gpAx` (`AxisIndex`); a channel's
//!   block takes `Channel : UDINT` (its index in `gpCh`); then `Execute` (a block that has
//!   it) and the inputs in PascalCase: BOOL, LREAL for numbers, UDINT for counts, IDs and
//!   modes (a wire enum's raw value), DINT for signed ranges and choices, DWORD for flag
//!   masks. Outputs: Done, Busy, Active, CommandAborted, Error, ErrorID, InVelocity, InSync,
//!   StartSync, Status (MC_Power's).
//! * The seeds' Hungarian blocks (the FIFO family): `iChannelId`, `iAxisId` (the axis's
//!   `gpAx` index), `bExecute`, the inputs under the seed's names (FiFoWrite's
//!   `AdrDataArray : POINTER TO LREAL`, `iColDim`, `iRowsToWrite`); outputs `bBusy`, `bErr`,
//!   `iErrId`.
//!
//! * Tables: the seed's `CamTable : MC_CAM_REF` (000 5.1.16.2: `pArray := ADR(aTable)`,
//!   `nArraySize := SIZEOF(aTable)`, `nTableType`, `nNoOfRows`, `nNoOfCols`) gives
//!   MC_CamTableSelect its rows or points and MC_WriteMotionFunction its points, read from
//!   the program's memory at the edge into room the block makes at load (at most
//!   [`crate::blocks::cam_data::CAM_REF_ROOM_BYTES`] of array).
//!
//! * Structures of the seeds: the flying saw's `SyncMode : ST_SyncMode` (001 12.3.1, its
//!   mode and one BOOL per flag), declared by the saw family with the input.
//!
//! * Arrays a read's answer goes into (`CamTable : MC_CAM_REF`, `AdrDataArray`), NC program
//!   names (`ProgramName : STRING(63)`), the compatibility blocks' two edges (`bCoupleOn`,
//!   `bCoupleOff`) and ID lists (`iTableId1` ..); a read block's results are outputs of its
//!   own ([`crate::timeline::registry::Results`]).
//!
//! An input whose `StForm` ST cannot give would be left out ([`left_out`], listed by `plc
//! library`: today none); a block that requires one is not in the library ([`unavailable`]).

use crate::timeline::registry::Target;
use crate::timeline::registry::{
    blocks, folded, BlockSpec, InputSpec, Kind, StForm, StStyle, StructReader,
};
use std::fmt::Write as _;

/// The library's types: AXIS_REF, the seed's MC_CAM_REF (000 5.1.16.2; its array's address
/// a pointer of 8 bytes) and MC_MotionFunctionPoint (5.1.16.10, the wire's layout: 56
/// bytes), and PVOID, the untyped address any pointer and ADR go to.
const TYPES: &str = "(* The block library, generated from the blocks' declarations. *)
TYPE
    PVOID : POINTER TO BYTE;
    AXIS_REF :
    STRUCT
        AxisIndex : UDINT; (* the axis's index in gpAx *)
    END_STRUCT
    MC_CAM_REF :
    STRUCT
        pArray : PVOID; (* ADR of the array *)
        nArraySize : UDINT; (* SIZEOF the array *)
        nTableType : UDINT; (* 10, 11 rows; 22 a motion function *)
        nNoOfRows : UDINT;
        nNoOfCols : UDINT; (* 2 for rows, 1 for points *)
    END_STRUCT
    MC_MotionFunctionPoint :
    STRUCT
        PointIndex : UDINT;
        FunctionType : UDINT;
        PointType : UDINT;
        RelIndexNextPoint : UDINT;
        MasterPos : LREAL;
        SlavePos : LREAL;
        SlaveVelo : LREAL;
        SlaveAcc : LREAL;
        SlaveJerk : LREAL;
    END_STRUCT
END_TYPE
";

/// Byte offsets of MC_CAM_REF's fields after pArray (nArraySize, nTableType, nNoOfRows,
/// nNoOfCols), as the layout places them (`tests/it/st_cam_ref.rs` fails if they move).
pub(super) const CAM_REF_FIELDS: [u32; 4] = [8, 12, 16, 20];

/// The room of a read's answer in Structured Text (values, or points of a motion function),
/// made at load: MC_ReadMotionFunctionValues and CamTableReadData up to 4,096 LREALs,
/// MC_ReadMotionFunction up to 4,096 points; a larger answer is the block's 0x4B31.
pub const ST_READ_ROOM: usize = 4096;

/// The name the library's declarations are loaded under.
pub const LIBRARY: &str = "<blocks>";

/// The outputs of a PLCopen block, in their order after the inputs.
pub(super) const PLCOPEN_OUTPUTS: [&str; 10] = [
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

/// The outputs of a block with the seeds' Hungarian names.
pub(super) const HUNGARIAN_OUTPUTS: [&str; 3] = ["bBusy", "bErr", "iErrId"];

/// How an input of the declaration meets its spec.
#[derive(Debug, Clone, Copy)]
pub(super) enum Bound {
    /// One variable; `axis` if it is an AXIS_REF.
    Value {
        /// Its index among the block's variables.
        var: usize,
        /// An AXIS_REF.
        axis: bool,
    },
    /// Rows through a pointer: the pointer's, the columns' and the rows' variables.
    Rows {
        /// The pointer.
        data: usize,
        /// The columns.
        columns: usize,
        /// The rows.
        rows: usize,
        /// The array's size in bytes, if declared.
        size: Option<usize>,
        /// The most values a call takes.
        max: usize,
    },
    /// An array a read's answer goes into: its pointer's and its size's variables.
    ReadAt {
        /// The pointer.
        data: usize,
        /// The size in bytes.
        size: usize,
    },
    /// The input is TRUE at a rising edge of `on`, FALSE at one of `off` (the block's edge).
    Edges {
        /// The edge that gives TRUE.
        on: usize,
        /// The edge that gives FALSE.
        off: usize,
    },
    /// A list of IDs: the count's variable and the first ID's (the others follow it).
    Ids {
        /// The count.
        count: usize,
        /// The first ID.
        first: usize,
        /// How many ID variables.
        len: usize,
    },
    /// An `MC_CAM_REF` (its variable) a read's answer goes into.
    ReadInto {
        /// The structure.
        var: usize,
    },
    /// A STRING (its variable) of at most `len` characters.
    Text {
        /// The string.
        var: usize,
        /// Its most characters.
        len: u32,
    },
    /// A structure (its variable) and how its fields become the block's inputs.
    Struct {
        /// The structure.
        var: usize,
        /// Its fields as inputs.
        read: StructReader,
    },
    /// An `MC_CAM_REF` (its variable) and the most bytes of array a call takes.
    CamRef {
        /// The structure.
        var: usize,
        /// The most bytes.
        max_bytes: usize,
    },
}

/// A declaration's variables: name and type.
type Vars = Vec<(String, String)>;

/// Declares variable `name` of type `ty`: its index.
fn push(vars: &mut Vars, name: String, ty: impl Into<String>) -> usize {
    vars.push((name, ty.into()));
    vars.len() - 1
}

/// How a block's ST declaration meets its spec: the index of each variable.
#[derive(Debug, Clone)]
pub(super) struct Binding {
    pub(super) spec: &'static BlockSpec,
    /// The axis (or channel) variable.
    pub(super) target: Option<usize>,
    /// Execute.
    pub(super) execute: Option<usize>,
    /// tTimeout (TIME), of a block that has it.
    pub(super) timeout: Option<usize>,
    /// Each input the declaration has, with its spec.
    pub(super) inputs: Vec<(Bound, InputSpec)>,
    /// The first output's variable.
    pub(super) outputs: usize,
    /// The two edges of a block without Execute ([`StForm::Edges`]).
    pub(super) edges: Option<(usize, usize)>,
    /// The outputs of its own of a read block ([`Results`]): the first's variable and how
    /// many.
    pub(super) results: Option<(usize, usize)>,
}

impl Binding {
    /// The room the instance's rows need (0 without rows).
    pub(super) fn rows_room(&self) -> usize {
        let room = |(b, _): &(Bound, InputSpec)| match b {
            Bound::Rows { max, .. } => *max,
            _ => 0,
        };
        self.inputs.iter().map(room).max().unwrap_or(0)
    }

    /// The room of a read's answer the instance's block is made with: [`ST_READ_ROOM`] for a
    /// block that reads into the program's array, the block's default otherwise.
    pub(super) fn read_room(&self) -> Option<usize> {
        let reads = |(b, _): &(Bound, InputSpec)| {
            matches!(b, Bound::ReadInto { .. } | Bound::ReadAt { .. })
        };
        self.inputs.iter().any(reads).then_some(ST_READ_ROOM)
    }

    /// The bytes of `MC_CAM_REF` array the instance's block makes room for (0 without).
    pub(super) fn cam_ref_room(&self) -> usize {
        let room = |(b, _): &(Bound, InputSpec)| match b {
            Bound::CamRef { max_bytes, .. } => *max_bytes,
            _ => 0,
        };
        self.inputs.iter().map(room).max().unwrap_or(0)
    }
}

/// Whether ST can give `input` (a hidden one comes with another).
fn expressible(input: &InputSpec) -> bool {
    matches!(
        input.st,
        StForm::Rows { .. }
            | StForm::ReadAt { .. }
            | StForm::Edges { .. }
            | StForm::Ids { .. }
            | StForm::CamRef { .. }
            | StForm::Hidden
            | StForm::Struct { .. }
            | StForm::Text { .. }
            | StForm::ReadInto { .. }
    ) || !matches!(input.kind, Kind::Parsed { .. } | Kind::Room)
}

/// A key in PascalCase (`master_offset` is `MasterOffset`).
fn pascal(key: &str) -> String {
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
            let missing = b.inputs.iter().find(|i| i.required && !expressible(i));
            missing.map(|i| (b.name, i.key))
        })
        .collect()
}

/// The inputs ST leaves out of blocks it has (each block and input).
pub fn left_out() -> Vec<(&'static str, &'static str)> {
    let missing = unavailable();
    blocks()
        .filter(|b| !missing.iter().any(|(n, _)| *n == b.name))
        .flat_map(|b| b.inputs.iter().map(move |i| (b.name, i)))
        .filter(|(_, i)| !expressible(i))
        .map(|(b, i)| (b, i.key))
        .collect()
}

/// The library: its declarations as ST, and how each block meets them.
#[derive(Debug, Clone)]
pub struct Library {
    text: String,
    pub(super) bindings: Vec<Binding>,
    /// The structure types the blocks' inputs and results declared.
    types: Vec<&'static str>,
}

impl Library {
    /// Every block of the registry that ST can call.
    pub fn new() -> Library {
        let mut lib = Library {
            text: TYPES.into(),
            bindings: Vec::new(),
            types: Vec::new(),
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
        let hungarian = spec.style == StStyle::Hungarian;
        let mut vars: Vars = Vec::new();
        let target = match (spec.target, hungarian) {
            (Target::Axis, false) => Some(push(&mut vars, "Axis".into(), "AXIS_REF")),
            (Target::Axis, true) => Some(push(&mut vars, "iAxisId".into(), "UDINT")),
            // The seed's own name for the axis's index (`iSlaveId`).
            (Target::AxisNamed(name), true) => Some(push(&mut vars, name.into(), "UDINT")),
            (Target::AxisNamed(name), false) => Some(push(&mut vars, pascal(name), "AXIS_REF")),
            (Target::Channel, _) => Some(push(&mut vars, "Channel".into(), "UDINT")),
            (Target::Group, _) => None,
        };
        // A block whose edge is two inputs of its own (bCoupleOn, bCoupleOff) has no Execute.
        let two_edges = spec
            .inputs
            .iter()
            .any(|i| matches!(i.st, StForm::Edges { .. }));
        let execute = (spec.execute && !two_edges).then(|| {
            let name = if hungarian { "bExecute" } else { "Execute" };
            push(&mut vars, name.into(), "BOOL")
        });
        // What a block takes and shows beyond its spec is asked of a probe instance: the
        // seed's tTimeout, and a read block's outputs of its own (their types declared
        // before the block).
        let mut probe = (spec.make)(None);
        let timeout = probe
            .timeout_cycles(crate::kernel::DEFAULT_TIMEOUT_CYCLES)
            .then(|| push(&mut vars, "tTimeout".into(), "TIME"));
        let own_outputs = probe.results();
        if let Some(r) = own_outputs {
            self.declare_type(r.type_name, r.declaration);
        }
        let mut inputs = Vec::new();
        for input in spec.inputs.iter().filter(|i| expressible(i)) {
            if let Some(bound) = self.bind(input, &mut vars) {
                inputs.push((bound, *input));
            }
        }
        let edges = inputs.iter().find_map(|(b, _)| match b {
            Bound::Edges { on, off } => Some((*on, *off)),
            _ => None,
        });
        let outputs = vars.len();
        let _ = writeln!(self.text, "FUNCTION_BLOCK {}\nVAR_INPUT", spec.name);
        for (name, ty) in &vars {
            let _ = writeln!(self.text, "    {name} : {ty};");
        }
        self.text.push_str("END_VAR\nVAR_OUTPUT\n");
        let names: &[&str] = if hungarian {
            &HUNGARIAN_OUTPUTS
        } else {
            &PLCOPEN_OUTPUTS
        };
        for name in names {
            let ty = if matches!(*name, "ErrorID" | "iErrId") {
                "UDINT"
            } else {
                "BOOL"
            };
            let _ = writeln!(self.text, "    {name} : {ty};");
        }
        // A read block's outputs of its own, after the standard ones.
        let results = own_outputs.map(|r| {
            for (name, ty) in r.outputs {
                let _ = writeln!(self.text, "    {name} : {ty};");
            }
            (outputs + names.len(), r.outputs.len())
        });
        self.text.push_str("END_VAR\nEND_FUNCTION_BLOCK\n");
        self.bindings.push(Binding {
            spec,
            target,
            execute,
            timeout,
            inputs,
            outputs,
            edges,
            results,
        });
    }

    /// Declares structure type `name` once (`declaration` is its `TYPE .. END_TYPE`; an
    /// empty name declares nothing).
    fn declare_type(&mut self, name: &'static str, declaration: &str) {
        if !name.is_empty() && !self.types.contains(&name) {
            self.types.push(name);
            self.text.push_str(declaration);
        }
    }

    /// How `input` is declared (its variables pushed to `vars`): `None` if it is not an
    /// input of its own.
    fn bind(&mut self, input: &InputSpec, vars: &mut Vars) -> Option<Bound> {
        Some(match input.st {
            StForm::Rows {
                data,
                columns,
                rows,
                size,
                max,
            } => Bound::Rows {
                data: push(vars, data.into(), "POINTER TO LREAL"),
                size: size.map(|size| push(vars, size.into(), "UDINT")),
                columns: push(vars, columns.into(), "UDINT"),
                rows: push(vars, rows.into(), "UDINT"),
                max,
            },
            StForm::ReadAt { data, size } => Bound::ReadAt {
                data: push(vars, data.into(), "POINTER TO LREAL"),
                size: push(vars, size.into(), "UDINT"),
            },
            StForm::Edges { on, off } => Bound::Edges {
                on: push(vars, on.into(), "BOOL"),
                off: push(vars, off.into(), "BOOL"),
            },
            StForm::Ids { count, ids } => {
                let count = push(vars, count.into(), "UDINT");
                let first = vars.len();
                for id in ids {
                    push(vars, (*id).into(), "UDINT");
                }
                Bound::Ids {
                    count,
                    first,
                    len: ids.len(),
                }
            }
            StForm::CamRef { name, max_bytes } => Bound::CamRef {
                var: push(vars, name.into(), "MC_CAM_REF"),
                max_bytes,
            },
            StForm::Hidden => return None,
            StForm::ReadInto { name } => Bound::ReadInto {
                var: push(vars, name.into(), "MC_CAM_REF"),
            },
            StForm::Text { name, len } => Bound::Text {
                var: push(vars, name.into(), format!("STRING({len})")),
                len,
            },
            StForm::Struct {
                name,
                ty,
                declaration,
                read,
            } => {
                self.declare_type(ty, declaration);
                Bound::Struct {
                    var: push(vars, name.into(), ty),
                    read,
                }
            }
            StForm::Named(name) => Bound::Value {
                var: push(vars, name.into(), st_type(&input.kind)),
                axis: false,
            },
            StForm::Key => {
                let name = pascal(input.key);
                if vars.iter().any(|(n, _)| folded(n) == folded(&name)) {
                    return None;
                }
                let axis = is_axis(input);
                let ty = if axis {
                    "AXIS_REF"
                } else {
                    st_type(&input.kind)
                };
                Bound::Value {
                    var: push(vars, name, ty),
                    axis,
                }
            }
        })
    }

    /// The declarations, as ST.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The blocks' names, in the order a host numbers them.
    pub fn names(&self) -> Vec<&'static str> {
        self.bindings.iter().map(|b| b.spec.name).collect()
    }
}

impl Default for Library {
    fn default() -> Self {
        Library::new()
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
        assert_eq!(unavailable(), Vec::new(), "every block is in the library");
        let p = crate::st::StProgram::from_texts(&[], 1).unwrap();
        assert_eq!(p.program().library_instances().len(), 0);
        assert!(lib.text().contains(
            "FUNCTION_BLOCK MC_MoveAbsolute\nVAR_INPUT\n    Axis : AXIS_REF;\n    Execute : BOOL;\n"
        ));
        assert!(lib.text().contains(
            "FUNCTION_BLOCK FiFoWrite\nVAR_INPUT\n    bExecute : BOOL;\n    tTimeout : TIME;\n    iChannelId : UDINT;\n    \
             AdrDataArray : POINTER TO LREAL;\n    iColDim : UDINT;\n    iRowsToWrite : UDINT;\n\
             END_VAR\nVAR_OUTPUT\n    bBusy : BOOL;\n    bErr : BOOL;\n    iErrId : UDINT;\n"
        ));
    }
}
