//! FIFO row blocks between processes: a PLC that dies while writing a block leaves no half
//! block; the block it had sent before arrives whole.

use hli::calls::fifo::FifoReply;
use hli::calls::reply;
use hli_transport::rpc::{AcyclicClient, AcyclicServer};
use std::time::{Duration, Instant};
use tests::unique_instance;

#[test]
fn a_plc_dying_mid_write_leaves_no_half_block() {
    hli_transport::init_logging();
    let instance = unique_instance("half-block");
    let server = AcyclicServer::open(&instance).unwrap();
    let mut child = tests::spawn_peer_saying(
        env!("CARGO_BIN_EXE_hli-peer"),
        &["plc-half-block", &instance],
        "half",
    );
    // The whole block arrives while the PLC is alive (a watchdog, not a timing assert).
    let mut blocks = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(30);
    while blocks.is_empty() {
        assert!(
            Instant::now() < deadline,
            "watchdog: the whole block never arrived"
        );
        server
            .poll_rows(|_, header, values| {
                blocks.push((*header, values.to_vec()));
                reply(&FifoReply::default())
            })
            .unwrap();
        std::thread::yield_now();
    }
    // Now the PLC dies with half of the second block written.
    drop(child.0.stdin.take());
    let status = child
        .wait_with_watchdog(Duration::from_secs(30))
        .expect("child ended");
    assert!(!status.success(), "the child aborted");
    // A few more polls: nothing else may arrive.
    for _ in 0..100 {
        server
            .poll_rows(|_, header, values| {
                blocks.push((*header, values.to_vec()));
                reply(&FifoReply::default())
            })
            .unwrap();
    }
    assert_eq!(blocks.len(), 1, "{blocks:?}");
    let (header, values) = &blocks[0];
    assert_eq!((header.rows, header.columns), (10, 3));
    assert_eq!(*values, (0..30).map(f64::from).collect::<Vec<_>>());
    // The service goes on for the next PLC.
    let mut client = AcyclicClient::open(&instance).unwrap();
    let header = hli::calls::fifo::rows_header(0, 1, 2, false);
    let pending = client.start_rows(header, &[7.0, 8.0]).unwrap();
    let mut got = Vec::new();
    let reply = loop {
        server
            .poll_rows(|_, _, values| {
                got.extend_from_slice(values);
                reply(&FifoReply {
                    row: 2,
                    ..FifoReply::default()
                })
            })
            .unwrap();
        if let Some(reply) = pending.poll::<FifoReply>() {
            break reply.unwrap();
        }
        assert!(
            Instant::now() < deadline + Duration::from_secs(30),
            "watchdog"
        );
        std::thread::yield_now();
    };
    assert_eq!((got, reply.row), (vec![7.0, 8.0], 2));
}
