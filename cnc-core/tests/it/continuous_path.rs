//! Continuous path on a channel (G261/G61 with `#CONTOUR MODE [DEV PATH_DEV=..]`): every tick
//! within the corner deviation of the programmed path and within the channel's velocity,
//! acceleration and jerk; exact stop where the program asks for one or an M function waits;
//! feed hold on the path; bad tolerances and look-ahead depths refused.

use tests::channel_rig as support;

use cnc_core::channel::{ChannelConfig, Controller, LoadedProgram, RunState};
use cnc_core::setpoint::AxisValues;
use hli::views::{PathOverride, PlcView};
use hli::ImageMemory;
use support::*;

use crate::counting_alloc;

/// A zigzag of `n` blocks of `len` mm turning by ±`turn` degrees, as points and as G1 blocks.
fn zigzag(n: usize, len: f64, turn: f64) -> (Vec<[f64; 2]>, String) {
    let mut points = vec![[0.0, 0.0]];
    let mut text = String::new();
    for k in 0..n {
        let phi = if k % 2 == 0 {
            0.0f64
        } else {
            turn.to_radians()
        };
        let [x, y] = points[k];
        let (px, py) = (
            format!("{:.6}", x + len * phi.cos()),
            format!("{:.6}", y + len * phi.sin()),
        );
        text.push_str(&format!("X{px} Y{py}\n"));
        points.push([px.parse().unwrap(), py.parse().unwrap()]);
    }
    (points, text)
}

/// Positions of X and Y each tick until the channel finished (or `each` decides).
fn run(
    program: &str,
    config: ChannelConfig,
    mut each: impl FnMut(&ImageMemory, u32),
) -> (Vec<AxisValues>, Controller) {
    let mut ctl = controller(vec![(config, program)]);
    let memory = image(1);
    let mut trace = vec![*ctl.channels()[0].programmed()];
    run_until(
        &mut ctl,
        &memory,
        400_000,
        |c, tick| {
            trace.push(*c.channels()[0].programmed());
            each(&memory, tick);
        },
        |c| c.channels()[0].state() == RunState::Finished,
    );
    (trace, ctl)
}

fn distance_to_path(p: &[f64], points: &[[f64; 2]], near: &mut usize) -> f64 {
    let seg = |k: usize| {
        let (a, b) = (points[k], points[k + 1]);
        let ab = [b[0] - a[0], b[1] - a[1]];
        let ap = [p[0] - a[0], p[1] - a[1]];
        let t = ((ap[0] * ab[0] + ap[1] * ab[1]) / (ab[0] * ab[0] + ab[1] * ab[1])).clamp(0.0, 1.0);
        ((ap[0] - t * ab[0]).powi(2) + (ap[1] - t * ab[1]).powi(2)).sqrt()
    };
    let lo = near.saturating_sub(2);
    let hi = (*near + 4).min(points.len() - 1);
    let (k, d) = (lo..hi)
        .map(|k| (k, seg(k)))
        .fold((*near, f64::INFINITY), |m, x| if x.1 < m.1 { x } else { m });
    *near = k;
    d + p[2].abs()
}

/// The largest distance from the path, and the largest |v|, |a|, |j| of any axis.
fn measure(trace: &[AxisValues], points: &[[f64; 2]]) -> (f64, [f64; 3]) {
    let mut near = 0;
    let worst = trace
        .iter()
        .map(|p| distance_to_path(p, points, &mut near))
        .fold(0.0, f64::max);
    let mut rates = [0.0f64; 3];
    for w in trace.windows(4) {
        let axes = w[0].iter().zip(&*w[1]).zip(&*w[2]).zip(&*w[3]).take(3);
        for (((&p0, &p1), &p2), &p3) in axes {
            rates[0] = rates[0].max(((p3 - p2) / CYCLE).abs());
            rates[1] = rates[1].max(((p3 - 2.0 * p2 + p1) / CYCLE.powi(2)).abs());
            rates[2] = rates[2].max(((p3 - 3.0 * p2 + 3.0 * p1 - p0) / CYCLE.powi(3)).abs());
        }
    }
    (worst, rates)
}

