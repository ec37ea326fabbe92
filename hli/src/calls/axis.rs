//! The axis calls: the cyclic state of an axis read on demand, and the axis commands of the
//! PLCopen motion blocks (MC_Power .. MC_SetPosition) as one acyclic call.

use crate::layout::HliAxisLrState;
use crate::wire::ACYCLIC_BODY_SIZE;
use bytemuck::{Pod, Zeroable};

/// Reads the cyclic state of the axis given as `target`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct ReadAxisState {
    /// Reserved, must be 0.
    pub reserved: u32,
}

const _: () = assert!(core::mem::size_of::<HliAxisLrState>() <= ACYCLIC_BODY_SIZE);

/// A motion command for the axis given as `target` (what MC_Power, MC_MoveAbsolute ... send
/// on their Execute edge). Units are the axis's (mm or degree, per second...).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct AxisCommandCall {
    /// Raw [`crate::enums::AxisCommandKind`].
    pub command: u32,
    /// MC_Power: 1 enable, 0 disable. Others: 0.
    pub enable: u32,
    /// MC_MoveVelocity: 1 positive, -1 negative. Others: 0.
    pub direction: i32,
    /// Reserved, 0.
    pub reserved: u32,
    /// Target position (absolute) or distance (relative).
    pub position: f64,
    /// Velocity limit of the move (or the velocity of MC_MoveVelocity), > 0.
    pub velocity: f64,
    /// Acceleration limit, > 0.
    pub acceleration: f64,
    /// Deceleration limit, > 0 (also of MC_Halt and MC_Stop).
    pub deceleration: f64,
    /// Jerk limit, > 0 (also of MC_Halt and MC_Stop).
    pub jerk: f64,
}

impl AxisCommandCall {
    fn motion(kind: crate::enums::AxisCommandKind) -> Self {
        Self {
            command: kind.raw(),
            ..Self::default()
        }
    }
    /// MC_Power with `enable`.
    pub fn power(enable: bool) -> Self {
        Self {
            enable: u32::from(enable),
            ..Self::motion(crate::enums::AxisCommandKind::Power)
        }
    }
    /// MC_Reset.
    pub fn reset() -> Self {
        Self::motion(crate::enums::AxisCommandKind::Reset)
    }
    /// MC_MoveAbsolute to `position` with the limits `[velocity, acceleration, deceleration,
    /// jerk]`.
    pub fn move_absolute(position: f64, limits: [f64; 4]) -> Self {
        Self {
            position,
            ..Self::motion(crate::enums::AxisCommandKind::MoveAbsolute).with_limits(limits)
        }
    }
    /// MC_MoveRelative by `distance` with the limits `[velocity, acceleration, deceleration,
    /// jerk]`.
    pub fn move_relative(distance: f64, limits: [f64; 4]) -> Self {
        Self {
            position: distance,
            ..Self::motion(crate::enums::AxisCommandKind::MoveRelative).with_limits(limits)
        }
    }
    /// MC_MoveSuperimposed by `distance` with the limits `[velocity difference,
    /// acceleration, deceleration, jerk]`.
    pub fn move_superimposed(distance: f64, limits: [f64; 4]) -> Self {
        Self {
            position: distance,
            ..Self::motion(crate::enums::AxisCommandKind::MoveSuperimposed).with_limits(limits)
        }
    }
    /// MC_MoveVelocity in `direction` (1 or -1) at `limits[0]`.
    pub fn move_velocity(direction: i32, limits: [f64; 4]) -> Self {
        Self {
            direction,
            ..Self::motion(crate::enums::AxisCommandKind::MoveVelocity).with_limits(limits)
        }
    }
    /// MC_Halt with `deceleration` and `jerk`.
    pub fn halt(deceleration: f64, jerk: f64) -> Self {
        Self {
            deceleration,
            jerk,
            ..Self::motion(crate::enums::AxisCommandKind::Halt)
        }
    }
    /// MC_Stop with `deceleration` and `jerk`.
    pub fn stop(deceleration: f64, jerk: f64) -> Self {
        Self {
            deceleration,
            jerk,
            ..Self::motion(crate::enums::AxisCommandKind::Stop)
        }
    }
    /// MC_SetPosition: the encoder counts from `position` (at standstill).
    pub fn set_position(position: f64) -> Self {
        Self {
            position,
            ..Self::motion(crate::enums::AxisCommandKind::SetPosition)
        }
    }
    /// Releases MC_Stop's lock.
    pub fn stop_release() -> Self {
        Self::motion(crate::enums::AxisCommandKind::StopRelease)
    }
    fn with_limits(self, [velocity, acceleration, deceleration, jerk]: [f64; 4]) -> Self {
        Self {
            velocity,
            acceleration,
            deceleration,
            jerk,
            ..self
        }
    }
}

/// The reply to an [`AxisCommandCall`]: the command's id, or why the axis refused it.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq, Eq)]
pub struct AxisCommandReply {
    /// Id the axis gave the command (see `HLI_AXIS_COMMAND_STATE`), 0 when refused.
    pub command_id: u32,
    /// 0 when accepted, else the raw [`crate::enums::AxisError`] of the refusal.
    pub error_id: u32,
}

calls! { family "axis";
    /// [`ReadAxisState`]: the cyclic state of an axis, read on demand.
    READ_AXIS_STATE = 1: ReadAxisState -> HliAxisLrState, read_only;
    /// [`AxisCommandCall`]: a PLCopen motion command.
    AXIS_COMMAND = 2: AxisCommandCall -> AxisCommandReply, command;
}
