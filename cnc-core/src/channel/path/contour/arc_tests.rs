//! Arcs in the contour against their promises: lines and arcs in any order within the
//! tolerance of the exact lines and circles and within every axis's limits, ending on the
//! last point; tangent transitions without slowing; small circles on fine chords.

use super::tests::{limits, worst_rates, Trace, CYCLE};
use super::*;
use crate::nc::arc::{ArcMove, Plane};
use arc::ArcBlock;
use proptest::prelude::*;

/// One block of a path in the XY plane.
#[derive(Debug, Clone, Copy)]
enum Element {
    Line {
        end: [f64; 2],
    },
    Arc {
        end: [f64; 2],
        center: [f64; 2],
        ccw: bool,
        radius: f64,
        sweep: f64,
    },
}

impl Element {
    fn end(&self) -> [f64; 2] {
        match *self {
            Self::Line { end } | Self::Arc { end, .. } => end,
        }
    }
}

fn xyz(p: [f64; 2]) -> AxisValues {
    AxisValues::from_slice(&[p[0], p[1], 0.0])
}

/// One step of a walk: a line of `length` or an arc of `radius` and `sweep` (rad, its sign
/// the side), after turning the heading by `turn` (0: tangent).
#[derive(Debug, Clone, Copy)]
struct Step {
    arc: bool,
    turn: f64,
    length: f64,
    radius: f64,
    sweep: f64,
}

/// The blocks of a walk from the origin heading along X.
fn walk(steps: &[Step]) -> Vec<Element> {
    let (mut at, mut heading) = ([0.0f64, 0.0f64], 0.0f64);
    let mut path = Vec::new();
    for s in steps {
        heading += s.turn;
        if s.arc {
            let side = s.sweep.signum();
            let normal = heading + side * core::f64::consts::FRAC_PI_2;
            let center = [
                at[0] + s.radius * normal.cos(),
                at[1] + s.radius * normal.sin(),
            ];
            let from = normal + core::f64::consts::PI;
            let to = from + s.sweep;
            let end = [
                center[0] + s.radius * to.cos(),
                center[1] + s.radius * to.sin(),
            ];
            path.push(Element::Arc {
                end,
                center,
                ccw: side > 0.0,
                radius: s.radius,
                sweep: s.sweep.abs(),
            });
            heading += s.sweep;
            at = end;
        } else {
            at = [
                at[0] + s.length * heading.cos(),
                at[1] + s.length * heading.sin(),
            ];
            path.push(Element::Line { end: at });
        }
    }
    path
}

/// Pushes block `k` of `path` at `feed` within `tol` as the channel does: no corner before
/// the first, and the corner after an arc keeps half the tolerance (its chords lie up to the
/// other half inside the circle).
fn push_element(
    c: &mut Contour,
    path: &[Element],
    k: usize,
    (feed, tol): (f64, f64),
) -> Result<(), String> {
    let start = if k == 0 {
        [0.0, 0.0]
    } else {
        path[k - 1].end()
    };
    let line = k as u32 + 1;
    let after_arc = k > 0 && matches!(path[k - 1], Element::Arc { .. });
    let blend = (k > 0).then_some(if after_arc { 0.5 * tol } else { tol });
    match path[k] {
        Element::Line { end } => {
            let seg = Segment {
                start: xyz(start),
                end: xyz(end),
                feed,
                rapid: false,
                line,
                blend,
                chamfer: true,
                on_arc: false,
            };
            c.push(&seg, &mut |_| {})
                .map_err(|e| format!("line {line}: {e:?}"))
        }
        Element::Arc {
            end, center, ccw, ..
        } => {
            let block = ArcBlock {
                start: xyz(start),
                end: xyz(end),
                arc: ArcMove {
                    plane: Plane::Xy,
                    center,
                    ccw,
                    full_turn: false,
                },
                feed,
                line,
                blend,
                tolerance: tol,
            };
            c.push_arc(&block).map_err(|e| format!("arc {line}: {e:?}"))
        }
    }
}

/// The set-points of a contour tick by tick, with the block under way (the last one's while
/// none is).
struct Recorder {
    pos: AxisValues,
    vel: AxisValues,
    acc: AxisValues,
    trace: Trace,
}

impl Recorder {
    fn new() -> Self {
        let pos = xyz([0.0, 0.0]);
        Self {
            pos,
            vel: AxisValues::zeros(3),
            acc: AxisValues::zeros(3),
            trace: Trace {
                positions: vec![pos],
                blocks: vec![0],
            },
        }
    }

