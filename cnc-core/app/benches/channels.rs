//! Tick cost of the CNC with 1, 4 and 12 six-axis robots (kinematic 45), tracking active on
//! every channel (robot 1 follows the PLC's dynamic CS, the others follow robot 1), each
//! running an endless loop of moves: interpreter, interpolation, inverse and forward
//! transformation, dynamic CS, HLI outputs and axis images.
//!
//! Reported: median over interleaved repeats of the time per tick and per channel-tick, and the ratio of
//! the per-channel-tick cost to the 1-channel run of the same process (linearity). Baseline in
//! the same run: the same channels ticking without any program and without tracking (the
//! fixed cost of outputs and bookkeeping), so the ratio says what the motion work adds.
//! Target: <= 5 us per channel-tick, linear in channels.
//!
//! Also in the same run: the whole machine tick with the robots' axes on simulated PT2 drives,
//! and the path before the machine tick (channels plus set-points written straight into the
//! axis images, no axis layer) as the baseline the machine tick is compared with.
//! Axis images hold 32 axes: the first five robots' axes are on the axis layer, the others
//! have none (as before).
//!
//! Last, the scenarios of examples 3 and 4 (both part of the demo's machine) in-process and
//! hot (no sleep between ticks): the p50 of the machine tick over the whole run, timed per
//! tick as `cnc run` times it, so the `machine` p50 that `cnc run` reports for them (after a
//! 1 ms sleep each tick) compares with it like for like.
//! And the demo's whole machine with its PLC program run in this process between the ticks
//! (the in-process twin of `cnc demo`), its machine tick timed the same way.
//! Run: `cargo bench -p cnc-app --bench channels`.

use bench_kit::{median, scaled};
use cnc_app::scenario::fleet::{
    plc_setup, running, running_on, running_with, tracking_robots, Moves,
};
use cnc_app::scenario::{InProcess, Scenario};
use cnc_core::channel::{Channel, Controller};
use cnc_core::setpoint::AxisValues;
use hli::enums::CouplingState;
use hli::layout::{HliAxis, HliAxisLrState};
use hli::views::CncView;
use hli::views::PlcView;
use hli::PlaceExt;
use std::time::Instant;

const TICKS: usize = 5_000;
const REPEATS: usize = 9;
const WARM_UP: usize = 3_000;

/// One sample: ns per tick over TICKS ticks.
fn sample(tick: &mut dyn FnMut()) -> f64 {
    let t0 = Instant::now();
    for _ in 0..scaled(TICKS) {
        tick();
    }
    t0.elapsed().as_nanos() as f64 / scaled(TICKS) as f64
}

