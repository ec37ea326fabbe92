//! The compatibility blocks of seed 000, chapter 5.2.1 and 5.2.2 (the older CamTable...
//! blocks), as thin wrappers over the calls of the chapter 5.1 blocks: each sends on its
//! rising edge (bExecute, or bCoupleOn / bCoupleOff) and reports Busy, Err and ErrId. The
//! multi-table blocks of 5.2.3 are in [`crate::blocks::cam_multi`].
//!
//! | block | what it sends |
//! | --- | --- |
//! | CamTableGenerate | the rows, in chunks (type 1..4: equidistant or not, linear or cyclic) |
//! | CamTableCreate | the table's type and size, for the rows of CamTableWriteData |
//! | CamTableWriteData | the rows of a created table, in chunks |
//! | CamTableReadData | a read of the table's rows |
//! | CamTableReadSlavePos | a read of the slave position at a master position |
//! | CamTableDelete | the deletion |
//! | CamTableCoupleAxes(Ipol) | MC_CamIn (start mode from the two absolute flags) / MC_CamOut |
//! | CamTableOffsetChange | MC_CamScaling of the two offsets, at once |
//! | CamTableSetSlaveScale | MC_CamScaling of the slave scaling, at once |
//! | CamTableSetMasterSlaveScale | MC_CamScaling of offsets and scalings, at once |

use super::cam::{recorded, CamCore};
use super::cam_data::{CamData, ChunkTransfer, ROW_BYTES};
use super::cam_read::{McCamRead, DEFAULT_READ_ROOM};
use crate::kernel::{no_follow, Accept, Kernel, Outputs};
use crate::runtime::PlcIo;
use crate::timeline::registry::{
    input, required, BlockSpec, InputField, InputSpec, Kind, Target, TimelineBlock, Value,
};
use hli::calls::cam::{
    CamInCall, CamOutCall, CamReadKind, CamRowsWriteCall, CamScalingCall, CamTableDeleteCall,
    CAM_KEEP_MASTER_OFFSET, CAM_KEEP_MASTER_SCALING, CAM_KEEP_SLAVE_OFFSET, CAM_KEEP_SLAVE_SCALING,
    CAM_ROWS_DECLARE,
};
use std::sync::Arc;

/// What a compatibility block is told, checked when the timeline is read.
#[derive(Debug, Clone, PartialEq)]
pub struct CompatConfig {
    /// Which block.
    pub kind: &'static str,
    /// iTableId.
    pub table: u32,
    /// iTableType 1..4 (equidistant linear, equidistant cyclic, non-equidistant linear,
    /// non-equidistant cyclic).
    pub table_type: u32,
    /// iNrOfRows of CamTableCreate.
    pub rows_declared: u32,
    /// The rows of CamTableGenerate and CamTableWriteData.
    pub rows: Option<Arc<[[f64; 2]]>>,
    /// iMasterId.
    pub master: u32,
    /// Offsets, slopes (scalings) and the master position of a read.
    pub master_offset: f64,
    /// Slave offset.
    pub slave_offset: f64,
    /// Master slope (scaling).
    pub master_slope: f64,
    /// Slave slope (scaling).
    pub slave_slope: f64,
    /// fMasterPos of CamTableReadSlavePos.
    pub master_pos: f64,
    /// bMasterAbsolut, bSlaveAbsolut.
    pub master_absolute: bool,
    /// See `master_absolute`.
    pub slave_absolute: bool,
    /// iIpolType.
    pub interpolation: u32,
    /// CoupleOn (TRUE) or CoupleOff (FALSE) for the coupling blocks.
    pub on: bool,
    /// Room for a read's numbers.
    pub room: usize,
    /// iBlockSize: bytes moved per call (0: the call's room, 13 rows or 28 numbers).
    pub block_size: u32,
    /// CamTableReadData's rows to read (0: all).
    pub rows_to_read: u32,
    /// CamTableReadData's column count of its array (the table's is 2).
    pub columns: u32,
    /// CamTableReadData's array size in bytes (none given: the room's, 8 a number).
    pub size: Option<u32>,
}