    /// One tick: whether the path moves or blocks wait.
    fn tick(&mut self, c: &mut Contour) -> bool {
        let moving = c
            .step(&mut self.pos, &mut self.vel, &mut self.acc)
            .expect("no fault");
        let t = &mut self.trace;
        t.positions.push(self.pos);
        let block = c
            .line()
            .map_or(*t.blocks.last().unwrap(), |l| l as usize - 1);
        t.blocks.push(block);
        moving
    }
}

/// Runs `path` at `feed` within `tol`, looking ahead `lookahead` blocks; `Err` when an arc
/// does not join.
fn run(path: &[Element], feed: f64, tol: f64, lookahead: usize) -> Result<Trace, String> {
    let lim = limits(3);
    let mut c = Contour::new(&lim, CYCLE, lookahead);
    let mut next = 0;
    let mut rec = Recorder::new();
    for _ in 0..2_000_000 {
        while next < path.len() && c.has_room() {
            push_element(&mut c, path, next, (feed, tol))?;
            next += 1;
        }
        if next == path.len() {
            c.close();
        }
        if !rec.tick(&mut c) && next == path.len() {
            return Ok(rec.trace);
        }
    }
    Err("did not finish".into())
}

/// The distance of `p` from block `k` of `path` (its exact line or circle).
fn distance(path: &[Element], k: usize, p: &[f64]) -> f64 {
    let a = if k == 0 {
        [0.0, 0.0]
    } else {
        path[k - 1].end()
    };
    match path[k] {
        Element::Line { end: b } => {
            let ab = [b[0] - a[0], b[1] - a[1]];
            let ap = [p[0] - a[0], p[1] - a[1]];
            let len2 = ab[0] * ab[0] + ab[1] * ab[1];
            let t = ((ap[0] * ab[0] + ap[1] * ab[1]) / len2).clamp(0.0, 1.0);
            (ap[0] - t * ab[0]).hypot(ap[1] - t * ab[1])
        }
        Element::Arc {
            end,
            center,
            ccw,
            radius,
            sweep,
        } => {
            let angle = |q: [f64; 2]| (q[1] - center[1]).atan2(q[0] - center[0]);
            let sign = if ccw { 1.0 } else { -1.0 };
            let along =
                ((angle([p[0], p[1]]) - angle(a)) * sign).rem_euclid(core::f64::consts::TAU);
            if along <= sweep {
                ((p[0] - center[0]).hypot(p[1] - center[1]) - radius).abs()
            } else {
                (p[0] - a[0])
                    .hypot(p[1] - a[1])
                    .min((p[0] - end[0]).hypot(p[1] - end[1]))
            }
        }
    }
}

/// Every tick within `tol` of the block under way or its neighbours, within the limits, the
/// run ending on the last point.
fn kept_its_promises(t: &Trace, path: &[Element], tol: f64) -> Result<(), String> {
    let mut worst = 0.0f64;
    for (p, &k) in t.positions.iter().zip(&t.blocks) {
        let near = (k.saturating_sub(2)..(k + 2).min(path.len()))
            .map(|j| distance(path, j, p))
            .fold(f64::INFINITY, f64::min);
        worst = worst.max(near + p[2].abs());
    }
    let l = limits(1)[0];
    let (v, a, j) = worst_rates(t);
    let slack = 1.0 + 1e-6;
    let end = t.positions.last().unwrap();
    let goal = path.last().unwrap().end();
    if worst > tol + 1e-9 {
        Err(format!("deviation {worst} > {tol}"))
    } else if v > l.velocity * slack || a > l.acceleration * slack || j > l.jerk * slack {
        Err(format!("velocity {v}, acceleration {a}, jerk {j}"))
    } else if [end[0], end[1]] != goal {
        Err(format!("ended at {end:?}, not {goal:?}"))
    } else {
        Ok(())
    }
}

/// The ticks between the first and the last moving one on which the path stood still.
fn stops_on_the_way(t: &Trace) -> usize {
    let moved: Vec<bool> = t
        .positions
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) > 1e-12)
        .collect();
    let first = moved.iter().position(|&m| m).unwrap_or(0);
    let last = moved.iter().rposition(|&m| m).unwrap_or(0);
    moved[first..=last].iter().filter(|&&m| !m).count()
}

