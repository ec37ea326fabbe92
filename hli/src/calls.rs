//! The vocabulary of the acyclic calls: the call kinds, each kind's typed request and reply
//! body ([`AcyclicCall`]), the ADS-style refusal codes, and the body decoding a handler uses.
//! The engines add their kinds to [`CallKind`].

mod axis;
pub use axis::{AxisCommandCall, AxisCommandReply};

use crate::enums::InvalidValue;
use crate::layout::HliAxisLrState;
use crate::wire::{encode_body, AcyclicRequest, ACYCLIC_BODY_SIZE};
use bytemuck::{Pod, Zeroable};
use core::time::Duration;

macro_rules! codes {
    ($( $(#[doc = $d:literal])* $name:ident = $v:literal ),* $(,)?) => {
        /// Why a call was refused: ADS-style device error codes.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum ErrorCode { $( $(#[doc = $d])* $name, )* }
        impl ErrorCode {
            /// The numeric code.
            pub fn raw(self) -> u32 { match self { $( ErrorCode::$name => $v, )* } }
            /// Decodes a numeric code.
            pub fn decode(raw: u32) -> Result<Self, InvalidValue> {
                $( if raw == $v { return Ok(ErrorCode::$name); } )*
                Err(InvalidValue { type_name: "ErrorCode", raw: raw as i64,
                                   allowed: concat!($(stringify!($v), " "),*) })
            }
        }
    };
}

codes! {
    /// The call kind is not known to the server (0x701, service not supported).
    ServiceNotSupported = 0x701,
    /// The target (axis, channel, table) does not exist (0x703, invalid index offset).
    InvalidTarget = 0x703,
    /// The body has the wrong size for the kind (0x705, invalid size).
    InvalidSize = 0x705,
    /// The body's values are not acceptable (0x706, invalid data).
    InvalidData = 0x706,
    /// The addressed object is busy or in a state that refuses the call (0x712, busy).
    Busy = 0x712,
}

/// Numbers of the call kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CallKind {
    /// [`ReadAxisState`].
    ReadAxisState,
    /// [`AxisCommandCall`].
    AxisCommand,
    /// [`CamTableSelectCall`].
    CamTableSelect,
    /// [`CamInCall`].
    CamIn,
    /// [`CamOutCall`].
    CamOut,
    /// [`CamScalingCall`].
    CamScaling,
    /// [`CamPointsWriteCall`].
    CamPointsWrite,
    /// [`CamPointsReadCall`].
    CamPointsRead,
    /// [`CamOnlineModeCall`].
    CamOnlineMode,
    /// [`CamRowsWriteCall`].
    CamRowsWrite,
    /// [`CamReadCall`].
    CamRead,
    /// [`CamTableWeightCall`].
    CamTableWeight,
    /// [`CamMultiCoupleCall`].
    CamMultiCouple,
    /// [`CamMultiTableCall`].
    CamMultiTable,
    /// [`CamTableDeleteCall`].
    CamTableDelete,
    /// [`crate::fifo_calls::FifoDimensionCall`].
    FifoDimension,
    /// [`crate::fifo_calls::FifoIntegrateCall`].
    FifoIntegrate,
    /// [`crate::fifo_calls::FifoDisintegrateCall`].
    FifoDisintegrate,
    /// [`crate::fifo_calls::FifoStartCall`].
    FifoStart,
    /// [`crate::fifo_calls::FifoStopCall`].
    FifoStop,
    /// [`crate::fifo_calls::FifoOverrideCall`].
    FifoOverride,
    /// [`crate::fifo_calls::FifoParametersCall`].
    FifoParameters,
    /// [`crate::saw_calls::SawGearInCall`].
    SawGearIn,
    /// [`crate::saw_calls::SawGearOutCall`].
    SawGearOut,
    /// [`crate::saw_calls::SawCharacCall`].
    SawCharac,
    /// [`crate::probe_calls::ProbeArmCall`].
    ProbeArm,
    /// [`crate::probe_calls::ProbeAbortCall`].
    ProbeAbort,
    /// [`crate::diag_calls::DynCsHistoryReadCall`].
    DynCsHistoryRead,
    /// [`crate::diag_calls::DynCsLogReadCall`].
    DynCsLogRead,
}

impl CallKind {
    /// The raw kind number.
    pub fn raw(self) -> u32 {
        match self {
            CallKind::ReadAxisState => 1,
            CallKind::AxisCommand => 2,
            CallKind::CamTableSelect => 10,
            CallKind::CamIn => 11,
            CallKind::CamOut => 12,
            CallKind::CamScaling => 13,
            CallKind::CamPointsWrite => 14,
            CallKind::CamPointsRead => 15,
            CallKind::CamOnlineMode => 16,
            CallKind::CamRowsWrite => 17,
            CallKind::CamRead => 18,
            CallKind::CamTableWeight => 19,
            CallKind::CamMultiCouple => 20,
            CallKind::CamMultiTable => 21,
            CallKind::CamTableDelete => 22,
            CallKind::FifoDimension => 30,
            CallKind::FifoIntegrate => 31,
            CallKind::FifoDisintegrate => 32,
            CallKind::FifoStart => 33,
            CallKind::FifoStop => 34,
            CallKind::FifoOverride => 35,
            CallKind::FifoParameters => 36,
            CallKind::SawGearIn => 40,
            CallKind::SawGearOut => 41,
            CallKind::SawCharac => 42,
            CallKind::ProbeArm => 50,
            CallKind::ProbeAbort => 51,
            CallKind::DynCsHistoryRead => 60,
            CallKind::DynCsLogRead => 61,
        }
    }

    /// Decodes a raw kind number.
    pub fn decode(raw: u32) -> Option<Self> {
        match raw {
            1 => Some(CallKind::ReadAxisState),
            2 => Some(CallKind::AxisCommand),
            10 => Some(CallKind::CamTableSelect),
            11 => Some(CallKind::CamIn),
            12 => Some(CallKind::CamOut),
            13 => Some(CallKind::CamScaling),
            14 => Some(CallKind::CamPointsWrite),
            15 => Some(CallKind::CamPointsRead),
            16 => Some(CallKind::CamOnlineMode),
            17 => Some(CallKind::CamRowsWrite),
            18 => Some(CallKind::CamRead),
            19 => Some(CallKind::CamTableWeight),
            20 => Some(CallKind::CamMultiCouple),
            21 => Some(CallKind::CamMultiTable),
            22 => Some(CallKind::CamTableDelete),
            30 => Some(CallKind::FifoDimension),
            31 => Some(CallKind::FifoIntegrate),
            32 => Some(CallKind::FifoDisintegrate),
            33 => Some(CallKind::FifoStart),
            34 => Some(CallKind::FifoStop),
            35 => Some(CallKind::FifoOverride),
            36 => Some(CallKind::FifoParameters),
            40 => Some(CallKind::SawGearIn),
            41 => Some(CallKind::SawGearOut),
            42 => Some(CallKind::SawCharac),
            50 => Some(CallKind::ProbeArm),
            51 => Some(CallKind::ProbeAbort),
            60 => Some(CallKind::DynCsHistoryRead),
            61 => Some(CallKind::DynCsLogRead),
            _ => None,
        }
    }
}

/// A typed call: request body `Self`, reply body `Reply`.
pub trait AcyclicCall: Pod {
    /// The kind number.
    const KIND: CallKind;
    /// The reply body.
    type Reply: Pod;
}

/// Reads the cyclic state of the axis given as `target`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct ReadAxisState {
    /// Reserved, must be 0.
    pub reserved: u32,
}

