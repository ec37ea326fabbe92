//! The seed's four application examples as scenarios (`scenarios/`), run in-process in
//! lockstep (CNC tick, trace sample, PLC timeline cycle), each checked on its physical outcome.

use cnc_app::scenario::{InProcess, Scenario};
use cnc_core::channel::{Channel, RunState};
use hli::enums::DynCsState;
use kinematics::frame::offset_frame;
use kinematics::PoseWords;
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

fn scenario(name: &str) -> Scenario {
    Scenario::load(&tests::cli::scenario(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs until every channel stopped (or `ticks` when given); fails on a channel error or when
/// the watchdog of `limit` ticks trips.
fn run(
    s: &Scenario,
    limit: u64,
    ticks: Option<u64>,
    mut each: impl FnMut(&InProcess, u64),
) -> InProcess {
    let mut run = InProcess::new(s, limit as usize).unwrap();
    for tick in 0..limit {
        run.step(s.cycle_s);
        for c in run.machine.controller().channels() {
            assert_ne!(
                c.state(),
                RunState::Error,
                "channel {} stopped: {:?}",
                c.config().name,
                c.error()
            );
        }
        each(&run, tick);
        let done = match ticks {
            Some(n) => tick + 1 >= n,
            None => run.machine.idle(),
        };
        if done {
            return run;
        }
    }
    panic!("watchdog: {} not done after {limit} ticks", s.name);
}

fn channel<'a>(run: &'a InProcess, name: &str) -> &'a Channel {
    run.machine
        .controller()
        .channels()
        .iter()
        .find(|c| c.config().name == name)
        .unwrap()
}

fn frame(xyz: [f64; 3], abc: [f64; 3]) -> Isometry3<f64> {
    offset_frame(&PoseWords { xyz, abc }, false).unwrap()
}

/// Example 3: both slaves hold their points on the workpiece the master moves, to 1 um.
#[test]
fn example_3_two_slaves_stay_on_the_moving_workpiece() {
    let s = scenario("example3-moving-workpiece");
    let left = frame([400.0, 700.0, 0.0], [0.0, 0.0, -90.0]);
    let right = frame([400.0, -700.0, 0.0], [0.0, 0.0, 90.0]);
    let right_point = Isometry3::translation(0.0, 30.0, 0.0);
    let (mut checked, mut worst, mut travel) = (0, 0.0f64, 0.0f64);
    let mut last: Option<Vector3<f64>> = None;
    let done = run(&s, 60_000, None, |run, _| {
        let m = channel(run, "master");
        let (l, r) = (channel(run, "slave-left"), channel(run, "slave-right"));
        let holding = |c: &Channel| c.tracker().state() == DynCsState::Active && !c.is_moving();
        if !(holding(l) && holding(r) && m.is_moving()) {
            return;
        }
        let master_tool = m.tool_pose();
        for (slave, expected) in [
            (l, left * master_tool),
            (r, right * master_tool * right_point),
        ] {
            let tool = slave.tool_pose();
            worst = worst.max((tool.translation.vector - expected.translation.vector).norm());
            let turn = tool.rotation.angle_to(&expected.rotation);
            assert!(
                turn < 1e-6,
                "{}: orientation off by {turn} rad",
                slave.config().name
            );
        }
        if let Some(p) = last {
            travel += (master_tool.translation.vector - p).norm();
        }
        last = Some(master_tool.translation.vector);
        checked += 1;
    });
    assert!(
        checked > 1000,
        "the workpiece moved for {checked} ticks only"
    );
    assert!(travel > 150.0, "the workpiece moved {travel} mm");
    assert!(worst < 1e-3, "a slave left the workpiece by {worst} mm");
    for slave in ["slave-left", "slave-right"] {
        let tracker = channel(&done, slave).tracker();
        assert_eq!(
            tracker.state(),
            DynCsState::Inactive,
            "{slave} let go softly"
        );
    }
    for c in done.machine.controller().channels() {
        assert_eq!(c.state(), RunState::Finished, "{}", c.config().name);
    }
    // The trace holds the slaves' ACTIVE state (2) while the master moved.
    let states: Vec<_> = done
        .trace
        .column("gpCh[1]^channel_mc_control.dyn_cs.state_r.actual_state")
        .unwrap()
        .collect();
    assert!(states.iter().any(|v| v.as_f64() == 2.0));
}

/// Example 4: the tool point circles with the turntable about its centre (600 mm in front of
/// the robot) by the angle the PLC commanded, keeps its orientation (OPTION=1), and so draws
/// the programmed square on the turning workpiece. The PLC reads the table axis after tick N
/// and the CNC applies that angle in tick N+1: against the angle of the same tick the tool
/// lags by at most one tick of table motion.
fn turntable(name: &str) {
    let s = scenario(name);
    // The manual's table centre, 1305.92 mm in front of the robot.
    let centre = Vector3::new(1305.92, 0.0, 0.0);
    let mut previous_table = 0.0;
    let (mut checked, mut worst, mut worst_same_tick) = (0, 0.0f64, 0.0f64);
    let mut max_table_step = 0.0f64;
    let done = run(&s, 60_000, None, |run, _| {
        let robot = channel(run, "robot");
        let table = robot.set_points()[6];
        let step = (table - previous_table).abs();
        if robot.tracker().state() == DynCsState::Active {
            let rotate_about_centre = |deg: f64, p: &Vector3<f64>| {
                let r = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), deg.to_radians());
                centre + r * (p - centre)
            };
            let pose_in = robot.pose_in();
            let tool = robot.tool_pose();
            let expected = rotate_about_centre(previous_table, &pose_in.translation.vector);
            worst = worst.max((tool.translation.vector - expected).norm());
            let same_tick = rotate_about_centre(table, &pose_in.translation.vector);
            worst_same_tick = worst_same_tick.max((tool.translation.vector - same_tick).norm());
            let turn = tool.rotation.angle_to(&pose_in.rotation);
            assert!(turn < 1e-6, "OPTION=1 keeps the orientation: {turn} rad");
            max_table_step = max_table_step.max(step);
            checked += 1;
        }
        previous_table = table;
    });
    // A switch-off without a filter shows DEACTIVATING for its tick: one more tick settles it.
    let mut done = done;
    done.step(s.cycle_s);
    let robot = channel(&done, "robot");
    assert_eq!(robot.state(), RunState::Finished);
    assert!((robot.set_points()[6] + 90.0).abs() < 1e-9, "table at -90");
    assert!(checked > 5000, "tracked for {checked} ticks");
    assert!(worst < 1e-3, "tool off the turning workpiece by {worst} mm");
    // One tick of table motion at the farthest point of the square (85 mm from the centre).
    let lag_bound = 86.0 * max_table_step.to_radians() + 1e-3;
    assert!(
        worst_same_tick <= lag_bound,
        "lag {worst_same_tick} mm > {lag_bound} mm"
    );
    assert!(worst_same_tick > 0.0, "the table moved while tracked");
    assert_eq!(robot.tracker().state(), DynCsState::Inactive);
}