fn step() -> impl Strategy<Value = Step> {
    (
        any::<bool>(),
        prop_oneof![Just(0.0), -1.5f64..1.5],
        1.0f64..30.0,
        prop_oneof![20.0f64..100.0, 100.0f64..400.0],
        prop_oneof![0.2f64..2.5, -2.5f64..-0.2],
    )
        .prop_map(|(arc, turn, length, radius, sweep)| Step {
            arc,
            turn,
            length,
            radius,
            sweep,
        })
}

/// The slowest speed (mm/s) between the first and the last tick at `above` or more.
fn slowest_between(t: &Trace, above: f64) -> f64 {
    let speed: Vec<f64> = t
        .positions
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) / CYCLE)
        .collect();
    let first = speed.iter().position(|&v| v >= above).unwrap_or(0);
    let last = speed.iter().rposition(|&v| v >= above).unwrap_or(0);
    speed[first..=last]
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
}

/// Runs `path` at 100 mm/s within 0.02 mm looking ahead `lookahead` blocks, checks its
/// promises, and returns the trace and its slowest speed between the first and the last tick
/// at `above` or more.
fn through(path: &[Element], lookahead: usize, above: f64) -> (Trace, f64) {
    let t = run(path, 100.0, 0.02, lookahead).unwrap();
    kept_its_promises(&t, path, 0.02).unwrap();
    let slowest = slowest_between(&t, above);
    (t, slowest)
}

fn line(length: f64, turn: f64) -> Step {
    Step {
        arc: false,
        turn,
        length,
        radius: 0.0,
        sweep: 0.0,
    }
}

fn arc(radius: f64, sweep_deg: f64) -> Step {
    Step {
        arc: true,
        turn: 0.0,
        length: 0.0,
        radius,
        sweep: sweep_deg.to_radians(),
    }
}

#[test]
fn tangent_transitions_keep_the_feed() {
    // A line, a quarter circle, a line, a half circle the other way, a line.
    let path = walk(&[
        line(30.0, 0.0),
        arc(50.0, 90.0),
        line(30.0, 0.0),
        arc(60.0, -180.0),
        line(20.0, 0.0),
    ]);
    let (_, slowest) = through(&path, 32, 99.9);
    assert!(slowest >= 99.9, "slowed to {slowest} mm/s at a transition");
}

/// A small circle whose chords would run it slower than it runs on its own (the curvature's
/// direction steps at every chord junction), between tangent lines: it runs through with
/// transitions into and out of its circle, never stopping, within the tolerance and the
/// limits. Leaving it at a corner instead, it runs on its own circle between rests.
#[test]
fn a_small_circle_between_tangent_lines_runs_through_with_transitions() {
    let path = walk(&[line(10.0, 0.0), arc(10.0, 270.0), line(10.0, 0.0)]);
    // The circle's own speed here is sqrt(a r / 2) = 70.7 mm/s; the transitions (their shift
    // within the tolerance) hold it to about 60.
    let (t, slowest) = through(&path, 32, 50.0);
    assert_eq!(stops_on_the_way(&t), 0);
    assert!(slowest >= 50.0, "slowed to {slowest} mm/s");
    let corner = walk(&[line(10.0, 0.0), arc(10.0, 90.0), line(10.0, 0.8)]);
    let (_, slowest) = through(&corner, 32, 5.0);
    assert!(slowest < 1.0, "came no nearer to rest than {slowest} mm/s");
}

/// A fillet in windows too small to hold it (lookahead below 8) runs on its own; in every
/// window the run ends, within the tolerance and the limits.
#[test]
fn a_fillet_in_a_small_window_runs_through_or_on_its_own() {
    let path = walk(&[
        line(10.0, 0.0),
        arc(5.0, 90.0),
        line(10.0, 0.0),
        arc(3.0, -120.0),
        line(5.0, 0.0),
    ]);
    for lookahead in 1..=9 {
        match run(&path, 100.0, 0.02, lookahead) {
            // Below 8 the arc does not join: the channel runs it on its own.
            Err(e) => assert!(
                lookahead < 8 && e.ends_with("NotStraight"),
                "{lookahead}: {e}"
            ),
            Ok(_) => {
                assert!(lookahead >= 8, "lookahead {lookahead} joined");
                let (_, slowest) = through(&path, lookahead, 20.0);
                assert!(slowest >= 20.0, "lookahead {lookahead}: {slowest}");
            }
        }
    }
}

