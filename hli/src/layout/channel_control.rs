//! The channel control unit: the PLC operates a channel (select a program, start, stop, feed
//! hold, resume, reset, single block, mode) and reads what the channel is doing. Our own
//! unit in the style of the specification's units: a command guarded by a semaphore (PLC
//! TRUE / CNC FALSE, the command pattern) and a state block the CNC writes every tick.

use crate::desc::Bool;
use crate::hli_struct;

/// Room for a program name in the unit (bytes, NUL-padded).
pub const PROGRAM_NAME_LEN: usize = 64;
/// Room for the text of a refusal (bytes, NUL-padded).
pub const CONTROL_MESSAGE_LEN: usize = 96;

hli_struct! {
    /// A command of the PLC to its channel.
    ///
    /// ST path: `gpCh[i]^channel_control.command_w`.
    #[st = "HLI_CHANNEL_COMMAND", size = 80]
    pub struct HliChannelCommand {
        /// The PLC's running id of the command; the CNC echoes it in `state_r.command_id`.
        pub command_id: u32 => [0, Parent],
        /// Raw [`crate::enums::ChannelCommand`].
        pub command: i32 => [4, Parent],
        /// SELECT: the source line to start at (0: the program's first block).
        pub start_line: i32 => [8, Parent],
        /// MODE: raw [`crate::enums::ChannelMode`]; SINGLE_BLOCK: 1 on, 0 off.
        pub value: i32 => [12, Parent],
        /// SELECT: the program's file name in the channel's program folder, NUL-padded.
        pub program: [u8; PROGRAM_NAME_LEN] => [16, Parent],
    }
}

hli_struct! {
    /// What a channel shows its PLC, written every tick.
    ///
    /// ST path: `gpCh[i]^channel_control.state_r`.
    #[st = "HLI_CHANNEL_CONTROL_STATE", size = 208]
    pub struct HliChannelControlState {
        /// Raw [`crate::enums::ChannelState`].
        pub state: i32 => [0, Cnc],
        /// Raw [`crate::enums::ChannelMode`].
        pub mode: i32 => [4, Cnc],
        /// Single block is on.
        pub single_block: Bool => [8, Cnc],
        /// The channel holds its feed (the PLC's FEED_HOLD or `path_override.feed_hold_w`).
        pub feed_hold: Bool => [9, Cnc],
        /// Padding.
        pub fill_up_1: u16 => [10, Cnc],
        /// Operator signals, bits of [`crate::enums::ChannelSignal`].
        pub signals: u32 => [12, Cnc],
        /// Id of the last command taken from `command_w`.
        pub command_id: u32 => [16, Cnc],
        /// Raw [`crate::enums::ChannelCommandState`] of that command.
        pub command_state: i32 => [20, Cnc],
        /// Why it was refused or failed: raw [`crate::enums::ChannelCommandError`], 0 if not.
        pub command_error: u32 => [24, Cnc],
        /// States passed since that command was taken: bit n for state n, bit 5 for ERROR.
        pub states_seen: u32 => [28, Cnc],
        /// Programs that ran to their end (M30/M2 or the last block) since the CNC started.
        pub programs_ended: u32 => [32, Cnc],
        /// Source line of the block executing (as `bahn_state.active_block_nr_r`).
        pub block_nr: i32 => [36, Cnc],
        /// The channel's error (as `bahn_state.error_id_r`), 0 when none.
        pub error_id: u32 => [40, Cnc],
        /// Padding.
        pub fill_up_2: u32 => [44, Cnc],
        /// The selected program's name, NUL-padded (empty: none).
        pub program: [u8; PROGRAM_NAME_LEN] => [48, Cnc],
        /// The text of the last refusal or error (a program's first diagnostic with
        /// FILE:LINE:COL), NUL-padded.
        pub message: [u8; CONTROL_MESSAGE_LEN] => [112, Cnc],
    }
}

hli_struct! {
    /// The channel control unit.
    ///
    /// ST path: `gpCh[i]^channel_control`.
    #[st = "HLI_CHANNEL_CONTROL_UNIT", size = 296]
    pub struct HliChannelControlUnit {
        /// Flow control of `command_w` (PLC TRUE, CNC FALSE).
        pub command_semaphore_rw: Bool => [0, Both],
        /// Padding.
        pub fill_up_1: u8 => [1, Plc],
        /// Padding.
        pub fill_up_2: u16 => [2, Plc],
        /// The command.
        pub command_w: HliChannelCommand => [4, Plc],
        /// The channel's state.
        pub state_r: HliChannelControlState => [84, Cnc],
        /// Padding.
        pub fill_up_3: u32 => [292, Cnc],
    }
}

/// `bytes` up to the first NUL as text; `None` when that is not UTF-8.
pub fn nul_padded_str(bytes: &[u8]) -> Option<&str> {
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    core::str::from_utf8(&bytes[..end]).ok()
}

/// `text` NUL-padded into `N` bytes, cut at a character boundary when it does not fit.
pub fn nul_padded<const N: usize>(text: &str) -> [u8; N] {
    let mut out = [0u8; N];
    let mut end = text.len().min(N);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    out[..end].copy_from_slice(&text.as_bytes()[..end]);
    out
}
