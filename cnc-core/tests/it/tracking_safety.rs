//! Safe tracking: a slave that cannot follow stops within its axes' limits, a step of the
//! tracked motion beyond them is refused, and switching on does not depend on which channel
//! ticks first. The axes here have real limits (the other channel tests use stiff ones).

use tests::channel_rig as support;

use cnc_core::channel::dyn_cs::TrackEvent;
use cnc_core::channel::path::AxisLimits;
use cnc_core::channel::{ChannelConfig, LoadedProgram, RunState};
use hli::enums::{ChannelErrorId, DynCsCommand, DynCsState};
use hli::views::{CncView, PlcView};
use hli::Bool;
use support::{controller, cs, image, transition, CYCLE, ROBOT_HOME};

/// Joint limits of a small six-axis robot (degrees per second and its derivatives).
const JOINT: AxisLimits = AxisLimits {
    velocity: 300.0,
    acceleration: 2000.0,
    jerk: 40_000.0,
};

fn robot(name: &str) -> ChannelConfig {
    let mut c = ChannelConfig::new(name, &["X", "Y", "Z", "A", "B", "C"]);
    c.kinematics.id = 45;
    c.kinematics.preset = Some("kr6r900sixx".into());
    c.start = ROBOT_HOME.to_vec();
    c.axis_limits = vec![JOINT; 6];
    c
}

fn cartesian(name: &str) -> ChannelConfig {
    ChannelConfig::new(name, &["X", "Y", "Z", "A", "B", "C"])
}

/// Watches one channel's set-points tick by tick: every step within the axes' velocity and
/// acceleration limits (the acceleration with 1 % for the sampling of the braking profile).
struct StepWatch {
    last: Vec<f64>,
    velocity: Vec<f64>,
    limits: AxisLimits,
    ticks: u32,
}

impl StepWatch {
    fn new(start: &[f64], limits: AxisLimits) -> Self {
        Self {
            last: start.to_vec(),
            velocity: vec![0.0; start.len()],
            limits,
            ticks: 0,
        }
    }

    fn check(&mut self, now: &[f64], what: &str) {
        self.ticks += 1;
        for (i, &p) in now.iter().enumerate() {
            let v = (p - self.last[i]) / CYCLE;
            let a = (v - self.velocity[i]) / CYCLE;
            assert!(
                v.abs() <= self.limits.velocity * (1.0 + 1e-6),
                "{what}, tick {}: axis {} velocity {v}",
                self.ticks,
                i + 1
            );
            assert!(
                a.abs() <= self.limits.acceleration * 1.01,
                "{what}, tick {}: axis {} acceleration {a}",
                self.ticks,
                i + 1
            );
            self.last[i] = p;
            self.velocity[i] = v;
        }
    }

    fn at_rest(&self) -> bool {
        self.velocity.iter().all(|v| *v == 0.0)
    }
}

