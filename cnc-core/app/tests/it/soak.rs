//! Soak: every engine's scenario with its PLC timeline, in-process in lockstep, for many
//! ticks, with a randomised second PLC on top that sends a call of a random kind with a
//! random body, and a bulk call, every few ticks (`hostile::random_calls`). Checked:
//! * no drift: a second run with the same seed gives the same trace, tick for tick (a running
//!   hash of the scenario's trace signals and of every axis's set-point);
//! * conservation: every call the timeline sent was answered once, and every unit of data an
//!   engine took (a FIFO row, a cam table's row or point) was done, dropped or is pending
//!   (`Engine::balance`);
//! * flat memory: the heap the soak thread holds after the warm-up (a tenth of the run) moves
//!   by at most 1 % and 4 KiB (counted by the counting allocator, per thread, so the test
//!   harness's other threads do not count; the process's RSS would count them).
//!
//! CI runs 20,000 ticks per scenario (10^5 in all); `SOAK_TICKS=2000000 cargo test --release
//! -p cnc-app --test it soak -- --nocapture` runs 10^7.

use crate::counting_alloc::live_bytes;
use cnc_app::scenario::{InProcess, Scenario};
use cnc_core::machine::engine::Balance;
use plc_shim::timeline::registry::{BlockSpec, Kind, Target, FAMILIES};
use std::path::PathBuf;
use tests::Noise;

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
    /// Calls the CNC refused (the timeline's and the random ones).
    refused: u64,
    /// Random calls made.
    random_calls: u64,
    /// Each engine's data: taken, done, dropped, pending.
    balances: Vec<(&'static str, Balance)>,
}

fn fnv(hash: u64, value: u64) -> u64 {
    value.to_le_bytes().iter().fold(hash, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x100_0000_01b3)
    })
}

fn soak(name: &str, ticks: u64, seed: u64) -> Soaked {
    let scenario = Scenario::load(&tests::cli::scenario(name)).unwrap();
    soak_scenario(&scenario, ticks, seed)
}