fn assert_within(config: &ChannelConfig, rates: [f64; 3]) {
    let l = config.limits;
    let slack = 1.0 + 1e-6;
    assert!(rates[0] <= l.velocity * slack, "velocity {}", rates[0]);
    assert!(
        rates[1] <= l.acceleration * slack,
        "acceleration {}",
        rates[1]
    );
    assert!(rates[2] <= l.jerk * slack, "jerk {}", rates[2]);
}

/// How many of the path's inner corners a tick stood on exactly.
fn corners_visited(trace: &[AxisValues], points: &[[f64; 2]]) -> usize {
    points[1..points.len() - 1]
        .iter()
        .filter(|c| trace.iter().any(|p| p[0] == c[0] && p[1] == c[1]))
        .count()
}

#[test]
fn a_zigzag_runs_through_its_corners_within_the_deviation_and_the_limits() {
    let (points, blocks) = zigzag(150, 1.0, 10.0);
    let program = format!("#CONTOUR MODE [DEV PATH_DEV=0.02]\nG261 G1 F6000\n{blocks}G260\nM30\n");
    let exact = format!("G1 F6000\n{blocks}M30\n");
    let config = cartesian("c");
    let (cont, _) = run(&program, config.clone(), |_, _| {});
    let (stop, _) = run(&exact, config.clone(), |_, _| {});
    let (dev, rates) = measure(&cont, &points);
    assert!(dev <= 0.02 + 1e-9, "deviation {dev}");
    assert!(dev > 0.005, "the corners are rounded: {dev}");
    assert_within(&config, rates);
    assert_within(&config, measure(&stop, &points).1);
    assert_eq!(corners_visited(&cont, &points), 0, "every corner rounded");
    assert_eq!(
        corners_visited(&stop, &points),
        149,
        "exact stop at every corner"
    );
    assert!(
        3 * cont.len() < stop.len(),
        "continuous {} ticks, exact stop {}",
        cont.len(),
        stop.len()
    );
    let end = cont.last().unwrap();
    assert_eq!([end[0], end[1]], points[150]);
}

/// G60 (this block), a block that does not move, and a dwell (as an M function, `#WAIT SYN` or any element that is no
/// straight block) stop the path exactly at their block's end; G61 blends
/// one corner without G261.
#[test]
fn exact_stop_where_the_program_asks_and_where_the_program_waits() {
    let program = "#CONTOUR MODE [DEV PATH_DEV=0.5]\nG1 F3000\nG261 X10\nX20 Y5\nG60 X30 Y0\nX40 Y5\nX40 Y5\nX50 Y0\nG04 0.05\nX60 Y5\nG260 G61 X70 Y0\nX80 Y5\nM30\n";
    let points = [
        [0.0, 0.0],
        [10.0, 0.0],
        [20.0, 5.0],
        [30.0, 0.0],
        [40.0, 5.0],
        [50.0, 0.0],
        [60.0, 5.0],
        [70.0, 0.0],
        [80.0, 5.0],
    ];
    let config = cartesian("c");
    let (trace, _) = run(program, config.clone(), |_, _| {});
    let (dev, rates) = measure(&trace, &points);
    assert!(dev <= 0.5 + 1e-9);
    assert_within(&config, rates);
    let stood_on = |c: [f64; 2]| trace.iter().any(|p| p[0] == c[0] && p[1] == c[1]);
    // Exactly at the G60 block's end, before the block that does not move (nothing to blend)
    // and at the dwell's block end; the corners of G261 and of G61 are rounded.
    for (k, exact) in [
        (1, false),
        (2, false),
        (3, true),
        (4, true),
        (5, true),
        (6, false),
        (7, false),
    ] {
        assert_eq!(stood_on(points[k]), exact, "corner {k}");
    }
}

