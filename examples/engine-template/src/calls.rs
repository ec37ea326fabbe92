//! The phase gear's wire vocabulary: what the PLC's blocks send and the engine answers.
//! Extension kinds take numbers no built-in family uses (70 and up here); registration
//! refuses a number that is taken.

use bytemuck::{Pod, Zeroable};

/// PhaseGearIn: couple the addressed slave axis to `master` with `ratio`, then shift to
/// `phase`; on a slave this engine holds, a new phase (same master and ratio).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct PhaseGearInCall {
    /// Master axis (gpAx index).
    pub master: u32,
    /// Sent 0.
    pub reserved: u32,
    /// Slave units per master unit, finite and not 0.
    pub ratio: f64,
    /// Phase offset of the slave, its units, finite.
    pub phase: f64,
}

impl Default for PhaseGearInCall {
    /// Master 0, ratio 1, phase 0.
    fn default() -> Self {
        PhaseGearInCall {
            master: 0,
            reserved: 0,
            ratio: 1.0,
            phase: 0.0,
        }
    }
}

/// PhaseGearOut: let the addressed slave go (it runs on free at its velocity).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct PhaseGearOutCall {
    /// Sent 0.
    pub reserved: u32,
}

/// The answer of both: 0, or a [`PhaseGearError`] code.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct PhaseGearReply {
    /// 0 or the refusal's code.
    pub error_id: u32,
    /// Sent 0.
    pub reserved: u32,
}

hli::extension_calls! { family "phase_gear";
    /// PhaseGearIn ([`PhaseGearInCall`]).
    PHASE_GEAR_IN = 70: PhaseGearInCall -> PhaseGearReply, command;
    /// PhaseGearOut ([`PhaseGearOutCall`]).
    PHASE_GEAR_OUT = 71: PhaseGearOutCall -> PhaseGearReply, command;
}

/// Why the engine refused a call (the block's ErrorID).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhaseGearError {
    /// The master is no axis of the machine, or is the slave.
    Master = 0x7F01,
    /// The ratio is not finite or is 0.
    Ratio = 0x7F02,
    /// The phase is not finite.
    Phase = 0x7F03,
    /// The slave is not enabled, in error, or held by another coupling.
    NotFree = 0x7F04,
    /// The master moves: a coupling starts only on a master at rest (the slave would jump
    /// to its velocity).
    MasterMoving = 0x7F05,
    /// PhaseGearOut of a slave this engine does not hold.
    NotCoupled = 0x7F06,
    /// A coupled slave changes only its phase: another master or ratio is refused.
    Coupled = 0x7F07,
}

impl PhaseGearError {
    /// The code on the wire.
    pub fn raw(self) -> u32 {
        self as u32
    }
}