fn soak_scenario(scenario: &Scenario, ticks: u64, seed: u64) -> Soaked {
    let mut run = InProcess::new(scenario, 0).unwrap();
    let mut noise = Noise::new(seed);
    let mut hash = 0xcbf2_9ce4_8422_2325;
    let mut heap_after_warm_up = 0;
    for tick in 0..ticks {
        if tick % 7 == 0 {
            super::hostile::random_calls(&mut run, &mut noise);
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
    let balances: Vec<_> = run.machine.balances().collect();
    for (engine, b) in &balances {
        assert!(b.holds(), "{engine}: data unaccounted for: {b:?}");
    }
    Soaked {
        balances,
        refused: run.machine.plc_violations().refused_calls,
        random_calls: ticks.div_ceil(7),
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
        // The data scenarios' engines took data, all of it accounted for (checked in the run).
        let data = [("fifo-blocks", "fifo"), ("cam-data", "cam")];
        if let Some((_, engine)) = data.iter().find(|(s, _)| s == name) {
            let took = first
                .balances
                .iter()
                .any(|(n, b)| n == engine && b.taken > 0);
            assert!(took, "{name}: {engine} took no data: {:?}", first.balances);
        }
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

/// A random value for an input of `kind`, as TOML text: mostly plausible, often not what the
/// machine takes (negative dynamics, far positions, IDs that do not exist), never what the
/// timeline itself refuses.
fn random_input(kind: &Kind, next: &mut impl FnMut() -> u64) -> Option<String> {
    const REALS: [f64; 12] = [
        0.0, 1.0, -1.0, 10.0, 100.0, 360.0, 1000.0, -250.0, 0.5, 1e6, -1e9, 5000.0,
    ];
    Some(match kind {
        Kind::Bool => next().is_multiple_of(2).to_string(),
        Kind::Real => format!("{:?}", REALS[(next() % REALS.len() as u64) as usize]),
        Kind::Count => (next() % 6).to_string(),
        Kind::Range(lo, hi) => {
            let span = (hi - lo).unsigned_abs().min(1 << 20) + 1;
            (lo + (next() % span) as i64).to_string()
        }
        Kind::ZeroOr(lo, hi) if next().is_multiple_of(2) => {
            let span = (hi - lo).unsigned_abs().min(1 << 20) + 1;
            (lo + (next() % span) as i64).to_string()
        }
        Kind::ZeroOr(..) => "0".into(),
        Kind::OneOf(values) => {
            let written = values[(next() % values.len() as u64) as usize].0;
            // The TOML value, without the note that may follow it.
            written.split(' ').next().unwrap_or(written).to_string()
        }
        Kind::Mode(mode) => {
            let raw = (0..16).find(|_| (mode.valid)((next() % 16) as u32));
            raw.map(|_| {
                let mut v = next() % 16;
                while !(mode.valid)(v as u32) {
                    v = next() % 16;
                }
                v.to_string()
            })?
        }
        Kind::Between(lo, hi) => {
            let share = (next() % 5) as f64 / 4.0;
            format!("{:?}", lo + (hi - lo) * share)
        }
        Kind::Positive => format!("{:?}", [0.5, 1.0, 2.0, 10.0][(next() % 4) as usize]),
        Kind::Flags { flags, .. } => {
            let bits = (0..next() % 3).map(|_| flags[(next() % flags.len() as u64) as usize].1);
            bits.fold(0, |mask, bit| mask | bit).to_string()
        }
        Kind::Room => (1 + next() % 64).to_string(),
        Kind::Parsed { example, .. } => example.to_string(),
    })
}

/// A timeline of `steps` random calls of every block, on the machine's six
/// axes (a scenario refuses an axis it does not have), one instance per block and axis,
/// Execute lowered now and then.
fn random_timeline(steps: usize, seed: u64) -> String {
    let mut noise = Noise::new(seed);
    let mut next = move || noise.next();
    let blocks: Vec<&BlockSpec> = FAMILIES
        .iter()
        .flat_map(|family| family.iter())
        // This machine has no channel: the channel blocks run in channel_control.rs.
        .filter(|b| !matches!(b.target, Target::Channel))
        .collect();
    let mut text = String::new();
    for k in 0..steps {
        let b = blocks[(next() % blocks.len() as u64) as usize];
        let inputs = b.inputs;
        let (instance, axis) = match b.target {
            Target::Group => (format!("{}_g", b.name), String::new()),
            _ => {
                let axis = next() % 6;
                (format!("{}_{axis}", b.name), format!(", axis = {axis}"))
            }
        };
        let mut call = format!("block = \"{}\", instance = \"{instance}\"{axis}", b.name);
        if b.execute && next().is_multiple_of(5) {
            call.push_str(", execute = false");
        } else {
            for input in inputs {
                if let Some(v) = random_input(&input.kind, &mut next) {
                    call.push_str(&format!(", {} = {v}", input.key));
                }
            }
        }
        text.push_str(&format!(
            "[[step]]\nat_tick = {}\ncall = {{ {call} }}\n\n",
            5 + 40 * k
        ));
    }
    text
}

#[test]
fn a_randomised_plc_calling_every_block_soaks_without_drift_or_loss() {
    let dir = tests::cli::repo_root().join("cnc-core/app/tests/data/soak");
    let machine = std::fs::read_to_string(dir.join("scenario.toml")).unwrap();
    let cam = std::fs::read_to_string(dir.join("seed_example.json")).unwrap();
    let ticks = ticks();
    let steps = (ticks / 40) as usize;
    let timeline = random_timeline(steps, 0xB10C5);
    let scenario = Scenario::parse("soak/scenario.toml", &machine, |name| match name {
        "plc.toml" => Ok((PathBuf::from(name), timeline.clone())),
        _ => Ok((PathBuf::from(name), cam.clone())),
    })
    .unwrap_or_else(|e| panic!("{e}\n{timeline}"));
    let run = |seed| soak_scenario(&scenario, ticks, seed);
    let (first, second) = (run(7), run(7));
    eprintln!("soak: random timeline, {steps} calls: {first:?}");
    assert_eq!(first.trace_hash, second.trace_hash, "the trace drifted");
    assert_eq!(first.sent, first.answered, "calls sent and answered");
    // The cams took data (and accounted for it: checked in the run); the FIFO group's rows
    // need a grouped, started group, which random calls rarely build: fifo-blocks has them.
    let took = first
        .balances
        .iter()
        .any(|(n, b)| *n == "cam" && b.taken > 0);
    assert!(took, "the cams took no data: {:?}", first.balances);
    assert!(
        first.sent as usize >= steps / 2,
        "{} calls for {steps} steps",
        first.sent
    );
    // Valid and invalid calls both: some taken, some refused.
    let all = first.sent + first.random_calls;
    assert!(first.refused > 0 && first.refused < all, "{first:?}");
    // Tables a call stores are the CNC's to keep; past the warm-up the heap stays within 1 %.
    let growth = first.heap_at_end - first.heap_after_warm_up;
    assert!(growth.unsigned_abs() <= first.heap_after_warm_up.unsigned_abs() / 100);
}
