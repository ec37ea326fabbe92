//! Robots are configured, not picked: kinematic 45 by its geometry (the presets are
//! shortcuts), kinematic 201 by its DH rows, both running in a channel, and the tool data
//! record (`D`) on the flange under a transformation.

use tests::channel_rig as support;

use cnc_core::channel::kin_config::{DhRow, KinematicsConfig, OpwGeometry};
use cnc_core::channel::{Channel, ChannelConfig, RunState};
use hli::views::CncView;
use kinematics::opw::Robot45Params;
use kinematics::RotationOrder;
use nalgebra::Vector3;
use support::{controller, image, run_to_end, stiff, CYCLE, ROBOT_HOME};

fn kr6_geometry() -> OpwGeometry {
    let p = Robot45Params::kuka_kr6_r900_sixx();
    OpwGeometry {
        base_to_j2_z: p.base_to_j2_z,
        base_to_j2_x: p.base_to_j2_x,
        j2_to_j3_z: p.j2_to_j3_z,
        j3_to_j5_x: p.j3_to_j5_x,
        j3_to_j5_z: p.j3_to_j5_z,
        lateral_offset: 0.0,
        j5_to_flange: p.j5_to_flange,
    }
}

fn config(k: &str) -> KinematicsConfig {
    toml::from_str(k).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_robot_given_by_its_geometry_is_the_preset_it_copies_and_overrides_change_it() {
    let q = [10.0, -70.0, 80.0, 20.0, 40.0, 30.0];
    let preset = config("id = 45\npreset = \"kr6r900sixx\"\n")
        .build(RotationOrder::Zyx)
        .unwrap();
    let g = kr6_geometry();
    let by_geometry = config(&format!(
        "id = 45\ngeometry = {{ base_to_j2_z = {}, base_to_j2_x = {}, j2_to_j3_z = {}, \
         j3_to_j5_x = {}, j3_to_j5_z = {}, j5_to_flange = {} }}\n\
         zero_offsets = [-90.0, 0.0]\ndirections = [-1.0, 1.0, 1.0, -1.0, 1.0, -1.0]\n",
        g.base_to_j2_z, g.base_to_j2_x, g.j2_to_j3_z, g.j3_to_j5_x, g.j3_to_j5_z, g.j5_to_flange
    ))
    .build(RotationOrder::Zyx)
    .unwrap();
    let (a, b) = (
        preset.forward(&q).unwrap(),
        by_geometry.forward(&q).unwrap(),
    );
    assert!((a.translation.vector - b.translation.vector).norm() < 1e-12);
    // A longer upper arm and the tool 100 mm out along the flange's Z.
    let longer = config(
        "id = 45\npreset = \"kr6r900sixx\"\ngeometry = { base_to_j2_z = 400.0, base_to_j2_x = 25.0, \
         j2_to_j3_z = 500.0, j3_to_j5_x = 420.0, j3_to_j5_z = 35.0, j5_to_flange = 80.0 }\n\
         tool = [0.0, 0.0, 100.0, 0.0, 0.0, 0.0]\n",
    )
    .build(RotationOrder::Zyx)
    .unwrap();
    let c = longer.forward(&q).unwrap();
    assert!((c.translation.vector - a.translation.vector).norm() > 10.0);
    let back = longer.inverse(&c, &q).unwrap();
    assert!(
        back.iter().zip(q).all(|(x, y)| (x - y).abs() < 1e-7),
        "{back:?}"
    );
}

#[test]
fn geometries_and_keys_that_cannot_run_are_refused_naming_the_key() {
    for (text, needle) in [
        (
            "id = 45\ngeometry = { base_to_j2_z = 400.0, base_to_j2_x = 25.0, j2_to_j3_z = 1e-300, \
             j3_to_j5_x = 420.0, j3_to_j5_z = 35.0, j5_to_flange = 80.0 }\n",
            "closed-form inverse",
        ),
        (
            "id = 45\ngeometry = { base_to_j2_z = 400.0, base_to_j2_x = 25.0, j2_to_j3_z = -1.0, \
             j3_to_j5_x = 420.0, j3_to_j5_z = 35.0, j5_to_flange = 80.0 }\n",
            "j2_to_j3_z",
        ),
        ("id = 45\ndirections = [1.0, 1.0, 2.0, 1.0, 1.0, 1.0]\n", "directions"),
        ("id = 45\njoint_limits = [[0.0, 1.0]]\n", "joint_limits: 1 entries for 6 joints"),
        (
            "id = 45\njoint_limits = [[0,1],[0,1],[0,1],[0,1],[5,1],[0,1]]\n",
            "joint_limits[4]",
        ),
        ("id = 0\npreset = \"kr6r900sixx\"\n", "preset is given for kinematic 45 only"),
        ("id = 201\n", "chain: 0 rows"),
        ("id = 45\npreset = \"robby\"\n", "preset \"robby\" is not known"),
        ("id = 9001\n", "not available in channels"),
    ] {
        let e = config(text).build(RotationOrder::Zyx).err().unwrap_or_default();
        assert!(e.contains(needle), "{text}: {e}");
    }
    // Through a channel: the channel and the key are named.
    let mut c = ChannelConfig::new("r", &["X", "Y", "Z", "A", "B", "C"]);
    c.kinematics = config("id = 201\n");
    let e = Channel::new(0, c, CYCLE).unwrap_err().to_string();
    assert!(e.contains("channel r: kinematics: chain"), "{e}");
}

/// Kinematic 201 runs in a channel: a six-joint DH chain under `#TRAFO [201]` moves its tool
/// point onto the programmed points.
/// A six-joint DH chain (kinematic 201) standing at a pose inside its reach.
fn dh_chain(name: &str) -> ChannelConfig {
    let mut c = stiff(ChannelConfig::new(name, &["X", "Y", "Z", "A", "B", "C"]));
    c.kinematics.id = 201;
    c.kinematics.chain = vec![
        DhRow {
            a: 25.0,
            alpha: -90.0,
            d: 400.0,
            theta: 0.0,
            prismatic: false,
        },
        DhRow {
            a: 455.0,
            alpha: 0.0,
            d: 0.0,
            theta: -90.0,
            prismatic: false,
        },
        DhRow {
            a: 35.0,
            alpha: -90.0,
            d: 0.0,
            theta: 0.0,
            prismatic: false,
        },
        DhRow {
            a: 0.0,
            alpha: 90.0,
            d: 420.0,
            theta: 0.0,
            prismatic: false,
        },
        DhRow {
            a: 0.0,
            alpha: -90.0,
            d: 0.0,
            theta: 0.0,
            prismatic: false,
        },
        DhRow {
            a: 0.0,
            alpha: 0.0,
            d: 80.0,
            theta: 0.0,
            prismatic: false,
        },
    ];
    c.start = vec![0.0, 20.0, 10.0, 0.0, 30.0, 0.0];
    c
}

#[test]
fn a_dh_chain_runs_in_a_channel() {
    let c = dh_chain("chain");
    let mut ctl = controller(vec![(
        c,
        "#TRAFO [201]\nG91 G1 X20 Y-15 Z10 F3000\nG1 X-10 F3000\nM30\n",
    )]);
    let memory = image(1);
    let start = ctl.channels()[0].tool_pose().translation.vector;
    run_to_end(&mut ctl, &memory, 10_000);
    let ch = &ctl.channels()[0];
    assert_eq!(ch.state(), RunState::Finished, "{:?}", ch.error());
    let moved = ch.tool_pose().translation.vector - start;
    assert!(
        (moved - Vector3::new(10.0, -15.0, 10.0)).norm() < 1e-6,
        "{moved:?}"
    );
    let realised = ch.realised_tool(ch.set_points()).unwrap();
    assert!((realised.translation.vector - ch.tool_pose().translation.vector).norm() < 1e-9);
}

/// `D1` (length 100 mm, turned 90 degrees about the tool axis) under `#TRAFO`: the axes do not
/// move at the D block; the programmed pose is then the record's tool point, which the next
/// block moves, and the tool pose (display, tracking error) is the record's tool point.
#[test]
fn the_tool_record_is_on_the_flange_under_a_transformation() {
    let mut c = support::robot("r");
    c.nc.tools = support::tools("{ d = 1, length = 100.0, orientation = [0.0, 0.0, 90.0] }");
    let program = "#TRAFO [45]\n#TIME 0.01\nD1\n#TIME 0.01\nG91 G1 Z-20 F3000\nM30\n";
    let mut ctl = controller(vec![(c, program)]);
    let memory = image(1);
    let view = CncView::new(&memory);
    let flange = ctl.channels()[0].tool_pose();
    let mut at_d = None;
    for _ in 0..5000 {
        ctl.tick(&view);
        let ch = &ctl.channels()[0];
        if ch.line() == 4 && at_d.is_none() {
            at_d = Some(ch.set_points().to_vec());
        }
        if ch.state() == RunState::Finished {
            break;
        }
    }
    let ch = &ctl.channels()[0];
    assert_eq!(ch.state(), RunState::Finished, "{:?}", ch.error());
    let at_d = at_d.unwrap();
    let still = at_d
        .iter()
        .zip(ROBOT_HOME)
        .all(|(a, b)| (a - b).abs() < 1e-9);
    assert!(still, "no motion at the D block: {at_d:?}");
    let tool = ch.tool_pose();
    // The record's tool point: 100 mm along the flange's Z from where the flange was, then
    // moved 20 mm down.
    let expected = flange.translation.vector
        + flange.rotation * Vector3::new(0.0, 0.0, 100.0)
        + Vector3::new(0.0, 0.0, -20.0);
    assert!(
        (tool.translation.vector - expected).norm() < 1e-6,
        "{tool:?}"
    );
    let turn = (flange.rotation.inverse() * tool.rotation).euler_angles();
    assert!((turn.2.to_degrees() - 90.0).abs() < 1e-6, "{turn:?}");
    let realised = ch.realised_tool(ch.set_points()).unwrap();
    assert!((realised.translation.vector - tool.translation.vector).norm() < 1e-9);
}

/// Kinematic 201 as a master channel (seed 003: a master's frame comes from its kinematic,
/// 45 or 201): its tool frame is published on its interface every tick, and a Cartesian
/// slave tracking it RELATIVE moves by what the chain's tool point moves.
#[test]
fn a_dh_chain_is_a_master_channel() {
    let master = "#TRAFO [201]\n#CHANNEL INTERFACE ON [DYN_CS]\n#TIME 0.05\nG91 G1 X20 Y-15 Z10 F3000\n#TIME 0.2\nM30\n";
    let slave = "#TRACK CS ON [CH=1 RELATIVE FILTER=0]\n#TIME 2\nM30\n";
    let mut ctl = controller(vec![
        (dh_chain("chain"), master),
        (
            stiff(ChannelConfig::new("slave", &["X", "Y", "Z", "A", "B", "C"])),
            slave,
        ),
    ]);
    let memory = image(2);
    let view = CncView::new(&memory);
    for _ in 0..2600 {
        ctl.tick(&view);
        let m = &ctl.channels()[0];
        assert_ne!(m.state(), RunState::Error, "{:?}", m.error());
        let leaf = |path: &str| {
            hli::access::Leaf::resolve(&format!("gpCh[0]^channel_interface.dyn_cs.{path}"))
                .unwrap()
                .read(&memory)
                .as_f64() as i64
        };
        assert_eq!(leaf("valid_r"), 1);
        let expected =
            cnc_core::channel::hli_frame::frame_to_hli(&m.tool_pose(), RotationOrder::Zyx).unwrap();
        for k in 0..3 {
            assert_eq!(
                leaf(&format!("cs_r.translation[{k}]")),
                i64::from(expected.translation[k])
            );
            assert_eq!(
                leaf(&format!("cs_r.rotation[{k}]")),
                i64::from(expected.rotation[k])
            );
        }
    }
    let s = &ctl.channels()[1];
    assert_eq!(s.state(), RunState::Finished, "{:?}", s.error());
    let moved = Vector3::new(s.set_points()[0], s.set_points()[1], s.set_points()[2]);
    assert!(
        (moved - Vector3::new(20.0, -15.0, 10.0)).norm() < 1e-6,
        "{moved:?}"
    );
}
