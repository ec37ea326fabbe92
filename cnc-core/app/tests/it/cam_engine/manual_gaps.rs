//! Gaps of the camming audit (seed 000) closed through the PLC's blocks: MC_ReadMotionFunction
//! (#61), the compatibility blocks (#84, #86, #87) and read arrays (#68).

use super::data::read_values;
use super::*;
use hli::calls::cam::{CamInterpolation, CamReadCall, CamReadKind, TableOrganisation};

/// MC_CamInfo of slave `axis`: its 40 values.
fn info_of(run: &mut InProcess, axis: usize) -> Vec<f64> {
    let call = CamReadCall {
        what: CamReadKind::Info.raw(),
        ..Default::default()
    };
    let (v, _) = read_all(run, axis as u32, call);
    assert_eq!(v.len(), 40);
    v
}

/// Whether `got` is `want` (to 1e-9).
fn near(got: f64, want: f64) -> bool {
    (got - want).abs() < 1e-9
}

/// The raw slave position of `profile` at master `x`.
fn cam_at(profile: &CamProfile, x: f64) -> f64 {
    profile.eval(x, &mut ProfileCursor::default()).position
}

/// Rows every `step` of the master with these slave positions.
fn rows_every(step: f64, slaves: &[f64]) -> Vec<[f64; 2]> {
    let row = |(i, s): (usize, &f64)| [step * i as f64, *s];
    slaves.iter().enumerate().map(row).collect()
}

/// The cyclic wave the compatibility tests generate: 0, 10, 0, -10, 0 every 90.
fn wave() -> Vec<[f64; 2]> {
    rows_every(90.0, &[0.0, 10.0, 0.0, -10.0, 0.0])
}

/// The rows' straight lines at `x`, held at the first and last row.
fn lerp(rows: &[[f64; 2]], x: f64) -> f64 {
    let x = x.clamp(rows[0][0], rows[rows.len() - 1][0]);
    let k = rows.windows(2).position(|w| x <= w[1][0]).unwrap();
    let ([m0, s0], [m1, s1]) = (rows[k], rows[k + 1]);
    s0 + (s1 - s0) / (m1 - m0) * (x - m0)
}

/// Whether block `instance` is Done without an ErrorID.
fn done(report: &str, instance: &str) -> bool {
    let line = block_line(report, instance);
    line.contains("Done") && !line.contains("ErrorID")
}

/// Whether block `instance` ended with ErrorID `code` (as the report writes it: `0x4b31`).
fn refused(report: &str, instance: &str, code: &str) -> bool {
    block_line(report, instance).contains(&format!("ErrorID {code}"))
}

/// How many numbers block `instance` read (the report shows only the first 12).
fn read_count(report: &str, instance: &str) -> usize {
    let start = format!("block {instance} ");
    let mut lines = report.lines().skip_while(|l| !l.starts_with(&start));
    let line = lines.nth(1).unwrap_or("");
    let count = line.trim_start().strip_prefix("read ");
    let count = count.and_then(|r| r.split(' ').next()?.parse().ok());
    count.unwrap_or_else(|| panic!("{instance} read nothing: {line}\n{report}"))
}

/// A machine with the seed's motion function as table 1 and one axis, for a PLC timeline.
const SEED_ONLY: &str = "cycle_ms = 1.0\nticks = 60\n[[axis]]\nname = \"Lifter\"\npower = true\n\
    [[cam_table]]\nfile = \"seed_example.json\"\n[plc]\ntimeline = \"plc.toml\"\n";

/// A linear drum (axis 0) and two pushers (axes 1 and 2, the second at 5), for a timeline.
const PUSHERS: &str = "cycle_ms = 1.0\nticks = 3000\n\
    [[axis]]\nname = \"Drum\"\npower = true\n\
    [[axis]]\nname = \"Pusher\"\npower = true\nsoft_limits = [-50.0, 50.0]\n\
    [[axis]]\nname = \"Second\"\npower = true\nstart = 5.0\nsoft_limits = [-50.0, 50.0]\n\
    [plc]\ntimeline = \"plc.toml\"\n";

/// The timeline step that moves the drum (axis 0) to `position` once `instance` is done.
fn drum_to(instance: &str, position: f64) -> String {
    format!(
        "[[step]]\nwait = \"{instance}.Done\"\ncall = {{ block = \"MC_MoveAbsolute\", \
         instance = \"go\", axis = 0, position = {position:?}, velocity = 90.0, \
         acceleration = 900.0, deceleration = 900.0, jerk = 9000.0 }}\n"
    )
}

