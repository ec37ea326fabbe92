//! The blocks a timeline calls by name. Each family registers its blocks in the `TIMELINE`
//! table at the end of its file in [`crate::blocks`]: name, what an instance addresses, the
//! inputs with their kinds, and the constructor; [`FAMILIES`] lists the tables, one line per
//! family. The instances, and the checks of a call against these declarations, are
//! [`super::instances`].
//!
//! Every block declares its inputs one way: a list of [`InputSpec`]s (the key under the
//! block's name for it, its [`Kind`], whether a call must give it), usually with the
//! `inputs!` macro of [`crate::blocks`], which also writes the block's `set`. A call's keys
//! meet the declared ones ignoring ASCII case and underscores (`RatioNumerator` is
//! `ratio_numerator`). Inputs keep their values from call to call, as a PLC block's do.

use crate::blocks::{
    cam, cam_compat, cam_data, cam_multi, cam_read, channel, fifo, motion, probe, saw,
};
use crate::kernel::Outputs;
use crate::runtime::PlcIo;
use hli::calls::cam::McMotionFunctionPoint;
use hli::enums::WireEnum;
use std::any::Any;
use std::sync::Arc;

/// The blocks of every family a timeline can call: one line per family.
pub const FAMILIES: &[&[BlockSpec]] = &[
    motion::TIMELINE,
    probe::TIMELINE,
    cam_data::TIMELINE,
    cam::TIMELINE,
    cam_read::TIMELINE,
    cam_multi::TIMELINE,
    cam_compat::TIMELINE,
    fifo::TIMELINE,
    saw::TIMELINE,
    channel::TIMELINE,
];

/// How a block's names read in Structured Text: PLCopen's (`Execute`, `Done`, `Busy`,
/// `Error`, `ErrorID`, ...) or the seeds' Hungarian ones of the FIFO and compatibility blocks
/// (`bExecute`; `bBusy`, `bErr`, `iErrId`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StStyle {
    /// PLCopen names.
    PlcOpen,
    /// The seeds' Hungarian names.
    Hungarian,
}

/// A block as a timeline knows it.
#[derive(Debug)]
pub struct BlockSpec {
    /// The name a `call` gives (ASCII case ignored).
    pub name: &'static str,
    /// What an instance addresses: how `axis` is read.
    pub target: Target,
    /// A call raises Execute (`execute = false` lowers it); false for MC_Power.
    pub execute: bool,
    /// The inputs a call may set.
    pub inputs: &'static [InputSpec],
    /// A fresh instance; `room` is the room of a read's answer, if the call gave one.
    pub make: fn(room: Option<usize>) -> Box<dyn TimelineBlock>,
    /// How its names read in Structured Text.
    pub style: StStyle,
}

impl BlockSpec {
    /// A block on an axis with an Execute input (most blocks).
    pub const fn on_axis(
        name: &'static str,
        inputs: &'static [InputSpec],
        make: fn(Option<usize>) -> Box<dyn TimelineBlock>,
    ) -> BlockSpec {
        BlockSpec::with_execute(name, Target::Axis, inputs, make)
    }

    /// A block with an Execute input on `target`.
    pub const fn with_execute(
        name: &'static str,
        target: Target,
        inputs: &'static [InputSpec],
        make: fn(Option<usize>) -> Box<dyn TimelineBlock>,
    ) -> BlockSpec {
        BlockSpec {
            name,
            target,
            execute: true,
            inputs,
            make,
            style: StStyle::PlcOpen,
        }
    }

    /// The same block with the seeds' Hungarian names in Structured Text.
    pub const fn hungarian(self) -> BlockSpec {
        BlockSpec {
            style: StStyle::Hungarian,
            ..self
        }
    }
}

