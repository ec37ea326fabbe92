//! The FIFO blocks of seed 002 chapter 7 for the PLC program: FiFoGetDimension,
//! FiFoGroupIntegrate, FiFoGroupDisintegrate, FiFoWrite, FiFoOverwrite, FiFoStart, FiFoStop,
//! FiFoSetChannelOverride, our FiFoSetParameters, and the library version function, on the
//! block kernel ([`crate::kernel`]: its Execute, timeout and output rules). Each sends on the
//! rising Execute edge without waiting, is Busy until the CNC answers, then Done or Error
//! (with the CNC's code, [`hli::calls::fifo::FifoError`] or [`hli::enums::AxisError`]). No answer
//! within the timeout (the seed's tTimeout; default 1000 cycles) is an Error with
//! [`crate::kernel::ERROR_NO_ANSWER`]: the call may still have been executed.
//!
//! FiFoWrite and FiFoOverwrite send a row block on the row service: the rows are written
//! once, straight into the shared memory the CNC reads (seed: `AdrdataArray`, `iColDim`,
//! `iRowsToWrite`). A block the FIFO cannot take whole is refused whole (`Full`): offer it
//! again later; [`PlcView::fifo_group`](hli::views::PlcView::fifo_group) tells the free rows.
//!
//! In a timeline ([`TIMELINE`]) a FIFO block addresses its group (`group`); of them only
//! FiFoGroupIntegrate names an axis:
//!
//! ```toml
//! [[step]]
//! call = { block = "FiFoGroupIntegrate", instance = "in_x", axis = 0, group_position = 1 }
//! [[step]]
//! call = { block = "FiFoWrite", instance = "w", group = 0,
//!          rows = [[0.0, 0.0, 0.0], [0.1, 0.0, -0.1]] }
//! [[step]]
//! call = { block = "FiFoSetChannelOverride", instance = "ov", override = 50.0 }   # percent
//! ```

use crate::kernel::{
    call_error_code, no_follow, send, Accept, InFlight, Kernel, Outputs, PendingBulk,
};
use crate::runtime::PlcIo;
use crate::timeline::registry::{
    input, mode, required, BlockSpec, InputSpec, Kind as InputKind, StForm, Target, TimelineBlock,
    Value,
};
use hli::calls::fifo::{
    rows_header, FifoDimensionCall, FifoDisintegrateCall, FifoIntegrateCall, FifoOverrideCall,
    FifoOverrideType, FifoParametersCall, FifoReply, FifoStartCall, FifoStopCall,
    FIFO_BLOCK_VALUES,
};
use hli::calls::AcyclicCall;
use hli::layout::FIFO_OVERRIDE_FULL;
use hli_transport::rpc::PendingCall;
use std::sync::Arc;

/// Version of this block library (seed 7.9, Get_TcNcFifoAxis_Version).
pub fn fifo_library_version() -> &'static str {
    concat!("cncplc-fifo ", env!("CARGO_PKG_VERSION"))
}

/// Error id of a row block that does not fit one call (more than
/// [`FIFO_BLOCK_VALUES`] values, or rows x columns not the slice given): refused in the PLC.
pub const ERROR_BLOCK_SIZE: u32 = hli::calls::fifo::FifoError::BlockSize.raw();

/// The CNC's answer to a FIFO call: Done with its reply, or Error with its code (the reply
/// beside it: the FIFO's state and fill level).
fn accept(reply: FifoReply) -> Accept<(), FifoReply> {
    if reply.error_id != 0 {
        Accept::Failed(reply.error_id, reply)
    } else {
        Accept::Done(reply)
    }
}

/// A FIFO block: what it sends on its Execute edge (`P`: a call on its way, or a row block)
/// is answered with a FifoReply, which its outputs carry as their extra: the FIFO's state,
/// fill level, and FiFoGetDimension's values.
pub struct FifoBlock<P> {
    kernel: Kernel<P, (), FifoReply>,
}

impl<P> Default for FifoBlock<P> {
    fn default() -> Self {
        Self {
            kernel: Kernel::default(),
        }
    }
}