/// Seed 000 5.1.8: MC_ReadMotionFunction with NumPoints 0 reads every point from PointID on:
/// NumPointsRead (a third of the numbers shown: index, master, slave) is 6 from point 1, 2
/// from point 5; NumPoints 2 reads two; an array too small for all is refused (0x4B31).
#[test]
fn mc_read_motion_function_with_num_points_0_reads_every_point() {
    let read = |name: &str, inputs: &str| {
        format!(
            "[[step]]\nat_tick = 2\ncall = {{ block = \"MC_ReadMotionFunction\", \
             instance = \"{name}\", axis = 0, table = 1, {inputs} }}\n"
        )
    };
    let timeline = [
        read("all", "point_index = 1, num_points = 0, room = 16"),
        read("two", "point_index = 3, num_points = 2"),
        read("tail", "point_index = 5, num_points = 0"),
        read("small", "point_index = 1, num_points = 0, room = 4"),
        read("beyond", "point_index = 3, num_points = 10, room = 16"),
    ]
    .concat();
    let s = with_timeline("points.toml", SEED_ONLY, &timeline);
    let run = InProcess::run_through(&s).unwrap();
    let report = run.timeline.as_ref().unwrap().summary();
    // NumPoints beyond the function's end reads what there is (NumPointsRead smaller).
    for (name, points) in [("all", 6), ("two", 2), ("tail", 2), ("beyond", 4)] {
        assert!(done(&report, name), "{report}");
        assert_eq!(read_count(&report, name), 3 * points, "{name}: {report}");
    }
    let all = [
        1.0, 0.0, 0.0, 2.0, 30.0, 0.0, 3.0, 150.0, 20.0, 4.0, 240.0, 40.0,
    ];
    assert_eq!(read_values(&report, "all"), all);
    assert_eq!(read_values(&report, "two"), all[6..]);
    let tail = [5.0, 340.0, 0.0, 6.0, 360.0, 0.0];
    assert_eq!(read_values(&report, "tail"), tail);
    assert!(refused(&report, "small", "0x4b31"), "{report}");
}

/// CamTableGenerate (type 2, the wave), CamTableCoupleAxesIpol with `interpolation`, the drum
/// to 45: the pusher's position and MC_CamInfo's InterpolationType (field 3).
fn pusher_at_45(interpolation: u32) -> (f64, f64) {
    let timeline = format!(
        "[[step]]\nat_tick = 2\ncall = {{ block = \"CamTableGenerate\", instance = \"gen\", \
         axis = 1, table = 22, table_type = 2, rows = {:?} }}\n\
         [[step]]\nwait = \"gen.Done\"\ncall = {{ block = \"CamTableCoupleAxesIpol\", \
         instance = \"couple\", axis = 1, master = 0, table = 22, \
         interpolation = {interpolation}, master_absolute = true, slave_absolute = true }}\n{}",
        wave(),
        drum_to("couple", 45.0)
    );
    let s = with_timeline("ipol.toml", PUSHERS, &timeline);
    let mut run = InProcess::run_through(&s).unwrap();
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    assert_eq!(set(&run, MASTER).position, 45.0, "{report}");
    (set(&run, SLAVE).position, info_of(&mut run, SLAVE)[3])
}

/// Seed 000 5.2.2.2: CamTableCoupleAxesIpol's iIpolType 1 (4-point) and 2 (spline) give the
/// coupling its interpolation of the linear table: at 45 the pusher stands where the table
/// so interpolated does (by hand), not at the line's 5.0; MC_CamInfo says which.
#[test]
fn cam_table_couple_axes_ipol_couples_with_four_point_and_spline() {
    let by_hand = |interpolation| {
        let equidistant = cnc_core::cam::TableType::Equidistant;
        let t = cnc_core::cam::PositionTable::new(&wave(), equidistant, interpolation, true);
        cam_at(&CamProfile::Table(t.unwrap()), 45.0)
    };
    let four = by_hand(CamInterpolation::FourPoint);
    let spline = by_hand(CamInterpolation::Spline);
    assert!((four - 5.0).abs() > 0.1, "{four}");
    assert!((spline - 5.0).abs() > 0.1, "{spline}");
    assert!((four - spline).abs() > 1e-3, "{four} {spline}");
    for (interpolation, expected) in [(0, 5.0), (1, four), (2, spline)] {
        let (got, field_3) = pusher_at_45(interpolation);
        assert!(near(got, expected), "{interpolation}: {got} vs {expected}");
        assert_eq!(field_3, f64::from(interpolation), "InterpolationType");
    }
}

