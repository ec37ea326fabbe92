//! The NC language core run for real: arcs interpolated in a channel within the chordal
//! tolerance, subroutines called in loops returning to the right block, nested calls that do
//! not grow memory, the depth limit, tools and zero offsets from the machine data, dwell, and
//! the refusals that keep a bad program from running at all.

use cnc_core::channel::{Channel, ChannelConfig, Controller, LoadedProgram, RunState};
use cnc_core::nc::decode::{DecoderSetup, DecoderState, ZeroVars};
use cnc_core::nc::interp::{Interpreter, ProgramSet, SearchPath, Step};
use cnc_core::nc::{Decoded, MotionMode};
use hli::image::heap_image;
use hli::views::CncView;

use tests::channel_rig as support;

use crate::counting_alloc;
use counting_alloc::allocations;

const CYCLE: f64 = 0.001;

fn channel_with(config: ChannelConfig, src: &str) -> Controller {
    support::controller(vec![(config, src)])
}

/// Ticks until the channel finishes (watchdog: `limit` ticks), calling `each` with the
/// programmed position after every tick.
fn run(ctl: &mut Controller, limit: u32, mut each: impl FnMut(&[f64])) -> u32 {
    let memory = heap_image(1, 8);
    let view = CncView::new(&memory);
    for tick in 0..limit {
        ctl.tick(&view);
        let c = &ctl.channels()[0];
        assert_ne!(c.state(), RunState::Error, "{:?}", c.error());
        each(c.programmed());
        if c.state() == RunState::Finished && !c.is_moving() {
            return tick;
        }
    }
    panic!("watchdog: not finished after {limit} ticks");
}

#[test]
fn an_arc_stays_on_its_circle_within_the_chordal_tolerance_at_every_tick() {
    // Radius 10 about (0, 0): a half turn, a full circle clockwise, a helix down 4 mm.
    let src = "G0 X10 Y0 Z0\nG3 X-10 Y0 I-10 J0 F12000\nG2 I10\nG3 X10 Y0 Z-4 R10\nM30\n";
    let mut config = ChannelConfig::new("mill", &["X", "Y", "Z", "A", "B", "C"]);
    // Stiff axes and a fine tolerance: the chordal error, not the axes, limits the speed.
    config.limits.velocity = 500.0;
    config.limits.acceleration = 100_000.0;
    config.limits.jerk = 10_000_000.0;
    config.interpolator.chordal_tolerance = 0.0002;
    let tolerance = config.interpolator.chordal_tolerance;
    let mut ctl = channel_with(config, src);
    let mut points: Vec<[f64; 3]> = Vec::new();
    run(&mut ctl, 200_000, |p| points.push([p[0], p[1], p[2]]));
    let on_arc: Vec<&[f64; 3]> = points
        .iter()
        .skip_while(|p| (p[0] - 10.0).abs() > 1e-12 || p[1] != 0.0)
        .collect();
    assert!(on_arc.len() > 1000, "{} arc ticks", on_arc.len());
    let mut worst_radius = 0.0f64;
    let mut worst_sagitta = 0.0f64;
    for pair in on_arc.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let r = a[0].hypot(a[1]);
        worst_radius = worst_radius.max((r - 10.0).abs());
        // The chord between two set-points strays from the circle by r - |midpoint|.
        let mid = ((a[0] + b[0]) / 2.0).hypot((a[1] + b[1]) / 2.0);
        worst_sagitta = worst_sagitta.max(10.0 - mid);
    }
    assert!(worst_radius < 1e-9, "off the circle by {worst_radius}");
    assert!(
        worst_sagitta <= tolerance && worst_sagitta > tolerance * 0.9,
        "chordal error {worst_sagitta} against {tolerance}"
    );
    // Exactly at the end point, the helix down by 4 mm.
    assert_eq!(*points.last().unwrap(), [10.0, 0.0, -4.0]);
    // The helix's Z moved in proportion to the angle: at the half-way tick of the last block,
    // Z is near -2 where the tool is at (0, -10) (G3 from (-10, 0) to (10, 0) passes y = -10).
    let bottom = on_arc
        .iter()
        .filter(|p| p[2] < 0.0)
        .min_by(|a, b| a[1].total_cmp(&b[1]))
        .unwrap();
    assert!((bottom[2] + 2.0).abs() < 0.05, "{bottom:?}");
}

