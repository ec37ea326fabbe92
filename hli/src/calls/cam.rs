//! The cam family's calls (seed 000): tables and motion functions written and read in
//! chunks, couplings (MC_CamIn, MC_CamOut, MC_CamScaling), the online change of points and
//! the multi-table slaves. Every reply is a [`CamReply`] unless a read says otherwise.

use crate::enums::{hli_enum, wire_enum};
use crate::wire::ACYCLIC_BODY_SIZE;
use bytemuck::{Pod, Zeroable};

hli_enum! {
    /// Why the cam engine refused a coupling command (beside the seed's table codes for an
    /// unknown table and the axis layer's codes for a slave that cannot be coupled). The
    /// seed does not number these; they are ours.
    CamCouplingError: u32, "CamCouplingError" {
        /// The master axis does not exist.
        NoSuchMaster = 0x4260,
        /// The master is the slave itself.
        MasterIsSlave = 0x4261,
        /// Activation, start and scaling mode do not go together (seed 5.1.16.13/14), or
        /// MC_CamIn's start mode contradicts the MasterAbsolute/SlaveAbsolute its table was
        /// selected with (MC_CamTableSelect).
        ModeCombination = 0x4262,
        /// The activation position lies behind the master in its direction of travel.
        ActivationPassed = 0x4263,
        /// MC_CamOut or MC_CamScaling on a slave no cam couples.
        NotCamCoupled = 0x4264,
        /// A coupling made with MC_CamIn cannot switch cams (MC_CamInExt can).
        NotSwitchable = 0x4265,
        /// An offset or scaling that is not finite, or a master scaling of 0.
        BadParameter = 0x4266,
        /// An unknown start, activation or scaling mode number.
        UnknownMode = 0x4267,
        /// A table a coupling uses cannot be replaced.
        TableInUse = 0x4268,
        /// A chunk that does not continue its transfer (order, count, total).
        ChunkOutOfOrder = 0x4269,
        /// MC_CamScaling or a switch while the first coupling still waits for its activation.
        CouplingPending = 0x426A,
    }
}

wire_enum! {
    /// `MC_StartMode` ([`CamInCall::start_mode`]): whether the cam's master and slave
    /// coordinates are absolute or measured from the axes' positions at coupling (or
    /// switching).
    CamStartMode {
        /// 1: both absolute.
        Absolute = 1 => "absolute" | "MC_STARTMODE_ABSOLUTE",
        /// 2: both relative.
        Relative = 2 => "relative" | "MC_STARTMODE_RELATIVE",
        /// 3: master absolute, slave relative.
        MasterAbsSlaveRel = 3 => "master_abs_slave_rel" | "MC_STARTMODE_MASTERABS_SLAVEREL",
        /// 4: master relative, slave absolute.
        MasterRelSlaveAbs = 4 => "master_rel_slave_abs" | "MC_STARTMODE_MASTERREL_SLAVEABS",
    }
}

/// [`CamInCall::start_mode`] 0: as MC_CamTableSelect chose (absolute for a table never
/// selected).
pub const CAM_START_AS_SELECTED: u32 = 0;

impl CamStartMode {
    /// Whether the master coordinate is measured from the coupling position.
    pub fn master_relative(self) -> bool {
        matches!(
            self,
            CamStartMode::Relative | CamStartMode::MasterRelSlaveAbs
        )
    }

    /// Whether the slave coordinate is measured from the coupling position.
    pub fn slave_relative(self) -> bool {
        matches!(
            self,
            CamStartMode::Relative | CamStartMode::MasterAbsSlaveRel
        )
    }
}