impl CompatConfig {
    /// The defaults of block `kind` (absolute, slopes 1, default read room).
    pub fn new(kind: &'static str) -> CompatConfig {
        CompatConfig {
            kind,
            table: 0,
            table_type: 3,
            rows_declared: 0,
            rows: None,
            master: 0,
            master_offset: 0.0,
            slave_offset: 0.0,
            master_slope: 1.0,
            slave_slope: 1.0,
            master_pos: 0.0,
            master_absolute: true,
            slave_absolute: true,
            interpolation: 0,
            on: true,
            room: DEFAULT_READ_ROOM,
            block_size: 0,
            rows_to_read: 0,
            columns: 2,
            size: None,
        }
    }
}

impl CompatConfig {
    /// Sets input `key` (one of the lists of [`TIMELINE`]).
    fn set(&mut self, key: &str, value: &Value) {
        match key {
            "table" => self.table.take(value),
            "table_type" => self.table_type.take(value),
            "num_rows" => self.rows_declared.take(value),
            "rows" => {
                if let Value::Rows(rows) = value {
                    self.rows = Some(Arc::clone(rows));
                }
            }
            "block_size" => self.block_size.take(value),
            "rows_to_read" => self.rows_to_read.take(value),
            "columns" => self.columns.take(value),
            "size" => self.size = value.uint().or(self.size),
            "master" => self.master.take(value),
            "master_offset" => self.master_offset.take(value),
            "slave_offset" => self.slave_offset.take(value),
            "master_slope" => self.master_slope.take(value),
            "slave_slope" => self.slave_slope.take(value),
            "master_pos" => self.master_pos.take(value),
            "master_absolute" => self.master_absolute.take(value),
            "slave_absolute" => self.slave_absolute.take(value),
            "interpolation" => self.interpolation.take(value),
            "on" => self.on.take(value),
            _ => {}
        }
    }
}

/// iTableId, 1..=255.
const TABLE: InputSpec = input("table", Kind::Range(1, 255));
/// iTableType 1..=4.
const TABLE_TYPE: InputSpec = input("table_type", Kind::Range(1, 4));
/// The rows `[[master, slave], ...]`.
const ROWS: InputSpec = input("rows", super::cam_data::ROWS);
/// iBlockSize: 0 (the call's room) or at least one row's bytes.
const BLOCK_SIZE: InputSpec = input(
    "block_size",
    Kind::Parsed {
        parse: |v| match v.as_integer() {
            Some(b) if b == 0 || (i64::from(ROW_BYTES)..=i64::from(u32::MAX)).contains(&b) => {
                Ok(Value::Int(b))
            }
            _ => Err(format!(
                "call: `block_size` = {v}: 0 (the default) or at least {ROW_BYTES} bytes (one row)"
            )),
        },
        example: "0",
    },
);
const MASTER_OFFSET: InputSpec = input("master_offset", Kind::Real);
const SLAVE_OFFSET: InputSpec = input("slave_offset", Kind::Real);
const SLAVE_SLOPE: InputSpec = input("slave_slope", Kind::Real);
/// The coupling blocks' inputs; CamTableCoupleAxesIpol's also `interpolation`.
const COUPLE: [InputSpec; 7] = [
    input("master", Kind::Range(0, u32::MAX as i64)),
    TABLE,
    MASTER_OFFSET,
    SLAVE_OFFSET,
    input("master_absolute", Kind::Bool),
    input("slave_absolute", Kind::Bool),
    input("on", Kind::Bool),
];
const COUPLE_IPOL: [InputSpec; 8] =
    crate::timeline::registry::joined(&[&COUPLE, &[input("interpolation", Kind::Range(0, 2))]]);

