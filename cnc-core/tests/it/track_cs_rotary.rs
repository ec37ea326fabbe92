//! A master's rotation followed word by word: a Cartesian slave without `#TRAFO` turns its A,
//! B or C axis by the master's angle with the master's sign (in the channel's own orientation
//! convention), alone and combined; `#TRACK CS ABS` takes the same per-axis offsets; and the
//! static offset of `#TRACK CS ON [... A= B= C=]` keeps the fixed Z-Y-X order whatever the
//! channel's convention.

use tests::channel_rig as support;

use cnc_core::channel::{ChannelConfig, RunState};
use hli::enums::DynCsState;
use hli::views::CncView;
use kinematics::tracking::{Tracking, TrackingMode, TrackingOption};
use kinematics::PoseWords;
use nalgebra::Isometry3;
use support::{cartesian, controller, image};

const MASTER_ON: &str = "#CHANNEL INTERFACE ON [DYN_CS]\n";

/// Runs a Cartesian master (channel 1) that moves to `target` after publishing its frame,
/// and a Cartesian slave (channel 2) running `slave`, both in convention `ori`, for 3 s.
/// Returns the set-points of master and slave.
fn follow(target: &str, slave: &str, ori: u32) -> ([f64; 6], [f64; 6]) {
    let master = format!("{MASTER_ON}#TIME 0.05\nG1 {target} F3000\n#TIME 0.2\nM30\n");
    let (mut m, mut s) = (cartesian("master"), cartesian("slave"));
    m.ori_rotation_angle = ori;
    s.ori_rotation_angle = ori;
    let mut ctl = controller(vec![(m, master.as_str()), (s, slave)]);
    let memory = image(2);
    let view = CncView::new(&memory);
    for _ in 0..3000 {
        ctl.tick(&view);
    }
    for c in ctl.channels() {
        assert_ne!(c.state(), RunState::Error, "{}: {:?}", target, c.error());
    }
    let words =
        |i: usize| -> [f64; 6] { core::array::from_fn(|k| ctl.channels()[i].set_points()[k]) };
    (words(0), words(1))
}

fn assert_words(got: [f64; 6], want: [f64; 6], what: &str) {
    for k in 0..6 {
        assert!(
            (got[k] - want[k]).abs() < 1e-6,
            "{what}: word {k} is {} instead of {} ({got:?})",
            got[k],
            want[k]
        );
    }
}

const TRACK: &str = "#TRACK CS ON [CH=1 FILTER=0 WAIT]\n#TIME 2\nM30\n";

#[test]
fn each_rotary_word_of_the_master_is_followed_with_its_own_sign() {
    for (k, name) in [(3, "A"), (4, "B"), (5, "C")] {
        for angle in [12.5, -12.5] {
            let (master, slave) = follow(&format!("{name}{angle}"), TRACK, 0);
            let mut want = [0.0; 6];
            want[k] = angle;
            assert_words(master, want, "the master");
            assert_words(slave, want, &format!("the slave of {name}{angle}"));
        }
    }
}

/// Combined angles map to the slave's words in the channel's convention: in yaw-pitch-roll
/// (0), Euler Z-Y-Z (1) and C-B-A (2) the slave stands on the master's own words.
#[test]
fn combined_rotations_are_followed_in_each_convention() {
    for ori in [0, 1, 2] {
        let (master, slave) = follow("A10 B20 C-30", TRACK, ori);
        assert_words(slave, master, &format!("convention {ori}"));
    }
}

/// `#TRACK CS ABS` (and its G92 twin) takes the master's words at switch-on as the per-axis
/// zero: the slave programmed at 0 stands where the tracking would have put it.
#[test]
fn track_cs_abs_and_g92_give_the_offsets_of_the_tracking() {
    let abs =
        "#TIME 0.5\n#TRACK CS ON [CH=1 SET_ZERO FILTER=0 WAIT]\n#TRACK CS OFF [FILTER=0 WAIT]\n\
               #TRACK CS ABS\nG1 X0 Y0 Z0 A0 B0 C0 F3000\n#TIME 1\nM30\n";
    let g92 = "#TIME 0.5\n#TRACK CS ON [CH=1 SET_ZERO FILTER=0 WAIT]\n#TRACK CS OFF [FILTER=0 WAIT]\n\
               G92 X=V.G.TRACK_CS.X Y=V.G.TRACK_CS.Y Z=V.G.TRACK_CS.Z A=V.G.TRACK_CS.A B=V.G.TRACK_CS.B C=V.G.TRACK_CS.C\n\
               G1 X0 Y0 Z0 A0 B0 C0 F3000\n#TIME 1\nM30\n";
    let target = "X5 A10 B-20 C30";
    let (master, tracked) = follow(target, TRACK, 0);
    assert_words(tracked, master, "tracked");
    for (what, program) in [("#TRACK CS ABS", abs), ("G92", g92)] {
        let (_, slave) = follow(target, program, 0);
        assert_words(slave, tracked, what);
    }
}