/// A slave robot tracks a Cartesian master (RELATIVE: from where the master stood) that runs
/// 700 mm out of the robot's reach and comes back. The slave goes to ERROR (tracker and
/// channel), brakes its joints within their limits to rest, holds there while the master
/// comes back (no jump), and after a reset a new program couples in softly again.
#[test]
fn a_slave_whose_master_leaves_its_reach_stops_within_its_limits_and_recovers() {
    let master = "#CHANNEL INTERFACE ON [DYN_CS]\n#TIME 0.1\nG1 X700 F6000\nG1 X0 F6000\nM30\n";
    let slave = "#TRAFO [45]\n#TRACK CS ON [CH=1 RELATIVE FILTER=0]\n#TIME 30\nM30\n";
    let mut ctl = controller(vec![(cartesian("master"), master), (robot("slave"), slave)]);
    let memory = image(2);
    let view = CncView::new(&memory);
    let plc = PlcView::new(&memory);
    let mut watch = StepWatch::new(&ROBOT_HOME, JOINT);
    let mut error_tick = None;
    for tick in 0..20_000u32 {
        ctl.tick(&view);
        let (m, s) = (&ctl.channels()[0], &ctl.channels()[1]);
        watch.check(s.set_points(), "slave");
        if error_tick.is_none() && s.state() == RunState::Error {
            error_tick = Some(tick);
            assert_eq!(s.tracker().state(), DynCsState::Error);
            assert_eq!(plc.dyn_cs_state(1).unwrap(), Ok(DynCsState::Error));
            let e = s.error().unwrap();
            assert!(
                matches!(e.id, ChannelErrorId::Kinematics | ChannelErrorId::Tracking),
                "{e:?}"
            );
        }
        if m.state() == RunState::Finished && error_tick.is_some() && !s.settling() {
            break;
        }
    }
    let error_tick = error_tick.expect("the slave could not follow and failed");
    assert!(watch.at_rest(), "the slave came to rest");
    let s = &ctl.channels()[1];
    assert!(!s.is_moving());
    // The master is back where it started; the slave stands where it braked.
    let held = s.set_points().to_vec();
    for _ in 0..100 {
        ctl.tick(&view);
        watch.check(ctl.channels()[1].set_points(), "held");
    }
    assert_eq!(ctl.channels()[1].set_points().to_vec(), held);
    assert!(
        error_tick > 100,
        "it tracked before it failed ({error_tick})"
    );
    // Recovery: a reset clears both errors where the axes stand; a new program switches on
    // with a filter and follows again without a step.
    let channel = ctl.channel_mut(1).unwrap();
    channel.reset().unwrap();
    assert_eq!(channel.state(), RunState::Idle);
    assert_eq!(channel.tracker().state(), DynCsState::Inactive);
    assert!(channel.error().is_none());
    let again = "#TRAFO [45]\n#TRACK CS ON [CH=1 FILTER=200]\n#TIME 1\nM30\n";
    channel
        .start(LoadedProgram::load("slave", again, &channel.config().axes.clone()).unwrap())
        .unwrap();
    for _ in 0..1500 {
        ctl.tick(&view);
        watch.check(ctl.channels()[1].set_points(), "recovered");
    }
    let s = &ctl.channels()[1];
    assert_eq!(s.state(), RunState::Finished, "{:?}", s.error());
    assert_eq!(s.tracker().state(), DynCsState::Active);
}

/// A PLC frame step of 100 mm without a filter, beyond `track_lag_max` (5 mm): the step is
/// refused (never handed to the axes), the tracker goes to ERROR, the channel fails naming the
/// lag, and the axes stay within their limits.
#[test]
fn a_frame_step_without_filter_is_refused_on_a_cartesian_and_a_robot_slave() {
    for (config, program) in [
        (
            cartesian("xyz"),
            "#TRACK CS ON [ID=0 FILTER=0]\n#TIME 2\nM30\n",
        ),
        (
            robot("kr6"),
            "#TRAFO [45]\n#TRACK CS ON [ID=0 FILTER=0]\n#TIME 2\nM30\n",
        ),
    ] {
        let limits = config.axis_limits(0);
        let start: Vec<f64> = {
            let mut s = config.start.clone();
            s.resize(6, 0.0);
            s
        };
        let name = config.name.clone();
        let mut ctl = controller(vec![(config, program)]);
        let memory = image(1);
        let view = CncView::new(&memory);
        let plc = PlcView::new(&memory);
        plc.set_dyn_cs_enabled(0, true).unwrap();
        plc.dyn_cs_command(0)
            .unwrap()
            .try_send(&cs([0; 3]))
            .unwrap();
        let mut watch = StepWatch::new(&start, limits);
        for _ in 0..50 {
            ctl.tick(&view);
            watch.check(ctl.channels()[0].set_points(), &name);
        }
        assert_eq!(ctl.channels()[0].tracker().state(), DynCsState::Active);
        // 100 mm in X in one frame.
        plc.dyn_cs_command(0)
            .unwrap()
            .try_send(&cs([1_000_000, 0, 0]))
            .unwrap();
        let before = ctl.channels()[0].set_points().to_vec();
        for _ in 0..200 {
            ctl.tick(&view);
            watch.check(ctl.channels()[0].set_points(), &name);
        }
        let ch = &ctl.channels()[0];
        assert_eq!(ch.tracker().state(), DynCsState::Error, "{name}");
        assert_eq!(ch.state(), RunState::Error);
        assert_eq!(ch.error().unwrap().id, ChannelErrorId::Tracking);
        assert!(ch
            .error()
            .unwrap()
            .to_string()
            .contains("beyond track_lag_max (5 mm, 5 degree)"));
        assert_eq!(
            ch.set_points().to_vec(),
            before,
            "{name}: nothing of the step passed"
        );
    }
}

