//! Touch probes (MC_TouchProbe, MC_AbortTrigger): the CNC arms a probe of the encoder or
//! drive through the encoder outputs, and when the probe input's edge latches the position,
//! reads it from the encoder inputs and records it in axis units.
//!
//! Every arming is a fresh handshake: the probe's enable stays off until its status shows no
//! latch (a value left from before can never be taken for the new one), then goes on; a
//! latched value outside the window (WindowOnly) re-arms the same way. Three interfaces
//! (see [`ProbeInterface`]): an encoder terminal's external latch and the CANopen and
//! SERCOS mappings of seed 004.

use super::config::ProbeInterface;
use super::increments::CounterWidth;
use hli::calls::probe::{ProbeAbortCall, ProbeArmCall};
use hli::enums::{AxisError, ProbeEdge, ProbeState};
use hli::layout::{HliAxisProbe, NcEncoderIn, HLI_AXIS_PROBES};

/// Encoder terminal (`nCtrl1`/`nStatus1`): enable the external latch on the rising edge.
pub const TERMINAL_LATCH_POSITIVE: u8 = 0x02;
/// Encoder terminal: enable the external latch on the falling edge.
pub const TERMINAL_LATCH_NEGATIVE: u8 = 0x08;
/// Encoder terminal status: the external latch holds a value (`nInData2`).
pub const TERMINAL_LATCH_VALID: u8 = 0x02;
/// Encoder terminal status bits with a meaning (0: zero-pulse latch valid, 1: external latch
/// valid, 2: counter set); others are undefined.
pub const TERMINAL_STATUS_DEFINED: u8 = 0x07;
/// CANopen probe control (0x60B8, one byte per probe): enable.
pub const CANOPEN_ENABLE: u8 = 0x01;
/// CANopen probe control: sample the rising edge.
pub const CANOPEN_POSITIVE: u8 = 0x10;
/// CANopen probe control: sample the falling edge.
pub const CANOPEN_NEGATIVE: u8 = 0x20;
/// CANopen probe status (0x60B9): rising edge stored.
pub const CANOPEN_POSITIVE_STORED: u8 = 0x02;
/// CANopen probe status: falling edge stored.
pub const CANOPEN_NEGATIVE_STORED: u8 = 0x04;
/// CANopen probe status bits 3..5 are reserved (6 and 7 are user-defined and ignored).
pub const CANOPEN_STATUS_RESERVED: u8 = 0x38;
/// SERCOS probe enable (S-0-0405/0406).
pub const SERCOS_ENABLE: u8 = 0x01;

/// The probe's bytes of the encoder outputs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ProbeControl {
    /// `enc_out.nCtrl1` (encoder terminal).
    pub ctrl1: u8,
    /// `enc_out.nCtrl5` (probe 1).
    pub ctrl5: u8,
    /// `enc_out.nCtrl6` (probe 2).
    pub ctrl6: u8,
}

#[derive(Debug, Clone, Copy)]
struct Slot {
    state: ProbeState,
    edge: Option<ProbeEdge>,
    window: Option<(f64, f64)>,
    arm_id: u32,
    error: Option<AxisError>,
    recorded: f64,
    /// The probe's status showed no latch since the arming: its enable may go on.
    clear: bool,
}

impl Default for Slot {
    fn default() -> Self {
        Self {
            state: ProbeState::Idle,
            edge: None,
            window: None,
            arm_id: 0,
            error: None,
            recorded: 0.0,
            clear: false,
        }
    }
}

/// What one probe's status says this tick.
enum Latch {
    /// No value latched.
    Empty,
    /// The edge latched this raw count.
    Value(i32),
    /// The status byte has undefined bits: not used.
    Undefined,
}

/// The touch probes of one axis.
#[derive(Debug, Clone)]
pub struct Probes {
    interface: ProbeInterface,
    width: CounterWidth,
    slots: [Slot; HLI_AXIS_PROBES],
}