/// Lines meeting a fillet not quite tangentially (rounded coordinates) still run through it,
/// within the tolerance and the limits: off by 1e-4 rad at 0.95 of the speed of exact
/// tangents (0.98 measured), by 0.001 at 0.8 (0.84), by 0.005 at half (0.60); the transitions
/// take the difference up over all their parts (with the last part alone: 0.94 and 0.44).
#[test]
fn a_fillet_met_nearly_tangentially_runs_through() {
    let fillet = |off: f64| {
        let mut bent = arc(5.0, 90.0);
        bent.turn = off;
        walk(&[line(10.0, 0.0), bent, line(10.0, -off), line(5.0, 0.0)])
    };
    // The slowest tick while the arc (block 1) is under way.
    let on_arc = |off: f64| {
        let (t, _) = through(&fillet(off), 32, 0.0);
        assert_eq!(stops_on_the_way(&t), 0, "{off}");
        (1..t.positions.len())
            .filter(|&k| t.blocks[k] == 1)
            .map(|k| {
                let (a, b) = (&t.positions[k - 1], &t.positions[k]);
                (b[0] - a[0]).hypot(b[1] - a[1]) / CYCLE
            })
            .fold(f64::INFINITY, f64::min)
    };
    let exact = on_arc(0.0);
    for (off, kept) in [(1e-4, 0.95), (-1e-3, 0.8), (5e-3, 0.5)] {
        let slowest = on_arc(off);
        assert!(slowest >= kept * exact, "{off}: {slowest} against {exact}");
    }
}

/// A program ending on a small arc (the window closed while it is held) runs it on its own
/// and ends on its end point; a stop while an arc is held brakes on what the window has,
/// within the limits, and comes to rest short of the arc.
#[test]
fn a_fillet_held_at_the_programs_end_or_at_a_stop() {
    let path = walk(&[line(10.0, 0.0), arc(5.0, 90.0)]);
    let (_, slowest) = through(&path, 32, 20.0);
    assert!(slowest < 1.0, "the arc ran on its own: {slowest}");
    // A stop while the arc is held, the path cruising on a line of 30 mm: at rest well short
    // of the arc (a stop while accelerating hard would take as long as the window's end).
    let path = walk(&[line(30.0, 0.0), arc(5.0, 90.0)]);
    let lim = limits(3);
    let mut c = Contour::new(&lim, CYCLE, 32);
    for k in 0..2 {
        push_element(&mut c, &path, k, (100.0, 0.02)).unwrap();
    }
    let mut rec = Recorder::new();
    for k in 0..5000 {
        if k == 150 {
            c.stop();
        }
        if !rec.tick(&mut c) && k > 150 {
            break;
        }
    }
    let trace = rec.trace;
    assert!(!c.active(), "the held arc is dropped at rest");
    let rest = trace.positions.last().unwrap();
    assert!(
        rest[1] == 0.0 && rest[0] > 0.0 && rest[0] < 25.0,
        "rests at {rest:?}"
    );
    let (v, a, j) = worst_rates(&trace);
    let l = limits(1)[0];
    assert!(v <= l.velocity && a <= l.acceleration * (1.0 + 1e-6) && j <= l.jerk * (1.0 + 1e-6));
}

/// The interpreter may stall with the straight after a fillet's transitions held back: the
/// path comes to rest where they end (the window's end), not anywhere else, and goes on from
/// there when the rest comes.
#[test]
fn a_stall_after_a_fillets_transitions_rests_where_they_end() {
    let path = walk(&[line(10.0, 0.0), arc(5.0, 90.0), line(10.0, 0.0)]);
    let lim = limits(3);
    let mut c = Contour::new(&lim, CYCLE, 32);
    for k in 0..3 {
        push_element(&mut c, &path, k, (100.0, 0.02)).unwrap();
    }
    let end = path[1].end();
    let mut rec = Recorder::new();
    // Stalled: nothing more comes for 2 s; the last straight waits, held back.
    for _ in 0..2000 {
        rec.tick(&mut c);
    }
    let rest = *rec.trace.positions.last().unwrap();
    let still = rec.trace.positions[rec.trace.positions.len() - 100..]
        .iter()
        .all(|p| *p == rest);
    assert!(still, "not at rest at the stall");
    // Where the transition out ends: on the straight after the arc, past its start, short
    // of its end.
    let after = path[2].end();
    let on_it = (rest[0] - end[0]).abs() < 1e-9 && rest[1] > end[1] + 0.1;
    assert!(on_it && rest[1] < after[1] - 1.0, "rests at {rest:?}");
    c.close();
    while rec.tick(&mut c) {}
    kept_its_promises(&rec.trace, &path, 0.02).unwrap();
}

