//! What a channel displays on the HLI (seed 003, "display on the HLI" and the channel
//! parameters): `w0_position_r` under P-CHAN-00145 `kin_trafo_display` 0/1/2 and its range
//! check, a master's `#CHANNEL INTERFACE` values (enabled, valid, freeze, update counter), the
//! automatic switch-on by P-CHAN-00399 `provide_channel_interface.track_cs`, and the slave's
//! `request_r`.

use tests::channel_rig as support;

use cnc_core::channel::{Channel, ChannelConfigError, Controller, RunState};
use hli::access::Leaf;
use hli::enums::{DynCsCommand, DynCsState};
use hli::views::{CncView, PlcView};
use hli::{Bool, ImageMemory};
use kinematics::opw::{Robot45, Robot45Params};
use kinematics::{Kinematics, PoseWords, RotationOrder};
use support::*;

/// `gpCh[ch]^bahn_state.coord_r[0..6].w0_position_r`.
fn w0(memory: &ImageMemory, channel: usize) -> [i64; 6] {
    core::array::from_fn(|i| {
        let path = format!("gpCh[{channel}]^bahn_state.coord_r[{i}].w0_position_r");
        Leaf::resolve(&path).unwrap().read(memory).as_f64() as i64
    })
}

/// `gpCh[0]^channel_interface.dyn_cs.NAME`.
fn interface(memory: &ImageMemory, name: &str) -> i64 {
    Leaf::resolve(&format!("gpCh[0]^channel_interface.dyn_cs.{name}"))
        .unwrap()
        .read(memory)
        .as_f64() as i64
}

/// The tool pose of the KR 6 R900 at `joints`, in HLI units (0.1 um, 0.0001 degree; A B C in
/// the channel's default convention, yaw-pitch-roll), from the kinematics crate directly.
fn tool_words(joints: &[f64; 6]) -> [i64; 6] {
    let robot = Robot45::new(Robot45Params::kuka_kr6_r900_sixx()).unwrap();
    let frame = robot.forward(joints).unwrap();
    let w = PoseWords::from_frame(&frame, RotationOrder::YawPitchRoll);
    let words = [w.xyz[0], w.xyz[1], w.xyz[2], w.abc[0], w.abc[1], w.abc[2]];
    words.map(|v| (v * 10_000.0).round() as i64)
}

/// P-CHAN-00145: with 0 `w0_position_r` stays 0; with 1, and with 2 (multi-stage display; one
/// stage here, so the same), it is the TCP in the machine's base frame, computed from the
/// set-points also without an active transformation (joints programmed directly).
#[test]
fn w0_position_r_follows_kin_trafo_display() {
    let joints = [10.0, -70.0, 95.0, 5.0, 50.0, -20.0];
    let program = format!(
        "G1 X{} Y{} Z{} A{} B{} C{} F60000\nM30\n",
        joints[0], joints[1], joints[2], joints[3], joints[4], joints[5]
    );
    let expected = tool_words(&joints);
    assert!(expected[0].abs() > 1_000_000, "a pose away from zero");
    for display in [0u16, 1, 2] {
        let mut config = robot("r");
        config.kin_trafo_display = display;
        let mut ctl = controller(vec![(config, program.as_str())]);
        let memory = image(1);
        run_to_end(&mut ctl, &memory, 20_000);
        ctl.tick(&CncView::new(&memory));
        let shown = w0(&memory, 0);
        if display == 0 {
            assert_eq!(shown, [0; 6]);
        } else {
            for i in 0..6 {
                assert!(
                    (shown[i] - expected[i]).abs() <= 1,
                    "display {display}, word {i}: {shown:?} vs {expected:?}"
                );
            }
        }
    }
    // Under #TRAFO the TCP is the programmed pose.
    let mut config = robot("r");
    config.kin_trafo_display = 1;
    let mut ctl = controller(vec![(config, "#TRAFO [45]\nG1 X600 Y50 Z450 F6000\nM30\n")]);
    let memory = image(1);
    run_to_end(&mut ctl, &memory, 20_000);
    ctl.tick(&CncView::new(&memory));
    let shown = w0(&memory, 0);
    assert_eq!(&shown[..3], &[6_000_000, 500_000, 4_500_000]);
}