/// A PLC frame step of 0.1 mm while ACTIVE (the manual leaves such a jump to the user):
/// caught up on a jerk-limited profile within every axis's limits (5000 mm/s^2 on the
/// Cartesian axes, the joints' own on the robot; every tick watched), landing exactly on the
/// new compensation well within 100 ticks; the tracking stays ACTIVE, and the lag is shown
/// on the HLI while it lasts and logged.
#[test]
fn a_small_plc_frame_step_is_caught_up_and_the_tracking_stays_active() {
    for (config, program) in [
        (
            cartesian("xyz"),
            "#TRACK CS ON [ID=0 FILTER=0 WAIT]\n#TIME 2\nM30\n",
        ),
        (
            robot("kr6"),
            "#TRAFO [45]\n#TRACK CS ON [ID=0 FILTER=0 WAIT]\n#TIME 2\nM30\n",
        ),
    ] {
        let limits = config.axis_limits(0);
        let mut start = config.start.clone();
        start.resize(6, 0.0);
        let name = config.name.clone();
        let mut ctl = controller(vec![(config, program)]);
        let memory = image(1);
        let view = CncView::new(&memory);
        let plc = PlcView::new(&memory);
        support::enable_plc_master(&memory, [0; 3]);
        let mut watch = StepWatch::new(&start, limits);
        for _ in 0..50 {
            ctl.tick(&view);
            watch.check(ctl.channels()[0].set_points(), &name);
        }
        assert_eq!(ctl.channels()[0].tracker().state(), DynCsState::Active);
        let tool_before = ctl.channels()[0].tool_pose().translation.vector;
        plc.dyn_cs_command(0)
            .unwrap()
            .try_send(&cs([1_000, 0, 0]))
            .unwrap();
        let (mut landed, mut hli_lag_seen) = (None, 0);
        for tick in 1..=300u32 {
            ctl.tick(&view);
            let ch = &ctl.channels()[0];
            watch.check(ch.set_points(), &name);
            assert_eq!(ch.tracker().state(), DynCsState::Active, "{name} {tick}");
            let hli = plc.gp_ch(0).unwrap().dyn_cs_result();
            hli_lag_seen = hli_lag_seen.max(hli.lag_translation_r);
            if landed.is_none() && !ch.settling() {
                assert_eq!(hli.lag_translation_r, 0);
                assert_eq!(hli.catch_ups_r, 1);
                landed = Some(tick);
            }
        }
        let landed = landed.expect("landed");
        assert!(
            landed > 3 && landed < 60,
            "{name}: landed after {landed} ticks"
        );
        assert!(
            hli_lag_seen > 500 && hli_lag_seen <= 1_000,
            "{name}: {hli_lag_seen}"
        );
        let ch = &ctl.channels()[0];
        let moved = ch.tool_pose().translation.vector - tool_before;
        assert!(
            (moved.x - 0.1).abs() < 1e-9 && moved.yz().norm() < 1e-9,
            "{name}: {moved:?}"
        );
        assert!(ch.error().is_none());
        let (now, peak) = ch.tracking_lag();
        assert_eq!(now.translation, 0.0);
        assert!((peak.translation - 0.1).abs() < 0.01, "{name}: {peak:?}");
        let logged = ch
            .tracker()
            .log()
            .filter(|(_, e)| matches!(e, TrackEvent::CatchUp { .. }))
            .count();
        assert_eq!(logged, 2, "{name}: began and landed");
    }
}

