//! The multi-table blocks of seed 000 chapter 5.2.3: CamTableSetWeight,
//! CamTableCoupleAxesMultiTables, CamTableEnableCorrectionTable and
//! CamTableDeactivateCyclicTable, each one call on [`CamCore`].

use super::cam::CamCore;
use crate::kernel::Outputs;
use crate::runtime::PlcIo;

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
    /// Outputs of the last call.
    pub out: Outputs,
    core: CamCore<hli::calls::cam::CamMultiCoupleCall>,
}

impl CamTableCoupleAxesMultiTables {
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let call = hli::calls::cam::CamMultiCoupleCall {
            master: self.master,
            on: u32::from(self.on),
            tables: self.count,
            profiles: self.profiles,
            table_ids: self.tables,
        };
        self.out = self.core.cycle(io, self.execute, slave, || call, None);
    }
}

/// CamTableEnableCorrectionTable (5.2.3.3) and CamTableDeactivateCyclicTable (5.2.3.4):
/// a table of a multi-table slave started (a correction: at once, or at `position` when
/// `at_position`) or ended at its cycle boundary (a cyclic profile table).
#[derive(Debug, Default)]
pub struct CamMultiTable {
    /// Input: a rising edge sends it.
    pub execute: bool,
    /// What it does: [`hli::calls::cam::CAM_MULTI_ENABLE_CORRECTION`] or
    /// [`hli::calls::cam::CAM_MULTI_STOP_CYCLIC`].
    pub op: u32,
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
    /// One cycle for slave axis `slave`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, slave: u32) {
        let call = hli::calls::cam::CamMultiTableCall {
            op: self.op,
            table: self.table,
            flags: u32::from(self.at_position),
            reserved: 0,
            position: self.position,
        };
        self.out = self.core.cycle(io, self.execute, slave, || call, None);
    }
}
