//! The data, multi-table and compatibility scenarios, and the cam blocks that read and write
//! table data in PLC timelines.

use super::*;

/// The numbers of a read block in the PLC's report.
pub(crate) fn read_values(report: &str, instance: &str) -> Vec<f64> {
    let mut lines = report.lines();
    lines
        .find(|l| l.starts_with(&format!("block {instance} ")))
        .unwrap_or_else(|| panic!("no block {instance}\n{report}"));
    let line = lines.next().unwrap_or("");
    let (_, values) = line
        .split_once(": ")
        .unwrap_or_else(|| panic!("{instance}: {line}"));
    values
        .split(", ")
        .filter(|v| *v != "...")
        .map(|v| v.parse().unwrap())
        .collect()
}

#[test]
fn the_data_scenario_loads_reads_and_writes_through_the_blocks() {
    let s = Scenario::load(&scenarios().join("cam-data/scenario.toml")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let mut followed = 0;
    for _ in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        if phase(&run, SLAVE) == AxisState::SlaveSynchronous {
            // The uploaded zigzag (0, 10, 0, -10, 0 every 90 degrees), linear, cyclic.
            let m = set(&run, MASTER).position.rem_euclid(360.0);
            let expected = match m {
                x if x < 90.0 => x / 9.0,
                x if x < 270.0 => 10.0 - (x - 90.0) / 9.0,
                x => -10.0 + (x - 270.0) / 9.0,
            };
            assert!(
                (set(&run, SLAVE).position - expected).abs() < 1e-9,
                "at {m}"
            );
            followed += 1;
        }
    }
    assert!(followed > 1000);
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    let seed = seed_cam();
    let s90 = seed.eval(90.0, &mut ProfileCursor::default());
    assert_eq!(
        read_values(&report, "dynamics"),
        vec![s90.position, s90.velocity, s90.acceleration]
    );
    // Positions every 45 degrees: 9 rows of master and slave (the first 12 numbers shown).
    let values = read_values(&report, "values");
    for row in values.chunks(2) {
        assert_eq!(
            row[1],
            seed.eval(row[0], &mut ProfileCursor::default()).position
        );
    }
    // Point 4 after MC_WriteMotionFunction: index, master, slave.
    assert_eq!(read_values(&report, "point4"), vec![4.0, 240.0, 30.0]);
    // MC_CamInfo: table 3, equidistant (10), cyclic, linear, 5 rows of 2 columns.
    assert_eq!(
        read_values(&report, "info")[..6],
        [3.0, 10.0, 1.0, 0.0, 5.0, 2.0]
    );
    assert!(run.machine.axes().axis(SLAVE).unwrap().coupling().is_none());
}

#[test]
fn the_multi_table_scenario_runs_start_work_correction_and_stop_tables() {
    let s = Scenario::load(&scenarios().join("cam-multi-table/scenario.toml")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    // By hand: the start table 0.2 per unit to 100; the work table 0.4 per unit from 20;
    // the correction bump (+0.2 per unit for 10, back for 10) from 350; the work table ends
    // at its boundary at 500 (the stop came at about 489) and the stop table adds 0.2 per
    // unit for 50 units from 180; then the feeder stands at 190.
    let bump = |d: f64| match d {
        d if (0.0..10.0).contains(&d) => 0.2 * d,
        d if (10.0..20.0).contains(&d) => 2.0 - 0.2 * (d - 10.0),
        _ => 0.0,
    };
    let expected = |pm: f64| match pm {
        pm if pm < 100.0 => 0.2 * pm,
        pm if pm < 500.0 => 20.0 + 0.4 * (pm - 100.0) + bump(pm - 350.0),
        pm if pm < 550.0 => 180.0 + 0.2 * (pm - 500.0),
        _ => 190.0,
    };
    let mut coupled_ticks = 0;
    for _ in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let feeder = run.machine.axes().axis(SLAVE).unwrap();
        if feeder.coupling().map(|c| c.kind) != Some(CouplingState::Cam) {
            continue;
        }
        coupled_ticks += 1;
        let pm = set(&run, MASTER).position;
        let f = set(&run, SLAVE).position;
        assert!(
            (f - expected(pm)).abs() < 1e-9,
            "line {pm}: feeder {f}, expected {}",
            expected(pm)
        );
    }
    assert!(coupled_ticks > 7000, "{coupled_ticks}");
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    assert!(run.machine.axes().axis(SLAVE).unwrap().coupling().is_none());
    assert_eq!(set(&run, SLAVE).position, 190.0);
}

