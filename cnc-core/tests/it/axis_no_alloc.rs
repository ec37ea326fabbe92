//! The axis tick (set-point generation, re-targets, process image, simulated drives) and the
//! command handler allocate nothing once the axes are built.

use cnc_core::axis::config::{AxisConfig, DriveLink, DriveMode, DriveProtocol, ProbeInterface};
use cnc_core::axis::increments::CounterWidth;
use cnc_core::axis::sim_drive::{Dynamic, SimDriveConfig};
use cnc_core::axis::AxisSet;
use hli::calls::axis::{AxisCommandCall, AxisCommandReply};
use hli::calls::CallKind;
use hli::views::CncView;
use hli::wire::{AcyclicRequest, ACYCLIC_BODY_SIZE};

use crate::counting_alloc;
use counting_alloc::allocations;

fn request(target: u32, call: &AxisCommandCall) -> AcyclicRequest {
    request_of(CallKind::AXIS_COMMAND, target, call)
}

fn request_of<T: bytemuck::Pod>(kind: CallKind, target: u32, call: &T) -> AcyclicRequest {
    let bytes = bytemuck::bytes_of(call);
    let mut body = [0u8; ACYCLIC_BODY_SIZE];
    body[..bytes.len()].copy_from_slice(bytes);
    AcyclicRequest {
        invoke_id: 1,
        kind: kind.raw(),
        target,
        body_len: bytes.len() as u32,
        body,
    }
}

#[test]
fn thirty_two_axes_tick_and_take_commands_without_allocating() {
    let configs: Vec<AxisConfig> = (0..32)
        .map(|i| {
            let mut c = AxisConfig::linear(&format!("A{i}"), i + 1);
            match i % 4 {
                0 => {}
                1 => c.drive_mode = DriveMode::Position,
                2 => c.encoder_width = CounterWidth::Bits16,
                _ => {
                    c.drive = DriveLink::Simulated(SimDriveConfig {
                        dynamic: Dynamic::Pt2 {
                            frequency_hz: 80.0,
                            damping: 0.8,
                        },
                        dead_time_ticks: 2,
                        start_position: 1.0,
                        ..SimDriveConfig::default()
                    })
                }
            }
            // CiA 402 drives with dead-time compensation, and touch probes on a sensor.
            if i % 2 == 0 {
                c.io.protocol = DriveProtocol::Cia402;
                c.io.dc_compensation = true;
            }
            if let (0, DriveLink::Simulated(sim)) = (i % 3, &mut c.drive) {
                c.io.probe = ProbeInterface::Canopen;
                sim.probe_windows = [Some([20.0, 30.0]), Some([-30.0, -20.0])];
            }
            // The last axis: an external drive mapped signal by signal (decoded and encoded
            // every tick).
            if i == 31 {
                c.drive = DriveLink::External;
                c.io = toml::from_str(
                    r#"map = [
                        { signal = "enc_in.nInData1", bit = 32, width = 32, signed = true },
                        { signal = "drive_out.nOutData1", bit = 0, width = 16, signed = true, scale = 100.0 },
                    ]"#,
                )
                .unwrap();
            }
            c
        })
        .collect();
    let memory = hli::image::heap_image(1, 32);
    let view = CncView::new(&memory);
    let mut set = AxisSet::new(configs, 0.001).unwrap();
    set.prime(&view);
    set.tick(&view);
    let limits = [400.0, 4000.0, 4000.0, 100_000.0];
    let calls = [
        AxisCommandCall::power(true),
        AxisCommandCall::move_absolute(50.0, limits),
        AxisCommandCall::move_relative(-20.0, limits),
        AxisCommandCall::move_velocity(1, limits),
        AxisCommandCall::halt(3000.0, 80_000.0),
        AxisCommandCall::move_absolute(5000.0, limits), // refused: outside the limits
        AxisCommandCall::stop(4000.0, 100_000.0),
        AxisCommandCall::stop_release(),
    ];
    // Warm up once through every command kind so lazily initialised statics (if any) are set.
    for (n, call) in calls.iter().enumerate() {
        let _ = set.handle_command(&request(0, call));
        for _ in 0..(50 + n) {
            set.tick(&view);
        }
    }
    let before = allocations();
    let mut accepted = 0;
    let mut armed = 0;
    for round in 0..20 {
        for (n, call) in calls.iter().enumerate() {
            for axis in 0..32u32 {
                let arm = hli::calls::probe::ProbeArmCall {
                    probe: 1 + axis % 2,
                    edge: 1,
                    ..Default::default()
                };
                let (body, _) = set
                    .handle_probe(&request_of(CallKind::PROBE_ARM, axis, &arm), true)
                    .unwrap();
                let reply: hli::calls::probe::ProbeReply = bytemuck::pod_read_unaligned(&body[..8]);
                armed += u32::from(reply.error_id == 0);
                let (body, _) = set.handle_command(&request(axis, call)).unwrap();
                let reply: AxisCommandReply = bytemuck::pod_read_unaligned(&body[..8]);
                accepted += u32::from(reply.error_id == 0);
            }
            for _ in 0..(37 + round + n) {
                set.tick(&view);
            }
        }
    }
    let allocations = allocations() - before;
    // 11 probed axes: an arming is accepted again only after the last one recorded, so
    // more than 11 accepted armings are recordings.
    assert!(
        armed > 11 + 10,
        "the probes must really record ({armed} armings)"
    );
    assert!(
        accepted > 4000,
        "the commands must really run ({accepted} accepted)"
    );
    assert_eq!(
        allocations, 0,
        "allocations in the axis tick or the command handler"
    );
}
