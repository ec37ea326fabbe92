//! Function-block instances a timeline calls by name: the PLCopen motion blocks of
//! [`crate::blocks::motion`], each instance bound to one axis, called once per PLC cycle like a PLC
//! program calls its instances, with the edges of its outputs recorded for the report.
//!
//! ```toml
//! [[step]]
//! call = { block = "MC_Power", instance = "power_x", axis = 0, enable = true }
//! [[step]]
//! wait = "power_x.Status"                  # ready once this output is TRUE
//! call = { block = "MC_MoveAbsolute", instance = "move_x", axis = 0, position = 100.0,
//!          velocity = 200.0, acceleration = 2000.0, deceleration = 2000.0, jerk = 50000.0 }
//! ```
//!
//! The cam blocks of [`crate::blocks::cam`] take the slave as `axis` and name the master and the
//! table; modes are given by number or by name:
//!
//! ```toml
//! [[step]]
//! call = { block = "MC_CamIn", instance = "cam", axis = 1, master = 0, table = 1,
//!          start_mode = "absolute", slave_scaling = 2.0 }
//! [[step]]
//! wait = "cam.InSync"
//! ```
//!
//! A call sets the given inputs and a rising edge on Execute (`execute = false` lowers it
//! instead, which releases MC_Stop). An instance called again while Execute is TRUE sees it
//! FALSE for one cycle first, so every call is a new edge.

use crate::blocks::cam::{
    McCamIn, McCamOut, McCamScaling, McSetCamOnlineChangeMode, McWriteMotionFunctionPoint,
};
use crate::blocks::cam_compat::{CompatBlock, CompatConfig};
use crate::blocks::cam_data::{CamData, McCamTableSelect, McWriteMotionFunction};
use crate::blocks::cam_multi::{CamMultiTable, CamTableCoupleAxesMultiTables, CamTableSetWeight};
use crate::blocks::cam_read::{McCamRead, McReadMotionFunction, DEFAULT_READ_ROOM};
use crate::blocks::motion::{
    McHalt, McMoveAbsolute, McMoveRelative, McMoveVelocity, McPower, McReset, McStop,
};
use crate::kernel::Outputs;
use crate::runtime::PlcIo;
use fifo::{FifoInputs, FifoInstance, FIFO_BLOCKS};
use hli::calls::cam::McMotionFunctionPoint;
use saw::{SawInputs, SawInstance, SAW_BLOCKS};
use std::sync::Arc;

mod fifo;
mod saw;

/// The blocks a timeline can call.
pub const BLOCKS: [&str; 49] = [
    "MC_Power",
    "MC_Reset",
    "MC_MoveAbsolute",
    "MC_MoveRelative",
    "MC_MoveVelocity",
    "MC_Halt",
    "MC_Stop",
    "MC_CamTableSelect",
    "MC_CamIn",
    "MC_CamInExt",
    "MC_CamOut",
    "MC_CamScaling",
    "MC_WriteMotionFunctionPoint",
    "MC_SetCamOnlineChangeMode",
    "MC_WriteMotionFunction",
    "MC_ReadMotionFunction",
    "MC_ReadMotionFunctionPoint",
    "MC_ReadCamTableSlaveDynamics",
    "MC_ReadCamTableCharacteristics",
    "MC_ReadMotionFunctionValues",
    "MC_CamInfo",
    "CamTableSetWeight",
    "CamTableCoupleAxesMultiTables",
    "CamTableEnableCorrectionTable",
    "CamTableDeactivateCyclicTable",
    "CamTableGenerate",
    "CamTableCreate",
    "CamTableWriteData",
    "CamTableReadData",
    "CamTableReadSlavePos",
    "CamTableDelete",
    "CamTableCoupleAxes",
    "CamTableCoupleAxesIpol",
    "CamTableOffsetChange",
    "CamTableSetSlaveScale",
    "CamTableSetMasterSlaveScale",
    "FiFoGetDimension",
    "FiFoGroupIntegrate",
    "FiFoGroupDisintegrate",
    "FiFoWrite",
    "FiFoOverwrite",
    "FiFoStart",
    "FiFoStop",
    "FiFoSetChannelOverride",
    "FiFoSetParameters",
    "MC_GearInVelo",
    "MC_GearInPos",
    "MC_GearOut",
    "MC_ReadFlyingSawCharacteristics",
];

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

#[derive(Debug)]
enum Block {
    Power(McPower),
    Reset(McReset),
    MoveAbsolute(McMoveAbsolute),
    MoveRelative(McMoveRelative),
    MoveVelocity(McMoveVelocity),
    Halt(McHalt),
    Stop(McStop),
    CamTableSelect(McCamTableSelect),
    CamIn(Box<McCamIn>),
    CamOut(McCamOut),
    CamScaling(Box<McCamScaling>),
    WritePoint(Box<McWriteMotionFunctionPoint>),
    OnlineMode(Box<McSetCamOnlineChangeMode>),
    WriteFunction(Box<McWriteMotionFunction>),
    ReadFunction(Box<McReadMotionFunction>),
    Read(Box<McCamRead>),
    SetWeight(Box<CamTableSetWeight>),
    MultiCouple(Box<CamTableCoupleAxesMultiTables>),
    MultiTable(Box<CamMultiTable>),
    Compat(Box<CompatBlock>),
    Fifo(Box<FifoInstance>),
    Saw(Box<SawInstance>),
}

/// A boolean output of a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Output(usize);

