//! A channel's HLI units as plain values. The machine's first stage reads what the PLC gave
//! each channel ([`read_inputs`]), the channel ticks on those values alone, and the machine's
//! last stage writes what the channel produced ([`write_outputs`]). The channel never touches
//! the image itself, so a tick reads the PLC once and a channel can be ticked without one.

use hli::enums::{ChannelErrorId, DynCsCommand, DynCsState, ProgramState};
use hli::handshake::ProtocolViolation;
use hli::layout::{
    HliChannelCommand, HliChannelControlState, HliCoordState, HliCoordinateSystemInt,
    HliDynCsChannelInterface, HliDynCsTransition, HliDynCsTransitionResult, HliMFunctionAck,
    HliMFunctionRequest, HLI_CHANNEL_AXES,
};
use hli::views::{BlockProgress, CncView, OverrideError, PathOverride};
use hli::Bool;
use kinematics::{PoseWords, RotationOrder};
use nalgebra::Isometry3;

/// What the channel should take from the PLC this tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Wanted {
    /// The dynamic-CS command and transition (not during a stop: the PLC must not move the
    /// compensation of a machine that stops; the handshakes stay pending).
    pub dyn_cs: bool,
    /// An M-function acknowledge (only while one is awaited, like a PLC reads it).
    pub m_ack: bool,
}

/// A transition the PLC posted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Transition {
    /// Taken: the command and its parameters.
    Taken(DynCsCommand, HliDynCsTransition),
    /// The command word was garbage (reset by the reader): the word found (0 when the
    /// unit broke the protocol otherwise).
    Garbage(i32),
}

/// The override unit as read this tick.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum OverrideInput {
    /// The channel has no unit in the image (or no image): 100 %, no hold.
    #[default]
    Absent,
    /// A valid value.
    Valid(PathOverride),
    /// A value out of range (the channel keeps its last valid one).
    Invalid(OverrideError),
}

/// What the CNC refused of what a PLC wrote, by class: counted, never taken. Counters
/// saturate; they cannot wrap.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Violations {
    /// Semaphore bytes neither FALSE nor TRUE.
    pub semaphore_garbage: u64,
    /// Payloads that changed while they were copied (written while the semaphore was TRUE).
    pub torn_payload: u64,
    /// Transition command words other than -1, 0 and +1.
    pub command_garbage: u64,
    /// BOOL bytes (`enable_w`, `feed_hold_w`) neither FALSE nor TRUE.
    pub bool_garbage: u64,
    /// Override values above their maximum.
    pub out_of_range: u64,
    /// Acyclic calls refused with an error code in the frame (a body of the wrong size, an
    /// unknown kind or target, a stopped machine, a refusal a family gives as a code). A
    /// refusal a family reports inside an accepted reply (an axis's or a cam's error id) is
    /// the block's to see and is not counted here.
    pub refused_calls: u64,
}

impl Violations {
    /// Counts one protocol violation.
    pub fn protocol(&mut self, violation: ProtocolViolation) {
        let class = match violation {
            ProtocolViolation::SemaphoreGarbage { .. } => &mut self.semaphore_garbage,
            ProtocolViolation::TornPayload => &mut self.torn_payload,
            ProtocolViolation::CommandGarbage { .. } => &mut self.command_garbage,
        };
        *class = class.saturating_add(1);
    }

    /// Adds `other`'s counts.
    pub fn add(&mut self, other: &Violations) {
        for (mine, theirs) in [
            (&mut self.semaphore_garbage, other.semaphore_garbage),
            (&mut self.torn_payload, other.torn_payload),
            (&mut self.command_garbage, other.command_garbage),
            (&mut self.bool_garbage, other.bool_garbage),
            (&mut self.out_of_range, other.out_of_range),
            (&mut self.refused_calls, other.refused_calls),
        ] {
            *mine = mine.saturating_add(theirs);
        }
    }

    /// Every count.
    pub fn total(&self) -> u64 {
        [
            self.semaphore_garbage,
            self.torn_payload,
            self.command_garbage,
            self.bool_garbage,
            self.out_of_range,
            self.refused_calls,
        ]
        .into_iter()
        .fold(0, u64::saturating_add)
    }
}

/// What the PLC gave a channel this tick.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ChannelInputs {
    /// Path override and feed hold (read every tick).
    pub path_override: OverrideInput,
    /// `enable_w` (a garbage byte reads as not enabled).
    pub dyn_cs_enabled: bool,
    /// A new frame taken from `command_w`.
    pub dyn_cs_command: Option<HliCoordinateSystemInt>,
    /// A transition taken from `transition_w`.
    pub transition: Option<Transition>,
    /// An acknowledge taken from `ack_w`.
    pub m_ack: Option<HliMFunctionAck>,
    /// Whether the PLC has read the last M-function announcement (a new one may be posted).
    pub m_request_free: bool,
    /// Whether the image has this channel's M-function unit (without one, M functions are
    /// not announced and not waited for).
    pub has_m_unit: bool,
    /// A command taken from the channel control unit.
    pub command: Option<HliChannelCommand>,
    /// What was refused this tick.
    pub violations: Violations,
}