wire_enum! {
    /// `MC_CamActivationMode`: when a coupling, switch, rescaling or change of points takes
    /// effect (the positional modes take their position from the call body).
    CamActivationMode {
        /// 0: at once (in the next tick).
        Instantaneous = 0 => "instantaneous" | "MC_CAMACTIVATION_INSTANTANEOUS",
        /// 1: when the master's position within the cam passes the activation position.
        AtMasterCamPos = 1 => "at_master_cam_pos" | "MC_CAMACTIVATION_ATMASTERCAMPOS",
        /// 2: when the master axis passes the activation position (absolute).
        AtMasterAxisPos = 2 => "at_master_axis_pos" | "MC_CAMACTIVATION_ATMASTERAXISPOS",
        /// 3: at the next cycle boundary (a cyclic cam) or range edge (a linear one).
        NextCycle = 3 => "next_cycle" | "MC_CAMACTIVATION_NEXTCYCLE",
        /// 4: at the next cycle boundary, once.
        NextCycleOnce = 4 => "next_cycle_once" | "MC_CAMACTIVATION_NEXTCYCLEONCE",
        /// 5: as soon as possible (point data).
        AsSoonAsPossible = 5 => "as_soon_as_possible" | "MC_CAMACTIVATION_ASSOONASPOSSIBLE",
        /// 6: nothing is changed.
        Off = 6 => "off" | "MC_CAMACTIVATION_OFF",
        /// 7: a queued, not yet active change is dropped.
        DeleteQueuedData = 7 => "delete_queued_data" | "MC_CAMACTIVATION_DELETEQUEUEDDATA",
    }
}

wire_enum! {
    /// `MC_InterpolationType` of a position table.
    CamInterpolation {
        /// 0: straight lines between rows.
        Linear = 0 => "linear" | "MC_InterpolationType_Linear",
        /// 1: the cubic through the four nearest rows (equidistant tables only).
        FourPoint = 1 => "4point" | "MC_InterpolationType_4Point",
        /// 2: a cubic spline, tangential at the ends of a linear table, cyclic for a periodic
        /// one.
        Spline = 2 => "spline" | "MC_InterpolationType_Spline",
    }
}

wire_enum! {
    /// `MC_CamScalingMode` of one side (master or slave).
    CamScalingMode {
        /// 0: scaling and offset taken as given.
        UserDefined = 0 => "user_defined" | "MC_CAMSCALING_USERDEFINED",
        /// 1: scaling taken, offset computed so that nothing jumps.
        AutoOffset = 1 => "auto_offset" | "MC_CAMSCALING_AUTOOFFSET",
        /// 2: this side's scaling and offset stay as they are.
        Off = 2 => "off" | "MC_CAMSCALING_OFF",
    }
}

/// MC_CamTableSelect for the table given as `target` (its ID, 1..=255): how couplings
/// through it run when MC_CamIn does not say otherwise.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct CamTableSelectCall {
    /// 1: continued period by period (cyclic); 0: linear.
    pub periodic: u32,
    /// 1: master coordinates absolute; 0: relative to the coupling position.
    pub master_absolute: u32,
    /// 1: slave coordinates absolute; 0: relative to the coupling position.
    pub slave_absolute: u32,
    /// Reserved, 0.
    pub reserved: u32,
}

/// MC_CamIn (`extended` 0) or MC_CamInExt (`extended` 1) for the slave axis given as `target`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamInCall {
    /// Master axis index.
    pub master: u32,
    /// Cam table ID.
    pub table_id: u32,
    /// Raw [`CamStartMode`], or [`CAM_START_AS_SELECTED`].
    pub start_mode: u32,
    /// Raw [`CamActivationMode`] (MC_CamInExt; 0 for MC_CamIn).
    pub activation_mode: u32,
    /// Raw [`CamScalingMode`] of the master (MC_CamInExt; 0 for MC_CamIn).
    pub master_scaling_mode: u32,
    /// Raw [`CamScalingMode`] of the slave (MC_CamInExt; 0 for MC_CamIn).
    pub slave_scaling_mode: u32,
    /// Raw [`CamInterpolation`] of a table (0 linear, the seed's default; one other than
    /// the stored table's gives the coupling its own copy). Motion functions ignore it.
    pub interpolation: u32,
    /// 1 for MC_CamInExt: the coupling may later switch to another cam.
    pub extended: u32,
    /// Activation position of the positional activation modes.
    pub activation_position: f64,
    /// Master offset.
    pub master_offset: f64,
    /// Slave offset.
    pub slave_offset: f64,
    /// Master scaling (not 0).
    pub master_scaling: f64,
    /// Slave scaling.
    pub slave_scaling: f64,
    /// What of the master the slave follows: 0 its set-point (the seed's rule, 5.1.4), 1 its
    /// actual position (a master moved by hand or by a foreign drive).
    pub master_source: u32,
    /// Reserved, 0.
    pub reserved: u32,
}

