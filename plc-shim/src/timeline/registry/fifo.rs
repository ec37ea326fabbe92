//! The FIFO blocks in a timeline: their inputs from a `call` table and one instance of each
//! kind, called once per cycle like the other blocks.
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

use crate::blocks::fifo::{
    FifoGetDimension, FifoGroupDisintegrate, FifoGroupIntegrate, FifoSetChannelOverride,
    FifoSetParameters, FifoStart, FifoStop, FifoWrite,
};
use crate::kernel::Outputs;
use crate::runtime::PlcIo;
use hli::calls::fifo::{
    FifoDimensionCall, FifoDisintegrateCall, FifoIntegrateCall, FifoOverrideCall, FifoOverrideType,
    FifoParametersCall, FifoReply, FifoStartCall, FifoStopCall, FIFO_BLOCK_VALUES,
};
use hli::layout::FIFO_OVERRIDE_FULL;
use std::sync::Arc;

/// The FIFO blocks a timeline can call: 9 entries of [`super::BLOCKS`] from index 36.
pub(super) const FIFO_BLOCKS: &[&str] = super::BLOCKS.as_slice().split_at(36).1.split_at(9).0;
const _: () = assert!(FIFO_BLOCKS.len() == 9);

/// The inputs of a FIFO call.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct FifoInputs {
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
pub(super) fn parse(kind: &str, table: &toml::Table) -> Result<FifoInputs, String> {
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
        if ["block", "instance", "axis", "execute"].contains(&key.as_str()) {
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
                inputs.params.override_type = match value.as_str() {
                    Some("instant") => FifoOverrideType::Instant.raw(),
                    Some("pt2") => FifoOverrideType::Pt2.raw(),
                    _ => return Err(bad("\"instant\" or \"pt2\"")),
                }
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
pub(crate) struct FifoInstance {
    /// Execute.
    pub(crate) execute: bool,
    /// The inputs of the last call.
    pub(crate) inputs: Arc<FifoInputs>,
    kind: Kind,
}

impl FifoInstance {
    /// An instance of `kind` (one of [`FIFO_BLOCKS`]).
    pub(super) fn new(kind: &str) -> FifoInstance {
        let kind = match kind {
            "FiFoGetDimension" => Kind::Dimension(FifoGetDimension::default()),
            "FiFoGroupIntegrate" => Kind::Integrate(FifoGroupIntegrate::default()),
            "FiFoGroupDisintegrate" => Kind::Disintegrate(FifoGroupDisintegrate::default()),
            "FiFoStart" => Kind::Start(FifoStart::default()),
            "FiFoStop" => Kind::Stop(FifoStop::default()),
            "FiFoSetChannelOverride" => Kind::Override(FifoSetChannelOverride::default()),
            "FiFoSetParameters" => Kind::Parameters(FifoSetParameters::default()),
            "FiFoOverwrite" => Kind::Write(FifoWrite::overwrite()),
            _ => Kind::Write(FifoWrite::default()),
        };
        FifoInstance {
            execute: false,
            inputs: Arc::default(),
            kind,
        }
    }

    /// One cycle; `axis` is FiFoGroupIntegrate's.
    pub(super) fn call(&mut self, io: &mut PlcIo<'_>, axis: u32) -> Outputs<FifoReply> {
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