impl AcyclicCall for ReadAxisState {
    const KIND: CallKind = CallKind::ReadAxisState;
    type Reply = HliAxisLrState;
}

const _: () = assert!(core::mem::size_of::<HliAxisLrState>() <= ACYCLIC_BODY_SIZE);

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
    /// Raw `MC_StartMode` (1..=4).
    pub start_mode: u32,
    /// Raw `MC_CamActivationMode` (MC_CamInExt; 0 for MC_CamIn).
    pub activation_mode: u32,
    /// Raw `MC_CamScalingMode` of the master (MC_CamInExt; 0 for MC_CamIn).
    pub master_scaling_mode: u32,
    /// Raw `MC_CamScalingMode` of the slave (MC_CamInExt; 0 for MC_CamIn).
    pub slave_scaling_mode: u32,
    /// Raw `MC_InterpolationType` of a table (0 linear, the seed's default; one other than
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
    /// Raw `MC_CamActivationMode`.
    pub activation_mode: u32,
    /// Raw `MC_CamScalingMode` of the master.
    pub master_scaling_mode: u32,
    /// Raw `MC_CamScalingMode` of the slave.
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
/// [`crate::enums::CamCouplingError`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct CamReply {
    /// 0 when accepted.
    pub error_id: u32,
    /// Reserved, 0.
    pub reserved: u32,
}

