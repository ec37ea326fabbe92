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
use crate::timeline::registry::{BlockSpec, Inputs, Target, TimelineBlock, Value, Whole};
use hli::calls::fifo::{
    rows_header, FifoDimensionCall, FifoDisintegrateCall, FifoIntegrateCall, FifoOverrideCall,
    FifoOverrideType, FifoParametersCall, FifoReply, FifoStartCall, FifoStopCall,
    FIFO_BLOCK_VALUES,
};
use hli::calls::AcyclicCall;
use hli::layout::FIFO_OVERRIDE_FULL;
use hli::rpc::PendingCall;
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

/// The inputs of a FIFO call.
#[derive(Debug, Clone, Default, PartialEq)]
struct FifoInputs {
    group: u32,
    group_position: u32,
    override_ppm: u32,
    params: FifoParametersCall,
    rows: Arc<[f64]>,
    columns: u32,
}

fn allowed(kind: &str) -> &'static [&'static str] {
    match kind {
        "FiFoGroupIntegrate" => &["group", "group_position"],
        "FiFoWrite" | "FiFoOverwrite" => &["group", "rows"],
        "FiFoSetChannelOverride" => &["group", "override"],
        "FiFoSetParameters" => &["group", "fifo_cycle_ms", "override_type", "pt2_t0_ms"],
        _ => &["group"],
    }
}

/// Checks the inputs of a FIFO `call` table (`block`, `instance`, `axis`, `execute` are the
/// caller's).
fn parse(kind: &str, table: &toml::Table) -> Result<FifoInputs, String> {
    let mut inputs = FifoInputs {
        params: FifoParametersCall {
            fifo_cycle_s: 0.001,
            pt2_t0_s: 0.0,
            override_type: FifoOverrideType::Instant.raw(),
            reserved: 0,
        },
        ..FifoInputs::default()
    };
    let known = allowed(kind);
    for (key, value) in table {
        if crate::timeline::registry::CALL_KEYS.contains(&key.as_str()) {
            continue;
        }
        if !known.contains(&key.as_str()) {
            return Err(format!(
                "call: {kind} has no input `{key}` (inputs: {})",
                known.join(", ")
            ));
        }
        let bad = |what: &str| format!("call: {kind} input `{key}` = {value}: {what}");
        let number = match value {
            toml::Value::Float(f) => Some(*f),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        };
        match key.as_str() {
            "group" => {
                inputs.group = value
                    .as_integer()
                    .filter(|g| (0..8).contains(g))
                    .ok_or_else(|| bad("a gpFifo index 0..=7"))?
                    as u32
            }
            "group_position" => {
                inputs.group_position = value
                    .as_integer()
                    .filter(|p| (1..=16).contains(p))
                    .ok_or_else(|| bad("a column 1..=16"))?
                    as u32
            }
            "override" => {
                let percent = number
                    .filter(|p| (0.0..=100.0).contains(p))
                    .ok_or_else(|| bad("percent, 0 to 100"))?;
                inputs.override_ppm =
                    (percent / 100.0 * f64::from(FIFO_OVERRIDE_FULL)).round() as u32
            }
            "fifo_cycle_ms" => {
                inputs.params.fifo_cycle_s = number
                    .filter(|t| t.is_finite() && *t > 0.0)
                    .ok_or_else(|| bad("a time > 0"))?
                    * 1e-3
            }
            "pt2_t0_ms" => {
                inputs.params.pt2_t0_s = number
                    .filter(|t| t.is_finite() && *t > 0.0)
                    .ok_or_else(|| bad("a time > 0"))?
                    * 1e-3
            }
            "override_type" => {
                // By the wire enum's names, as written.
                let types = FifoOverrideType::ALL.iter();
                let given = types.clone().find(|t| value.as_str() == Some(t.name()));
                let names: Vec<String> = types.map(|t| format!("{:?}", t.name())).collect();
                let given = given.ok_or_else(|| bad(&names.join(" or ")))?;
                inputs.params.override_type = given.raw()
            }
            _ => {
                let (rows, columns) = rows_of(value).map_err(|e| bad(&e))?;
                inputs.rows = rows;
                inputs.columns = columns;
            }
        }
    }
    if kind == "FiFoGroupIntegrate" && inputs.group_position == 0 {
        return Err("call: FiFoGroupIntegrate needs `group_position` (1..=N)".into());
    }
    if matches!(kind, "FiFoWrite" | "FiFoOverwrite") && inputs.rows.is_empty() {
        return Err(format!("call: {kind} needs `rows` = [[..], ..]"));
    }
    Ok(inputs)
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

/// A FIFO block instance of a timeline.
#[derive(Debug)]
struct FifoInstance {
    /// Execute.
    execute: bool,
    /// The inputs of the last call.
    inputs: Arc<FifoInputs>,
    kind: Kind,
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
        let i = &*self.inputs;
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
            Kind::Write(b) => {
                let rows = i.rows.len() as u32 / i.columns.max(1);
                b.cycle(io, e, g, &i.rows, i.columns, rows)
            }
        }
    }
}