/// MC_CamOut for the slave axis given as `target`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct CamOutCall {
    /// Reserved, 0.
    pub reserved: u32,
}

/// MC_CamScaling for the slave axis given as `target`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamScalingCall {
    /// Raw [`CamActivationMode`].
    pub activation_mode: u32,
    /// Raw [`CamScalingMode`] of the master.
    pub master_scaling_mode: u32,
    /// Raw [`CamScalingMode`] of the slave.
    pub slave_scaling_mode: u32,
    /// Values left as they are ([`CAM_KEEP_MASTER_SCALING`] ...); 0 for MC_CamScaling.
    pub reserved: u32,
    /// Activation position of the positional activation modes.
    pub activation_position: f64,
    /// Master offset.
    pub master_offset: f64,
    /// Slave offset.
    pub slave_offset: f64,
    /// Master scaling (not 0).
    pub master_scaling: f64,
    /// Slave scaling.
    pub slave_scaling: f64,
}

/// The reply to every cam call: 0 when accepted, else the error code of the refusal (the
/// seed's table codes 0x4B30.., [`crate::enums::AxisError`] or
/// [`CamCouplingError`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct CamReply {
    /// 0 when accepted.
    pub error_id: u32,
    /// Reserved, 0.
    pub reserved: u32,
}

/// One point of a motion function as the PLC holds it (`MC_MotionFunctionPoint`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct McMotionFunctionPoint {
    /// Absolute index, 1, 2, 3, ...
    pub point_index: u32,
    /// Raw `MC_MotionFunctionType` of the segment that starts here.
    pub function_type: u32,
    /// Raw `MC_MotionPointType`.
    pub point_type: u32,
    /// Relative index of the next point (normally 1).
    pub rel_index_next_point: u32,
    /// Master position.
    pub master_pos: f64,
    /// Slave position.
    pub slave_pos: f64,
    /// Slave velocity.
    pub slave_velo: f64,
    /// Slave acceleration.
    pub slave_acc: f64,
    /// Slave jerk (or the symmetry of the laws that have one).
    pub slave_jerk: f64,
}

/// Points that fit one call.
pub const CAM_POINTS_PER_CALL: usize = 4;

/// Bit of [`CamPointsWriteCall::flags`] and [`CamRowsWriteCall::flags`]: the last chunk of
/// the transfer; the CNC checks and takes the whole transfer now.
pub const CAM_CHUNK_LAST: u32 = 1;
/// Bit of [`CamPointsWriteCall::flags`] and [`CamRowsWriteCall::flags`]: the first chunk of
/// a transfer; whatever an earlier transfer to the table left unfinished is dropped.
pub const CAM_CHUNK_FIRST: u32 = 4;
/// Bit of [`CamPointsWriteCall::flags`]: the points make a new motion function under the
/// table ID (MC_CamTableSelect with data) instead of changing points of the existing one.
pub const CAM_POINTS_CREATE: u32 = 2;

/// A chunk of MC_WriteMotionFunction(Point) (or of a new motion function) for the table
/// given as `target`. A transfer is `total` points from point `first` on, sent in chunks in
/// order, the first flagged [`CAM_CHUNK_FIRST`]; nothing changes before its last chunk, which
/// the CNC checks whole.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamPointsWriteCall {
    /// Index of the first point of this chunk.
    pub first: u32,
    /// Points in this chunk (1..=4).
    pub count: u32,
    /// [`CAM_CHUNK_FIRST`], [`CAM_CHUNK_LAST`], [`CAM_POINTS_CREATE`].
    pub flags: u32,
    /// Points of the whole transfer.
    pub total: u32,
    /// The points; the first `count` are used.
    pub points: [McMotionFunctionPoint; CAM_POINTS_PER_CALL],
}

