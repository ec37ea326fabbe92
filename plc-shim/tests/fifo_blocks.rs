//! The FIFO blocks' Execute semantics against the row service in one process: an edge while
//! Busy is ignored (one block travels, its answer is kept), and no answer within the
//! timeout is an Error.

use hli::calls::fifo::{FifoReply, FifoStartCall};
use hli::rpc::{AcyclicClient, AcyclicServer};
use plc_shim::blocks::fifo::{FifoStart, FifoWrite};
use plc_shim::kernel::ERROR_NO_ANSWER;
use plc_shim::runtime::PlcIo;

fn io<'a>(memory: &'a hli::ImageMemory, client: &'a mut AcyclicClient, cycle: u64) -> PlcIo<'a> {
    PlcIo {
        view: hli::views::PlcView::new(memory),
        memory,
        acyclic: client,
        cycle,
        link: plc_shim::runtime::Link::Operational,
    }
}

#[test]
fn an_edge_while_busy_sends_the_new_block_and_a_silent_cnc_times_out() {
    hli::init_logging();
    let instance = tests::unique_instance("fifo-blocks");
    let server = AcyclicServer::open(&instance).unwrap();
    let mut client = AcyclicClient::open(&instance).unwrap();
    let memory = hli::segment::heap_image(0, 1);
    let rows = [1.0, 2.0, 3.0, 4.0];
    let mut write = FifoWrite::default();
    // Edge, low, edge again: the CNC has not answered yet.
    for (cycle, execute) in [(0, true), (1, false), (2, true)] {
        let out = write.cycle(
            &mut io(&memory, &mut client, cycle),
            execute,
            0,
            &rows,
            2,
            2,
        );
        assert!(out.busy, "cycle {cycle}");
    }
    let mut blocks = 0;
    server
        .poll_rows(|_, _, values| {
            assert_eq!(values, rows);
            blocks += 1;
            hli::calls::reply(&FifoReply {
                row: 2,
                ..FifoReply::default()
            })
        })
        .unwrap();
    // The block kernel's rule: the edge while Busy is a new command; only its answer counts.
    assert_eq!(blocks, 2, "the edge while Busy sent the block again");
    let mut cycle = 3;
    let out = loop {
        let out = write.cycle(&mut io(&memory, &mut client, cycle), true, 0, &rows, 2, 2);
        cycle += 1;
        if !out.busy {
            break out;
        }
        assert!(cycle < 100_000, "watchdog: no answer");
        std::thread::yield_now();
    };
    assert!(out.done && out.extra.row == 2, "{out:?}");

    // Nobody answers: Error after the timeout.
    let mut start = FifoStart::default();
    start.set_timeout_cycles(5);
    let mut seen = Vec::new();
    for cycle in 0..8 {
        let out = start.cycle(
            &mut io(&memory, &mut client, 100 + cycle),
            true,
            0,
            FifoStartCall::default,
        );
        seen.push((out.busy, out.error, out.error_id));
    }
    assert_eq!(seen[5], (true, false, 0), "still waiting at the timeout");
    assert_eq!(seen[6], (false, true, ERROR_NO_ANSWER), "{seen:?}");
}