/// The catch-up runs in the tick without allocating: a robot slave catches a PLC step of
/// 2 mm up (the joints' lags replanned every tick) under the counting allocator.
#[test]
fn a_catch_up_allocates_nothing() {
    let program = "#TRAFO [45]\n#TRACK CS ON [ID=0 FILTER=0 WAIT]\n#TIME 2\nM30\n";
    let mut ctl = controller(vec![(robot("kr6"), program)]);
    let memory = image(1);
    let view = CncView::new(&memory);
    let plc = PlcView::new(&memory);
    support::enable_plc_master(&memory, [0; 3]);
    for _ in 0..50 {
        ctl.tick(&view);
    }
    plc.dyn_cs_command(0)
        .unwrap()
        .try_send(&cs([20_000, 10_000, 0]))
        .unwrap();
    let before = crate::counting_alloc::allocations();
    let mut lagged = 0;
    for _ in 0..300 {
        ctl.tick(&view);
        lagged += u32::from(ctl.channels()[0].settling());
    }
    assert_eq!(crate::counting_alloc::allocations(), before);
    assert!(lagged > 10, "it caught up ({lagged} ticks)");
    assert!(ctl.channels()[0].error().is_none());
}

/// Master and slave switch the interface and the tracking on in the same block of their
/// programs: whichever channel ticks first, the slave couples in (ACTIVATING while it waits)
/// and follows the master, its axes within their limits.
#[test]
fn switching_on_works_in_either_channel_order() {
    let master = "#CHANNEL INTERFACE ON [DYN_CS]\nG1 X50 F1200\n#TIME 0.5\nM30\n";
    let slave = "#TRACK CS ON [CH={m} FILTER=100 WAIT]\nG1 Y10 F600\n#TIME 2\nM30\n";
    for master_first in [true, false] {
        let (mi, si) = if master_first { (0, 1) } else { (1, 0) };
        let slave = slave.replace("{m}", &(mi + 1).to_string());
        let mut configs = vec![
            (cartesian("master"), master),
            (cartesian("slave"), slave.as_str()),
        ];
        if !master_first {
            configs.swap(0, 1);
        }
        let mut ctl = controller(configs);
        let memory = image(2);
        let view = CncView::new(&memory);
        let mut watch = StepWatch::new(&[0.0; 6], cartesian("x").axis_limits(0));
        let mut seen_activating = false;
        for _ in 0..4000 {
            ctl.tick(&view);
            let s = &ctl.channels()[si];
            seen_activating |= s.tracker().state() == DynCsState::Activating;
            watch.check(s.set_points(), "slave");
            assert_ne!(s.state(), RunState::Error, "{:?}", s.error());
        }
        let (m, s) = (&ctl.channels()[mi], &ctl.channels()[si]);
        assert!(seen_activating);
        assert_eq!(
            s.tracker().state(),
            DynCsState::Active,
            "order {master_first}"
        );
        assert_eq!(s.state(), RunState::Finished);
        // Absolute tracking of a Cartesian master: the slave's X is the master's X.
        assert!((s.set_points()[0] - m.set_points()[0]).abs() < 1e-9);
        assert!((s.set_points()[1] - 10.0).abs() < 1e-9);
    }
}