impl AcyclicCall for CamTableSelectCall {
    const KIND: CallKind = CallKind::CamTableSelect;
    type Reply = CamReply;
}

impl AcyclicCall for CamInCall {
    const KIND: CallKind = CallKind::CamIn;
    type Reply = CamReply;
}

impl AcyclicCall for CamOutCall {
    const KIND: CallKind = CallKind::CamOut;
    type Reply = CamReply;
}

impl AcyclicCall for CamScalingCall {
    const KIND: CallKind = CallKind::CamScaling;
    type Reply = CamReply;
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
    /// Raw `MC_CamActivationMode`.
    pub activation_mode: u32,
    /// Raw `MC_CamScalingMode` of the master when a change applies.
    pub master_scaling_mode: u32,
    /// Raw `MC_CamScalingMode` of the slave when a change applies.
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

/// [`CamReadCall::what`]: CamTableReadData of the table given as `target`: its rows
/// `[master, slave]`, row after row (position tables only).
pub const CAM_READ_ROWS: u32 = 5;

/// CamTableDelete for the table given as `target` (refused while a coupling uses it).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct CamTableDeleteCall {
    /// Reserved, 0.
    pub reserved: u32,
}

impl AcyclicCall for CamTableDeleteCall {
    const KIND: CallKind = CallKind::CamTableDelete;
    type Reply = CamReply;
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
    /// Raw `MC_InterpolationType` the table keeps by default.
    pub interpolation: u32,
    /// 1: continued period by period.
    pub periodic: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// The rows; the first `count` are used.
    pub rows: [[f64; 2]; CAM_ROWS_PER_CALL],
}

/// [`CamReadCall::what`]: MC_ReadCamTableSlaveDynamics of the table given as `target` at
/// master position `a`: slave position, velocity, acceleration (what the table type gives).
pub const CAM_READ_SLAVE_DYNAMICS: u32 = 1;
/// [`CamReadCall::what`]: MC_ReadCamTableCharacteristics of the table given as `target`: the
/// 31 values of `MC_TableCharacValues` in their order.
pub const CAM_READ_CHARACTERISTICS: u32 = 2;
/// [`CamReadCall::what`]: MC_ReadMotionFunctionValues of the table given as `target`: rows
/// `[master, the columns of mask]` from `a` to `b` in steps of `c`, row after row.
pub const CAM_READ_VALUES: u32 = 3;
/// [`CamReadCall::what`]: MC_CamInfo of the slave axis given as `target` (at master
/// position `a` when `flags` bit 0 is set): the 40 values of `MC_CamInfoData` in their order
/// (booleans 0 or 1, IDs and modes as numbers).
pub const CAM_READ_INFO: u32 = 4;
/// Values in one [`CamValuesReply`].
pub const CAM_VALUES_PER_REPLY: usize = 28;

/// A read of cam data, answered as numbers in parts of [`CAM_VALUES_PER_REPLY`]: part `k`
/// holds values `28 k ..` of the whole answer.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamReadCall {
    /// [`CAM_READ_SLAVE_DYNAMICS`], [`CAM_READ_CHARACTERISTICS`], [`CAM_READ_VALUES`],
    /// [`CAM_READ_INFO`].
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

impl AcyclicCall for CamReadCall {
    const KIND: CallKind = CallKind::CamRead;
    type Reply = CamValuesReply;
}