impl CamPointsWriteCall {
    /// One point written alone, in one chunk (MC_WriteMotionFunctionPoint's call).
    pub fn one(point: McMotionFunctionPoint) -> Self {
        let mut points = [McMotionFunctionPoint::default(); CAM_POINTS_PER_CALL];
        points[0] = point;
        CamPointsWriteCall {
            first: point.point_index,
            count: 1,
            flags: CAM_CHUNK_FIRST | CAM_CHUNK_LAST,
            total: 1,
            points,
        }
    }
}

/// MC_ReadMotionFunction(Point) for the table given as `target`: up to four points from
/// `first` on.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct CamPointsReadCall {
    /// Index of the first point to read.
    pub first: u32,
    /// Points wanted (0 or more than 4 reads as many as fit, up to 4).
    pub count: u32,
}

/// The reply to a [`CamPointsReadCall`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamPointsReply {
    /// 0 when read, else the error code.
    pub error_id: u32,
    /// Points read.
    pub count: u32,
    /// Points the function has.
    pub total: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// The points read.
    pub points: [McMotionFunctionPoint; CAM_POINTS_PER_CALL],
}

/// MC_SetCamOnlineChangeMode for the table given as `target`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamOnlineModeCall {
    /// Raw [`CamActivationMode`].
    pub activation_mode: u32,
    /// Raw [`CamScalingMode`] of the master when a change applies.
    pub master_scaling_mode: u32,
    /// Raw [`CamScalingMode`] of the slave when a change applies.
    pub slave_scaling_mode: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// Activation position of the positional modes.
    pub activation_position: f64,
}

/// Bit of [`CamRowsWriteCall::flags`]: with `count` 0, declares table `target` (type,
/// cyclic, `total` rows) for rows that follow with `table_type` 0 (CamTableCreate, then
/// CamTableWriteData).
pub const CAM_ROWS_DECLARE: u32 = 2;

/// Bits of [`CamScalingCall::reserved`]: values the call leaves as they are (the
/// compatibility blocks that change offsets or scalings alone): master scaling, slave
/// scaling, master offset, slave offset.
pub const CAM_KEEP_MASTER_SCALING: u32 = 1;
/// See [`CAM_KEEP_MASTER_SCALING`].
pub const CAM_KEEP_SLAVE_SCALING: u32 = 2;
/// See [`CAM_KEEP_MASTER_SCALING`].
pub const CAM_KEEP_MASTER_OFFSET: u32 = 4;
/// See [`CAM_KEEP_MASTER_SCALING`].
pub const CAM_KEEP_SLAVE_OFFSET: u32 = 8;

/// CamTableDelete for the table given as `target` (refused while a coupling uses it).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct CamTableDeleteCall {
    /// Reserved, 0.
    pub reserved: u32,
}

/// Rows of a position table that fit one call.
pub const CAM_ROWS_PER_CALL: usize = 13;

/// A chunk of a position table for the table ID given as `target` (MC_CamTableSelect with
/// data): `total` rows of `[master, slave]` from row 0 on, sent in order; the table is built
/// and checked whole with the last chunk.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamRowsWriteCall {
    /// Index (0-based) of the first row of this chunk.
    pub first_row: u32,
    /// Rows in this chunk (1..=13).
    pub count: u32,
    /// [`CAM_CHUNK_FIRST`], [`CAM_CHUNK_LAST`], [`CAM_ROWS_DECLARE`].
    pub flags: u32,
    /// Rows of the whole table.
    pub total: u32,
    /// Raw `MC_TableType` (10 equidistant, 11 non-equidistant).
    pub table_type: u32,
    /// Raw [`CamInterpolation`] the table keeps by default.
    pub interpolation: u32,
    /// 1: continued period by period.
    pub periodic: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// The rows; the first `count` are used.
    pub rows: [[f64; 2]; CAM_ROWS_PER_CALL],
}

