//! Requirements of seed 003 (the dynamic CS) that the other tests did not pin down (audit
//! 003, gaps #9, #73, #93 and #115): `#CHANNEL INTERFACE` takes only DYN_CS or TRACK_CS in
//! its bracket, refused at load with the place; `#TRACK CS OFF` without WAIT lets the next
//! block run while the tracking couples out; `w0_position_r` includes the selected tool
//! record (D); P-CHAN-00145 `kin_trafo_display` is 0 by default, so `w0_position_r` stays 0.

use tests::channel_rig as support;

use cnc_core::channel::{ChannelConfig, LoadedProgram, RunState};
use cnc_core::nc::interp::SearchPath;
use hli::access::Leaf;
use hli::enums::DynCsState;
use hli::views::CncView;
use hli::ImageMemory;
use kinematics::opw::{Robot45, Robot45Params};
use kinematics::{Kinematics, PoseWords, RotationOrder};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use support::{cartesian, controller, image, robot, run_to_end, run_until, ROBOT_HOME};

/// `src` checked as a Cartesian channel's program named `prog`: the refusal's text.
fn load(src: &str) -> Result<LoadedProgram, String> {
    let config = cartesian("prog");
    LoadedProgram::load_with(
        "prog",
        src,
        &config.axes,
        &config.nc.setup(),
        None,
        &SearchPath::default(),
    )
    .map_err(|e| e.to_string())
}

/// Seed 003: only DYN_CS or TRACK_CS may stand in `#CHANNEL INTERFACE ON|OFF [..]`. Any
/// other name, a value, or both names are refused at load as FILE:LINE:COL at the entry;
/// each name alone (and no bracket) loads.
#[test]
fn channel_interface_takes_only_dyn_cs_or_track_cs_in_its_bracket() {
    for (line, place, needle) in [
        (
            "#CHANNEL INTERFACE ON [FOO]",
            "prog:2:24:",
            "expected DYN_CS or TRACK_CS",
        ),
        (
            "#CHANNEL INTERFACE OFF [FOO]",
            "prog:2:25:",
            "expected DYN_CS or TRACK_CS",
        ),
        (
            "#CHANNEL INTERFACE ON [DYN_CS=1]",
            "prog:2:",
            "expected DYN_CS or TRACK_CS",
        ),
        (
            "#CHANNEL INTERFACE ON [DYN_CS TRACK_CS]",
            "prog:2:",
            "names its interface once",
        ),
    ] {
        let src = format!("G1 X1 F600\n{line}\nM30\n");
        let e = load(&src)
            .err()
            .unwrap_or_else(|| panic!("{line} was accepted"));
        assert!(e.contains(place), "{line}: {e}");
        assert!(e.contains(needle), "{line}: {e}");
    }
    for good in [
        "#CHANNEL INTERFACE ON [DYN_CS]\nG1 X1 F600\n#CHANNEL INTERFACE OFF [DYN_CS]\nM30\n",
        "#CHANNEL INTERFACE ON [TRACK_CS]\nG1 X1 F600\n#CHANNEL INTERFACE OFF [TRACK_CS]\nM30\n",
        "#CHANNEL INTERFACE ON\nG1 X1 F600\n#CHANNEL INTERFACE OFF\nM30\n",
    ] {
        if let Err(e) = load(good) {
            panic!("{good:?} was refused: {e}");
        }
    }
}

/// What one switch-off showed, in ticks of the run.
#[derive(Debug)]
struct SwitchOff {
    /// First tick in DEACTIVATING.
    off: u32,
    /// First tick the `G1 X1` after the switch-off moved the programmed X, and the state then.
    started: (u32, DynCsState),
    /// First tick INACTIVE after the switch-off, and the programmed X then.
    inactive: (u32, f64),
}