impl Probes {
    /// Probes of an encoder with `interface` and counter `width`.
    pub fn new(interface: ProbeInterface, width: CounterWidth) -> Self {
        Self {
            interface,
            width,
            slots: [Slot::default(); HLI_AXIS_PROBES],
        }
    }

    fn slot_of(&self, probe: u32) -> Result<usize, AxisError> {
        let k = match probe {
            1 => 0,
            2 => 1,
            _ => return Err(AxisError::InvalidProbeParameter),
        };
        let available = match self.interface {
            ProbeInterface::None => 0,
            ProbeInterface::Terminal => 1,
            ProbeInterface::Canopen | ProbeInterface::Sercos => 2,
        };
        if k < available {
            Ok(k)
        } else {
            Err(AxisError::ProbeNotAvailable)
        }
    }

    /// MC_TouchProbe: arms a probe; returns the arming's id. A probe armed already stays as
    /// it is and the call is refused.
    pub fn arm(&mut self, call: &ProbeArmCall) -> Result<u32, AxisError> {
        let edge = ProbeEdge::decode(call.edge).map_err(|_| AxisError::InvalidProbeParameter)?;
        let window = match call.window_only {
            0 => None,
            1 if call.first_position.is_finite()
                && call.last_position.is_finite()
                && call.first_position <= call.last_position =>
            {
                Some((call.first_position, call.last_position))
            }
            _ => return Err(AxisError::InvalidProbeParameter),
        };
        if call.reserved != 0 {
            return Err(AxisError::InvalidProbeParameter);
        }
        let k = self.slot_of(call.probe)?;
        let slot = &mut self.slots[k];
        if slot.state == ProbeState::Armed {
            return Err(AxisError::ProbeAlreadyArmed);
        }
        *slot = Slot {
            state: ProbeState::Armed,
            edge: Some(edge),
            window,
            arm_id: slot.arm_id.wrapping_add(1).max(1),
            ..Slot::default()
        };
        Ok(slot.arm_id)
    }

    /// MC_AbortTrigger: disarms a probe; returns the id of the arming it ended.
    pub fn abort(&mut self, call: &ProbeAbortCall) -> Result<u32, AxisError> {
        if call.reserved != 0 {
            return Err(AxisError::InvalidProbeParameter);
        }
        let k = self.slot_of(call.probe)?;
        let slot = &mut self.slots[k];
        if slot.state != ProbeState::Armed {
            return Err(AxisError::ProbeNotArmed);
        }
        slot.state = ProbeState::Aborted;
        Ok(slot.arm_id)
    }

    /// The encoder's data became invalid: every armed probe ends (Aborted, with `cause`), as
    /// its handshake cannot be trusted.
    pub fn lose_data(&mut self, cause: AxisError) {
        for slot in &mut self.slots {
            if slot.state == ProbeState::Armed {
                slot.state = ProbeState::Aborted;
                slot.error = Some(cause);
            }
        }
    }

    /// Reads the probes' status from the encoder inputs and records latched positions.
    /// `raw`/`count`: this tick's encoder reading and its unwrapped count, against which a
    /// latched raw value is unwrapped. Returns how many status bytes had undefined bits.
    pub fn sense(&mut self, enc_in: &NcEncoderIn, raw: i32, count: i64, scale: f64) -> u32 {
        let mut undefined = 0;
        for k in 0..HLI_AXIS_PROBES {
            let slot = self.slots[k];
            let (ProbeState::Armed, Some(edge)) = (slot.state, slot.edge) else {
                continue;
            };
            let latch = self.latch(enc_in, k, edge);
            let slot = &mut self.slots[k];
            match latch {
                Latch::Undefined => undefined += 1,
                Latch::Empty => slot.clear = true,
                Latch::Value(_) if !slot.clear => {}
                Latch::Value(value) => {
                    let latched = count + self.width.delta(raw, value);
                    let position = latched as f64 / scale;
                    let inside = slot
                        .window
                        .is_none_or(|(first, last)| (first..=last).contains(&position));
                    if inside {
                        slot.state = ProbeState::Recorded;
                        slot.recorded = position;
                    } else {
                        // Outside the window: a fresh handshake re-arms the probe.
                        slot.clear = false;
                    }
                }
            }
        }
        undefined
    }