/// Feed hold from the PLC's override unit brakes on the path within the limits; releasing it
/// lets the contour go on to its end.
#[test]
fn feed_hold_brakes_on_the_contour_and_goes_on() {
    let (points, blocks) = zigzag(60, 2.0, 30.0);
    let program = format!("#CONTOUR MODE [DEV PATH_DEV=0.05]\nG261 G1 F9000\n{blocks}M30\n");
    let config = cartesian("c");
    let hold = |memory: &ImageMemory, on: bool| {
        PlcView::new(memory)
            .set_path_override(
                0,
                PathOverride {
                    feed_permille: 1000,
                    rapid_permille: 1000,
                    feed_hold: on,
                },
            )
            .unwrap()
    };
    let (trace, _) = run(&program, config.clone(), |memory, tick| match tick {
        300 => hold(memory, true),
        900 => hold(memory, false),
        _ => {}
    });
    let (dev, rates) = measure(&trace, &points);
    assert!(dev <= 0.05 + 1e-9);
    assert_within(&config, rates);
    let still = trace.windows(2).filter(|w| w[0] == w[1]).count();
    assert!(still > 400, "stood still under feed hold: {still}");
    assert_eq!(
        [trace.last().unwrap()[0], trace.last().unwrap()[1]],
        points[60]
    );
}

#[test]
fn bad_tolerances_and_depths_are_refused() {
    let config = cartesian("c");
    for (src, col) in [
        ("G1 F100\n#CONTOUR MODE [DEV PATH_DEV=-0.1]\nX1\n", "2:"),
        ("G1 F100\n#CONTOUR MODE [DEV PATH_DEV=1/0]\nX1\n", "2:"),
        ("G1 F100\n#CONTOUR MODE [DIST PATH_DEV=1]\nX1\n", "2:"),
    ] {
        let e = LoadedProgram::load_with(
            "bad.nc",
            src,
            &config.axes,
            &config.nc.setup(),
            None,
            &cnc_core::nc::interp::SearchPath::default(),
        )
        .err()
        .unwrap_or_else(|| panic!("{src} accepted"))
        .to_string();
        assert!(e.contains(&format!("bad.nc:{col}")), "{e}");
    }
    for (depth, dev) in [(0, 0.1), (129, 0.1), (32, f64::NAN), (32, -1.0)] {
        let mut c = cartesian("c");
        c.interpolator.lookahead = depth;
        c.nc.path_dev = Some(dev);
        let e = cnc_core::channel::Channel::new(0, c, CYCLE).err().unwrap();
        let e = e.to_string();
        assert!(
            e.contains("interpolator.lookahead") || e.contains("nc.path_dev"),
            "{e}"
        );
    }
}

/// Under `#TRAFO` the contour slows down where the robot's joints would exceed their own
/// limits: every tick's joint steps stay within the joints' velocity and acceleration.
#[test]
fn under_trafo_the_joints_stay_within_their_limits() {
    let program = "#TRAFO [45]\nG1 X680 Y40 Z560 F3000\n#CONTOUR MODE [DEV PATH_DEV=1]\nG261 F30000\nX640 Y0 Z540\nX600 Y-40 Z520\nX640 Y-80 Z540\nX680 Y40 Z560\nG260 X680 Y40 Z550\n#TRAFO OFF\nM30\n";
    let joint = cnc_core::channel::path::AxisLimits {
        velocity: 20.0,
        acceleration: 200.0,
        jerk: 4000.0,
    };
    let mut config = robot("r");
    config.axis_limits = vec![joint; 6];
    let mut ctl = controller(vec![(config, program)]);
    let memory = image(1);
    let mut joints = Vec::new();
    let mut contour_ticks = 0;
    run_until(
        &mut ctl,
        &memory,
        200_000,
        |c, _| {
            let ch = &c.channels()[0];
            let on_contour = ch.line() >= 5 && ch.line() <= 9;
            joints.push((*ch.set_points(), on_contour));
            contour_ticks += usize::from(on_contour);
        },
        |c| c.channels()[0].state() == RunState::Finished,
    );
    assert!(contour_ticks > 100, "the contour ran: {contour_ticks}");
    let (mut v, mut a) = (0.0f64, 0.0f64);
    // The first block runs at exact stop in Cartesian limits only: the contour is measured.
    for w in joints.windows(3).filter(|w| w.iter().all(|(_, on)| *on)) {
        let w: Vec<_> = w.iter().map(|(q, _)| q).collect();
        for ((q0, q1), q2) in w[0].iter().zip(w[1].iter()).zip(w[2].iter()).take(6) {
            v = v.max(((q2 - q1) / CYCLE).abs());
            a = a.max(((q2 - 2.0 * q1 + q0) / CYCLE.powi(2)).abs());
        }
    }
    assert!(v <= joint.velocity * 1.001, "joint velocity {v}");
    assert!(a <= joint.acceleration * 1.05, "joint acceleration {a}");
}

