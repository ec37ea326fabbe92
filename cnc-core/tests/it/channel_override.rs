//! The channel's override unit (`gpCh[i]^channel_mc_control.path_override`) and its block
//! progress (`bahn_state`): feed and rapid override, feed hold that brakes along the path and
//! lets the block go on, a PLC holding the feed until tracking is ACTIVE, refused values, and
//! `path_feed_r`, `program_state_r`, `error_id_r`, `feed_override_r` as the PLC reads them.

use tests::channel_rig as support;

use cnc_core::channel::{Controller, RunState};
use hli::enums::{ChannelErrorId, DynCsCommand, DynCsState, ProgramState};
use hli::views::{CncView, PathOverride, PlcView, DEFAULT_PATH_OVERRIDE};
use hli::{Bool, ImageMemory};
use support::*;

fn set_override(memory: &ImageMemory, feed: u32, rapid: u32, hold: bool) {
    PlcView::new(memory)
        .set_path_override(
            0,
            PathOverride {
                feed_permille: feed,
                rapid_permille: rapid,
                feed_hold: hold,
            },
        )
        .unwrap();
}

/// Runs `program` to its end on a Cartesian channel with the override set before the start;
/// returns the largest `path_feed_r` (um/s) and the `feed_override_r` the channel reported.
fn top_feed(program: &str, feed: u32, rapid: u32) -> (i32, u32) {
    let mut ctl = controller(vec![(cartesian("c"), program)]);
    let memory = image(1);
    set_override(&memory, feed, rapid, false);
    let plc = PlcView::new(&memory);
    let mut top = 0;
    run_until(
        &mut ctl,
        &memory,
        20_000,
        |_, _| top = top.max(plc.path_feed(0).unwrap()),
        |c| c.channels()[0].state() == RunState::Finished,
    );
    (top, plc.feed_override_applied(0).unwrap())
}

#[test]
fn a_fresh_image_holds_100_percent_and_no_feed_hold() {
    let memory = image(2);
    let view = CncView::new(&memory);
    for channel in 0..2 {
        assert_eq!(
            view.path_override(channel).unwrap(),
            Ok(DEFAULT_PATH_OVERRIDE)
        );
    }
    assert_eq!(
        DEFAULT_PATH_OVERRIDE,
        PathOverride {
            feed_permille: 1000,
            rapid_permille: 1000,
            feed_hold: false
        }
    );
}

/// G1 at F6000 (100 mm/s) cruises at F times the feed override, up to the axes' limit; G0
/// cruises at the axis limit (1000 mm/s) times the rapid override. `path_feed_r` shows the
/// path velocity in um/s, `feed_override_r` the override in effect.
#[test]
fn the_overrides_scale_the_path_feed_that_path_feed_r_reports() {
    assert_eq!(
        top_feed("G1 X200 F6000\nM30\n", 1000, 1000),
        (100_000, 1000)
    );
    assert_eq!(top_feed("G1 X200 F6000\nM30\n", 500, 1000), (50_000, 500));
    assert_eq!(
        top_feed("G1 X200 F6000\nM30\n", 1500, 1000),
        (150_000, 1500)
    );
    // 200 % of F60000 (1000 mm/s) stays at the axes' 1000 mm/s.
    assert_eq!(top_feed("G1 X900 F60000\nM30\n", 2000, 1000).0, 1_000_000);
    assert_eq!(top_feed("G0 X500\nM30\n", 1000, 250).0, 250_000);
    // The feed override does not act on G0, the rapid override not on G1.
    assert_eq!(top_feed("G0 X500\nM30\n", 100, 1000).0, 1_000_000);
    assert_eq!(top_feed("G1 X200 F6000\nM30\n", 1000, 100).0, 100_000);
}