/// CamTableSetWeight for the table given as `target`: how it counts in a multi-table slave.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamTableWeightCall {
    /// Weight W (> 0).
    pub weight: f64,
    /// Master offset MO.
    pub master_offset: f64,
    /// Master slope MS (multiplies the master position; not 0).
    pub master_slope: f64,
    /// Slave offset SO.
    pub slave_offset: f64,
    /// Slave slope SS.
    pub slave_slope: f64,
    /// Lower end RL of the master range in which a profile table counts.
    pub range_low: f64,
    /// Upper end RH (RL < RH).
    pub range_high: f64,
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
}

/// [`CamMultiTableCall::op`]: CamTableEnableCorrectionTable.
pub const CAM_MULTI_ENABLE_CORRECTION: u32 = 1;
/// [`CamMultiTableCall::op`]: CamTableDeactivateCyclicTable.
pub const CAM_MULTI_STOP_CYCLIC: u32 = 2;

/// A table of the multi-table slave given as `target`: start a correction (at once, or when
/// the master passes `position` if `flags` bit 0) or end a cyclic profile table at its next
/// cycle boundary.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct CamMultiTableCall {
    /// [`CAM_MULTI_ENABLE_CORRECTION`] or [`CAM_MULTI_STOP_CYCLIC`].
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

impl AcyclicCall for CamTableWeightCall {
    const KIND: CallKind = CallKind::CamTableWeight;
    type Reply = CamReply;
}

impl AcyclicCall for CamMultiCoupleCall {
    const KIND: CallKind = CallKind::CamMultiCouple;
    type Reply = CamReply;
}

impl AcyclicCall for CamMultiTableCall {
    const KIND: CallKind = CallKind::CamMultiTable;
    type Reply = CamReply;
}

impl AcyclicCall for CamPointsWriteCall {
    const KIND: CallKind = CallKind::CamPointsWrite;
    type Reply = CamReply;
}

impl AcyclicCall for CamPointsReadCall {
    const KIND: CallKind = CallKind::CamPointsRead;
    type Reply = CamPointsReply;
}

impl AcyclicCall for CamOnlineModeCall {
    const KIND: CallKind = CallKind::CamOnlineMode;
    type Reply = CamReply;
}

impl AcyclicCall for CamRowsWriteCall {
    const KIND: CallKind = CallKind::CamRowsWrite;
    type Reply = CamReply;
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

/// Why a call did not produce a reply.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CallError {
    /// The server refused it.
    #[error("refused with error 0x{:X} ({code:?})", code.raw())]
    Refused {
        /// The server's code.
        code: ErrorCode,
    },
    /// The server answered with something that does not decode.
    #[error("malformed response: {0}")]
    Malformed(String),
    /// No answer within the timeout.
    #[error("no response within {0:?}")]
    Timeout(Duration),
    /// iceoryx2 failed.
    #[error("request-response service: {0}")]
    Transport(String),
}

/// Decodes a request body as `T`; a size mismatch is [`ErrorCode::InvalidSize`].
pub fn decode_body<T: Pod>(request: &AcyclicRequest) -> Result<T, ErrorCode> {
    let len = request.body_len as usize;
    if len != core::mem::size_of::<T>() {
        return Err(ErrorCode::InvalidSize);
    }
    Ok(bytemuck::pod_read_unaligned(&request.body[..len]))
}

/// Decodes a handler's reply body as `C`'s reply; a size mismatch is
/// [`ErrorCode::InvalidSize`].
pub fn decode_reply<C: AcyclicCall>(
    body: &[u8; ACYCLIC_BODY_SIZE],
    len: u32,
) -> Result<C::Reply, ErrorCode> {
    if len as usize != core::mem::size_of::<C::Reply>() {
        return Err(ErrorCode::InvalidSize);
    }
    Ok(bytemuck::pod_read_unaligned(&body[..len as usize]))
}

/// A reply a handler produces: the encoded body or a refusal.
pub type HandlerResult = Result<([u8; ACYCLIC_BODY_SIZE], u32), ErrorCode>;

/// Encodes a typed reply for a handler.
pub fn reply<T: Pod>(value: &T) -> HandlerResult {
    Ok(encode_body(value))
}
