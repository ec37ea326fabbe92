//! The dynamic-coordinate-system control unit and its parts, byte-exact to the specification
//! (seed 003, section 2.2.2.1). ST path of the unit: `gpCh[channel_idx]^channel_mc_control.dyn_cs`.

use crate::desc::Bool;
use crate::hli_struct;

/// Highest index of the per-axis arrays of a coordinate system (X/Y/Z, A/B/C).
pub const HLI_CS_AXES_MAXIDX: usize = 2;
/// Number of elements of those arrays.
pub const HLI_CS_AXES: usize = HLI_CS_AXES_MAXIDX + 1;

hli_struct! {
    /// A coordinate system as integers: translation in 0.1 um, rotation A/B/C in 0.0001 degree.
    ///
    /// ST path: `gpCh[i]^channel_mc_control.dyn_cs.command_w` / `.request_r` / `.transition_w.kinematic_base_cs`.
    #[st = "HLI_COORDINATE_SYSTEM_INT", size = 32]
    pub struct HliCoordinateSystemInt {
        /// X/Y/Z translation in 0.1 um.
        pub translation: [i32; HLI_CS_AXES] => [0, Parent],
        /// Padding the specification names explicitly.
        pub fill_up_2: i32 => [12, Parent],
        /// A/B/C rotation in 0.0001 degree.
        pub rotation: [i32; HLI_CS_AXES] => [16, Parent],
        /// Padding.
        pub fill_up_1: i32 => [28, Parent],
    }
}

// Published as an iceoryx2 sample by the handshake benchmark's baseline.
crate::raw::zero_copy_send!(HliCoordinateSystemInt);

hli_struct! {
    /// State of the tracking (slave) channel as the CNC reports it.
    ///
    /// ST path: `gpCh[i]^channel_mc_control.dyn_cs.state_r`.
    #[st = "HLI_DYN_CS_STATE", size = 8]
    pub struct HliDynCsState {
        /// Raw `HLI_DYN_CS_*` value; decode with [`crate::enums::DynCsState::decode`]. The
        /// specification types it UDINT although ERROR is -1, so ERROR reads as 0xFFFF_FFFF.
        pub actual_state: u32 => [0, Parent],
        /// Padding.
        pub fill_up_1: i32 => [4, Parent],
    }
}

hli_struct! {
    /// A switching request from the PLC, equivalent to `#TRACK CS ON/OFF [ID=0 ...]`. The PLC
    /// fills every parameter first and writes `command` last; the CNC takes the transition when
    /// `command` is +1 or -1 and then resets `command` to 0.
    ///
    /// ST path: `gpCh[i]^channel_mc_control.dyn_cs.transition_w`.
    #[st = "HLI_DYN_CS_TRANSITION", size = 48]
    pub struct HliDynCsTransition {
        /// -1 deactivate, +1 activate, 0 nothing pending.
        pub command: i32 => [0, Both],
        /// Soft in/out-coupling filter length in ticks (like FILTER=).
        pub filter_max_ticks: u32 => [4, Parent],
        /// Tracking option (like OPTION=): 0 translation and rotation, 1 translation only.
        pub option: u32 => [8, Parent],
        /// Like WAIT.
        pub f_wait: Bool => [12, Parent],
        /// Like SET_ZERO.
        pub f_set_zero: Bool => [13, Parent],
        /// Like KIN_BASE.
        pub f_kin_base: Bool => [14, Parent],
        /// Like ROT_TRANS.
        pub f_rot_trans: Bool => [15, Parent],
        /// Static shift between the error point and the kinematic base (like X.. C..).
        pub kinematic_base_cs: HliCoordinateSystemInt => [16, Parent],
    }
}

hli_struct! {
    /// The control unit through which the PLC acts as master of a channel's dynamic coordinate
    /// system and switches its tracking.
    ///
    /// ST path: `gpCh[i]^channel_mc_control.dyn_cs`.
    #[st = "MC_CONTROL_DYN_CS_UNIT", size = 128]
    pub struct McControlDynCsUnit {
        /// The PLC takes over the unit (redirection).
        pub enable_w: Bool => [0, Plc],
        /// Flow control of `request_r` (request pattern: CNC sets TRUE, PLC sets FALSE).
        pub request_semaphore_rw: Bool => [1, Both],
        /// Flow control of `command_w` (command pattern: PLC sets TRUE, CNC sets FALSE).
        pub command_semaphore_rw: Bool => [2, Both],
        /// Padding.
        pub fill_up_1: Bool => [3, Plc],
        /// Padding.
        pub fill_up_2: i32 => [4, Plc],
        /// Coordinate system the CNC reports back (request pattern).
        pub request_r: HliCoordinateSystemInt => [8, Cnc],
        /// Coordinate system the PLC commands (command pattern, consumable datum).
        pub command_w: HliCoordinateSystemInt => [40, Plc],
        /// Switching request, see [`HliDynCsTransition`].
        pub transition_w: HliDynCsTransition => [72, Plc],
        /// Tracking state.
        pub state_r: HliDynCsState => [120, Cnc],
    }
}
