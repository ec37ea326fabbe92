//! The CiA 402 drive state machine as the process image carries it: `drive_out.nCtrl1` is the
//! control word's low byte, `drive_in.nStatus1`/`nStatus2` the status word's low and high
//! byte. The specification calls these bytes "drive state machine communication" and leaves
//! their coding to the drive; CiA 402 (CANopen, EtherCAT CoE) is the coding most drives speak.

use hli::enums::{drive_flags, DriveState};

/// Control word (low byte) the CNC sends.
pub mod control {
    /// Shutdown: to Ready to switch on (and out of Operation enabled).
    pub const SHUTDOWN: u8 = 0x06;
    /// Switch on + enable operation: to Operation enabled.
    pub const ENABLE_OPERATION: u8 = 0x0F;
    /// Fault reset (bit 7; the drive acts on its rising edge).
    pub const FAULT_RESET: u8 = 0x80;
    /// Bit 0: switch on.
    pub const SWITCH_ON: u8 = 0x01;
    /// Bit 1: enable voltage.
    pub const ENABLE_VOLTAGE: u8 = 0x02;
    /// Bit 2: quick stop (active low: 0 requests a quick stop).
    pub const QUICK_STOP: u8 = 0x04;
    /// Bit 3: enable operation.
    pub const OPERATION: u8 = 0x08;
}

/// Status word (low byte) of each state, as a drive reports it (voltage enabled, bit 4, set
/// where the state implies it).
pub fn status_of(state: DriveState) -> u8 {
    match state {
        DriveState::NotEvaluated | DriveState::NotReadyToSwitchOn => 0x00,
        DriveState::SwitchOnDisabled => 0x40,
        DriveState::ReadyToSwitchOn => 0x31,
        DriveState::SwitchedOn => 0x33,
        DriveState::OperationEnabled => 0x37,
        DriveState::QuickStopActive => 0x17,
        DriveState::FaultReactionActive => 0x1F,
        DriveState::Fault => 0x08,
    }
}

/// The state a status word's low byte codes, by CiA 402's masks; `None` for a pattern no
/// state has (an undefined input word).
pub fn decode_state(status_low: u8) -> Option<DriveState> {
    let s = status_low;
    // Bits 0..3 and 6 decide, bit 5 (quick stop) too where the state says.
    let state = match (s & 0x4F, s & 0x6F) {
        (0x00, _) => DriveState::NotReadyToSwitchOn,
        (0x40, _) => DriveState::SwitchOnDisabled,
        (_, 0x21) => DriveState::ReadyToSwitchOn,
        (_, 0x23) => DriveState::SwitchedOn,
        (_, 0x27) => DriveState::OperationEnabled,
        (_, 0x07) => DriveState::QuickStopActive,
        (0x0F, _) => DriveState::FaultReactionActive,
        (0x08, _) => DriveState::Fault,
        _ => return None,
    };
    Some(state)
}

/// Whether the state is one of the two fault states.
pub fn is_fault(state: DriveState) -> bool {
    matches!(state, DriveState::Fault | DriveState::FaultReactionActive)
}

/// The status bits the CNC shows (`drive_flags_r`) from the status word's two bytes.
pub fn flags(status_low: u8, status_high: u8) -> u32 {
    let mut f = 0;
    let mut set = |on: bool, bit: u32| {
        if on {
            f |= bit;
        }
    };
    set(status_low & 0x80 != 0, drive_flags::WARNING);
    set(status_high & 0x02 != 0, drive_flags::REMOTE);
    set(status_high & 0x04 != 0, drive_flags::TARGET_REACHED);
    set(status_high & 0x08 != 0, drive_flags::INTERNAL_LIMIT);
    set(status_high & 0x10 != 0, drive_flags::FOLLOWS_COMMAND);
    set(status_high & 0x20 != 0, drive_flags::FOLLOWING_ERROR);
    f
}

/// The status word's high byte of a drive in cyclic position mode.
pub fn status_high(remote: bool, target_reached: bool, follows: bool, following_error: bool) -> u8 {
    u8::from(remote) << 1
        | u8::from(target_reached) << 2
        | u8::from(follows) << 4
        | u8::from(following_error) << 5
}

