//! The dynamic-CS diagnosis over the acyclic channel: the CNC answers one history entry or
//! one log event per call from its rings ([`answer_history`], [`answer_log`]: no formatting,
//! no allocation, so it can run between ticks), and a reader turns the replies back into the
//! entries the listing renders ([`history_entry`], [`log_event`]).

use super::dyn_cs::{HistoryEntry, MasterSource, RingRead, TrackError, TrackEvent, Tracker};
use hli::calls::diag::{
    log_flags, log_kind, DiagWindow, DynCsHistoryReadCall, DynCsHistoryReply, DynCsLogReadCall,
    DynCsLogReply,
};

fn window<T>(read: &RingRead<'_, T>) -> DiagWindow {
    DiagWindow {
        sequence: read.entry.map_or(read.recorded, |(s, _)| s),
        recorded: read.recorded,
        kept: read.kept as u32,
        present: u32::from(read.entry.is_some()),
    }
}

/// The reply to a history read.
pub fn answer_history(tracker: &Tracker, call: &DynCsHistoryReadCall) -> DynCsHistoryReply {
    let read = tracker.history_at(call.sequence);
    let entry = read.entry.map(|(_, e)| *e).unwrap_or_default();
    DynCsHistoryReply {
        window: window(&read),
        tick: entry.tick,
        state: entry.state,
        reserved: 0,
        input: entry.input,
        translation: entry.translation,
        rotation: entry.rotation,
        output: entry.output,
    }
}

/// The history entry a reply carries (`None` when it holds none).
pub fn history_entry(reply: &DynCsHistoryReply) -> Option<HistoryEntry> {
    (reply.window.present == 1).then_some(HistoryEntry {
        tick: reply.tick,
        state: reply.state,
        input: reply.input,
        translation: reply.translation,
        rotation: reply.rotation,
        output: reply.output,
    })
}

fn source_number(source: MasterSource) -> u32 {
    match source {
        MasterSource::Plc => 0,
        MasterSource::Channel(c) => c as u32 + 1,
    }
}

fn source_of(number: u32) -> Result<MasterSource, WireError> {
    match number as usize {
        0 => Ok(MasterSource::Plc),
        n if n <= hli::layout::HLI_MAX_CHANNELS => Ok(MasterSource::Channel(n - 1)),
        _ => Err(WireError::UnknownSource(number)),
    }
}

fn flag(on: bool, bit: u32) -> u32 {
    if on {
        bit
    } else {
        0
    }
}

/// The reply to a log read.
pub fn answer_log(tracker: &Tracker, call: &DynCsLogReadCall) -> DynCsLogReply {
    let read = tracker.log_at(call.sequence);
    let mut reply = DynCsLogReply {
        window: window(&read),
        ..DynCsLogReply::default()
    };
    let Some((_, (tick, event))) = read.entry else {
        return reply;
    };
    reply.tick = *tick;
    match *event {
        TrackEvent::On {
            source,
            filter_ticks,
            wait,
            relative,
            simu,
            master,
        } => {
            reply.kind = log_kind::ON;
            reply.source = source_number(source);
            reply.filter_ticks = filter_ticks;
            reply.flags = flag(wait, log_flags::WAIT)
                | flag(relative, log_flags::RELATIVE)
                | flag(simu, log_flags::SIMU);
            reply.frame = master;
        }
        TrackEvent::OnValues { axes, master } => {
            reply.kind = log_kind::ON_VALUES;
            reply.axes = axes;
            reply.frame = master;
        }
        TrackEvent::Active => reply.kind = log_kind::ACTIVE,
        TrackEvent::Off {
            source,
            filter_ticks,
            axes,
            applied,
        } => {
            reply.kind = log_kind::OFF;
            reply.source = source_number(source);
            reply.filter_ticks = filter_ticks;
            reply.axes = axes;
            reply.frame = applied;
        }
        TrackEvent::Inactive => reply.kind = log_kind::INACTIVE,
        TrackEvent::MasterFrozen => reply.kind = log_kind::MASTER_FROZEN,
        TrackEvent::MasterResumed => reply.kind = log_kind::MASTER_RESUMED,
        TrackEvent::Error(e) | TrackEvent::Refused(e) => {
            reply.kind = if matches!(event, TrackEvent::Error(_)) {
                log_kind::ERROR
            } else {
                log_kind::REFUSED
            };
            (reply.error, reply.error_value) = e.code();
        }
        TrackEvent::Restart { finished } => {
            reply.kind = log_kind::RESTART;
            reply.flags = flag(finished, log_flags::FINISHED);
        }
        TrackEvent::CatchUp {
            landed,
            translation,
            rotation,
        } => {
            reply.kind = log_kind::CATCH_UP;
            reply.flags = flag(landed, log_flags::FINISHED);
            reply.frame[0] = translation;
            reply.frame[1] = rotation;
        }
    }
    reply
}

