//! One million command and one million request handshakes between two real processes through
//! the real segment: none lost, duplicated or torn.

use hli::views::CncView;
use hli_transport::segment::CncSegment;
use std::process::Stdio;
use std::time::{Duration, Instant};
use tests::{payload, unique_instance, verify};

const HANDSHAKES: u32 = 1_000_000;

#[test]
fn a_million_handshakes_each_way_are_exact() {
    hli_transport::init_logging();
    let instance = unique_instance("million");
    let segment = CncSegment::create(&instance, 1, 1).unwrap();
    let mut child = tests::Cli::new(env!("CARGO_BIN_EXE_hli-peer"))
        .args(["plc-handshakes", &instance, &HANDSHAKES.to_string()])
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let view = CncView::new(segment.memory());
    let mut rx = view.dyn_cs_command(0).unwrap();
    let tx = view.dyn_cs_request(0).unwrap();
    let (mut taken, mut published, mut spins) = (0u32, 0u32, 0u64);
    // A watchdog against a hung child, not a performance assertion.
    let watchdog = Instant::now() + Duration::from_secs(600);
    while taken < HANDSHAKES || published < HANDSHAKES {
        let mut progressed = false;
        match rx.try_take() {
            Ok(Some(p)) => {
                assert_eq!(
                    verify(&p),
                    Some(taken),
                    "command {taken} lost, duplicated or torn"
                );
                taken += 1;
                progressed = true;
            }
            Ok(None) => {}
            Err(e) => panic!("command {taken}: {e}"),
        }
        if published < HANDSHAKES && tx.try_send(&payload(published)).is_ok() {
            published += 1;
            progressed = true;
        }
        if !progressed {
            spins += 1;
            if spins % 64 == 0 {
                std::thread::yield_now();
                if let Ok(Some(status)) = child.0.try_wait() {
                    panic!("PLC child exited early ({status}) at {taken}/{published}");
                }
                assert!(
                    Instant::now() < watchdog,
                    "watchdog: stuck at {taken}/{published}"
                );
            }
        }
    }
    let status = child
        .wait_with_watchdog(Duration::from_secs(60))
        .expect("child exits");
    assert!(status.success(), "PLC side reported a mismatch: {status}");
    assert_eq!(rx.stats().taken, u64::from(HANDSHAKES));
    assert_eq!(rx.stats().violations(), 0);
}
