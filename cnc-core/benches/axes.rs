//! Per-axis tick cost of the axis layer for 32 axes: set-point generation, increments and
//! overflow counting, following-error check, position controller, process image in and out,
//! command book, and the simulated drive and encoder.
//!
//! Baseline in the same run: the image traffic alone (the same reads and writes of every
//! axis's structs, no computation), so the ratio says what the axis work adds. Medians over
//! repeats. Run: `cargo bench -p cnc-core --bench axes`.

use bench_kit::{median, scaled};
use cnc_core::axis::config::AxisConfig;
use cnc_core::axis::AxisSet;
use core::mem::offset_of;
use hli::calls::axis::AxisCommandCall;
use hli::layout::{
    HliAxis, HliAxisCommandState, HliAxisLrState, NcDriveIn, NcDriveOut, NcEncoderIn, NcEncoderOut,
};
use hli::views::CncView;
use hli::PlaceExt;
use std::hint::black_box;
use std::time::Instant;

const AXES: usize = 32;
const TICKS: usize = 20_000;
const REPEATS: usize = 9;

fn image_only(view: &CncView<'_>) {
    for i in 0..AXES {
        let place = view.axis(i).unwrap();
        let e: NcEncoderIn = place
            .field::<NcEncoderIn>(offset_of!(HliAxis, enc_in))
            .read();
        let d: NcDriveIn = place
            .field::<NcDriveIn>(offset_of!(HliAxis, drive_in))
            .read();
        black_box((&e, &d));
        place
            .field::<HliAxisLrState>(offset_of!(HliAxis, lr_state))
            .write(&bytemuck::Zeroable::zeroed());
        place
            .field::<NcDriveOut>(offset_of!(HliAxis, drive_out))
            .write(&bytemuck::Zeroable::zeroed());
        place
            .field::<NcEncoderOut>(offset_of!(HliAxis, enc_out))
            .write(&bytemuck::Zeroable::zeroed());
        place
            .field::<HliAxisCommandState>(offset_of!(HliAxis, command_state))
            .write(&bytemuck::Zeroable::zeroed());
        place
            .field::<NcDriveIn>(offset_of!(HliAxis, drive_in))
            .write(&d);
        place
            .field::<NcEncoderIn>(offset_of!(HliAxis, enc_in))
            .write(&e);
    }
}

/// ns per axis-tick of `work` over TICKS ticks, median of REPEATS.
fn time(mut work: impl FnMut(usize)) -> f64 {
    let mut runs = Vec::new();
    for _ in 0..scaled(REPEATS) {
        let t0 = Instant::now();
        for tick in 0..scaled(TICKS) {
            work(tick);
        }
        runs.push(t0.elapsed().as_nanos() as f64 / (scaled(TICKS) * AXES) as f64);
    }
    median(runs)
}

fn rig() -> (hli::raw::ImageMemory, AxisSet) {
    let memory = hli::image::heap_image(1, AXES as u32);
    let configs = (0..AXES)
        .map(|i| AxisConfig::linear(&format!("A{i}"), i as u32 + 1))
        .collect();
    let mut set = AxisSet::new(configs, 0.001).unwrap();
    set.prime(&CncView::new(&memory));
    set.tick(&CncView::new(&memory));
    for i in 0..AXES {
        set.axis_mut(i)
            .unwrap()
            .command(&AxisCommandCall::power(true))
            .unwrap();
    }
    (memory, set)
}

fn main() {
    let limits = [300.0, 3000.0, 3000.0, 60_000.0];
    let (memory, _) = rig();
    let floor = time(|_| image_only(&CncView::new(&memory)));

    let (memory, mut set) = rig();
    let holding = time(|_| set.tick(&CncView::new(&memory)));

    // Every axis moving: endless velocity moves, so the generator samples a live profile.
    let (memory, mut set) = rig();
    for i in 0..AXES {
        let dir = if i % 2 == 0 { 1 } else { -1 };
        set.axis_mut(i)
            .unwrap()
            .command(&AxisCommandCall::move_velocity(
                dir,
                [1.0, 100.0, 100.0, 1000.0],
            ))
            .unwrap();
    }
    let moving = time(|_| set.tick(&CncView::new(&memory)));

    // Worst case: every axis re-targeted every 10th tick (a new profile is computed).
    let (memory, mut set) = rig();
    let retarget = time(|tick| {
        if tick % 10 == 0 {
            for i in 0..AXES {
                let target = ((tick / 10 + i) % 7) as f64 * 10.0 - 30.0;
                let _ = set
                    .axis_mut(i)
                    .unwrap()
                    .command(&AxisCommandCall::move_absolute(target, limits));
            }
        }
        set.tick(&CncView::new(&memory));
    });

    println!("{AXES} axes, {TICKS} ticks per run, median of {REPEATS} runs; ns per axis-tick");
    println!("| case | ns/axis-tick | ratio to image floor |\n|---|---:|---:|");
    for (name, ns) in [
        ("image traffic only (floor)", floor),
        ("holding position", holding),
        ("all moving (velocity moves)", moving),
        ("re-target every 10th tick", retarget),
    ] {
        println!("| {name} | {ns:.1} | {:.2} |", ns / floor);
    }
    let worst = holding.max(moving).max(retarget);
    println!(
        "TARGET | <= 500 ns per axis-tick, worst case | {worst:.1} ns | {}",
        if worst <= 500.0 { "met" } else { "MISSED" }
    );
}