#[test]
fn a_subroutine_called_in_a_loop_returns_to_the_block_after_its_call() {
    let src = "%L STEP\nN1 G91 G1 X1 F6000\nN2 G90\nN3 M17\n%MAIN\nN10 P1 = 0\n\
               N20 $WHILE P1 < 3\nN30 LL STEP\nN40 Y=P1\nN50 P1 = P1 + 1\nN60 $ENDWHILE\nN70 Z5\nM30\n";
    let axes: Vec<String> = ["X", "Y", "Z"].map(String::from).to_vec();
    let (set, diags) = ProgramSet::load("loop.nc", src.to_string(), None, &SearchPath::default());
    assert!(diags.is_empty(), "{diags:?}");
    let mut interp = Interpreter::new();
    let mut decoder = DecoderState::new(&axes);
    interp.start(&set);
    let mut out = Vec::new();
    let mut lines = Vec::new();
    loop {
        out.clear();
        match interp
            .step(&set, &mut decoder, &ZeroVars, &mut out)
            .unwrap()
        {
            Step::End => break,
            _ => lines.extend(out.iter().filter_map(|d| match d {
                Decoded::Motion(m) => Some((m.line, m.target[0], m.target[1], m.target[2])),
                _ => None,
            })),
        }
    }
    // N1 (line 2) then N40 (line 9), three times, then N70 (line 12).
    assert_eq!(
        lines,
        vec![
            (2, 1.0, 0.0, 0.0),
            (9, 1.0, 0.0, 0.0),
            (2, 2.0, 0.0, 0.0),
            (9, 2.0, 1.0, 0.0),
            (2, 3.0, 1.0, 0.0),
            (9, 3.0, 2.0, 0.0),
            (12, 3.0, 2.0, 5.0),
        ]
    );
}

#[test]
fn ten_thousand_nested_call_cycles_run_without_allocating() {
    // Main -> a.nc -> sub/b.nc (found through the search path), 10,000 times.
    let dir = tests::Scratch::new("nc-nested");
    std::fs::create_dir_all(dir.join("lib")).unwrap();
    std::fs::write(
        dir.join("a.nc"),
        "V.L.DEPTH = 1\nL b.nc\nP2 = P2 + V.L.DEPTH\nM17\n",
    )
    .unwrap();
    // b.nc declares its own V.L.DEPTH (shadowing a.nc's until it returns).
    std::fs::write(
        dir.join("lib/b.nc"),
        "#VAR\nV.L.DEPTH = 2\n#ENDVAR\nP3 = P3 + V.L.DEPTH\nM17\n",
    )
    .unwrap();
    let src = "P1 = 0 P2 = 0 P3 = 0\n$WHILE P1 < 10000\nL a.nc\nP1 = P1 + 1\n$ENDWHILE\nG1 X=P2 Y=P3 F100\nM30\n";
    let search = SearchPath(vec![dir.join("lib")]);
    let (set, diags) = ProgramSet::load("main.nc", src.to_string(), Some(dir.path()), &search);
    assert!(diags.is_empty(), "{diags:?}");
    assert_eq!(set.units.len(), 3);
    let axes: Vec<String> = ["X", "Y"].map(String::from).to_vec();
    let mut interp = Interpreter::new();
    let mut decoder = DecoderState::new(&axes);
    interp.start(&set);
    let mut out = Vec::with_capacity(16);
    let mut deepest = 0;
    let before = allocations();
    let mut steps = 0u64;
    loop {
        out.clear();
        steps += 1;
        let step = interp
            .step(&set, &mut decoder, &ZeroVars, &mut out)
            .unwrap();
        deepest = deepest.max(interp.depth());
        if step == Step::End {
            break;
        }
    }
    let made = allocations() - before;
    assert_eq!(made, 0, "{made} allocations in {steps} steps");
    assert_eq!(deepest, 2);
    // V.L.DEPTH of a.nc is its own again after b.nc returned: P2 adds 1 each time.
    assert_eq!(interp.param(2), Some(10_000.0));
    assert_eq!(interp.param(3), Some(20_000.0));
}