/// A pocket's corners as radius-5 fillets at F6000 within 0.02 mm: the path never stops.
#[test]
fn a_pockets_small_fillets_never_stop_the_path() {
    let mut steps = Vec::new();
    for side in [40.0, 20.0, 40.0, 20.0] {
        steps.push(line(side, 0.0));
        steps.push(arc(5.0, 90.0));
    }
    steps.push(line(10.0, 0.0));
    let (t, slowest) = through(&walk(&steps), 32, 40.0);
    assert_eq!(stops_on_the_way(&t), 0);
    assert!(slowest >= 40.0, "slowed to {slowest} mm/s");
}

fn fillet_step() -> impl Strategy<Value = (Step, Step)> {
    (
        2.0f64..30.0,
        prop_oneof![0.5f64..5.0, 5.0f64..20.0],
        prop_oneof![0.2f64..3.1, -3.1f64..-0.2],
    )
        .prop_map(|(length, radius, sweep)| {
            (
                line(length, 0.0),
                Step {
                    arc: true,
                    turn: 0.0,
                    length: 0.0,
                    radius,
                    sweep,
                },
            )
        })
}

/// Cases of the fillet property test: 48, or `FILLET_CASES` (a long run by hand).
fn fillet_cases() -> u32 {
    std::env::var("FILLET_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(48)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(fillet_cases()))]

    /// Small arcs between tangent lines (fillets of any radius, sweep and side) keep the
    /// tolerance and the limits, end on the last point and never slow below 0.3 of the
    /// speed the smallest runs at on its own.
    #[test]
    fn small_fillets_keep_tolerance_and_limits(
        pairs in proptest::collection::vec(fillet_step(), 1..6),
        last in 2.0f64..30.0,
        tol in 0.005f64..0.1,
    ) {
        let mut steps: Vec<Step> = pairs.iter().flat_map(|&(l, a)| [l, a]).collect();
        steps.push(line(last, 0.0));
        let path = walk(&steps);
        let t = run(&path, 100.0, tol, 32).map_err(TestCaseError::fail)?;
        kept_its_promises(&t, &path, tol).map_err(TestCaseError::fail)?;
        // Never below 0.3 of the speed the smallest arc runs at on its own.
        let own = |r: f64| 100.0f64.min((1000.0 * r).sqrt()).min((20_000.0 * r * r).cbrt());
        let floor = 0.3 * pairs.iter().map(|(_, a)| own(a.radius)).fold(f64::INFINITY, f64::min);
        let slowest = slowest_between(&t, floor);
        prop_assert!(slowest >= 0.99 * floor, "slowed to {} mm/s (floor {})", slowest, floor);
        // Never above the feed (the transitions' parameter is not their length).
        let fastest = t
            .positions
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) / CYCLE)
            .fold(0.0, f64::max);
        prop_assert!(fastest <= 100.0 * (1.0 + 1e-9), "{} mm/s", fastest);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Lines and arcs in any order, tangent or at corners, keep the tolerance and the limits
    /// and end on the last point; where every transition is tangent the path never stops on
    /// the way. (The feed is one whose chords keep the arcs' speed: 100 mm/s for radii of 100
    /// mm and more, 30 mm/s below; the channel runs an arc whose chords would be slower on its
    /// own.)
    #[test]
    fn random_lines_and_arcs_keep_tolerance_and_limits(
        steps in proptest::collection::vec(step(), 2..10),
        tol in 0.005f64..0.1,
        tangent in any::<bool>(),
    ) {
        let steps: Vec<Step> = steps
            .into_iter()
            .map(|s| if tangent { Step { turn: 0.0, ..s } } else { s })
            .collect();
        let path = walk(&steps);
        let small = steps.iter().any(|s| s.arc && s.radius < 100.0);
        let feed = if small { 30.0 } else { 100.0 };
        let t = run(&path, feed, tol, 64).map_err(TestCaseError::fail)?;
        kept_its_promises(&t, &path, tol).map_err(TestCaseError::fail)?;
        if tangent {
            prop_assert_eq!(stops_on_the_way(&t), 0);
        }
    }
}