#[test]
fn the_compatibility_blocks_make_read_couple_rescale_and_delete() {
    let s = Scenario::load(&scenarios().join("cam-compat/scenario.toml")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    // The generated zigzag, linear: +-9 per turn, doubled, shifted by 0.5 from tick 1500.
    let mut checked = 0;
    for tick in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let coupled = run.machine.axes().axis(SLAVE).unwrap().coupling().is_some();
        if coupled && (1600..3000).contains(&tick) {
            let m = set(&run, MASTER).position;
            let expected = 0.5 + 2.0 * zigzag(m);
            assert!(
                (set(&run, SLAVE).position - expected).abs() < 1e-9,
                "tick {tick}, drum {m}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 1400);
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    assert_eq!(
        read_values(&report, "read"),
        vec![0.0, 0.0, 40.0, 4.0, 100.0, 5.0]
    );
    // Non-equidistant: the slave position only (seed 5.1.7).
    assert_eq!(read_values(&report, "slavepos"), vec![2.0, 0.0, 0.0]);
    for (done, kind) in [
        ("release", "CamTableCoupleAxes"),
        ("delete21", "CamTableDelete"),
        ("delete22", "CamTableDelete"),
    ] {
        assert!(
            report.contains(&format!("block {done} ({kind} on gpAx[1]): Done")),
            "{report}"
        );
    }
    assert!(run.machine.axes().axis(SLAVE).unwrap().coupling().is_none());
}

/// Seed 000 4.6.3/4.6.4, "scale, then activate", through the engine: while the multi-table
/// scenario's work table runs, CamTableSetWeight doubles the stop table's slave slope (the
/// stop table is not active yet: accepted) and is refused for the work table (active: 0x4268,
/// nothing changed). The stop table then adds 20 instead of 10, and the feeder stands at 200.
#[test]
fn a_multi_table_coupling_takes_the_scaling_of_a_table_not_yet_active() {
    use hli::calls::cam::CamTableWeightCall;
    let s = Scenario::load(&scenarios().join("cam-multi-table/scenario.toml")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    for _ in 0..3000 {
        run.step(s.cycle_s);
    }
    let pm = set(&run, MASTER).position;
    assert!(
        pm > 150.0 && pm < 400.0,
        "the work table runs: line at {pm}"
    );
    let steeper = CamTableWeightCall {
        slave_slope: 2.0,
        range_low: 100_000.0,
        range_high: 200_000.0,
        ..CamTableWeightCall::default()
    };
    let weight = |run: &mut InProcess, table: u32, w: &CamTableWeightCall| {
        bytemuck::pod_read_unaligned::<CamReply>(&dispatch_raw(run, table, w)).error_id
    };
    assert_eq!(
        weight(&mut run, 13, &steeper),
        0,
        "the stop table, not active yet"
    );
    let work = CamTableWeightCall {
        slave_slope: 3.0,
        ..CamTableWeightCall::default()
    };
    assert_eq!(
        weight(&mut run, 12, &work),
        CamCouplingError::TableInUse.raw()
    );
    for _ in 3000..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let pm = set(&run, MASTER).position;
        let f = set(&run, SLAVE).position;
        // The work table as before (its scaling kept), the stop table at slope 0.4 per unit.
        if (400.0..500.0).contains(&pm) {
            assert!(
                (f - (20.0 + 0.4 * (pm - 100.0))).abs() < 1e-9,
                "line {pm}: {f}"
            );
        }
        if (500.0..550.0).contains(&pm) {
            assert!(
                (f - (180.0 + 0.4 * (pm - 500.0))).abs() < 1e-9,
                "line {pm}: {f}"
            );
        }
    }
    assert!(run.machine.axes().axis(SLAVE).unwrap().coupling().is_none());
    assert_eq!(set(&run, SLAVE).position, 200.0);
}

/// The machine of the compatibility tests: a drum and a pusher, single axes 0 and 1 with
/// NC axis IDs 7 and 9.
const DRUM_AND_PUSHER: &str = "cycle_ms = 1.0\nticks = 3000\n\
    [[axis]]\nname = \"Drum\"\nid = 7\nkind = \"rotary\"\npower = true\n\
    [[axis]]\nname = \"Pusher\"\nid = 9\npower = true\nsoft_limits = [-50.0, 50.0]\n\
    following_error_limit = 5.0\n[plc]\ntimeline = \"plc.toml\"\n";

/// CamTableGenerate, CamTableCoupleAxesIpol, CamTableOffsetChange, CamTableSetSlaveScale and
/// MC_MoveVelocity in a row; `pusher` and `drum` address the axes (`axis = 1` or
/// `axis_id = 9`; `master = 0` or `master_id = 7`).
fn slave_scale_timeline(pusher: &str, drum: &str, master: &str) -> String {
    format!(
        r#"
[[step]]
at_tick = 2
call = {{ block = "CamTableGenerate", instance = "generate", {pusher}, table = 22, table_type = 2, rows = [[0.0, 0.0], [90.0, 9.0], [180.0, 0.0], [270.0, -9.0], [360.0, 0.0]] }}
[[step]]
wait = "generate.Done"
call = {{ block = "CamTableCoupleAxesIpol", instance = "couple", {pusher}, {master}, table = 22, interpolation = 0, master_absolute = true, slave_absolute = true }}
[[step]]
wait = "couple.Done"
call = {{ block = "CamTableOffsetChange", instance = "shift", {pusher}, master_offset = 30.0, slave_offset = 0.5 }}
[[step]]
wait = "shift.Done"
call = {{ block = "CamTableSetSlaveScale", instance = "slave", {pusher}, slave_slope = 3.0 }}
[[step]]
wait = "slave.Done"
call = {{ block = "MC_MoveVelocity", instance = "turn", {drum}, velocity = 180.0, direction = 1, acceleration = 1800.0, deceleration = 1800.0, jerk = 18000.0 }}
"#
    )
}

/// Runs the slave-scale timeline; every tick after the drum turns, the pusher follows
/// 0.5 + 3 x zigzag(drum + 30).
fn run_slave_scale(timeline: &str) {
    let s = with_timeline("slave-scale.toml", DRUM_AND_PUSHER, timeline);
    let mut run = InProcess::new(&s, 0).unwrap();
    let mut checked = 0;
    for tick in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        if tick > 1000 && set(&run, MASTER).velocity > 0.0 {
            let m = set(&run, MASTER).position;
            let expected = 0.5 + 3.0 * zigzag(m + 30.0);
            assert!(
                (set(&run, SLAVE).position - expected).abs() < 1e-9,
                "tick {tick}, drum {m}: {}",
                set(&run, SLAVE).position
            );
            checked += 1;
        }
    }
    assert!(checked > 1500, "{checked}");
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
}

/// CamTableSetSlaveScale (a compatibility block): only the slave's scaling changes, at once;
/// the master and slave offsets a CamTableOffsetChange set before, and the master scaling,
/// stay. The pusher then follows 0.5 + 3 x zigzag(drum + 30).
#[test]
fn cam_table_set_slave_scale_changes_the_slave_scaling_alone() {
    run_slave_scale(&slave_scale_timeline("axis = 1", "axis = 0", "master = 0"));
}

/// Every block addresses its axis, and a coupling its master, by NC axis ID as well as by
/// image index (issue 37 item 7): the same run with `axis_id` and `master_id` only.
#[test]
fn blocks_address_axes_by_their_nc_axis_id() {
    run_slave_scale(&slave_scale_timeline(
        "axis_id = 9",
        "axis_id = 7",
        "master_id = 7",
    ));
    // IDs the machine does not have, or a channel's, are refused when the scenario is read.
    let refused = |timeline: &str| {
        let s = with_timeline_result("ids.toml", DRUM_AND_PUSHER, timeline);
        s.expect_err("refused")
    };
    let call = |keys: &str| {
        format!("[[step]]\nat_tick = 2\ncall = {{ block = \"CamTableCoupleAxes\", {keys} }}\n")
    };
    let e = refused(&call("axis_id = 9, master_id = 8"));
    assert!(e.contains("`master_id` = 8: no axis has that ID"), "{e}");
    let e = refused(&call("axis_id = 12, master = 0"));
    assert!(e.contains("`axis_id` = 12: no axis has that ID"), "{e}");
    let e = refused(&call("axis_id = 9, axis = 1"));
    assert!(e.contains("`axis_id` or the axis index, not both"), "{e}");
    let e = refused(&call("axis_id = 9, master_id = 7, master = 0"));
    assert!(
        e.contains("`master_id` or the master's index, not both"),
        "{e}"
    );
    let e = refused(
        "[[step]]\nat_tick = 2\ncall = { block = \"MC_Halt\", axis_id = 9, master_id = 7 }\n",
    );
    assert!(e.contains("MC_Halt has no master"), "{e}");
}

/// MC_ReadCamTableCharacteristics with its `master_velocity` input in a timeline: the values
/// for a master running backwards at 2 units/s (seed 000 3.4's rescaling on the PLC path).
#[test]
fn the_characteristics_block_reads_values_rescaled_to_a_master_velocity() {
    let scenario = "cycle_ms = 1.0\nticks = 20\n[[axis]]\nname = \"Lifter\"\npower = true\n\
        [[cam_table]]\nfile = \"seed_example.json\"\n[plc]\ntimeline = \"plc.toml\"\n";
    let timeline = "[[step]]\nat_tick = 2\ncall = { block = \"MC_ReadCamTableCharacteristics\", \
        instance = \"charac\", axis = 0, table = 1, master_velocity = -2.0 }\n";
    let s = with_timeline("charac.toml", scenario, timeline);
    let mut run = InProcess::new(&s, 0).unwrap();
    for _ in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
    }
    let report = run.timeline.as_ref().unwrap().summary();
    let got = read_values(&report, "charac");
    let expected = cnc_core::cam::CharacValues::normed(&seed_cam())
        .rescaled(-2.0)
        .unwrap();
    let fields = expected.fields();
    assert_eq!(got[0], -2.0, "fMasterVeloNom: {report}");
    for (k, value) in got.iter().enumerate() {
        assert_eq!(*value, fields[k].1, "{}", fields[k].0);
    }
}

/// The tick of the first rising edge of `output` of `instance` in the PLC's report.
fn first_edge(report: &str, instance: &str, output: &str) -> u64 {
    let line = block_line(report, instance);
    let (_, after) = line
        .split_once(&format!("{output} "))
        .unwrap_or_else(|| panic!("{instance}: no {output}: {line}"));
    after.split(' ').next().unwrap().parse().unwrap()
}

/// iBlockSize of the compatibility blocks (seed 000 5.2.1): CamTableGenerate with 32 bytes
/// sends two rows per call (four calls for eight rows, where the default sends one), and
/// CamTableReadData with 16 bytes reads one row per part; the table arrives and reads back
/// the same either way. Both also take a tTimeout.
#[test]
fn a_block_size_sets_how_much_each_step_of_a_compatibility_block_moves() {
    let scenario = "cycle_ms = 1.0\nticks = 60\n[[axis]]\nname = \"Lifter\"\npower = true\n\
        [plc]\ntimeline = \"plc.toml\"\n";
    let rows = "[[0.0, 0.0], [10.0, 1.0], [20.0, 4.0], [30.0, 9.0], [40.0, 16.0], \
        [50.0, 25.0], [60.0, 36.0], [70.0, 49.0]]";
    let timeline = format!(
        "[[step]]\nat_tick = 2\ncall = {{ block = \"CamTableGenerate\", instance = \"whole\", \
         axis = 0, table = 21, rows = {rows} }}\n\
         [[step]]\nat_tick = 2\ncall = {{ block = \"CamTableGenerate\", instance = \"pairs\", \
         axis = 0, table = 22, rows = {rows}, block_size = 32, timeout_cycles = 100 }}\n\
         [[step]]\nwait = \"pairs.Done\"\ncall = {{ block = \"CamTableReadData\", \
         instance = \"read\", axis = 0, table = 22 }}\n\
         [[step]]\nwait = \"pairs.Done\"\ncall = {{ block = \"CamTableReadData\", \
         instance = \"row_by_row\", axis = 0, table = 22, block_size = 16, \
         timeout_cycles = 100 }}\n"
    );
    let s = with_timeline("block_size.toml", scenario, &timeline);
    let mut run = InProcess::new(&s, 0).unwrap();
    for _ in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
    }
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    let (whole, pairs) = (
        first_edge(&report, "whole", "Done"),
        first_edge(&report, "pairs", "Done"),
    );
    assert!(pairs >= whole + 3, "four calls, not one: {report}");
    let (read, row_by_row) = (
        first_edge(&report, "read", "Done"),
        first_edge(&report, "row_by_row", "Done"),
    );
    assert!(row_by_row >= read + 6, "eight parts, not one: {report}");
    let expected = [
        0.0, 0.0, 10.0, 1.0, 20.0, 4.0, 30.0, 9.0, 40.0, 16.0, 50.0, 25.0,
    ];
    assert_eq!(read_values(&report, "read"), expected, "{report}");
    assert_eq!(read_values(&report, "row_by_row"), expected, "{report}");
    // All 16 numbers came, the last part too (the report shows the first 12).
    for instance in ["read", "row_by_row"] {
        let line = format!("block {instance} ");
        let at = report.find(&line).unwrap();
        assert!(report[at..].contains("read 16 value(s)"), "{report}");
    }
}
