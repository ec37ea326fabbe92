//! The numbers of the camming manual (seed 000) pinned to the project's enums, and the
//! characteristic values a cam with known analytic values must have:
//!
//! * `MC_MotionFunctionType` (3.2 and 5.1.16.9): every number 1..99 the manual lists, its
//!   enumerator, the name of the table in 3.2 and the boundary conditions (RR, VV, ...); no
//!   other number decodes;
//! * `MC_MotionPointType` (3.1 and 5.1.16.8): IGNORE 0, REST 1, VELOCITY 2, TURN 4,
//!   MOTION 8; ADD and ACTIVATION are refused (a documented deviation);
//! * `MC_TableCharacValues` (3.4): the start and end velocity, acceleration and jerk, the
//!   slave velocity at the acceleration extremes (fSVeloAtSAccMin/Max) and the dynamic
//!   momentum (always 0) of a POLYNOM5 unit cam, a POLYNOM5_MM segment that reproduces a
//!   cubic, and a straight position table.

use cnc_core::cam::law::EndKind;
use cnc_core::cam::{
    CamProfile, CharacValues, FunctionType, MotionFunction, MotionFunctionPoint, PointType,
    PositionTable, ProfileCursor, TableType,
};
use hli::calls::cam::CamInterpolation;

/// The manual's function types: the enumerator of 5.1.16.9 (without `MOTIONFUNCTYPE_`, in the
/// manual's spelling), its number, the name in the table of 3.2 ("" where 3.2 does not list
/// it) and the boundary conditions there (start and end: R rest, V velocity, T turn, M
/// motion; the three laws 3.2 leaves out are motion to motion, as their comments say).
const FUNCTION_TYPES: [(&str, u32, &str, &str); 21] = [
    ("POLYNOM1", 1, "POLYNOM1", "VV"),
    ("POLYNOM3", 3, "POLYNOM3", "RR"),
    ("POLYNOM5", 5, "POLYNOM5", "RR"),
    ("POLYNOM8", 8, "POLYNOM8", "RR"),
    ("SINUSLINIE", 10, "SINELINE", "RR"),
    ("MODSINUSLINIE", 11, "MODSINELINE", "RR"),
    ("BESTEHOORN", 12, "BESTEHORN", "RR"),
    ("BESCHLTRAPEZ", 13, "ACCTRAPEZ", "RR"),
    ("POLYNOM5_MM", 15, "POLYNOM5_MM", "MM"),
    ("SINUS_GERADE_KOMBI", 16, "SINE_LINE_COMBI", "RR"),
    ("HARMONIC_KOMBI_RT", 17, "HARMONIC_COMBI_RT", "RT"),
    ("HARMONIC_KOMBI_TR", 18, "HARMONIC_COMBI_TR", "TR"),
    ("HARMONIC_KOMBI_VT", 19, "HARMONIC_COMBI_VT", "VT"),
    ("HARMONIC_KOMBI_TV", 20, "HARMONIC_COMBI_TV", "TV"),
    ("BESCHLTRAPEZ_RT", 21, "ACCTRAPEZ_RT", "RT"),
    ("BESCHLTRAPEZ_TR", 22, "ACCTRAPEZ_TR", "TR"),
    ("MODSINUSLINIE_VV", 23, "MODSINELINE_VV", "VV"),
    ("POLYNOM7_MM", 24, "", "MM"),
    ("POLYNOM6STP", 27, "", "MM"),
    ("POLYNOM6WDP", 28, "", "MM"),
    ("STEPFUNCTION", 99, "STEPFUNCTION", "RR"),
];

/// The manual's point types (5.1.16.8), without `MOTIONPOINTTYPE_`.
const POINT_TYPES: [(&str, u32); 5] = [
    ("IGNORE", 0x0000),
    ("REST", 0x0001),
    ("VELOCITY", 0x0002),
    ("TURN", 0x0004),
    ("MOTION", 0x0008),
];

/// A boundary letter of 3.2 as the law's end kind.
fn end_kind(letter: char) -> EndKind {
    match letter {
        'R' => EndKind::Rest,
        'V' => EndKind::Velocity,
        'T' => EndKind::Turn,
        'M' => EndKind::Motion,
        other => panic!("no boundary condition {other}"),
    }
}

