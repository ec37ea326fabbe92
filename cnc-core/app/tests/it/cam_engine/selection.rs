//! The blocks in PLC timelines: MC_CamScaling with activation OFF beside a queued scaling,
//! MC_CamIn's interpolation override, reserve points switched on while a cam runs with
//! AxisCamDataQueued, and CamTableReadData's rows and array (seed 000).

use super::*;

/// The block: MC_CamScaling with ActivationMode "off" is Done as soon as the CNC took it,
/// while a NextCycle scaling queued before it waits for its cycle (and is Done then).
#[test]
fn mc_cam_scaling_off_is_done_at_once_beside_a_queued_scaling() {
    let timeline = r#"
[[step]]
at_tick = 2
call = { block = "CamTableGenerate", instance = "generate", axis = 1, table = 22, table_type = 2, rows = [[0.0, 0.0], [90.0, 9.0], [180.0, 0.0], [270.0, -9.0], [360.0, 0.0]] }
[[step]]
wait = "generate.Done"
call = { block = "CamTableCoupleAxesIpol", instance = "couple", axis = 1, master = 0, table = 22, interpolation = 0, master_absolute = true, slave_absolute = true }
[[step]]
wait = "couple.Done"
call = { block = "MC_MoveVelocity", instance = "turn", axis = 0, velocity = 180.0, direction = 1, acceleration = 1800.0, deceleration = 1800.0, jerk = 18000.0 }
[[step]]
at_tick = 600
call = { block = "MC_CamScaling", instance = "queued", axis = 1, activation_mode = "next_cycle", master_scaling_mode = "off", slave_scaling_mode = "user_defined", slave_scaling = 0.5 }
[[step]]
at_tick = 610
call = { block = "MC_CamScaling", instance = "off", axis = 1, activation_mode = "off", master_scaling_mode = "off", slave_scaling_mode = "user_defined", slave_scaling = 3.0 }
"#;
    let toml = "cycle_ms = 1.0\nticks = 3000\n\
        [[axis]]\nname = \"Drum\"\nkind = \"rotary\"\npower = true\n\
        [[axis]]\nname = \"Pusher\"\npower = true\nsoft_limits = [-50.0, 50.0]\n\
        following_error_limit = 5.0\n[plc]\ntimeline = \"plc.toml\"\n";
    let s = with_timeline("off.toml", toml, timeline);
    let run = InProcess::run_through(&s).unwrap();
    let summary = run.timeline.as_ref().unwrap().summary();
    let done_at = |name: &str| -> u64 {
        let line = block_line(&summary, name);
        let after = &line[line.find("Done ").unwrap_or_else(|| panic!("{line}")) + 5..];
        after.split_whitespace().next().unwrap().parse().unwrap()
    };
    let (off, queued) = (done_at("off"), done_at("queued"));
    assert!(off < 620, "done at once: {off}\n{summary}");
    assert!(
        queued > off + 100,
        "the queued one at its cycle: {queued}\n{summary}"
    );
    assert!(!summary.contains("ErrorID"), "{summary}");
}