#[test]
fn example_4_hybrid_the_robot_machines_the_turning_workpiece() {
    turntable("example4-turntable-hybrid");
}

#[test]
fn example_4_plc_only_the_plc_switches_the_tracking_through_the_transition() {
    turntable("example4-turntable-plc");
    // Both M functions were acknowledged by the timeline, each once.
    let s = scenario("example4-turntable-plc");
    let done = run(&s, 60_000, None, |_, _| {});
    assert_eq!(channel(&done, "robot").m_functions_acked(), 2);
    let records = done.timeline.as_ref().unwrap().records();
    assert_eq!(records[1].fired, 1, "M100 once");
    assert_eq!(records[2].fired, 1, "M101 once");
}

#[test]
fn lockstep_runs_are_identical() {
    let s = scenario("example4-turntable-plc");
    let csv = |run: &InProcess| {
        let mut out = Vec::new();
        run.trace.write_csv(&mut out).unwrap();
        out
    };
    let a = run(&s, 60_000, Some(4000), |_, _| {});
    let b = run(&s, 60_000, Some(4000), |_, _| {});
    assert_eq!(a.trace.len(), 4000);
    assert_eq!(csv(&a), csv(&b));
}

/// Example 2: the PLC reports a base error D; with KIN_BASE the channel commands D^-1, so the
/// real tool (the swayed base D carrying the commanded pose) is on the programmed point. The
/// compensation comes in over FILTER=1000 ticks and goes over the same 1000 (a switch-off
/// without FILTER takes the switch-on's), along the smoothing ramp: never faster than its
/// steepest slope, 15/8 of a linear ramp's step, and reaching it in the middle.
#[test]
fn example_2_the_base_error_is_compensated_and_switched_softly() {
    let s = scenario("example2-kin-base");
    let base_error = frame([1.5, -0.8, 0.3], [0.2, -0.1, 0.5]);
    let full_shift = base_error.inverse().translation.vector.norm();
    let mut last_comp = Isometry3::identity();
    let (mut active, mut inactive_after, mut worst) = (0, 0, 0.0f64);
    let mut max_step = [0.0f64; 2]; // ACTIVATING, DEACTIVATING
    let mut was_on = false;
    run(&s, 250_000, None, |run, _| {
        let robot = channel(run, "robot");
        let comp = *robot.tracker().applied();
        let step = (comp.translation.vector - last_comp.translation.vector).norm();
        last_comp = comp;
        match robot.tracker().state() {
            DynCsState::Activating => max_step[0] = max_step[0].max(step),
            DynCsState::Deactivating => max_step[1] = max_step[1].max(step),
            DynCsState::Active => {
                was_on = true;
                let real_tool = base_error * robot.tool_pose();
                let programmed = robot.pose_in();
                worst = worst
                    .max((real_tool.translation.vector - programmed.translation.vector).norm());
                assert!(real_tool.rotation.angle_to(&programmed.rotation) < 1e-6);
                active += 1;
            }
            DynCsState::Inactive if was_on => {
                // Off again: the tool is on the programmed point of the nominal base.
                let miss = (robot.tool_pose().translation.vector
                    - robot.pose_in().translation.vector)
                    .norm();
                assert!(miss < 1e-6, "uncompensated tool off by {miss}");
                inactive_after += 1;
            }
            _ => {}
        }
    });
    assert!(active > 3000, "compensated for {active} ticks");
    assert!(inactive_after > 1000);
    assert!(
        worst < 1e-3,
        "the real tool missed the programmed point by {worst} mm"
    );
    for step in max_step {
        let steepest = full_shift / 1000.0 * 15.0 / 8.0;
        assert!(step <= steepest + 1e-9, "{max_step:?}");
        assert!(step > steepest * 0.999, "{max_step:?}");
    }
}