#[test]
fn every_function_type_of_the_manual_has_its_number_names_and_boundary_conditions() {
    for (enumerator, number, table_name, ends) in FUNCTION_TYPES {
        let by_number = FunctionType::from_raw(number)
            .unwrap_or_else(|| panic!("{enumerator} = {number} does not decode"));
        assert_eq!(by_number.raw(), number, "{enumerator}");
        let prefixed = format!("MOTIONFUNCTYPE_{enumerator}");
        assert_eq!(
            FunctionType::from_name(&prefixed),
            Some(by_number),
            "{prefixed} is {number}"
        );
        assert_eq!(
            FunctionType::from_name(&number.to_string()),
            Some(by_number),
            "{number} by its digits"
        );
        if !table_name.is_empty() {
            assert_eq!(
                FunctionType::from_name(table_name),
                Some(by_number),
                "{table_name} of table 3.2 is {number}"
            );
        }
        // POLYNOM1's "VV": a straight line, whose velocity the points' positions fix (3.2).
        let mut letters = ends.chars();
        let expected = match by_number {
            FunctionType::Polynom1 => (EndKind::Line, EndKind::Line),
            _ => (
                end_kind(letters.next().unwrap()),
                end_kind(letters.next().unwrap()),
            ),
        };
        assert_eq!(by_number.ends(), expected, "{enumerator} ({number}) {ends}");
    }
    // Nothing beyond the manual's list: the project has exactly these 21 laws, and every
    // other number (0 is MOTIONFUNCTYPE_NOTDEF) is refused.
    assert_eq!(FunctionType::all().len(), FUNCTION_TYPES.len());
    for law in FunctionType::all() {
        assert!(
            FUNCTION_TYPES.iter().any(|(_, n, _, _)| *n == law.raw()),
            "{law:?} = {} is not the manual's",
            law.raw()
        );
    }
    for n in 0..=200u32 {
        if !FUNCTION_TYPES.iter().any(|(_, number, _, _)| *number == n) {
            assert_eq!(FunctionType::from_raw(n), None, "{n} is no function type");
        }
    }
    // The symmetry (SlaveJerk field) belongs to the rest-to-rest laws but the step.
    for (enumerator, number, _, ends) in FUNCTION_TYPES {
        let law = FunctionType::from_raw(number).unwrap();
        let shaped = ends == "RR" && law != FunctionType::Step;
        assert_eq!(law.has_symmetry(), shaped, "{enumerator}");
    }
}

#[test]
fn every_point_type_of_the_manual_has_its_number_and_nothing_else_decodes() {
    for (name, number) in POINT_TYPES {
        let t = PointType::from_raw(number).unwrap_or_else(|| panic!("{name} = {number}"));
        assert_eq!(t.raw(), number, "{name}");
        assert_eq!(t.name(), name);
        let prefixed = format!("MOTIONPOINTTYPE_{name}");
        assert_eq!(PointType::from_name(&prefixed), Some(t), "{prefixed}");
    }
    assert_eq!(PointType::all().len(), POINT_TYPES.len());
    // MOTIONPOINTTYPE_ADD (16#0F00) and _ACTIVATION (16#2000) are refused as unknown types
    // (docs/cams.md), as is every number between the manual's.
    for n in [3, 5, 6, 7, 9, 16, 0x0F00, 0x2000] {
        assert_eq!(PointType::from_raw(n), None, "{n:#x}");
    }
    // A point built from the typed values carries the manual's numbers.
    let p = MotionFunctionPoint::new(
        4,
        FunctionType::Polynom5Motion,
        PointType::Velocity,
        240.0,
        40.0,
    );
    assert_eq!((p.function, p.point_type), (15, 2));
}

fn near(got: f64, want: f64, what: &str) {
    assert!(
        (got - want).abs() <= 1e-9 * (1.0 + want.abs()),
        "{what}: {got} != {want}"
    );
}

/// The slave velocity at master `x`.
fn velocity_at(profile: &CamProfile, x: f64) -> f64 {
    profile.eval(x, &mut ProfileCursor::default()).velocity
}