/// FILTER=0 from the PLC: ACTIVATING and DEACTIVATING are each shown for a tick.
#[test]
fn without_filter_the_transient_states_are_shown_for_a_tick() {
    let mut ctl = controller(vec![(cartesian("slave"), "#TIME 1\nM30\n")]);
    let memory = image(1);
    let view = CncView::new(&memory);
    let plc = PlcView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    let mut states = Vec::new();
    for command in [DynCsCommand::Activate, DynCsCommand::Deactivate] {
        plc.dyn_cs_transition(0)
            .unwrap()
            .try_send(command, &transition(0, Bool::FALSE))
            .unwrap();
        for _ in 0..3 {
            ctl.tick(&view);
            states.push(plc.dyn_cs_state(0).unwrap().unwrap());
        }
    }
    use DynCsState::*;
    assert_eq!(
        states,
        [Activating, Active, Active, Deactivating, Inactive, Inactive]
    );
    // The diagnosis history shows each tick's state as `state_r` did (recorded once the axes
    // took the tick's set-points): one ACTIVATING row, then ACTIVE, then one DEACTIVATING.
    let history: Vec<i32> = ctl.channels()[0]
        .tracker()
        .history()
        .map(|e| e.state)
        .collect();
    assert_eq!(history, [1, 2, 2, 3]);
    // The same for a master channel: the first ACTIVE row is the tick the log says ACTIVE.
    let master = "#CHANNEL INTERFACE ON [DYN_CS]\n#TIME 1\nM30\n";
    let slave = "#TRACK CS ON [CH=1 FILTER=0 WAIT]\n#TIME 1\nM30\n";
    let mut ctl = controller(vec![
        (cartesian("master"), master),
        (cartesian("slave"), slave),
    ]);
    let memory = image(2);
    let view = CncView::new(&memory);
    for _ in 0..10 {
        ctl.tick(&view);
    }
    let tracker = ctl.channels()[1].tracker();
    let rows: Vec<(u64, i32)> = tracker.history().map(|e| (e.tick, e.state)).collect();
    let active = tracker
        .log()
        .find(|(_, e)| matches!(e, TrackEvent::Active))
        .map(|(t, _)| *t)
        .unwrap();
    let first_active = rows.iter().find(|(_, s)| *s == 2).unwrap().0;
    assert_eq!(first_active, active, "{rows:?}");
    assert_eq!(rows.iter().filter(|(_, s)| *s == 1).count(), 1, "{rows:?}");
}

/// Every refusal of a PLC transition, from INACTIVE and from ACTIVE, reaches the PLC in
/// `dyn_cs_result` (a new count, the command word, the reason) and leaves the state as it was;
/// an accepted one reports 0 and the states it passed.
#[test]
fn every_refused_transition_is_reported_with_its_reason_from_both_start_states() {
    use hli::access::{Leaf, Value};
    use hli::enums::DynCsTransitionError as E;
    let read = |plc: &PlcView<'_>| plc.gp_ch(0).unwrap().dyn_cs_result();
    // (what the PLC does, the refusal expected from INACTIVE, from ACTIVE): a +1's
    // parameters are checked before the state.
    type Post = fn(&PlcView<'_>, &hli::ImageMemory);
    let send = |plc: &PlcView<'_>, command, t| {
        plc.dyn_cs_transition(0)
            .unwrap()
            .try_send(command, &t)
            .unwrap()
    };
    let cases: [(&str, Post, E, E); 5] = [
        (
            "garbage word",
            |_, m| {
                let word = Leaf::resolve("gpCh[0]^channel_mc_control.dyn_cs.transition_w.command");
                word.unwrap().write(m, Value::Int(5));
            },
            E::CommandWord,
            E::CommandWord,
        ),
        (
            "flag byte",
            |p, _| {
                let mut t = transition(0, Bool::FALSE);
                t.f_set_zero = bytemuck::cast(7u8);
                p.dyn_cs_transition(0)
                    .unwrap()
                    .try_send(DynCsCommand::Activate, &t)
                    .unwrap();
            },
            E::FlagByte,
            E::FlagByte,
        ),
        (
            "option",
            |p, _| {
                let mut t = transition(0, Bool::FALSE);
                t.option = 7;
                p.dyn_cs_transition(0)
                    .unwrap()
                    .try_send(DynCsCommand::Activate, &t)
                    .unwrap();
            },
            E::OptionValue,
            E::OptionValue,
        ),
        (
            "not enabled",
            |p, _| {
                p.set_dyn_cs_enabled(0, false).unwrap();
                let t = transition(0, Bool::FALSE);
                p.dyn_cs_transition(0)
                    .unwrap()
                    .try_send(DynCsCommand::Activate, &t)
                    .unwrap();
            },
            E::NotEnabled,
            E::NotEnabled,
        ),
        (
            "on while on",
            |p, _| {
                let t = transition(0, Bool::FALSE);
                p.dyn_cs_transition(0)
                    .unwrap()
                    .try_send(DynCsCommand::Activate, &t)
                    .unwrap();
            },
            E::None,
            E::AlreadyOn,
        ),
    ];
    for from_active in [false, true] {
        for (name, post, from_inactive_id, from_active_id) in cases {
            let mut ctl = controller(vec![(cartesian("slave"), "#TIME 1\nM30\n")]);
            let memory = image(1);
            let view = CncView::new(&memory);
            let plc = PlcView::new(&memory);
            plc.set_dyn_cs_enabled(0, true).unwrap();
            if from_active {
                send(&plc, DynCsCommand::Activate, transition(0, Bool::FALSE));
                ctl.tick(&view);
                ctl.tick(&view);
            }
            let start = plc.dyn_cs_state(0).unwrap().unwrap();
            let before = read(&plc).taken_count_r;
            post(&plc, &memory);
            ctl.tick(&view);
            let r = read(&plc);
            let expected = if from_active {
                from_active_id
            } else {
                from_inactive_id
            };
            assert_eq!(r.taken_count_r, before + 1, "{name}");
            assert_eq!(
                r.error_id_r,
                expected.raw(),
                "{name}, from ACTIVE {from_active}"
            );
            if expected != E::None {
                assert_eq!(plc.dyn_cs_state(0).unwrap().unwrap(), start, "{name}");
            } else {
                // Accepted: ACTIVATING passed (and shown for the tick).
                assert_eq!(r.states_seen_r, 1 << 1, "{name}");
                assert_eq!(r.command_r, 1);
            }
        }
    }
    // f_set_zero while the axes move.
    let mut ctl = controller(vec![(cartesian("slave"), "G1 X100 F600\nM30\n")]);
    let memory = image(1);
    let view = CncView::new(&memory);
    let plc = PlcView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    for _ in 0..10 {
        ctl.tick(&view);
    }
    let mut t = transition(0, Bool::FALSE);
    t.f_set_zero = Bool::TRUE;
    send(&plc, DynCsCommand::Activate, t);
    ctl.tick(&view);
    assert_eq!(read(&plc).error_id_r, E::SetZeroMoving.raw());
    assert_eq!(plc.dyn_cs_state(0).unwrap().unwrap(), DynCsState::Inactive);
}

