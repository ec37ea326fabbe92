//! Continuous path against exact stop, against a lower bound and against LinuxCNC's planner,
//! on the same programs and limits in the same run.
//!
//! 0. **CAM-like programs** (issue 54's): a 300-gon of radius 50 mm (1.05 mm chords) and a
//!    zigzag of 60 blocks of 2.83 mm turning by 90 degrees, limits 200 mm/s, 2000 mm/s²,
//!    40000 mm/s³ (and the jerk at 1e8: acceleration-limited, like LinuxCNC 2.9's planner),
//!    F6000, `PATH_DEV=0.02`, each at exact stop and in continuous path. Targets: the 300-gon
//!    within 1.3× length/feed, the zigzag no slower than exact stop, and with the jerk off
//!    both no slower than LinuxCNC (`G64 P0.02`, the same limits; run headless by
//!    `linuxcnc/peer.rs`, skipped and said so when LinuxCNC or root is missing).
//!    **Arcs** ([`arcs`]): a slot of lines and half circles (tangent transitions) and a
//!    pocket outline with radius-5 fillets, the same way; targets on the slot: at the feed
//!    through every transition, no slower than exact stop, with the jerk off no slower than
//!    LinuxCNC.
//! 1. **Polyline**: 1,000 blocks of 1 mm turning by ±10 degrees (a zigzag), F6000, the
//!    channel's default limits (1000 mm/s, 5000 mm/s², 50000 mm/s³), `PATH_DEV=0.05`. Cycle
//!    time with exact stop (every block ends at rest) and with continuous path (G261); the
//!    largest distance of any tick's set-point from the programmed polyline; and the lower
//!    bound: the time-optimal jerk-limited move over the straight distance from start to end
//!    at the feed, with the limits of the best direction (√3 × an axis's acceleration and
//!    jerk). The bound ignores the corners, and here that is nearly fair: the zigzag's points
//!    lie within 0.044 mm of one straight line, so a path within the tolerance could be all
//!    but straight (corner curves cannot find it: they round each corner on its own).
//!    Targets: continuous ≥ 3× faster than exact stop, ≤ 1.3× the bound.
//! 2. **Robot contour** of application example 4 (the square over the turntable, without the
//!    table's motion) on the IRB 2400 under `#TRAFO`, the same way.
//! 3. **Tick cost** on the polyline, continuous against exact stop: ns per tick over the whole
//!    run (median over interleaved repeats), and CPU for the whole program. A continuous tick
//!    runs through 3× the blocks, so per tick it costs more and per program less; the target
//!    on the look-ahead's tick cost (≤ 1.2× per channel-tick on the same moves) is measured
//!    by the channels bench, whose robots go round a triangle in both modes.
//!
//! Cycle times are counted in ticks of the 1 ms cycle (the trace is deterministic); only
//! the tick cost is timed. Run: `cargo bench -p cnc-core --bench contour`.

#[path = "contour/arcs.rs"]
mod arcs;
#[path = "linuxcnc/peer.rs"]
mod peer;

use bench_kit::{median, smoke};
use cnc_core::channel::{Channel, ChannelConfig, Controller, LoadedProgram, RunState};
use cnc_core::nc::interp::SearchPath;
use cnc_core::setpoint::AxisValues;
use hli::image::heap_image;
use hli::views::CncView;
use std::time::Instant;

const CYCLE: f64 = 0.001;
const REPEATS: usize = 7;

/// The zigzag's points and its blocks.
fn zigzag(n: usize) -> (Vec<[f64; 3]>, String) {
    let mut points = vec![[0.0; 3]];
    let mut text = String::new();
    for k in 0..n {
        let phi = if k % 2 == 0 {
            0.0f64
        } else {
            10f64.to_radians()
        };
        let [x, y, _] = points[k];
        let (px, py) = (
            format!("{:.6}", x + phi.cos()),
            format!("{:.6}", y + phi.sin()),
        );
        text.push_str(&format!("X{px} Y{py}\n"));
        points.push([px.parse().unwrap(), py.parse().unwrap(), 0.0]);
    }
    (points, text)
}

