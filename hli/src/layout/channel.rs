//! Per-channel part of the image: `gpCh[channel_idx]^...`. Designed in the style of the
//! specification's units (explicit padding, natural alignment, asserted offsets).

use super::channel_control::HliChannelControlUnit;
use super::dyn_cs::{HliCoordinateSystemInt, McControlDynCsUnit};
use crate::desc::Bool;
use crate::hli_struct;

/// Path axes per channel in the image.
pub const HLI_CHANNEL_AXES: usize = 32;

hli_struct! {
    /// Per-axis display values of a channel, updated every interpolation tick.
    ///
    /// ST path: `gpCh[i]^bahn_state.coord_r[axis_idx]`.
    #[st = "HLI_COORD_STATE", size = 16]
    pub struct HliCoordState {
        /// Tool-centre-point set position in the machine coordinate system, 0.1 um (0.0001 deg
        /// for orientation). Filled only when the channel parameter `kin_trafo_display` is on.
        pub w0_position_r: i32 => [0, Cnc],
        /// Tool-centre-point set position after the dynamic coordinate system, 0.1 um.
        pub position_dyncs_r: i32 => [4, Cnc],
        /// Programmed position in the channel's coordinates (after offsets), 0.1 um.
        pub command_position_r: i32 => [8, Cnc],
        /// Tool-centre-point set position *before* the dynamic coordinate system (its input,
        /// beside `position_dyncs_r`, its output), 0.1 um (0.0001 deg for orientation).
        pub position_in_dyncs_r: i32 => [12, Cnc],
    }
}

hli_struct! {
    /// Path ("Bahn") state of a channel.
    ///
    /// ST path: `gpCh[i]^bahn_state`.
    #[st = "HLI_BAHN_STATE", size = 536]
    pub struct HliBahnState {
        /// Display values per path axis.
        pub coord_r: [HliCoordState; HLI_CHANNEL_AXES] => [0, Cnc],
        /// Block number (N word) of the block being interpolated.
        pub active_block_nr_r: i32 => [512, Cnc],
        /// Raw [`crate::enums::ProgramState`].
        pub program_state_r: i32 => [516, Cnc],
        /// Path feed, 1 um/s.
        pub path_feed_r: i32 => [520, Cnc],
        /// Error code of the channel, 0 when none.
        pub error_id_r: u32 => [524, Cnc],
        /// Interpolation ticks since start.
        pub tick_counter_r: u64 => [528, Cnc],
    }
}

hli_struct! {
    /// An M function the CNC announces to the PLC.
    ///
    /// ST path: `gpCh[i]^channel_mc_control.m_function.request_r`.
    #[st = "HLI_M_FUNCTION_REQUEST", size = 12]
    pub struct HliMFunctionRequest {
        /// M code number.
        pub m_code: i32 => [0, Parent],
        /// Block number (N word) of the block that programmed it.
        pub block_nr: i32 => [4, Parent],
        /// Running id of the announcement (1, 2, ...).
        pub request_id: u32 => [8, Parent],
    }
}

hli_struct! {
    /// The PLC's acknowledge of an announced M function.
    ///
    /// ST path: `gpCh[i]^channel_mc_control.m_function.ack_w`.
    #[st = "HLI_M_FUNCTION_ACK", size = 8]
    pub struct HliMFunctionAck {
        /// M code acknowledged.
        pub m_code: i32 => [0, Parent],
        /// Id of the announcement acknowledged.
        pub request_id: u32 => [4, Parent],
    }
}

hli_struct! {
    /// M-function handshake (M100/M101-style PLC actions). Two flows: the CNC announces an
    /// M function with the request pattern (`request_semaphore_rw`, CNC TRUE / PLC FALSE) and
    /// the PLC acknowledges it with the command pattern (`ack_semaphore_rw`, PLC TRUE / CNC
    /// FALSE), echoing the request id so a stale acknowledge cannot release a later block.
    ///
    /// ST path: `gpCh[i]^channel_mc_control.m_function`.
    #[st = "HLI_M_FUNCTION_UNIT", size = 24]
    pub struct HliMFunctionUnit {
        /// Flow control of the announcement.
        pub request_semaphore_rw: Bool => [0, Both],
        /// Flow control of the acknowledge.
        pub ack_semaphore_rw: Bool => [1, Both],
        /// Padding.
        pub fill_up_1: u8 => [2, Cnc],
        /// Padding.
        pub fill_up_2: u8 => [3, Cnc],
        /// The announcement.
        pub request_r: HliMFunctionRequest => [4, Cnc],
        /// The acknowledge.
        pub ack_w: HliMFunctionAck => [16, Plc],
    }
}

hli_struct! {
    /// Path override and feed hold, level values the PLC writes every cycle.
    ///
    /// ST path: `gpCh[i]^channel_mc_control.path_override`.
    #[st = "HLI_CHANNEL_OVERRIDE_UNIT", size = 16]
    pub struct HliChannelOverrideUnit {
        /// Feed override in 0.1 % (0..=2000); out-of-range values are rejected by the CNC.
        pub feed_override_w: u32 => [0, Plc],
        /// Rapid (G0) override in 0.1 % (0..=1000).
        pub rapid_override_w: u32 => [4, Plc],
        /// TRUE stops the path feed (decelerating, no contour violation).
        pub feed_hold_w: Bool => [8, Plc],
        /// Padding.
        pub fill_up_1: u8 => [9, Plc],
        /// Padding.
        pub fill_up_2: u16 => [10, Plc],
        /// Feed override the CNC applies, 0.1 %.
        pub feed_override_r: u32 => [12, Cnc],
    }
}

