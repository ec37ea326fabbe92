//! The acyclic request-response plumbing and the wake-up events, between two threads of one
//! process (the transport is the same iceoryx2 IPC service the processes use).

use hli::calls::axis::ReadAxisState;
use hli::calls::{AcyclicCall, CallError, CallKind, ErrorCode};
use hli::enums::AxisState;
use hli::layout::{HliAxis, HliAxisLrState};
use hli::views::handle_read_axis_state;
use hli::views::CncView;
use hli::PlaceExt;
use hli_transport::events::{EventLink, Side};
use hli_transport::rpc::{AcyclicClient, AcyclicServer};
use hli_transport::segment::CncSegment;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tests::unique_instance;

/// A call whose body has the wrong size for its kind.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct OversizedRead {
    a: u64,
}
impl AcyclicCall for OversizedRead {
    const KIND: CallKind = CallKind::READ_AXIS_STATE;
    type Reply = HliAxisLrState;
}

#[test]
fn read_axis_state_is_answered_and_bad_calls_are_refused_with_codes() {
    hli_transport::init_logging();
    let instance = unique_instance("rpc");
    let segment = CncSegment::create(&instance, 1, 2).unwrap();
    let view = CncView::new(segment.memory());
    view.axis(1)
        .unwrap()
        .field::<HliAxisLrState>(core::mem::offset_of!(HliAxis, lr_state))
        .write(&HliAxisLrState {
            current_position_acs_r: 123_456,
            axis_state_r: AxisState::SlaveSynchronous.raw(),
            ..bytemuck::Zeroable::zeroed()
        });
    let server = AcyclicServer::open(&instance).unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let client_instance = instance.clone();
    let client_stop = stop.clone();
    let client = std::thread::spawn(move || {
        let mut client = AcyclicClient::open(&client_instance).unwrap();
        let timeout = Duration::from_secs(30); // watchdog, not a performance bound
        let ok = client.call(1, &ReadAxisState::default(), timeout);
        let bad_index = client.call(7, &ReadAxisState::default(), timeout);
        let bad_data = client.call(0, &ReadAxisState { reserved: 5 }, timeout);
        let bad_size = client.call(0, &OversizedRead { a: 1 }, timeout);
        client_stop.store(true, Ordering::Release);
        (ok, bad_index, bad_data, bad_size)
    });
    let mut answered = 0;
    while !stop.load(Ordering::Acquire) {
        answered += server
            .poll(|kind, request| match kind {
                CallKind::READ_AXIS_STATE => handle_read_axis_state(&view, request),
                _ => Err(ErrorCode::ServiceNotSupported),
            })
            .unwrap();
        std::thread::yield_now();
    }
    let (ok, bad_index, bad_data, bad_size) = client.join().unwrap();
    let state = ok.unwrap();
    assert_eq!(state.current_position_acs_r, 123_456);
    assert_eq!(state.axis_state_r, 13);
    assert_eq!(
        bad_index,
        Err(CallError::Refused {
            code: ErrorCode::InvalidTarget
        })
    );
    assert_eq!(
        bad_data,
        Err(CallError::Refused {
            code: ErrorCode::InvalidData
        })
    );
    assert_eq!(
        bad_size,
        Err(CallError::Refused {
            code: ErrorCode::InvalidSize
        })
    );
    assert_eq!(answered, 4);
}

#[test]
fn a_call_nobody_answers_times_out() {
    hli_transport::init_logging();
    let instance = unique_instance("rpc-timeout");
    let _server = AcyclicServer::open(&instance).unwrap(); // never polled
    let mut client = AcyclicClient::open(&instance).unwrap();
    let result = client.call(0, &ReadAxisState::default(), Duration::from_millis(20));
    assert_eq!(result, Err(CallError::Timeout(Duration::from_millis(20))));
}

#[test]
fn tick_and_cycle_events_wake_the_other_side() {
    hli_transport::init_logging();
    let instance = unique_instance("events");
    let cnc = EventLink::open(&instance, Side::Cnc).unwrap();
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    let peer_instance = instance.clone();
    let peer = std::thread::spawn(move || {
        // iceoryx2 ports are not Send: the PLC side lives in its own thread from the start.
        let plc = EventLink::open(&peer_instance, Side::Plc).unwrap();
        assert!(!plc.poll().unwrap());
        ready_tx.send(()).unwrap();
        // Answer three ticks with three cycles.
        for _ in 0..3 {
            assert!(plc.wait(Duration::from_secs(30)).unwrap(), "tick event");
            plc.notify().unwrap();
        }
    });
    ready_rx.recv().unwrap();
    for _ in 0..3 {
        cnc.notify().unwrap();
        assert!(cnc.wait(Duration::from_secs(30)).unwrap(), "cycle event");
    }
    peer.join().unwrap();
    assert!(!cnc.poll().unwrap(), "no spurious wake-ups left");
}