/// The inputs of each compatibility block.
const GENERATE: &[InputSpec] = &[TABLE, TABLE_TYPE, ROWS, BLOCK_SIZE];
const CREATE: &[InputSpec] = &[
    TABLE,
    TABLE_TYPE,
    required("num_rows", Kind::Range(2, u32::MAX as i64)),
];
const WRITE_DATA: &[InputSpec] = &[TABLE, ROWS, BLOCK_SIZE];
const READ_DATA: &[InputSpec] = &[
    TABLE,
    input("room", Kind::Room),
    BLOCK_SIZE,
    input("rows_to_read", Kind::Range(0, 1 << 20)),
    input("columns", Kind::Range(1, 16)),
    input("size", Kind::Range(8, 1 << 30)),
];
const READ_SLAVE_POS: &[InputSpec] = &[TABLE, input("master_pos", Kind::Real)];
const OFFSETS: &[InputSpec] = &[MASTER_OFFSET, SLAVE_OFFSET];
const MASTER_SLAVE_SCALE: &[InputSpec] = &[
    MASTER_OFFSET,
    SLAVE_OFFSET,
    input("master_slope", Kind::Real),
    SLAVE_SLOPE,
];

/// A compatibility block in a timeline: its configuration and its running state.
#[derive(Debug)]
pub struct CompatBlock {
    /// Input: the edge (bExecute, or bCoupleOn / bCoupleOff by `config.on`).
    pub execute: bool,
    /// What it was told by the last call.
    pub config: Arc<CompatConfig>,
    /// Outputs (bBusy, bErr, iErrId; Done when finished).
    pub out: Outputs,
    /// A read's numbers (CamTableReadData: master, slave per row; ReadSlavePos: the slave
    /// position first).
    pub read: McCamRead,
    transfer: Kernel<ChunkTransfer>,
    declare: CamCore<CamRowsWriteCall>,
    delete: CamCore<CamTableDeleteCall>,
    couple: CamCore<CamInCall>,
    decouple: CamCore<CamOutCall>,
    scale: CamCore<CamScalingCall>,
    /// The master of CamTableCoupleAxes(Ipol) when given by NC axis ID (the timeline's
    /// `master_id`, resolved): it overrides `config.master` until the next configuration.
    master: Option<u32>,
}

/// `iTableType` to the table type and whether it is cyclic.
fn type_of(t: u32) -> (u32, bool) {
    match t {
        1 => (10, false),
        2 => (10, true),
        4 => (11, true),
        _ => (11, false),
    }
}

impl CompatBlock {
    /// A block of `config`'s kind.
    pub fn new(config: Arc<CompatConfig>) -> CompatBlock {
        let (what, room) = match config.kind {
            "CamTableReadSlavePos" => (CamReadKind::SlaveDynamics, 3),
            _ => (CamReadKind::Rows, config.room.max(2)),
        };
        CompatBlock {
            execute: false,
            read: McCamRead::new(what, room),
            config,
            out: Outputs::default(),
            transfer: Kernel::default(),
            declare: CamCore::default(),
            delete: CamCore::default(),
            couple: CamCore::default(),
            decouple: CamCore::default(),
            scale: CamCore::default(),
            master: None,
        }
    }

    /// Input tTimeout: cycles to wait for the CNC's answer (for each part of a transfer or
    /// read), for whichever call the block makes.
    pub fn set_timeout_cycles(&mut self, cycles: u64) {
        self.transfer.set_timeout_cycles(cycles);
        self.read.set_timeout_cycles(cycles);
        self.declare.set_timeout_cycles(cycles);
        self.delete.set_timeout_cycles(cycles);
        self.couple.set_timeout_cycles(cycles);
        self.decouple.set_timeout_cycles(cycles);
        self.scale.set_timeout_cycles(cycles);
    }