/// A block that fails while decoded ahead (here on a value only the run knows: the tracked
/// frame's X, 1 mm, which the check takes as 0): the contour runs to the end of the blocks
/// before it and comes to rest there, then the channel fails with the block's line.
#[test]
fn an_error_found_ahead_takes_effect_at_rest() {
    let program = "#TRACK CS ON [ID=0 SET_ZERO WAIT]\n#CONTOUR MODE [DEV PATH_DEV=0.2]\nG261 G1 F6000\nX10\nX20 Y2\nX30 Y0\nX[10/[V.G.TRACK_CS.X - 1]] Y9\nM30\n";
    let config = cartesian("c");
    let mut ctl = controller(vec![(config.clone(), program)]);
    let memory = image(1);
    enable_plc_master(&memory, [10_000, 0, 0]);
    let view = hli::views::CncView::new(&memory);
    let mut trace = vec![*ctl.channels()[0].programmed()];
    for _ in 0..20_000 {
        ctl.tick(&view);
        let c = &ctl.channels()[0];
        trace.push(*c.programmed());
        if c.state() == RunState::Error {
            break;
        }
    }
    let c = &ctl.channels()[0];
    assert_eq!(c.state(), RunState::Error, "{:?}", c.error());
    assert_eq!(c.error().unwrap().line, 7, "{:?}", c.error());
    let end = trace.last().unwrap();
    assert_eq!(
        [end[0], end[1]],
        [30.0, 0.0],
        "at rest at the last good block"
    );
    let points = [[0.0, 0.0], [10.0, 0.0], [20.0, 2.0], [30.0, 0.0]];
    let (dev, rates) = measure(&trace, &points);
    assert!(dev <= 0.2 + 1e-9, "deviation {dev}");
    assert_within(&config, rates);
    assert!(
        corners_visited(&trace, &points) == 0,
        "its corners were rounded"
    );
}

/// CAM output on a channel: a circle of 300 chords of 1 mm (rounded as a post-processor writes
/// them) runs close to its feed, within the tolerance and the limits, and its tick allocates
/// nothing while the neighbouring corners share their curvature and the units are planned.
#[test]
fn a_dense_circle_runs_near_its_feed_without_allocating() {
    let points: Vec<[f64; 2]> = (0..=300)
        .map(|k| {
            let phi = std::f64::consts::TAU * k as f64 / 300.0;
            let r = |v: f64| format!("{v:.6}").parse::<f64>().unwrap();
            [r(50.0 * phi.cos()), r(50.0 * phi.sin())]
        })
        .collect();
    let blocks: String = points[1..]
        .iter()
        .map(|p| format!("X{} Y{}\n", p[0], p[1]))
        .collect();
    let program =
        format!("G1 X50 Y0 F6000\n#CONTOUR MODE [DEV PATH_DEV=0.02]\nG261\n{blocks}G260\nM30\n");
    let mut config = cartesian("c");
    config.limits.velocity = 200.0;
    config.limits.acceleration = 2000.0;
    config.limits.jerk = 40_000.0;
    let mut ctl = controller(vec![(config.clone(), &program)]);
    let memory = image(1);
    let view = hli::views::CncView::new(&memory);
    let mut trace = Vec::new();
    // Up to the circle's start and some of its blocks: the window is full.
    for _ in 0..2000 {
        ctl.tick(&view);
        trace.push(*ctl.channels()[0].programmed());
    }
    let before = counting_alloc::allocations();
    for _ in 0..1000 {
        ctl.tick(&view);
    }
    let made = counting_alloc::allocations() - before;
    assert_eq!(made, 0, "{made} allocations in 1000 ticks on the circle");
    let (rest, _) = run(&program, config.clone(), |_, _| {});
    let path: Vec<[f64; 2]> = std::iter::once([0.0, 0.0]).chain(points).collect();
    let (dev, rates) = measure(&rest, &path);
    assert!(dev <= 0.02 + 1e-9, "deviation {dev}");
    assert_within(&config, rates);
    // The first move (50 mm from the origin at exact stop) and the circle at 100 mm/s.
    let circle_ticks = rest.len() as f64
        - trace
            .iter()
            .position(|p| p[0] == 50.0 && p[1] == 0.0)
            .unwrap() as f64;
    let at_feed = std::f64::consts::TAU * 50.0 / 100.0 / 0.001;
    assert!(
        circle_ticks < 1.15 * at_feed,
        "{circle_ticks} ticks for {at_feed} at the feed"
    );
}