wire_enum! {
    /// What a [`CamReadCall`] reads ([`CamReadCall::what`]).
    CamReadKind {
        /// 1: MC_ReadCamTableSlaveDynamics of the table given as `target` at master position
        /// `a`: slave position, velocity, acceleration (what the table type gives).
        SlaveDynamics = 1 => "slave_dynamics",
        /// 2: MC_ReadCamTableCharacteristics of the table given as `target`: the 31 values of
        /// `MC_TableCharacValues` in their order, for a master at constant velocity `a` (0:
        /// the normed values, for 1.0; a negative velocity runs the cam backwards), then the
        /// five organisation fields ([`TableOrganisation`]; the reserved block between is
        /// left out): 36 values.
        Characteristics = 2 => "characteristics",
        /// 3: MC_ReadMotionFunctionValues of the table given as `target`: rows
        /// `[master, the columns of mask]` from `a` to `b` in steps of `c`, row after row.
        Values = 3 => "values",
        /// 4: MC_CamInfo of the slave axis given as `target` (at master position `a` when
        /// `flags` bit 0 is set): the 40 values of `MC_CamInfoData` in their order (booleans
        /// 0 or 1, IDs and modes as numbers).
        Info = 4 => "info",
        /// 5: CamTableReadData of the table given as `target`: its rows `[master, slave]`,
        /// row after row (position tables only).
        Rows = 5 => "rows",
        /// 6: what the coupling of the slave axis given as `target` still waits to activate:
        /// a scaling (MC_CamScaling), a switch (MC_CamInExt), a point change of its table
        /// (1 or 0 each). MC_CamScaling is Done once its scaling no longer waits.
        Queued = 6 => "queued",
    }
}

/// Values in one [`CamValuesReply`].
pub const CAM_VALUES_PER_REPLY: usize = 28;

/// The organisation fields that close `MC_TableCharacValues` and `MC_FlyingSawCharacValues`
/// (after the 31 values and a reserved block): which table the values describe and its shape.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TableOrganisation {
    /// CamTableID.
    pub table_id: u32,
    /// NumberOfRows: the rows of a position table, the points of a motion function.
    pub rows: u32,
    /// NumberOfColumns: 2 for a position table (master, slave), 1 for a motion function.
    pub columns: u32,
    /// TableType: raw `MC_TableType` (10 equidistant, 11 non-equidistant, 22 motion function).
    pub table_type: u32,
    /// Periodic.
    pub periodic: bool,
}

/// `MC_TableType` of a motion function (`MC_TableType_TABULARTYPE_MOTIONFUNC`).
pub const TABLE_TYPE_MOTION_FUNCTION: u32 = 22;

/// The resource kind of a cam table ID (1..=255) that engines share: the cam engine holds the
/// tables it stores, the flying saw the one it plans its slave's motion in (256 - the
/// slave's axis ID, seed 001 chapter 13). `cnc_core::machine::Resource`.
pub const MOTION_TABLE: &str = "motion table";

impl TableOrganisation {
    /// The field names, in the structure's order.
    pub const FIELDS: [&'static str; 5] = [
        "CamTableID",
        "NumberOfRows",
        "NumberOfColumns",
        "TableType",
        "Periodic",
    ];

    /// The five fields as numbers, in [`Self::FIELDS`] order (Periodic 1 or 0).
    pub fn values(&self) -> [f64; 5] {
        [
            f64::from(self.table_id),
            f64::from(self.rows),
            f64::from(self.columns),
            f64::from(self.table_type),
            f64::from(u8::from(self.periodic)),
        ]
    }

    /// The fields from their numbers; `None` unless each is a whole number in its range.
    pub fn from_values(v: &[f64]) -> Option<TableOrganisation> {
        let whole = |x: f64| {
            (x.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(&x)).then_some(x as u32)
        };
        let [id, rows, columns, kind, periodic] = <[f64; 5]>::try_from(v).ok()?;
        Some(TableOrganisation {
            table_id: whole(id)?,
            rows: whole(rows)?,
            columns: whole(columns)?,
            table_type: whole(kind)?,
            periodic: match periodic {
                0.0 => false,
                1.0 => true,
                _ => return None,
            },
        })
    }
}