/// Example 1: after SET_ZERO and `#TRACK CS ABS` the gripper's zero is the carriage's position
/// at switch-on; while tracking, each gripper axis follows the same carriage axis, so the
/// gripper holds its grip (X0, Z25.44 above the carriage) while the carriage travels.
#[test]
fn example_1_the_gripper_follows_the_carriage_axis_by_axis() {
    let s = scenario("example1-axis-following");
    let (mut checked, mut worst, mut travel) = (0, 0.0f64, 0.0f64);
    let mut last_x: Option<f64> = None;
    let mut cycles = 0;
    let mut was_active = false;
    let (mut far, mut near) = (f64::MIN, f64::MAX);
    let done = run(&s, 60_000, s.ticks, |run, tick| {
        let (g, c) = (channel(run, "gripper"), channel(run, "carriage"));
        // The manual's carriage positions: magazine AB=30, working position AB=127.7213.
        if tick > 5000 {
            far = far.max(c.set_points()[0]);
            near = near.min(c.set_points()[0]);
        }
        let active = g.tracker().state() == DynCsState::Active;
        if active && !was_active {
            cycles += 1;
        }
        was_active = active;
        if !(active && !g.is_moving() && c.is_moving()) {
            return;
        }
        let (gs, cs) = (g.set_points(), c.set_points());
        worst = worst
            .max((gs[0] - cs[0]).abs())
            .max((gs[2] - (cs[2] + 25.44)).abs())
            .max(gs[1].abs());
        if let Some(x) = last_x {
            travel += (cs[0] - x).abs();
        }
        last_x = Some(cs[0]);
        checked += 1;
    });
    assert!(cycles >= 3, "{cycles} transfer cycles");
    assert!((far - 127.7213).abs() < 1e-9, "working position {far}");
    assert!((near - 30.0).abs() < 1e-9, "magazine {near}");
    assert!(checked > 1000, "followed for {checked} ticks");
    assert!(
        travel > 200.0,
        "the carriage travelled {travel} mm while followed"
    );
    assert!(worst < 1e-3, "the grip slipped by {worst} mm");
    assert!(channel(&done, "carriage").m_functions_acked() >= 3);
}