/// Median ns per tick of each contender, the repeats interleaved (contender 1, 2, .., 1, 2,
/// ..) so a slow phase of the machine hits all of them alike.
fn interleaved(contenders: &mut [Box<dyn FnMut() + '_>]) -> Vec<f64> {
    let mut samples = vec![Vec::with_capacity(scaled(REPEATS)); contenders.len()];
    for _ in 0..scaled(REPEATS) {
        for (c, tick) in contenders.iter_mut().enumerate() {
            samples[c].push(sample(tick.as_mut()));
        }
    }
    samples.into_iter().map(median).collect()
}

/// The fleet going round a triangle, at exact stop or in continuous path.
fn tracking_moves(n: usize, moves: Moves) -> Box<dyn FnMut()> {
    let mut run = running_with(n, None, moves, WARM_UP).expect("fleet running");
    Box::new(move || run.machine.tick(&run.memory))
}

fn tracking(n: usize) -> Box<dyn FnMut()> {
    let mut run = running(n, WARM_UP).expect("fleet running");
    Box::new(move || run.machine.tick(&run.memory))
}

fn tracking_pt2(n: usize) -> Box<dyn FnMut()> {
    let drive = "{ model = \"pt2\", frequency_hz = 80.0, damping = 0.9 }";
    let mut run = running_on(n, Some(drive), WARM_UP).expect("fleet running on PT2 drives");
    Box::new(move || run.machine.tick(&run.memory))
}

/// The way channel axes reached the axis images before the machine tick, kept here as this
/// benchmark's baseline: each channel axis's `gpAx[k]^lr_state` written straight from the
/// channel's set-point, no axis layer, no drive (the library's only writer of gpAx is the
/// axis layer).
struct AxisPublisher {
    first: usize,
    last: AxisValues,
    last_velocity: AxisValues,
    cycle_s: f64,
}

impl AxisPublisher {
    /// Axes `first..first + start.len()` of the image, standing at `start`, ticking every
    /// `cycle_s`.
    fn new(first: usize, start: &AxisValues, cycle_s: f64) -> Self {
        Self {
            first,
            last: *start,
            last_velocity: AxisValues::zeros(start.len()),
            cycle_s,
        }
    }

    /// Writes `set_points` (channel order) into the axis images. Does not allocate.
    fn publish(&mut self, view: &CncView<'_>, set_points: &AxisValues) {
        for (i, &p) in set_points.iter().enumerate() {
            let Ok(axis) = view.axis(self.first + i) else {
                break;
            };
            let v = (p - self.last[i]) / self.cycle_s;
            let a = (v - self.last_velocity[i]) / self.cycle_s;
            let state = cnc_core::axis::motion_phase(v, a);
            // Linear units (0.1 um) and angle units (0.0001 degree) scale alike.
            let raw = |x: f64| {
                hli::units::mm_to_hli(x).unwrap_or(if x < 0.0 { i32::MIN } else { i32::MAX })
            };
            let position = raw(p);
            axis.field::<HliAxisLrState>(core::mem::offset_of!(HliAxis, lr_state))
                .write(&HliAxisLrState {
                    current_position_acs_r: position,
                    command_position_acs_r: position,
                    current_velocity_r: raw(v),
                    command_velocity_r: raw(v),
                    command_acceleration_r: raw(a),
                    following_error_r: 0,
                    axis_state_r: state.raw(),
                    coupling_state_r: CouplingState::Channel.raw(),
                    master_axis_r: -1,
                    error_id_r: 0,
                    status_r: 0,
                    nc_axis_id_r: i as u32 + 1,
                });
            self.last[i] = p;
            self.last_velocity[i] = v;
        }
    }
}

/// The path before the machine tick: channels, then each channel's set-points written into
/// its axis images (while they last), the CNC heartbeat not counted.
fn before_machine(n: usize) -> Box<dyn FnMut()> {
    let s = tracking_robots(n).expect("fleet scenario");
    let mut channels: Vec<Channel> = Vec::new();
    for (i, (c, p)) in s.channels.iter().zip(&s.programs).enumerate() {
        let mut ch = Channel::new(i, c.clone(), s.cycle_s).expect("channel");
        ch.start(p.clone().expect("a program"))
            .expect("a fresh channel starts");
        channels.push(ch);
    }
    let mut publishers: Vec<Option<AxisPublisher>> = Vec::new();
    let mut first = 0;
    for c in &channels {
        let fits = first + 6 <= 32;
        publishers.push(fits.then(|| AxisPublisher::new(first, c.set_points(), s.cycle_s)));
        if fits {
            first += 6;
        }
    }
    let mut controller = Controller::new(channels).expect("controller");
    let memory = hli::image::heap_image(n as u32, 32);
    plc_setup(&PlcView::new(&memory));
    let mut tick = move || {
        let view = CncView::new(&memory);
        controller.tick(&view);
        for (c, p) in controller.channels().iter().zip(publishers.iter_mut()) {
            if let Some(p) = p {
                p.publish(&view, c.set_points());
            }
        }
    };
    for _ in 0..WARM_UP {
        tick();
    }
    Box::new(tick)
}

fn idle(n: usize) -> Box<dyn FnMut()> {
    let s = tracking_robots(n).expect("fleet scenario");
    let channels = s
        .channels
        .iter()
        .enumerate()
        .map(|(i, c)| Channel::new(i, c.clone(), s.cycle_s).expect("channel"))
        .collect();
    let mut controller = Controller::new(channels).expect("controller");
    let memory = hli::image::heap_image(n as u32, 32);
    Box::new(move || controller.tick(&CncView::new(&memory)))
}

fn main() {
    // `-- profile N`: only the machine tick of N robots, for a profiler.
    let args: Vec<String> = std::env::args().collect();
    if let Some(at) = args.iter().position(|a| a == "profile") {
        let n = args.get(at + 1).and_then(|a| a.parse().ok()).unwrap_or(1);
        let mut tick = tracking(n);
        for _ in 0..200_000 / n {
            tick();
        }
        return;
    }
    println!("channels | tracking: ns/tick | ns/channel-tick | vs 1 channel | idle baseline ns/channel-tick | tracking / idle | PT2 drives ns/channel-tick | before machine ns/channel-tick | machine / before");
    let mut one = None;
    let mut worst: f64 = 0.0;
    for n in [1usize, 4, 12] {
        let mut contenders = [tracking(n), idle(n), tracking_pt2(n), before_machine(n)];
        let [t, b, d, old] = interleaved(&mut contenders)[..] else {
            unreachable!("four contenders")
        };
        let per = t / n as f64;
        let base = *one.get_or_insert(per);
        worst = worst.max(per);
        println!(
            "{n:>8} | {t:>17.0} | {per:>15.0} | {:>12.2} | {:>29.0} | {:>15.1} | {:>26.0} | {:>31.0} | {:>16.2}",
            per / base,
            b / n as f64,
            t / b,
            d / n as f64,
            old / n as f64,
            t / old
        );
    }
    println!("(medians of {REPEATS} interleaved runs of {TICKS} ticks each)");
    println!(
        "TARGET | <= 5000 ns per tracking channel-tick, 1 to 12 channels | worst {worst:.0} ns | {}",
        if worst <= 5000.0 { "met" } else { "MISSED" }
    );
    contour_cost();
    println!();
    println!("example scenario (part of the demo machine), hot in-process | ticks | machine tick p50 ns | p99 ns");
    for name in ["example3-moving-workpiece", "example4-turntable-plc"] {
        let (ticks, p50, p99) = demo_hot(name);
        println!("{name:>29} | {ticks:>5} | {p50:>19} | {p99:>6}");
    }
    demo_gain();
    let (ticks, p50, p99) = demo_twin();
    println!(
        "{:>29} | {ticks:>5} | {p50:>19} | {p99:>6}",
        "demo machine + its PLC program"
    );
    println!("(per-tick times of one whole run each, after {REPEATS} warm-up runs; the demo's");
    println!(" twin runs its PLC program in this process between the ticks, untimed: compare");
    println!(" its p50 with the `machine` p50 of `cnc demo`'s report)");
}

/// The fleet going round a triangle in continuous path (look-ahead, corner curves, joint
/// caps under #TRAFO) against the same triangle at exact stop, interleaved: what continuous
/// path adds per channel-tick.
fn contour_cost() {
    println!();
    println!("channels | exact stop ns/channel-tick | continuous path ns/channel-tick | ratio");
    let mut worst: f64 = 0.0;
    for n in [1usize, 4, 12] {
        let mut contenders = [
            tracking_moves(n, Moves::Triangle),
            tracking_moves(n, Moves::TriangleContour),
        ];
        let [e, c] = interleaved(&mut contenders)[..] else {
            unreachable!("two contenders")
        };
        worst = worst.max(c / e);
        println!(
            "{n:>8} | {:>26.0} | {:>31.0} | {:>5.2}",
            e / n as f64,
            c / n as f64,
            c / e
        );
    }
    println!(
        "TARGET | continuous path per channel-tick <= 1.2x exact stop's (channels bench fleet) | worst {worst:.2}x | {}",
        if worst <= 1.2 { "met" } else { "MISSED" }
    );
}

/// The tick at which each robot's program ended in the demo's twin (with its PLC program).
fn robots_end(scenario: &cnc_app::scenario::Scenario) -> Vec<(String, Option<usize>)> {
    let ticks = scenario.ticks.unwrap_or(14_500) as usize;
    let mut run = InProcess::new(scenario, 0).expect("in-process demo");
    let n = run.machine.controller().channels().len();
    let mut ended = vec![None; n];
    for tick in 0..ticks {
        run.machine.tick(&run.memory);
        run.answer_calls();
        run.run_program();
        run.machine.serve_channels();
        for (i, c) in run.machine.controller().channels().iter().enumerate() {
            if ended[i].is_none() && c.state() == cnc_core::channel::RunState::Finished {
                ended[i] = Some(tick + 1);
            }
        }
    }
    let names = run.machine.controller().channels().iter();
    names.map(|c| c.config().name.clone()).zip(ended).collect()
}

/// The demo's robot programs in continuous path against the manual's own (exact stop), the
/// same machine and PLC program: when each program ends.
fn demo_gain() {
    let cont = robots_end(&cnc_app::demo::scenario().expect("the demo"));
    let exact = robots_end(&cnc_app::demo::scenario_exact_stop().expect("the demo"));
    println!("demo robot program | exact stop ends at tick | continuous path ends at tick | saved");
    for ((name, c), (_, e)) in cont.iter().zip(&exact) {
        let show = |t: &Option<usize>| t.map_or("-".to_string(), |t| t.to_string());
        let saved = match (c, e) {
            (Some(c), Some(e)) => format!("{} ms", *e as i64 - *c as i64),
            _ => "-".into(),
        };
        println!("{name:>18} | {:>23} | {:>28} | {saved}", show(e), show(c));
    }
    println!();
}

/// The demo's whole machine with its PLC program (`demo-machine`) in this process, every
/// machine tick timed: (ticks, p50 ns, p99 ns) of the last of 3 runs.
fn demo_twin() -> (usize, u64, u64) {
    let scenario = cnc_app::demo::scenario().expect("the demo scenario");
    let ticks = scenario.ticks.unwrap_or(14_500) as usize;
    let mut times = Vec::with_capacity(ticks);
    for _ in 0..scaled(3) {
        times.clear();
        let mut run = InProcess::new(&scenario, 0).expect("in-process demo");
        for _ in 0..ticks {
            let t0 = Instant::now();
            run.machine.tick(&run.memory);
            times.push(t0.elapsed().as_nanos() as u64);
            run.answer_calls();
            run.run_program();
            run.machine.serve_channels();
        }
    }
    times.sort_unstable();
    let at = |q: f64| times[((times.len() - 1) as f64 * q) as usize];
    (times.len(), at(0.5), at(0.99))
}

/// One example scenario in-process, every tick timed: (ticks, p50 ns, p99 ns) of the
/// last of REPEATS runs (the earlier ones warm the caches and the allocator up).
fn demo_hot(name: &str) -> (usize, u64, u64) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios")
        .join(name)
        .join("scenario.toml");
    let scenario = Scenario::load(&path).expect("example scenario");
    let mut times = Vec::with_capacity(20_000);
    for _ in 0..scaled(REPEATS) {
        times.clear();
        let mut run = InProcess::new(&scenario, 0).expect("in-process run");
        while times.len() < 100_000 && (times.len() < 10 || !run.machine.idle()) {
            let t0 = Instant::now();
            run.machine.tick(&run.memory);
            times.push(t0.elapsed().as_nanos() as u64);
            if let Some(t) = run.timeline.as_mut() {
                t.cycle(&run.memory);
            }
        }
    }
    times.sort_unstable();
    let at = |q: f64| times[((times.len() - 1) as f64 * q) as usize];
    (times.len(), at(0.5), at(0.99))
}