/// What an instance addresses.
#[derive(Debug, Clone, Copy)]
pub enum Target {
    /// An axis: `axis`, its gpAx index.
    Axis,
    /// A FIFO group, given as an input: no `axis`.
    Group,
    /// An axis given as `axis` or as the input of this name (the seed's `Slave` of the
    /// flying-saw blocks; keys meet ignoring case and underscores); both given must agree.
    AxisNamed(&'static str),
    /// A channel, given as `channel` (its gpCh index), handed to the block as its `axis`.
    Channel,
}

/// The keys of a call every block takes (checked by [`super::instances`], beside the block's
/// declared inputs): `timeout_cycles` is the seed's tTimeout, in PLC cycles, of a block
/// that has it ([`TimelineBlock::timeout_cycles`]); `axis_id` addresses the block's axis by
/// its NC axis ID instead of `axis`, and `master_id` its master ([`TimelineBlock::set_master`]).
pub const CALL_KEYS: [&str; 7] = [
    "block",
    "instance",
    "axis",
    "execute",
    "timeout_cycles",
    "axis_id",
    "master_id",
];

/// An input of a block.
#[derive(Debug, Clone, Copy)]
pub struct InputSpec {
    /// Its key in a `call` (ASCII case and underscores do not matter).
    pub key: &'static str,
    /// What it takes.
    pub kind: Kind,
    /// Whether every call must give it (a master input may be given as `master_id`).
    pub required: bool,
    /// How it reads in Structured Text.
    pub st: StForm,
}

/// How an input reads in Structured Text.
#[derive(Debug, Clone, Copy)]
pub enum StForm {
    /// Its key in PascalCase (`master_offset` is `MasterOffset`).
    Key,
    /// Under this name (the seed's `iChannelId` for `group`).
    Named(&'static str),
    /// Rows of LREAL read through a pointer (the seed's FiFoWrite: `AdrdataArray`,
    /// `iColDim`, `iRowsToWrite`), at most `max` values: the block takes them with
    /// [`TimelineBlock::set_rows`].
    Rows {
        /// The pointer's name.
        data: &'static str,
        /// The columns' name.
        columns: &'static str,
        /// The rows' name.
        rows: &'static str,
        /// The name of the array's size in bytes, if the block declares it (the seed's
        /// `iSizeOfDataArray`): rows beyond it are refused by the block.
        size: Option<&'static str>,
        /// The most values a call takes.
        max: usize,
    },
    /// An array a read's answer goes into, through a pointer to its first LREAL and its size
    /// in bytes (the seed's CamTableReadData: `AdrDataArray`, `iSizeOfDataArray`).
    ReadAt {
        /// The pointer's name.
        data: &'static str,
        /// The size's name.
        size: &'static str,
    },
    /// The block's edge in two inputs (the seed's `bCoupleOn`, `bCoupleOff`): a rising edge
    /// of either is the command's (this input TRUE for the first), and the block has no
    /// Execute of its own.
    Edges {
        /// The name of the edge that gives this input TRUE.
        on: &'static str,
        /// The name of the edge that gives it FALSE.
        off: &'static str,
    },
    /// A list of IDs as separate inputs and a count (the seed's `iTableId1` .. `iTableId8`
    /// and `iNrOfMultiTables`).
    Ids {
        /// The count's name.
        count: &'static str,
        /// The IDs' names.
        ids: &'static [&'static str],
    },
    /// A table as the seed's `MC_CAM_REF` (000 5.1.16.2) under this name: the array's
    /// address, its size in bytes, the table type, rows and columns; the array (at most
    /// `max_bytes` of it) read from the program's memory at the edge into room the block
    /// makes at load ([`TimelineBlock::reserve_cam_ref`], [`TimelineBlock::set_cam_ref`]).
    CamRef {
        /// The structure's name (`CamTable`).
        name: &'static str,
        /// The most bytes of array a call takes.
        max_bytes: usize,
    },
    /// Not an input of its own in Structured Text (a table's points and type come with the
    /// [`StForm::CamRef`] of the block).
    Hidden,
    /// The seed's `MC_CAM_REF` under this name as the array a read's answer goes into
    /// (MC_ReadMotionFunction's and MC_ReadMotionFunctionValues' `CamTable`): the block
    /// checks its description when it reads ([`TimelineBlock::set_destination`]) and its
    /// answer is copied there when it is Done ([`TimelineBlock::read_bytes`]).
    ReadInto {
        /// The structure's name.
        name: &'static str,
    },
    /// A `STRING(len)` under this name (ChannelSelectProgram's `ProgramName`): the block
    /// takes its text with [`TimelineBlock::set_text`].
    Text {
        /// The input's name.
        name: &'static str,
        /// The most characters.
        len: u32,
    },
    /// A structure of the seeds' (the saw's `SyncMode : ST_SyncMode`) that gives this input
    /// and others: its name and type, the type's declaration, and how its fields become the
    /// block's inputs.
    Struct {
        /// The input's name.
        name: &'static str,
        /// Its type's name.
        ty: &'static str,
        /// The type's declaration (`TYPE .. END_TYPE`), given once in the library.
        declaration: &'static str,
        /// Its fields as the block's inputs.
        read: StructReader,
    },
}

/// How a structure input's fields become a block's inputs: `field(offset, bytes)` reads the
/// integer of `bytes` bytes at `offset` of the structure (as the library's declaration lays
/// it out), `set(key, value)` gives the block an input; `false` if a field's value is not
/// one the input takes (the command is refused). Does not allocate.
pub type StructReader =
    fn(field: &dyn Fn(u32, u8) -> Option<i64>, set: &mut dyn FnMut(&'static str, &Value)) -> bool;

/// What a read block shows in Structured Text as outputs of its own, after the standard ones
/// (MC_ReadCamTableSlaveDynamics' `SlavePosition` .., MC_CamInfo's `CamInfo`): each output's
/// name and type (elementary, or a structure `declaration` declares), filled when the read is
/// Done from [`TimelineBlock::result_values`], in the order of their elementary leaves.
#[derive(Debug, Clone, Copy)]
pub struct Results {
    /// Each output: name and ST type.
    pub outputs: &'static [(&'static str, &'static str)],
    /// The structure types they use (`TYPE .. END_TYPE`, given once), or "".
    pub declaration: &'static str,
    /// The name the declaration is known by (to give it once), or "".
    pub type_name: &'static str,
}

/// An `MC_CAM_REF` as a PLC program gives it: its description and the bytes of its array
/// (`array_size` of them, read from the program's memory; little-endian, as the program
/// holds them: LREAL rows `[master, slave]`, or 56-byte `MC_MotionFunctionPoint`s).
#[derive(Debug, Clone, Copy)]
pub struct CamRefIn<'a> {
    /// The array's bytes.
    pub bytes: &'a [u8],
    /// nArraySize.
    pub array_size: u32,
    /// nTableType (raw `MC_TableType`).
    pub table_type: u32,
    /// nNoOfRows.
    pub rows: u32,
    /// nNoOfCols.
    pub columns: u32,
}

/// An input `key` of kind `kind`.
pub const fn input(key: &'static str, kind: Kind) -> InputSpec {
    InputSpec {
        key,
        kind,
        required: false,
        st: StForm::Key,
    }
}

/// An input `key` of kind `kind` that every call gives.
pub const fn required(key: &'static str, kind: Kind) -> InputSpec {
    InputSpec {
        key,
        kind,
        required: true,
        st: StForm::Key,
    }
}

impl InputSpec {
    /// The same input under `name` in Structured Text.
    pub const fn st_named(self, name: &'static str) -> InputSpec {
        InputSpec {
            st: StForm::Named(name),
            ..self
        }
    }

    /// The same input in another form in Structured Text ([`StForm::Rows`],
    /// [`StForm::Struct`]).
    pub const fn st_form(self, form: StForm) -> InputSpec {
        InputSpec { st: form, ..self }
    }
}

/// A key without underscores, in lower case: how a call's keys meet the declared ones.
pub fn folded(key: &str) -> String {
    key.chars()
        .filter(|c| *c != '_')
        .collect::<String>()
        .to_ascii_lowercase()
}

/// The input lists `parts` one after the other, as one list of `N` inputs (a block's list
/// made of groups it shares with others).
pub const fn joined<const N: usize>(parts: &[&[InputSpec]]) -> [InputSpec; N] {
    let mut out = [input("", Kind::Bool); N];
    let (mut n, mut i) = (0, 0);
    while i < parts.len() {
        let mut j = 0;
        while j < parts[i].len() {
            out[n] = parts[i][j];
            (n, j) = (n + 1, j + 1);
        }
        i += 1;
    }
    assert!(n == N, "joined: the parts do not make N inputs");
    out
}

/// What an input takes, and the [`Value`] a block is set with.
#[derive(Debug, Clone, Copy)]
pub enum Kind {
    /// `true` or `false`: [`Value::Bool`].
    Bool,
    /// A finite number: [`Value::Real`].
    Real,
    /// An integer 0..u32::MAX (a table ID, an index, a mask): [`Value::Int`].
    Count,
    /// An integer `lo..=hi`: [`Value::Int`].
    Range(i64, i64),
    /// 0 (a default) or an integer `lo..=hi` (the seed's iBlockSize: 0 or at least a row's
    /// bytes): [`Value::Int`].
    ZeroOr(i64, i64),
    /// A finite number `lo..=hi`: [`Value::Real`].
    Between(f64, f64),
    /// A finite number above 0 (a time, a period): [`Value::Real`].
    Positive,
    /// A bit mask: the raw bits as an integer (sent as given), or a list of these flags'
    /// names, each with or without one of the prefixes (case and underscores do not
    /// matter): [`Value::Int`].
    Flags {
        /// `(name, bit)` of every flag.
        flags: &'static [(&'static str, u32)],
        /// The prefixes a name may carry (the seed's constant names), folded.
        prefixes: &'static [&'static str],
    },
    /// One of these values as written in TOML (a note may follow a space): [`Value::Int`].
    OneOf(&'static [(&'static str, i64)]),
    /// A wire enum by name or number ([`mode`]): [`Value::Int`], its raw value.
    Mode(Mode),
    /// The room of a read's answer, 1..=1048576: sizes the instance, is not set.
    Room,
    /// A shape of the family's, parsed by `parse`; `example` is a valid value in TOML.
    Parsed {
        /// The parser (its errors name the key).
        parse: fn(&toml::Value) -> Result<Value, String>,
        /// A valid value.
        example: &'static str,
    },
}

