//! Why the tracking went to ERROR or a switching request was refused, as values (rendered
//! to text outside the tick) and as two numbers for the diagnosis read over the acyclic
//! channel.

use super::guard::LimitKind;
use hli::enums::ChannelErrorId;

/// Why tracking went to ERROR (or a switching request was refused).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum TrackError {
    /// `#TRACK CS ON` while tracking is on.
    #[error("tracking is already on: switch it off first")]
    AlreadyOn,
    /// The master channel publishes no dynamic CS.
    #[error("master channel {0} provides no DYN_CS interface (#CHANNEL INTERFACE ON [DYN_CS] or provide_channel_interface.track_cs)")]
    NoMasterInterface(usize),
    /// The master channel does not exist.
    #[error("master channel {0} does not exist")]
    NoSuchChannel(usize),
    /// A channel cannot track itself.
    #[error("a channel cannot track its own interface")]
    OwnChannel,
    /// The PLC posted a transition while the unit was not enabled.
    #[error("PLC transition while enable_w is FALSE")]
    PlcNotEnabled,
    /// A transition with invalid parameters.
    #[error("invalid transition parameter: {0}")]
    BadTransition(BadParameter),
    /// The compensation could not be computed (non-finite frame).
    #[error("invalid master frame")]
    BadFrame,
    /// The machine stopped (its PLC was lost, or a stop was requested).
    #[error("machine stop")]
    MachineStop,
    /// A step of the tracked motion broke an axis's limit (refused, not passed on).
    #[error("axis {} {} limit exceeded by the tracked motion", axis + 1, limit_name(*kind))]
    JointLimit {
        /// Axis index in the channel (0-based).
        axis: u8,
        /// Which limit.
        kind: LimitKind,
    },
    /// The slave channel failed (its error id names the cause): it can no longer follow.
    #[error("the channel failed ({0:?})")]
    ChannelFailed(ChannelErrorId),
    /// The PLC stopped or reset the channel: its axes brake on their own limits and hold;
    /// the compensation they hold becomes part of the programmed position at rest.
    #[error("stopped by the PLC")]
    PlcStop,
    /// The axes lagged behind the compensation by more than `track_lag_max` (its
    /// translation, or with `rotation` its angle).
    #[error("the axes lag behind the compensation beyond track_lag_max.{}", if *rotation { "rotation" } else { "translation" })]
    LagBeyondBound {
        /// The angle broke the bound (else the distance).
        rotation: bool,
    },
    /// An axis's catch-up found no profile.
    #[error("axis {} found no catch-up profile", axis + 1)]
    NoCatchUp {
        /// Axis index in the channel (0-based).
        axis: u8,
    },
}

fn limit_name(kind: LimitKind) -> &'static str {
    match kind {
        LimitKind::Velocity => "velocity",
        LimitKind::Acceleration => "acceleration",
    }
}

impl TrackError {
    /// The error as two numbers (for the diagnosis read over the acyclic channel): its kind
    /// and its value (a channel, a parameter).
    pub fn code(self) -> (u32, u32) {
        match self {
            TrackError::AlreadyOn => (1, 0),
            TrackError::NoMasterInterface(c) => (2, c as u32),
            TrackError::NoSuchChannel(c) => (3, c as u32),
            TrackError::OwnChannel => (4, 0),
            TrackError::PlcNotEnabled => (5, 0),
            TrackError::BadTransition(p) => (6, p as u32),
            TrackError::BadFrame => (7, 0),
            TrackError::MachineStop => (8, 0),
            TrackError::JointLimit { axis, kind } => (
                9,
                u32::from(axis) * 2 + u32::from(kind == LimitKind::Acceleration),
            ),
            TrackError::ChannelFailed(id) => (10, id.raw()),
            TrackError::PlcStop => (11, 0),
            TrackError::LagBeyondBound { rotation } => (12, u32::from(rotation)),
            TrackError::NoCatchUp { axis } => (13, u32::from(axis)),
        }
    }

    /// The error [`Self::code`] gave; `None` for numbers it never gives.
    pub fn from_code(kind: u32, value: u32) -> Option<TrackError> {
        let channel = value as usize;
        Some(match kind {
            1 => TrackError::AlreadyOn,
            2 => TrackError::NoMasterInterface(channel),
            3 => TrackError::NoSuchChannel(channel),
            4 => TrackError::OwnChannel,
            5 => TrackError::PlcNotEnabled,
            6 => TrackError::BadTransition(
                BadParameter::ALL.into_iter().find(|p| *p as u32 == value)?,
            ),
            7 => TrackError::BadFrame,
            8 => TrackError::MachineStop,
            9 if value / 2 < u32::from(u8::MAX) => TrackError::JointLimit {
                axis: (value / 2) as u8,
                kind: if value % 2 == 1 {
                    LimitKind::Acceleration
                } else {
                    LimitKind::Velocity
                },
            },
            10 => TrackError::ChannelFailed(ChannelErrorId::decode(value).ok()?),
            11 => TrackError::PlcStop,
            12 if value < 2 => TrackError::LagBeyondBound {
                rotation: value == 1,
            },
            13 if value < u32::from(u8::MAX) => TrackError::NoCatchUp { axis: value as u8 },
            _ => return None,
        })
    }
}

/// Which parameter of a PLC transition was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum BadParameter {
    /// The command word.
    #[error("command word is not -1, 0 or +1")]
    CommandWord = 0,
    /// One of the flag bytes.
    #[error("a flag byte is neither FALSE nor TRUE")]
    FlagByte = 1,
    /// The option.
    #[error("option must be 0 or 1")]
    OptionValue = 3,
    /// The offset frame.
    #[error("offset X..C is not finite")]
    Offset = 4,
    /// SET_ZERO while the channel moves.
    #[error("f_set_zero needs the channel at standstill")]
    SetZeroMoving = 5,
}

impl BadParameter {
    /// Every parameter, in the order of their numbers.
    pub const ALL: [BadParameter; 5] = [
        BadParameter::CommandWord,
        BadParameter::FlagByte,
        BadParameter::OptionValue,
        BadParameter::Offset,
        BadParameter::SetZeroMoving,
    ];
}