/// Feed hold in the middle of a block brakes along the path within the block's deceleration
/// (5000 mm/s^2) and jerk (50000 mm/s^3), stands (path_feed_r 0, feed_override_r 0, the
/// program still RUNNING), and after the release the block runs on to its exact end.
#[test]
fn feed_hold_brakes_along_the_path_and_the_block_goes_on_after_release() {
    let mut ctl = controller(vec![(cartesian("c"), "G1 X100 Y0 F6000\nM30\n")]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    let view = CncView::new(&memory);
    let x = |ctl: &Controller| ctl.channels()[0].programmed()[0];
    let mut trace = vec![0.0];
    for _ in 0..300 {
        ctl.tick(&view);
        trace.push(x(&ctl));
    }
    assert!(trace[300] > 20.0 && trace[300] < 40.0, "{}", trace[300]);
    set_override(&memory, 1000, 1000, true);
    for _ in 0..400 {
        ctl.tick(&view);
        trace.push(x(&ctl));
    }
    let held_at = x(&ctl);
    assert!(held_at < 100.0 - 1.0, "stopped short of the end: {held_at}");
    assert_eq!(plc.path_feed(0).unwrap(), 0);
    assert_eq!(plc.feed_override_applied(0).unwrap(), 0);
    assert_eq!(plc.program_state(0).unwrap(), Ok(ProgramState::Running));
    // Velocity, acceleration and jerk of the braking, per tick.
    let v: Vec<f64> = trace.windows(2).map(|w| (w[1] - w[0]) / CYCLE).collect();
    let a: Vec<f64> = v.windows(2).map(|w| (w[1] - w[0]) / CYCLE).collect();
    let j: Vec<f64> = a.windows(2).map(|w| (w[1] - w[0]) / CYCLE).collect();
    let worst_a = a[290..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst_j = j[290..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(worst_a <= 5000.0 * 1.001, "deceleration {worst_a}");
    assert!(worst_j <= 50_000.0 * 1.001, "jerk {worst_j}");
    assert!(v[299] > 99.0 && v[400..].iter().all(|v| v.abs() < 1e-9));
    for _ in 0..200 {
        ctl.tick(&view);
        assert_eq!(x(&ctl), held_at, "standing under feed hold");
    }
    set_override(&memory, 1000, 1000, false);
    run_to_end(&mut ctl, &memory, 5000);
    assert_eq!(x(&ctl), 100.0);
}

/// The manual leaves waiting for the switching to the PLC ("it gives the feed only once the
/// state is ACTIVE"): here the PLC holds the feed, switches on with FILTER=300, and releases
/// the feed when `state_r` reads ACTIVE. The program's move starts only then.
#[test]
fn the_plc_holds_the_feed_until_tracking_is_active() {
    let mut ctl = controller(vec![(cartesian("slave"), "G1 X10 F600\nM30\n")]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    let view = CncView::new(&memory);
    set_override(&memory, 1000, 1000, true);
    enable_plc_master(&memory, [0, 0, 0]);
    plc.dyn_cs_transition(0)
        .unwrap()
        .try_send(DynCsCommand::Activate, &transition(300, Bool::FALSE))
        .unwrap();
    let (mut active_at, mut moved_at) = (None, None);
    for tick in 0..5000u32 {
        ctl.tick(&view);
        let ch = &ctl.channels()[0];
        assert_ne!(ch.state(), RunState::Error, "{:?}", ch.error());
        if active_at.is_none() && plc.dyn_cs_state(0).unwrap() == Ok(DynCsState::Active) {
            active_at = Some(tick);
            set_override(&memory, 1000, 1000, false);
        }
        if moved_at.is_none() && ch.programmed()[0] > 0.0 {
            moved_at = Some(tick);
        }
        if ch.state() == RunState::Finished {
            break;
        }
    }
    let (active_at, moved_at) = (active_at.unwrap(), moved_at.unwrap());
    assert_eq!(active_at, 299, "ACTIVE after the filter's 300 ticks");
    assert_eq!(
        moved_at,
        active_at + 1,
        "the move starts in the tick after the release"
    );
    assert_eq!(ctl.channels()[0].state(), RunState::Finished);
    assert_eq!(ctl.channels()[0].programmed()[0], 10.0);
}

/// A feed override above 200 % (or a feed-hold byte that is no BOOL) is refused: counted every
/// tick it stands there, the last valid value in effect.
#[test]
fn an_override_out_of_range_is_refused_and_the_last_valid_value_stays() {
    let mut ctl = controller(vec![(cartesian("c"), "G1 X200 F6000\nM30\n")]);
    let memory = image(1);
    let plc = PlcView::new(&memory);
    let view = CncView::new(&memory);
    set_override(&memory, 500, 1000, false);
    for _ in 0..10 {
        ctl.tick(&view);
    }
    set_override(&memory, 2500, 1000, false);
    let mut top = 0;
    for _ in 0..1000 {
        ctl.tick(&view);
        top = top.max(plc.path_feed(0).unwrap());
    }
    assert_eq!(top, 50_000, "still 50 %");
    let ch = &ctl.channels()[0];
    assert_eq!(ch.override_refused_count(), 1000);
    assert_eq!(ch.path_override().feed_permille, 500);
    let hold =
        hli::access::Leaf::resolve("gpCh[0]^channel_mc_control.path_override.feed_hold_w").unwrap();
    set_override(&memory, 1000, 1000, false);
    ctl.tick(&view);
    hold.write(&memory, hli::access::Value::Int(7));
    ctl.tick(&view);
    assert_eq!(ctl.channels()[0].override_refused_count(), 1001);
    assert!(!ctl.channels()[0].path_override().feed_hold);
}

/// `program_state_r` and `error_id_r` as the PLC reads them: RUNNING and no error while a
/// program runs, FINISHED at its end, ERROR with the kind of cause when it stops.
#[test]
fn program_state_r_and_error_id_r_say_how_a_channel_stands() {
    let cases = [
        (
            "G1 X1 F600\nM30\n",
            ProgramState::Finished,
            ChannelErrorId::None,
        ),
        (
            "#CS ON [1, 0, 0, 0, 0, 0]\nM30\n",
            ProgramState::Error,
            ChannelErrorId::CoordinateSystem,
        ),
        (
            "#TRACK CS ON [ID=0 FILTER=0]\n#TIME 0.01\n#TRACK CS ON [ID=0 FILTER=0]\nM30\n",
            ProgramState::Error,
            ChannelErrorId::Tracking,
        ),
    ];
    for (program, end_state, error) in cases {
        let mut ctl = controller(vec![(cartesian("c"), program)]);
        let memory = image(1);
        let plc = PlcView::new(&memory);
        let view = CncView::new(&memory);
        ctl.tick(&view);
        let first = plc.program_state(0).unwrap().unwrap();
        assert!(
            matches!(first, ProgramState::Running | ProgramState::Waiting) || first == end_state,
            "{program}: {first:?}"
        );
        for _ in 0..2000 {
            ctl.tick(&view);
        }
        assert_eq!(plc.program_state(0).unwrap(), Ok(end_state), "{program}");
        assert_eq!(plc.channel_error(0).unwrap(), Ok(error), "{program}");
        if error != ChannelErrorId::None {
            assert_eq!(ctl.channels()[0].error().unwrap().id, error);
        }
    }
}

/// A machine stop while feed hold holds the path ends the block where it stands and the
/// channel in ERROR (machine stop); releasing the hold afterwards moves nothing.
#[test]
fn a_stop_under_feed_hold_ends_the_block_where_it_stands() {
    let mut ctl = controller(vec![(cartesian("c"), "G1 X100 F6000\nM30\n")]);
    let memory = image(1);
    let view = CncView::new(&memory);
    for _ in 0..300 {
        ctl.tick(&view);
    }
    set_override(&memory, 1000, 1000, true);
    for _ in 0..300 {
        ctl.tick(&view);
    }
    let held_at = ctl.channels()[0].programmed()[0];
    ctl.channel_mut(0).unwrap().stop("machine stop: test");
    set_override(&memory, 1000, 1000, false);
    for _ in 0..100 {
        ctl.tick(&view);
    }
    let ch = &ctl.channels()[0];
    assert_eq!(ch.state(), RunState::Error);
    assert_eq!(ch.error().unwrap().id, ChannelErrorId::MachineStop);
    assert!(!ch.is_moving());
    assert_eq!(ch.programmed()[0], held_at);
}