/// What a channel shows the PLC after its tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelOutputs {
    /// `state_r` of the dynamic-CS unit.
    pub dyn_cs_state: DynCsState,
    /// The applied compensation for `request_r` (posted when the PLC read the last one).
    pub dyn_cs_request: Option<HliCoordinateSystemInt>,
    /// Display values of the path axes; the first `coord_count` are written.
    pub coords: [HliCoordState; HLI_CHANNEL_AXES],
    /// Path axes of the channel.
    pub coord_count: usize,
    /// Block number, program state, path feed, error and ticks (`bahn_state`).
    pub progress: BlockProgress,
    /// The feed override in effect (0.1 %; 0 while feed hold holds the path).
    pub feed_override_applied: u32,
    /// The channel's published frame.
    pub interface: HliDynCsChannelInterface,
    /// An M function to announce (kept until it is posted).
    pub m_request: Option<HliMFunctionRequest>,
    /// What became of the PLC's transitions.
    pub dyn_cs_result: HliDynCsTransitionResult,
    /// The channel control unit's state block.
    pub control: HliChannelControlState,
}

impl Default for ChannelOutputs {
    fn default() -> Self {
        Self {
            dyn_cs_state: DynCsState::Inactive,
            dyn_cs_request: None,
            coords: [bytemuck::Zeroable::zeroed(); HLI_CHANNEL_AXES],
            coord_count: 0,
            progress: BlockProgress {
                block_nr: 0,
                program_state: ProgramState::Idle,
                path_feed_um_s: 0,
                error_id: ChannelErrorId::None,
                tick: 0,
            },
            feed_override_applied: 0,
            interface: bytemuck::Zeroable::zeroed(),
            m_request: None,
            dyn_cs_result: bytemuck::Zeroable::zeroed(),
            control: bytemuck::Zeroable::zeroed(),
        }
    }
}

/// Reads channel `index`'s PLC units into `inputs` (everything not wanted is left pending in
/// the image). An index outside the image reads as a PLC that gives nothing.
pub fn read_inputs(view: &CncView<'_>, index: usize, wanted: Wanted, inputs: &mut ChannelInputs) {
    let mut violations = Violations::default();
    let request = view.m_function_request(index);
    let m_request_free = match request.as_ref().map(|w| w.is_free()) {
        Ok(Ok(free)) => free,
        Ok(Err(v)) => {
            violations.protocol(v);
            false
        }
        Err(_) => false,
    };
    let path_override = match view.path_override(index) {
        Ok(Ok(value)) => OverrideInput::Valid(value),
        Ok(Err(error)) => {
            match error {
                OverrideError::FeedHold(_) => violations.bool_garbage += 1,
                OverrideError::Feed(_) | OverrideError::Rapid(_) => violations.out_of_range += 1,
            }
            OverrideInput::Invalid(error)
        }
        Err(_) => OverrideInput::Absent,
    };
    *inputs = ChannelInputs {
        m_request_free,
        has_m_unit: request.is_ok(),
        path_override,
        ..ChannelInputs::default()
    };
    if wanted.dyn_cs {
        inputs.dyn_cs_enabled = match view.dyn_cs_enabled(index) {
            Ok(Ok(enabled)) => enabled,
            Ok(Err(_)) => {
                violations.bool_garbage += 1;
                false
            }
            Err(_) => false,
        };
        if let Ok(mut reader) = view.dyn_cs_command(index) {
            inputs.dyn_cs_command = taken(reader.try_take(), &mut violations);
        }
        if let Ok(mut reader) = view.dyn_cs_transition(index) {
            let attempt = reader.try_take();
            if let Err(v) = attempt {
                violations.protocol(v);
            }
            inputs.transition = transition_input(attempt);
        }
    }
    if wanted.m_ack {
        if let Ok(mut reader) = view.m_function_ack(index) {
            inputs.m_ack = taken(reader.try_take(), &mut violations);
        }
    }
    // Taken every tick: a command the channel cannot carry out now is refused, not left.
    if let Ok(mut reader) = view.channel_command(index) {
        inputs.command = taken(reader.try_take(), &mut violations);
    }
    inputs.violations = violations;
}

/// What a take gave: the payload, or nothing with the violation counted.
fn taken<P>(
    attempt: Result<Option<P>, ProtocolViolation>,
    violations: &mut Violations,
) -> Option<P> {
    attempt.unwrap_or_else(|v| {
        violations.protocol(v);
        None
    })
}

