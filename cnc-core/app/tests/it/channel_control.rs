//! `scenarios/channel-control`: the PLC runs the part three times, holds the feed for an
//! operator in the second run, and recovers the channel from an error by RESET, all from its
//! timeline; the channel's states and axes checked tick by tick on the trace.

use cnc_app::scenario::{InProcess, Scenario};
use hli::enums::{ChannelErrorId, ChannelState};

fn column(run: &InProcess, name: &str) -> Vec<f64> {
    run.trace
        .column(name)
        .unwrap_or_else(|| panic!("no column {name}"))
        .map(|v| v.as_f64())
        .collect()
}

const STATE: &str = "gpCh[0]^channel_control.state_r.state";
const ENDED: &str = "gpCh[0]^channel_control.state_r.programs_ended";
const ERROR: &str = "gpCh[0]^channel_control.state_r.error_id";
const FEED: &str = "gpCh[0]^bahn_state.path_feed_r";
const X: &str = "gpAx[0]^lr_state.current_position_acs_r";
const Y: &str = "gpAx[1]^lr_state.current_position_acs_r";

fn is(state: f64, s: ChannelState) -> bool {
    state == f64::from(s.raw())
}

/// The ticks of each maximal stretch in state `s`.
fn stretches(state: &[f64], s: ChannelState) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = None;
    for (t, v) in state.iter().enumerate() {
        match (is(*v, s), start) {
            (true, None) => start = Some(t),
            (false, Some(a)) => {
                out.push(a..t);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(a) = start {
        out.push(a..state.len());
    }
    out
}

#[test]
fn the_plc_runs_the_part_holds_it_and_recovers_the_channel_by_reset() {
    let s =
        Scenario::load(&tests::cli::scenario("channel-control")).unwrap_or_else(|e| panic!("{e}"));
    let run = InProcess::run_through(&s).unwrap();
    let (state, ended, error) = (
        column(&run, STATE),
        column(&run, ENDED),
        column(&run, ERROR),
    );
    let (feed, x, y) = (column(&run, FEED), column(&run, X), column(&run, Y));

    // Nothing moves before the PLC's START (the timeline sends it at tick 10).
    let first_run = state
        .iter()
        .position(|v| is(*v, ChannelState::Running))
        .unwrap();
    assert!(
        first_run > 10,
        "started by the PLC, not with the CNC: {first_run}"
    );
    assert!(state[..first_run]
        .iter()
        .all(|v| is(*v, ChannelState::Selected)));
    assert!(x[..first_run].iter().all(|v| *v == 0.0));

    // Four runs of the part; between runs the program stays selected.
    let mut counts: Vec<f64> = ended.clone();
    counts.dedup();
    assert_eq!(counts, [0.0, 1.0, 2.0, 3.0, 4.0]);
    let runs = stretches(&state, ChannelState::Running);
    assert!(
        runs.len() >= 5,
        "three parts (one held), the failing program, a fourth part: {runs:?}"
    );

    // The hold: one stretch of HOLDING inside part 2, the axes standing still once the feed is
    // 0, for the operator's half second, and the part went on (part 2 ended).
    let holds = stretches(&state, ChannelState::Holding);
    assert_eq!(holds.len(), 1, "{holds:?}");
    let hold = holds[0].clone();
    assert!(hold.start >= 2500 && hold.end <= 3002, "{hold:?}");
    let still = (hold.start..hold.end).find(|&t| feed[t] == 0.0).unwrap();
    assert!(
        hold.end - still > 300,
        "standing {} ticks",
        hold.end - still
    );
    for t in still..hold.end {
        assert_eq!(
            (x[t], y[t]),
            (x[still], y[still]),
            "tick {t}: moved in the hold"
        );
    }
    // It stood on the path, not at a corner of the rectangle (a block's end).
    let corners = [(0.0, 0.0), (1e6, 0.0), (1e6, 5e5), (0.0, 5e5)];
    assert!(
        !corners.contains(&(x[still], y[still])),
        "held at a corner: {}",
        x[still]
    );
    assert_eq!(ended[hold.start], 1.0);
    assert_eq!(ended[hold.end + 1], 1.0);

    // The failing program: ERROR with the tracking's error id, then RESET, error cleared,
    // selected again, and the fourth part runs.
    let errors = stretches(&state, ChannelState::Error);
    let failed = errors.first().expect("the failing program's ERROR").start;
    assert_eq!(error[failed], f64::from(ChannelErrorId::Tracking.raw()));
    assert_eq!(ended[failed], 3.0);
    let after = (failed..state.len())
        .find(|&t| is(state[t], ChannelState::Selected))
        .unwrap();
    assert_eq!(error[after], 0.0, "RESET cleared the error");
    assert!(state[after..].iter().any(|v| is(*v, ChannelState::Running)));
    assert!(is(*state.last().unwrap(), ChannelState::Selected));
    assert_eq!(*error.last().unwrap(), 0.0);

    // No jump anywhere: every tick's step within the channel's velocity (0.1 um per tick).
    let limits = s.channels[0].limits;
    let per_tick = limits.velocity * s.cycle_s * 1e4 * 1.001;
    for axis in [&x, &y] {
        for (t, w) in axis.windows(2).enumerate() {
            assert!(
                (w[1] - w[0]).abs() <= per_tick,
                "tick {t}: step {}",
                w[1] - w[0]
            );
        }
    }
}
