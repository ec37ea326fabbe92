//! Channels of any axes: a 3-axis mill (X Y Z), a 5-axis machine (X Y Z A C), axes besides
//! the pose ones; what such a channel keeps per slot, and what it refuses (words, arcs,
//! `#TRAFO` and a tracked motion on axes it lacks; kinematics without their joints).

use tests::channel_rig as support;

use cnc_core::channel::{Channel, ChannelConfig, ChannelError, RunState};
use cnc_core::nc::check::check_source;
use cnc_core::nc::decode::AxisLayout;
use hli::enums::DynCsState;
use hli::views::{CncView, PlcView};
use support::{controller, cs, image, run_to_end, stiff, CYCLE};

fn names(axes: &[&str]) -> Vec<String> {
    axes.iter().map(|a| a.to_string()).collect()
}

fn channel(axes: &[&str]) -> ChannelConfig {
    stiff(ChannelConfig::new("c", axes))
}

/// The messages of `src` checked for a channel of `axes`, with their line and column.
fn refusals(src: &str, axes: &[&str]) -> Vec<(u32, u32, String)> {
    let (diags, _) = check_source(src, &names(axes));
    diags
        .into_iter()
        .map(|d| (d.line, d.col, d.message))
        .collect()
}

#[test]
fn the_layout_puts_pose_axes_in_their_slots_and_the_others_after_them() {
    let six = AxisLayout::new(&names(&["X", "Y", "Z", "A", "B", "C", "X1"]));
    assert_eq!(
        six.slots(),
        &[0, 1, 2, 3, 4, 5, 6],
        "X..C first: kept as configured"
    );
    let mill = AxisLayout::new(&names(&["X", "Y", "Z"]));
    assert_eq!(mill.slots(), &[0, 1, 2]);
    assert_eq!(mill.len(), 6);
    assert_eq!(mill.missing_pose(), "A B C");
    assert!(!mill.has_pose() && mill.has(2) && !mill.has(3));
    let five = AxisLayout::new(&names(&["X", "Y", "Z", "A", "C", "U"]));
    assert_eq!(five.slots(), &[0, 1, 2, 3, 5, 6]);
    assert_eq!(five.missing_pose(), "B");
    let named = AxisLayout::new(&names(&["AM", "AH", "AA", "A", "B", "C"]));
    assert_eq!(named.slots(), &[0, 1, 2, 3, 4, 5], "six axes: by place");
    assert!(named.has_pose());
    let swapped = AxisLayout::new(&names(&["Y", "X", "Z", "A", "B", "C"]));
    assert_eq!(
        swapped.slots(),
        &[1, 0, 2, 3, 4, 5],
        "by name, not by place"
    );
    assert!(swapped.has_pose());
}

#[test]
fn a_three_axis_mill_runs_lines_and_an_arc_on_x_y_z() {
    let mut ctl = controller(vec![(
        channel(&["X", "Y", "Z"]),
        "G1 X10 Y0 F6000\nG2 X0 Y-10 I-10 J0\nG1 Z-5\nG91 X2.5\nM30\n",
    )]);
    let memory = image(1);
    run_to_end(&mut ctl, &memory, 20_000);
    let c = &ctl.channels()[0];
    assert_eq!(c.layout().slots(), &[0, 1, 2]);
    let p = c.set_points();
    assert_eq!(p.len(), 6, "six pose slots");
    for (i, want) in [2.5, -10.0, -5.0, 0.0, 0.0, 0.0].into_iter().enumerate() {
        assert!((p[i] - want).abs() < 1e-9, "slot {i}: {} vs {want}", p[i]);
    }
}

#[test]
fn a_five_axis_channel_moves_a_and_c_in_their_slots_and_refuses_b() {
    let axes = ["X", "Y", "Z", "A", "C"];
    let mut ctl = controller(vec![(channel(&axes), "G1 X5 A30 C45 F6000\nM30\n")]);
    run_to_end(&mut ctl, &image(1), 20_000);
    let p = ctl.channels()[0].set_points();
    assert_eq!(&p[..6], &[5.0, 0.0, 0.0, 30.0, 0.0, 45.0]);
    let found = refusals("G1 X5 B10 F100\n", &axes);
    assert_eq!(found.len(), 1, "{found:?}");
    let (line, col, message) = &found[0];
    assert_eq!((*line, *col), (1, 7));
    assert!(
        message.contains("unknown axis \"B\"") && message.contains("(axes: X Y Z A C)"),
        "{message}"
    );
}