/// A PLC-tracked slave (a 10 mm frame, coupled in over 50 ticks with WAIT) switches off with
/// `off`, then runs `G1 X1` (about 110 ticks) and dwells past the end of the switch-off.
fn switch_off_then_move(off: &str) -> SwitchOff {
    let program =
        format!("#TRACK CS ON [ID=0 FILTER=50 WAIT]\n{off}\nG1 X1 F600\n#TIME 0.5\nM30\n");
    let mut ctl = controller(vec![(cartesian("slave"), program.as_str())]);
    let memory = image(1);
    support::enable_plc_master(&memory, [100_000, 0, 0]);
    let view = CncView::new(&memory);
    let (mut off_tick, mut started, mut inactive) = (None, None, None);
    for tick in 0..20_000u32 {
        ctl.tick(&view);
        let ch = &ctl.channels()[0];
        assert_ne!(ch.state(), RunState::Error, "{:?}", ch.error());
        let state = ch.tracker().state();
        let x = ch.programmed()[0];
        if off_tick.is_none() && state == DynCsState::Deactivating {
            off_tick = Some(tick);
        }
        if started.is_none() && x > 0.0 {
            started = Some((tick, state));
        }
        if off_tick.is_some() && inactive.is_none() && state == DynCsState::Inactive {
            inactive = Some((tick, x));
        }
        if ch.state() == RunState::Finished {
            return SwitchOff {
                off: off_tick.expect("never DEACTIVATING"),
                started: started.expect("G1 X1 never started"),
                inactive: inactive.expect("never INACTIVE again"),
            };
        }
    }
    panic!("watchdog: off {off_tick:?}, started {started:?}, inactive {inactive:?}");
}

/// Seed 003: `#TRACK CS OFF` without WAIT couples out on the fly: the next block starts while
/// the state is still DEACTIVATING and has moved by the time the 300-tick filter ends. With
/// WAIT the same block starts only once the state is INACTIVE.
#[test]
fn track_cs_off_without_wait_lets_the_next_block_run_while_deactivating() {
    let s = switch_off_then_move("#TRACK CS OFF [FILTER=300]");
    assert_eq!(s.started.1, DynCsState::Deactivating, "{s:?}");
    assert!(s.started.0 < s.inactive.0, "{s:?}");
    assert!(
        (299..=301).contains(&(s.inactive.0 - s.off)),
        "the whole filter: {s:?}"
    );
    assert!(s.inactive.1 > 0.5, "moved while coupling out: {s:?}");

    let s = switch_off_then_move("#TRACK CS OFF [FILTER=300 WAIT]");
    assert_eq!(s.started.1, DynCsState::Inactive, "{s:?}");
    assert!(s.started.0 >= s.inactive.0, "{s:?}");
    assert_eq!(s.inactive.1, 0.0, "nothing moved before INACTIVE: {s:?}");
}

/// `gpCh[channel]^bahn_state.coord_r[0..6].w0_position_r`.
fn w0(memory: &ImageMemory, channel: usize) -> [i64; 6] {
    core::array::from_fn(|i| {
        let path = format!("gpCh[{channel}]^bahn_state.coord_r[{i}].w0_position_r");
        Leaf::resolve(&path).unwrap().read(memory).as_f64() as i64
    })
}

/// The KR 6 R900's flange at `joints`, from the kinematics crate directly.
fn flange(joints: &[f64; 6]) -> Isometry3<f64> {
    Robot45::new(Robot45Params::kuka_kr6_r900_sixx())
        .unwrap()
        .forward(joints)
        .unwrap()
}

