//! `cnc run --plc-restart`: a lost PLC stops the machine, but the run goes on and takes a new
//! PLC process on the same instance.
//!
//! ```text
//!  PLC lost ─► machine stop ─► Lost ──at rest──► PLC units cleared ─► Waiting
//!                                                                      │ a new pid in the header
//!                 Running ◄──its heartbeat moves── Attached ◄── machine re-armed
//!                            (20 s without a cycle, or it left: lost again)
//! ```
//!
//! While the gap is open the machine stays stopped: the channels ended, the single axes stand
//! where their stop brought them (locked until the re-arm releases them, powered as they
//! were). A new PLC sees every PLC-written leaf cleared, every command unit empty and every
//! request withdrawn ([`CncSegment::reset_plc_units`]).

use super::super::file::DrivesOnLoss;
use super::super::machine::Machine;
use cnc_os::monotonic;
use core::mem::offset_of;
use core::time::Duration;
use hli::layout::HliSegmentHeader;
use hli_transport::segment::CncSegment;

/// How long a new PLC may take from attaching to its first cycle.
const FIRST_CYCLE_PATIENCE: Duration = Duration::from_secs(20);

/// Where the run is between two PLCs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Gap {
    /// A PLC runs (or none was lost yet).
    Closed,
    /// The PLC (`pid`, 0 when unknown) was lost at `since`; the machine is stopping.
    Lost { pid: u32, since: u64 },
    /// The machine is at rest and the PLC units are cleared; waiting for a new pid.
    Waiting { pid: u32 },
    /// PLC `pid` attached (the machine is re-armed); waiting for its heartbeat to move from
    /// `beat`, since `at`.
    Attached { pid: u32, beat: u64, at: Duration },
}

/// What a step of the gap did, for the loop to say.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum GapEvent {
    /// Nothing changed.
    None,
    /// The machine came to rest; `cleared` PLC leaves were set back, the drives disabled
    /// when so configured.
    Waiting { cleared: usize, disabled: bool },
    /// PLC `pid` attached; the machine takes commands again.
    Attached { pid: u32 },
    /// The new PLC runs its cycles.
    Running { pid: u32 },
    /// The new PLC did not cycle in time, or left.
    Lost { pid: u32 },
}

impl Gap {
    /// Whether a PLC is missing (the supervision of a running PLC is off).
    pub(super) fn open(&self) -> bool {
        *self != Gap::Closed
    }

    /// One tick of the gap.
    pub(super) fn step(
        &mut self,
        tick: u64,
        machine: &mut Machine,
        segment: &CncSegment,
        drives: DrivesOnLoss,
    ) -> GapEvent {
        let pid_now = segment
            .header()
            .field::<u32>(offset_of!(HliSegmentHeader, plc_pid))
            .load_acquire();
        match *self {
            Gap::Closed => GapEvent::None,
            Gap::Lost { pid, .. } => {
                if !machine.at_rest() {
                    return GapEvent::None;
                }
                let cleared = segment.reset_plc_units();
                let disabled = drives == DrivesOnLoss::Disable;
                if disabled {
                    machine.disable_drives();
                }
                *self = Gap::Waiting { pid };
                GapEvent::Waiting { cleared, disabled }
            }
            Gap::Waiting { pid } => {
                if pid_now == 0 || pid_now == pid || !machine.rearm() {
                    return GapEvent::None;
                }
                *self = Gap::Attached {
                    pid: pid_now,
                    beat: segment.plc_heartbeat(),
                    at: monotonic::now(),
                };
                GapEvent::Attached { pid: pid_now }
            }
            Gap::Attached { pid, beat, at } => {
                if segment.plc_heartbeat() != beat {
                    *self = Gap::Closed;
                    return GapEvent::Running { pid };
                }
                let late = monotonic::now().saturating_sub(at) > FIRST_CYCLE_PATIENCE;
                if pid_now != pid || late {
                    *self = Gap::Lost { pid, since: tick };
                    return GapEvent::Lost { pid };
                }
                GapEvent::None
            }
        }
    }
}
