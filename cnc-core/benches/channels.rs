//! Tick cost of the CNC with 1, 4 and 12 six-axis robots (kinematic 45), tracking active on
//! every channel (robot 1 follows the PLC's dynamic CS, the others follow robot 1), each
//! running an endless loop of moves: interpreter, interpolation, inverse and forward
//! transformation, dynamic CS, HLI outputs and axis images.
//!
//! Reported: median over repeats of the time per tick and per channel-tick, and the ratio of
//! the per-channel-tick cost to the 1-channel run of the same process (linearity). Baseline in
//! the same run: the same channels ticking without any program and without tracking (the
//! fixed cost of outputs and bookkeeping), so the ratio says what the motion work adds.
//! Target: <= 5 us per channel-tick, linear in channels.
//! Run: `cargo bench -p cnc-core --bench channels`.

use cnc_core::channel::{Channel, Controller};
use cnc_core::scenario::fleet::{running, tracking_robots};
use hli::views::CncView;
use std::time::Instant;

const TICKS: usize = 5_000;
const REPEATS: usize = 9;
const WARM_UP: usize = 3_000;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median ns per tick of `tick`, over REPEATS runs of TICKS ticks.
fn time(mut tick: impl FnMut()) -> f64 {
    let mut samples = Vec::with_capacity(REPEATS);
    for _ in 0..REPEATS {
        let t0 = Instant::now();
        for _ in 0..TICKS {
            tick();
        }
        samples.push(t0.elapsed().as_nanos() as f64 / TICKS as f64);
    }
    median(samples)
}

fn tracking(n: usize) -> f64 {
    let mut run = running(n, WARM_UP).expect("fleet running");
    time(|| run.machine.tick(&run.memory))
}

fn idle(n: usize) -> f64 {
    let s = tracking_robots(n).expect("fleet scenario");
    let channels = s
        .channels
        .iter()
        .enumerate()
        .map(|(i, c)| Channel::new(i, c.clone(), s.cycle_s).expect("channel"))
        .collect();
    let mut controller = Controller::new(channels).expect("controller");
    let memory = hli::segment::heap_image(n as u32, 32);
    let view = CncView::new(&memory);
    time(|| controller.tick(&view))
}

fn main() {
    println!("channels | tracking: ns/tick | ns/channel-tick | vs 1 channel | idle baseline ns/channel-tick | tracking / idle");
    let mut one = None;
    for n in [1usize, 4, 12] {
        let t = tracking(n);
        let b = idle(n);
        let per = t / n as f64;
        let base = *one.get_or_insert(per);
        println!(
            "{n:>8} | {t:>17.0} | {per:>15.0} | {:>12.2} | {:>29.0} | {:>15.1}",
            per / base,
            b / n as f64,
            t / b
        );
    }
    println!("(medians of {REPEATS} runs of {TICKS} ticks; target <= 5000 ns per channel-tick)");
}