impl Kind {
    /// A valid value of this kind, as TOML (the lowest of a range, the first choice).
    pub fn example(&self) -> String {
        match self {
            Kind::Bool => "true".into(),
            Kind::Real => "1.5".into(),
            Kind::Count => "1".into(),
            Kind::Range(lo, _) => lo.to_string(),
            Kind::ZeroOr(..) => "0".into(),
            Kind::Between(lo, _) => format!("{lo:?}"),
            Kind::Positive => "2.0".into(),
            Kind::Flags { flags, .. } => format!("[{:?}]", flags[0].0),
            Kind::Room => "4".into(),
            Kind::OneOf(choices) => choices[0].0.split(' ').next().unwrap_or("").into(),
            Kind::Mode(m) => {
                let names = (m.names)();
                format!("{:?}", names.split(' ').next().unwrap_or(""))
            }
            Kind::Parsed { example, .. } => example.to_string(),
        }
    }
}

/// A wire enum seen through its names and numbers.
#[derive(Debug, Clone, Copy)]
pub struct Mode {
    /// The raw value of a name.
    pub from_name: fn(&str) -> Option<u32>,
    /// Whether a number is one of its values.
    pub valid: fn(u32) -> bool,
    /// Every value as `name (number)`.
    pub names: fn() -> String,
    /// The values the manuals' ST names: constant name and raw value.
    pub st_names: fn() -> Vec<(&'static str, u32)>,
}

/// The input kind of wire enum `E` (its names come with it from hli).
pub const fn mode<E: WireEnum>() -> Kind {
    fn from_name<E: WireEnum>(name: &str) -> Option<u32> {
        E::from_name(name).map(E::raw)
    }
    fn valid<E: WireEnum>(raw: u32) -> bool {
        E::from_raw(raw).is_some()
    }
    fn names<E: WireEnum>() -> String {
        let name = |v: &E| format!("{} ({})", v.name(), v.raw());
        E::ALL.iter().map(name).collect::<Vec<_>>().join(", ")
    }
    fn st_names<E: WireEnum>() -> Vec<(&'static str, u32)> {
        E::ALL
            .iter()
            .filter_map(|v| v.st_name().map(|n| (n, v.raw())))
            .collect()
    }
    Kind::Mode(Mode {
        from_name: from_name::<E>,
        valid: valid::<E>,
        names: names::<E>,
        st_names: st_names::<E>,
    })
}

/// A checked input value.
#[derive(Debug, Clone)]
pub enum Value {
    /// [`Kind::Bool`].
    Bool(bool),
    /// [`Kind::Real`].
    Real(f64),
    /// The integer kinds.
    Int(i64),
    /// Table rows `[master, slave]`.
    Rows(Arc<[[f64; 2]]>),
    /// Motion-function points.
    Points(Arc<[McMotionFunctionPoint]>),
    /// Up to 8 table IDs, and how many.
    Ids([u32; 8], u32),
    /// A shape of a family's own ([`Kind::Parsed`]).
    Custom(Arc<dyn Any + Send + Sync>),
}

impl Value {
    /// An integer input's value as a `u32` (a count, a table ID, a mode's raw value).
    pub fn uint(&self) -> Option<u32> {
        match self {
            Value::Int(v) => Some(*v as u32),
            _ => None,
        }
    }

