//! The vocabulary of the acyclic calls: the call kinds, each kind's typed request and reply
//! body ([`AcyclicCall`]), the ADS-style refusal codes, and the body decoding a handler uses.
//! The engines add their kinds to [`CallKind`].

pub mod axis;
pub mod cam;
pub mod diag;
pub mod fifo;
pub mod probe;
pub mod saw;

use crate::enums::InvalidValue;
use crate::wire::{encode_body, AcyclicRequest, ACYCLIC_BODY_SIZE};
use bytemuck::Pod;
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
    /// [`crate::calls::fifo::FifoDimensionCall`].
    FifoDimension,
    /// [`crate::calls::fifo::FifoIntegrateCall`].
    FifoIntegrate,
    /// [`crate::calls::fifo::FifoDisintegrateCall`].
    FifoDisintegrate,
    /// [`crate::calls::fifo::FifoStartCall`].
    FifoStart,
    /// [`crate::calls::fifo::FifoStopCall`].
    FifoStop,
    /// [`crate::calls::fifo::FifoOverrideCall`].
    FifoOverride,
    /// [`crate::calls::fifo::FifoParametersCall`].
    FifoParameters,
    /// [`crate::calls::saw::SawGearInCall`].
    SawGearIn,
    /// [`crate::calls::saw::SawGearOutCall`].
    SawGearOut,
    /// [`crate::calls::saw::SawCharacCall`].
    SawCharac,
    /// [`crate::calls::probe::ProbeArmCall`].
    ProbeArm,
    /// [`crate::calls::probe::ProbeAbortCall`].
    ProbeAbort,
    /// [`crate::calls::diag::DynCsHistoryReadCall`].
    DynCsHistoryRead,
    /// [`crate::calls::diag::DynCsLogReadCall`].
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