/// The state a drive in `state` goes to on control word `control_low` (one transition per
/// call, as a drive takes one per cycle), or stays in.
pub fn next_state(state: DriveState, control_low: u8, fault_reset_edge: bool) -> DriveState {
    use control::*;
    let c = control_low;
    let voltage = c & ENABLE_VOLTAGE != 0;
    let quick_stop_requested = voltage && c & QUICK_STOP == 0;
    let shutdown = c & (ENABLE_VOLTAGE | QUICK_STOP | SWITCH_ON) == (ENABLE_VOLTAGE | QUICK_STOP);
    let switch_on =
        c & (ENABLE_VOLTAGE | QUICK_STOP | SWITCH_ON) == (ENABLE_VOLTAGE | QUICK_STOP | SWITCH_ON);
    let operation = switch_on && c & OPERATION != 0;
    match state {
        DriveState::Fault if fault_reset_edge => DriveState::SwitchOnDisabled,
        DriveState::Fault => DriveState::Fault,
        DriveState::FaultReactionActive => DriveState::Fault,
        DriveState::NotEvaluated | DriveState::NotReadyToSwitchOn => DriveState::SwitchOnDisabled,
        _ if !voltage => DriveState::SwitchOnDisabled,
        DriveState::SwitchOnDisabled if shutdown => DriveState::ReadyToSwitchOn,
        DriveState::SwitchOnDisabled => DriveState::SwitchOnDisabled,
        DriveState::ReadyToSwitchOn if switch_on => DriveState::SwitchedOn,
        DriveState::ReadyToSwitchOn => DriveState::ReadyToSwitchOn,
        DriveState::SwitchedOn if operation => DriveState::OperationEnabled,
        DriveState::SwitchedOn if shutdown => DriveState::ReadyToSwitchOn,
        DriveState::SwitchedOn => DriveState::SwitchedOn,
        DriveState::OperationEnabled if quick_stop_requested => DriveState::QuickStopActive,
        DriveState::OperationEnabled if shutdown => DriveState::ReadyToSwitchOn,
        DriveState::OperationEnabled if switch_on && !operation => DriveState::SwitchedOn,
        DriveState::OperationEnabled => DriveState::OperationEnabled,
        DriveState::QuickStopActive if quick_stop_requested => DriveState::QuickStopActive,
        DriveState::QuickStopActive => DriveState::SwitchOnDisabled,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_state_decodes_from_the_status_it_reports() {
        for &s in DriveState::ALL {
            let expected = match s {
                DriveState::NotEvaluated => DriveState::NotReadyToSwitchOn,
                other => other,
            };
            assert_eq!(decode_state(status_of(s)), Some(expected), "{s:?}");
            // Manufacturer and warning bits change nothing.
            assert_eq!(decode_state(status_of(s) | 0x80), Some(expected), "{s:?}");
        }
    }

    #[test]
    fn patterns_of_no_state_are_undefined() {
        for undefined in [0x01, 0x03, 0x05, 0x25, 0x29, 0x2B] {
            assert_eq!(decode_state(undefined), None, "{undefined:#x}");
        }
    }

    #[test]
    fn enable_operation_takes_a_fresh_drive_to_operation_enabled_in_steps() {
        let mut s = DriveState::NotReadyToSwitchOn;
        let mut path = vec![];
        for _ in 0..4 {
            s = next_state(s, control::ENABLE_OPERATION, false);
            path.push(s);
        }
        // Enable operation from Switch on disabled needs a shutdown first.
        assert_eq!(path, [DriveState::SwitchOnDisabled; 4]);
        let mut s = DriveState::SwitchOnDisabled;
        let mut path = vec![];
        for c in [
            control::SHUTDOWN,
            control::ENABLE_OPERATION,
            control::ENABLE_OPERATION,
        ] {
            s = next_state(s, c, false);
            path.push(s);
        }
        assert_eq!(
            path,
            [
                DriveState::ReadyToSwitchOn,
                DriveState::SwitchedOn,
                DriveState::OperationEnabled
            ]
        );
        assert_eq!(
            next_state(DriveState::OperationEnabled, control::SHUTDOWN, false),
            DriveState::ReadyToSwitchOn
        );
    }

    #[test]
    fn only_a_fault_reset_edge_leaves_fault() {
        assert_eq!(
            next_state(DriveState::Fault, control::ENABLE_OPERATION, false),
            DriveState::Fault
        );
        assert_eq!(
            next_state(DriveState::Fault, control::FAULT_RESET, true),
            DriveState::SwitchOnDisabled
        );
    }

    #[test]
    fn flags_map_the_status_bits() {
        assert_eq!(flags(0x80, 0), drive_flags::WARNING);
        assert_eq!(
            flags(0x37, status_high(true, true, true, false)),
            drive_flags::REMOTE | drive_flags::TARGET_REACHED | drive_flags::FOLLOWS_COMMAND
        );
        assert_eq!(flags(0, 0x08), drive_flags::INTERNAL_LIMIT);
        assert_eq!(flags(0, 0x20), drive_flags::FOLLOWING_ERROR);
    }
}