impl<P> core::fmt::Debug for FifoBlock<P> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.kernel.fmt(f)
    }
}

impl<P: InFlight<Reply = FifoReply, Buffer = ()>> FifoBlock<P> {
    timeout_input!(kernel);

    /// One cycle: on a rising `execute`, `send` puts the call or the rows on their way.
    fn run(
        &mut self,
        io: &mut PlcIo<'_>,
        execute: bool,
        send: impl FnOnce(&mut PlcIo<'_>) -> Result<P, u32>,
    ) -> Outputs<FifoReply> {
        self.kernel.cycle(io, execute, send, accept, no_follow)
    }
}

impl<C: AcyclicCall<Reply = FifoReply>> FifoBlock<PendingCall<C>> {
    /// One cycle: on a rising `execute`, `call()` goes to FIFO group `group`.
    pub fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        execute: bool,
        group: u32,
        call: impl FnOnce() -> C,
    ) -> Outputs<FifoReply> {
        self.run(io, execute, |io| send(io, group, &call()))
    }
}

/// FiFoGetDimension: `reply.dimension` (iNoOfAxes) and `reply.capacity` (iNoOfFifoEntries).
pub type FifoGetDimension = FifoBlock<PendingCall<FifoDimensionCall>>;
/// FiFoGroupIntegrate.
pub type FifoGroupIntegrate = FifoBlock<PendingCall<FifoIntegrateCall>>;
/// FiFoGroupDisintegrate.
pub type FifoGroupDisintegrate = FifoBlock<PendingCall<FifoDisintegrateCall>>;
/// FiFoStart.
pub type FifoStart = FifoBlock<PendingCall<FifoStartCall>>;
/// FiFoStop.
pub type FifoStop = FifoBlock<PendingCall<FifoStopCall>>;
/// FiFoSetChannelOverride (ppm, 1,000,000 = 100 %).
pub type FifoSetChannelOverride = FifoBlock<PendingCall<FifoOverrideCall>>;
/// FiFoSetParameters (ours): T_f and the override type while the group is not running.
pub type FifoSetParameters = FifoBlock<PendingCall<FifoParametersCall>>;

/// FiFoWrite (`overwrite` false) or FiFoOverwrite (true).
#[derive(Debug, Default)]
pub struct FifoWrite {
    /// FiFoOverwrite: replace the rows queued behind the pair in use.
    pub overwrite: bool,
    block: FifoBlock<PendingBulk<FifoReply>>,
}

impl FifoWrite {
    /// FiFoOverwrite.
    pub fn overwrite() -> FifoWrite {
        FifoWrite {
            overwrite: true,
            ..FifoWrite::default()
        }
    }

    timeout_input!(block.kernel);

    /// One cycle: on a rising `execute`, the first `rows` rows of `data` (rows of `columns`
    /// values, row after row: iColDim, iRowsToWrite) go to group `group`.
    pub fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        execute: bool,
        group: u32,
        data: &[f64],
        columns: u32,
        rows: u32,
    ) -> Outputs<FifoReply> {
        let overwrite = self.overwrite;
        let send = |io: &mut PlcIo<'_>| {
            let values = (columns as usize).checked_mul(rows as usize);
            match values {
                Some(n) if n <= data.len() && n <= FIFO_BLOCK_VALUES => {
                    let header = rows_header(group, columns, rows, overwrite);
                    io.acyclic
                        .start_rows(header, &data[..n])
                        .map(PendingBulk::new)
                        .map_err(|e| call_error_code(&e))
                }
                _ => Err(ERROR_BLOCK_SIZE),
            }
        };
        self.block.run(io, execute, send)
    }
}

/// The inputs of a FIFO instance: what its calls set so far.
#[derive(Debug, Clone, PartialEq)]
struct FifoInputs {
    group: u32,
    group_position: u32,
    override_ppm: u32,
    params: FifoParametersCall,
    rows: Arc<[f64]>,
    columns: u32,
}

