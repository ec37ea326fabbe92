//! The dynamic-CS diagnosis as text in the layout of the controller's listings: the per-tick
//! history (P-STUP-00074 entries) and the switching log.
//!
//! History rows are `TIME n) STATE (in X..C) (translation) (rotation) (out X..C)` in 0.1 um /
//! 0.0001 degree; the first row shows the whole tick and the following rows its last three
//! digits, as the controller abbreviates them. The log is a ring of [`LOG_LINES`] lines, each
//! `TICK LEVEL MESSAGE` with an eight-digit hexadecimal level (`00000001` channel messages,
//! `00000010` dynamic-CS messages); its header counts the lines used and the next write index.
//! A switch-on logs its axis positions (before the dynamic CS) and the master frame in the
//! tick after the command; a switch-off logs them in its own tick. `NO` after the source is
//! printed where the controller prints it; the manual does not explain it. The state names
//! follow the controller's `DYN_CS_SYNC_*`; the freeze, resume, error and refusal lines are
//! ours.

use super::dyn_cs::{HistoryEntry, MasterSource, TrackEvent, Tracker, LOG_LINES};
use std::fmt::Write as _;

/// Level of the channel's own messages.
const LEVEL_CHANNEL: u32 = 0x01;
/// Level of dynamic-CS messages.
const LEVEL_DYN_CS: u32 = 0x10;

fn list(values: &[i64]) -> String {
    values
        .iter()
        .map(i64::to_string)
        .collect::<Vec<_>>()
        .join(",")
}

/// Renders the history and the log of channel `index` (0-based; printed 1-based).
pub fn render(index: usize, tracker: &Tracker) -> String {
    render_entries(
        index,
        tracker.history().copied(),
        tracker.log().map(|(tick, event)| (*tick, *event)),
    )
}

/// Renders a history and a log given entry by entry, oldest first (what a tool read from a
/// running CNC).
pub fn render_entries(
    index: usize,
    history: impl Iterator<Item = HistoryEntry>,
    log: impl Iterator<Item = (u64, TrackEvent)>,
) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "BAHN : DYNAMIC CS, CHANNEL-NR.: {}", index + 1);
    let _ = writeln!(out, "=====");
    let _ = writeln!(out, "dynCs : max entries per PDU 15");
    let _ = writeln!(
        out,
        "TIME STATE POSITION_IN CS_TRANSLATION CS_ROTATION POSITION_OUT"
    );
    for (n, e) in history.enumerate() {
        let time = if n == 0 {
            e.tick.to_string()
        } else {
            format!("{:03}", e.tick % 1000)
        };
        let _ = writeln!(
            out,
            "{time} {}) {} ({}) ({}) ({}) ({})",
            n + 1,
            e.state,
            list(&e.input),
            list(&e.translation),
            list(&e.rotation),
            list(&e.output)
        );
    }
    let _ = writeln!(out);
    let _ = writeln!(out, "BAHN LOGGING KANAL-NR.: {}", index + 1);
    let _ = writeln!(out, "=====");
    let lines: Vec<(u64, u32, String)> = log
        .flat_map(|(tick, event)| event_lines(tick, &event))
        .collect();
    let kept = &lines[lines.len().saturating_sub(LOG_LINES)..];
    let _ = writeln!(
        out,
        "BF 8 logging : {}/{LOG_LINES}, level ffffffff, index {}",
        kept.len(),
        lines.len() % LOG_LINES
    );
    let _ = writeln!(out);
    let _ = writeln!(out, "time level message");
    let _ = writeln!(out, "-----");
    for (tick, level, message) in kept {
        let _ = writeln!(out, "{tick} {level:08x} {message}");
    }
    out
}

