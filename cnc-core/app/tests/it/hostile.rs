//! A hostile PLC: every cycle it writes random values (random bits, NaN, infinities, extreme
//! integers, TRUE semaphores that push the garbage through) over random leaves of everything
//! a PLC may write, and sends a call of a random kind with a random body. The CNC must never
//! panic, keep its own values valid (every float it writes finite, every axis state a state,
//! every set-point finite and inside its axis's software limits) and count what it refused,
//! by class.
//!
//! CI runs a few thousand ticks per scenario; `cargo test --release -p cnc-app --test it
//! hostile -- --ignored --nocapture` runs 10^6 and prints the counts (docs/reliability.md).

use cnc_app::scenario::{InProcess, Scenario};
use cnc_core::channel::plc_io::Violations;
use hli::calls::CallKind;
use hli::desc::{Scalar, SymbolWriter};
use hli::symbols::{Symbol, SymbolKind, SymbolTable};
use hli::views::CncView;
use hli::wire::AcyclicRequest;
use hli::PlaceExt;
use tests::Noise;

/// Scenarios that together run every engine with a PLC timeline in-process.
const SCENARIOS: &[&str] = &[
    "example4-turntable-plc",
    "axes-plcopen",
    "cam-data",
    "fifo-blocks",
    "saw-blocks",
];

/// A hostile value of `size` bytes: random bits, or one of the values that break
/// careless code (NaN, ±inf, extremes, 0, ±1, TRUE).
fn hostile_value(noise: &mut Noise, size: usize) -> u64 {
    let special: [u64; 10] = [
        f64::NAN.to_bits(),
        f64::INFINITY.to_bits(),
        f64::NEG_INFINITY.to_bits(),
        u64::from(f32::NAN.to_bits()),
        u64::MAX,
        1 << (size * 8 - 1),
        (1 << (size * 8 - 1)) - 1,
        0,
        1,
        2,
    ];
    match noise.below(3) {
        0 => special[noise.below(special.len())],
        _ => noise.next(),
    }
}

/// What the PLC may write, and the CNC's float leaves.
struct Leaves {
    plc: Vec<&'static Symbol>,
    semaphores: Vec<&'static Symbol>,
    cnc_floats: Vec<&'static Symbol>,
}

fn leaves() -> Leaves {
    let all = SymbolTable::global().symbols();
    let leaf =
        |s: &&Symbol| matches!(s.kind, SymbolKind::Leaf(_)) && !s.path.starts_with("header.");
    Leaves {
        plc: all
            .iter()
            .filter(leaf)
            .filter(|s| matches!(s.writer, SymbolWriter::Plc | SymbolWriter::Both))
            .collect(),
        semaphores: all
            .iter()
            .filter(leaf)
            .filter(|s| s.writer == SymbolWriter::Both && s.path.ends_with("semaphore_rw"))
            .collect(),
        cnc_floats: all
            .iter()
            .filter(leaf)
            .filter(|s| s.writer == SymbolWriter::Cnc)
            .filter(|s| matches!(s.kind, SymbolKind::Leaf(Scalar::Real | Scalar::Lreal)))
            .collect(),
    }
}

fn write(memory: &hli::ImageMemory, s: &Symbol, value: u64) {
    match s.size {
        1 => memory.place::<u8>(s.offset).store(value as u8),
        2 => memory.place::<u16>(s.offset).store(value as u16),
        4 => memory.place::<u32>(s.offset).store(value as u32),
        _ => memory.place::<u64>(s.offset).store(value),
    }
}

/// One hostile PLC cycle: `writes` random leaves, a semaphore or two set TRUE, one call.
fn attack(run: &mut InProcess, leaves: &Leaves, noise: &mut Noise, writes: usize) {
    for _ in 0..writes {
        let s = leaves.plc[noise.below(leaves.plc.len())];
        let v = hostile_value(noise, s.size);
        write(&run.memory, s, v);
    }
    for _ in 0..2 {
        let s = leaves.semaphores[noise.below(leaves.semaphores.len())];
        write(&run.memory, s, 1);
    }
    random_calls(run, noise);
}

/// A call frame of a random kind with a random target and body, and a bulk call of that kind
/// with random numbers and shape, straight to the machine (most are refused; the soak uses it
/// too).
pub(crate) fn random_calls(run: &mut InProcess, noise: &mut Noise) {
    let Some(kind) = CallKind::decode(noise.below(48) as u32) else {
        return;
    };
    let mut request: AcyclicRequest = bytemuck::Zeroable::zeroed();
    request.kind = kind.raw();
    request.target = hostile_value(noise, 4) as u32 % 40;
    request.body_len = noise.below(hli::wire::ACYCLIC_BODY_SIZE + 8) as u32;
    for chunk in request.body.chunks_mut(8) {
        let bytes = hostile_value(noise, 8).to_le_bytes();
        chunk.copy_from_slice(&bytes[..chunk.len()]);
    }
    let view = CncView::new(&run.memory);
    let _ = run.machine.dispatch(&view, kind, &request);
    let values: Vec<f64> = (0..noise.below(16))
        .map(|_| f64::from_bits(hostile_value(noise, 8)))
        .collect();
    let header = hli::wire::BulkHeader {
        kind: kind.raw(),
        target: request.target,
        columns: noise.below(5) as u32,
        rows: noise.below(5) as u32,
    };
    let _ = run.machine.dispatch_bulk(&header, &values);
}