/// A history size the machine cannot hold (inside the manual's range) is refused with the key,
/// not aborted on.
#[test]
fn a_history_size_beyond_what_is_kept_is_refused_with_its_key() {
    let mut c = cartesian("big");
    c.interpolator.dyn_cs_history_max = u32::MAX;
    let e = cnc_core::channel::Channel::new(0, c, CYCLE).unwrap_err();
    assert!(
        e.to_string()
            .contains("interpolator.dyn_cs_history_max = 4294967295"),
        "{e}"
    );
    let mut c = cartesian("ok");
    c.interpolator.dyn_cs_history_max = cnc_core::channel::config::MAX_HISTORY;
    assert!(cnc_core::channel::Channel::new(0, c, CYCLE).is_ok());
}

/// ROT_TRANS measures the offset's translation in the rotated frame, the same from the NC
/// (`ROT_TRANS`) and from the PLC (`f_rot_trans`), with and without KIN_BASE (the manual's
/// text forbids no combination; only a garbled table row hints at one). Checked against the
/// compensation computed from the offset frame directly.
#[test]
fn rot_trans_acts_the_same_from_the_nc_and_the_plc_with_and_without_kin_base() {
    use kinematics::frame::offset_frame;
    use kinematics::tracking::{Tracking, TrackingMode, TrackingOption};
    use kinematics::PoseWords;
    let offset = PoseWords {
        xyz: [100.0, 0.0, 0.0],
        abc: [0.0, 0.0, 90.0],
    };
    // The master: 10 mm in X, turned 30 degrees about Z (HLI units).
    let master_cs = hli::layout::HliCoordinateSystemInt {
        translation: [100_000, 0, 0],
        fill_up_2: 0,
        rotation: [0, 0, 300_000],
        fill_up_1: 0,
    };
    let master =
        cnc_core::channel::hli_frame::frame_from_hli(&master_cs, kinematics::RotationOrder::Zyx);
    for kin_base in [false, true] {
        let mode = if kin_base {
            TrackingMode::KinematicBase
        } else {
            TrackingMode::MovingWorkpiece
        };
        let expected = |rot: bool| {
            let t = Tracking::new(mode, TrackingOption::Full, &offset, rot, None).unwrap();
            t.compensation(&master).translation.vector
        };
        assert!(
            (expected(true) - expected(false)).norm() > 1.0,
            "ROT_TRANS matters here"
        );
        assert!(offset_frame(&offset, true).is_ok());
        let kb = if kin_base { " KIN_BASE" } else { "" };
        let nc = format!("#TRACK CS ON [ID=0 FILTER=0 ROT_TRANS{kb} X=100 C=90]\n#TIME 1\nM30\n");
        let mut ctl = controller(vec![
            (support::stiff(cartesian("nc")), nc.as_str()),
            (support::stiff(cartesian("plc")), "#TIME 1\nM30\n"),
        ]);
        let memory = image(2);
        let view = CncView::new(&memory);
        let plc = PlcView::new(&memory);
        let mut t = transition(0, Bool::FALSE);
        t.f_rot_trans = Bool::TRUE;
        t.f_kin_base = Bool::from(kin_base);
        t.kinematic_base_cs.translation = [1_000_000, 0, 0];
        t.kinematic_base_cs.rotation = [0, 0, 900_000];
        for ch in 0..2 {
            plc.set_dyn_cs_enabled(ch, true).unwrap();
            plc.dyn_cs_command(ch)
                .unwrap()
                .try_send(&master_cs)
                .unwrap();
        }
        plc.dyn_cs_transition(1)
            .unwrap()
            .try_send(DynCsCommand::Activate, &t)
            .unwrap();
        for _ in 0..5 {
            ctl.tick(&view);
        }
        for ch in ctl.channels() {
            assert_eq!(
                ch.tracker().state(),
                DynCsState::Active,
                "{}",
                ch.config().name
            );
            let applied = ch.tracker().applied().translation.vector;
            assert!(
                (applied - expected(true)).norm() < 1e-6,
                "{} KIN_BASE {kin_base}: {applied:?} vs {:?}",
                ch.config().name,
                expected(true)
            );
        }
    }
}

