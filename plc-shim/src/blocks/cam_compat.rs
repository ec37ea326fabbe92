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
use super::cam_data::{CamData, ChunkTransfer, CAM_REF_ROOM_BYTES, ROW_BYTES};
use super::cam_read::{McCamRead, DEFAULT_READ_ROOM};
use super::cam_room::CamRoom;
use crate::kernel::{no_follow, Accept, Kernel, Outputs};
use crate::runtime::PlcIo;
use crate::timeline::registry::{
    input, required, BlockSpec, CamRefIn, InputField, InputSpec, Kind, StForm, Target,
    TimelineBlock, Value,
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
    /// How many of `rows` are the table's (a PLC program's rows in room made at load);
    /// `None`: all.
    pub rows_count: Option<usize>,
    /// The seed's code of rows a PLC program gave that do not fit their array (0x4B37 for
    /// columns other than 2, 0x4B31 for more than the array's size): the command ends with
    /// it, nothing sent.
    pub refuse: Option<u32>,
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
            rows_count: None,
            refuse: None,
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
                    (self.rows_count, self.refuse) = (None, None);
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

// The inputs under the seed's names in Structured Text (5.2: `iTableId`, `AdrDataArray`,
// `fMasterPositionOffset`, `bCoupleOn`, ...).

/// iTableId, 1..=255.
const TABLE: InputSpec = input("table", Kind::Range(1, 255)).st_named("iTableId");
/// iTableType 1..=4.
const TABLE_TYPE: InputSpec = input("table_type", Kind::Range(1, 4)).st_named("iTableType");
/// The rows `[[master, slave], ...]`; in ST the seed's array through a pointer.
const ROWS: InputSpec = input("rows", super::cam_data::ROWS).st_form(StForm::Rows {
    data: "AdrDataArray",
    columns: "iColDim",
    rows: "iRowsToWrite",
    size: Some("iSizeOfDataArray"),
    max: CAM_REF_ROOM_BYTES / 8,
});
/// iBlockSize: 0 (the call's room) or at least one row's bytes.
const BLOCK_SIZE: InputSpec = input(
    "block_size",
    Kind::ZeroOr(ROW_BYTES as i64, u32::MAX as i64),
)
.st_named("iBlockSize");
const MASTER_OFFSET: InputSpec =
    input("master_offset", Kind::Real).st_named("fMasterPositionOffset");
const SLAVE_OFFSET: InputSpec = input("slave_offset", Kind::Real).st_named("fSlavePositionOffset");
const SLAVE_SLOPE: InputSpec = input("slave_slope", Kind::Real).st_named("fSlaveSlope");
/// The coupling blocks' inputs; CamTableCoupleAxesIpol's also `interpolation`.
const COUPLE: [InputSpec; 7] = [
    input("master", Kind::Range(0, u32::MAX as i64)).st_named("iMasterId"),
    TABLE,
    MASTER_OFFSET,
    SLAVE_OFFSET,
    input("master_absolute", Kind::Bool).st_named("bMasterAbsolut"),
    input("slave_absolute", Kind::Bool).st_named("bSlaveAbsolut"),
    input("on", Kind::Bool).st_form(COUPLE_EDGES),
];
/// bCoupleOn and bCoupleOff: the couplings' two edges.
pub(super) const COUPLE_EDGES: StForm = StForm::Edges {
    on: "bCoupleOn",
    off: "bCoupleOff",
};
const COUPLE_IPOL: [InputSpec; 8] = crate::timeline::registry::joined(&[
    &COUPLE,
    &[input("interpolation", Kind::Range(0, 2)).st_named("iIpolType")],
]);

/// The inputs of each compatibility block.
const GENERATE: &[InputSpec] = &[TABLE, TABLE_TYPE, ROWS, BLOCK_SIZE];
const CREATE: &[InputSpec] = &[
    TABLE,
    TABLE_TYPE,
    required("num_rows", Kind::Range(2, u32::MAX as i64)).st_named("iNrOfRows"),
];
const WRITE_DATA: &[InputSpec] = &[TABLE, ROWS, BLOCK_SIZE];
const READ_DATA: &[InputSpec] = &[
    TABLE,
    input("room", Kind::Room).st_form(StForm::ReadAt {
        data: "AdrDataArray",
        size: "iSizeOfDataArray",
    }),
    BLOCK_SIZE,
    input("rows_to_read", Kind::Range(0, 1 << 20)).st_named("iRowsToRead"),
    input("columns", Kind::Range(1, 16)).st_named("iColDim"),
    input("size", Kind::Range(8, 1 << 30)).st_form(StForm::Hidden),
];
const READ_SLAVE_POS: &[InputSpec] = &[
    TABLE,
    input("master_pos", Kind::Real).st_named("fMasterPos"),
];
const OFFSETS: &[InputSpec] = &[MASTER_OFFSET, SLAVE_OFFSET];
const MASTER_SLAVE_SCALE: &[InputSpec] = &[
    MASTER_OFFSET,
    SLAVE_OFFSET,
    input("master_slope", Kind::Real).st_named("fMasterSlope"),
    SLAVE_SLOPE,
];
/// CamTableSetSlaveScale's slope is the seed's `fSlaveScale`.
const SLAVE_SCALE: &[InputSpec] = &[input("slave_slope", Kind::Real).st_named("fSlaveScale")];

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
    /// Room for a PLC program's rows (Structured Text), made at load.
    room: Option<CamRoom>,
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
            room: None,
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
                let (block, refuse) = (c.block_size, c.refuse);
                let count = c.rows_count.unwrap_or(data.len());
                self.out = self.transfer.cycle(
                    io,
                    self.execute,
                    |_| match refuse {
                        Some(code) => Err(code),
                        None => Ok(ChunkTransfer::new(c.table, &data, false, periodic)
                            .with_block_size(block)
                            .with_count(count)),
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
    fn reserve_cam_ref(&mut self, bytes: usize) -> bool {
        let writes = ["CamTableGenerate", "CamTableWriteData"].contains(&self.config.kind);
        if writes {
            self.room = Some(CamRoom::rows_only(bytes));
        }
        writes
    }
    /// The seed's `AdrDataArray` rows (2 columns; `values` fewer than the rows when the array
    /// did not hold them), copied into the room made at load.
    fn set_rows(&mut self, values: &[f64], columns: u32, rows: u32) -> bool {
        let Some(room) = self.room.as_mut() else {
            return false;
        };
        // Unique between cycles: no copy is made; the last rows' buffer is given back.
        let c = Arc::make_mut(&mut self.config);
        (c.rows, c.rows_count, c.refuse) = (None, None, None);
        let n = rows as usize;
        if columns != 2 {
            c.refuse = Some(super::cam_read::ERROR_COLUMNS);
            return true;
        }
        if values.len() < n.saturating_mul(2) {
            c.refuse = Some(super::cam_read::ERROR_ARRAY_SIZE);
            return true;
        }
        let given = values[..2 * n].chunks_exact(2).map(|r| [r[0], r[1]]);
        match room.rows(given) {
            Some((rows, n)) => {
                (c.rows, c.rows_count) = (Some(rows), Some(n));
                true
            }
            None => false,
        }
    }
    /// CamTableReadData's `AdrDataArray`: its size in bytes the most the answer may hold.
    fn set_destination(&mut self, array: &CamRefIn<'_>) -> bool {
        if self.config.kind != "CamTableReadData" {
            return false;
        }
        Arc::make_mut(&mut self.config).size = Some(array.array_size);
        true
    }
    /// CamTableReadSlavePos: `fSlavePos`.
    fn results(&self) -> Option<&'static crate::timeline::registry::Results> {
        (self.config.kind == "CamTableReadSlavePos").then_some(&super::cam_results::SLAVE_POS)
    }
    fn result_values(&self, out: &mut [f64]) -> usize {
        super::cam_results::copied(&self.read.values[..self.read.values.len().min(1)], out)
    }
    fn read_bytes(&self, out: &mut [u8]) -> usize {
        super::cam_results::lreal_bytes(&self.read.values, out)
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

/// A compatibility block a timeline calls, on the slave's axis (`axis`, or the seed's name
/// for it); the seed's names in Structured Text.
macro_rules! compat_block {
    ($name:literal, $target:expr, $inputs:expr) => {
        BlockSpec {
            name: $name,
            target: $target,
            execute: true,
            inputs: $inputs,
            make: |room| make($name, room),
            style: crate::timeline::registry::StStyle::Hungarian,
        }
    };
}

/// The seed's slave of a coupling (`iSlaveId`) and of a scaling (`iSlaveAxisId`); a table
/// block has no axis in the seed (ours is `iAxisId`, of no effect).
const SLAVE: Target = Target::AxisNamed("iSlaveId");
const SLAVE_AXIS: Target = Target::AxisNamed("iSlaveAxisId");

/// The compatibility blocks a timeline calls.
pub const TIMELINE: &[BlockSpec] = &[
    compat_block!("CamTableGenerate", Target::Axis, GENERATE),
    compat_block!("CamTableCreate", Target::Axis, CREATE),
    compat_block!("CamTableWriteData", Target::Axis, WRITE_DATA),
    compat_block!("CamTableReadData", Target::Axis, READ_DATA),
    compat_block!("CamTableReadSlavePos", Target::Axis, READ_SLAVE_POS),
    compat_block!("CamTableDelete", Target::Axis, &[TABLE]),
    compat_block!("CamTableCoupleAxes", SLAVE, &COUPLE),
    compat_block!("CamTableCoupleAxesIpol", SLAVE, &COUPLE_IPOL),
    compat_block!("CamTableOffsetChange", SLAVE_AXIS, OFFSETS),
    compat_block!("CamTableSetSlaveScale", SLAVE_AXIS, SLAVE_SCALE),
    compat_block!(
        "CamTableSetMasterSlaveScale",
        SLAVE_AXIS,
        MASTER_SLAVE_SCALE
    ),
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