#[test]
fn kin_trafo_display_outside_0_to_2_is_refused() {
    let mut config = robot("r");
    config.kin_trafo_display = 3;
    match Channel::new(0, config, CYCLE) {
        Err(ChannelConfigError::Parameter { name, value, .. }) => {
            assert_eq!((name, value), ("kin_trafo_display", 3.0));
        }
        other => panic!("{:?}", other.map(|_| ())),
    }
}

/// The master's interface as another channel or the PLC reads it: enabled and valid with the
/// update counter counting every tick while `#CHANNEL INTERFACE ON`, the frame the tool's
/// (here X 10 mm); after OFF neither enabled nor valid, the counter and frame standing.
#[test]
fn a_master_interface_counts_its_updates_and_stops_when_switched_off() {
    let mut ctl = controller(vec![(
        cartesian("master"),
        "#CHANNEL INTERFACE ON [DYN_CS]\nG1 X10 F6000\n#TIME 0.05\n#CHANNEL INTERFACE OFF [DYN_CS]\n#TIME 0.05\nM30\n",
    )]);
    let memory = image(1);
    let view = CncView::new(&memory);
    let leaf = |name: &str| interface(&memory, name);
    let mut last_count = 0;
    let mut on_ticks = 0;
    let mut off_seen = false;
    for _ in 0..2000 {
        ctl.tick(&view);
        let (enabled, valid, count) =
            (leaf("enabled_r"), leaf("valid_r"), leaf("update_counter_r"));
        if enabled == 1 {
            assert!(!off_seen, "switched on again");
            assert_eq!(valid, 1);
            assert_eq!(leaf("freeze_r"), 0);
            assert_eq!(count, last_count + 1, "one update per tick");
            on_ticks += 1;
        } else if on_ticks > 0 {
            off_seen = true;
            assert_eq!(valid, 0);
            assert_eq!(count, last_count, "the counter stands");
            assert_eq!(
                leaf("cs_r.translation[0]"),
                100_000,
                "the last frame: X 10 mm"
            );
        }
        last_count = count;
        if ctl.channels()[0].state() == RunState::Finished {
            break;
        }
    }
    assert!(off_seen && on_ticks > 100, "{on_ticks}");
}

/// A master in ERROR publishes but is no longer valid: freeze_r TRUE, the counter standing.
#[test]
fn a_master_in_error_shows_freeze() {
    let mut ctl = controller(vec![(
        cartesian("master"),
        "#CHANNEL INTERFACE ON [DYN_CS]\nG1 X1 F6000\n#CS ON [1, 0, 0, 0, 0, 0]\nM30\n",
    )]);
    let memory = image(1);
    let view = CncView::new(&memory);
    for _ in 0..1000 {
        ctl.tick(&view);
    }
    assert_eq!(ctl.channels()[0].state(), RunState::Error);
    let read = |name: &str| interface(&memory, name);
    let count = read("update_counter_r");
    ctl.tick(&view);
    assert_eq!(
        (read("enabled_r"), read("valid_r"), read("freeze_r")),
        (1, 0, 1)
    );
    assert_eq!(read("update_counter_r"), count);
}

