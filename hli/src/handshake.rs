//! Typed handles for the two flow-control patterns of the HLI control units, plus the
//! command-word pattern of the dynamic-CS transition.
//!
//! ```text
//! command (consumable datum, PLC -> CNC)       request (CNC -> PLC)
//!  PLC: sem == FALSE ? write payload            CNC: sem == FALSE ? write payload
//!       sem := TRUE   (release)                      sem := TRUE   (release)
//!  CNC: sem == TRUE  ? (acquire) copy payload   PLC: sem == TRUE  ? (acquire) copy payload
//!       sem := FALSE  (release)                      sem := FALSE  (release)
//! ```
//!
//! The semaphore byte is only touched with atomic acquire/release operations; payloads are
//! copied leaf by leaf with relaxed atomics ([`crate::raw`]). A peer that breaks the protocol
//! cannot cause undefined behaviour. What the reading side can observe is counted and
//! reported: a semaphore byte that is neither 0 nor 1, a payload that changes while it is
//! copied (torn: it is copied until two consecutive copies agree, else left for the next
//! attempt, never consumed). The writing side's handles refuse to write while the semaphore is
//! TRUE, so a PLC built on them cannot break the protocol.

use crate::desc::{Bool, HliType, PlaceExt};
use crate::enums::DynCsCommand;
use crate::layout::HliDynCsTransition;
use crate::raw::Place;
use bytemuck::bytes_of;
use core::mem::offset_of;

/// Copies of a payload attempted before a changing payload counts as torn.
const COPY_ATTEMPTS: usize = 3;

/// A breach of the handshake protocol, observed by the side that reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum ProtocolViolation {
    /// The semaphore byte holds neither FALSE (0) nor TRUE (1).
    #[error("semaphore byte {raw} is neither FALSE nor TRUE")]
    SemaphoreGarbage {
        /// The byte found.
        raw: u8,
    },
    /// The payload kept changing while it was copied: the writer wrote while the semaphore
    /// was TRUE. Nothing was consumed; the next attempt tries again.
    #[error("payload changed while being read (written while the semaphore was TRUE)")]
    TornPayload,
    /// The transition's command word is not -1, 0 or +1.
    #[error("transition command {raw} is not -1, 0 or +1")]
    CommandGarbage {
        /// The value found.
        raw: i32,
    },
}

/// Why a write was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum SendError {
    /// The previous value has not been taken yet (semaphore TRUE).
    #[error("the previous value has not been taken yet")]
    Busy,
    /// The semaphore byte holds garbage; the handle does not write over it.
    #[error(transparent)]
    Violation(#[from] ProtocolViolation),
}

/// Counts of what a reading handle observed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HandshakeStats {
    /// Values taken.
    pub taken: u64,
    /// Semaphore bytes that were neither 0 nor 1.
    pub garbage: u64,
    /// Payloads that changed while copied.
    pub torn: u64,
}

impl HandshakeStats {
    /// Protocol violations seen.
    pub fn violations(&self) -> u64 {
        self.garbage + self.torn
    }
}

/// Copies `payload` until two consecutive copies agree.
fn stable_copy<P: HliType>(payload: Place<'_, P>) -> Option<P> {
    let mut previous = payload.read();
    for _ in 1..COPY_ATTEMPTS {
        let current = payload.read();
        if bytes_of(&current) == bytes_of(&previous) {
            return Some(current);
        }
        previous = current;
    }
    None
}

fn semaphore_state(sem: Place<'_, Bool>) -> Result<bool, ProtocolViolation> {
    let raw = sem.cast::<u8>().load_acquire();
    Bool(raw)
        .get()
        .map_err(|raw| ProtocolViolation::SemaphoreGarbage { raw })
}

fn set_semaphore(sem: Place<'_, Bool>, value: bool) {
    sem.cast::<u8>().store_release(u8::from(value));
}

/// The writing end of a semaphore-guarded unit: the PLC for commands, the CNC for requests.
#[derive(Debug)]
pub struct Writer<'m, P> {
    sem: Place<'m, Bool>,
    payload: Place<'m, P>,
}

impl<'m, P: HliType> Writer<'m, P> {
    /// A writer of `payload` guarded by `sem`.
    pub fn new(sem: Place<'m, Bool>, payload: Place<'m, P>) -> Self {
        Self { sem, payload }
    }