/// Distance from the slot of the arcs test: two lines of 40 mm joined by half circles of
/// radius 50 around (40, 50) and (0, 50).
fn distance_to_slot(p: &[f64]) -> f64 {
    let line = |y: f64| {
        let x = p[0].clamp(0.0, 40.0);
        (p[0] - x).hypot(p[1] - y)
    };
    let half = |cx: f64, right: bool| {
        let (dx, dy) = (p[0] - cx, p[1] - 50.0);
        if (dx >= 0.0) == right {
            (dx.hypot(dy) - 50.0).abs()
        } else {
            f64::INFINITY
        }
    };
    line(0.0)
        .min(line(100.0))
        .min(half(40.0, true))
        .min(half(0.0, false))
        + p[2].abs()
}

/// The issue's limits (200 mm/s, 2000 mm/s², 40000 mm/s³): `body` in continuous path within
/// `PATH_DEV = 0.02` and at exact stop; the config, both traces and the continuous path's
/// speed per tick (mm/s in X and Y).
fn contour_and_stop(body: &str) -> (ChannelConfig, Vec<AxisValues>, Vec<AxisValues>, Vec<f64>) {
    let program = format!("#CONTOUR MODE [DEV PATH_DEV=0.02]\nG261\n{body}G260\nM30\n");
    let mut config = cartesian("c");
    config.limits.velocity = 200.0;
    config.limits.acceleration = 2000.0;
    config.limits.jerk = 40_000.0;
    let (trace, _) = run(&program, config.clone(), |_, _| {});
    let (stopped, _) = run(&format!("{body}M30\n"), config.clone(), |_, _| {});
    let speed = trace
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) / CYCLE)
        .collect();
    (config, trace, stopped, speed)
}

/// The slowest of `speed` between the first and the last at `above` or more.
fn slowest_between(speed: &[f64], above: f64) -> f64 {
    let first = speed.iter().position(|&v| v >= above).unwrap();
    let last = speed.iter().rposition(|&v| v >= above).unwrap();
    speed[first..=last].iter().copied().fold(f64::MAX, f64::min)
}