/// P-CHAN-00399: with `provide_channel_interface.track_cs` the master publishes from the
/// program's start without `#CHANNEL INTERFACE`, and a slave can track it (`CH=1`); without
/// it the same slave waits in ACTIVATING for an interface that never comes.
#[test]
fn provide_channel_interface_switches_the_interface_on_at_program_start() {
    let run = |provide: bool| -> Controller {
        let mut master = cartesian("master");
        master.provide_channel_interface.track_cs = provide;
        let mut ctl = controller(vec![
            (master, "G1 X10 F600\nM30\n"),
            (
                cartesian("slave"),
                "#TRACK CS ON [CH=1 FILTER=0]\n#TIME 0.5\nM30\n",
            ),
        ]);
        let memory = image(2);
        let view = CncView::new(&memory);
        for _ in 0..1500 {
            ctl.tick(&view);
        }
        ctl
    };
    let ctl = run(true);
    let (master, slave) = (&ctl.channels()[0], &ctl.channels()[1]);
    assert!(master.published().is_some());
    assert_eq!(slave.state(), RunState::Finished, "{:?}", slave.error());
    assert_eq!(slave.tracker().state(), DynCsState::Active);
    let ctl = run(false);
    let slave = &ctl.channels()[1];
    assert_eq!(slave.state(), RunState::Finished, "{:?}", slave.error());
    assert_eq!(slave.tracker().state(), DynCsState::Activating);
}

/// `request_r` of a tracking slave carries the compensation it applies (request pattern: the
/// CNC posts when the PLC has read the last one).
#[test]
fn request_r_carries_the_applied_compensation() {
    let mut ctl = controller(vec![(cartesian("slave"), "#TIME 1\nM30\n")]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    let view = CncView::new(&memory);
    // 1 um: without a filter the step reaches the axes at once, within their limits.
    enable_plc_master(&memory, [10, -10, 0]);
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(DynCsCommand::Activate, &transition(0, Bool::FALSE))
        .unwrap();
    ctl.tick(&view);
    // FILTER=0: ACTIVATING is shown for the switch-on tick, ACTIVE from the next.
    assert_eq!(plc.dyn_cs_state(0).unwrap(), Ok(DynCsState::Activating));
    ctl.tick(&view);
    assert_eq!(plc.dyn_cs_state(0).unwrap(), Ok(DynCsState::Active));
    let mut reader = plc.dyn_cs_request(0).unwrap();
    let request = reader.try_take().unwrap().expect("posted");
    assert_eq!(request.translation, [10, -10, 0]);
    assert_eq!(request.rotation, [0, 0, 0]);
    // Not read again: nothing new is posted until the PLC has taken the last one.
    assert_eq!(reader.try_take().unwrap(), None);
    plc.dyn_cs_command(0)
        .unwrap()
        .try_send(&cs([20, 0, 0]))
        .unwrap();
    ctl.tick(&view);
    let request = reader.try_take().unwrap().expect("posted again");
    assert_eq!(request.translation, [20, 0, 0]);
}

/// The dynamic CS's input and output on the HLI: the manual's diagnosis example (the axis at
/// X 0.32 mm, the PLC's frame (0.1, -0.1, 0) mm) shows the pose before the dynamic CS in
/// `position_in_dyncs_r` (3200, 0) and after it in `position_dyncs_r` (4200, -1000).
#[test]
fn the_pose_before_and_after_the_dynamic_cs_are_shown_side_by_side() {
    let mut ctl = controller(vec![(
        cartesian("slave"),
        "G1 X0.32 F600\n#TRACK CS ON [ID=0 FILTER=0 WAIT]\n#TIME 1\nM30\n",
    )]);
    let memory = image(1);
    let view = CncView::new(&memory);
    enable_plc_master(&memory, [1000, -1000, 0]);
    for _ in 0..300 {
        ctl.tick(&view);
    }
    assert_eq!(ctl.channels()[0].tracker().state(), DynCsState::Active);
    let leaf = |i: usize, name: &str| {
        Leaf::resolve(&format!("gpCh[0]^bahn_state.coord_r[{i}].{name}"))
            .unwrap()
            .read(&memory)
            .as_f64() as i64
    };
    let input: Vec<i64> = (0..3).map(|i| leaf(i, "position_in_dyncs_r")).collect();
    let output: Vec<i64> = (0..3).map(|i| leaf(i, "position_dyncs_r")).collect();
    assert_eq!(input, [3200, 0, 0]);
    assert_eq!(output, [4200, -1000, 0]);
}