impl Default for FifoInputs {
    /// Group 0, a FIFO cycle of 1 ms and the instant override (FiFoSetParameters' defaults).
    fn default() -> Self {
        FifoInputs {
            group: 0,
            group_position: 0,
            override_ppm: 0,
            params: FifoParametersCall {
                fifo_cycle_s: 0.001,
                pt2_t0_s: 0.0,
                override_type: FifoOverrideType::Instant.raw(),
                reserved: 0,
            },
            rows: Arc::from([]),
            columns: 0,
        }
    }
}

impl FifoInputs {
    /// Sets input `key` (one of the lists below).
    fn set(&mut self, key: &str, value: &Value) {
        let (int, real) = (value.uint(), value.real());
        match (key, int, real) {
            ("group", Some(g), _) => self.group = g,
            ("group_position", Some(p), _) => self.group_position = p,
            ("override_type", Some(t), _) => self.params.override_type = t,
            ("override", _, Some(percent)) => {
                self.override_ppm = (percent / 100.0 * f64::from(FIFO_OVERRIDE_FULL)).round() as u32
            }
            ("fifo_cycle_ms", _, Some(ms)) => self.params.fifo_cycle_s = ms * 1e-3,
            ("pt2_t0_ms", _, Some(ms)) => self.params.pt2_t0_s = ms * 1e-3,
            ("rows", _, _) => {
                if let Some(rows) = value.custom::<FifoRows>() {
                    (self.rows, self.columns) = (Arc::clone(&rows.values), rows.columns);
                }
            }
            _ => {}
        }
    }
}

/// `gpFifo[group]`: every FIFO block's.
const GROUP: InputSpec = input("group", InputKind::Range(0, 7)).st_named("iChannelId");
/// The FIFO blocks' inputs, block by block.
const GROUP_ONLY: &[InputSpec] = &[GROUP];
const INTEGRATE: &[InputSpec] = &[
    GROUP,
    required("group_position", InputKind::Range(1, 16)).st_named("iGroupPosition"),
];
/// FiFoWrite's rows in ST, as the seed declares them: a pointer to the first value of an
/// `ARRAY[ROWS, COLUMNS] OF LREAL`, its columns, the rows to write.
const ST_ROWS: StForm = StForm::Rows {
    data: "AdrDataArray",
    columns: "iColDim",
    rows: "iRowsToWrite",
    size: None,
    max: FIFO_BLOCK_VALUES,
};
const WRITE: &[InputSpec] = &[
    GROUP,
    required(
        "rows",
        InputKind::Parsed {
            parse: |v| {
                let (values, columns) =
                    rows_of(v).map_err(|e| format!("call: `rows` = {v}: {e}"))?;
                Ok(Value::Custom(Arc::new(FifoRows { values, columns })))
            },
            example: "[[1.0, 2.0], [3.0, 4.0]]",
        },
    )
    .st_form(ST_ROWS),
];
const OVERRIDE: &[InputSpec] = &[
    GROUP,
    input("override", InputKind::Between(0.0, 100.0)).st_named("iOverride"),
];
const PARAMETERS: &[InputSpec] = &[
    GROUP,
    input("fifo_cycle_ms", InputKind::Positive),
    input("override_type", mode::<FifoOverrideType>()),
    input("pt2_t0_ms", InputKind::Positive),
];

/// FiFoWrite's rows: the values row by row, and how many columns a row has.
#[derive(Debug)]
struct FifoRows {
    values: Arc<[f64]>,
    columns: u32,
}

/// `rows = [[a, b, c], ...]`: equal lengths, finite numbers, one block's worth at most.
fn rows_of(value: &toml::Value) -> Result<(Arc<[f64]>, u32), String> {
    let list = value
        .as_array()
        .ok_or("rows of equal length of finite numbers")?;
    let mut values = Vec::new();
    let mut columns = None;
    for row in list {
        let row = row.as_array().ok_or("each row is an array")?;
        if *columns.get_or_insert(row.len()) != row.len() || row.is_empty() {
            return Err("rows of equal length, not empty".into());
        }
        for v in row {
            let v = match v {
                toml::Value::Float(f) => *f,
                toml::Value::Integer(i) => *i as f64,
                _ => return Err("numbers only".into()),
            };
            if !v.is_finite() {
                return Err("finite numbers only".into());
            }
            values.push(v);
        }
    }
    if values.len() > FIFO_BLOCK_VALUES {
        return Err(format!("at most {FIFO_BLOCK_VALUES} values per block"));
    }
    Ok((values.into(), columns.unwrap_or(0) as u32))
}