/// Why a log reply could not be read back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum WireError {
    /// An event kind this build does not know.
    #[error("log event kind {0} is not known")]
    UnknownKind(u32),
    /// An error code this build does not know.
    #[error("tracking error {0}/{1} is not known")]
    UnknownError(u32, u32),
    /// A master that is neither the PLC nor a channel.
    #[error("master {0} is neither the PLC (0) nor a channel (1..=12)")]
    UnknownSource(u32),
    /// A frame value that is not a number.
    #[error("log event at tick {0} carries a non-finite frame value")]
    NotFinite(u64),
}

/// The log event a reply carries (`Ok(None)` when it holds none).
pub fn log_event(reply: &DynCsLogReply) -> Result<Option<(u64, TrackEvent)>, WireError> {
    if reply.window.present != 1 {
        return Ok(None);
    }
    if reply.frame.iter().any(|v| !v.is_finite()) {
        return Err(WireError::NotFinite(reply.tick));
    }
    let has = |bit| reply.flags & bit != 0;
    let error = || {
        TrackError::from_code(reply.error, reply.error_value)
            .ok_or(WireError::UnknownError(reply.error, reply.error_value))
    };
    let event = match reply.kind {
        log_kind::ON => TrackEvent::On {
            source: source_of(reply.source)?,
            filter_ticks: reply.filter_ticks,
            wait: has(log_flags::WAIT),
            relative: has(log_flags::RELATIVE),
            simu: has(log_flags::SIMU),
            master: reply.frame,
        },
        log_kind::ON_VALUES => TrackEvent::OnValues {
            axes: reply.axes,
            master: reply.frame,
        },
        log_kind::ACTIVE => TrackEvent::Active,
        log_kind::OFF => TrackEvent::Off {
            source: source_of(reply.source)?,
            filter_ticks: reply.filter_ticks,
            axes: reply.axes,
            applied: reply.frame,
        },
        log_kind::INACTIVE => TrackEvent::Inactive,
        log_kind::MASTER_FROZEN => TrackEvent::MasterFrozen,
        log_kind::MASTER_RESUMED => TrackEvent::MasterResumed,
        log_kind::ERROR => TrackEvent::Error(error()?),
        log_kind::REFUSED => TrackEvent::Refused(error()?),
        log_kind::RESTART => TrackEvent::Restart {
            finished: has(log_flags::FINISHED),
        },
        log_kind::CATCH_UP => TrackEvent::CatchUp {
            landed: has(log_flags::FINISHED),
            translation: reply.frame[0],
            rotation: reply.frame[1],
        },
        other => return Err(WireError::UnknownKind(other)),
    };
    Ok(Some((reply.tick, event)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::channel::dyn_cs::BadParameter;

    fn every_event() -> Vec<TrackEvent> {
        let frame = [1.5, -2.25, 3.0, 10.0, -20.0, 30.5];
        let axes = [1, -2, 3, -4, 5, -6];
        let mut events = vec![
            TrackEvent::On {
                source: MasterSource::Channel(2),
                filter_ticks: 40,
                wait: true,
                relative: false,
                simu: true,
                master: frame,
            },
            TrackEvent::On {
                source: MasterSource::Plc,
                filter_ticks: 0,
                wait: false,
                relative: true,
                simu: false,
                master: frame,
            },
            TrackEvent::OnValues {
                axes,
                master: frame,
            },
            TrackEvent::Active,
            TrackEvent::Off {
                source: MasterSource::Plc,
                filter_ticks: 7,
                axes,
                applied: frame,
            },
            TrackEvent::Inactive,
            TrackEvent::MasterFrozen,
            TrackEvent::MasterResumed,
            TrackEvent::Restart { finished: false },
            TrackEvent::Restart { finished: true },
            TrackEvent::CatchUp {
                landed: false,
                translation: 0.125,
                rotation: 0.0,
            },
            TrackEvent::CatchUp {
                landed: true,
                translation: 2.5,
                rotation: 1.25,
            },
        ];
        let errors = [
            TrackError::AlreadyOn,
            TrackError::NoMasterInterface(3),
            TrackError::NoSuchChannel(11),
            TrackError::OwnChannel,
            TrackError::PlcNotEnabled,
            TrackError::BadFrame,
            TrackError::MachineStop,
            TrackError::JointLimit {
                axis: 5,
                kind: crate::channel::guard::LimitKind::Acceleration,
            },
            TrackError::ChannelFailed(hli::enums::ChannelErrorId::Kinematics),
            TrackError::PlcStop,
        ]
        .into_iter()
        .chain(BadParameter::ALL.map(TrackError::BadTransition));
        for e in errors {
            events.push(TrackEvent::Error(e));
            events.push(TrackEvent::Refused(e));
        }
        events
    }

    #[test]
    fn every_log_event_comes_back_as_it_went() {
        let mut tracker = Tracker::new(4, kinematics::RotationOrder::Zyx);
        let events = every_event();
        for e in &events {
            tracker.log_for_test(*e);
        }
        assert_eq!(tracker.log_at(0).recorded, events.len() as u64);
        for (sequence, e) in events.iter().enumerate() {
            let reply = answer_log(
                &tracker,
                &DynCsLogReadCall {
                    sequence: sequence as u64,
                },
            );
            assert_eq!(reply.window.sequence, sequence as u64);
            assert_eq!(log_event(&reply).unwrap().map(|(_, e)| e), Some(*e));
        }
        // Past the end: nothing, and the window says where it ends.
        let reply = answer_log(&tracker, &DynCsLogReadCall { sequence: 999 });
        assert_eq!(reply.window.present, 0);
        assert_eq!(reply.window.sequence, events.len() as u64);
        assert_eq!(log_event(&reply).unwrap(), None);
    }

    #[test]
    fn a_ring_is_read_by_sequence_across_its_wrap() {
        let mut ring = crate::channel::dyn_cs::Ring::<u64>::new(4);
        assert!(ring.read(0).entry.is_none());
        for v in 0..10u64 {
            ring.push(v * 100);
        }
        let read = ring.read(0);
        assert_eq!((read.recorded, read.kept), (10, 4));
        // Older than kept: the oldest kept; then each by its number; none past the end.
        assert_eq!(read.entry, Some((6, &600)));
        for s in 6..10u64 {
            assert_eq!(ring.read(s).entry, Some((s, &(s * 100))));
        }
        assert_eq!(ring.read(10).entry, None);
    }

    #[test]
    fn bad_replies_are_refused() {
        let mut reply = DynCsLogReply {
            window: DiagWindow {
                present: 1,
                ..DiagWindow::default()
            },
            kind: 99,
            ..DynCsLogReply::default()
        };
        assert_eq!(log_event(&reply), Err(WireError::UnknownKind(99)));
        reply.kind = log_kind::ERROR;
        reply.error = 6;
        reply.error_value = 6;
        assert_eq!(log_event(&reply), Err(WireError::UnknownError(6, 6)));
        reply.kind = log_kind::ON;
        reply.source = 13;
        assert_eq!(log_event(&reply), Err(WireError::UnknownSource(13)));
        reply.source = 0;
        reply.frame[2] = f64::NAN;
        assert_eq!(log_event(&reply), Err(WireError::NotFinite(0)));
    }
}