/// What the channel sees of one attempt to take the transition: a torn copy (the PLC rewrote
/// the unit while it was copied) is nothing yet, left pending for the next tick; only a
/// command word that is not -1, 0 or +1 is garbage.
fn transition_input(
    taken: Result<Option<(DynCsCommand, HliDynCsTransition)>, ProtocolViolation>,
) -> Option<Transition> {
    match taken {
        Ok(Some((command, params))) => Some(Transition::Taken(command, params)),
        Ok(None) | Err(ProtocolViolation::TornPayload) => None,
        Err(ProtocolViolation::CommandGarbage { raw }) => Some(Transition::Garbage(raw)),
        Err(_) => Some(Transition::Garbage(0)),
    }
}

/// Writes channel `index`'s outputs; the M-function announcement is cleared once posted.
pub fn write_outputs(view: &CncView<'_>, index: usize, outputs: &mut ChannelOutputs) {
    let _ = view.set_dyn_cs_state(index, outputs.dyn_cs_state);
    if let (Ok(writer), Some(cs)) = (view.dyn_cs_request(index), outputs.dyn_cs_request) {
        // Request pattern: posted only when the PLC has read the last one.
        let _ = writer.try_send(&cs);
    }
    if let (Ok(writer), Some(request)) = (view.m_function_request(index), outputs.m_request) {
        if writer.try_send(&request).is_ok() {
            outputs.m_request = None;
        }
    }
    for (i, coord) in outputs.coords[..outputs.coord_count].iter().enumerate() {
        let _ = view.write_coord_state(index, i, coord);
    }
    let _ = view.write_block_progress(index, &outputs.progress);
    let _ = view.write_feed_override_applied(index, outputs.feed_override_applied);
    let _ = view.write_channel_interface(index, &outputs.interface);
    let _ = view.write_dyn_cs_result(index, &outputs.dyn_cs_result);
    let _ = view.write_channel_control_state(index, &outputs.control);
}

/// The interface of a channel after one tick: a valid published frame updates the frame and
/// counts up; otherwise the last frame is held (frozen when the channel publishes but its
/// frame is not valid).
pub fn next_interface(
    last: &HliDynCsChannelInterface,
    published: Option<(Isometry3<f64>, bool)>,
) -> HliDynCsChannelInterface {
    let (enabled, valid, cs) = match published {
        Some((frame, live)) => {
            match crate::channel::hli_frame::frame_to_hli(&frame, RotationOrder::Zyx) {
                Ok(cs) => (true, live, Some(cs)),
                Err(_) => (true, false, None),
            }
        }
        None => (false, false, None),
    };
    let mut out = HliDynCsChannelInterface {
        enabled_r: Bool::from(enabled),
        valid_r: Bool::from(valid),
        freeze_r: Bool::from(enabled && !valid),
        fill_up_1: 0,
        update_counter_r: last.update_counter_r,
        cs_r: last.cs_r,
    };
    if let Some(cs) = cs.filter(|_| valid) {
        out.cs_r = cs;
        out.update_counter_r = last.update_counter_r.wrapping_add(1);
    }
    out
}

/// X..C words of a frame in the channel's orientation convention.
pub(super) fn words_in(frame: &Isometry3<f64>, order: RotationOrder) -> [f64; 6] {
    let w = PoseWords::from_frame(frame, order);
    [w.xyz[0], w.xyz[1], w.xyz[2], w.abc[0], w.abc[1], w.abc[2]]
}

/// The words X..C of `frame` in `order`, its angles the solution nearest `near` (see
/// [`RotationOrder::angles_near`]).
pub(super) fn words_near(frame: &Isometry3<f64>, order: RotationOrder, near: [f64; 3]) -> [f64; 6] {
    let t = frame.translation.vector;
    let [a, b, c] = order.angles_near(&frame.rotation.to_rotation_matrix(), near);
    [t.x, t.y, t.z, a, b, c]
}

/// mm or degree to the HLI's 0.1 um / 0.0001 degree, saturating at the DINT range.
pub(super) fn hli_value(v: f64, angle: bool) -> i32 {
    let raw = if angle {
        hli::units::deg_to_hli(v)
    } else {
        hli::units::mm_to_hli(v)
    };
    raw.unwrap_or(if v < 0.0 { i32::MIN } else { i32::MAX })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_torn_transition_is_left_for_the_next_tick_and_garbage_is_reported() {
        assert_eq!(transition_input(Err(ProtocolViolation::TornPayload)), None);
        assert_eq!(transition_input(Ok(None)), None);
        assert_eq!(
            transition_input(Err(ProtocolViolation::CommandGarbage { raw: 5 })),
            Some(Transition::Garbage(5))
        );
        let params: HliDynCsTransition = bytemuck::Zeroable::zeroed();
        assert_eq!(
            transition_input(Ok(Some((DynCsCommand::Activate, params)))),
            Some(Transition::Taken(DynCsCommand::Activate, params))
        );
    }
}
