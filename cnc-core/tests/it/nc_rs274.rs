//! Against LinuxCNC's interpreter: random programs of G0, G1, G2 and G3 (centre and radius
//! forms, all three planes, helical, full circles) run through `cnc check` and `rs274 -g` give
//! the same end points and arc centres. Skipped, and said so, when `rs274` is not installed
//! (Debian package `linuxcnc-uspace`).
//!
//! rs274 prints four decimals. The programs are written on a 0.0001 mm grid, so end points and
//! the centres of the centre form are exact in both and compared to 1e-6 mm; the centres of the
//! radius form are computed (irrational in general) and compared to rs274's printing precision,
//! 5e-5 mm.

use cnc_core::nc::check::check_source;
use cnc_core::nc::Decoded;
use proptest::prelude::*;
use tests::{Cli, Scratch};

fn have_rs274() -> bool {
    let found = Cli::new("rs274")
        .arg("-g")
        .arg("/dev/null")
        .output()
        .is_ok();
    if !found {
        eprintln!("rs274 is not installed (apt-get install linuxcnc-uspace): comparison skipped");
    }
    found
}

/// One motion as both interpreters report it: end X Y Z, and for arcs the centre in the
/// plane's (first, second) axes with the turning direction.
#[derive(Debug, Clone, PartialEq)]
struct Motion {
    end: [f64; 3],
    arc: Option<([f64; 2], bool, bool)>,
}

#[derive(Debug, Clone)]
enum Op {
    Line {
        rapid: bool,
        to: [i64; 3],
    },
    Arc {
        plane: usize,
        ccw: bool,
        center: [i64; 2],
        sweep_deg: i64,
        rise: i64,
        radius_form: bool,
        long: bool,
    },
}

/// Axis indices (X 0, Y 1, Z 2) of a plane's first and second axis and normal, and the
/// letters of its centre words.
const PLANES: [([usize; 3], [char; 2], &str); 3] = [
    ([0, 1, 2], ['I', 'J'], "G17"),
    ([2, 0, 1], ['K', 'I'], "G18"),
    ([1, 2, 0], ['J', 'K'], "G19"),
];

const GRID: f64 = 1e-4;

fn fmt(v: i64) -> String {
    format!("{:.4}", v as f64 * GRID)
}

/// The program text (the same words for both, the header apart) and whether each arc uses the
/// radius form.
fn program(ops: &[Op]) -> (String, Vec<bool>) {
    let mut pos = [0i64; 3];
    let mut body = String::from("G0 X0 Y0 Z0\n");
    let mut radius_forms = Vec::new();
    for op in ops {
        match op {
            Op::Line { rapid, to } => {
                let g = if *rapid { "G0" } else { "G1" };
                body.push_str(&format!(
                    "{g} X{} Y{} Z{} F1000\n",
                    fmt(to[0]),
                    fmt(to[1]),
                    fmt(to[2])
                ));
                pos = *to;
            }
            Op::Arc {
                plane,
                ccw,
                center,
                sweep_deg,
                rise,
                radius_form,
                long,
            } => {
                let (axes, letters, g) = PLANES[*plane];
                let start = [pos[axes[0]] as f64, pos[axes[1]] as f64];
                let c = [start[0] + center[0] as f64, start[1] + center[1] as f64];
                let r = (center[0] as f64).hypot(center[1] as f64);
                if r < 1000.0 {
                    continue; // below 0.1 mm: the grid would move the end off the circle
                }
                let a0 = (start[1] - c[1]).atan2(start[0] - c[0]);
                let mut sweep = (*sweep_deg as f64).to_radians();
                if *radius_form {
                    // Radius form: at most or more than half a turn, never a full one.
                    sweep = if *long {
                        sweep.clamp(3.3, 6.0)
                    } else {
                        sweep.clamp(0.3, 3.0)
                    };
                }
                let a1 = if *ccw { a0 + sweep } else { a0 - sweep };
                let full = !*radius_form && *sweep_deg >= 360;
                let mut end = pos;
                if !full {
                    end[axes[0]] = (c[0] + r * a1.cos()).round() as i64;
                    end[axes[1]] = (c[1] + r * a1.sin()).round() as i64;
                }
                end[axes[2]] += rise;
                let dir = if *ccw { "G3" } else { "G2" };
                let target = format!("X{} Y{} Z{}", fmt(end[0]), fmt(end[1]), fmt(end[2]));
                if *radius_form {
                    let sign = if *long { -1.0 } else { 1.0 };
                    body.push_str(&format!(
                        "{g} {dir} {target} R{:.4} F1000\n",
                        sign * r * GRID
                    ));
                } else {
                    body.push_str(&format!(
                        "{g} {dir} {target} {}{} {}{} F1000\n",
                        letters[0],
                        fmt(center[0]),
                        letters[1],
                        fmt(center[1])
                    ));
                }
                radius_forms.push(*radius_form);
                pos = end;
            }
        }
    }
    (body, radius_forms)
}

