//! The multi-table blocks of seed 000 chapter 5.2.3: CamTableSetWeight,
//! CamTableCoupleAxesMultiTables, CamTableEnableCorrectionTable and
//! CamTableDeactivateCyclicTable, each one call on [`CamCore`].

use super::cam::{recorded, CamCore};
use crate::kernel::Outputs;
use crate::runtime::PlcIo;
use crate::timeline::registry::{input, BlockSpec, Kind, StForm, Target, TimelineBlock, Value};
use hli::calls::cam::CamMultiTableOp;

/// CamTableSetWeight (5.2.3.1): weight, offsets, slopes and range of `table` in a
/// multi-table slave.
#[derive(Debug)]
pub struct CamTableSetWeight {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Input: the table ID.
    pub table: u32,
    /// Input: the scaling.
    pub weight: hli::calls::cam::CamTableWeightCall,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<hli::calls::cam::CamTableWeightCall>,
}

impl Default for CamTableSetWeight {
    fn default() -> Self {
        Self {
            execute: false,
            table: 0,
            weight: hli::calls::cam::CamTableWeightCall {
                weight: 1.0,
                master_slope: 1.0,
                slave_slope: 1.0,
                range_low: -1e300,
                range_high: 1e300,
                ..Default::default()
            },
            out: Outputs::default(),
            core: CamCore::default(),
        }
    }
}

impl CamTableSetWeight {
    timeout_input!(core);

    /// One cycle.
    pub fn call(&mut self, io: &mut PlcIo<'_>) {
        let call = self.weight;
        self.out = self.core.cycle(io, self.execute, self.table, || call, None);
    }
}

/// CamTableCoupleAxesMultiTables (5.2.3.2): couples `slave` to `master` through up to
/// eight tables (the first `profiles` are profile tables, the others corrections), or
/// decouples it (`on` FALSE; the block's CoupleOff edge).
#[derive(Debug, Default)]
pub struct CamTableCoupleAxesMultiTables {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// Input: couple (TRUE) or decouple (FALSE).
    pub on: bool,
    /// Input: the master axis.
    pub master: u32,
    /// Input: the table IDs (up to 8).
    pub tables: [u32; 8],
    /// Input: tables used.
    pub count: u32,
    /// Input: profile tables among them.
    pub profiles: u32,
    /// Input: follow the master's actual values (an encoder master), as MC_CamIn's
    /// `master_source`; ours, not the seed's.
    pub master_actual: bool,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<hli::calls::cam::CamMultiCoupleCall>,
}

impl CamTableCoupleAxesMultiTables {
    timeout_input!(core);

    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let call = hli::calls::cam::CamMultiCoupleCall {
            master: self.master,
            on: u32::from(self.on),
            tables: self.count,
            profiles: self.profiles,
            table_ids: self.tables,
            master_source: u32::from(self.master_actual),
            reserved: 0,
        };
        self.out = self.core.cycle(io, self.execute, slave, || call, None);
    }
}

/// CamTableEnableCorrectionTable (5.2.3.3) and CamTableDeactivateCyclicTable (5.2.3.4):
/// a table of a multi-table slave started (a correction: at once, or at `position` when
/// `at_position`) or ended at its cycle boundary (a cyclic profile table).
#[derive(Debug)]
pub struct CamMultiTable {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// What it does.
    pub op: CamMultiTableOp,
    /// Input: the table ID.
    pub table: u32,
    /// Input: a correction starts at `position` rather than at once.
    pub at_position: bool,
    /// Input: the activation position.
    pub position: f64,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<hli::calls::cam::CamMultiTableCall>,
}

impl CamMultiTable {
    timeout_input!(core);

    /// The block that does `op`, its inputs cleared.
    pub fn new(op: CamMultiTableOp) -> CamMultiTable {
        CamMultiTable {
            execute: false,
            op,
            table: 0,
            at_position: false,
            position: 0.0,
            out: Outputs::default(),
            core: CamCore::default(),
        }
    }

    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let call = hli::calls::cam::CamMultiTableCall {
            op: self.op.raw(),
            table: self.table,
            flags: u32::from(self.at_position),
            reserved: 0,
            position: self.position,
        };
        self.out = self.core.cycle(io, self.execute, slave, || call, None);
    }
}

inputs! {
    /// CamTableSetWeight's inputs: the table and its scaling.
    WEIGHT, set_weight: CamTableSetWeight {
        "table" as I_TABLE_ID: Kind::Count => table,
        "weight" as F_ORIGINAL_WEIGHT: Kind::Real => weight.weight,
        "master_offset" as F_MASTER_OFFSET: Kind::Real => weight.master_offset,
        "master_slope" as F_MASTER_SLOPE: Kind::Real => weight.master_slope,
        "slave_offset" as F_SLAVE_OFFSET: Kind::Real => weight.slave_offset,
        "slave_slope" as F_SLAVE_SLOPE: Kind::Real => weight.slave_slope,
        "range_low" as F_RANGE_LOW: Kind::Real => weight.range_low,
        "range_high" as F_RANGE_HIGH: Kind::Real => weight.range_high,
    }
}