    /// One cycle for slave axis `slave` (the coupling and scaling blocks' axis).
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let c = Arc::clone(&self.config);
        match c.kind {
            "CamTableGenerate" | "CamTableWriteData" => {
                let (table_type, periodic) = if c.kind == "CamTableGenerate" {
                    type_of(c.table_type)
                } else {
                    (0, false) // as declared by CamTableCreate
                };
                let data = match &c.rows {
                    Some(rows) => CamData::Rows {
                        rows: Arc::clone(rows),
                        table_type,
                        interpolation: 0,
                    },
                    None => CamData::None,
                };
                let block = c.block_size;
                self.out = self.transfer.cycle(
                    io,
                    self.execute,
                    |_| {
                        Ok(ChunkTransfer::new(c.table, &data, false, periodic)
                            .with_block_size(block))
                    },
                    |()| Accept::Done(()),
                    no_follow,
                );
            }
            "CamTableCreate" => {
                let (table_type, periodic) = type_of(c.table_type);
                let call = CamRowsWriteCall {
                    flags: CAM_ROWS_DECLARE,
                    total: c.rows_declared,
                    table_type,
                    periodic: u32::from(periodic),
                    ..CamRowsWriteCall::default()
                };
                self.out = self.declare.cycle(io, self.execute, c.table, || call, None);
            }
            "CamTableDelete" => {
                self.out =
                    self.delete
                        .cycle(io, self.execute, c.table, CamTableDeleteCall::default, None);
            }
            "CamTableReadData" | "CamTableReadSlavePos" => {
                self.read.execute = self.execute;
                self.read.target = c.table;
                self.read.request.a = c.master_pos;
                if c.kind == "CamTableReadData" {
                    self.read.request.rows = c.rows_to_read;
                    self.read.refuse = read_array_refusal(&c);
                    // Rows to read 0 is all the table's rows, a count only the answer
                    // tells: the array's size is checked against it then (0x4B31).
                    self.read.size_limit = c.size.map(|bytes| bytes as usize / 8);
                }
                // iBlockSize in numbers of 8 bytes (0: the reply's room).
                self.read.request.part_len = c.block_size / 8;
                self.read.call(io);
                self.out = self.read.out;
            }
            "CamTableCoupleAxes" | "CamTableCoupleAxesIpol" => {
                self.out = self.couple_axes(io, &c, slave)
            }
            _ => self.out = self.rescale(io, &c, slave),
        }
    }

    /// CamTableCoupleAxes(Ipol): MC_CamIn (CoupleOn), or MC_CamOut (CoupleOff).
    fn couple_axes(&mut self, io: &mut PlcIo<'_>, c: &CompatConfig, slave: u32) -> Outputs {
        let start_mode = match (c.master_absolute, c.slave_absolute) {
            (true, true) => 1,
            (false, false) => 2,
            (true, false) => 3,
            (false, true) => 4,
        };
        let call = CamInCall {
            master: self.master.unwrap_or(c.master),
            table_id: c.table,
            start_mode,
            interpolation: c.interpolation,
            master_offset: c.master_offset,
            slave_offset: c.slave_offset,
            master_scaling: 1.0,
            slave_scaling: 1.0,
            ..CamInCall::default()
        };
        if c.on {
            let mut o = self
                .couple
                .cycle(io, self.execute, slave, || call, Some(slave));
            // The old block is done once the coupling stands (no InSync output).
            o.done = o.in_sync;
            o
        } else {
            self.decouple
                .cycle(io, self.execute, slave, CamOutCall::default, None)
        }
    }

    /// CamTableOffsetChange, CamTableSetSlaveScale, CamTableSetMasterSlaveScale: MC_CamScaling
    /// at once, keeping what the block does not set.
    fn rescale(&mut self, io: &mut PlcIo<'_>, c: &CompatConfig, slave: u32) -> Outputs {
        let keep = match c.kind {
            "CamTableOffsetChange" => CAM_KEEP_MASTER_SCALING | CAM_KEEP_SLAVE_SCALING,
            "CamTableSetSlaveScale" => {
                CAM_KEEP_MASTER_SCALING | CAM_KEEP_MASTER_OFFSET | CAM_KEEP_SLAVE_OFFSET
            }
            _ => 0,
        };
        let call = CamScalingCall {
            activation_mode: 0,
            master_scaling_mode: 0,
            slave_scaling_mode: 0,
            reserved: keep,
            activation_position: 0.0,
            master_offset: c.master_offset,
            slave_offset: c.slave_offset,
            master_scaling: c.master_slope,
            slave_scaling: c.slave_slope,
        };
        self.scale.cycle(io, self.execute, slave, || call, None)
    }
}