/// One input value of a call.
#[derive(Debug, Clone, PartialEq)]
enum Input {
    Enable(bool),
    Position(f64),
    Distance(f64),
    Velocity(f64),
    Acceleration(f64),
    Deceleration(f64),
    Jerk(f64),
    Direction(i32),
    /// Cam blocks: master axis, table ID, mode numbers.
    Master(u32),
    Table(u32),
    StartMode(u32),
    ActivationMode(u32),
    MasterScalingMode(u32),
    SlaveScalingMode(u32),
    Interpolation(u32),
    ActivationPosition(f64),
    MasterOffset(f64),
    SlaveOffset(f64),
    MasterScaling(f64),
    SlaveScaling(f64),
    Periodic(bool),
    MasterAbsolute(bool),
    SlaveAbsolute(bool),
    /// MC_WriteMotionFunctionPoint: the point's fields.
    PointIndex(u32),
    FunctionType(u32),
    PointType(u32),
    RelIndexNext(u32),
    MasterPos(f64),
    SlavePos(f64),
    SlaveVelo(f64),
    SlaveAcc(f64),
    SlaveJerk(f64),
    /// Table data: rows, or motion-function points.
    Rows(Arc<[[f64; 2]]>),
    Points(Arc<[McMotionFunctionPoint]>),
    TableType(u32),
    /// Reads.
    NumPoints(u32),
    Room(usize),
    ValueSelectMask(u32),
    StartPosMaster(f64),
    EndPosMaster(f64),
    Increment(f64),
    MasterPosition(f64),
    AtMasterPosition(bool),
    /// Multi-table blocks.
    Weight(f64),
    MasterSlope(f64),
    SlaveSlope(f64),
    RangeLow(f64),
    RangeHigh(f64),
    TableIds([u32; 8], u32),
    Profiles(u32),
    On(bool),
    AtPosition(bool),
    /// MC_CamIn(Ext): follow the master's actual position.
    MasterActual(bool),
    /// A compatibility block's whole configuration.
    Compat(Arc<CompatConfig>),
    /// A FIFO block's inputs.
    Fifo(Arc<FifoInputs>),
    /// A flying-saw block's inputs.
    Saw(Arc<SawInputs>),
}

/// `rows = [[master, slave], ...]`.
pub(crate) fn rows_of(value: &toml::Value) -> Result<Arc<[[f64; 2]]>, String> {
    let bad = || "call: `rows` must be [[master, slave], ...] of finite numbers".to_string();
    let list = value.as_array().ok_or_else(bad)?;
    list.iter()
        .map(|row| match row.as_array().map(|r| r.as_slice()) {
            Some([m, s]) => match (number(m), number(s)) {
                (Some(m), Some(s)) if m.is_finite() && s.is_finite() => Ok([m, s]),
                _ => Err(bad()),
            },
            _ => Err(bad()),
        })
        .collect()
}

/// `points = [{ index = 1, function = 15, type = 1, master = 0.0, slave = 0.0, ... }, ...]`.
fn points_of(value: &toml::Value) -> Result<Arc<[McMotionFunctionPoint]>, String> {
    let list = value
        .as_array()
        .ok_or("call: `points` must be an array of point tables")?;
    list.iter()
        .enumerate()
        .map(|(i, p)| {
            let t = p
                .as_table()
                .ok_or_else(|| format!("call: points[{i}] is not a table"))?;
            let int = |k: &str, default: Option<u32>| -> Result<u32, String> {
                match t.get(k) {
                    Some(v) => v
                        .as_integer()
                        .filter(|v| (0..i64::from(u32::MAX)).contains(v))
                        .map(|v| v as u32)
                        .ok_or_else(|| format!("call: points[{i}].{k} = {v} is not valid")),
                    None => default.ok_or_else(|| format!("call: points[{i}].{k} is missing")),
                }
            };
            let num = |k: &str, required: bool| -> Result<f64, String> {
                match t.get(k) {
                    Some(v) => number(v)
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| format!("call: points[{i}].{k} = {v} is not valid")),
                    None if required => Err(format!("call: points[{i}].{k} is missing")),
                    None => Ok(0.0),
                }
            };
            for key in t.keys() {
                let known = [
                    "index",
                    "function",
                    "type",
                    "rel_index_next",
                    "master",
                    "slave",
                    "velocity",
                    "acceleration",
                    "jerk",
                ];
                if !known.contains(&key.as_str()) {
                    return Err(format!(
                        "call: points[{i}] has no field `{key}` (fields: {})",
                        known.join(", ")
                    ));
                }
            }
            Ok(McMotionFunctionPoint {
                point_index: int("index", None)?,
                function_type: int("function", None)?,
                point_type: int("type", None)?,
                rel_index_next_point: int("rel_index_next", Some(1))?,
                master_pos: num("master", true)?,
                slave_pos: num("slave", true)?,
                slave_velo: num("velocity", false)?,
                slave_acc: num("acceleration", false)?,
                slave_jerk: num("jerk", false)?,
            })
        })
        .collect()
}