/// The lines one event adds to the log: tick, level and message.
pub fn event_lines(tick: u64, event: &TrackEvent) -> Vec<(u64, u32, String)> {
    let axes = |a: &[i64; 6]| {
        [
            format!("a[0..2]({}, {}, {})", a[0], a[1], a[2]),
            format!("a[3..5]({}, {}, {})", a[3], a[4], a[5]),
        ]
    };
    let frame = |w: &[f64; 6]| {
        let u = w.map(|v| (v * 10_000.0).round() as i64);
        [
            format!("T({}, {}, {})", u[0], u[1], u[2]),
            format!("R({}, {}, {})", u[3], u[4], u[5]),
        ]
    };
    let source = |s: &MasterSource| match s {
        MasterSource::Plc => "PLC=1".to_string(),
        MasterSource::Channel(c) => format!("CH={}", c + 1),
    };
    let dyn_cs = |messages: Vec<String>| {
        messages
            .into_iter()
            .map(|m| (tick, LEVEL_DYN_CS, m))
            .collect::<Vec<_>>()
    };
    match event {
        TrackEvent::Restart { finished } => vec![(
            tick,
            LEVEL_CHANNEL,
            if *finished {
                "BAHN restart...finished".to_string()
            } else {
                "BAHN restart... start".to_string()
            },
        )],
        TrackEvent::On {
            source: s,
            filter_ticks,
            wait,
            relative,
            simu,
            ..
        } => {
            let flags = match (relative, simu) {
                (false, false) => "",
                (true, false) => " RELATIVE",
                (false, true) => " SIMU",
                (true, true) => " RELATIVE SIMU",
            };
            dyn_cs(vec![format!(
                "dynCS: cmd=ON {} NO FILTER={filter_ticks} WAIT={}{flags}",
                source(s),
                u8::from(*wait)
            )])
        }
        TrackEvent::OnValues { axes: a, master } => {
            let [a012, a345] = axes(a);
            let [t, r] = frame(master);
            dyn_cs(vec![
                "dynCS: ON, axes positions".to_string(),
                a012,
                a345,
                "dynCS: ON, VALUE".to_string(),
                t,
                r,
            ])
        }
        TrackEvent::Active => dyn_cs(vec!["dynCS: is on = DYN_CS_SYNC_ACTIVE".to_string()]),
        TrackEvent::Off {
            source: s,
            filter_ticks,
            axes: a,
            applied,
        } => {
            let [a012, a345] = axes(a);
            let [t, r] = frame(applied);
            dyn_cs(vec![
                format!("dynCS: cmd=OFF {} NO FILTER={filter_ticks}", source(s)),
                a012,
                a345,
                "dynCS: VALUE".to_string(),
                t,
                r,
            ])
        }
        TrackEvent::Inactive => dyn_cs(vec!["dynCS: is off = DYN_CS_SYNC_INACTIVE".to_string()]),
        TrackEvent::MasterFrozen => dyn_cs(vec!["dynCS: master frozen, holding".to_string()]),
        TrackEvent::MasterResumed => {
            dyn_cs(vec!["dynCS: master resumed, soft take-over".to_string()])
        }
        TrackEvent::CatchUp {
            landed,
            translation,
            rotation,
        } => dyn_cs(vec![format!(
            "dynCS: axes {} lag {translation:.4} mm {rotation:.4} deg",
            if *landed {
                "on the compensation, largest"
            } else {
                "catch up with a step,"
            }
        )]),
        TrackEvent::Error(e) => dyn_cs(vec![format!("dynCS: ERROR: {e}")]),
        TrackEvent::Refused(e) => dyn_cs(vec![format!("dynCS: refused: {e}")]),
    }
}

/// The first line of an event's message, for reports; `None` for the lines that only carry
/// values or the channel's restart.
pub fn log_message(tick: u64, event: &TrackEvent) -> Option<String> {
    match event {
        TrackEvent::Restart { .. } | TrackEvent::OnValues { .. } => None,
        _ => event_lines(tick, event)
            .into_iter()
            .next()
            .map(|(_, _, message)| message),
    }
}