    /// Whether the last value was taken (semaphore FALSE).
    pub fn is_free(&self) -> Result<bool, ProtocolViolation> {
        semaphore_state(self.sem).map(|busy| !busy)
    }

    /// Writes `value` and sets the semaphore TRUE, if it is FALSE.
    pub fn try_send(&self, value: &P) -> Result<(), SendError> {
        if semaphore_state(self.sem)? {
            return Err(SendError::Busy);
        }
        self.payload.write(value);
        set_semaphore(self.sem, true);
        Ok(())
    }
}

/// The reading end: the CNC for commands (consumable datum), the PLC for requests.
#[derive(Debug)]
pub struct Reader<'m, P> {
    sem: Place<'m, Bool>,
    payload: Place<'m, P>,
    stats: HandshakeStats,
}

impl<'m, P: HliType> Reader<'m, P> {
    /// A reader of `payload` guarded by `sem`.
    pub fn new(sem: Place<'m, Bool>, payload: Place<'m, P>) -> Self {
        Self {
            sem,
            payload,
            stats: HandshakeStats::default(),
        }
    }

    /// Takes the value if the semaphore is TRUE and sets it FALSE. A garbage semaphore byte is
    /// reset to FALSE without taking anything; a torn payload is left for the next attempt.
    pub fn try_take(&mut self) -> Result<Option<P>, ProtocolViolation> {
        match semaphore_state(self.sem) {
            Ok(false) => Ok(None),
            Ok(true) => match stable_copy(self.payload) {
                Some(value) => {
                    set_semaphore(self.sem, false);
                    self.stats.taken += 1;
                    Ok(Some(value))
                }
                None => {
                    self.stats.torn += 1;
                    Err(ProtocolViolation::TornPayload)
                }
            },
            Err(violation) => {
                self.stats.garbage += 1;
                set_semaphore(self.sem, false);
                Err(violation)
            }
        }
    }

    /// What this reader observed so far.
    pub fn stats(&self) -> HandshakeStats {
        self.stats
    }
}

/// The PLC's end of the dynamic-CS transition: parameters first, `command` last.
#[derive(Debug)]
pub struct TransitionWriter<'m> {
    unit: Place<'m, HliDynCsTransition>,
}

impl<'m> TransitionWriter<'m> {
    /// Writer for `unit`.
    pub fn new(unit: Place<'m, HliDynCsTransition>) -> Self {
        Self { unit }
    }

    fn command(&self) -> Place<'m, i32> {
        self.unit.field(offset_of!(HliDynCsTransition, command))
    }

    /// Whether the CNC has taken the last command (the command word is 0).
    pub fn is_free(&self) -> Result<bool, ProtocolViolation> {
        match self.command().load_acquire() {
            0 => Ok(true),
            1 | -1 => Ok(false),
            raw => Err(ProtocolViolation::CommandGarbage { raw }),
        }
    }

    /// Writes the parameters of `transition`, then its command (which must not be `None`).
    /// Refused while the CNC has not taken the previous transition.
    pub fn try_send(
        &self,
        command: DynCsCommand,
        params: &HliDynCsTransition,
    ) -> Result<(), SendError> {
        match self.command().load_acquire() {
            0 => {}
            1 | -1 => return Err(SendError::Busy),
            raw => return Err(ProtocolViolation::CommandGarbage { raw }.into()),
        }
        // The command word is 0 and only we set it non-zero, so writing the whole struct with
        // command 0 first and then releasing the command is the specified order.
        self.unit.write(&HliDynCsTransition {
            command: 0,
            ..*params
        });
        self.command().store_release(command.raw());
        Ok(())
    }
}

/// The CNC's end of the dynamic-CS transition.
#[derive(Debug)]
pub struct TransitionReader<'m> {
    unit: Place<'m, HliDynCsTransition>,
    stats: HandshakeStats,
}

impl<'m> TransitionReader<'m> {
    /// Reader for `unit`.
    pub fn new(unit: Place<'m, HliDynCsTransition>) -> Self {
        Self {
            unit,
            stats: HandshakeStats::default(),
        }
    }