/// The 3-axis mill: its channel takes three axis images, which follow X Y Z; the pocket's
/// far corner (70, 50) is rounded within PATH_DEV, never overshot, with the tool length on Z;
/// the finishing pass's radius-5 corners run through without stopping (never below 40 mm/s
/// there), within its PATH_DEV of 0.02 mm of the lines and arcs.
#[test]
fn the_3_axis_mill_drives_three_axes_around_its_pocket() {
    let s = scenario("mill-3axis");
    let (mut far_x, mut far_y, mut nearest) = (f64::MIN, f64::MIN, f64::MAX);
    let mut finish: Vec<[f64; 2]> = Vec::new();
    let done = run(&s, 20_000, None, |run, _| {
        let axes = run.machine.axes();
        let p: Vec<f64> = (0..3).map(|i| axes.axis(i).unwrap().actual()).collect();
        if (p[2] - 48.0).abs() < 1e-9 {
            far_x = far_x.max(p[0]);
            far_y = far_y.max(p[1]);
            nearest = nearest.min(((p[0] - 70.0).powi(2) + (p[1] - 50.0).powi(2)).sqrt());
        }
        if (p[2] - 47.0).abs() < 1e-9 {
            finish.push([p[0], p[1]]);
        }
    });
    // The finishing outline: a rectangle from (10, 10) to (70, 50), corners of radius 5 (its
    // start in the first corner's square aside).
    let off = finish
        .iter()
        .filter(|p| p[0] >= 15.0 || p[1] >= 15.0)
        .map(|p| {
            let q = [(p[0] - 40.0).abs() - 25.0, (p[1] - 30.0).abs() - 15.0];
            (q[0].max(0.0).hypot(q[1].max(0.0)) + q[0].max(q[1]).min(0.0) - 5.0).abs()
        })
        .fold(0.0, f64::max);
    assert!(
        off <= 0.02 + 1e-9,
        "the finishing pass {off} mm off its outline"
    );
    let speed: Vec<f64> = finish
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) / 1e-3)
        .collect();
    let first = speed.iter().position(|&v| v >= 40.0).unwrap();
    let last = speed.iter().rposition(|&v| v >= 40.0).unwrap();
    let slowest = speed[first..=last].iter().copied().fold(f64::MAX, f64::min);
    assert!(
        slowest >= 40.0,
        "the finishing pass slowed to {slowest} mm/s"
    );
    assert_eq!(done.machine.channel_axes(), 3, "X Y Z only");
    let axes = done.machine.axes();
    let end: Vec<f64> = (0..3).map(|i| axes.axis(i).unwrap().actual()).collect();
    assert_eq!(
        end,
        [0.0, 0.0, 55.0],
        "back over the origin, tool length 50 on Z"
    );
    assert!(
        far_x <= 70.0 + 1e-9 && far_y <= 50.0 + 1e-9,
        "{far_x} {far_y}"
    );
    // The curve's middle lies PATH_DEV = 0.5 mm from the corner (the ticks sample near it).
    eprintln!("NEAREST {nearest}");
    assert!(
        (nearest - 0.5).abs() < 1e-2,
        "corner passed at {nearest} mm"
    );
    let c = channel(&done, "mill");
    assert_eq!(c.state(), RunState::Finished);
}

/// Channels whose axes the image cannot hold, no axes, axes twice, a robot without its joints:
/// refused at load with the channel and the key.
#[test]
fn channel_axes_the_machine_cannot_have_are_refused_with_the_channel() {
    let load = |channels: &str| {
        let toml = format!("ticks = 10\n{channels}");
        match Scenario::parse("axes.toml", &toml, |_| unreachable!()) {
            Err(e) => e.to_string(),
            Ok(s) => InProcess::new(&s, 10)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default(),
        }
    };
    let six = |name: &str| {
        format!(
            "[[channel]]\nname = \"{name}\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\n"
        )
    };
    let five_channels: String = (1..=5).map(|i| six(&format!("c{i}"))).collect();
    let e = load(&format!("{five_channels}{}", six("c6")));
    assert!(
        e.contains(
            "channel c6: axes: its 6 axes would take axis images 31 to 36, the image holds 32"
        ),
        "{e}"
    );
    assert!(load(&format!(
        "{five_channels}[[channel]]\nname = \"c6\"\naxes = [\"X\", \"Y\"]\n"
    ))
    .is_empty());
    for (axes, expected) in [
        ("[]", "channel m: axes: a channel has 1 to 16 axes, found 0"),
        (
            "[\"X\", \"Y\", \"X\"]",
            "channel m: axes: axis name \"X\" is given twice",
        ),
    ] {
        let e = load(&format!("[[channel]]\nname = \"m\"\naxes = {axes}\n"));
        assert!(e.contains(expected), "{e}");
    }
    let e =
        load("[[channel]]\nname = \"m\"\naxes = [\"X\", \"Y\", \"Z\"]\nkinematics = { id = 45 }\n");
    assert!(
        e.contains(
            "channel m: axes: kinematic 45 needs X Y Z A B C as its six joints, missing: A B C"
        ),
        "{e}"
    );
}