/// Arcs inside a contour: a slot (line, half circle G03 of radius 50, line, half circle) in continuous
/// path runs without stopping anywhere between its start and its end, within PATH_DEV of the
/// lines and the circles, within the limits, quicker than exact stop, its tick allocating
/// nothing on the arcs; the circles' chords share their curvature.
#[test]
fn arcs_join_the_contour_tangent_to_its_lines() {
    let slot = "G1 X40 F6000\nG3 X40 Y100 I0 J50\nG1 X0\nG3 X0 Y0 I0 J-50\n";
    let (config, trace, stopped, speed) = contour_and_stop(slot);
    let program = format!("#CONTOUR MODE [DEV PATH_DEV=0.02]\nG261\n{slot}G260\nM30\n");
    let worst = trace
        .iter()
        .map(|p| distance_to_slot(p))
        .fold(0.0, f64::max);
    assert!(worst <= 0.02 + 1e-9, "deviation {worst}");
    let (_, rates) = measure(&trace, &[[0.0, 0.0], [0.0, 0.0]]);
    assert_within(&config, rates);
    // Tangent transitions without slowing (exact stop would stop at all four): at the feed
    // (100 mm/s) from the first tick there to the last.
    let slowest = slowest_between(&speed, 99.9);
    assert!(slowest > 99.9, "slowed to {slowest} mm/s on the way");
    let end = trace.last().unwrap();
    assert_eq!([end[0], end[1]], [0.0, 0.0]);
    assert!(
        trace.len() < stopped.len(),
        "continuous {} ticks, exact stop {}",
        trace.len(),
        stopped.len()
    );
    // The tick on the arcs (the window full of their chords) allocates nothing.
    let mut ctl = controller(vec![(config, &program)]);
    let memory = image(1);
    let view = hli::views::CncView::new(&memory);
    for _ in 0..600 {
        ctl.tick(&view);
    }
    let before = counting_alloc::allocations();
    for _ in 0..600 {
        ctl.tick(&view);
    }
    assert_eq!(counting_alloc::allocations() - before, 0);
}

/// How far `p` lies from the outline of the pocket below (a rounded rectangle from -5, 0 to
/// 75, 50 with corners of radius 5).
fn distance_to_pocket(p: &[f64]) -> f64 {
    let q = [(p[0] - 35.0).abs() - 35.0, (p[1] - 25.0).abs() - 20.0];
    let outside = q[0].max(0.0).hypot(q[1].max(0.0));
    (outside + q[0].max(q[1]).min(0.0) - 5.0).abs() + p[2].abs()
}

/// Small arcs inside a contour: a pocket's corners as radius-5 fillets between tangent lines
/// (too small for chords at this jerk) run through with transitions into and out of their
/// circles: never below 40 mm/s between the first and the last tick at that speed, within
/// PATH_DEV of the lines and circles and within the limits, quicker than exact stop, the tick
/// allocating nothing on the fillets.
#[test]
fn small_fillets_run_through_with_transitions() {
    let pocket = "G1 X70 F6000\nG3 X75 Y5 I0 J5\nG1 Y45\nG3 X70 Y50 I-5 J0\nG1 X0\n\
                  G3 X-5 Y45 I0 J-5\nG1 Y5\nG3 X0 Y0 I5 J0\nG1 X5\n";
    let (config, trace, stopped, speed) = contour_and_stop(pocket);
    let worst = trace
        .iter()
        .map(|p| distance_to_pocket(p))
        .fold(0.0, f64::max);
    assert!(worst <= 0.02 + 1e-9, "deviation {worst}");
    let (_, rates) = measure(&trace, &[[0.0, 0.0], [0.0, 0.0]]);
    assert_within(&config, rates);
    let slowest = slowest_between(&speed, 40.0);
    assert!(slowest >= 40.0, "slowed to {slowest} mm/s on the way");
    let end = trace.last().unwrap();
    assert_eq!([end[0], end[1]], [5.0, 0.0]);
    assert!(
        trace.len() < stopped.len(),
        "{} against {}",
        trace.len(),
        stopped.len()
    );
    // Twelve rounds (108 blocks): arcs are held and released while the ticks are counted.
    let rounds = format!(
        "#CONTOUR MODE [DEV PATH_DEV=0.02]\nG261\n{}G260\nM30\n",
        pocket.repeat(12)
    );
    let mut ctl = controller(vec![(config, &rounds)]);
    let memory = image(1);
    let view = hli::views::CncView::new(&memory);
    for _ in 0..600 {
        ctl.tick(&view);
    }
    let before = counting_alloc::allocations();
    for _ in 0..20_000 {
        ctl.tick(&view);
    }
    assert_eq!(counting_alloc::allocations() - before, 0);
}