hli_struct! {
    /// What became of the PLC's dynamic-CS transitions (our unit; the manual's unit reports
    /// only the state): the CNC counts every transition it takes from `transition_w`, keeps
    /// the command word and whether it was carried out or refused (with the reason), and
    /// collects the tracking states passed since (bit `n` for state `n`, bit 4 for ERROR),
    /// so a PLC that runs every N ticks sees a state that lasted one tick. Beside it, the
    /// lag of the slave's axes while they catch up with a step of the compensation.
    ///
    /// ST path: `gpCh[i]^channel_mc_control.dyn_cs_result`.
    #[st = "HLI_DYN_CS_TRANSITION_RESULT", size = 32]
    pub struct HliDynCsTransitionResult {
        /// Transitions taken from `transition_w` so far (wraps).
        pub taken_count_r: u32 => [0, Cnc],
        /// The command word of the last one taken (as the PLC wrote it).
        pub command_r: i32 => [4, Cnc],
        /// 0: carried out; else why it was refused (`DynCsTransitionError`).
        pub error_id_r: u32 => [8, Cnc],
        /// Tracking states passed since it was taken: bit 0 INACTIVE, 1 ACTIVATING, 2 ACTIVE,
        /// 3 DEACTIVATING, 4 ERROR.
        pub states_seen_r: u32 => [12, Cnc],
        /// The distance between the tool pose the axes are commanded and the compensated
        /// one while they catch up with a step (0.1 um); 0 when they follow exactly.
        pub lag_translation_r: i32 => [16, Cnc],
        /// The angle between the two (0.0001 degree).
        pub lag_rotation_r: i32 => [20, Cnc],
        /// Catch-ups started since the CNC started (wraps).
        pub catch_ups_r: u32 => [24, Cnc],
        /// Padding.
        pub fill_up_1: u32 => [28, Cnc],
    }
}

hli_struct! {
    /// Control units of a channel.
    ///
    /// ST path: `gpCh[i]^channel_mc_control`.
    #[st = "HLI_CHANNEL_MC_CONTROL", size = 200]
    pub struct HliChannelMcControl {
        /// Dynamic coordinate system (PLC as master, tracking switch).
        pub dyn_cs: McControlDynCsUnit => [0, Parent],
        /// M-function handshake.
        pub m_function: HliMFunctionUnit => [128, Parent],
        /// Override and feed hold (ST element `path_override`).
        pub path_override: HliChannelOverrideUnit => [152, Parent],
        /// The outcome of the PLC's dynamic-CS transitions.
        pub dyn_cs_result: HliDynCsTransitionResult => [168, Parent],
    }
}

hli_struct! {
    /// The dynamic coordinate system a master channel publishes (`#CHANNEL INTERFACE ON
    /// [DYN_CS]`), read by tracking slave channels and by the PLC.
    ///
    /// ST path: `gpCh[i]^channel_interface.dyn_cs`.
    #[st = "HLI_DYN_CS_CHANNEL_INTERFACE", size = 40]
    pub struct HliDynCsChannelInterface {
        /// The channel publishes a dynamic coordinate system.
        pub enabled_r: Bool => [0, Cnc],
        /// `cs_r` holds valid values.
        pub valid_r: Bool => [1, Cnc],
        /// The master paused the supply (FREEZE); slaves take the values over softly on resume.
        pub freeze_r: Bool => [2, Cnc],
        /// Padding.
        pub fill_up_1: u8 => [3, Cnc],
        /// Incremented every tick the master updates `cs_r`.
        pub update_counter_r: u32 => [4, Cnc],
        /// The published frame (tool pose of the master, kinematic-specific).
        pub cs_r: HliCoordinateSystemInt => [8, Cnc],
    }
}

hli_struct! {
    /// Interfaces a channel offers to other channels.
    ///
    /// ST path: `gpCh[i]^channel_interface`.
    #[st = "HLI_CHANNEL_INTERFACE", size = 40]
    pub struct HliChannelInterface {
        /// Dynamic-coordinate-system output.
        pub dyn_cs: HliDynCsChannelInterface => [0, Parent],
    }
}

hli_struct! {
    /// Everything of one channel: `gpCh[channel_idx]^`.
    ///
    /// ST path: `gpCh[i]^`.
    #[st = "HLI_CHANNEL", size = 1072]
    pub struct HliChannel {
        /// Path state and display values.
        pub bahn_state: HliBahnState => [0, Parent],
        /// Control units.
        pub channel_mc_control: HliChannelMcControl => [536, Parent],
        /// Channel interface (dynamic CS master output).
        pub channel_interface: HliChannelInterface => [736, Parent],
        /// The PLC operates the channel (program select, start, stop, ...).
        pub channel_control: HliChannelControlUnit => [776, Parent],
    }
}

/// Convenience: the channel's published frame.
pub type PublishedFrame = HliCoordinateSystemInt;