/// Seed 003 (P-CHAN-00145): the TCP shown in `w0_position_r` includes the selected tool.
/// With D1 (100 mm, turned 90 degrees about the tool axis) under `#TRAFO` and a move of
/// 20 mm down, it is the flange (from the kinematics crate) plus 100 mm along the flange's Z
/// minus 20 mm in Z, to 0.1 um, and its A B C give the flange turned 90 degrees about Z.
#[test]
fn w0_position_r_includes_the_selected_tool_record() {
    let mut c = robot("r");
    c.kin_trafo_display = 1;
    c.nc.tools = support::tools("{ d = 1, length = 100.0, orientation = [0.0, 0.0, 90.0] }");
    let program = "#TRAFO [45]\n#TIME 0.01\nD1\n#TIME 0.01\nG91 G1 Z-20 F3000\nM30\n";
    let mut ctl = controller(vec![(c, program)]);
    let memory = image(1);
    run_to_end(&mut ctl, &memory, 20_000);
    ctl.tick(&CncView::new(&memory));
    let shown = w0(&memory, 0);
    let f = flange(&ROBOT_HOME);
    let down = Vector3::new(0.0, 0.0, -20.0);
    let point = f.translation.vector + f.rotation * Vector3::new(0.0, 0.0, 100.0) + down;
    for k in 0..3 {
        let want = (point[k] * 10_000.0).round() as i64;
        assert!(
            (shown[k] - want).abs() <= 1,
            "word {k}: {shown:?} vs the tool point {point:?}"
        );
    }
    // Not the flange: 100 mm from where the flange point went.
    let at = Vector3::new(shown[0] as f64, shown[1] as f64, shown[2] as f64) / 10_000.0;
    let from_flange = (at - (f.translation.vector + down)).norm();
    assert!((from_flange - 100.0).abs() < 1e-3, "{from_flange}");
    let words = PoseWords {
        xyz: [at.x, at.y, at.z],
        abc: [3usize, 4, 5].map(|k| shown[k] as f64 / 10_000.0),
    };
    let frame = words.to_frame(RotationOrder::YawPitchRoll).unwrap();
    let turned =
        f.rotation * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 90f64.to_radians());
    let off = frame.rotation.angle_to(&turned);
    assert!(
        off < 1e-5,
        "orientation {off} rad from the record's: {shown:?}"
    );
}

/// Seed 003: P-CHAN-00145 `kin_trafo_display` defaults to 0, both for a channel built in code
/// and for one read from a configuration without the key; a robot channel left at the
/// default keeps `w0_position_r` at 0 on every tick of a move to a pose far from zero, which
/// the same channel with 1 shows.
#[test]
fn kin_trafo_display_defaults_to_0_and_w0_position_r_then_stays_0() {
    let six = ["X", "Y", "Z", "A", "B", "C"];
    assert_eq!(ChannelConfig::new("r", &six).kin_trafo_display, 0);
    let parsed: ChannelConfig =
        toml::from_str("name = \"r\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\n")
            .unwrap();
    assert_eq!(parsed.kin_trafo_display, 0);
    assert_eq!(robot("r").kin_trafo_display, 0);

    let joints = [10.0, -70.0, 95.0, 5.0, 50.0, -20.0];
    let program = format!(
        "G1 X{} Y{} Z{} A{} B{} C{} F60000\nM30\n",
        joints[0], joints[1], joints[2], joints[3], joints[4], joints[5]
    );
    let x = (flange(&joints).translation.vector.x * 10_000.0).round() as i64;
    assert!(x.abs() > 1_000_000, "a pose away from zero");

    let mut ctl = controller(vec![(robot("r"), program.as_str())]);
    let memory = image(1);
    let mut ticks = 0;
    run_until(
        &mut ctl,
        &memory,
        20_000,
        |_, tick| {
            assert_eq!(w0(&memory, 0), [0; 6], "tick {tick}");
            ticks += 1;
        },
        |c| c.channels()[0].state() == RunState::Finished,
    );
    ctl.tick(&CncView::new(&memory));
    assert_eq!(w0(&memory, 0), [0; 6]);
    assert!(ticks > 10, "{ticks}");

    let mut shown = robot("r");
    shown.kin_trafo_display = 1;
    let mut ctl = controller(vec![(shown, program.as_str())]);
    let memory = image(1);
    run_to_end(&mut ctl, &memory, 20_000);
    ctl.tick(&CncView::new(&memory));
    assert!(
        (w0(&memory, 0)[0] - x).abs() <= 1,
        "display 1 shows the TCP"
    );
}