    fn latch(&self, enc_in: &NcEncoderIn, k: usize, edge: ProbeEdge) -> Latch {
        let positive = edge == ProbeEdge::Positive;
        let (status, value) = match self.interface {
            ProbeInterface::None => return Latch::Empty,
            ProbeInterface::Terminal => {
                let s = enc_in.nStatus1;
                if s & !TERMINAL_STATUS_DEFINED != 0 {
                    return Latch::Undefined;
                }
                (s & TERMINAL_LATCH_VALID != 0, enc_in.nInData2)
            }
            ProbeInterface::Canopen => {
                let s = [enc_in.nStatus5, enc_in.nStatus6][k];
                if s & CANOPEN_STATUS_RESERVED != 0 {
                    return Latch::Undefined;
                }
                let bit = if positive {
                    CANOPEN_POSITIVE_STORED
                } else {
                    CANOPEN_NEGATIVE_STORED
                };
                (s & bit != 0, self.position_word(enc_in, k, positive))
            }
            ProbeInterface::Sercos => {
                let flags = [
                    [enc_in.nStatus5, enc_in.nStatus6],
                    [enc_in.nStatus7, enc_in.nStatus8],
                ][k];
                if flags.iter().any(|&f| f > 1) {
                    return Latch::Undefined;
                }
                let flag = if positive { flags[0] } else { flags[1] };
                (flag == 1, self.position_word(enc_in, k, positive))
            }
        };
        if status {
            Latch::Value(value)
        } else {
            Latch::Empty
        }
    }

    fn position_word(&self, enc_in: &NcEncoderIn, k: usize, positive: bool) -> i32 {
        match (k, positive) {
            (0, true) => enc_in.nInData3,
            (0, false) => enc_in.nInData4,
            (_, true) => enc_in.nInData5,
            (_, false) => enc_in.nInData6,
        }
    }

    /// The probes' control bytes of the encoder outputs: a probe's enable is on while it is
    /// armed and its handshake is clear.
    pub fn control(&self) -> ProbeControl {
        let mut c = ProbeControl::default();
        for (k, slot) in self.slots.iter().enumerate() {
            let (ProbeState::Armed, true, Some(edge)) = (slot.state, slot.clear, slot.edge) else {
                continue;
            };
            let positive = edge == ProbeEdge::Positive;
            let byte = match self.interface {
                ProbeInterface::None => 0,
                ProbeInterface::Terminal => {
                    c.ctrl1 = if positive {
                        TERMINAL_LATCH_POSITIVE
                    } else {
                        TERMINAL_LATCH_NEGATIVE
                    };
                    0
                }
                ProbeInterface::Canopen => {
                    CANOPEN_ENABLE
                        | if positive {
                            CANOPEN_POSITIVE
                        } else {
                            CANOPEN_NEGATIVE
                        }
                }
                ProbeInterface::Sercos => SERCOS_ENABLE,
            };
            if k == 0 {
                c.ctrl5 = byte;
            } else {
                c.ctrl6 = byte;
            }
        }
        c
    }

    /// The probes' block of the image.
    pub fn image(&self) -> [HliAxisProbe; HLI_AXIS_PROBES] {
        self.slots.map(|s| HliAxisProbe {
            state_r: s.state.raw(),
            edge_r: s.edge.map_or(0, ProbeEdge::raw),
            arm_id_r: s.arm_id,
            error_id_r: s.error.map_or(0, AxisError::raw),
            recorded_position_r: if s.state == ProbeState::Recorded {
                s.recorded
            } else {
                0.0
            },
        })
    }
}