/// A mode input by number or by its name.
fn mode(key: &str, value: &toml::Value) -> Result<u32, String> {
    let names: &[(&str, u32)] = match key {
        "start_mode" => &[
            ("absolute", 1),
            ("relative", 2),
            ("master_abs_slave_rel", 3),
            ("master_rel_slave_abs", 4),
        ],
        "activation_mode" => &[
            ("instantaneous", 0),
            ("at_master_cam_pos", 1),
            ("at_master_axis_pos", 2),
            ("next_cycle", 3),
            ("next_cycle_once", 4),
            ("as_soon_as_possible", 5),
            ("off", 6),
            ("delete_queued_data", 7),
        ],
        "interpolation" => &[("linear", 0), ("4point", 1), ("spline", 2)],
        _ => &[("user_defined", 0), ("auto_offset", 1), ("off", 2)],
    };
    let known = || {
        names
            .iter()
            .map(|(n, v)| format!("{n} ({v})"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match value {
        toml::Value::String(name) => names
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| *v)
            .ok_or_else(|| format!("call: `{key}` = {name:?}: known are {}", known())),
        toml::Value::Integer(i) if names.iter().any(|(_, v)| i64::from(*v) == *i) => Ok(*i as u32),
        _ => Err(format!("call: `{key}` = {value}: known are {}", known())),
    }
}

/// A call of an instance, checked.
#[derive(Debug, Clone)]
pub struct Call {
    instance: usize,
    inputs: Vec<Input>,
    execute: bool,
}

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
    kind: &'static str,
    axis: u32,
    /// False for FIFO blocks that address a group only.
    uses_axis: bool,
    block: Block,
    raise_next_cycle: bool,
    last: [bool; 8],
    edges: [Edge; 8],
    error_id: u32,
    /// Room of a read block's answer (made with the instance, never in a cycle).
    room: Option<usize>,
}

/// The instances of a timeline.
#[derive(Debug, Default)]
pub struct Instances {
    list: Vec<Instance>,
}

fn number(value: &toml::Value) -> Option<f64> {
    match value {
        toml::Value::Float(f) => Some(*f),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

impl Instances {
    /// Checks a `call` table and registers its instance (created on its first call); `Err`
    /// says which key is wrong.
    pub fn parse_call(&mut self, table: &toml::Table) -> Result<Call, String> {
        let text = |key: &str| -> Result<&str, String> {
            table
                .get(key)
                .and_then(toml::Value::as_str)
                .ok_or_else(|| format!("call: `{key}` (a string) is missing"))
        };
        let block = text("block")?;
        let kind = *BLOCKS
            .iter()
            .find(|b| b.eq_ignore_ascii_case(block))
            .ok_or_else(|| {
                format!(
                    "call: unknown block {block:?} (known: {})",
                    BLOCKS.join(", ")
                )
            })?;
        let name = table
            .get("instance")
            .and_then(toml::Value::as_str)
            .unwrap_or(kind);
        // The FIFO blocks address a group; of them only FiFoGroupIntegrate names an axis.
        let fifo = FIFO_BLOCKS.contains(&kind);
        let is_saw = SAW_BLOCKS.contains(&kind);
        let uses_axis = !fifo || kind == "FiFoGroupIntegrate";
        // The flying-saw blocks take their axis as the seed's `Slave` (or `axis`).
        let axis_value = match table.get("axis") {
            None if is_saw => saw::slave(table),
            given => given,
        };
        let axis = match axis_value.and_then(toml::Value::as_integer) {
            Some(a) if (0..i64::from(u32::MAX)).contains(&a) && uses_axis => a as u32,
            Some(a) if uses_axis => return Err(format!("call: axis {a} is not an axis index")),
            Some(_) => return Err(format!("call: {kind} addresses a FIFO group: no `axis`")),
            None if uses_axis => return Err("call: `axis` (the gpAx index) is missing".into()),
            None => 0,
        };
        let allowed: &[&str] = match kind {
            "MC_Power" => &["enable"],
            "MC_Reset" => &[],
            "MC_MoveAbsolute" => &[
                "position",
                "velocity",
                "acceleration",
                "deceleration",
                "jerk",
            ],
            "MC_MoveRelative" => &[
                "distance",
                "velocity",
                "acceleration",
                "deceleration",
                "jerk",
            ],
            "MC_MoveVelocity" => &[
                "velocity",
                "direction",
                "acceleration",
                "deceleration",
                "jerk",
            ],
            "MC_Halt" | "MC_Stop" => &["deceleration", "jerk"],
            "MC_CamTableSelect" => &[
                "table",
                "periodic",
                "master_absolute",
                "slave_absolute",
                "rows",
                "points",
                "table_type",
                "interpolation",
            ],
            "MC_WriteMotionFunction" => &["table", "points"],
            "MC_ReadMotionFunction" => &["table", "point_index", "num_points", "room"],
            "MC_ReadMotionFunctionPoint" => &["table", "point_index"],
            "MC_ReadCamTableSlaveDynamics" => &["table", "master_position"],
            "MC_ReadCamTableCharacteristics" => &["table"],
            "MC_ReadMotionFunctionValues" => &[
                "table",
                "value_select_mask",
                "start_pos_master",
                "end_pos_master",
                "increment",
                "room",
            ],
            "MC_CamInfo" => &["at_master_position", "master_position"],
            "CamTableSetWeight" => &[
                "table",
                "weight",
                "master_offset",
                "master_slope",
                "slave_offset",
                "slave_slope",
                "range_low",
                "range_high",
            ],
            "CamTableCoupleAxesMultiTables" => &["master", "tables", "profiles", "on"],
            "CamTableEnableCorrectionTable" => &["table", "at_position", "position"],
            "CamTableDeactivateCyclicTable" => &["table"],
            "MC_CamIn" => &[
                "master_source",
                "master",
                "table",
                "start_mode",
                "master_offset",
                "slave_offset",
                "master_scaling",
                "slave_scaling",
                "interpolation",
            ],
            "MC_CamInExt" => &[
                "master_source",
                "master",
                "table",
                "start_mode",
                "activation_mode",
                "activation_position",
                "master_scaling_mode",
                "slave_scaling_mode",
                "master_offset",
                "slave_offset",
                "master_scaling",
                "slave_scaling",
                "interpolation",
            ],
            "MC_CamScaling" => &[
                "activation_mode",
                "activation_position",
                "master_scaling_mode",
                "slave_scaling_mode",
                "master_offset",
                "slave_offset",
                "master_scaling",
                "slave_scaling",
            ],
            "MC_WriteMotionFunctionPoint" => &[
                "table",
                "point_index",
                "function_type",
                "point_type",
                "rel_index_next",
                "master_pos",
                "slave_pos",
                "slave_velo",
                "slave_acc",
                "slave_jerk",
            ],
            "MC_SetCamOnlineChangeMode" => &[
                "table",
                "activation_mode",
                "activation_position",
                "master_scaling_mode",
                "slave_scaling_mode",
            ],
            _ => &[],
        };
        let mut inputs = Vec::new();
        let mut execute = true;
        let compat = crate::blocks::cam_compat::COMPAT_BLOCKS
            .iter()
            .chain([crate::blocks::cam_compat::COMPAT_MASTER_SLAVE_SCALE].iter())
            .find(|b| **b == kind)
            .copied();
        if fifo {
            inputs.push(Input::Fifo(Arc::new(fifo::parse(kind, table)?)));
        }
        if is_saw {
            inputs.push(Input::Saw(Arc::new(saw::parse(kind, table)?)));
        }
        if let Some(kind) = compat {
            let config = crate::blocks::cam_compat::parse(kind, table)?;
            if kind == "CamTableReadData" {
                inputs.push(Input::Room(config.room));
            }
            inputs.push(Input::Compat(Arc::new(config)));
        }
        for (key, value) in table {
            if ["block", "instance", "axis"].contains(&key.as_str()) {
                continue;
            }
            if (compat.is_some() || fifo || is_saw) && key != "execute" {
                continue; // checked by cam_compat::parse or fifo::parse
            }
            if key == "execute" && kind != "MC_Power" {
                execute = value
                    .as_bool()
                    .ok_or_else(|| "call: `execute` must be true or false".to_string())?;
                continue;
            }
            if !allowed.contains(&key.as_str()) {
                return Err(format!(
                    "call: {kind} has no input `{key}` (inputs: {})",
                    if allowed.is_empty() {
                        "none".to_string()
                    } else {
                        allowed.join(", ")
                    }
                ));
            }
            let bad = || format!("call: {kind} input `{key}` = {value} is not valid");
            let input = match key.as_str() {
                "enable" => Input::Enable(value.as_bool().ok_or_else(bad)?),
                "direction" => match value.as_integer() {
                    Some(d @ (-1 | 1)) => Input::Direction(d as i32),
                    _ => return Err(format!("call: `direction` = {value}: 1 or -1")),
                },
                "point_index" | "function_type" | "point_type" | "rel_index_next" => {
                    let v = value
                        .as_integer()
                        .filter(|v| (0..i64::from(u32::MAX)).contains(v))
                        .ok_or_else(bad)? as u32;
                    match key.as_str() {
                        "point_index" => Input::PointIndex(v),
                        "function_type" => Input::FunctionType(v),
                        "point_type" => Input::PointType(v),
                        _ => Input::RelIndexNext(v),
                    }
                }
                "rows" => Input::Rows(rows_of(value)?),
                "points" => Input::Points(points_of(value)?),
                "table_type" => match value.as_integer() {
                    Some(t @ (10 | 11)) => Input::TableType(t as u32),
                    _ => {
                        return Err(format!(
                        "call: `table_type` = {value}: 10 (equidistant) or 11 (non-equidistant)"
                    ))
                    }
                },
                "num_points" | "value_select_mask" => {
                    let v = value
                        .as_integer()
                        .filter(|v| (0..i64::from(u32::MAX)).contains(v))
                        .ok_or_else(bad)? as u32;
                    if key == "num_points" {
                        Input::NumPoints(v)
                    } else {
                        Input::ValueSelectMask(v)
                    }
                }
                "room" => Input::Room(
                    value
                        .as_integer()
                        .filter(|v| (1..=1 << 20).contains(v))
                        .ok_or_else(|| format!("call: `room` = {value}: 1..=1048576"))?
                        as usize,
                ),
                "at_master_position" => Input::AtMasterPosition(value.as_bool().ok_or_else(bad)?),
                "on" => Input::On(value.as_bool().ok_or_else(bad)?),
                "master_source" => match value.as_str() {
                    Some("set_point") => Input::MasterActual(false),
                    Some("actual") => Input::MasterActual(true),
                    _ => {
                        return Err(format!(
                            "call: `master_source` = {value}: \"set_point\" or \"actual\""
                        ))
                    }
                },
                "at_position" => Input::AtPosition(value.as_bool().ok_or_else(bad)?),
                "profiles" => Input::Profiles(
                    value
                        .as_integer()
                        .filter(|v| (1..=8).contains(v))
                        .ok_or_else(|| format!("call: `profiles` = {value}: 1..=8"))?
                        as u32,
                ),
                "tables" => {
                    let list = value
                        .as_array()
                        .filter(|l| (1..=8).contains(&l.len()))
                        .ok_or_else(|| format!("call: `tables` = {value}: 1 to 8 table IDs"))?;
                    let mut ids = [0u32; 8];
                    for (slot, v) in ids.iter_mut().zip(list) {
                        *slot = v
                            .as_integer()
                            .filter(|v| (1..=255).contains(v))
                            .ok_or_else(|| format!("call: `tables`: {v} is not a table ID"))?
                            as u32;
                    }
                    Input::TableIds(ids, list.len() as u32)
                }
                "master" | "table" => {
                    let v = value
                        .as_integer()
                        .filter(|v| (0..i64::from(u32::MAX)).contains(v))
                        .ok_or_else(bad)? as u32;
                    if key == "master" {
                        Input::Master(v)
                    } else {
                        Input::Table(v)
                    }
                }
                "start_mode" => Input::StartMode(mode(key, value)?),
                "activation_mode" => Input::ActivationMode(mode(key, value)?),
                "master_scaling_mode" => Input::MasterScalingMode(mode(key, value)?),
                "slave_scaling_mode" => Input::SlaveScalingMode(mode(key, value)?),
                "interpolation" => Input::Interpolation(mode(key, value)?),
                "periodic" => Input::Periodic(value.as_bool().ok_or_else(bad)?),
                "master_absolute" => Input::MasterAbsolute(value.as_bool().ok_or_else(bad)?),
                "slave_absolute" => Input::SlaveAbsolute(value.as_bool().ok_or_else(bad)?),
                other => {
                    let v = number(value).filter(|v| v.is_finite()).ok_or_else(bad)?;
                    match other {
                        "position" => Input::Position(v),
                        "distance" => Input::Distance(v),
                        "velocity" => Input::Velocity(v),
                        "acceleration" => Input::Acceleration(v),
                        "deceleration" => Input::Deceleration(v),
                        "activation_position" => Input::ActivationPosition(v),
                        "master_offset" => Input::MasterOffset(v),
                        "slave_offset" => Input::SlaveOffset(v),
                        "master_scaling" => Input::MasterScaling(v),
                        "slave_scaling" => Input::SlaveScaling(v),
                        "master_pos" => Input::MasterPos(v),
                        "slave_pos" => Input::SlavePos(v),
                        "slave_velo" => Input::SlaveVelo(v),
                        "slave_acc" => Input::SlaveAcc(v),
                        "slave_jerk" => Input::SlaveJerk(v),
                        "start_pos_master" => Input::StartPosMaster(v),
                        "end_pos_master" => Input::EndPosMaster(v),
                        "increment" => Input::Increment(v),
                        "master_position" => Input::MasterPosition(v),
                        "weight" => Input::Weight(v),
                        "master_slope" => Input::MasterSlope(v),
                        "slave_slope" => Input::SlaveSlope(v),
                        "range_low" => Input::RangeLow(v),
                        "range_high" => Input::RangeHigh(v),
                        _ => Input::Jerk(v),
                    }
                }
            };
            inputs.push(input);
        }
        // The room of a read's answer is the instance's, made now (never in a PLC cycle).
        let room = inputs.iter().find_map(|i| match i {
            Input::Room(r) => Some(*r),
            _ => None,
        });
        inputs.retain(|i| !matches!(i, Input::Room(_)));
        let instance = match self.list.iter().position(|i| i.name == name) {
            Some(i) if self.list[i].kind != kind || self.list[i].axis != axis => {
                return Err(format!(
                    "call: instance {name:?} is a {} on axis {}, not a {kind} on axis {axis}",
                    self.list[i].kind, self.list[i].axis
                ))
            }
            Some(i) => {
                if let Some(r) = room.filter(|r| Some(*r) > self.list[i].room) {
                    self.list[i].room = Some(r);
                    self.list[i].block = new_block(kind, Some(r));
                }
                i
            }
            None => {
                self.list.push(Instance {
                    name: name.to_string(),
                    kind,
                    axis,
                    uses_axis,
                    block: new_block(kind, room),
                    raise_next_cycle: false,
                    last: [false; 8],
                    edges: [Edge::default(); 8],
                    error_id: 0,
                    room,
                });
                self.list.len() - 1
            }
        };
        Ok(Call {
            instance,
            inputs,
            execute,
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
                format!(
                    "wait: unknown output {output:?} (known: {})",
                    OUTPUTS.join(", ")
                )
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
            .filter(|i| i.uses_axis)
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
        for input in &call.inputs {
            set_input(&mut inst.block, input.clone());
        }
        inst.last = [false; 8];
        match execute_of(&mut inst.block) {
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
                if let Some(e) = execute_of(&mut inst.block) {
                    *e = true;
                }
            }
        }
    }

    /// Calls every instance once and records its output edges at CNC tick `tick`.
    pub fn call_all(&mut self, io: &mut PlcIo<'_>, tick: u64) {
        for inst in &mut self.list {
            let axis = inst.axis;
            let (out, status) = match &mut inst.block {
                Block::Power(b) => {
                    b.call(io, axis);
                    let out = Outputs {
                        error: b.error,
                        error_id: b.error_id,
                        ..Outputs::default()
                    };
                    (out, b.status)
                }
                Block::Reset(b) => {
                    b.call(io, axis);
                    (b.out, false)
                }
                Block::MoveAbsolute(b) => {
                    b.call(io, axis);
                    (b.out, false)
                }
                Block::MoveRelative(b) => {
                    b.call(io, axis);
                    (b.out, false)
                }
                Block::MoveVelocity(b) => {
                    b.call(io, axis);
                    (b.out, false)
                }
                Block::Halt(b) => {
                    b.call(io, axis);
                    (b.out, false)
                }
                Block::Stop(b) => {
                    b.call(io, axis);
                    (b.out, false)
                }
                Block::CamTableSelect(b) => {
                    b.call(io);
                    (cam_outputs(b.out), false)
                }
                Block::CamIn(b) => {
                    b.call(io, axis);
                    (cam_outputs(b.out), false)
                }
                Block::CamOut(b) => {
                    b.call(io, axis);
                    (cam_outputs(b.out), false)
                }
                Block::CamScaling(b) => {
                    b.call(io, axis);
                    (cam_outputs(b.out), false)
                }
                Block::WritePoint(b) => {
                    b.call(io);
                    (cam_outputs(b.out), false)
                }
                Block::OnlineMode(b) => {
                    b.call(io);
                    (cam_outputs(b.out), false)
                }
                Block::WriteFunction(b) => {
                    b.call(io);
                    (cam_outputs(b.out), false)
                }
                Block::ReadFunction(b) => {
                    b.call(io);
                    (cam_outputs(b.out), false)
                }
                Block::Read(b) => {
                    if b.request.what == hli::calls::cam::CAM_READ_INFO {
                        b.target = axis;
                    }
                    b.call(io);
                    (cam_outputs(b.out), false)
                }
                Block::SetWeight(b) => {
                    b.call(io);
                    (cam_outputs(b.out), false)
                }
                Block::MultiCouple(b) => {
                    b.call(io, axis);
                    (cam_outputs(b.out), false)
                }
                Block::MultiTable(b) => {
                    b.call(io, axis);
                    (cam_outputs(b.out), false)
                }
                Block::Compat(b) => {
                    b.call(io, axis);
                    (cam_outputs(b.out), false)
                }
                Block::Fifo(b) => {
                    let out = b.call(io, axis);
                    let out = Outputs {
                        done: out.done,
                        busy: out.busy,
                        error: out.error,
                        error_id: out.error_id,
                        ..Outputs::default()
                    };
                    (out, false)
                }
                Block::Saw(b) => (b.call(io, axis), false),
            };
            let in_sync = match &inst.block {
                Block::CamIn(b) => b.out.in_sync,
                Block::Saw(b) => b.in_sync(),
                _ => false,
            };
            let now = [
                out.done,
                out.busy,
                out.active,
                out.command_aborted,
                out.error,
                out.in_velocity,
                status,
                in_sync,
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
    /// that rose (`Busy 12 (x1), Done 341 (x1)`), with the last error id.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        for inst in &self.list {
            let edges: Vec<String> = OUTPUTS
                .iter()
                .zip(&inst.edges)
                .filter_map(|(name, e)| e.first.map(|t| format!("{name} {t} (x{})", e.count)))
                .collect();
            let target = if inst.uses_axis {
                format!(" on gpAx[{}]", inst.axis)
            } else {
                String::new()
            };
            out.push_str(&format!(
                "block {} ({}{target}): {}{}\n",
                inst.name,
                inst.kind,
                if edges.is_empty() {
                    "no output rose".to_string()
                } else {
                    edges.join(", ")
                },
                if inst.error_id != 0 {
                    format!(", ErrorID {:#06x}", inst.error_id)
                } else {
                    String::new()
                },
            ));
            // What a read block read, as it stands after the last cycle.
            let read: Option<Vec<f64>> = match &inst.block {
                Block::Read(b) => Some(b.values.clone()),
                Block::Compat(b) => Some(b.read.values.clone()),
                Block::ReadFunction(b) => Some(
                    b.points
                        .iter()
                        .flat_map(|p| [p.point_index as f64, p.master_pos, p.slave_pos])
                        .collect(),
                ),
                Block::Saw(b) => b.read_values(),
                _ => None,
            };
            if let Some(values) = read.filter(|v| !v.is_empty()) {
                let shown: Vec<String> = values.iter().take(12).map(|v| format!("{v}")).collect();
                out.push_str(&format!(
                    "  read {} value(s): {}{}\n",
                    values.len(),
                    shown.join(", "),
                    if values.len() > 12 { ", ..." } else { "" }
                ));
            }
        }
        out
    }
}

/// A clone has the same instances with fresh block states (a timeline is cloned before it
/// runs).
impl Clone for Instances {
    fn clone(&self) -> Self {
        Instances {
            list: self
                .list
                .iter()
                .map(|i| Instance {
                    name: i.name.clone(),
                    kind: i.kind,
                    axis: i.axis,
                    uses_axis: i.uses_axis,
                    block: new_block(i.kind, i.room),
                    raise_next_cycle: false,
                    last: [false; 8],
                    edges: [Edge::default(); 8],
                    error_id: 0,
                    room: i.room,
                })
                .collect(),
        }
    }
}

/// A cam block's outputs in the motion blocks' shape (InSync is recorded beside them).
fn cam_outputs(out: Outputs) -> Outputs {
    Outputs {
        active: false,
        in_velocity: false,
        in_sync: false,
        start_sync: false,
        ..out
    }
}

fn new_block(kind: &str, room: Option<usize>) -> Block {
    let room = room.unwrap_or(DEFAULT_READ_ROOM);
    match kind {
        "MC_Power" => Block::Power(McPower::default()),
        "MC_Reset" => Block::Reset(McReset::default()),
        "MC_MoveAbsolute" => Block::MoveAbsolute(McMoveAbsolute::default()),
        "MC_MoveRelative" => Block::MoveRelative(McMoveRelative::default()),
        "MC_MoveVelocity" => {
            let mut b = McMoveVelocity::default();
            b.direction = 1;
            Block::MoveVelocity(b)
        }
        "MC_Halt" => Block::Halt(McHalt::default()),
        "MC_CamTableSelect" => Block::CamTableSelect(McCamTableSelect::default()),
        "MC_CamIn" => Block::CamIn(Box::default()),
        "MC_CamInExt" => {
            let mut b = Box::<McCamIn>::default();
            b.extended = true;
            Block::CamIn(b)
        }
        "MC_CamOut" => Block::CamOut(McCamOut::default()),
        "MC_CamScaling" => Block::CamScaling(Box::default()),
        "MC_WriteMotionFunctionPoint" => Block::WritePoint(Box::default()),
        "MC_SetCamOnlineChangeMode" => Block::OnlineMode(Box::default()),
        "MC_WriteMotionFunction" => Block::WriteFunction(Box::default()),
        "MC_ReadMotionFunction" => Block::ReadFunction(Box::new(McReadMotionFunction::new(room))),
        "MC_ReadMotionFunctionPoint" => {
            let mut b = McReadMotionFunction::new(1);
            b.count = 1;
            Block::ReadFunction(Box::new(b))
        }
        "MC_ReadCamTableSlaveDynamics" => Block::Read(Box::new(McCamRead::new(
            hli::calls::cam::CAM_READ_SLAVE_DYNAMICS,
            3,
        ))),
        "MC_ReadCamTableCharacteristics" => Block::Read(Box::new(McCamRead::new(
            hli::calls::cam::CAM_READ_CHARACTERISTICS,
            31,
        ))),
        "MC_ReadMotionFunctionValues" => Block::Read(Box::new(McCamRead::new(
            hli::calls::cam::CAM_READ_VALUES,
            room,
        ))),
        "MC_CamInfo" => Block::Read(Box::new(McCamRead::new(hli::calls::cam::CAM_READ_INFO, 40))),
        "CamTableSetWeight" => Block::SetWeight(Box::default()),
        "CamTableCoupleAxesMultiTables" => {
            let mut b = Box::<CamTableCoupleAxesMultiTables>::default();
            b.on = true;
            Block::MultiCouple(b)
        }
        "CamTableEnableCorrectionTable" => {
            let mut b = Box::<CamMultiTable>::default();
            b.op = hli::calls::cam::CAM_MULTI_ENABLE_CORRECTION;
            Block::MultiTable(b)
        }
        "CamTableDeactivateCyclicTable" => {
            let mut b = Box::<CamMultiTable>::default();
            b.op = hli::calls::cam::CAM_MULTI_STOP_CYCLIC;
            Block::MultiTable(b)
        }
        fifo if FIFO_BLOCKS.contains(&fifo) => Block::Fifo(Box::new(FifoInstance::new(fifo))),
        s if SAW_BLOCKS.contains(&s) => Block::Saw(Box::new(SawInstance::new(s))),
        compat if compat.starts_with("CamTable") => {
            let kind = BLOCKS
                .iter()
                .find(|b| **b == compat)
                .copied()
                .unwrap_or("CamTableDelete");
            let mut config = CompatConfig::new(kind);
            config.room = room;
            Block::Compat(Box::new(CompatBlock::new(Arc::new(config))))
        }
        _ => Block::Stop(McStop::default()),
    }
}

fn execute_of(block: &mut Block) -> Option<&mut bool> {
    match block {
        Block::Power(_) => None,
        Block::Reset(b) => Some(&mut b.execute),
        Block::MoveAbsolute(b) => Some(&mut b.execute),
        Block::MoveRelative(b) => Some(&mut b.execute),
        Block::MoveVelocity(b) => Some(&mut b.execute),
        Block::Halt(b) => Some(&mut b.execute),
        Block::Stop(b) => Some(&mut b.execute),
        Block::CamTableSelect(b) => Some(&mut b.execute),
        Block::CamIn(b) => Some(&mut b.execute),
        Block::CamOut(b) => Some(&mut b.execute),
        Block::CamScaling(b) => Some(&mut b.execute),
        Block::WritePoint(b) => Some(&mut b.execute),
        Block::OnlineMode(b) => Some(&mut b.execute),
        Block::WriteFunction(b) => Some(&mut b.execute),
        Block::ReadFunction(b) => Some(&mut b.execute),
        Block::Read(b) => Some(&mut b.execute),
        Block::SetWeight(b) => Some(&mut b.execute),
        Block::MultiCouple(b) => Some(&mut b.execute),
        Block::MultiTable(b) => Some(&mut b.execute),
        Block::Compat(b) => Some(&mut b.execute),
        Block::Fifo(b) => Some(&mut b.execute),
        Block::Saw(b) => Some(&mut b.execute),
    }
}

fn set_input(block: &mut Block, input: Input) {
    match (block, input) {
        (Block::Power(b), Input::Enable(e)) => b.enable = e,
        (Block::MoveAbsolute(b), Input::Position(v)) => b.position = v,
        (Block::MoveAbsolute(b), Input::Velocity(v)) => b.velocity = v,
        (Block::MoveAbsolute(b), Input::Acceleration(v)) => b.acceleration = v,
        (Block::MoveAbsolute(b), Input::Deceleration(v)) => b.deceleration = v,
        (Block::MoveAbsolute(b), Input::Jerk(v)) => b.jerk = v,
        (Block::MoveRelative(b), Input::Distance(v)) => b.distance = v,
        (Block::MoveRelative(b), Input::Velocity(v)) => b.velocity = v,
        (Block::MoveRelative(b), Input::Acceleration(v)) => b.acceleration = v,
        (Block::MoveRelative(b), Input::Deceleration(v)) => b.deceleration = v,
        (Block::MoveRelative(b), Input::Jerk(v)) => b.jerk = v,
        (Block::MoveVelocity(b), Input::Velocity(v)) => b.velocity = v,
        (Block::MoveVelocity(b), Input::Direction(d)) => b.direction = d,
        (Block::MoveVelocity(b), Input::Acceleration(v)) => b.acceleration = v,
        (Block::MoveVelocity(b), Input::Deceleration(v)) => b.deceleration = v,
        (Block::MoveVelocity(b), Input::Jerk(v)) => b.jerk = v,
        (Block::Halt(b), Input::Deceleration(v)) => b.deceleration = v,
        (Block::Halt(b), Input::Jerk(v)) => b.jerk = v,
        (Block::Stop(b), Input::Deceleration(v)) => b.deceleration = v,
        (Block::Stop(b), Input::Jerk(v)) => b.jerk = v,
        (Block::CamTableSelect(b), Input::Table(v)) => b.table = v,
        (Block::CamTableSelect(b), Input::Periodic(v)) => b.periodic = v,
        (Block::CamTableSelect(b), Input::MasterAbsolute(v)) => b.master_absolute = v,
        (Block::CamTableSelect(b), Input::SlaveAbsolute(v)) => b.slave_absolute = v,
        (Block::CamIn(b), Input::Master(v)) => b.master = v,
        (Block::CamIn(b), Input::Table(v)) => b.table = v,
        (Block::CamIn(b), Input::StartMode(v)) => b.start_mode = v,
        (Block::CamIn(b), Input::ActivationMode(v)) => b.activation_mode = v,
        (Block::CamIn(b), Input::ActivationPosition(v)) => b.activation_position = v,
        (Block::CamIn(b), Input::MasterScalingMode(v)) => b.master_scaling_mode = v,
        (Block::CamIn(b), Input::SlaveScalingMode(v)) => b.slave_scaling_mode = v,
        (Block::CamIn(b), Input::MasterOffset(v)) => b.master_offset = v,
        (Block::CamIn(b), Input::SlaveOffset(v)) => b.slave_offset = v,
        (Block::CamIn(b), Input::MasterScaling(v)) => b.master_scaling = v,
        (Block::CamIn(b), Input::SlaveScaling(v)) => b.slave_scaling = v,
        (Block::CamIn(b), Input::Interpolation(v)) => b.interpolation = v,
        (Block::CamIn(b), Input::MasterActual(v)) => b.master_actual = v,
        (Block::CamScaling(b), Input::ActivationMode(v)) => b.activation_mode = v,
        (Block::CamScaling(b), Input::ActivationPosition(v)) => b.activation_position = v,
        (Block::CamScaling(b), Input::MasterScalingMode(v)) => b.master_scaling_mode = v,
        (Block::CamScaling(b), Input::SlaveScalingMode(v)) => b.slave_scaling_mode = v,
        (Block::CamScaling(b), Input::MasterOffset(v)) => b.master_offset = v,
        (Block::CamScaling(b), Input::SlaveOffset(v)) => b.slave_offset = v,
        (Block::CamScaling(b), Input::MasterScaling(v)) => b.master_scaling = v,
        (Block::CamScaling(b), Input::SlaveScaling(v)) => b.slave_scaling = v,
        (Block::WritePoint(b), Input::Table(v)) => b.table = v,
        (Block::WritePoint(b), Input::PointIndex(v)) => b.point.point_index = v,
        (Block::WritePoint(b), Input::FunctionType(v)) => b.point.function_type = v,
        (Block::WritePoint(b), Input::PointType(v)) => b.point.point_type = v,
        (Block::WritePoint(b), Input::RelIndexNext(v)) => b.point.rel_index_next_point = v,
        (Block::WritePoint(b), Input::MasterPos(v)) => b.point.master_pos = v,
        (Block::WritePoint(b), Input::SlavePos(v)) => b.point.slave_pos = v,
        (Block::WritePoint(b), Input::SlaveVelo(v)) => b.point.slave_velo = v,
        (Block::WritePoint(b), Input::SlaveAcc(v)) => b.point.slave_acc = v,
        (Block::WritePoint(b), Input::SlaveJerk(v)) => b.point.slave_jerk = v,
        (Block::OnlineMode(b), Input::Table(v)) => b.table = v,
        (Block::OnlineMode(b), Input::ActivationMode(v)) => b.activation_mode = v,
        (Block::OnlineMode(b), Input::ActivationPosition(v)) => b.activation_position = v,
        (Block::OnlineMode(b), Input::MasterScalingMode(v)) => b.master_scaling_mode = v,
        (Block::OnlineMode(b), Input::SlaveScalingMode(v)) => b.slave_scaling_mode = v,
        (Block::CamTableSelect(b), Input::Rows(rows)) => {
            b.data = CamData::Rows {
                rows,
                table_type: 10,
                interpolation: 0,
            }
        }
        (Block::CamTableSelect(b), Input::Points(points)) => b.data = CamData::Points(points),
        (Block::CamTableSelect(b), Input::TableType(v)) => b.table_type = v,
        (Block::CamTableSelect(b), Input::Interpolation(v)) => b.interpolation = v,
        (Block::WriteFunction(b), Input::Table(v)) => b.table = v,
        (Block::WriteFunction(b), Input::Points(points)) => b.points = CamData::Points(points),
        (Block::ReadFunction(b), Input::Table(v)) => b.table = v,
        (Block::ReadFunction(b), Input::PointIndex(v)) => b.first = v,
        (Block::ReadFunction(b), Input::NumPoints(v)) => b.count = v,

        (Block::Read(b), Input::Table(v)) => b.target = v,
        (Block::Read(b), Input::MasterPosition(v)) => b.request.a = v,
        (Block::Read(b), Input::AtMasterPosition(v)) => b.request.flags = u32::from(v),
        (Block::Read(b), Input::ValueSelectMask(v)) => b.request.mask = v,
        (Block::Read(b), Input::StartPosMaster(v)) => b.request.a = v,
        (Block::Read(b), Input::EndPosMaster(v)) => b.request.b = v,
        (Block::Read(b), Input::Increment(v)) => b.request.c = v,
        (Block::SetWeight(b), Input::Table(v)) => b.table = v,
        (Block::SetWeight(b), Input::Weight(v)) => b.weight.weight = v,
        (Block::SetWeight(b), Input::MasterOffset(v)) => b.weight.master_offset = v,
        (Block::SetWeight(b), Input::MasterSlope(v)) => b.weight.master_slope = v,
        (Block::SetWeight(b), Input::SlaveOffset(v)) => b.weight.slave_offset = v,
        (Block::SetWeight(b), Input::SlaveSlope(v)) => b.weight.slave_slope = v,
        (Block::SetWeight(b), Input::RangeLow(v)) => b.weight.range_low = v,
        (Block::SetWeight(b), Input::RangeHigh(v)) => b.weight.range_high = v,
        (Block::MultiCouple(b), Input::Master(v)) => b.master = v,
        (Block::MultiCouple(b), Input::TableIds(ids, n)) => {
            b.tables = ids;
            b.count = n;
            if b.profiles == 0 || b.profiles > n {
                b.profiles = n;
            }
        }
        (Block::MultiCouple(b), Input::Profiles(v)) => b.profiles = v,
        (Block::MultiCouple(b), Input::On(v)) => b.on = v,
        (Block::MultiTable(b), Input::Table(v)) => b.table = v,
        (Block::MultiTable(b), Input::AtPosition(v)) => b.at_position = v,
        (Block::MultiTable(b), Input::Position(v)) => b.position = v,
        (Block::Compat(b), Input::Compat(config)) => b.config = config,
        (Block::Fifo(b), Input::Fifo(inputs)) => b.inputs = inputs,
        (Block::Saw(b), Input::Saw(inputs)) => b.inputs = inputs,

        // parse_call admits only the inputs of the block.
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> toml::Table {
        toml::from_str(text).unwrap()
    }

    fn execute(i: &Instances) -> bool {
        match &i.list[0].block {
            Block::MoveAbsolute(b) => b.execute,
            _ => unreachable!(),
        }
    }

    /// Every call is its own edge, a `wait` sees only the latest call's outputs, and
    /// `execute = false` cancels a pending re-trigger.
    #[test]
    fn calls_make_edges_and_forget_old_outputs() {
        let mut i = Instances::default();
        let call = i
            .parse_call(&table(
                "block = \"MC_MoveAbsolute\"\ninstance = \"m\"\naxis = 0\nposition = 1.0",
            ))
            .unwrap();
        let lower = i
            .parse_call(&table(
                "block = \"MC_MoveAbsolute\"\ninstance = \"m\"\naxis = 0\nexecute = false",
            ))
            .unwrap();
        let done = i.parse_wait("m.Done").unwrap();
        i.apply(&call);
        assert!(execute(&i), "first call: rising edge now");
        i.list[0].last[0] = true; // the move finished: Done
        assert!(i.holds(done));
        i.apply(&call);
        assert!(!i.holds(done), "a new call forgets the old Done");
        assert!(
            !execute(&i) && i.list[0].raise_next_cycle,
            "FALSE for a cycle first"
        );
        i.apply(&call); // again in the same cycle: still one edge to come
        assert!(!execute(&i) && i.list[0].raise_next_cycle);
        i.begin_cycle();
        assert!(execute(&i));
        i.apply(&call);
        i.apply(&lower); // lowered before the edge came: no edge
        i.begin_cycle();
        assert!(!execute(&i) && !i.list[0].raise_next_cycle);
    }
}
