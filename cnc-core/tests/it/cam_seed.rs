//! The seed's worked motion function (chapter 3.3: six points, POLYNOM1 and POLYNOM5_MM) and
//! its two changes. The figures are the project's own test data
//! (`tests/data/seed000_motion_function.toml`); when `../shared/seeds/` is present
//! (`support::seed_text` checks that it exists()), one more
//! test reads the seed's table and checks that the data says the same.

use tests::channel_rig as support;

use cnc_core::cam::motion_function::Cursor;
use cnc_core::cam::online::{MasterNow, OnlineChangeQueue, WriteOutcome};
use cnc_core::cam::{FunctionType, MotionFunction, MotionFunctionPoint, PointType};
use serde::Deserialize;

/// One point as the test data writes it: enumerator names, the rest numbers.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PointRow {
    index: u32,
    function: String,
    point_type: String,
    rel_index_next: i64,
    master: f64,
    slave: f64,
    velocity: f64,
    acceleration: f64,
    jerk: f64,
}

impl PointRow {
    fn point(&self) -> MotionFunctionPoint {
        let function = FunctionType::from_name(&self.function)
            .unwrap_or_else(|| panic!("function type {:?}", self.function));
        let point_type = PointType::from_name(&self.point_type)
            .unwrap_or_else(|| panic!("point type {:?}", self.point_type));
        MotionFunctionPoint {
            index: self.index,
            function: function.raw(),
            point_type: point_type.raw(),
            rel_index_next: self.rel_index_next,
            master: self.master,
            slave: self.slave,
            velocity: self.velocity,
            acceleration: self.acceleration,
            jerk: self.jerk,
        }
    }
}

/// The test data file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SeedData {
    /// The six points of the example table.
    example: Vec<PointRow>,
    /// The first change: point 4 becomes a velocity point at slave 60.
    change_velocity: Vec<PointRow>,
    /// The second change: points 3 and 4 are ignored.
    change_ignore: Vec<PointRow>,
}

/// The example and its two changes, as points.
struct Figures {
    example: Vec<MotionFunctionPoint>,
    change_velocity: Vec<MotionFunctionPoint>,
    change_ignore: Vec<MotionFunctionPoint>,
}

fn figures() -> Figures {
    let text = include_str!("../data/seed000_motion_function.toml");
    let data: SeedData = toml::from_str(text).expect("tests/data/seed000_motion_function.toml");
    let points = |rows: &[PointRow]| rows.iter().map(PointRow::point).collect::<Vec<_>>();
    Figures {
        example: points(&data.example),
        change_velocity: points(&data.change_velocity),
        change_ignore: points(&data.change_ignore),
    }
}

fn seed() -> Option<String> {
    support::seed_text("000_f46a22ead927b2f0.txt")
}

/// A point from the seed's table cells: the extraction splits names ("POLYNO M5_MM",
/// "VELOCIT Y"); joined again they are the enumerator names.
fn point(cells: &[&str]) -> MotionFunctionPoint {
    let name = |s: &str| s.split_whitespace().collect::<String>();
    let function = FunctionType::from_name(&name(cells[1])).expect("function type");
    let point_type = PointType::from_name(&name(cells[2])).expect("point type");
    let num = |s: &str| s.trim().parse::<f64>().expect("number");
    // "1 bzw. 0" (1 or 0): both mean "the next point".
    let rel = cells[3]
        .split_whitespace()
        .last()
        .unwrap()
        .parse::<i64>()
        .unwrap();
    let mut p = MotionFunctionPoint::new(
        cells[0].trim().parse().unwrap(),
        function,
        point_type,
        num(cells[4]),
        num(cells[5]),
    );
    p.rel_index_next = rel;
    p.velocity = num(cells[6]);
    p.acceleration = num(cells[7]);
    p.jerk = num(cells[8]);
    p
}

/// The six points of the example table.
fn example_points(text: &str) -> Vec<MotionFunctionPoint> {
    let start = text
        .lines()
        .position(|l| l.starts_with("Point Index\tFunction Type"))
        .expect("the example table");
    text.lines()
        .skip(start + 1)
        .take_while(|l| !l.trim().is_empty())
        .map(|l| point(&l.split('\t').collect::<Vec<_>>()))
        .collect()
}