impl TimelineBlock for FifoInstance {
    timeline_timeout!();
    fn set(&mut self, _: &str, value: &Value) {
        if let Some(inputs) = value.custom::<FifoInputs>() {
            self.inputs = inputs;
        }
    }
    fn execute(&mut self) -> Option<&mut bool> {
        Some(&mut self.execute)
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

/// A call of `kind` checked whole.
fn checked(kind: &'static str, table: &toml::Table) -> Result<Whole, String> {
    Ok((Value::Custom(Arc::new(parse(kind, table)?)), None))
}

/// A FIFO block a timeline calls: on its group (`group`, an input), or also on an axis.
macro_rules! fifo_block {
    ($name:literal, $target:ident, $block:expr) => {
        BlockSpec {
            name: $name,
            target: Target::$target,
            execute: true,
            inputs: Inputs::Table(checked),
            make: |_| {
                Box::new(FifoInstance {
                    execute: false,
                    inputs: Arc::default(),
                    kind: $block,
                })
            },
        }
    };
}

/// The FIFO blocks a timeline calls; of them only FiFoGroupIntegrate names an axis.
pub const TIMELINE: &[BlockSpec] = &[
    fifo_block!(
        "FiFoGetDimension",
        Group,
        Kind::Dimension(FifoGetDimension::default())
    ),
    fifo_block!(
        "FiFoGroupIntegrate",
        Axis,
        Kind::Integrate(FifoGroupIntegrate::default())
    ),
    fifo_block!(
        "FiFoGroupDisintegrate",
        Group,
        Kind::Disintegrate(FifoGroupDisintegrate::default())
    ),
    fifo_block!("FiFoWrite", Group, Kind::Write(FifoWrite::default())),
    fifo_block!("FiFoOverwrite", Group, Kind::Write(FifoWrite::overwrite())),
    fifo_block!("FiFoStart", Group, Kind::Start(FifoStart::default())),
    fifo_block!("FiFoStop", Group, Kind::Stop(FifoStop::default())),
    fifo_block!(
        "FiFoSetChannelOverride",
        Group,
        Kind::Override(FifoSetChannelOverride::default())
    ),
    fifo_block!(
        "FiFoSetParameters",
        Group,
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
        let parsed = |text: &str| super::parse("FiFoSetParameters", &toml::from_str(text).unwrap());
        let i = parsed("override_type = \"pt2\"\npt2_t0_ms = 20").unwrap();
        assert_eq!(i.params.override_type, super::FifoOverrideType::Pt2.raw());
        assert_eq!(
            parsed("override_type = \"fast\"").unwrap_err(),
            "call: FiFoSetParameters input `override_type` = \"fast\": \"instant\" or \"pt2\""
        );
    }
}
