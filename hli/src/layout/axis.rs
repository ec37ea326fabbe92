//! Per-axis part of the image: `gpAx[axis_idx]^...`.

use super::axis_image::{NcDriveIn, NcDriveOut, NcEncoderIn, NcEncoderOut};
use crate::hli_struct;

hli_struct! {
    /// Cyclic state of an axis ("lr" = position controller), written by the CNC every tick.
    /// Positions in 0.1 um (linear) or 0.0001 degree (rotary).
    ///
    /// ST path: `gpAx[i]^lr_state`.
    #[st = "HLI_AXIS_LR_STATE", size = 48]
    pub struct HliAxisLrState {
        /// Actual position in the axis coordinate system.
        pub current_position_acs_r: i32 => [0, Cnc],
        /// Set position in the axis coordinate system.
        pub command_position_acs_r: i32 => [4, Cnc],
        /// Actual velocity, 0.1 um/s (0.0001 deg/s).
        pub current_velocity_r: i32 => [8, Cnc],
        /// Set velocity, 0.1 um/s (0.0001 deg/s).
        pub command_velocity_r: i32 => [12, Cnc],
        /// Set acceleration, 1 um/s^2 (0.001 deg/s^2).
        pub command_acceleration_r: i32 => [16, Cnc],
        /// Following error (set minus actual), 0.1 um.
        pub following_error_r: i32 => [20, Cnc],
        /// Motion state `nAxisState`; see [`crate::enums::AxisState`].
        pub axis_state_r: i32 => [24, Cnc],
        /// Coupling; see [`crate::enums::CouplingState`].
        pub coupling_state_r: i32 => [28, Cnc],
        /// Index of the master axis while coupled, -1 otherwise.
        pub master_axis_r: i32 => [32, Cnc],
        /// Error code of the axis, 0 when none.
        pub error_id_r: u32 => [36, Cnc],
        /// Status bits; see [`crate::enums::axis_status`].
        pub status_r: u32 => [40, Cnc],
        /// The axis's NC axis ID (the ID the NC and the manuals name it by; 0 when it has
        /// none): a PLC finds the image index of an axis ID here.
        pub nc_axis_id_r: u32 => [44, Cnc],
    }
}

hli_struct! {
    /// How one motion command of an axis ended.
    ///
    /// ST path: `gpAx[i]^command_state.outcomes_r[k]`.
    #[st = "HLI_AXIS_COMMAND_OUTCOME", size = 16]
    pub struct HliAxisCommandOutcome {
        /// Id of the command (as returned when it was accepted), 0 for an empty slot.
        pub command_id: u32 => [0, Cnc],
        /// Raw [`crate::enums::CommandResult`].
        pub result: u32 => [4, Cnc],
        /// Error code when the result is an error, else 0; see [`crate::enums::AxisError`].
        pub error_id: u32 => [8, Cnc],
        /// Raw [`crate::enums::AxisCommandKind`] of the command.
        pub kind: u32 => [12, Cnc],
    }
}

/// Outcome slots per axis: the last four finished commands.
pub const HLI_AXIS_OUTCOMES: usize = 4;

hli_struct! {
    /// The command book of an axis, written by the CNC every tick: which command owns the
    /// set-point generator and how the last ones ended. A PLC block that holds a command id
    /// derives Busy / Done / CommandAborted / Error from it without an acyclic call.
    ///
    /// ST path: `gpAx[i]^command_state`.
    #[st = "HLI_AXIS_COMMAND_STATE", size = 80]
    pub struct HliAxisCommandState {
        /// Id of the last accepted command (ids count up from 1 per axis).
        pub issued_id_r: u32 => [0, Cnc],
        /// Id of the command that owns the set-point generator, 0 when none.
        pub active_id_r: u32 => [4, Cnc],
        /// Whether the active command has reached its goal while still owning the axis
        /// (MC_MoveVelocity: in velocity; MC_Stop: stopped and held). 0 or 1.
        pub active_reached_r: u32 => [8, Cnc],
        /// Slot of `outcomes_r` written last.
        pub last_outcome_r: u32 => [12, Cnc],
        /// Ring of the last finished commands.
        pub outcomes_r: [HliAxisCommandOutcome; HLI_AXIS_OUTCOMES] => [16, Cnc],
    }
}