impl TimelineBlock for CompatBlock {
    timeline_timeout!();
    fn set(&mut self, key: &str, value: &Value) {
        // Unique between cycles (a cycle's clone is gone): no copy is made.
        Arc::make_mut(&mut self.config).set(key, value);
        if key == "master" {
            self.master = None;
        }
    }
    fn set_master(&mut self, index: u32) -> bool {
        let coupling = ["CamTableCoupleAxes", "CamTableCoupleAxesIpol"].contains(&self.config.kind);
        if coupling {
            self.master = Some(index);
        }
        coupling
    }
    execute_cycle!(with_axis, recorded);
    fn read(&self) -> Option<Vec<f64>> {
        Some(self.read.values.clone())
    }
}

/// A block of `kind` with room `room` for a read's numbers.
fn make(kind: &'static str, room: Option<usize>) -> Box<dyn TimelineBlock> {
    let config = CompatConfig {
        room: room.unwrap_or(DEFAULT_READ_ROOM),
        ..CompatConfig::new(kind)
    };
    Box::new(CompatBlock::new(Arc::new(config)))
}

/// A compatibility block a timeline calls, on the slave's axis.
macro_rules! compat_block {
    ($name:literal, $inputs:expr) => {
        BlockSpec {
            name: $name,
            target: Target::Axis,
            execute: true,
            inputs: $inputs,
            make: |room| make($name, room),
            style: crate::timeline::registry::StStyle::PlcOpen,
        }
    };
}

/// The compatibility blocks a timeline calls.
pub const TIMELINE: &[BlockSpec] = &[
    compat_block!("CamTableGenerate", GENERATE),
    compat_block!("CamTableCreate", CREATE),
    compat_block!("CamTableWriteData", WRITE_DATA),
    compat_block!("CamTableReadData", READ_DATA),
    compat_block!("CamTableReadSlavePos", READ_SLAVE_POS),
    compat_block!("CamTableDelete", &[TABLE]),
    compat_block!("CamTableCoupleAxes", &COUPLE),
    compat_block!("CamTableCoupleAxesIpol", &COUPLE_IPOL),
    compat_block!("CamTableOffsetChange", OFFSETS),
    compat_block!("CamTableSetSlaveScale", &[SLAVE_SLOPE]),
    compat_block!("CamTableSetMasterSlaveScale", MASTER_SLAVE_SCALE),
];

/// CamTableReadData's array against what it asks for (seed 000 5.2.1.5): a column count other
/// than the table's 2 is 0x4B37; rows to read that do not fit the array's size in bytes (8 a
/// number) are 0x4B31. `None`: the read may go. Rows to read 0 means all the table's rows,
/// which the block does not know before the answer: that read goes, and the array's size
/// (`McCamRead::size_limit`, else its room) refuses an answer it cannot hold with 0x4B31.
fn read_array_refusal(c: &CompatConfig) -> Option<u32> {
    if c.columns != 2 {
        return Some(super::cam_read::ERROR_COLUMNS);
    }
    let size = c.size.map_or(c.room as u64 * 8, u64::from);
    let wanted = u64::from(c.rows_to_read) * u64::from(c.columns) * 8;
    (wanted > size).then_some(super::cam_read::ERROR_ARRAY_SIZE)
}