fn controller(config: &ChannelConfig, src: &str) -> Controller {
    let program = LoadedProgram::load_with(
        "bench.nc",
        src,
        &config.axes,
        &config.nc.setup(),
        None,
        &SearchPath::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let mut channel = Channel::new(0, config.clone(), CYCLE).unwrap();
    channel.start(program).unwrap();
    Controller::new(vec![channel]).unwrap()
}

/// Runs `src` to its end: the programmed positions of every tick.
fn run(config: &ChannelConfig, src: &str) -> Vec<AxisValues> {
    let mut ctl = controller(config, src);
    let memory = heap_image(1, 8);
    let view = CncView::new(&memory);
    let mut trace = Vec::new();
    for _ in 0..2_000_000 {
        ctl.tick(&view);
        let c = &ctl.channels()[0];
        assert_ne!(c.state(), RunState::Error, "{:?}", c.error());
        trace.push(*c.programmed());
        if c.state() == RunState::Finished {
            return trace;
        }
    }
    panic!("did not finish");
}

/// ns per tick of a whole run of `src`.
fn tick_cost(config: &ChannelConfig, src: &str) -> f64 {
    let mut ctl = controller(config, src);
    let memory = heap_image(1, 8);
    let view = CncView::new(&memory);
    let t0 = Instant::now();
    let mut ticks = 0;
    while ctl.channels()[0].state() != RunState::Finished {
        ctl.tick(&view);
        ticks += 1;
    }
    t0.elapsed().as_nanos() as f64 / ticks as f64
}

fn distance_to_polyline(p: &[f64], points: &[[f64; 3]], near: &mut usize) -> f64 {
    let seg = |k: usize| {
        let (a, b) = (points[k], points[k + 1]);
        let ab: Vec<f64> = (0..3).map(|i| b[i] - a[i]).collect();
        let ap: Vec<f64> = (0..3).map(|i| p[i] - a[i]).collect();
        let len2: f64 = ab.iter().map(|v| v * v).sum();
        let t = (ap.iter().zip(&ab).map(|(x, y)| x * y).sum::<f64>() / len2).clamp(0.0, 1.0);
        (0..3)
            .map(|i| (ap[i] - t * ab[i]).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let lo = near.saturating_sub(2);
    let hi = (*near + 4).min(points.len() - 1);
    let (k, d) = (lo..hi)
        .map(|k| (k, seg(k)))
        .fold((*near, f64::INFINITY), |m, x| if x.1 < m.1 { x } else { m });
    *near = k;
    d
}

/// The time-optimal rest-to-rest jerk-limited move over `length` within `v`, `a`, `j`.
fn lower_bound(length: f64, v: f64, a: f64, j: f64) -> f64 {
    // Velocity change 0 -> w takes w/a + a/j (or 2 sqrt(w/j)) and covers w T / 2.
    let change = |w: f64| {
        if w * j >= a * a {
            w / a + a / j
        } else {
            2.0 * (w / j).sqrt()
        }
    };
    let fits = |w: f64| w * change(w) <= length;
    let peak = if fits(v) {
        v
    } else {
        let (mut lo, mut hi) = (0.0, v);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if fits(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    };
    2.0 * change(peak) + (length - peak * change(peak)) / peak
}

fn report(what: &str, exact: usize, cont: usize, bound: f64) {
    let (te, tc) = (exact as f64 * CYCLE, cont as f64 * CYCLE);
    println!("{what}");
    println!("  exact stop:      {te:9.3} s");
    println!("  continuous path: {tc:9.3} s   ({:.2}x faster)", te / tc);
    println!(
        "  lower bound:     {bound:9.3} s   (continuous / bound {:.2})",
        tc / bound
    );
}

fn polyline() {
    let n = if smoke() { 40 } else { 1000 };
    let (points, blocks) = zigzag(n);
    let config = ChannelConfig::new("c", &["X", "Y", "Z", "A", "B", "C"]);
    let exact = run(&config, &format!("G1 F6000\n{blocks}M30\n"));
    let cont = run(
        &config,
        &format!("#CONTOUR MODE [DEV PATH_DEV=0.05]\nG261 G1 F6000\n{blocks}M30\n"),
    );
    let mut near = 0;
    let deviation = cont
        .iter()
        .map(|p| distance_to_polyline(p, &points, &mut near))
        .fold(0.0, f64::max);
    let l = config.limits;
    let straight = points[n][0].hypot(points[n][1]);
    let root3 = 3f64.sqrt();
    let bound = lower_bound(straight, 100.0, root3 * l.acceleration, root3 * l.jerk);
    report(
        &format!("polyline, {n} blocks of 1 mm, +-10 degrees, F6000, PATH_DEV 0.05 mm"),
        exact.len(),
        cont.len(),
        bound,
    );
    println!("  largest deviation on any tick: {deviation:.5} mm (tolerance 0.05 mm)");
    let ratio = exact.len() as f64 / cont.len() as f64;
    println!(
        "TARGET | continuous path >= 3x faster than exact stop (polyline) | {ratio:.2}x (lower bound ratio {:.2}) | {}",
        cont.len() as f64 * CYCLE / bound,
        if ratio >= 3.0 { "met" } else { "MISSED" }
    );
    let to_bound = cont.len() as f64 * CYCLE / bound;
    println!(
        "TARGET | continuous path <= 1.3x the lower bound (polyline) | {to_bound:.2}x | {}",
        met(to_bound <= 1.3)
    );
    println!(
        "TARGET | corner deviation <= tolerance on every tick | {deviation:.5} mm of 0.05 mm | {}",
        if deviation <= 0.05 + 1e-9 {
            "met"
        } else {
            "MISSED"
        }
    );
    let mut costs = (Vec::new(), Vec::new());
    let exact_src = format!("G1 F6000\n{blocks}M30\n");
    let cont_src = format!("#CONTOUR MODE [DEV PATH_DEV=0.05]\nG261 G1 F6000\n{blocks}M30\n");
    for _ in 0..if smoke() { 1 } else { REPEATS } {
        costs.0.push(tick_cost(&config, &exact_src));
        costs.1.push(tick_cost(&config, &cont_src));
    }
    let (e, c) = (median(costs.0), median(costs.1));
    let (te, tc) = (exact.len() as f64, cont.len() as f64);
    println!("channel tick on the polyline (median of {REPEATS} interleaved runs)");
    println!(
        "  exact stop:      {e:8.0} ns/tick, {:8.0} us for the program",
        e * te / 1000.0
    );
    println!(
        "  continuous path: {c:8.0} ns/tick, {:8.0} us for the program",
        c * tc / 1000.0
    );
    println!(
        "  per tick {:.2}x: a continuous tick goes through {:.1}x the blocks an exact-stop tick \
         does (decoding, corner curves, the backward sweep); for the whole program {:.2}x",
        c / e,
        te / tc,
        c * tc / (e * te)
    );
    println!("  (the target on the look-ahead's tick cost is the channels bench's: same moves, both modes)");
}

fn robot() {
    let square = "X-60\nX60\nX0\nY-60\nY60\nY0\n";
    let head = "#TRAFO [45]\nG1 X1305.92 Y0 Z130 F6000\nG92 X1305.92\nZ90\nX0 Y0\nZ80\n";
    let mut config = ChannelConfig::new("robot", &["X", "Y", "Z", "A", "B", "C"]);
    config.kinematics.id = 45;
    config.kinematics.preset = Some("irb2400".into());
    config.start = vec![0.0, 40.0, 0.0, 0.0, 50.0, 0.0];
    let exact = run(&config, &format!("{head}{square}Z90\nM30\n"));
    let cont = run(
        &config,
        &format!("{head}#CONTOUR MODE [DEV PATH_DEV=1]\nG261\n{square}G260 Z90\nM30\n"),
    );
    // The square alone: 6 blocks, 420 mm of path.
    let l = config.limits;
    let root3 = 3f64.sqrt();
    let bound = lower_bound(420.0, 100.0, root3 * l.acceleration, root3 * l.jerk);
    report(
        "robot contour of example 4 (IRB 2400, #TRAFO), whole program, F6000, PATH_DEV 1 mm",
        exact.len(),
        cont.len(),
        bound,
    );
    println!("  (the bound covers the square's 420 mm only: a floor for the whole program)");
}

/// The limits: 200 mm/s, 2000 mm/s², 40000 mm/s³ (`jerk` to switch it off).
fn cam_config(jerk: f64, start: [f64; 2]) -> ChannelConfig {
    let mut config = ChannelConfig::new("c", &["X", "Y", "Z", "A", "B", "C"]);
    config.limits.velocity = 200.0;
    config.limits.acceleration = 2000.0;
    config.limits.jerk = jerk;
    config.start = vec![start[0], start[1], 0.0, 0.0, 0.0, 0.0];
    config
}

/// Blocks through `points` (from the second on).
fn blocks_through(points: &[[f64; 3]]) -> String {
    points[1..]
        .iter()
        .map(|p| format!("X{:.6} Y{:.6}\n", p[0], p[1]))
        .collect()
}

/// One CAM-like program at exact stop and continuous path, with the jerk on and off.
fn cam_program(what: &str, points: &[[f64; 3]]) -> [(f64, f64); 2] {
    let blocks = blocks_through(points);
    let length: f64 = points
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum();
    println!(
        "{what}: {} blocks, {length:.1} mm, F6000, PATH_DEV 0.02 mm",
        points.len() - 1
    );
    let mut out = [(0.0, 0.0); 2];
    for (k, jerk) in [40_000.0, 1e8].into_iter().enumerate() {
        let config = cam_config(jerk, [points[0][0], points[0][1]]);
        let exact = run(&config, &format!("G1 F6000\n{blocks}M30\n"));
        let cont = run(
            &config,
            &format!("#CONTOUR MODE [DEV PATH_DEV=0.02]\nG261 G1 F6000\n{blocks}M30\n"),
        );
        let mut near = 0;
        let deviation = cont
            .iter()
            .map(|p| distance_to_polyline(p, points, &mut near))
            .fold(0.0, f64::max);
        let (te, tc) = (exact.len() as f64 * CYCLE, cont.len() as f64 * CYCLE);
        println!(
            "  jerk {jerk:>9}: exact stop {te:7.3} s, continuous {tc:7.3} s = {:.2}x length/feed, \
             {:.2}x exact stop; deviation {deviation:.4} mm",
            tc / (length / 100.0),
            tc / te
        );
        out[k] = (te, tc);
    }
    out
}

fn cam_like() {
    let n = if smoke() { 30 } else { 300 };
    let gon: Vec<[f64; 3]> = (0..=n)
        .map(|k| {
            let phi = std::f64::consts::TAU * k as f64 / n as f64;
            [50.0 * phi.cos(), 50.0 * phi.sin(), 0.0]
        })
        .collect();
    let zig: Vec<[f64; 3]> = (0..=60)
        .map(|k| [2.0 * k as f64, if k % 2 == 0 { 0.0 } else { 2.0 }, 0.0])
        .collect();
    let gon_name = format!("{n}-gon of radius 50 mm");
    let ours = [
        cam_program(&gon_name, &gon),
        cam_program("zigzag of 90-degree turns", &zig),
    ];
    let length = |p: &[[f64; 3]]| -> f64 {
        p.windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum()
    };
    let gon_ratio = ours[0][0].1 / (length(&gon) / 100.0);
    let zig_ratio = ours[1][0].1 / ours[1][0].0;
    println!(
        "TARGET | {n}-gon r = 50 mm, j = 40000: continuous <= 1.3x length/feed | {gon_ratio:.2}x | {}",
        met(gon_ratio <= 1.3)
    );
    println!(
        "TARGET | 90-degree zigzag, j = 40000: continuous <= 1.0x exact stop | {zig_ratio:.3}x | {}",
        met(zig_ratio <= 1.0)
    );
    let body = |p: &[[f64; 3]]| (p[0][0], p[0][1], blocks_through(p));
    let programs: Vec<(&str, [f64; 2], String)> = [("gon", &gon[..]), ("zigzag", &zig[..])]
        .into_iter()
        .map(|(name, p)| {
            let (x, y, b) = body(p);
            (name, [x, y], b)
        })
        .collect();
    compare_with_peer(&programs, &[ours[0][1].1, ours[1][1].1], &["gon", "zigzag"]);
}

fn met(ok: bool) -> &'static str {
    if ok {
        "met"
    } else {
        "MISSED"
    }
}

/// The same programs on LinuxCNC's planner (no jerk limit), against ours with the jerk set
/// very high (`ours`, seconds): medians of 3 interleaved runs each. `programs`: name, start
/// point, blocks; a target line for those named in `targets`.
fn compare_with_peer(programs: &[(&str, [f64; 2], String)], ours: &[f64], targets: &[&str]) {
    if smoke() {
        println!("LinuxCNC peer: not run in the smoke run");
        return;
    }
    if let Some(why) = peer::unavailable() {
        println!("LinuxCNC peer: skipped, {why}");
        return;
    }
    match peer::run(programs, 0.02, 6000.0, 3) {
        Ok(times) => {
            println!("LinuxCNC 2.9 (G64 P0.02, the same velocity and acceleration limits, no jerk limit), median of 3 interleaved runs");
            for (k, (name, _, _)) in programs.iter().enumerate() {
                let us = ours[k];
                let ratio = us / times[k];
                println!(
                    "  {name}: LinuxCNC {:.3} s, ours (jerk 1e8) {us:.3} s = {ratio:.3}x",
                    times[k]
                );
                if targets.contains(name) {
                    println!(
                        "TARGET | {name} with the jerk off <= 1.0x LinuxCNC's time | {ratio:.3}x ({us:.3} / {:.3} s) | {}",
                        times[k],
                        met(ratio <= 1.0)
                    );
                }
            }
        }
        Err(e) => println!("LinuxCNC peer: failed, {e}"),
    }
}

fn main() {
    cam_like();
    arcs::arcs();
    polyline();
    robot();
}