/// A read of cam data, answered as numbers in parts of [`CAM_VALUES_PER_REPLY`] (or fewer:
/// [`CamReadCall::part_len`]): part `k` holds values `28 k ..` of the whole answer.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamReadCall {
    /// Raw [`CamReadKind`]: what is read.
    pub what: u32,
    /// Which part of the answer.
    pub part: u32,
    /// `MC_ValueSelectType` mask of a values read (1 position, 2 velocity, 4 acceleration,
    /// 8 jerk).
    pub mask: u32,
    /// Bit 0 of an info read: at master position `a` rather than the master's position now.
    pub flags: u32,
    /// First parameter (master position; start of a values read).
    pub a: f64,
    /// End of a values read.
    pub b: f64,
    /// Increment of a values read.
    pub c: f64,
    /// Values per part (CamTableReadData's iBlockSize / 8): 0 or above
    /// [`CAM_VALUES_PER_REPLY`] is [`CAM_VALUES_PER_REPLY`]; part `k` then holds values
    /// `part_len k ..`.
    pub part_len: u32,
    /// A rows read (CamTableReadData's rows to read): at most this many rows, 0 for all; more
    /// rows than the table has is refused (0x4B36). 0 for every other read.
    pub rows: u32,
}

/// The answer to a [`CamReadCall`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamValuesReply {
    /// 0 when read, else the error code.
    pub error_id: u32,
    /// Values in this part.
    pub count: u32,
    /// Values of the whole answer.
    pub total: u32,
    /// Columns per row of a values read (else 1).
    pub columns: u32,
    /// The values.
    pub values: [f64; CAM_VALUES_PER_REPLY],
}

/// CamTableSetWeight for the table given as `target`: how it counts in a multi-table slave.
/// The CNC keeps it as it came as the table's scaling (`cnc_core::cam::multi_table::TableWeight`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct CamTableWeightCall {
    /// Weight W of the table in the sum (> 0).
    pub weight: f64,
    /// Master offset MO, added to the scaled master position.
    pub master_offset: f64,
    /// Master slope MS (multiplies the master position; not 0).
    pub master_slope: f64,
    /// Slave offset SO, added to the scaled slave value.
    pub slave_offset: f64,
    /// Slave slope SS, multiplies the slave value.
    pub slave_slope: f64,
    /// Lower end RL of the master range in which a profile table counts.
    pub range_low: f64,
    /// Upper end RH (RL < RH).
    pub range_high: f64,
}

impl Default for CamTableWeightCall {
    /// The neutral scaling: weight and slopes 1, no offsets, a range without ends.
    fn default() -> Self {
        CamTableWeightCall {
            weight: 1.0,
            master_offset: 0.0,
            master_slope: 1.0,
            slave_offset: 0.0,
            slave_slope: 1.0,
            range_low: f64::NEG_INFINITY,
            range_high: f64::INFINITY,
        }
    }
}

/// Tables of a multi-table slave.
pub const CAM_MULTI_TABLES: usize = 8;

/// CamTableCoupleAxesMultiTables for the slave axis given as `target`: couple (`on` 1) to
/// `master` through `tables` tables, the first `profiles` of them profile tables and the
/// others corrections; or decouple (`on` 0, the rest unused).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct CamMultiCoupleCall {
    /// Master axis index.
    pub master: u32,
    /// 1 couple, 0 decouple.
    pub on: u32,
    /// Tables used (1..=8).
    pub tables: u32,
    /// Profile tables among them (1..=tables), the first ones.
    pub profiles: u32,
    /// Table IDs.
    pub table_ids: [u32; CAM_MULTI_TABLES],
    /// 0: the master's set-point; 1: its actual values (an encoder master), as MC_CamIn's
    /// `master_source`.
    pub master_source: u32,
    /// Reserved, 0.
    pub reserved: u32,
}

wire_enum! {
    /// What a [`CamMultiTableCall`] does to its table ([`CamMultiTableCall::op`]).
    CamMultiTableOp {
        /// 1: CamTableEnableCorrectionTable, a correction table starts.
        EnableCorrection = 1 => "enable_correction",
        /// 2: CamTableDeactivateCyclicTable, a cyclic profile table ends at its next cycle
        /// boundary.
        StopCyclic = 2 => "stop_cyclic",
    }
}