/// MC_CamIn's InterpolationType overrides the table's for that coupling (seed 000 5.1.2): a
/// cyclic equidistant table stored linear, coupled once as it is and once with "spline", the
/// master moved to 45: the slave reads the linear 5.0, then the periodic spline's value there
/// (the kinematics of the table evaluated with the spline, by hand through `PositionTable`).
#[test]
fn mc_cam_in_interpolation_overrides_the_tables() {
    let rows = [
        [0.0, 0.0],
        [90.0, 10.0],
        [180.0, 0.0],
        [270.0, -10.0],
        [360.0, 0.0],
    ];
    let at_45 = |interpolation: &str| -> f64 {
        let timeline = format!(
            r#"
[[step]]
at_tick = 2
call = {{ block = "CamTableGenerate", instance = "generate", axis = 1, table = 22, table_type = 2, rows = [[0.0, 0.0], [90.0, 10.0], [180.0, 0.0], [270.0, -10.0], [360.0, 0.0]] }}
[[step]]
wait = "generate.Done"
call = {{ block = "MC_CamTableSelect", instance = "select", axis = 1, table = 22, periodic = true, master_absolute = true, slave_absolute = true }}
[[step]]
wait = "select.Done"
call = {{ block = "MC_CamIn", instance = "cam", axis = 1, master = 0, table = 22, start_mode = "absolute", interpolation = "{interpolation}" }}
[[step]]
wait = "cam.InSync"
call = {{ block = "MC_MoveAbsolute", instance = "go", axis = 0, position = 45.0, velocity = 90.0, acceleration = 900.0, deceleration = 900.0, jerk = 9000.0 }}
"#
        );
        let toml = "cycle_ms = 1.0\nticks = 3000\n\
            [[axis]]\nname = \"Drum\"\nkind = \"rotary\"\npower = true\n\
            [[axis]]\nname = \"Pusher\"\npower = true\nsoft_limits = [-50.0, 50.0]\n\
            following_error_limit = 5.0\n[plc]\ntimeline = \"plc.toml\"\n";
        let s = with_timeline("ipol.toml", toml, &timeline);
        let run = InProcess::run_through(&s).unwrap();
        let summary = run.timeline.as_ref().unwrap().summary();
        assert!(!summary.contains("ErrorID"), "{summary}");
        assert_eq!(set(&run, MASTER).position, 45.0);
        set(&run, SLAVE).position
    };
    assert!((at_45("linear") - 5.0).abs() < 1e-9);
    let spline = CamProfile::Table(
        cnc_core::cam::PositionTable::new(
            &rows,
            cnc_core::cam::TableType::Equidistant,
            hli::calls::cam::CamInterpolation::Spline,
            true,
        )
        .unwrap(),
    )
    .eval(45.0, &mut cnc_core::cam::ProfileCursor::default())
    .position;
    assert!(
        (spline - 5.0).abs() > 0.1,
        "the spline differs here: {spline}"
    );
    assert!((at_45("spline") - spline).abs() < 1e-9, "{spline}");
}

/// Reserve points (seed 000 3.1, 3.5): points laid in as IGNORE drop out of the cam, and are
/// switched on while it runs by writing another point type. The seed's six-point cam with
/// its points 3 and 4 as IGNORE keeps the slave at rest through the running cycle; written as
/// VELOCITY points at NextCycle (point 4 first: written alone, point 3's line would end in a
/// rest point), they apply at the cycle's end: in the next cycle the slave is
/// 20 at 150 and 40 at 240, as in the full cam, and nothing jumps at the wrap. From the first
/// write until then the slave's `AxisCamDataQueued` (its axis image's bit) is TRUE.
#[test]
fn reserve_points_switched_on_while_the_cam_runs_apply_at_the_next_cycle() {
    let json = std::fs::read_to_string(scenarios().join("cams/seed_example.json"))
        .unwrap()
        .replacen(
            "\"point_type\": \"VELOCITY\"",
            "\"point_type\": \"IGNORE\"",
            2,
        );
    assert_eq!(json.matches("IGNORE").count(), 2);
    let timeline = &format!(
        "{COUPLED_AND_RUNNING}{}",
        r#"
[[step]]
at_tick = 500
call = { block = "MC_SetCamOnlineChangeMode", instance = "mode", axis = 1, table = 1, activation_mode = "next_cycle" }
[[step]]
wait = "mode.Done"
call = { block = "MC_WriteMotionFunctionPoint", instance = "p4", axis = 1, table = 1, point_index = 4, function_type = 15, point_type = 2, master_pos = 240.0, slave_pos = 40.0 }
[[step]]
wait = "p4.Done"
call = { block = "MC_WriteMotionFunctionPoint", instance = "p3", axis = 1, table = 1, point_index = 3, function_type = 1, point_type = 2, master_pos = 150.0, slave_pos = 20.0 }
"#
    );
    let toml = "cycle_ms = 1.0\nticks = 3000\n\
        [[axis]]\nname = \"Conveyor\"\nkind = \"rotary\"\npower = true\nvelocity = 720.0\n\
        acceleration = 3600.0\ndeceleration = 3600.0\njerk = 36000.0\n\
        [[axis]]\nname = \"Lifter\"\npower = true\nsoft_limits = [-10.0, 100.0]\n\
        [[cam_table]]\nfile = \"seed_example.json\"\n[plc]\ntimeline = \"plc.toml\"\n";
    let s = Scenario::parse("reserve.toml", toml, |f| {
        let text = match f {
            "plc.toml" => timeline.to_string(),
            "seed_example.json" => json.clone(),
            other => panic!("{other}"),
        };
        Ok((PathBuf::from(f), text))
    })
    .unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let (mut first_cycle_max, mut seen, mut last): (f64, Vec<(f64, f64)>, f64) = (0.0, vec![], 0.0);
    let mut queued_at = Vec::new();
    for tick in 0..s.ticks.unwrap() {
        run.step(s.cycle_s);
        let (m, p) = (set(&run, MASTER).position, set(&run, SLAVE).position);
        // AxisCamDataQueued: from the write until the change applies at the cycle's end.
        let view = hli::views::PlcView::new(&run.memory);
        if plc_shim::blocks::cam::axis_cam_data_queued(&view, SLAVE) {
            queued_at.push((tick, m));
        }
        assert!((p - last).abs() < 0.5, "no jump: {last} -> {p} at {m}");
        last = p;
        if m < 360.0 {
            first_cycle_max = first_cycle_max.max(p.abs());
        } else if m < 720.0 {
            seen.push((m, p));
        }
    }
    let report = run.timeline.as_ref().unwrap().summary();
    assert!(!report.contains("ErrorID"), "{report}");
    assert_eq!(
        first_cycle_max, 0.0,
        "the reserves stay out in the running cycle"
    );
    let (first, last_queued) = (queued_at[0], *queued_at.last().unwrap());
    assert!(
        (503..=506).contains(&first.0),
        "queued from the write: {first:?}"
    );
    assert!(
        last_queued.1 < 360.0,
        "until the cycle's end: {last_queued:?}"
    );
    assert_eq!(
        queued_at.len() as u64,
        last_queued.0 - first.0 + 1,
        "without a gap"
    );
    let near = |x: f64| {
        seen.iter()
            .min_by(|a, b| (a.0 - x).abs().total_cmp(&(b.0 - x).abs()))
            .unwrap()
            .1
    };
    assert!((near(510.0) - 20.0).abs() < 0.5, "{}", near(510.0));
    assert!((near(600.0) - 40.0).abs() < 0.5, "{}", near(600.0));
}