fn op() -> impl Strategy<Value = Op> {
    let coord = -2_000_000i64..2_000_000;
    prop_oneof![
        (any::<bool>(), [coord.clone(), coord.clone(), coord])
            .prop_map(|(rapid, to)| Op::Line { rapid, to }),
        (
            0usize..3,
            any::<bool>(),
            [-500_000i64..500_000, -500_000i64..500_000],
            5i64..400,
            prop_oneof![Just(0i64), -100_000i64..100_000],
            any::<bool>(),
            any::<bool>()
        )
            .prop_map(
                |(plane, ccw, center, sweep_deg, rise, radius_form, long)| Op::Arc {
                    plane,
                    ccw,
                    center,
                    sweep_deg,
                    rise,
                    radius_form,
                    long
                }
            ),
    ]
}

fn ours(body: &str) -> Vec<Motion> {
    let axes: Vec<String> = ["X", "Y", "Z"].map(String::from).to_vec();
    let (diags, decoded) = check_source(&format!("{body}M30\n"), &axes);
    assert!(diags.is_empty(), "{body}\n{diags:#?}");
    decoded
        .iter()
        .filter_map(|d| match d {
            Decoded::Motion(m) => Some(Motion {
                end: [m.target[0], m.target[1], m.target[2]],
                arc: m.arc.map(|a| (a.center, a.ccw, false)),
            }),
            _ => None,
        })
        .collect()
}

fn numbers(args: &str) -> Vec<f64> {
    args.split(',')
        .map(|s| s.trim().parse::<f64>().unwrap())
        .collect()
}

fn theirs(body: &str) -> Vec<Motion> {
    let dir = Scratch::new("rs274");
    let path = dir.join("program.ngc");
    std::fs::write(&path, format!("G21 G90 G94 G91.1\n{body}M2\n")).unwrap();
    let output = Cli::new("rs274").arg("-g").arg(&path).output().unwrap();
    let text = String::from_utf8_lossy(&output.stdout);
    let mut plane = 0usize;
    let mut motions = Vec::new();
    for line in text.lines() {
        let Some(call) = line.split("N..... ").nth(1) else {
            continue;
        };
        let (name, rest) = call.split_once('(').unwrap_or((call, ""));
        let args = rest.trim_end_matches(')');
        match name {
            "SELECT_PLANE" => {
                plane = match args {
                    "CANON_PLANE_XY" => 0,
                    "CANON_PLANE_XZ" => 1,
                    _ => 2,
                }
            }
            "STRAIGHT_TRAVERSE" | "STRAIGHT_FEED" => {
                let v = numbers(args);
                motions.push(Motion {
                    end: [v[0], v[1], v[2]],
                    arc: None,
                });
            }
            "ARC_FEED" => {
                // first_end, second_end, first_centre, second_centre, rotation, axis_end, ...
                let v = numbers(args);
                let axes = PLANES[plane].0;
                let mut end = [0.0; 3];
                end[axes[0]] = v[0];
                end[axes[1]] = v[1];
                end[axes[2]] = v[5];
                motions.push(Motion {
                    end,
                    arc: Some(([v[2], v[3]], v[4] > 0.0, false)),
                });
            }
            _ => {}
        }
    }
    assert!(
        text.contains("ON_RESET") && !String::from_utf8_lossy(&output.stderr).contains("rror"),
        "rs274 refused the program:\n{body}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    motions
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn end_points_and_centres_match_rs274(ops in proptest::collection::vec(op(), 1..25)) {
        if !have_rs274() {
            return Ok(());
        }
        let (body, radius_forms) = program(&ops);
        let (a, b) = (ours(&body), theirs(&body));
        prop_assert_eq!(a.len(), b.len(), "{}", body);
        let mut arc = 0;
        for (i, (m, t)) in a.iter().zip(&b).enumerate() {
            for k in 0..3 {
                prop_assert!((m.end[k] - t.end[k]).abs() < 1e-6, "motion {}: {:?} vs {:?}\n{}", i, m, t, body);
            }
            prop_assert_eq!(m.arc.is_some(), t.arc.is_some());
            if let (Some(ma), Some(ta)) = (m.arc, t.arc) {
                let tolerance = if radius_forms[arc] { 5.1e-5 } else { 1e-6 };
                arc += 1;
                prop_assert_eq!(ma.1, ta.1, "direction of motion {}\n{}", i, body);
                for k in 0..2 {
                    prop_assert!((ma.0[k] - ta.0[k]).abs() < tolerance, "centre of motion {}: {:?} vs {:?}\n{}", i, ma.0, ta.0, body);
                }
            }
        }
    }
}