    /// A number input's value.
    pub fn real(&self) -> Option<f64> {
        match self {
            Value::Real(v) => Some(*v),
            _ => None,
        }
    }

    /// The family's own inputs, if they are a `T`.
    pub fn custom<T: Any + Send + Sync>(&self) -> Option<Arc<T>> {
        match self {
            Value::Custom(c) => Arc::clone(c).downcast().ok(),
            _ => None,
        }
    }
}

/// A field of a block that an input sets, from a value of the input's kind: the integer kinds
/// set a `u32`, [`Kind::Real`] an `f64`, [`Kind::Bool`] a `bool`. A value of another kind
/// (which the checks against the kinds do not let through) leaves it.
pub trait InputField {
    /// Takes `value` if it is of the field's kind.
    fn take(&mut self, value: &Value);
}

impl InputField for u32 {
    fn take(&mut self, value: &Value) {
        if let Some(v) = value.uint() {
            *self = v;
        }
    }
}

impl InputField for f64 {
    fn take(&mut self, value: &Value) {
        if let Some(v) = value.real() {
            *self = v;
        }
    }
}

impl InputField for bool {
    /// A [`Kind::Bool`], or an integer kind's 0 (false) or other value (true): a
    /// [`Kind::OneOf`] of two choices sets a flag.
    fn take(&mut self, value: &Value) {
        match value {
            Value::Bool(v) => *self = *v,
            Value::Int(v) => *self = *v != 0,
            _ => {}
        }
    }
}

/// A block instance a timeline calls.
pub trait TimelineBlock: core::fmt::Debug {
    /// Sets input `key` of the block's spec (its declared spelling) to `value`, of the key's
    /// kind.
    fn set(&mut self, key: &str, value: &Value);
    /// Execute, if the block has it.
    fn execute(&mut self) -> Option<&mut bool>;
    /// One PLC cycle for `axis` (0 for a group's block): the outputs to record (InSync
    /// where the report shows it) and Status.
    fn cycle(&mut self, io: &mut PlcIo<'_>, axis: u32) -> (Outputs, bool);
    /// What a read block read, as it stands, for the report.
    fn read(&self) -> Option<Vec<f64>> {
        None
    }
    /// Input tTimeout, in PLC cycles: `true` if the block has it (and took it).
    fn timeout_cycles(&mut self, _cycles: u64) -> bool {
        false
    }
    /// Rows of `columns` values (`rows` of them; `values` holds them row by row, or fewer
    /// when there were more than the block takes, which it then refuses): `true` if the
    /// block takes rows ([`StForm::Rows`]). Does not allocate.
    fn set_rows(&mut self, _values: &[f64], _columns: u32, _rows: u32) -> bool {
        false
    }
    /// The array a read's answer goes into (an `MC_CAM_REF`'s description; `bytes` empty):
    /// `true` if the block reads into one. The block checks the description against what it
    /// reads, with the seed's codes, when it runs.
    fn set_destination(&mut self, _array: &CamRefIn<'_>) -> bool {
        false
    }
    /// The last read's answer as the bytes a program's array holds it in (LREALs, or
    /// 56-byte `MC_MotionFunctionPoint`s), at most `out.len()` of them: the bytes written.
    fn read_bytes(&self, _out: &mut [u8]) -> usize {
        0
    }
    /// The outputs of its own a read block shows in Structured Text ([`Results`]).
    fn results(&self) -> Option<&'static Results> {
        None
    }
    /// The values of those outputs, leaf by leaf, into `out` (as many as fit): how many.
    /// Does not allocate.
    fn result_values(&self, _out: &mut [f64]) -> usize {
        0
    }
    /// Input `key` as text (a STRING's characters before its NUL): `false` if the block
    /// takes no text or refuses this one. Does not allocate.
    fn set_text(&mut self, _key: &str, _text: &[u8]) -> bool {
        false
    }
    /// Makes room for an `MC_CAM_REF`'s array of up to `bytes` bytes (at load): `true` if
    /// the block takes one ([`StForm::CamRef`]).
    fn reserve_cam_ref(&mut self, _bytes: usize) -> bool {
        false
    }
    /// An `MC_CAM_REF`'s table, copied into the room made at load (its description checked
    /// by the block when it runs, with the seed's codes): `false` if the block takes none or
    /// the array holds a value that is not finite. Does not allocate.
    fn set_cam_ref(&mut self, _table: &CamRefIn<'_>) -> bool {
        false
    }
    /// The master axis (gpAx index) of a coupling block: `true` if the block has one (and
    /// took it). A timeline's `master_id` is resolved to the index and set here every cycle.
    fn set_master(&mut self, _index: u32) -> bool {
        false
    }
}

/// A number, integer or float.
pub fn number(value: &toml::Value) -> Option<f64> {
    match value {
        toml::Value::Float(f) => Some(*f),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

/// Block families outside this crate, registered once per process ([`register_extension`]).
static EXTENSIONS: std::sync::OnceLock<&'static [&'static [BlockSpec]]> =
    std::sync::OnceLock::new();

/// Registers block families outside this crate (an extension engine's blocks), once per
/// process and before the first timeline is read. Registering the same families again is
/// allowed; others are refused, as is a block name that is taken (ASCII case ignored).
pub fn register_extension(families: &'static [&'static [BlockSpec]]) -> Result<(), String> {
    let new = || families.iter().flat_map(|f| f.iter());
    for (i, spec) in new().enumerate() {
        let taken = |b: &BlockSpec| b.name.eq_ignore_ascii_case(spec.name);
        if FAMILIES.iter().flat_map(|f| f.iter()).any(taken) || new().take(i).any(taken) {
            return Err(format!("block {}: the name is taken", spec.name));
        }
    }
    let set = EXTENSIONS.get_or_init(|| families);
    if core::ptr::eq(*set, families) {
        Ok(())
    } else {
        Err("other extension block families are registered already".into())
    }
}

/// Every block a timeline can call: the built-in families', then the registered extensions'.
pub fn blocks() -> impl Iterator<Item = &'static BlockSpec> {
    let extensions: &'static [&'static [BlockSpec]] = EXTENSIONS.get().copied().unwrap_or(&[]);
    FAMILIES
        .iter()
        .chain(extensions)
        .flat_map(|family| family.iter())
}

/// The block called `name` (ASCII case ignored).
pub fn find(name: &str) -> Result<&'static BlockSpec, String> {
    blocks()
        .find(|b| b.name.eq_ignore_ascii_case(name))
        .ok_or_else(|| {
            let known: Vec<&str> = blocks().map(|b| b.name).collect();
            format!("call: unknown block {name:?} (known: {})", known.join(", "))
        })
}

#[cfg(test)]
mod tests;