/// A changed point of the seed's two change listings: one line of values, the rest of the
/// function name on the next line.
fn changed_point(text: &str, prefix: &str) -> MotionFunctionPoint {
    let lines: Vec<&str> = text.lines().collect();
    let i = lines
        .iter()
        .position(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line {prefix:?}"));
    let words: Vec<&str> = lines[i].split_whitespace().collect();
    let tail: Vec<&str> = lines[i + 1].split_whitespace().collect();
    let function = format!("{}{}", words[1], tail[0]);
    let point_type = match tail.get(1) {
        Some(rest) => format!("{}{rest}", words[2]),
        None => words[2].to_string(),
    };
    let cells = [
        words[0],
        function.as_str(),
        point_type.as_str(),
        words[3],
        words[4],
        words[5],
        words[6],
        words[7],
        words[8],
    ];
    point(&cells)
}

fn eval(f: &MotionFunction, x: f64) -> cnc_core::cam::Sample {
    f.eval(x, &mut Cursor::new())
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn the_seed_example_has_the_velocities_the_seed_gives() {
    let points = figures().example;
    assert_eq!(points.len(), 6);
    let f = MotionFunction::new(&points).expect("the seed's example is valid");
    // The Cam Design Tool view of the same cam: segment 150..240 runs at 0.222... (20/90).
    let v = 20.0 / 90.0;
    let seg = f.segments();
    assert_eq!(seg.len(), 5);
    assert_eq!(seg[1].law, FunctionType::Polynom5Motion);
    assert!(
        close(seg[1].end.v, v, 1e-12),
        "POLYNOM1's velocity handed to point 3"
    );
    assert!(close(seg[3].start.v, v, 1e-12), "and to point 4");
    for x in [150.0, 195.0, 240.0] {
        assert!(close(eval(&f, x).velocity, v, 1e-12), "at {x}");
    }
    assert!(close(eval(&f, 195.0).position, 30.0, 1e-12));
    // The rest stretches and the points.
    for (x, y) in [
        (0.0, 0.0),
        (15.0, 0.0),
        (30.0, 0.0),
        (150.0, 20.0),
        (240.0, 40.0),
        (340.0, 0.0),
        (360.0, 0.0),
    ] {
        assert!(close(eval(&f, x).position, y, 1e-9), "y({x})");
    }
    // POLYNOM5_MM joins with continuous velocity and acceleration (rest, then line).
    for x in [30.0, 150.0, 240.0, 340.0] {
        let (a, b) = (eval(&f, x - 1e-7), eval(&f, x + 1e-7));
        assert!(close(a.velocity, b.velocity, 1e-6), "velocity at {x}");
        assert!(
            close(a.acceleration, b.acceleration, 1e-6),
            "acceleration at {x}"
        );
    }
}

#[test]
fn writing_one_point_changes_the_whole_cam() {
    let data = figures();
    let f = MotionFunction::new(&data.example).unwrap();
    let &[change] = data.change_velocity.as_slice() else {
        panic!("one changed point: {:?}", data.change_velocity);
    };
    assert_eq!(change.index, 4);
    assert_eq!(change.slave, 60.0);
    let mut queue = OnlineChangeQueue::default();
    let outcome = queue
        .write(&f, 4, &[change], MasterNow::standing(0.0))
        .unwrap();
    assert_eq!(outcome, WriteOutcome::Queued);
    let (g, _) = queue
        .take_due(MasterNow::standing(0.0))
        .expect("instantaneous");
    // The line now climbs 40 over 90.
    let v = 40.0 / 90.0;
    assert!(close(eval(&g, 200.0).velocity, v, 1e-12));
    assert!(close(eval(&g, 240.0).position, 60.0, 1e-12));
    // Both POLYNOM5_MM neighbours took the new velocity: still smooth at the joints.
    for x in [150.0, 240.0] {
        let (a, b) = (eval(&g, x - 1e-7), eval(&g, x + 1e-7));
        assert!(
            close(a.velocity, b.velocity, 1e-6) && close(a.velocity, v, 1e-6),
            "at {x}"
        );
    }
    // Every segment from 30 to 340 changed; the rests at both ends did not.
    assert_eq!(
        cnc_core::cam::online::changed_ranges(&f, &g),
        vec![(30.0, 150.0), (150.0, 240.0), (240.0, 340.0)]
    );
}

#[test]
fn ignoring_the_two_middle_points_sets_the_cam_to_zero() {
    let data = figures();
    let f = MotionFunction::new(&data.example).unwrap();
    let &[p3, p4] = data.change_ignore.as_slice() else {
        panic!("two changed points: {:?}", data.change_ignore);
    };
    assert_eq!((p3.index, p4.index), (3, 4));
    assert_eq!(p3.point_type, PointType::Ignore.raw());
    assert_eq!(p4.point_type, PointType::Ignore.raw());
    let g = f.with_points_written(3, &[p3, p4]).expect("valid change");
    assert_eq!(g.segments().len(), 3);
    for i in 0..=360 {
        let s = eval(&g, i as f64);
        assert!(
            s.position.abs() < 1e-12 && s.velocity.abs() < 1e-12,
            "at {i}: {s:?}"
        );
    }
}

#[test]
fn the_test_data_is_the_seed_table() {
    let Some(text) = seed() else {
        return;
    };
    let data = figures();
    assert_eq!(example_points(&text), data.example);
    assert_eq!(
        vec![changed_point(&text, "4 POLYNO VELOCIT 1 240 60")],
        data.change_velocity
    );
    assert_eq!(
        vec![
            changed_point(&text, "3 POLYNO IGNORE 1 150 20"),
            changed_point(&text, "4 POLYNO IGNORE 1 240 40"),
        ],
        data.change_ignore
    );
}
