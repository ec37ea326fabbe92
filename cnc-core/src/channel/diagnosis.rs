//! The dynamic-CS diagnosis as text tables in the layout of the controller's listings: the
//! per-tick history (P-STUP-00074 entries) and the switching log.

use super::dyn_cs::MasterSource;
use super::dyn_cs::{TrackEvent, Tracker};
use std::fmt::Write as _;

fn list(values: &[i64]) -> String {
    values
        .iter()
        .map(i64::to_string)
        .collect::<Vec<_>>()
        .join(",")
}

/// Renders the history and the log of channel `index` (0-based; printed 1-based).
pub fn render(index: usize, tracker: &Tracker) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "BAHN : DYNAMIC CS, CHANNEL-NR.: {}", index + 1);
    let _ = writeln!(out, "=====");
    let _ = writeln!(
        out,
        "TIME STATE POSITION_IN CS_TRANSLATION CS_ROTATION POSITION_OUT"
    );
    for (n, e) in tracker.history().enumerate() {
        let _ = writeln!(
            out,
            "{} {}) {} ({}) ({}) ({}) ({})",
            e.tick,
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
    let _ = writeln!(out, "time message");
    let _ = writeln!(out, "-----");
    for (tick, event) in tracker.log() {
        let _ = writeln!(out, "{tick} {}", log_message(*tick, event));
    }
    out
}

/// One switching-log message (a switch-on or -off message holds a second, tick-stamped line).
pub(crate) fn log_message(tick: u64, event: &TrackEvent) -> String {
    let frame = |w: &[f64; 6]| {
        let u = w.map(|v| (v * 10_000.0).round() as i64);
        format!(
            "T({}, {}, {}) R({}, {}, {})",
            u[0], u[1], u[2], u[3], u[4], u[5]
        )
    };
    match event {
        TrackEvent::On {
            source,
            filter_ticks,
            wait,
            relative,
            simu,
            master,
        } => {
            let source = match source {
                MasterSource::Plc => "PLC=1".to_string(),
                MasterSource::Channel(c) => format!("CH={}", c + 1),
            };
            let flags = match (relative, simu) {
                (false, false) => "",
                (true, false) => " RELATIVE",
                (false, true) => " SIMU",
                (true, true) => " RELATIVE SIMU",
            };
            format!(
                "dynCS: cmd=ON {source} FILTER={filter_ticks} WAIT={}{flags}\n{tick} dynCS: ON, VALUE {}",
                u8::from(*wait),
                frame(master)
            )
        }
        TrackEvent::Active => "dynCS: is on = ACTIVE".to_string(),
        TrackEvent::Off {
            filter_ticks,
            applied,
        } => format!(
            "dynCS: cmd=OFF FILTER={filter_ticks}\n{tick} dynCS: VALUE {}",
            frame(applied)
        ),
        TrackEvent::Inactive => "dynCS: is off = INACTIVE".to_string(),
        TrackEvent::MasterFrozen => "dynCS: master frozen, holding".to_string(),
        TrackEvent::MasterResumed => "dynCS: master resumed, soft take-over".to_string(),
        TrackEvent::Error(e) => format!("dynCS: ERROR: {e}"),
    }
}