/// 600 ticks of `program` on one channel whose PLC master stands at `x` (0.1 um), every step
/// watched.
fn plc_master_run(
    config: ChannelConfig,
    program: &str,
    x: i32,
    mut watch: StepWatch,
) -> (cnc_core::channel::Controller, StepWatch) {
    let mut ctl = controller(vec![(config, program)]);
    let memory = image(1);
    let view = CncView::new(&memory);
    let plc = PlcView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    plc.dyn_cs_command(0)
        .unwrap()
        .try_send(&cs([x, 0, 0]))
        .unwrap();
    for _ in 0..600 {
        ctl.tick(&view);
        watch.check(ctl.channels()[0].set_points(), "slave");
    }
    (ctl, watch)
}

/// The last step of a coupling out is caught up: 1 mm shed in one tick (FILTER=1) runs on
/// a catch-up within the axis's limits (every tick watched), the tracking stays DEACTIVATING
/// until the axis stands exactly on the programmed position, then INACTIVE; no error.
#[test]
fn the_last_step_of_a_switch_off_is_caught_up_within_the_limits() {
    let program =
        "#TRACK CS ON [ID=0 FILTER=300 WAIT]\n#TRACK CS OFF [FILTER=1 WAIT]\n#TIME 1\nM30\n";
    let watch = StepWatch::new(&[0.0; 6], cartesian("x").axis_limits(0));
    let (ctl, watch) = plc_master_run(cartesian("slave"), program, 10_000, watch);
    let ch = &ctl.channels()[0];
    assert!(ch.error().is_none(), "{:?}", ch.error());
    assert_eq!(ch.tracker().state(), DynCsState::Inactive);
    assert_eq!(ch.set_points()[0], 0.0, "landed exactly");
    assert!(watch.at_rest());
    let log: Vec<_> = ch.tracker().log().map(|(_, e)| *e).collect();
    assert!(
        log.iter().any(
            |e| matches!(e, TrackEvent::CatchUp { landed: true, translation, .. }
            if (*translation - 1.0).abs() < 0.01)
        ),
        "the catch-up is logged with its largest lag: {log:?}"
    );
}