    fn command(&self) -> Place<'m, i32> {
        self.unit.field(offset_of!(HliDynCsTransition, command))
    }

    /// Takes a pending transition (command +1/-1) and resets the command word to 0.
    pub fn try_take(
        &mut self,
    ) -> Result<Option<(DynCsCommand, HliDynCsTransition)>, ProtocolViolation> {
        let raw = self.command().load_acquire();
        let command = match DynCsCommand::decode(raw) {
            Ok(DynCsCommand::None) => return Ok(None),
            Ok(command) => command,
            Err(_) => {
                self.stats.garbage += 1;
                self.command().store_release(0);
                return Err(ProtocolViolation::CommandGarbage { raw });
            }
        };
        let Some(params) = stable_copy(self.unit) else {
            self.stats.torn += 1;
            return Err(ProtocolViolation::TornPayload);
        };
        if params.command != raw {
            // The PLC rewrote the command while we copied: take it next time.
            self.stats.torn += 1;
            return Err(ProtocolViolation::TornPayload);
        }
        self.command().store_release(0);
        self.stats.taken += 1;
        Ok(Some((command, params)))
    }

    /// What this reader observed so far.
    pub fn stats(&self) -> HandshakeStats {
        self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::heap_image;
    use crate::layout::{HliCoordinateSystemInt, HliImage, McControlDynCsUnit};
    use crate::views::{CncView, PlcView};

    fn cs(seed: i32) -> HliCoordinateSystemInt {
        HliCoordinateSystemInt {
            translation: [seed, seed + 1, seed + 2],
            fill_up_2: 0,
            rotation: [-seed, 7, seed * 3],
            fill_up_1: 0,
        }
    }

    #[test]
    fn command_is_taken_once_and_frees_the_unit() {
        let mem = heap_image(1, 0);
        let plc = PlcView::new(&mem);
        let cnc = CncView::new(&mem);
        let tx = plc.dyn_cs_command(0).unwrap();
        let mut rx = cnc.dyn_cs_command(0).unwrap();
        assert_eq!(rx.try_take(), Ok(None));
        tx.try_send(&cs(10)).unwrap();
        assert_eq!(tx.try_send(&cs(11)), Err(SendError::Busy));
        assert_eq!(rx.try_take(), Ok(Some(cs(10))));
        assert_eq!(rx.try_take(), Ok(None));
        tx.try_send(&cs(11)).unwrap();
        assert_eq!(rx.try_take(), Ok(Some(cs(11))));
        assert_eq!(rx.stats().taken, 2);
    }

    #[test]
    fn garbage_semaphore_is_reported_and_reset() {
        let mem = heap_image(1, 0);
        let unit = mem
            .place::<HliImage>(0)
            .field::<[crate::layout::HliChannel; 12]>(offset_of!(HliImage, gpCh))
            .at(0)
            .field::<crate::layout::HliChannelMcControl>(offset_of!(
                crate::layout::HliChannel,
                channel_mc_control
            ))
            .field::<McControlDynCsUnit>(0);
        unit.field::<u8>(offset_of!(McControlDynCsUnit, command_semaphore_rw))
            .store(0x5A);
        let cnc = CncView::new(&mem);
        let mut rx = cnc.dyn_cs_command(0).unwrap();
        assert_eq!(
            rx.try_take(),
            Err(ProtocolViolation::SemaphoreGarbage { raw: 0x5A })
        );
        assert_eq!(rx.stats().garbage, 1);
        assert_eq!(rx.try_take(), Ok(None));
    }

    #[test]
    fn transition_parameters_travel_with_the_command() {
        let mem = heap_image(1, 0);
        let tx = PlcView::new(&mem).dyn_cs_transition(0).unwrap();
        let mut rx = CncView::new(&mem).dyn_cs_transition(0).unwrap();
        let params = HliDynCsTransition {
            command: 0,
            filter_max_ticks: 1000,
            option: 1,
            f_wait: Bool::TRUE,
            f_set_zero: Bool::FALSE,
            f_kin_base: Bool::TRUE,
            f_rot_trans: Bool::FALSE,
            kinematic_base_cs: cs(2000),
        };
        tx.try_send(DynCsCommand::Activate, &params).unwrap();
        assert_eq!(
            tx.try_send(DynCsCommand::Deactivate, &params),
            Err(SendError::Busy)
        );
        let (cmd, got) = rx.try_take().unwrap().unwrap();
        assert_eq!(cmd, DynCsCommand::Activate);
        assert_eq!(got.filter_max_ticks, 1000);
        assert_eq!(got.kinematic_base_cs, cs(2000));
        assert_eq!(rx.try_take(), Ok(None));
        tx.try_send(DynCsCommand::Deactivate, &params).unwrap();
        assert_eq!(rx.try_take().unwrap().unwrap().0, DynCsCommand::Deactivate);
    }
}
