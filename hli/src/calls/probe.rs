//! The touch-probe calls: MC_TouchProbe arms a probe of the axis given as `target` (its `gpAx`
//! index), MC_AbortTrigger disarms it. What the probe recorded is read from the axis image,
//! `gpAx[i]^drive_state.probe_r[k]`, under the arm id the reply carries.

use bytemuck::{Pod, Zeroable};

/// MC_TouchProbe: arm probe `probe` (1 or 2) for one edge; with `window_only` 1 only an edge
/// between `first_position` and `last_position` (axis units, inclusive) records.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct ProbeArmCall {
    /// Probe number, 1 or 2.
    pub probe: u32,
    /// Raw [`crate::enums::ProbeEdge`].
    pub edge: u32,
    /// 1: only edges inside the window record; 0: every edge.
    pub window_only: u32,
    /// Reserved, 0.
    pub reserved: u32,
    /// Start of the window, axis units.
    pub first_position: f64,
    /// End of the window, axis units (at or above `first_position`).
    pub last_position: f64,
}

/// MC_AbortTrigger: disarm probe `probe` (1 or 2).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct ProbeAbortCall {
    /// Probe number, 1 or 2.
    pub probe: u32,
    /// Reserved, 0.
    pub reserved: u32,
}

/// The reply to both probe calls.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct ProbeReply {
    /// The arming's id (`HLI_AXIS_PROBE.arm_id_r`), 0 when refused; MC_AbortTrigger: the id
    /// of the arming it ended.
    pub arm_id: u32,
    /// 0 when accepted, else the raw [`crate::enums::AxisError`] of the refusal.
    pub error_id: u32,
}

calls! { family "probe";
    /// [`ProbeArmCall`]: MC_TouchProbe.
    PROBE_ARM = 50: ProbeArmCall -> ProbeReply, command;
    /// [`ProbeAbortCall`]: MC_AbortTrigger.
    PROBE_ABORT = 51: ProbeAbortCall -> ProbeReply, command;
}
