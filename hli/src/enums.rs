//! Enumerations carried as raw integers in the image, decoded with validation: an unknown raw
//! value is an [`InvalidValue`] error, never undefined behaviour and never a silent default.

/// A raw value from the image that is not one of its type's values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("invalid {type_name} value {raw} (0x{raw:X}); allowed: {allowed}")]
pub struct InvalidValue {
    /// The enumeration the value was decoded as.
    pub type_name: &'static str,
    /// The raw value, widened.
    pub raw: i64,
    /// The values that would have been accepted.
    pub allowed: &'static str,
}

/// Declares a validated enumeration carried as a raw integer: the enum, `ALL`, `raw` and
/// `decode` (an unknown raw value is an [`InvalidValue`] naming `$st`). The one macro of every
/// enumeration on the wire: [`wire_enum!`] builds a call's mode selector on it.
macro_rules! hli_enum {
    (
        @enum
        $(#[doc = $doc:literal])*
        $name:ident : $raw:ty, $st:tt {
            $( $(#[doc = $vdoc:literal])* $variant:ident = $value:expr ),* $(,)?
        }
    ) => {
        $(#[doc = $doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum $name {
            $( $(#[doc = $vdoc])* $variant, )*
        }

        impl $name {
            /// Every variant, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$variant),*];

            /// The raw value stored in the image.
            pub const fn raw(self) -> $raw {
                match self { $( $name::$variant => $value, )* }
            }

            /// Decodes a raw value read from the image.
            pub const fn decode(raw: $raw) -> Result<Self, $crate::enums::InvalidValue> {
                $( if raw == $value { return Ok($name::$variant); } )*
                Err($crate::enums::InvalidValue {
                    type_name: $st,
                    raw: raw as i64,
                    allowed: concat!($( stringify!($value), " " ),*),
                })
            }
        }
    };
    (
        $(#[doc = $doc:literal])*
        $name:ident : $raw:ty, $st:literal {
            $( $(#[doc = $vdoc:literal])* $variant:ident = $value:expr ),* $(,)?
        }
    ) => {
        $crate::enums::hli_enum! {
            @enum
            $(#[doc = $doc])*
            $name: $raw, $st {
                $( $(#[doc = $vdoc])* $variant = $value ),*
            }
        }
    };
}

/// Declares a mode selector a call body carries as a raw `u32`: the enum, and `raw`,
/// `from_raw` (`None` for a number it does not have), `name`, `from_name` (ASCII case
/// ignored) and `ALL`, the names being what timelines and command lines give; the same as
/// [`WireEnum`] for code generic over them.
macro_rules! wire_enum {
    (@st) => { None };
    (@st $st:literal) => { Some($st) };
    (
        $(#[doc = $doc:literal])*
        $name:ident {
            $(
                $(#[doc = $vdoc:literal])*
                $variant:ident = $value:literal => $text:literal $(| $st:literal)?
            ),* $(,)?
        }
    ) => {
        $crate::enums::hli_enum! {
            @enum
            $(#[doc = $doc])*
            $name: u32, (stringify!($name)) {
                $( $(#[doc = $vdoc])* $variant = $value ),*
            }
        }

        impl $name {
            /// The value of a raw number, `None` for a number it does not have.
            pub const fn from_raw(raw: u32) -> Option<Self> {
                match $name::decode(raw) {
                    Ok(value) => Some(value),
                    Err(_) => None,
                }
            }

            /// The value's name.
            pub const fn name(self) -> &'static str {
                match self { $( $name::$variant => $text, )* }
            }

            /// The value's constant in the manuals' Structured Text
            /// (`MC_STARTMODE_ABSOLUTE`), where they name one.
            pub const fn st_name(self) -> Option<&'static str> {
                match self {
                    $( $name::$variant => $crate::enums::wire_enum!(@st $($st)?), )*
                }
            }

            /// The value of a name (ASCII case ignored), `None` for a name it does not have.
            pub fn from_name(name: &str) -> Option<Self> {
                <Self as $crate::enums::WireEnum>::from_name(name)
            }
        }

        impl $crate::enums::WireEnum for $name {
            const ALL: &'static [Self] = $name::ALL;
            fn raw(self) -> u32 {
                $name::raw(self)
            }
            fn from_raw(raw: u32) -> Option<Self> {
                $name::from_raw(raw)
            }
            fn name(self) -> &'static str {
                $name::name(self)
            }
            fn st_name(self) -> Option<&'static str> {
                $name::st_name(self)
            }
        }
    };
}
pub(crate) use {hli_enum, wire_enum};

/// Every `wire_enum!` type, for code generic over them (the PLC timeline takes a mode by
/// its name or its number).
pub trait WireEnum: Copy + 'static {
    /// Every value, in declaration order.
    const ALL: &'static [Self];
    /// The raw value on the wire.
    fn raw(self) -> u32;
    /// The value of a raw number, `None` for a number it does not have.
    fn from_raw(raw: u32) -> Option<Self>;
    /// The value's name.
    fn name(self) -> &'static str;
    /// The value's constant in the manuals' Structured Text, where they name one.
    fn st_name(self) -> Option<&'static str> {
        None
    }
    /// The value of a name (ASCII case ignored), `None` for a name it does not have.
    fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .iter()
            .copied()
            .find(|v| v.name().eq_ignore_ascii_case(name))
    }
}

hli_enum! {
    /// `HLI_DYN_CS_*`: state of a tracking channel. Carried in a UDINT, so ERROR (-1) is
    /// stored as 0xFFFF_FFFF.
    DynCsState: u32, "HLI_DYN_CS_STATE" {
        /// Not following.
        Inactive = 0,
        /// Coupling in softly through the filter.
        Activating = 1,
        /// Following the dynamic coordinate system.
        Active = 2,
        /// Coupling out softly.
        Deactivating = 3,
        /// Failed; cannot follow any more.
        Error = u32::MAX,
    }
}

impl DynCsState {
    /// The state's bit in `HLI_DYN_CS_TRANSITION_RESULT.states_seen_r`: bit n for state n,
    /// bit 4 for ERROR.
    pub fn seen_bit(self) -> u32 {
        1 << match self {
            DynCsState::Inactive => 0,
            DynCsState::Activating => 1,
            DynCsState::Active => 2,
            DynCsState::Deactivating => 3,
            DynCsState::Error => 4,
        }
    }
}

hli_enum! {
    /// `HLI_DYN_CS_TRANSITION.command`.
    DynCsCommand: i32, "HLI_DYN_CS_TRANSITION.command" {
        /// Nothing pending.
        None = 0,
        /// Switch tracking on.
        Activate = 1,
        /// Switch tracking off.
        Deactivate = -1,
    }
}

hli_enum! {
    /// `HLI_DYN_CS_TRANSITION.option`.
    DynCsOption: u32, "HLI_DYN_CS_TRANSITION.option" {
        /// Follow translation and rotation.
        TranslationAndRotation = 0,
        /// Follow the translation only.
        TranslationOnly = 1,
    }
}

hli_enum! {
    /// `nAxisState`: motion state of an axis. 0 and the slave states 11..13 are the values the
    /// flying-saw specification names; the master states 1..4 are our own numbering (the
    /// specification refers to documentation we do not have).
    AxisState: i32, "nAxisState" {
        /// Set-point generator not active.
        Inactive = 0,
        /// Master: accelerating.
        Accelerating = 1,
        /// Master: constant velocity.
        ConstantVelocity = 2,
        /// Master: decelerating.
        Decelerating = 3,
        /// Master: holding position at standstill under control.
        Standstill = 4,
        /// Slave: motion pre-phase.
        SlavePrephase = 11,
        /// Slave: synchronising.
        SlaveSynchronizing = 12,
        /// Slave: synchronous.
        SlaveSynchronous = 13,
    }
}

impl AxisState {
    /// Whether the axis is a slave (`nAxisState >= 10`).
    pub fn is_slave(self) -> bool {
        self.raw() >= 10
    }
}

hli_enum! {
    /// What an axis is coupled to.
    CouplingState: i32, "HLI_AXIS_LR_STATE.coupling_state_r" {
        /// A free master axis.
        Uncoupled = 0,
        /// Slave of an electronic cam.
        Cam = 1,
        /// Slave of a linear gear / flying saw (velocity synchronisation).
        GearVelocity = 2,
        /// Slave of a flying saw (position synchronisation).
        GearPosition = 3,
        /// Member of a FIFO axis group.
        Fifo = 4,
        /// Driven by a CNC channel's interpolator.
        Channel = 5,
    }
}

hli_enum! {
    /// State of a channel's program.
    ProgramState: i32, "HLI_BAHN_STATE.program_state_r" {
        /// No program selected or finished and reset.
        Idle = 0,
        /// Executing blocks.
        Running = 1,
        /// Waiting (synchronisation, M-function acknowledge, WAIT).
        Waiting = 2,
        /// Program ended with M30.
        Finished = 3,
        /// Stopped by an error.
        Error = -1,
    }
}

hli_enum! {
    /// Why a channel stopped (`HLI_BAHN_STATE.error_id_r`; 0 while it has no error). The seed
    /// names no channel error numbers; these are ours, one per kind of cause.
    ChannelErrorId: u32, "HLI_BAHN_STATE.error_id_r" {
        /// No error.
        None = 0,
        /// A block or statement failed when it was decoded or run (an expression, a call).
        Program = 0x4501,
        /// No velocity profile for a block (limits, a target that is not finite).
        Path = 0x4502,
        /// `#TRACK CS ON` refused (no master interface, own channel, already on).
        Tracking = 0x4503,
        /// `#CS` refused (no transformation, too many frames, a bad frame).
        CoordinateSystem = 0x4504,
        /// The kinematic transformation: a pose out of reach, an unconfigured kinematic.
        Kinematics = 0x4505,
        /// An independent axis move without a profile.
        IndependentAxis = 0x4506,
        /// `#SIGNAL SYN` with too many ids pending.
        Synchronisation = 0x4507,
        /// A machine stop (the PLC was lost, or a stop was requested).
        MachineStop = 0x4508,
        /// `#WAIT SYN` waited longer than the channel's `sync_timeout_s`, or a channel it
        /// waited for was stopped, reset or failed.
        SyncAbandoned = 0x4509,
    }
}

hli_enum! {
    /// Why the CNC refused a dynamic-CS transition of the PLC
    /// (`HLI_DYN_CS_TRANSITION_RESULT.error_id_r`; 0 when it carried it out). Ours: the seed
    /// defines no refusals.
    DynCsTransitionError: u32, "HLI_DYN_CS_TRANSITION_RESULT.error_id_r" {
        /// Carried out.
        None = 0,
        /// The command word was not -1, 0 or +1.
        CommandWord = 0x4511,
        /// A flag byte was neither FALSE nor TRUE.
        FlagByte = 0x4512,
        /// `option` was not 0 or 1.
        OptionValue = 0x4514,
        /// The kinematic-base frame was not finite.
        Offset = 0x4515,
        /// `enable_w` was FALSE.
        NotEnabled = 0x4516,
        /// +1 while tracking is on (ACTIVATING, ACTIVE or ERROR: switch it off first).
        AlreadyOn = 0x4517,
        /// `f_set_zero` while the channel's axes move (SET_ZERO needs standstill).
        SetZeroMoving = 0x4518,
        /// Refused for another reason of the tracker.
        Refused = 0x451F,
    }
}

hli_enum! {
    /// State of a FIFO axis group.
    FifoGroupState: i32, "HLI_FIFO_GROUP_STATE.group_state_r" {
        /// No job: axes may be integrated, the FIFO is empty.
        Idle = 0,
        /// Rows are queued, the group is not started yet.
        Filling = 1,
        /// Executing rows (also while the FIFO runs dry or the override is 0 %).
        Running = 2,
        /// FiFoStop: the override decays to 0; then the job ends and the group is Idle.
        Stopping = 3,
        /// An axis of the running group faulted; the job ended, the axes stand.
        Error = -1,
    }
}

hli_enum! {
    /// Direction output of the drive process image (`nCtrl2`, `nCtrl3`).
    DirectionBits: u8, "nCtrl direction" {
        /// Moving in the negative direction.
        Minus = 0x41,
        /// Moving in the positive direction.
        Plus = 0x42,
        /// Standing still.
        Stop = 0x80,
    }
}

hli_enum! {
    /// Field-bus I/O state (`nStatus4` of encoder and drive inputs).
    IoState: u8, "nStatus4" {
        /// Process data valid.
        Valid = 0,
        /// Process data invalid: the axis must treat this as a fault.
        Invalid = 1,
    }
}

hli_enum! {
    /// Life cycle of a segment, `HLI_SEGMENT_HEADER.segment_state`.
    SegmentState: u32, "HLI_SEGMENT_HEADER.segment_state" {
        /// Created, header not complete yet.
        Initialising = 0,
        /// The CNC runs; PLCs may attach.
        Ready = 1,
        /// The CNC shut down in order.
        Closed = 2,
    }
}

hli_enum! {
    /// The PLCopen-style motion commands an axis takes over the acyclic service.
    AxisCommandKind: u32, "AxisCommandKind" {
        /// MC_Power: enable (flag 1) or disable (flag 0) the axis.
        Power = 1,
        /// MC_Reset: clear the axis error once its cause is gone.
        Reset = 2,
        /// MC_MoveAbsolute: go to a position.
        MoveAbsolute = 3,
        /// MC_MoveRelative: go a distance from the current set position.
        MoveRelative = 4,
        /// MC_MoveVelocity: run endlessly at a velocity.
        MoveVelocity = 5,
        /// MC_Halt: brake to standstill; can be overridden by another move.
        Halt = 6,
        /// MC_Stop: brake to standstill and lock the axis until released.
        Stop = 7,
        /// Releases the lock of MC_Stop (its Execute input fell).
        StopRelease = 8,
        /// MC_SetPosition: at standstill, the encoder counts from the given position (its
        /// counter is set through the register interface); nothing moves.
        SetPosition = 9,
        /// A gear coupling of an engine (MC_GearInVelo, MC_GearInPos): active while it holds
        /// the axis; a new coupling of the axis, by any block, aborts it, and so does its end
        /// (MC_GearOut, MC_Stop).
        GearIn = 10,
        /// MC_MoveSuperimposed: a relative move added to the coupled motion of a cam or gear
        /// slave (the distance with at most the velocity difference given), beside the command
        /// that owns the axis; a new one aborts the one running, so do the coupling's end and
        /// an axis error.
        MoveSuperimposed = 11,
    }
}

hli_enum! {
    /// How a command ended (`HLI_AXIS_COMMAND_OUTCOME.result`).
    CommandResult: u32, "HLI_AXIS_COMMAND_OUTCOME.result" {
        /// Empty slot.
        None = 0,
        /// Reached its goal.
        Done = 1,
        /// Replaced by a newer command before reaching its goal.
        Aborted = 2,
        /// Ended with an error (see `error_id`).
        Error = 3,
    }
}

hli_enum! {
    /// Error codes of the axis layer: why a command was refused or an axis stopped. The
    /// specification leaves the numbers to the NC's error list, which it does not include; these
    /// are ours, grouped by cause.
    AxisError: u32, "AxisError" {
        /// Velocity not above zero, not finite, or above the axis maximum.
        InvalidVelocity = 0x4221,
        /// Acceleration not above zero, not finite, or above the axis maximum.
        InvalidAcceleration = 0x4222,
        /// Deceleration not above zero, not finite, or above the axis maximum.
        InvalidDeceleration = 0x4223,
        /// Jerk not above zero, not finite, or above the axis maximum.
        InvalidJerk = 0x4224,
        /// Target position not finite or outside the software limits.
        TargetOutsideLimits = 0x4225,
        /// Direction of MC_MoveVelocity is neither positive (1) nor negative (-1).
        InvalidDirection = 0x4226,
        /// Unknown flag bits or a reserved field not zero.
        InvalidParameter = 0x4227,
        /// The axis is not enabled (MC_Power).
        NotEnabled = 0x4230,
        /// The axis is a slave of a coupling (cam, gear, FIFO group, channel).
        Coupled = 0x4231,
        /// The axis is locked by MC_Stop.
        StopActive = 0x4232,
        /// The axis is in an error state; MC_Reset first.
        AxisInError = 0x4233,
        /// MC_Power off while the axis moves at speed is refused; stop first.
        MovingWhileDisable = 0x4234,
        /// MC_MoveSuperimposed on an axis no cam or gear engine holds (a free axis, a FIFO
        /// or channel axis): there is no coupled motion to add it to.
        SuperimposedNotCoupled = 0x4235,
        /// The following error exceeded its limit.
        FollowingError = 0x4240,
        /// The encoder's process data are invalid (`nStatus4`).
        EncoderIoInvalid = 0x4241,
        /// The drive's process data are invalid (`nStatus4`).
        DriveIoInvalid = 0x4242,
        /// A velocity move ran into a software limit and was stopped at it.
        SoftwareLimitReached = 0x4243,
        /// The set-point generator found no trajectory.
        GeneratorFailed = 0x4250,
        /// MC_Reset while the cause of the error is still present.
        ResetRefused = 0x4251,
        /// The drive reports a fault (CiA 402 Fault or Fault reaction active).
        DriveFault = 0x4244,
        /// The drive left Operation enabled on its own while the axis was enabled, or its
        /// status word holds no defined state.
        DriveStateInvalid = 0x4245,
        /// The drive's own following error (`drive_in.nInData1`, cyclic position mode) or its
        /// following-error bit exceeded the limit.
        ExternalFollowingError = 0x4246,
        /// The encoder reports an error (its configured bit of `enc_in.nStatus1`).
        EncoderError = 0x4247,
        /// A touch probe that is armed already was armed again; the first arming stays.
        ProbeAlreadyArmed = 0x4260,
        /// The axis has no touch probe of that number (its probe interface, or none).
        ProbeNotAvailable = 0x4261,
        /// Probe number, edge or window of a touch-probe call out of range.
        InvalidProbeParameter = 0x4262,
        /// MC_AbortTrigger for a probe that is not armed.
        ProbeNotArmed = 0x4263,
        /// The encoder's register is busy (the absolute position is still read at start-up,
        /// or a counter set waits for its answer).
        EncoderNotReady = 0x4252,
        /// The encoder cannot set its counter (`io.encoder_set_counter` is off).
        SetPositionNotSupported = 0x4253,
        /// MC_SetPosition while the axis moves (it needs standstill).
        SetPositionWhileMoving = 0x4254,
    }
}

hli_enum! {
    /// The drive's state machine as the CNC decodes it from `drive_in.nStatus1` (CiA 402
    /// status word, low byte), `HLI_AXIS_DRIVE_STATE.drive_state_r`.
    DriveState: u32, "HLI_AXIS_DRIVE_STATE.drive_state_r" {
        /// The axis does not evaluate a drive state (plain drive protocol).
        NotEvaluated = 0,
        /// Not ready to switch on.
        NotReadyToSwitchOn = 1,
        /// Switch on disabled.
        SwitchOnDisabled = 2,
        /// Ready to switch on.
        ReadyToSwitchOn = 3,
        /// Switched on.
        SwitchedOn = 4,
        /// Operation enabled: the drive follows the set-points.
        OperationEnabled = 5,
        /// Quick stop active.
        QuickStopActive = 6,
        /// Fault reaction active.
        FaultReactionActive = 7,
        /// Fault.
        Fault = 8,
    }
}

hli_enum! {
    /// A touch probe of an axis, `HLI_AXIS_PROBE.state_r`.
    ProbeState: u32, "HLI_AXIS_PROBE.state_r" {
        /// Not armed (never armed, or its result was read and it was armed no more).
        Idle = 0,
        /// Armed: the next matching edge records the position.
        Armed = 1,
        /// An edge recorded the position in `recorded_position_r`.
        Recorded = 2,
        /// MC_AbortTrigger (or the axis's probe interface lost its data) ended the arming.
        Aborted = 3,
    }
}

hli_enum! {
    /// Which edge of the probe input records (`HLI_AXIS_PROBE.edge_r`, MC_TouchProbe's
    /// trigger input).
    ProbeEdge: u32, "ProbeEdge" {
        /// The rising edge.
        Positive = 1,
        /// The falling edge.
        Negative = 2,
    }
}

/// Bits of `HLI_AXIS_DRIVE_STATE.drive_flags_r`: the CiA 402 status bits the CNC shows
/// (`drive_in.nStatus1` bit 7 and `nStatus2`, the status word's high byte).
pub mod drive_flags {
    /// Warning (status word bit 7).
    pub const WARNING: u32 = 1 << 0;
    /// Remote: the drive takes its commands from the field bus (bit 9).
    pub const REMOTE: u32 = 1 << 1;
    /// Target reached (bit 10).
    pub const TARGET_REACHED: u32 = 1 << 2;
    /// Internal limit active, e.g. torque or current limit (bit 11).
    pub const INTERNAL_LIMIT: u32 = 1 << 3;
    /// Cyclic position mode: the drive follows the command value (bit 12).
    pub const FOLLOWS_COMMAND: u32 = 1 << 4;
    /// Cyclic position mode: the drive's own following-error monitor tripped (bit 13).
    pub const FOLLOWING_ERROR: u32 = 1 << 5;
}

/// Bits of `HLI_AXIS_LR_STATE.status_r`.
pub mod axis_status {
    /// Drive enabled (MC_Power).
    pub const ENABLED: u32 = 1 << 0;
    /// Referenced / homed.
    pub const HOMED: u32 = 1 << 1;
    /// Set-point generator active.
    pub const MOVING: u32 = 1 << 2;
    /// Set position reached and following error within the window.
    pub const IN_TARGET: u32 = 1 << 3;
    /// The axis has an error (see `error_id_r`).
    pub const ERROR: u32 = 1 << 4;
    /// The process image reported I/O data invalid.
    pub const IO_INVALID: u32 = 1 << 5;
    /// A cam slave whose table has data written and not yet active (an online change
    /// waiting for its activation): the seed's bit for synchronising online changes, which
    /// `AxisCamDataQueued` reads.
    pub const CAM_DATA_QUEUED: u32 = 1 << 6;
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn dyn_cs_state_values_match_the_specification() {
        assert_eq!(DynCsState::Inactive.raw(), 0);
        assert_eq!(DynCsState::Activating.raw(), 1);
        assert_eq!(DynCsState::Active.raw(), 2);
        assert_eq!(DynCsState::Deactivating.raw(), 3);
        assert_eq!(DynCsState::Error.raw() as i32, -1);
        assert_eq!(DynCsState::decode(0xFFFF_FFFF), Ok(DynCsState::Error));
    }

    #[test]
    fn unknown_raw_value_is_a_typed_error() {
        let err = DynCsState::decode(7).unwrap_err();
        assert_eq!(err.raw, 7);
        assert_eq!(err.type_name, "HLI_DYN_CS_STATE");
        assert!(err.to_string().contains("invalid HLI_DYN_CS_STATE value 7"));
        assert!(AxisState::decode(10).is_err());
        assert!(DirectionBits::decode(0x40).is_err());
    }

    proptest! {
        #[test]
        fn decode_is_total_and_inverts_raw(raw in any::<i32>()) {
            match AxisState::decode(raw) {
                Ok(state) => prop_assert_eq!(state.raw(), raw),
                Err(e) => prop_assert!(AxisState::ALL.iter().all(|s| s.raw() != raw) && e.raw == raw as i64),
            }
        }
    }
}

mod channel;
pub use channel::*;