/// A table of the multi-table slave given as `target`: start a correction (at once, or when
/// the master passes `position` if `flags` bit 0) or end a cyclic profile table at its next
/// cycle boundary.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamMultiTableCall {
    /// Raw [`CamMultiTableOp`]: what is done to the table.
    pub op: u32,
    /// The table ID.
    pub table: u32,
    /// Bit 0: a correction starts at `position` rather than at once.
    pub flags: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// Activation position of a correction.
    pub position: f64,
}

calls! { family "cam";
    /// [`CamTableSelectCall`]: MC_CamTableSelect.
    CAM_TABLE_SELECT = 10: CamTableSelectCall -> CamReply, command;
    /// [`CamInCall`]: MC_CamIn / MC_CamInExt.
    CAM_IN = 11: CamInCall -> CamReply, command;
    /// [`CamOutCall`]: MC_CamOut.
    CAM_OUT = 12: CamOutCall -> CamReply, command;
    /// [`CamScalingCall`]: MC_CamScaling.
    CAM_SCALING = 13: CamScalingCall -> CamReply, command;
    /// [`CamPointsWriteCall`]: a chunk of MC_WriteMotionFunction(Point).
    CAM_POINTS_WRITE = 14: CamPointsWriteCall -> CamReply, command;
    /// [`CamPointsReadCall`]: MC_ReadMotionFunction(Point).
    CAM_POINTS_READ = 15: CamPointsReadCall -> CamPointsReply, read_only;
    /// [`CamOnlineModeCall`]: MC_SetCamOnlineChangeMode.
    CAM_ONLINE_MODE = 16: CamOnlineModeCall -> CamReply, command;
    /// [`CamRowsWriteCall`]: a chunk of a position table.
    CAM_ROWS_WRITE = 17: CamRowsWriteCall -> CamReply, command;
    /// [`CamReadCall`]: cam data read in parts.
    CAM_READ = 18: CamReadCall -> CamValuesReply, read_only;
    /// [`CamTableWeightCall`]: CamTableSetWeight.
    CAM_TABLE_WEIGHT = 19: CamTableWeightCall -> CamReply, command;
    /// [`CamMultiCoupleCall`]: CamTableCoupleAxesMultiTables.
    CAM_MULTI_COUPLE = 20: CamMultiCoupleCall -> CamReply, command;
    /// [`CamMultiTableCall`]: a table of a multi-table slave.
    CAM_MULTI_TABLE = 21: CamMultiTableCall -> CamReply, command;
    /// [`CamTableDeleteCall`]: CamTableDelete.
    CAM_TABLE_DELETE = 22: CamTableDeleteCall -> CamReply, command;
}

// Every body fits one frame.
const _: () = {
    assert!(core::mem::size_of::<McMotionFunctionPoint>() == 56);
    assert!(core::mem::size_of::<CamPointsWriteCall>() <= ACYCLIC_BODY_SIZE);
    assert!(core::mem::size_of::<CamPointsReply>() <= ACYCLIC_BODY_SIZE);
    assert!(core::mem::size_of::<CamRowsWriteCall>() <= ACYCLIC_BODY_SIZE);
    assert!(core::mem::size_of::<CamValuesReply>() <= ACYCLIC_BODY_SIZE);
    assert!(core::mem::size_of::<CamInCall>() <= ACYCLIC_BODY_SIZE);
    assert!(core::mem::size_of::<CamScalingCall>() <= ACYCLIC_BODY_SIZE);
};

#[cfg(test)]
mod tests {
    use super::*;

    fn table<T: Copy>(
        all: &[T],
        raw: fn(T) -> u32,
        name: fn(T) -> &'static str,
    ) -> Vec<(&'static str, u32)> {
        all.iter().map(|&v| (name(v), raw(v))).collect()
    }