hli_struct! {
    /// One touch probe of an axis: the arming MC_TouchProbe made and what it recorded.
    ///
    /// ST path: `gpAx[i]^drive_state.probe_r[k]` (k 0: probe 1, k 1: probe 2).
    #[st = "HLI_AXIS_PROBE", size = 24]
    pub struct HliAxisProbe {
        /// Raw [`crate::enums::ProbeState`].
        pub state_r: u32 => [0, Cnc],
        /// Raw [`crate::enums::ProbeEdge`] of the current or last arming, 0 before the first.
        pub edge_r: u32 => [4, Cnc],
        /// Id of the current or last arming (counts up from 1 per probe; the reply to the
        /// arming call carries it), 0 before the first.
        pub arm_id_r: u32 => [8, Cnc],
        /// Raw [`crate::enums::AxisError`] that ended the last arming, 0 when none.
        pub error_id_r: u32 => [12, Cnc],
        /// Position the edge recorded, in axis units (mm or degree), valid while `state_r`
        /// is Recorded.
        pub recorded_position_r: f64 => [16, Cnc],
    }
}

/// Touch probes per axis.
pub const HLI_AXIS_PROBES: usize = 2;

hli_struct! {
    /// What the CNC made of the drive's and encoder's optional inputs (seed 004): the drive's
    /// own following error, its torque, its state machine, the distributed-clock times and the
    /// touch probes.
    ///
    /// ST path: `gpAx[i]^drive_state`.
    #[st = "HLI_AXIS_DRIVE_STATE", size = 80]
    pub struct HliAxisDriveState {
        /// The drive's following error (`drive_in.nInData1`, cyclic position mode), 0.1 um
        /// (0.0001 degree); 0 in the other drive modes.
        pub drive_following_error_r: i32 => [0, Cnc],
        /// Actual torque (`drive_in.nInData3`), 0.1 % of the rated torque.
        pub actual_torque_r: i32 => [4, Cnc],
        /// Raw [`crate::enums::DriveState`].
        pub drive_state_r: u32 => [8, Cnc],
        /// Bits of [`crate::enums::drive_flags`].
        pub drive_flags_r: u32 => [12, Cnc],
        /// How long before the tick the encoder reading was taken (`nDcInputTime`), ns; 0
        /// without dead-time compensation.
        pub dc_input_lag_r: i32 => [16, Cnc],
        /// How long after the end of the tick the drive applies its set-point
        /// (`nDcOutputTime`), ns; 0 without dead-time compensation.
        pub dc_output_shift_r: i32 => [20, Cnc],
        /// Input words with undefined bits or patterns (status bytes, DC times) counted
        /// since start; such a word is not used.
        pub undefined_inputs_r: u32 => [24, Cnc],
        /// Id of the MC_MoveSuperimposed running on the axis beside its main command (see
        /// `HLI_AXIS_COMMAND_STATE`: its outcome goes to the same ring), 0 when none.
        pub superimposed_id_r: u32 => [28, Cnc],
        /// The touch probes.
        pub probe_r: [HliAxisProbe; HLI_AXIS_PROBES] => [32, Cnc],
    }
}

hli_struct! {
    /// Everything of one axis: `gpAx[axis_idx]^`.
    ///
    /// ST path: `gpAx[i]^`.
    #[st = "HLI_AXIS", size = 352]
    pub struct HliAxis {
        /// Cyclic state.
        pub lr_state: HliAxisLrState => [0, Parent],
        /// Encoder inputs (process image).
        pub enc_in: NcEncoderIn => [48, Parent],
        /// Encoder outputs (process image).
        pub enc_out: NcEncoderOut => [88, Parent],
        /// Drive inputs (process image).
        pub drive_in: NcDriveIn => [120, Parent],
        /// Drive outputs (process image).
        pub drive_out: NcDriveOut => [160, Parent],
        /// The command book.
        pub command_state: HliAxisCommandState => [192, Parent],
        /// The drive's and encoder's optional inputs, evaluated.
        pub drive_state: HliAxisDriveState => [272, Parent],
    }
}