/// CamTableReadData's rows to read and its array (seed 000 5.2.1.5): three of five rows read
/// just those; more rows than the table has is refused by the CNC (0x4B36); a column count
/// other than 2 (0x4B37) and rows that do not fit the array's size (0x4B31) are refused by
/// the block without a call.
#[test]
fn cam_table_read_data_reads_the_rows_asked_into_an_array_that_holds_them() {
    let scenario = "cycle_ms = 1.0\nticks = 40\n[[axis]]\nname = \"Lifter\"\npower = true\n\
        [plc]\ntimeline = \"plc.toml\"\n";
    let read = |name: &str, inputs: &str| {
        format!(
            "[[step]]\nwait = \"table.Done\"\ncall = {{ block = \"CamTableReadData\", \
             instance = \"{name}\", axis = 0, table = 22, {inputs} }}\n"
        )
    };
    let timeline = format!(
        "[[step]]\nat_tick = 2\ncall = {{ block = \"CamTableGenerate\", instance = \"table\", \
         axis = 0, table = 22, rows = [[0.0, 0.0], [90.0, 10.0], [180.0, 0.0], [270.0, -10.0], \
         [360.0, 0.0]] }}\n{}{}{}{}",
        read("three", "rows_to_read = 3"),
        read("six", "rows_to_read = 6"),
        read("columns", "rows_to_read = 3, columns = 3"),
        read("small", "rows_to_read = 3, size = 32"),
    );
    let s = with_timeline("rows.toml", scenario, &timeline);
    let run = InProcess::run_through(&s).unwrap();
    let report = run.timeline.as_ref().unwrap().summary();
    assert_eq!(
        super::data::read_values(&report, "three"),
        [0.0, 0.0, 90.0, 10.0, 180.0, 0.0],
        "{report}"
    );
    let line = |name: &str| block_line(&report, name);
    assert!(line("six").contains("ErrorID 0x4b36"), "{report}");
    assert!(line("columns").contains("ErrorID 0x4b37"), "{report}");
    assert!(line("small").contains("ErrorID 0x4b31"), "{report}");
    // Refused by the block: no Busy before the Error (no call was sent).
    assert!(!line("columns").contains("Busy"), "{report}");
}