/// The block of a FIFO instance.
#[derive(Debug)]
enum Kind {
    Dimension(FifoGetDimension),
    Integrate(FifoGroupIntegrate),
    Disintegrate(FifoGroupDisintegrate),
    Start(FifoStart),
    Stop(FifoStop),
    Override(FifoSetChannelOverride),
    Parameters(FifoSetParameters),
    Write(FifoWrite),
}

/// A FIFO block instance of a timeline or an ST program.
#[derive(Debug)]
struct FifoInstance {
    /// Execute.
    execute: bool,
    /// The inputs its calls set.
    inputs: FifoInputs,
    kind: Kind,
    /// FiFoWrite's rows from an ST program (room for one block, made with the instance) and
    /// their columns and rows, once given ([`TimelineBlock::set_rows`]).
    data: Vec<f64>,
    shape: Option<(u32, u32)>,
}

impl FifoInstance {
    fn new(kind: Kind) -> FifoInstance {
        let room = if matches!(kind, Kind::Write(_)) {
            FIFO_BLOCK_VALUES
        } else {
            0
        };
        FifoInstance {
            execute: false,
            inputs: FifoInputs::default(),
            kind,
            data: Vec::with_capacity(room),
            shape: None,
        }
    }
}

impl FifoInstance {
    /// Input tTimeout of whichever block this is.
    fn set_timeout_cycles(&mut self, cycles: u64) {
        match &mut self.kind {
            Kind::Dimension(b) => b.set_timeout_cycles(cycles),
            Kind::Integrate(b) => b.set_timeout_cycles(cycles),
            Kind::Disintegrate(b) => b.set_timeout_cycles(cycles),
            Kind::Start(b) => b.set_timeout_cycles(cycles),
            Kind::Stop(b) => b.set_timeout_cycles(cycles),
            Kind::Override(b) => b.set_timeout_cycles(cycles),
            Kind::Parameters(b) => b.set_timeout_cycles(cycles),
            Kind::Write(b) => b.set_timeout_cycles(cycles),
        }
    }

    /// One cycle; `axis` is FiFoGroupIntegrate's.
    fn call(&mut self, io: &mut PlcIo<'_>, axis: u32) -> Outputs<FifoReply> {
        let e = self.execute;
        let i = &self.inputs;
        let g = i.group;
        match &mut self.kind {
            Kind::Dimension(b) => b.cycle(io, e, g, FifoDimensionCall::default),
            Kind::Integrate(b) => b.cycle(io, e, g, || FifoIntegrateCall {
                axis,
                group_position: i.group_position,
            }),
            Kind::Disintegrate(b) => b.cycle(io, e, g, FifoDisintegrateCall::default),
            Kind::Start(b) => b.cycle(io, e, g, FifoStartCall::default),
            Kind::Stop(b) => b.cycle(io, e, g, FifoStopCall::default),
            Kind::Override(b) => b.cycle(io, e, g, || FifoOverrideCall {
                override_ppm: i.override_ppm,
            }),
            Kind::Parameters(b) => b.cycle(io, e, g, || i.params),
            Kind::Write(b) => match self.shape {
                Some((columns, rows)) => b.cycle(io, e, g, &self.data, columns, rows),
                None => {
                    let rows = i.rows.len() as u32 / i.columns.max(1);
                    b.cycle(io, e, g, &i.rows, i.columns, rows)
                }
            },
        }
    }
}

