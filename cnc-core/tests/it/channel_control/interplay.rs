//! The channel control unit's interplay with tracking, `#WAIT SYN`, M functions, a machine
//! stop and axis faults, the block search of a start line and the loader thread.

use super::*;

/// Channel 0 waits for a signal channel 1 would give; channel 1 is stopped by the PLC: the
/// waiting channel is told (it fails with SyncAbandoned) instead of waiting forever.
#[test]
fn a_wait_syn_partner_that_is_stopped_releases_the_waiting_channel_with_an_error() {
    let waits = "G1 X10 F6000\n#WAIT SYN [ID1]\nG1 X20\nM30\n";
    let signals = "G1 X300 F600\n#SIGNAL SYN [ID1 COUNT1]\nM30\n";
    let mut rig = Rig::new(
        vec![
            (cartesian("a"), Some(waits)),
            (cartesian("b"), Some(signals)),
        ],
        None,
    );
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    assert_eq!(rig.command(1, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(1_000, |_| {});
    assert_ne!(
        rig.state_block(0).signals & ChannelSignal::WaitingSync.raw(),
        0
    );
    assert_eq!(rig.command(1, ChannelCommand::Stop, plain, 2_000), None);
    rig.run_ticks(2, |_| {});
    assert_eq!(rig.state(0), ChannelState::Error);
    assert_eq!(
        rig.state_block(0).error_id,
        ChannelErrorId::SyncAbandoned.raw()
    );
}

/// `sync_timeout_s`: a `#WAIT SYN` nobody answers ends after the configured time.
#[test]
fn a_wait_syn_times_out_when_configured() {
    let mut config = cartesian("a");
    config.sync_timeout_s = Some(0.5);
    let waits = "#WAIT SYN [ID1]\nM30\n";
    let other = "G1 X300 F600\nM30\n";
    let mut rig = Rig::new(
        vec![(config, Some(waits)), (cartesian("b"), Some(other))],
        None,
    );
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    assert_eq!(rig.command(1, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(480, |r| assert_eq!(r.state(0), ChannelState::Running));
    rig.run_ticks(30, |_| {});
    assert_eq!(rig.state(0), ChannelState::Error);
    let error = rig.ctl.channels()[0].error().unwrap().to_string();
    assert!(error.contains("sync_timeout_s"), "{error}");
}

/// An M function announced and not acknowledged when the PLC stops the channel: the wait
/// ends; the PLC's late acknowledge is taken as stale by the next program, whose own M
/// function then completes its handshake.
#[test]
fn a_stop_ends_an_m_function_wait_and_the_next_handshake_works() {
    fn announced(memory: &ImageMemory) -> hli::layout::HliMFunctionRequest {
        let plc = PlcView::new(memory);
        let ch = plc.gp_ch(0).unwrap();
        ch.m_function_request()
            .try_take()
            .unwrap()
            .expect("M100 announced")
    }
    fn acknowledge(memory: &ImageMemory, request_id: u32) {
        let plc = PlcView::new(memory);
        let ack = hli::layout::HliMFunctionAck {
            m_code: 100,
            request_id,
        };
        plc.gp_ch(0)
            .unwrap()
            .m_function_ack()
            .try_send(&ack)
            .unwrap();
    }
    let program = "M100\nG1 X10 F6000\nM30\n";
    let mut rig = Rig::new(vec![(cartesian("c"), Some(program))], None);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(5, |_| {});
    let first = announced(&rig.memory);
    assert_ne!(
        rig.state_block(0).signals & ChannelSignal::WaitingMAck.raw(),
        0
    );
    assert_eq!(rig.command(0, ChannelCommand::Stop, plain, 10), None);
    assert_eq!(rig.state(0), ChannelState::Selected);
    // The PLC acknowledges late.
    acknowledge(&rig.memory, first.request_id);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(5, |_| {});
    let second = announced(&rig.memory);
    assert_ne!(second.request_id, first.request_id);
    rig.run_ticks(50, |r| {
        assert_eq!(r.x(0), 0.0, "the stale acknowledge released nothing")
    });
    acknowledge(&rig.memory, second.request_id);
    rig.run_ticks(2_000, |_| {});
    assert_eq!(rig.x(0), 10.0);
    assert_eq!(rig.state_block(0).programs_ended, 1);
}

/// Feed hold on a tracking slave: the path stops, the slave keeps following its master.
#[test]
fn feed_hold_on_a_tracking_slave_keeps_tracking() {
    let slave = "#TRACK CS ON [ID=0 FILTER=0]\nG1 X500 F600\nM30\n";
    let mut rig = Rig::new(vec![(cartesian("s"), Some(slave))], None);
    enable_plc_master(&rig.memory, [0, 0, 0]);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(200, |_| {});
    assert_eq!(rig.ctl.channels()[0].tracker().state(), DynCsState::Active);
    assert_eq!(rig.command(0, ChannelCommand::FeedHold, plain, 2_000), None);
    // The master moves 1 mm: the slave follows it while its path holds.
    let before = rig.x(0);
    let plc = PlcView::new(&rig.memory);
    plc.dyn_cs_command(0)
        .unwrap()
        .try_send(&cs([10_000, 0, 0]))
        .unwrap();
    rig.run_ticks(20, |_| {});
    assert_eq!(rig.ctl.channels()[0].tracker().state(), DynCsState::Active);
    assert!(
        (rig.x(0) - before - 1.0).abs() < 1e-9,
        "followed: {} -> {}",
        before,
        rig.x(0)
    );
    assert_eq!(rig.state(0), ChannelState::Holding);
    // STOP switches the tracking off softly and ends at rest.
    assert_eq!(rig.command(0, ChannelCommand::Stop, plain, 2_000), None);
    assert_eq!(
        rig.ctl.channels()[0].tracker().state(),
        DynCsState::Inactive
    );
    assert_eq!(rig.state(0), ChannelState::Selected);
}

/// A machine stop (a lost PLC, supervision): commands are refused while the channel brakes;
/// at rest the channel is in ERROR, and a (new) PLC resets it and runs the part again.
#[test]
fn after_a_machine_stop_the_plc_resets_and_restarts_the_channel() {
    let mut rig = Rig::new(vec![(cartesian("c"), Some(PART))], None);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(400, |_| {});
    rig.ctl.channel_mut(0).unwrap().stop("machine stop: test");
    assert_eq!(
        rig.command(0, ChannelCommand::Reset, plain, 5),
        Some(E::MachineStop)
    );
    while rig.ctl.channels()[0].stopping() {
        rig.tick();
        assert!(rig.ticks < 5_000, "watchdog");
    }
    rig.tick();
    assert_eq!(rig.state(0), ChannelState::Error);
    assert_eq!(
        rig.state_block(0).error_id,
        ChannelErrorId::MachineStop.raw()
    );
    assert_eq!(rig.command(0, ChannelCommand::Reset, plain, 5), None);
    assert_eq!(rig.state(0), ChannelState::Selected);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    while rig.state(0) != ChannelState::Selected {
        rig.tick();
        assert!(rig.ticks < 50_000, "watchdog");
    }
    assert_eq!(rig.state_block(0).programs_ended, 1);
}

/// A command payload written without its semaphore is never read; a garbage semaphore byte is
/// counted as a protocol violation and nothing is taken.
#[test]
fn a_command_without_its_semaphore_is_not_taken() {
    use hli::desc::PlaceExt;
    use hli::layout::{HliChannel, HliChannelControlUnit};
    use std::mem::offset_of;
    fn unit(memory: &ImageMemory) -> hli::Place<'_, HliChannelControlUnit> {
        CncView::new(memory)
            .channel(0)
            .unwrap()
            .field::<HliChannelControlUnit>(offset_of!(HliChannel, channel_control))
    }
    let mut rig = Rig::new(vec![(cartesian("c"), Some(PART))], None);
    let start = HliChannelCommand {
        command_id: 42,
        command: ChannelCommand::Start.raw(),
        start_line: 0,
        value: 0,
        program: [0; 64],
    };
    unit(&rig.memory)
        .field::<HliChannelCommand>(offset_of!(HliChannelControlUnit, command_w))
        .write(&start);
    rig.run_ticks(100, |r| {
        assert_eq!(r.state(0), ChannelState::Selected);
        assert_eq!(r.state_block(0).command_id, 0);
    });
    unit(&rig.memory)
        .field::<hli::Bool>(offset_of!(HliChannelControlUnit, command_semaphore_rw))
        .write(&hli::Bool(7));
    rig.tick();
    assert_eq!(
        rig.state_block(0).command_id,
        0,
        "garbage semaphore: nothing taken"
    );
    assert_eq!(rig.ctl.violations().semaphore_garbage, 1);
    assert_eq!(rig.state(0), ChannelState::Selected);
}

/// A tracking slave on a conveyor moving at 100 mm/s is stopped by the PLC: with real axis
/// limits it brakes on them from the conveyor's speed (never back along the compensation),
/// comes to rest relative to the world, and ends SELECTED with tracking INACTIVE.
#[test]
fn stop_of_a_tracking_slave_brakes_it_to_rest_in_the_world_within_its_limits() {
    let mut config = ChannelConfig::new("s", &["X", "Y", "Z", "A", "B", "C"]);
    let limit = cnc_core::channel::path::AxisLimits {
        velocity: 500.0,
        acceleration: 2000.0,
        jerk: 100_000.0,
    };
    config.axis_limits = vec![limit; 6];
    let slave = "#TRACK CS ON [ID=0 FILTER=500]\nG1 X50 F600\nG1 X0\nM30\n";
    let mut rig = Rig::new(vec![(config, Some(slave))], None);
    enable_plc_master(&rig.memory, [0, 0, 0]);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    // The conveyor: 100 mm/s = 1000 units of 0.1 um per 1 ms tick.
    let mut conveyor = 0i32;
    let mut step = |rig: &mut Rig| {
        conveyor += 1000;
        let plc = PlcView::new(&rig.memory);
        let _ = plc
            .dyn_cs_command(0)
            .unwrap()
            .try_send(&cs([conveyor, 0, 0]));
        rig.tick();
    };
    for _ in 0..1_000 {
        step(&mut rig);
    }
    let c = &rig.ctl.channels()[0];
    assert_eq!(c.tracker().state(), DynCsState::Active, "{:?}", c.error());
    let id = rig.post(0, ChannelCommand::Stop, plain);
    let (mut last, mut v_last) = (rig.x(0), f64::NAN);
    let mut ticks = 0;
    loop {
        step(&mut rig);
        let v = (rig.x(0) - last) / CYCLE;
        assert!(v.abs() <= limit.velocity * 1.01, "velocity {v}");
        if v_last.is_finite() {
            let a = (v - v_last) / CYCLE;
            assert!(a.abs() <= limit.acceleration * 1.01, "acceleration {a}");
        }
        assert!(v >= -1e-9, "never back along the compensation: {v}");
        (last, v_last) = (rig.x(0), v);
        let s = rig.state_block(0);
        if s.command_id == id && s.command_state == ChannelCommandState::Done.raw() {
            break;
        }
        ticks += 1;
        assert!(ticks < 5_000, "watchdog");
    }
    assert_eq!(rig.state(0), ChannelState::Selected);
    assert_eq!(
        rig.ctl.channels()[0].tracker().state(),
        DynCsState::Inactive
    );
    let rest = rig.x(0);
    for _ in 0..200 {
        step(&mut rig);
        assert_eq!(
            rig.x(0),
            rest,
            "at rest in the world while the conveyor runs on"
        );
    }
}

/// Feed hold while the channel waits for an M acknowledge: the acknowledge is taken and the
/// program goes on after RESUME.
#[test]
fn an_m_acknowledge_during_feed_hold_is_not_lost() {
    let program = "M100\nG1 X10 F6000\nM30\n";
    let mut rig = Rig::new(vec![(cartesian("c"), Some(program))], None);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(3, |_| {});
    assert_eq!(rig.command(0, ChannelCommand::FeedHold, plain, 5), None);
    let plc = PlcView::new(&rig.memory);
    let ch = plc.gp_ch(0).unwrap();
    let request = ch.m_function_request().try_take().unwrap().unwrap();
    let ack = hli::layout::HliMFunctionAck {
        m_code: 100,
        request_id: request.request_id,
    };
    ch.m_function_ack().try_send(&ack).unwrap();
    rig.run_ticks(50, |r| assert_eq!(r.x(0), 0.0, "held"));
    assert_eq!(rig.command(0, ChannelCommand::Resume, plain, 5), None);
    rig.run_ticks(2_000, |_| {});
    assert_eq!(rig.x(0), 10.0);
    assert_eq!(rig.state_block(0).programs_ended, 1);
}

/// STOP while a RESET decelerates ends with it; single block switched off in a single-block
/// stop still waits for START; the machine-stopped flag refuses every command.
#[test]
fn stop_during_reset_single_block_off_and_a_machine_stop_flag() {
    let mut rig = Rig::new(vec![(cartesian("c"), Some(PART))], None);
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(300, |_| {});
    rig.post(0, ChannelCommand::Reset, plain);
    rig.tick();
    assert_eq!(rig.command(0, ChannelCommand::Stop, plain, 2_000), None);
    assert_eq!(rig.state(0), ChannelState::Selected);

    assert_eq!(
        rig.command(0, ChannelCommand::SingleBlock, |c| c.value = 1, 5),
        None
    );
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    while rig.state(0) != ChannelState::Holding {
        rig.tick();
        assert!(rig.ticks < 20_000, "watchdog");
    }
    assert_eq!(
        rig.command(0, ChannelCommand::SingleBlock, |c| c.value = 0, 5),
        None
    );
    let at = rig.x(0);
    rig.run_ticks(100, |r| {
        assert_eq!(r.state(0), ChannelState::Holding);
        assert_eq!(r.x(0), at);
    });
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(10, |_| {});
    assert_eq!(rig.state(0), ChannelState::Running);

    rig.ctl.channel_mut(0).unwrap().set_machine_stopped(true);
    assert_eq!(
        rig.command(0, ChannelCommand::Stop, plain, 5),
        Some(E::MachineStop)
    );
    rig.ctl.channel_mut(0).unwrap().set_machine_stopped(false);
    assert_eq!(rig.command(0, ChannelCommand::Stop, plain, 2_000), None);
}

/// Three channels: A waits for a signal B will give, B is selected and not started yet, C is
/// unrelated and stopped by the PLC. A keeps waiting (B may still signal) and goes on once B
/// runs.
#[test]
fn a_wait_syn_is_not_failed_while_a_selected_partner_may_still_signal() {
    let waits = "#WAIT SYN [ID1]\nG1 X20 F6000\nM30\n";
    let signals = "#SIGNAL SYN [ID1 COUNT1]\nM30\n";
    let other = "G1 X300 F600\nM30\n";
    let mut rig = Rig::new(
        vec![
            (cartesian("a"), Some(waits)),
            (cartesian("b"), Some(signals)),
            (cartesian("c"), Some(other)),
        ],
        None,
    );
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    assert_eq!(rig.command(2, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(100, |_| {});
    assert_eq!(rig.command(2, ChannelCommand::Stop, plain, 2_000), None);
    rig.run_ticks(100, |r| assert_eq!(r.state(0), ChannelState::Running));
    assert_eq!(rig.command(1, ChannelCommand::Start, plain, 5), None);
    rig.run_ticks(2_000, |_| {});
    assert_eq!(rig.x(0), 20.0);
    assert_eq!(rig.state_block(0).programs_ended, 1);
}

/// SELECT with a start line is a block search: the modal state of the blocks before it is
/// carried (here G1 and F), and blocks a search cannot carry are refused with their line.
#[test]
fn a_start_line_carries_the_modal_state_and_refuses_what_a_search_cannot_carry() {
    let plain_part = "G1 X100 F6000\nY50\nX0\nY0\nM30\n";
    let with_m = "G1 X10 F6000\nM100\nX20\nM30\n";
    let dir = folder(&[("part.nc", plain_part), ("m.nc", with_m)]);
    let mut rig = Rig::new(vec![(cartesian("c"), None)], Some(&dir));
    // Line 2 (Y50) is a bare `Y50`: G1 at F6000 come from line 1. X stays 0 (line 1 is
    // not run), Y goes to 50 and back.
    assert_eq!(
        rig.command(0, ChannelCommand::Select, select("part.nc", 2), 5),
        None
    );
    assert_eq!(rig.command(0, ChannelCommand::Start, plain, 5), None);
    let mut top_y = 0.0f64;
    while rig.state(0) != ChannelState::Selected {
        rig.tick();
        assert_eq!(rig.x(0), 0.0);
        top_y = top_y.max(rig.ctl.channels()[0].set_points()[1]);
        assert!(rig.ticks < 20_000, "watchdog");
    }
    assert_eq!(top_y, 50.0, "line 2 ran as G1 Y50 at the feed of line 1");
    assert_eq!(
        rig.command(0, ChannelCommand::Select, select("m.nc", 3), 5),
        Some(E::StartLineNotFound)
    );
    let message = rig.state_block(0).message;
    let text = nul_padded_str(&message).unwrap();
    assert!(
        text.contains("m.nc:2: an M function before line 3"),
        "{text}"
    );
}

/// The real-time loop's loader: the file is read on a thread of its own; the channel stays
/// BUSY meanwhile and selects the program once the result is taken between ticks.
#[test]
fn the_loader_thread_selects_between_later_ticks() {
    let dir = folder(&[("part.nc", PART)]);
    let mut rig = Rig::new(vec![(cartesian("c"), None)], Some(&dir));
    let loader = cnc_core::channel::folder::Loader::spawn().unwrap();
    let id = rig.post(0, ChannelCommand::Select, select("part.nc", 0));
    let mut ticks = 0;
    loop {
        rig.ctl.tick(&CncView::new(&rig.memory));
        rig.ctl.serve_channels(Some(&loader));
        let s = rig.state_block(0);
        assert_eq!(s.command_id, id);
        if s.command_state == ChannelCommandState::Done.raw() {
            break;
        }
        assert_eq!(s.command_state, ChannelCommandState::Busy.raw());
        ticks += 1;
        assert!(ticks < 1_000_000, "watchdog");
        std::thread::yield_now();
    }
    assert_eq!(rig.state(0), ChannelState::Selected);
    assert_eq!(nul_padded_str(&rig.state_block(0).program), Some("part.nc"));
}
