//! Soak: every engine's scenario with its PLC timeline, in-process in lockstep, for many
//! ticks, with a randomised second PLC on top that sends a call of a random kind with a
//! random body every few ticks. Checked:
//! * no drift: a second run with the same seed gives the same trace, tick for tick (a running
//!   hash of the scenario's trace signals and of every axis's set-point);
//! * conservation: every call the timeline sent was answered once;
//! * flat memory: the heap the soak thread holds after the warm-up (a tenth of the run) moves
//!   by at most 1 % and 4 KiB (counted by the counting allocator, per thread, so the test
//!   harness's other threads do not count; the process's RSS would count them).
//!
//! CI runs 20,000 ticks per scenario (10^5 in all); `SOAK_TICKS=2000000 cargo test --release
//! -p cnc-app --test it soak -- --nocapture` runs 10^7.

use crate::counting_alloc::live_bytes;
use cnc_app::scenario::{InProcess, Scenario};
use hli::calls::CallKind;
use hli::views::CncView;
use hli::wire::AcyclicRequest;

const SCENARIOS: &[&str] = &[
    "example4-turntable-plc",
    "axes-plcopen",
    "cam-data",
    "fifo-blocks",
    "saw-blocks",
];

/// What one soak run saw.
#[derive(Debug, PartialEq)]
struct Soaked {
    trace_hash: u64,
    sent: u64,
    answered: u64,
    heap_after_warm_up: isize,
    heap_at_end: isize,
}

fn fnv(hash: u64, value: u64) -> u64 {
    value.to_le_bytes().iter().fold(hash, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x100_0000_01b3)
    })
}

/// A call of a random kind with a random body (most are refused; each is answered).
fn random_call(run: &mut InProcess, state: &mut u64) {
    let mut next = || {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    };
    let Some(kind) = CallKind::decode((next() % 48) as u32) else {
        return;
    };
    let mut request: AcyclicRequest = bytemuck::Zeroable::zeroed();
    request.kind = kind.raw();
    request.target = (next() % 40) as u32;
    request.body_len = (next() % 248) as u32;
    for chunk in request.body.chunks_mut(8) {
        let bytes = next().to_le_bytes();
        chunk.copy_from_slice(&bytes[..chunk.len()]);
    }
    let view = CncView::new(&run.memory);
    let _ = run.machine.dispatch(&view, kind, &request);
}

fn soak(name: &str, ticks: u64, seed: u64) -> Soaked {
    let path = tests::cli::scenario(name);
    let scenario = Scenario::load(&path).unwrap();
    let mut run = InProcess::new(&scenario, 0).unwrap();
    let mut state = seed | 1;
    let mut hash = 0xcbf2_9ce4_8422_2325;
    let mut heap_after_warm_up = 0;
    for tick in 0..ticks {
        if tick % 7 == 0 {
            random_call(&mut run, &mut state);
        }
        run.step(scenario.cycle_s);
        for (_, leaf) in &scenario.signals {
            hash = fnv(hash, leaf.read(&run.memory).as_f64().to_bits());
        }
        for i in 0..run.machine.axes().len() {
            let set = run.machine.axes().axis(i).map(|a| a.setpoint());
            let (p, v) = set.map_or((0.0, 0.0), |s| (s.position, s.velocity));
            hash = fnv(fnv(hash, p.to_bits()), v.to_bits());
        }
        if tick == ticks / 10 {
            heap_after_warm_up = live_bytes();
        }
    }
    // The calls of the last cycle are answered in one more step.
    run.step(scenario.cycle_s);
    let (sent, answered) = run.calls();
    Soaked {
        trace_hash: hash,
        sent,
        answered,
        heap_after_warm_up,
        heap_at_end: live_bytes(),
    }
}

fn ticks() -> u64 {
    std::env::var("SOAK_TICKS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20_000)
}

#[test]
fn every_engine_soaks_without_drift_loss_or_growth() {
    let ticks = ticks();
    let mut calls = 0;
    for (k, name) in SCENARIOS.iter().enumerate() {
        let seed = 0x50A4 + k as u64;
        let first = soak(name, ticks, seed);
        let second = soak(name, ticks, seed);
        eprintln!("soak: {name}: {ticks} ticks: {first:?}");
        assert_eq!(
            first.trace_hash, second.trace_hash,
            "{name}: the trace drifted"
        );
        assert_eq!(
            first.sent, first.answered,
            "{name}: calls sent and answered"
        );
        calls += first.sent;
        // The heap of the second run is measured from the first's end: its growth only.
        for run in [&first, &second] {
            let growth = run.heap_at_end - run.heap_after_warm_up;
            let bound = run.heap_after_warm_up.unsigned_abs() / 100 + 4096;
            assert!(
                growth.unsigned_abs() <= bound,
                "{name}: the heap moved by {growth} bytes after the warm-up ({run:?})"
            );
        }
    }
    assert!(calls > 0, "no timeline called a block");
}