/// The static offset's angles are Z, then Y, then X in every convention: with A=30 and
/// C=-90 at once, the PLC master's translation reaches the slave turned by
/// `Rz(-90) * Rx(30)`, the same for conventions 0 and 1.
#[test]
fn the_static_offset_turns_z_then_y_then_x_in_every_convention() {
    let offset = PoseWords {
        xyz: [0.0; 3],
        abc: [30.0, 0.0, -90.0],
    };
    let tracking = Tracking::new(
        TrackingMode::MovingWorkpiece,
        TrackingOption::Full,
        &offset,
        false,
        None,
    )
    .unwrap();
    let master = Isometry3::translation(10.0, 0.0, 0.0);
    let want = tracking.compensation(&master).translation.vector;
    // By hand: X of the master turned -90 about Z (Rx first, which leaves X alone).
    assert!((want - nalgebra::Vector3::new(0.0, -10.0, 0.0)).norm() < 1e-9);
    // X first, then Z would give (0, -10 cos 30, -10 sin 30): the order matters here.
    let x_then_z = nalgebra::Vector3::new(0.0, -10.0 * 30f64.to_radians().cos(), -5.0);
    assert!((want - x_then_z).norm() > 1.0);
    for ori in [0, 1] {
        let mut c = cartesian("slave");
        c.ori_rotation_angle = ori;
        let program = "#TRACK CS ON [ID=0 A=30 C=-90 FILTER=0 WAIT]\n#TIME 1\nM30\n";
        let mut ctl = controller(vec![(c, program)]);
        let memory = image(1);
        support::enable_plc_master(&memory, [100_000, 0, 0]);
        let view = CncView::new(&memory);
        for _ in 0..100 {
            ctl.tick(&view);
        }
        let ch = &ctl.channels()[0];
        assert_eq!(ch.tracker().state(), DynCsState::Active);
        let got = ch.tracker().applied().translation.vector;
        assert!(
            (got - want).norm() < 1e-9,
            "convention {ori}: {got:?} vs {want:?}"
        );
    }
}

/// Euler Z-Y-Z (convention 1): a master that tilts about X through B = 0 (A-90 B2 C90 to
/// A-90 B-2 C90, each a turn about X) is followed word by word through the singular
/// orientation: the slave's B passes 0 and its A and C stay, instead of flipping by 180
/// degree (which stopped the slave beyond its lag bound).
#[test]
fn an_euler_zyz_slave_follows_a_tilt_through_the_singular_orientation() {
    let master = format!(
        "{MASTER_ON}#TIME 0.05\nG1 A-90 B2 C90 F30000\n#TIME 0.1\nG1 B-2 F3000\n#TIME 0.2\nM30\n"
    );
    let (mut m, mut s) = (cartesian("master"), cartesian("slave"));
    m.ori_rotation_angle = 1;
    s.ori_rotation_angle = 1;
    let mut ctl = controller(vec![(m, master.as_str()), (s, TRACK)]);
    let memory = image(2);
    let view = CncView::new(&memory);
    let mut a_seen = (f64::MAX, f64::MIN);
    for _ in 0..3000 {
        ctl.tick(&view);
        let b = ctl.channels()[1].set_points()[4];
        if ctl.channels()[0].set_points()[3] < -89.999 && b.abs() < 2.0 {
            let a = ctl.channels()[1].set_points()[3];
            a_seen = (a_seen.0.min(a), a_seen.1.max(a));
        }
    }
    for c in ctl.channels() {
        assert_ne!(c.state(), RunState::Error, "{:?}", c.error());
    }
    let words =
        |i: usize| -> [f64; 6] { core::array::from_fn(|k| ctl.channels()[i].set_points()[k]) };
    assert_words(words(0), [0.0, 0.0, 0.0, -90.0, -2.0, 90.0], "the master");
    assert_words(words(1), words(0), "the slave");
    assert!(
        a_seen.0 > -90.01 && a_seen.1 < -89.99,
        "A stayed (within the rounding near B = 0) while B passed 0: {a_seen:?}"
    );
}

/// The same pair, the slave switching off (FILTER=300) while the master stands at A-90 B-2
/// C90: its words blend back without a step, and what the nearest words kept at the end of
/// the blend (A-90 C90, no rotation in Z-Y-Z) is caught up within the axes' limits before the
/// tracking is INACTIVE; the slave ends on its programmed words.
#[test]
fn an_euler_zyz_slave_switches_off_onto_its_programmed_words_without_a_step() {
    let master = format!(
        "{MASTER_ON}#TIME 0.05\nG1 A-90 B2 C90 F3000\n#TIME 0.1\nG1 B-2 F3000\n#TIME 5\nM30\n"
    );
    let slave = "#TRACK CS ON [CH=1 FILTER=0 WAIT]\n#TIME 3.5\n#TRACK CS OFF [FILTER=300 WAIT]\n\
                 #TIME 0.5\nM30\n";
    // The slave with real axis limits (the rig's are stiff): a step would break them.
    let (mut m, mut s) = (
        cartesian("master"),
        ChannelConfig::new("slave", &["X", "Y", "Z", "A", "B", "C"]),
    );
    m.ori_rotation_angle = 1;
    s.ori_rotation_angle = 1;
    let limit = s.axis_limits(3).velocity * support::CYCLE;
    let mut ctl = controller(vec![(m, master.as_str()), (s, slave)]);
    let memory = image(2);
    let view = CncView::new(&memory);
    let mut last: Option<[f64; 6]> = None;
    let mut largest = 0.0f64;
    for _ in 0..6000 {
        ctl.tick(&view);
        let now: [f64; 6] = core::array::from_fn(|k| ctl.channels()[1].set_points()[k]);
        if let Some(before) = last {
            for k in 3..6 {
                largest = largest.max((now[k] - before[k]).abs());
            }
        }
        last = Some(now);
    }
    for c in ctl.channels() {
        assert_ne!(c.state(), RunState::Error, "{:?}", c.error());
    }
    assert!(
        largest <= limit * (1.0 + 1e-6),
        "a step of {largest} degree in a tick"
    );
    assert_eq!(ctl.channels()[1].tracker().state(), DynCsState::Inactive);
    assert_words(last.unwrap(), [0.0; 6], "the slave after switching off");
}