#[test]
fn recursion_past_the_depth_limit_refuses_the_program() {
    let dir = tests::Scratch::new("nc-recursion");
    std::fs::write(dir.join("again.nc"), "P1 = P1 + 1\nL again.nc\nM17\n").unwrap();
    let main = dir.join("main.nc");
    std::fs::write(&main, "P1 = 0\nL again.nc\nM30\n").unwrap();
    let axes: Vec<String> = ["X"].map(String::from).to_vec();
    let err = LoadedProgram::load(
        &main.display().to_string(),
        "P1 = 0\nL again.nc\nM30\n",
        &axes,
    )
    .unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("again.nc:2:1: error: subroutine calls nest deeper than 16"),
        "{text}"
    );
}

#[test]
fn tool_length_and_zero_offsets_come_from_the_machine_data() {
    let toml = r#"
        name = "mill"
        axes = ["X", "Y", "Z", "A", "B", "C"]
        [nc]
        zero_offsets = { G54 = [100.0, 50.0, 0.0], G55 = [-10.0] }
        tools = [{ d = 1, length = 80.0 }, { d = 2, length = 120.5 }]
    "#;
    let config: ChannelConfig = toml::from_str(toml).unwrap();
    let setup: DecoderSetup = config.nc.setup();
    let src = "G54 G0 X0 Y0 Z10\nD1 Z10\nG18 D2 Z10 Y0\nG17 G55 D0 X0 Y0 Z0\nG53 X0\n\
               G54 X10\n#PSET X0\nX5\nM30\n";
    let mut decoded = Vec::new();
    let (_, diags) = cnc_core::nc::check_program(
        "t.nc",
        src.to_string(),
        &config.axes,
        &setup,
        (None, &SearchPath::default()),
        &ZeroVars,
        Some(&mut |step: &[Decoded]| decoded.extend_from_slice(step)),
    );
    assert!(diags.is_empty(), "{diags:?}");
    let targets: Vec<[f64; 3]> = decoded
        .iter()
        .filter_map(|d| match d {
            Decoded::Motion(m) => Some([m.target[0], m.target[1], m.target[2]]),
            _ => None,
        })
        .collect();
    assert_eq!(
        targets,
        vec![
            [100.0, 50.0, 10.0],
            // D1 under G17: the length along Z.
            [100.0, 50.0, 90.0],
            // G18: the normal is Y, so D2 lengthens Y (programmed again), Z keeps the zero offset.
            [100.0, 170.5, 10.0],
            // G55, no tool: only X has a G55 offset.
            [-10.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            // G54 again: X10 stands at 110; #PSET X0 declares that 0, and X5 is 5 further
            // (the preset does not take the zero offset a second time).
            [110.0, 0.0, 0.0],
            [115.0, 0.0, 0.0],
        ]
    );
}

#[test]
fn a_dwell_holds_the_channel_for_its_time() {
    let mut ctl = channel_with(
        ChannelConfig::new("d", &["X", "Y", "Z", "A", "B", "C"]),
        "G04 0.25\nG1 X1 F60000\nM30\n",
    );
    let mut first_move = None;
    let mut tick = 0u32;
    run(&mut ctl, 10_000, |p| {
        tick += 1;
        if first_move.is_none() && p[0] != 0.0 {
            first_move = Some(tick);
        }
    });
    // The dwell is decoded in tick 1 and holds ticks 1..=250 (0.25 s of 1 ms ticks); the
    // move is decoded and starts in tick 251.
    assert_eq!(first_move, Some(251));
}

#[test]
fn spindle_tool_and_messages_reach_the_channel() {
    let mut ctl = channel_with(
        ChannelConfig::new("s", &["X", "Y", "Z", "A", "B", "C"]),
        "S6000 T24\n#MSG [\"tool in\"]\nM30\n",
    );
    run(&mut ctl, 100, |_| {});
    let c = &ctl.channels()[0];
    assert_eq!(c.spindle_speed(), 6000.0);
    assert_eq!(c.tool_number(), 24);
    assert_eq!(c.message(), (Some("tool in"), 1));
}

#[test]
fn an_arc_program_ticks_without_allocating() {
    // Decoding and executing arcs, calls, loops, assignments and functions in the tick.
    let src = "%L ROUND\nN1 G3 X-10 Y0 I-10 F30000\nN2 G3 X10 Y0 R10\nN3 M17\n%MAIN\n\
               G0 X10 Y0\nP1 = 0\n$WHILE 1\nLL ROUND\nP1 = P1 + 1\n$FOR P2 = 1, 2\nG1 Z=SIN[P2 * 30] F30000\n$ENDFOR\n\
               $SWITCH P1 MOD 2\n$CASE 0\nG04 0.002\n$BREAK\n$DEFAULT\n#TIME 0.001\n$ENDSWITCH\n$ENDWHILE\n";
    let mut config = ChannelConfig::new("a", &["X", "Y", "Z", "A", "B", "C"]);
    config.limits.velocity = 2000.0;
    config.limits.acceleration = 50_000.0;
    config.limits.jerk = 5_000_000.0;
    let mut ctl = channel_with(config, src);
    let memory = heap_image(1, 8);
    let view = CncView::new(&memory);
    for _ in 0..3000 {
        ctl.tick(&view);
    }
    let before = allocations();
    for _ in 0..20_000 {
        ctl.tick(&view);
    }
    let made = allocations() - before;
    assert_eq!(made, 0, "{made} allocations in 20,000 ticks");
    let c = &ctl.channels()[0];
    assert_eq!(c.state(), RunState::Running, "{:?}", c.error());
}

#[test]
fn the_arc_modes_are_named_in_the_block_stream() {
    let (diags, decoded) = cnc_core::nc::check::check_source(
        "G0 X1 Y0\nG2 X0 Y-1 R1 F100\n",
        &["X".to_string(), "Y".to_string(), "Z".to_string()],
    );
    assert!(diags.is_empty());
    let Some(Decoded::Motion(m)) = decoded.get(1) else {
        panic!("{decoded:?}")
    };
    assert_eq!(m.motion, MotionMode::ArcCw);
    let arc = m.arc.unwrap();
    assert!(arc.center[0].abs() < 1e-12 && arc.center[1].abs() < 1e-12);
}

#[test]
fn an_arc_under_the_kinematic_transformation_moves_the_tool_on_the_circle() {
    // A six-axis robot: the arc is programmed in the tool's coordinates, the joints follow
    // through the inverse kinematics every tick.
    let mut config = ChannelConfig::new("robot", &["X", "Y", "Z", "A", "B", "C"]);
    config.kinematics.id = 45;
    config.kinematics.preset = Some("kr6r900sixx".into());
    config.start = vec![0.0, -60.0, 90.0, 0.0, 60.0, 0.0];
    let src = "#TRAFO ON\nG91 G3 X-40 Y0 I-20 J0 F3000\nG2 X40 Y0 R20\nG90\nM30\n";
    let mut ctl = channel_with(config, src);
    let memory = heap_image(1, 8);
    let view = CncView::new(&memory);
    // Before the first tick the tool stands where the joints put it: where #TRAFO ON starts.
    let mut tool = vec![ctl.channels()[0].tool_pose().translation.vector];
    for _ in 0..20_000 {
        ctl.tick(&view);
        let c = &ctl.channels()[0];
        assert_ne!(c.state(), RunState::Error, "{:?}", c.error());
        tool.push(c.tool_pose().translation.vector);
        if c.state() == RunState::Finished && !c.is_moving() {
            break;
        }
    }
    let start = tool[0];
    let center = start - nalgebra::Vector3::new(20.0, 0.0, 0.0);
    let mut worst = 0.0f64;
    let mut highest_y = f64::NEG_INFINITY;
    for p in &tool {
        let d = p - center;
        worst = worst
            .max((d.x.hypot(d.y) - 20.0).abs())
            .max((p.z - start.z).abs());
        highest_y = highest_y.max(p.y - start.y);
    }
    // The tool pose of the joints (forward kinematics) is on the circle to the solver's
    // precision. G3 from angle 0 to 180 degrees and G2 back from 180 to 0 both pass over the
    // top of the circle (y + 20).
    assert!(worst < 1e-6, "off the circle by {worst}");
    assert!((highest_y - 20.0).abs() < 1e-3, "{highest_y}");
    let end = tool.last().unwrap();
    assert!((end - start).norm() < 1e-6, "{end:?} vs {start:?}");
}

#[test]
fn an_open_var_section_of_a_subroutine_ends_with_it() {
    // The subroutine opens #VAR and never closes it; back in the caller an assignment updates
    // the caller's V.L.N instead of declaring a new one.
    let src =
        "%L SUB\n#VAR\nV.L.N = 7\nM17\n%MAIN\nV.L.N = 1\nLL SUB\nV.L.N = 2\nP1 = V.L.N\nM30\n";
    let (set, diags) = ProgramSet::load("var.nc", src.to_string(), None, &SearchPath::default());
    assert!(diags.is_empty(), "{diags:?}");
    let axes: Vec<String> = ["X"].map(String::from).to_vec();
    let mut interp = Interpreter::new();
    let mut decoder = DecoderState::new(&axes);
    interp.start(&set);
    let mut out = Vec::new();
    while interp
        .step(&set, &mut decoder, &ZeroVars, &mut out)
        .unwrap()
        != Step::End
    {}
    assert_eq!(interp.param(1), Some(2.0));
}

#[test]
fn tolerances_and_tool_data_that_are_no_numbers_are_refused() {
    for (field, toml) in [
        (
            "chordal_tolerance",
            "interpolator = { chordal_tolerance = 0.0 }",
        ),
        ("arc_tolerance", "nc = { arc_tolerance = -1.0 }"),
        ("nc.tools", "nc = { tools = [{ d = 0, length = 5.0 }] }"),
        (
            "nc.zero_offsets",
            "nc = { zero_offsets = { G54 = [1, 2, 3, 4, 5, 6, 7] } }",
        ),
    ] {
        let text =
            format!("name = \"c\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\n{toml}\n");
        let config: ChannelConfig = toml::from_str(&text).unwrap();
        let err = Channel::new(0, config, CYCLE).unwrap_err().to_string();
        assert!(err.contains(field), "{field}: {err}");
    }
}

#[test]
fn a_new_program_starts_from_the_modal_defaults() {
    let config = ChannelConfig::new("m", &["X", "Y", "Z", "A", "B", "C"]);
    let first = LoadedProgram::load("first", "G70 G91 G1 X1 F100\nM30\n", &config.axes).unwrap();
    let second = LoadedProgram::load("second", "G1 X1 F100\nM30\n", &config.axes).unwrap();
    let mut channel = Channel::new(0, config, CYCLE).unwrap();
    channel.start(first).unwrap();
    let mut ctl = Controller::new(vec![channel]).unwrap();
    run(&mut ctl, 100_000, |_| {});
    assert!((ctl.channels()[0].programmed()[0] - 25.4).abs() < 1e-9);
    ctl.channel_mut(0).unwrap().start(second).unwrap();
    run(&mut ctl, 100_000, |_| {});
    // Millimetres and absolute again: X1 is 1 mm, not 25.4 mm further.
    assert!((ctl.channels()[0].programmed()[0] - 1.0).abs() < 1e-9);
}