// The seed's names in Structured Text (5.2.3).
const I_TABLE_ID: StForm = StForm::Named("iTableId");
const F_ORIGINAL_WEIGHT: StForm = StForm::Named("fOriginalWeight");
const F_MASTER_OFFSET: StForm = StForm::Named("fMasterOffset");
const F_MASTER_SLOPE: StForm = StForm::Named("fMasterSlope");
const F_SLAVE_OFFSET: StForm = StForm::Named("fSlaveOffset");
const F_SLAVE_SLOPE: StForm = StForm::Named("fSlaveSlope");
const F_RANGE_LOW: StForm = StForm::Named("fRangeLow");
const F_RANGE_HIGH: StForm = StForm::Named("fRangeHigh");
/// The slave of the multi-table blocks that have one (`iSlaveId`).
const SLAVE: Target = Target::AxisNamed("iSlaveId");
/// `iNrOfMultiTables` and `iTableId1` .. `iTableId8`.
const TABLE_IDS: StForm = StForm::Ids {
    count: "iNrOfMultiTables",
    ids: &[
        "iTableId1",
        "iTableId2",
        "iTableId3",
        "iTableId4",
        "iTableId5",
        "iTableId6",
        "iTableId7",
        "iTableId8",
    ],
};

impl TimelineBlock for CamTableSetWeight {
    timeline_timeout!();
    fn set(&mut self, key: &str, value: &Value) {
        set_weight(self, key, value);
    }
    execute_cycle!(no_axis, recorded);
}

impl TimelineBlock for CamTableCoupleAxesMultiTables {
    timeline_timeout!();
    fn set_master(&mut self, index: u32) -> bool {
        self.master = index;
        true
    }
    fn set(&mut self, key: &str, value: &Value) {
        match (key, value) {
            ("master", Value::Int(v)) => self.master = *v as u32,
            ("master_source", Value::Int(v)) => self.master_actual = *v != 0,
            ("profiles", Value::Int(v)) => self.profiles = *v as u32,
            ("on", Value::Bool(v)) => self.on = *v,
            ("tables", Value::Ids(ids, n)) => {
                (self.tables, self.count) = (*ids, *n);
                if self.profiles == 0 || self.profiles > *n {
                    self.profiles = *n;
                }
            }
            _ => {}
        }
    }
    execute_cycle!(with_axis, recorded);
}

impl TimelineBlock for CamMultiTable {
    timeline_timeout!();
    fn set(&mut self, key: &str, value: &Value) {
        match (key, value) {
            ("table", Value::Int(v)) => self.table = *v as u32,
            ("at_position", Value::Bool(v)) => self.at_position = *v,
            ("position", Value::Real(v)) => self.position = *v,
            _ => {}
        }
    }
    execute_cycle!(with_axis, recorded);
}

/// `tables = [1, 2, ...]`: 1 to 8 table IDs.
fn table_ids(value: &toml::Value) -> Result<Value, String> {
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
    Ok(Value::Ids(ids, list.len() as u32))
}

/// The multi-table blocks a timeline calls; the slave is the instance's axis (`axis`, or
/// the seed's `iSlaveId`); the seed's names in Structured Text.
pub const TIMELINE: &[BlockSpec] = &[
    BlockSpec::on_axis("CamTableSetWeight", &WEIGHT, |_| {
        Box::<CamTableSetWeight>::default()
    })
    .hungarian(),
    BlockSpec::with_execute(
        "CamTableCoupleAxesMultiTables",
        SLAVE,
        &[
            input("master", Kind::Count).st_named("iMasterId"),
            input(
                "tables",
                Kind::Parsed {
                    parse: table_ids,
                    example: "[1, 2]",
                },
            )
            .st_form(TABLE_IDS),
            input("profiles", Kind::Range(1, 8)).st_named("iNrOfProfileTables"),
            input("on", Kind::Bool).st_form(super::cam_compat::COUPLE_EDGES),
            crate::blocks::cam::MASTER_SOURCE,
        ],
        |_| {
            Box::new(CamTableCoupleAxesMultiTables {
                on: true,
                ..CamTableCoupleAxesMultiTables::default()
            })
        },
    )
    .hungarian(),
    BlockSpec::with_execute(
        "CamTableEnableCorrectionTable",
        SLAVE,
        &[
            input("table", Kind::Count).st_named("iTableId"),
            input("at_position", Kind::Bool),
            input("position", Kind::Real),
        ],
        |_| Box::new(CamMultiTable::new(CamMultiTableOp::EnableCorrection)),
    )
    .hungarian(),
    BlockSpec::with_execute(
        "CamTableDeactivateCyclicTable",
        SLAVE,
        &[input("table", Kind::Count).st_named("iTableId")],
        |_| Box::new(CamMultiTable::new(CamMultiTableOp::StopCyclic)),
    )
    .hungarian(),
];