/// The CNC's invariants after a tick.
fn check(run: &InProcess, leaves: &Leaves, scenario: &str) {
    let tick = run.machine.ticks();
    for s in &leaves.cnc_floats {
        let v = match s.kind {
            SymbolKind::Leaf(Scalar::Real) => f64::from(run.memory.place::<f32>(s.offset).load()),
            _ => run.memory.place::<f64>(s.offset).load(),
        };
        assert!(v.is_finite(), "{scenario} tick {tick}: {} = {v}", s.path);
    }
    let view = CncView::new(&run.memory);
    for i in 0..run.machine.axes().len() {
        let axis = run.machine.axes().axis(i).unwrap();
        let sp = axis.setpoint();
        assert!(
            sp.position.is_finite() && sp.velocity.is_finite() && sp.acceleration.is_finite(),
            "{scenario} tick {tick}: axis {i} {sp:?}"
        );
        // Within its software limits (a set-point that would leave them stops the axis).
        if let Some([min, max]) = axis.config().soft_limits {
            let room = 1e-6 * (max - min);
            assert!(
                (min - room..=max + room).contains(&sp.position),
                "{scenario} tick {tick}: axis {i} at {} outside [{min}, {max}]",
                sp.position
            );
        }
        let lr: hli::layout::HliAxisLrState = view
            .axis(i)
            .unwrap()
            .field::<hli::layout::HliAxisLrState>(core::mem::offset_of!(
                hli::layout::HliAxis,
                lr_state
            ))
            .read();
        assert!(
            hli::enums::AxisState::decode(lr.axis_state_r).is_ok(),
            "{scenario} tick {tick}: axis {i} state {}",
            lr.axis_state_r
        );
    }
}

/// Runs every scenario `ticks` ticks under attack; the refusals summed.
fn siege(ticks: u64, writes: usize, seed: u64) -> Violations {
    let leaves = leaves();
    let mut total = Violations::default();
    for (k, name) in SCENARIOS.iter().enumerate() {
        let path = tests::cli::repo_root()
            .join("scenarios")
            .join(name)
            .join("scenario.toml");
        let scenario = Scenario::load(&path).unwrap();
        let mut run = InProcess::new(&scenario, 0).unwrap();
        let mut noise = Noise::new(seed ^ (k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        for _ in 0..ticks {
            attack(&mut run, &leaves, &mut noise, writes);
            run.step(scenario.cycle_s);
            check(&run, &leaves, name);
        }
        let seen = run.machine.plc_violations();
        eprintln!(
            "hostile PLC: {name}: {ticks} ticks, {} random writes: {seen:?}",
            ticks * writes as u64
        );
        total.add(&seen);
    }
    total
}

#[test]
fn a_hostile_plc_is_refused_and_counted_and_the_cnc_keeps_its_invariants() {
    let seen = siege(3_000, 8, 0x00C0_FFEE);
    // Every class the attack can produce was seen and counted.
    assert!(seen.semaphore_garbage > 0, "{seen:?}");
    assert!(seen.bool_garbage > 0, "{seen:?}");
    assert!(seen.out_of_range > 0, "{seen:?}");
    assert!(seen.command_garbage > 0, "{seen:?}");
    assert!(seen.refused_calls > 0, "{seen:?}");
}

#[test]
#[ignore = "10^6 ticks per scenario: run in release for the figures of docs/reliability.md"]
fn a_hostile_plc_for_a_million_cycles() {
    let seen = siege(1_000_000, 8, 0x5EED_0001);
    eprintln!(
        "hostile PLC: all scenarios: {seen:?}, total {}",
        seen.total()
    );
}

/// Every leaf only the CNC writes (the axis image's inputs included: the simulated drives'
/// answers), header aside.
fn cnc_leaves() -> Vec<&'static Symbol> {
    SymbolTable::global()
        .symbols()
        .iter()
        .filter(|s| matches!(s.kind, SymbolKind::Leaf(_)) && !s.path.starts_with("header."))
        .filter(|s| matches!(s.writer, SymbolWriter::Cnc | SymbolWriter::Io))
        .collect()
}

#[test]
fn garbage_over_the_cnc_s_own_leaves_changes_nothing_it_does() {
    // Example 3 (three channels, two tracking the master through the channel interface) has
    // no PLC: whatever a PLC wrote over the CNC's own leaves, the CNC must not take it back.
    // A clean run and one whose CNC-written leaves are overwritten before every tick must
    // move every axis the same, tick for tick.
    let leaves = cnc_leaves();
    let path = tests::cli::scenario("example3-moving-workpiece");
    let scenario = Scenario::load(&path).unwrap();
    let mut clean = InProcess::new(&scenario, 0).unwrap();
    let mut hit = InProcess::new(&scenario, 0).unwrap();
    let mut noise = Noise::new(0xBAD_CAFE);
    for tick in 0..4_000 {
        for _ in 0..64 {
            let s = leaves[noise.below(leaves.len())];
            let v = hostile_value(&mut noise, s.size);
            write(&hit.memory, s, v);
        }
        clean.step(scenario.cycle_s);
        hit.step(scenario.cycle_s);
        for i in 0..clean.machine.axes().len() {
            let (a, b) = (
                clean.machine.axes().axis(i).unwrap().setpoint(),
                hit.machine.axes().axis(i).unwrap().setpoint(),
            );
            assert_eq!(a, b, "tick {tick}: axis {i}");
        }
    }
    let moved = (0..clean.machine.axes().len())
        .filter(|&i| clean.machine.axes().axis(i).unwrap().setpoint().position != 0.0)
        .count();
    assert!(moved > 3, "the example moved {moved} axes");
}