impl TimelineBlock for FifoInstance {
    timeline_timeout!();
    fn set(&mut self, key: &str, value: &Value) {
        if key == "rows" {
            self.shape = None;
        }
        self.inputs.set(key, value);
    }
    fn execute(&mut self) -> Option<&mut bool> {
        Some(&mut self.execute)
    }
    fn set_rows(&mut self, values: &[f64], columns: u32, rows: u32) -> bool {
        if !matches!(self.kind, Kind::Write(_)) {
            return false;
        }
        self.data.clear();
        let room = self.data.capacity();
        self.data
            .extend_from_slice(&values[..values.len().min(room)]);
        self.shape = Some((columns, rows));
        true
    }
    /// Done, Busy, Error and ErrorID (the reply is not recorded).
    fn cycle(&mut self, io: &mut PlcIo<'_>, axis: u32) -> (Outputs, bool) {
        let out = self.call(io, axis);
        let out = Outputs {
            done: out.done,
            busy: out.busy,
            error: out.error,
            error_id: out.error_id,
            ..Outputs::default()
        };
        (out, false)
    }
}

/// A FIFO block a timeline calls: on its group (`group`, an input), or also on an axis.
macro_rules! fifo_block {
    ($name:literal, $target:ident, $inputs:expr, $block:expr) => {
        BlockSpec {
            name: $name,
            target: Target::$target,
            execute: true,
            inputs: $inputs,
            make: |_| Box::new(FifoInstance::new($block)),
            style: crate::timeline::registry::StStyle::Hungarian,
        }
    };
}

/// The FIFO blocks a timeline calls; of them only FiFoGroupIntegrate names an axis.
pub const TIMELINE: &[BlockSpec] = &[
    fifo_block!(
        "FiFoGetDimension",
        Group,
        GROUP_ONLY,
        Kind::Dimension(FifoGetDimension::default())
    ),
    fifo_block!(
        "FiFoGroupIntegrate",
        Axis,
        INTEGRATE,
        Kind::Integrate(FifoGroupIntegrate::default())
    ),
    fifo_block!(
        "FiFoGroupDisintegrate",
        Group,
        GROUP_ONLY,
        Kind::Disintegrate(FifoGroupDisintegrate::default())
    ),
    fifo_block!("FiFoWrite", Group, WRITE, Kind::Write(FifoWrite::default())),
    fifo_block!(
        "FiFoOverwrite",
        Group,
        WRITE,
        Kind::Write(FifoWrite::overwrite())
    ),
    fifo_block!(
        "FiFoStart",
        Group,
        GROUP_ONLY,
        Kind::Start(FifoStart::default())
    ),
    fifo_block!(
        "FiFoStop",
        Group,
        GROUP_ONLY,
        Kind::Stop(FifoStop::default())
    ),
    fifo_block!(
        "FiFoSetChannelOverride",
        Group,
        OVERRIDE,
        Kind::Override(FifoSetChannelOverride::default())
    ),
    fifo_block!(
        "FiFoSetParameters",
        Group,
        PARAMETERS,
        Kind::Parameters(FifoSetParameters::default())
    ),
];

#[cfg(test)]
mod tests {
    #[test]
    fn the_library_names_its_version() {
        let v = super::fifo_library_version();
        assert_eq!(v, concat!("cncplc-fifo ", env!("CARGO_PKG_VERSION")));
        assert!(v.len() <= 20, "fits the seed's STRING(20)");
    }

    #[test]
    fn the_override_type_goes_by_the_wire_enums_names() {
        use crate::timeline::instances::inputs_of;
        use crate::timeline::registry::find;
        let parsed = |text: &str| {
            let spec = find("FiFoSetParameters").unwrap();
            let (inputs, _, _) = inputs_of(spec, &toml::from_str(text).unwrap())?;
            let mut i = super::FifoInputs::default();
            inputs.iter().for_each(|(k, v)| i.set(k, v));
            Ok::<_, String>(i)
        };
        let i = parsed("override_type = \"pt2\"\npt2_t0_ms = 20").unwrap();
        assert_eq!(i.params.override_type, super::FifoOverrideType::Pt2.raw());
        assert_eq!(i.params.pt2_t0_s, 0.02);
        assert!(parsed("override_type = \"fast\"")
            .unwrap_err()
            .contains("known are instant (0), pt2 (1)"));
    }
}