/// POLYNOM5 from rest to rest over master 0..1, stroke 1: y = 10z^3 - 15z^4 + 6z^5. Its
/// acceleration 60z(1-z)(1-2z) is extreme at z = 1/2 -+ sqrt(3)/6, where z(1-z) = 1/6: the
/// acceleration is +-10/sqrt(3) and the velocity 30 (z(1-z))^2 = 5/6 at both. The jerk
/// 60 - 360z + 360z^2 is 60 at both ends, velocity and acceleration 0 there.
#[test]
fn a_polynom5_unit_cam_has_the_analytic_derived_characteristic_values() {
    let p = MotionFunctionPoint::new(1, FunctionType::Polynom5, PointType::Rest, 0.0, 0.0);
    let q = MotionFunctionPoint::new(2, FunctionType::Polynom1, PointType::Rest, 1.0, 1.0);
    let profile = CamProfile::MotionFunction(MotionFunction::new(&[p, q]).unwrap());
    let c = CharacValues::normed(&profile);
    let root3 = 3f64.sqrt();
    // Start and end (fields 4-6, 9-11).
    near(c.fSlaveVeloStart, 0.0, "fSlaveVeloStart");
    near(c.fSlaveAccStart, 0.0, "fSlaveAccStart");
    near(c.fSlaveJerkStart, 60.0, "fSlaveJerkStart");
    near(c.fSlaveVeloEnd, 0.0, "fSlaveVeloEnd");
    near(c.fSlaveAccEnd, 0.0, "fSlaveAccEnd");
    near(c.fSlaveJerkEnd, 60.0, "fSlaveJerkEnd");
    // The acceleration extremes, where they lie, and the velocity there (fields 16-18,
    // 25-27).
    near(c.fSlaveAccMax, 10.0 / root3, "fSlaveAccMax");
    near(c.fMPosAtSAccMax, 0.5 - root3 / 6.0, "fMPosAtSAccMax");
    near(c.fSVeloAtSAccMax, 5.0 / 6.0, "fSVeloAtSAccMax");
    near(c.fSlaveAccMin, -10.0 / root3, "fSlaveAccMin");
    near(c.fMPosAtSAccMin, 0.5 + root3 / 6.0, "fMPosAtSAccMin");
    near(c.fSVeloAtSAccMin, 5.0 / 6.0, "fSVeloAtSAccMin");
    // The velocity field is the cam's own velocity at the extreme's master position.
    near(
        c.fSVeloAtSAccMax,
        velocity_at(&profile, c.fMPosAtSAccMax),
        "at fMPosAtSAccMax",
    );
    near(
        c.fSVeloAtSAccMin,
        velocity_at(&profile, c.fMPosAtSAccMin),
        "at fMPosAtSAccMin",
    );
    // The jerk's range: 60 at the ends, -30 in the middle.
    near(c.fSlaveJerkMax, 60.0, "fSlaveJerkMax");
    near(c.fSlaveJerkMin, -30.0, "fSlaveJerkMin");
    // Dynamic momentum: not supported by the seed, always 0 (fields 20, 29).
    assert_eq!((c.fSlaveDynMomMin, c.fSlaveDynMomMax), (0.0, 0.0));
    // Rescaled to a master velocity of 2: the derived fields scale with V and V^3 too.
    let r = c.rescaled(2.0).unwrap();
    near(
        r.fSVeloAtSAccMax,
        2.0 * 5.0 / 6.0,
        "rescaled fSVeloAtSAccMax",
    );
    near(r.fSlaveJerkStart, 8.0 * 60.0, "rescaled fSlaveJerkStart");
    assert_eq!((r.fSlaveDynMomMin, r.fSlaveDynMomMax), (0.0, 0.0));
}