/// A reset is refused while the dynamic CS is on (it may be moving the axes); once switched
/// off it resets.
#[test]
fn a_reset_is_refused_while_tracking() {
    let mut ctl = controller(vec![(cartesian("slave"), "#TIME 0.01\nM30\n")]);
    let memory = image(1);
    let view = CncView::new(&memory);
    let plc = PlcView::new(&memory);
    plc.set_dyn_cs_enabled(0, true).unwrap();
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(DynCsCommand::Activate, &transition(0, Bool::FALSE))
        .unwrap();
    for _ in 0..20 {
        ctl.tick(&view);
    }
    let channel = ctl.channel_mut(0).unwrap();
    assert_eq!(channel.tracker().state(), DynCsState::Active);
    assert_eq!(
        channel.reset(),
        Err(cnc_core::channel::run::ResetError::Tracking)
    );
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(DynCsCommand::Deactivate, &transition(0, Bool::FALSE))
        .unwrap();
    for _ in 0..3 {
        ctl.tick(&view);
    }
    assert_eq!(ctl.channel_mut(0).unwrap().reset(), Ok(()));
}

/// A D record selected while a robot tracks: nothing moves at the D block (the compensation
/// is not applied twice), the tracking goes on.
#[test]
fn a_tool_record_selected_while_tracking_moves_nothing() {
    let mut c = robot("r");
    c.nc.tools = support::tools("{ d = 2, length = 50.0 }");
    let program = "#TRAFO [45]\n#TRACK CS ON [ID=0 FILTER=200 WAIT]\nD2\n#TIME 0.2\nM30\n";
    let watch = StepWatch::new(&ROBOT_HOME, JOINT);
    let (ctl, watch) = plc_master_run(c, program, 50_000, watch);
    let ch = &ctl.channels()[0];
    assert_eq!(ch.state(), RunState::Finished, "{:?}", ch.error());
    assert_eq!(ch.tracker().state(), DynCsState::Active);
    assert!(watch.at_rest());
}

/// A switch-on without filter takes a step of any size (here 10 mm, beyond the 5 mm of
/// `track_lag_max`) onto a master already moving. Its lag grows while the axes take up the
/// master's velocity: a master the axes can overtake (500 mm/s against their 1000) is landed
/// on and followed, one faster than they may go (1500 mm/s) ends in the safe stop once the
/// lag grew 5 mm above its smallest. Every tick watched.
#[test]
fn a_switching_step_onto_a_moving_master_is_caught_up_unless_it_outruns_the_axes() {
    for (top, fails) in [(1500.0, true), (500.0, false)] {
        let program = "#TRACK CS ON [ID=0 FILTER=0 WAIT]\n#TIME 2\nM30\n";
        let config = cartesian("slave");
        let mut watch = StepWatch::new(&[0.0; 6], config.axis_limits(0));
        let mut ctl = controller(vec![(config, program)]);
        let memory = image(1);
        let view = CncView::new(&memory);
        let plc = PlcView::new(&memory);
        plc.set_dyn_cs_enabled(0, true).unwrap();
        let (mut x, mut v) = (10.0_f64, top); // mm, mm/s
        for _ in 0..1000 {
            let frame = cs([(x * 1e4).round() as i32, 0, 0]);
            plc.dyn_cs_command(0).unwrap().try_send(&frame).unwrap();
            ctl.tick(&view);
            watch.check(ctl.channels()[0].set_points(), "slave");
            if ctl.channels()[0].error().is_some() {
                v = 0.0; // the master stands again: only the slave's braking is left
            }
            x += v * CYCLE;
        }
        let ch = &ctl.channels()[0];
        if fails {
            let error = ch
                .error()
                .expect("the runaway ends in an error")
                .to_string();
            assert!(error.contains("above the smallest lag"), "{error}");
            assert_eq!(ch.tracker().state(), DynCsState::Error);
            assert!(watch.at_rest(), "braked to rest");
        } else {
            assert!(ch.error().is_none(), "{:?}", ch.error());
            assert_eq!(ch.tracker().state(), DynCsState::Active);
            assert!(!ch.tracker().in_transition());
        }
    }
}
