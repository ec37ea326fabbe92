//! `#TRACK CS` as the program loads it: every refusal with its place (NAME:LINE:COL), ABSOLUTE
//! as SET_ZERO's other name, and `V.G.TRACK_CS.A..C` in the channel's orientation convention.

use tests::channel_rig as support;

use cnc_core::channel::hli_frame::frame_from_hli;
use cnc_core::channel::{LoadedProgram, RunState};
use hli::views::{CncView, PlcView};
use kinematics::{PoseWords, RotationOrder};
use support::{cartesian, controller, cs, image};

fn axes() -> Vec<String> {
    ["X", "Y", "Z", "A", "B", "C"].map(String::from).to_vec()
}

#[test]
fn every_bad_track_cs_is_refused_at_load_with_its_place() {
    for (line, needle) in [
        (
            "#TRACK CS ON [ID=0 FILTER=5 FILTER=6]",
            "option FILTER given twice",
        ),
        ("#TRACK CS OFF [SET_ZERO]", "only allowed with ON"),
        ("#TRACK CS ON [ID=0 LOG_FILE=log]", "expected a number"),
        (
            "#TRACK CS ON [ID=0 LOG_FILE=\"  \"]",
            "LOG_FILE needs a file name in quotes",
        ),
        ("#TRACK CS ON [ID=0 CH=2]", "not both"),
        ("#TRACK CS ON [FILTER=5]", "expected a source"),
        ("#TRACK CS ON [ID=0 SET_ZERO ABSOLUTE]", "the same option"),
        ("#TRACK CS ON [ID=0 OPTION=2]", "OPTION"),
        ("#TRACK CS ON [CH=13]", "CH"),
        ("#TRACK CS ON [ID=0 FILTER=-1]", "FILTER"),
        ("#TRACK CS ON [ID=0 X=1/0]", "division by zero"),
    ] {
        let src = format!("G1 X1 F600\n{line}\nM30\n");
        let e = LoadedProgram::load("prog", &src, &axes())
            .err()
            .unwrap_or_else(|| panic!("{line} was accepted"))
            .to_string();
        assert!(e.contains("prog:2:"), "{line}: {e}");
        assert!(e.contains(needle), "{line}: {e}");
    }
}

/// The PLC's master frame: 10 mm, 20 mm, 5 mm and turned 30 degrees about Z, then 20 about Y.
fn master() -> hli::layout::HliCoordinateSystemInt {
    let mut m = cs([100_000, 200_000, 50_000]);
    m.rotation = [0, 200_000, 300_000];
    m
}

/// Runs `program` on a Cartesian slave of the PLC's master frame with orientation convention
/// `ori` and returns `V.G.TRACK_CS.X..C` after the switch-on.
fn zero_values(program: &str, ori: u32) -> [f64; 6] {
    let mut c = cartesian("slave");
    c.ori_rotation_angle = ori;
    let mut ctl = controller(vec![(c, program)]);
    let memory = image(1);
    let view = CncView::new(&memory);
    let plc = PlcView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    plc.dyn_cs_command(0).unwrap().try_send(&master()).unwrap();
    for _ in 0..50 {
        ctl.tick(&view);
    }
    let ch = &ctl.channels()[0];
    assert_ne!(ch.state(), RunState::Error, "{:?}", ch.error());
    ch.tracker().zero_values()
}