/// Seed 000 5.2.2.1: CamTableCoupleAxes' bMasterAbsolut / bSlaveAbsolut, the drum at 100: the
/// pusher coupled master-relative follows T(drum - 100), the second (at 5) coupled slave-
/// relative 5 + T(drum); MC_CamInfo's fields 9-13 show stroke, coupling positions and flags.
#[test]
fn cam_table_couple_axes_maps_its_absolute_flags_to_relative_sides() {
    // A zigzag of +-5 every 50 to 250, then up to 10 at 300: a stroke of 10.
    let rows = rows_every(50.0, &[0.0, 5.0, 0.0, -5.0, 0.0, 5.0, 10.0]);
    let timeline = format!(
        r#"[[step]]
at_tick = 2
call = {{ block = "CamTableGenerate", instance = "gen", axis = 1, table = 22, table_type = 1, rows = {rows:?} }}
[[step]]
wait = "gen.Done"
call = {{ block = "CamTableCoupleAxes", instance = "a", axis = 1, master = 0, table = 22, master_absolute = false, slave_absolute = true }}
[[step]]
wait = "a.Done"
call = {{ block = "CamTableCoupleAxes", instance = "b", axis = 2, master = 0, table = 22, master_absolute = true, slave_absolute = false }}
{}"#,
        drum_to("b", 250.0)
    );
    let toml = PUSHERS.replacen("name = \"Drum\"\n", "name = \"Drum\"\nstart = 100.0\n", 1);
    let s = with_timeline("flags.toml", &toml, &timeline);
    let mut run = InProcess::new(&s, 0).unwrap();
    let mut checked = 0;
    for _ in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        if [1, 2].map(|a| phase(&run, a)) != [AxisState::SlaveSynchronous; 2] {
            continue;
        }
        let m = set(&run, MASTER).position;
        let (a, b) = (set(&run, 1).position, set(&run, 2).position);
        assert!(near(a, lerp(&rows, m - 100.0)), "drum {m}: a {a}");
        assert!(near(b, 5.0 + lerp(&rows, m)), "drum {m}: b {b}");
        checked += 1;
    }
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    assert!(checked > 1000, "{checked}");
    assert_eq!(set(&run, MASTER).position, 250.0);
    // RawSlaveStroke, Master/SlaveAxisCouplingPos, MasterAbsolute, SlaveAbsolute.
    let a = info_of(&mut run, 1);
    assert_eq!(a[9..14], [10.0, 100.0, 0.0, 0.0, 1.0], "a: {a:?}");
    let b = info_of(&mut run, 2);
    assert_eq!(b[9..14], [10.0, 100.0, 5.0, 1.0, 0.0], "b: {b:?}");
}

/// Seed 000 5.2.1.1: CamTableGenerate replaces an uncoupled table of its ID (type 1, then 4),
/// type 4 is non-equidistant (11) and cyclic, 1 equidistant (10) and linear; the read and the
/// pusher coupled to 22 see the second data (at 130: 3 + 7 x 70/140 = 6.5; the first: 5).
#[test]
fn cam_table_generate_replaces_an_uncoupled_table_and_makes_types_1_and_4() {
    let timeline = format!(
        r#"[[step]]
at_tick = 2
call = {{ block = "CamTableGenerate", instance = "first", axis = 1, table = 22, table_type = 1, rows = {:?} }}
[[step]]
wait = "first.Done"
call = {{ block = "CamTableGenerate", instance = "second", axis = 1, table = 22, table_type = 4, rows = [[0, 0], [60, 3], [200, 10], [360, 0]] }}
[[step]]
wait = "second.Done"
call = {{ block = "CamTableGenerate", instance = "other", axis = 1, table = 23, table_type = 1, rows = [[0, 0], [120, 6], [240, 12]] }}
[[step]]
wait = "other.Done"
call = {{ block = "CamTableReadData", instance = "read", axis = 1, table = 22 }}
[[step]]
wait = "read.Done"
call = {{ block = "CamTableCoupleAxes", instance = "couple", axis = 1, master = 0, table = 22 }}
{}"#,
        wave(),
        drum_to("couple", 130.0)
    );
    let s = with_timeline("generate.toml", PUSHERS, &timeline);
    let mut run = InProcess::run_through(&s).unwrap();
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    let second = [0.0, 0.0, 60.0, 3.0, 200.0, 10.0, 360.0, 0.0];
    assert_eq!(read_values(&report, "read"), second);
    assert_eq!(set(&run, MASTER).position, 130.0);
    assert!(near(set(&run, SLAVE).position, 6.5));
    for expected in [(22, 4, 11, true), (23, 3, 10, false)] {
        let call = CamReadCall {
            what: CamReadKind::Characteristics.raw(),
            ..Default::default()
        };
        let (v, _) = read_all(&mut run, expected.0, call);
        let t = TableOrganisation::from_values(&v[31..]).unwrap();
        assert_eq!((t.table_id, t.rows, t.table_type, t.periodic), expected);
        assert_eq!(t.columns, 2);
    }
}