#[test]
fn arcs_and_a_transformation_need_the_axes_they_move() {
    let found = refusals("G18\nG2 X10 I5 F100\n", &["X", "Y"]);
    assert!(
        found
            .iter()
            .any(|(l, _, m)| *l == 2 && m.contains("both axes of its plane")),
        "{found:?}"
    );
    assert!(
        refusals("G17\nG2 X10 Y0 I5 J0 F100\n", &["X", "Y"]).is_empty(),
        "G17 on X Y is fine"
    );
    // A tool length needs the plane's normal axis (G17: Z).
    let mut xy = channel(&["X", "Y"]);
    xy.nc.tools = support::tools("{ d = 1, length = 50.0 }, { d = 2, length = 0.0 }");
    let load = |src: &str| {
        cnc_core::channel::LoadedProgram::load_with(
            "xy",
            src,
            &xy.axes,
            &xy.nc.setup(),
            None,
            &cnc_core::nc::interp::SearchPath::default(),
        )
        .map(|_| ())
        .map_err(|e| e.to_string())
    };
    let e = load("G1 X1 F100\nD1\n").unwrap_err();
    assert!(
        e.contains(":2:1:") && e.contains("which this channel lacks"),
        "{e}"
    );
    assert_eq!(
        load("D2\nG1 X1 F100\n"),
        Ok(()),
        "a tool without a length is fine"
    );
    let found = refusals("G1 X1 F100\n#TRAFO ON\n", &["X", "Y", "Z"]);
    assert!(
        found
            .iter()
            .any(|(l, c, m)| (*l, *c) == (2, 1) && m.contains("#TRAFO ON needs the six pose axes")),
        "{found:?}"
    );
}

#[test]
fn zero_offsets_and_start_positions_are_given_in_configuration_order() {
    let mut config = channel(&["X", "Y", "Z", "U"]);
    config.nc.zero_offsets.g54 = vec![1.0, 2.0, 3.0, 4.0];
    config.start = vec![0.0, 0.0, 0.0, 7.0];
    let c = Channel::new(0, config.clone(), CYCLE).unwrap();
    assert_eq!(c.layout().slots(), &[0, 1, 2, 6]);
    assert_eq!(c.set_points()[6], 7.0, "U starts in its slot");
    let mut ctl = controller(vec![(config, "G54 G0 X0 Y0 Z0 U0\nM30\n")]);
    run_to_end(&mut ctl, &image(1), 20_000);
    let p = ctl.channels()[0].set_points();
    assert_eq!(&p[..], &[1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 4.0]);
}

#[test]
fn a_kinematic_without_its_joints_and_too_many_axes_are_refused_at_load() {
    let mut robot = channel(&["X", "Y", "Z"]);
    robot.kinematics.id = 45;
    let e = Channel::new(0, robot, CYCLE).unwrap_err().to_string();
    assert_eq!(
        e,
        "channel c: axes: kinematic 45 needs X Y Z A B C as its six joints, missing: A B C"
    );
    // C out of its place: the pose slots by name, the 11 others behind all six.
    let many: Vec<String> = ["X", "Y", "Z", "C"]
        .into_iter()
        .map(String::from)
        .chain((1..=11).map(|i| format!("U{i}")))
        .collect();
    let refs: Vec<&str> = many.iter().map(String::as_str).collect();
    let e = Channel::new(0, channel(&refs), CYCLE)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("11 axes besides X Y Z A B C take 17 places"),
        "{e}"
    );
    assert!(Channel::new(0, channel(&refs[..14]), CYCLE).is_ok());
    // Sixteen axes in place are sixteen slots.
    let in_place: Vec<String> = (1..=16).map(|i| format!("U{i}")).collect();
    let refs: Vec<&str> = in_place.iter().map(String::as_str).collect();
    assert!(Channel::new(0, channel(&refs), CYCLE).is_ok());
}

/// A 3-axis channel follows a master's translation; a master that turns needs axes it lacks:
/// the channel fails naming the axis, the slot stays at 0 and the axes come to rest.
#[test]
fn a_three_axis_channel_tracks_a_translation_and_stops_on_a_rotation() {
    let mut ctl = controller(vec![(
        channel(&["X", "Y", "Z"]),
        "#TRACK CS ON [ID=0 FILTER=0 WAIT]\n#TIME 5\nM30\n",
    )]);
    let memory = image(1);
    let view = CncView::new(&memory);
    let plc = PlcView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    let send = |x: f64, c_deg: f64| {
        let mut frame = cs([(x * 1e4).round() as i32, 0, 0]);
        frame.rotation[2] = (c_deg * 1e4).round() as i32;
        plc.dyn_cs_command(0).unwrap().try_send(&frame).unwrap();
    };
    for tick in 0..400u32 {
        send(f64::from(tick) * 0.01, 0.0);
        ctl.tick(&view);
    }
    let ch = &ctl.channels()[0];
    assert_eq!(ch.tracker().state(), DynCsState::Active, "{:?}", ch.error());
    assert!(
        (ch.set_points()[0] - 3.99).abs() < 1e-3,
        "{}",
        ch.set_points()[0]
    );
    let mut stopped_at = None;
    for tick in 0..2000u32 {
        send(4.0, f64::from(tick.min(100)) * 0.01);
        ctl.tick(&view);
        let ch = &ctl.channels()[0];
        assert!(
            ch.set_points()[3..6].iter().all(|&v| v == 0.0),
            "A B C stay 0"
        );
        if stopped_at.is_none() && ch.state() == RunState::Error {
            stopped_at = Some(tick);
        }
        if stopped_at.is_some() && !ch.is_moving() {
            break;
        }
    }
    let ch = &ctl.channels()[0];
    assert!(stopped_at.is_some(), "the rotation stops the channel");
    assert!(!ch.is_moving(), "at rest");
    let error: &ChannelError = ch.error().unwrap();
    let text = error.to_string();
    assert!(
        text.contains("needs axis C, which this channel lacks"),
        "{text}"
    );
}