#[test]
fn absolute_is_set_zero_and_the_angles_follow_the_channels_convention() {
    let program = |option: &str| format!("#TRACK CS ON [ID=0 {option} FILTER=0]\n#TIME 1\nM30\n");
    let set_zero = zero_values(&program("SET_ZERO"), 0);
    assert_eq!(zero_values(&program("ABSOLUTE"), 0), set_zero);
    assert!((set_zero[0] - 10.0).abs() < 1e-9 && (set_zero[1] - 20.0).abs() < 1e-9);
    // Without SET_ZERO nothing is handed to the program.
    assert_eq!(zero_values(&program(""), 0), [0.0; 6]);
    // Each convention's angles describe the same master orientation, and they differ.
    let frame = frame_from_hli(&master(), RotationOrder::Zyx);
    let mut angles = Vec::new();
    for ori in [0, 1, 2] {
        let v = zero_values(&program("SET_ZERO"), ori);
        let order = RotationOrder::from_channel_parameter(ori).unwrap();
        let words = PoseWords {
            xyz: [v[0], v[1], v[2]],
            abc: [v[3], v[4], v[5]],
        };
        let back = words.to_frame(order).unwrap();
        assert!(
            back.rotation.angle_to(&frame.rotation) < 1e-9,
            "convention {ori}: {v:?}"
        );
        angles.push([v[3], v[4], v[5]]);
    }
    assert_ne!(angles[0], angles[1]);
}

/// `V.G.WZ_AKT.*` (the controller's tool variables, named only in the manual's remark on
/// the TCP display) is refused by name with its place: tool data are the D records.
#[test]
fn the_tool_variables_are_refused_by_name() {
    let e = LoadedProgram::load("prog", "G1 F600\nG1 X=V.G.WZ_AKT.V.X\nM30\n", &axes())
        .err()
        .unwrap_or_else(|| panic!("accepted"))
        .to_string();
    assert!(e.contains("prog:2:"), "{e}");
    assert!(
        e.contains("V.G.WZ_AKT.V.X") && e.contains("not supported"),
        "{e}"
    );
    // Any other unknown V.G. name keeps the generic refusal.
    let e = LoadedProgram::load("prog", "G1 X=V.G.NOPE F600\nM30\n", &axes())
        .err()
        .unwrap_or_else(|| panic!("accepted"))
        .to_string();
    assert!(e.contains("unknown variable"), "{e}");
}

/// The PLC's switch-on with `f_set_zero` hands the master's frame to the program as the NC's
/// SET_ZERO does: `V.G.TRACK_CS.X..C` of the frame (angles in the channel's convention),
/// read by the next block decoded, and the switch-on moves nothing.
#[test]
fn a_plc_switch_on_with_set_zero_hands_the_master_frame_to_the_program() {
    let program = "#TIME 0.2\nG1 X=V.G.TRACK_CS.X Y=V.G.TRACK_CS.Y Z=V.G.TRACK_CS.Z F6000\n\
                   #TIME 0.3\nM30\n";
    let mut ctl = controller(vec![(cartesian("slave"), program)]);
    let memory = image(1);
    let view = CncView::new(&memory);
    let plc = PlcView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    plc.dyn_cs_command(0).unwrap().try_send(&master()).unwrap();
    for _ in 0..50 {
        ctl.tick(&view);
    }
    let mut t = support::transition(0, hli::Bool::TRUE);
    t.f_set_zero = hli::Bool::TRUE;
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(hli::enums::DynCsCommand::Activate, &t)
        .unwrap();
    let before = ctl.channels()[0].set_points()[0];
    ctl.tick(&view);
    assert_eq!(plc.gp_ch(0).unwrap().dyn_cs_result().error_id_r, 0);
    assert_eq!(
        ctl.channels()[0].set_points()[0],
        before,
        "SET_ZERO moves nothing"
    );
    let zero = ctl.channels()[0].tracker().zero_values();
    let frame = frame_from_hli(&master(), RotationOrder::Zyx);
    let words = PoseWords::from_frame(&frame, RotationOrder::YawPitchRoll);
    for k in 0..3 {
        assert!((zero[k] - words.xyz[k]).abs() < 1e-9, "{zero:?}");
        assert!((zero[3 + k] - words.abc[k]).abs() < 1e-9, "{zero:?}");
    }
    support::run_to_end(&mut ctl, &memory, 5000);
    let p = ctl.channels()[0].programmed();
    assert!((p[0] - 10.0).abs() < 1e-9 && (p[1] - 20.0).abs() < 1e-9 && (p[2] - 5.0).abs() < 1e-9);
}