/// POLYNOM5_MM between two MOTION points takes the points' velocity and acceleration; with
/// the boundary values of the cubic y = x + x^2 + x^3 over 0..2 (start: y 0, v 1, a 2; end:
/// y 14, v 17, a 14) the quintic is that cubic, whose jerk is 6 everywhere. Its acceleration
/// 2 + 6x rises throughout: least at the start (velocity 1), greatest at the end (17).
#[test]
fn a_motion_to_motion_polynom5_mm_starts_and_ends_with_its_boundary_values() {
    let mut p =
        MotionFunctionPoint::new(1, FunctionType::Polynom5Motion, PointType::Motion, 0.0, 0.0);
    p.velocity = 1.0;
    p.acceleration = 2.0;
    let mut q = MotionFunctionPoint::new(2, FunctionType::Polynom1, PointType::Motion, 2.0, 14.0);
    q.velocity = 17.0;
    q.acceleration = 14.0;
    let profile = CamProfile::MotionFunction(MotionFunction::new(&[p, q]).unwrap());
    let c = CharacValues::normed(&profile);
    let expected = [
        ("fMasterPosStart", c.fMasterPosStart, 0.0),
        ("fSlavePosStart", c.fSlavePosStart, 0.0),
        ("fSlaveVeloStart", c.fSlaveVeloStart, 1.0),
        ("fSlaveAccStart", c.fSlaveAccStart, 2.0),
        ("fSlaveJerkStart", c.fSlaveJerkStart, 6.0),
        ("fMasterPosEnd", c.fMasterPosEnd, 2.0),
        ("fSlavePosEnd", c.fSlavePosEnd, 14.0),
        ("fSlaveVeloEnd", c.fSlaveVeloEnd, 17.0),
        ("fSlaveAccEnd", c.fSlaveAccEnd, 14.0),
        ("fSlaveJerkEnd", c.fSlaveJerkEnd, 6.0),
        ("fSlaveAccMin", c.fSlaveAccMin, 2.0),
        ("fMPosAtSAccMin", c.fMPosAtSAccMin, 0.0),
        ("fSVeloAtSAccMin", c.fSVeloAtSAccMin, 1.0),
        ("fSlaveAccMax", c.fSlaveAccMax, 14.0),
        ("fMPosAtSAccMax", c.fMPosAtSAccMax, 2.0),
        ("fSVeloAtSAccMax", c.fSVeloAtSAccMax, 17.0),
        // Mean |v| = stroke / range; effective acceleration sqrt(int (2 + 6x)^2 dx / 2).
        ("fSlaveVeloMean", c.fSlaveVeloMean, 7.0),
        ("fSlaveAccEff", c.fSlaveAccEff, 76f64.sqrt()),
        ("fSlaveDynMomMin", c.fSlaveDynMomMin, 0.0),
        ("fSlaveDynMomMax", c.fSlaveDynMomMax, 0.0),
    ];
    for (name, got, want) in expected {
        assert!(
            (got - want).abs() <= 1e-8 * (1.0 + want.abs()),
            "{name}: {got} != {want}"
        );
    }
    // Each field is also where it is in the seed's order (fields 4-6 and 9-11, 18, 27).
    let fields = c.fields();
    for (index, name, value) in [
        (3, "fSlaveVeloStart", 1.0),
        (4, "fSlaveAccStart", 2.0),
        (5, "fSlaveJerkStart", 6.0),
        (8, "fSlaveVeloEnd", 17.0),
        (9, "fSlaveAccEnd", 14.0),
        (10, "fSlaveJerkEnd", 6.0),
        (17, "fSVeloAtSAccMin", 1.0),
        (19, "fSlaveDynMomMin", 0.0),
        (26, "fSVeloAtSAccMax", 17.0),
        (28, "fSlaveDynMomMax", 0.0),
    ] {
        assert_eq!(fields[index].0, name);
        assert!(
            (fields[index].1 - value).abs() <= 1e-8 * (1.0 + value),
            "{name}"
        );
    }
}

/// A straight position table (slope 0.5): velocity 0.5 from start to end, no acceleration
/// or jerk anywhere; the velocity at the (flat) acceleration extremes is that slope, and the
/// dynamic momentum 0.
#[test]
fn a_straight_table_has_its_slope_at_both_ends_and_no_acceleration() {
    let rows = [[0.0, 0.0], [10.0, 5.0], [20.0, 10.0], [30.0, 15.0]];
    let table = PositionTable::new(
        &rows,
        TableType::Equidistant,
        CamInterpolation::Linear,
        false,
    )
    .unwrap();
    let c = CharacValues::normed(&CamProfile::Table(table));
    for (name, got, want) in [
        ("fSlaveVeloStart", c.fSlaveVeloStart, 0.5),
        ("fSlaveAccStart", c.fSlaveAccStart, 0.0),
        ("fSlaveJerkStart", c.fSlaveJerkStart, 0.0),
        ("fSlaveVeloEnd", c.fSlaveVeloEnd, 0.5),
        ("fSlaveAccEnd", c.fSlaveAccEnd, 0.0),
        ("fSlaveJerkEnd", c.fSlaveJerkEnd, 0.0),
        ("fSlavePosEnd", c.fSlavePosEnd, 15.0),
        ("fSVeloAtSAccMin", c.fSVeloAtSAccMin, 0.5),
        ("fSVeloAtSAccMax", c.fSVeloAtSAccMax, 0.5),
        ("fSlaveAccMin", c.fSlaveAccMin, 0.0),
        ("fSlaveAccMax", c.fSlaveAccMax, 0.0),
    ] {
        near(got, want, name);
    }
    assert_eq!((c.fSlaveDynMomMin, c.fSlaveDynMomMax), (0.0, 0.0));
}