    #[test]
    fn the_mode_selectors_keep_their_names_and_numbers() {
        assert_eq!(
            table(CamStartMode::ALL, CamStartMode::raw, CamStartMode::name),
            [
                ("absolute", 1),
                ("relative", 2),
                ("master_abs_slave_rel", 3),
                ("master_rel_slave_abs", 4)
            ]
        );
        assert_eq!(
            table(
                CamActivationMode::ALL,
                CamActivationMode::raw,
                CamActivationMode::name
            ),
            [
                ("instantaneous", 0),
                ("at_master_cam_pos", 1),
                ("at_master_axis_pos", 2),
                ("next_cycle", 3),
                ("next_cycle_once", 4),
                ("as_soon_as_possible", 5),
                ("off", 6),
                ("delete_queued_data", 7)
            ]
        );
        assert_eq!(
            table(
                CamInterpolation::ALL,
                CamInterpolation::raw,
                CamInterpolation::name
            ),
            [("linear", 0), ("4point", 1), ("spline", 2)]
        );
        assert_eq!(
            table(
                CamScalingMode::ALL,
                CamScalingMode::raw,
                CamScalingMode::name
            ),
            [("user_defined", 0), ("auto_offset", 1), ("off", 2)]
        );
        assert_eq!(
            table(CamReadKind::ALL, CamReadKind::raw, CamReadKind::name),
            [
                ("slave_dynamics", 1),
                ("characteristics", 2),
                ("values", 3),
                ("info", 4),
                ("rows", 5),
                ("queued", 6)
            ]
        );
        assert_eq!(
            table(
                CamMultiTableOp::ALL,
                CamMultiTableOp::raw,
                CamMultiTableOp::name
            ),
            [("enable_correction", 1), ("stop_cyclic", 2)]
        );
    }

    #[test]
    fn a_selector_decodes_from_its_number_or_its_name() {
        for &mode in CamActivationMode::ALL {
            assert_eq!(CamActivationMode::from_raw(mode.raw()), Some(mode));
            assert_eq!(CamActivationMode::from_name(mode.name()), Some(mode));
        }
        assert_eq!(CamStartMode::from_raw(0), None);
        assert_eq!(CamScalingMode::from_raw(3), None);
        assert_eq!(
            CamInterpolation::from_name("4POINT"),
            Some(CamInterpolation::FourPoint)
        );
        assert_eq!(
            CamStartMode::from_name("Master_Abs_Slave_Rel"),
            Some(CamStartMode::MasterAbsSlaveRel)
        );
        assert_eq!(CamScalingMode::from_name("auto offset"), None);
        assert_eq!(CamReadKind::from_raw(0), None);
        assert_eq!(CamReadKind::from_raw(7), None);
        assert_eq!(CamMultiTableOp::from_raw(3), None);
        assert!(
            CamStartMode::Relative.master_relative() && CamStartMode::Relative.slave_relative()
        );
        assert!(!CamStartMode::MasterAbsSlaveRel.master_relative());
        assert!(CamStartMode::MasterRelSlaveAbs.master_relative());
        assert!(!CamStartMode::Absolute.slave_relative());
    }

    #[test]
    fn the_organisation_fields_go_to_numbers_and_back_and_refuse_what_they_cannot_be() {
        let org = TableOrganisation {
            table_id: 254,
            rows: 3,
            columns: 1,
            table_type: TABLE_TYPE_MOTION_FUNCTION,
            periodic: true,
        };
        assert_eq!(org.values(), [254.0, 3.0, 1.0, 22.0, 1.0]);
        assert_eq!(TableOrganisation::from_values(&org.values()), Some(org));
        for bad in [
            [254.5, 3.0, 1.0, 22.0, 0.0],
            [-1.0, 3.0, 1.0, 22.0, 0.0],
            [1.0, f64::NAN, 1.0, 22.0, 0.0],
            [1.0, 3.0, 1.0, 22.0, 2.0],
        ] {
            assert_eq!(TableOrganisation::from_values(&bad), None, "{bad:?}");
        }
        assert_eq!(TableOrganisation::from_values(&[1.0; 4]), None);
    }
}