/// Seed 000 5.1.13 (l. 1969): MC_ReadMotionFunctionValues' array must have the columns its
/// ValueSelectMask asks for (master + one per bit): 3 for mask 3 and 5 for mask 15 read;
/// 2 and 4 are refused by the block with 0x4B37 without a call; no column count given reads.
#[test]
fn mc_read_motion_function_values_refuses_an_array_whose_columns_do_not_match_the_mask() {
    let read = |name: &str, mask: u32, columns: &str| {
        format!(
            "[[step]]\nat_tick = 2\ncall = {{ block = \"MC_ReadMotionFunctionValues\", \
             instance = \"{name}\", axis = 0, table = 1, value_select_mask = {mask}, \
             start_pos_master = 0.0, end_pos_master = 360.0, increment = 90.0{columns} }}\n"
        )
    };
    let timeline = [
        read("three", 3, ", columns = 3"),
        read("two", 3, ", columns = 2"),
        read("five", 15, ", columns = 5"),
        read("four", 15, ", columns = 4"),
        read("unsaid", 3, ""),
    ]
    .concat();
    let s = with_timeline("values.toml", SEED_ONLY, &timeline);
    let run = InProcess::run_through(&s).unwrap();
    let report = run.timeline.as_ref().unwrap().summary();
    for (name, count) in [("three", 15), ("five", 25), ("unsaid", 15)] {
        assert!(done(&report, name), "{report}");
        assert_eq!(read_count(&report, name), count, "{name}: {report}");
    }
    let seed = seed_cam();
    for row in read_values(&report, "three").chunks(3) {
        let s = seed.eval(row[0], &mut ProfileCursor::default());
        assert_eq!([row[1], row[2]], [s.position, s.velocity], "at {}", row[0]);
    }
    for name in ["two", "four"] {
        assert!(refused(&report, name, "0x4b37"), "{name}: {report}");
        let line = block_line(&report, name);
        assert!(!line.contains("Busy"), "refused without a call: {report}");
    }
}

/// CamTableReadData with rows to read 0 (seed 000 5.2.1.5; the block: "0: all") reads every
/// row, and the array's size still applies: 80 bytes hold the five rows, 72 or 32 do not
/// (0x4B31, found when the answer tells how many rows come).
#[test]
fn cam_table_read_data_of_all_rows_still_checks_the_arrays_size() {
    let read = |name: &str, inputs: &str| {
        format!(
            "[[step]]\nwait = \"table.Done\"\ncall = {{ block = \"CamTableReadData\", \
             instance = \"{name}\", axis = 0, table = 22{inputs} }}\n"
        )
    };
    let timeline = [
        format!(
            "[[step]]\nat_tick = 2\ncall = {{ block = \"CamTableGenerate\", \
             instance = \"table\", axis = 0, table = 22, rows = {:?} }}\n",
            wave()
        ),
        read("all", ", rows_to_read = 0"),
        read("fits", ", rows_to_read = 0, size = 80"),
        read("small", ", rows_to_read = 0, size = 72"),
        read("unsaid", ", size = 32"),
    ]
    .concat();
    let s = with_timeline("all_rows.toml", SEED_ONLY, &timeline);
    let run = InProcess::run_through(&s).unwrap();
    let report = run.timeline.as_ref().unwrap().summary();
    let numbers: Vec<f64> = wave().iter().flatten().copied().collect();
    for name in ["all", "fits"] {
        assert!(done(&report, name), "{report}");
        assert_eq!(read_values(&report, name), numbers, "{report}");
    }
    for name in ["small", "unsaid"] {
        assert!(refused(&report, name, "0x4b31"), "{name}: {report}");
    }
}
