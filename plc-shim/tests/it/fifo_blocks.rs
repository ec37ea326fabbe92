//! The FIFO blocks' Execute semantics against the row service in one process: an edge while
//! Busy is ignored (one block travels, its answer is kept), and no answer within the
//! timeout is an Error. FiFoWrite's size check in the PLC (seed 002, FiFoWrite: the block's
//! columns x rows must lie within the array it is taken from): a block larger than the array,
//! or larger than one row call ([`FIFO_BLOCK_VALUES`]), ends with [`ERROR_BLOCK_SIZE`] in the
//! cycle of the Execute edge and nothing reaches the CNC; a block of exactly one call, or the
//! first rows of a larger array, is sent.

use hli::calls::fifo::FifoError;
use hli::calls::fifo::{FifoReply, FifoStartCall, FIFO_BLOCK_VALUES};
use hli::calls::CallKind;
use hli_transport::rpc::{AcyclicClient, AcyclicServer};
use plc_shim::blocks::fifo::{FifoStart, FifoWrite, ERROR_BLOCK_SIZE};
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
    hli_transport::init_logging();
    let instance = tests::unique_instance("fifo-blocks");
    let server = AcyclicServer::open(&instance).unwrap();
    let mut client = AcyclicClient::open(&instance).unwrap();
    let memory = hli::image::heap_image(0, 1);
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

/// Blocks too large for their array or for one call: Error with ERROR_BLOCK_SIZE (the CNC's
/// `BlockSize` code) in the first cycle, held while Execute stays high; no call sent, and
/// the CNC's row service finds no block.
#[test]
fn a_block_larger_than_its_array_or_one_call_is_refused_and_nothing_is_sent() {
    hli_transport::init_logging();
    assert_eq!(ERROR_BLOCK_SIZE, FifoError::BlockSize.raw());
    let instance = tests::unique_instance("fifo-block-sizes");
    let server = AcyclicServer::open(&instance).unwrap();
    let mut client = AcyclicClient::open(&instance).unwrap();
    let memory = hli::image::heap_image(0, 1);
    let small = [1.0, 2.0, 3.0, 4.0];
    // Fits its array (rows x columns == its length) but not one call.
    let big = vec![0.5; FIFO_BLOCK_VALUES + 2];
    let over_one_call = (FIFO_BLOCK_VALUES / 2 + 1) as u32;
    let cases: [(&str, &[f64], u32, u32, bool); 6] = [
        ("3 rows of 2 from 4 values", &small[..], 2, 3, false),
        ("2 rows of 3 from 4 values", &small[..], 3, 2, false),
        ("5 rows of 1 from 4 values", &small[..], 1, 5, false),
        ("the same as FiFoOverwrite", &small[..], 2, 3, true),
        ("one call and 2 values", &big[..], 2, over_one_call, false),
        ("u32::MAX x u32::MAX", &small[..], u32::MAX, u32::MAX, false),
    ];
    let mut cycle = 0;
    for (what, data, columns, rows, overwrite) in cases {
        let mut write = if overwrite {
            FifoWrite::overwrite()
        } else {
            FifoWrite::default()
        };
        let out = write.cycle(
            &mut io(&memory, &mut client, cycle),
            true,
            0,
            data,
            columns,
            rows,
        );
        assert!(
            out.error && !out.busy && !out.done,
            "{what}: refused in the edge's cycle: {out:?}"
        );
        assert_eq!(out.error_id, ERROR_BLOCK_SIZE, "{what}");
        let held = write.cycle(
            &mut io(&memory, &mut client, cycle + 1),
            true,
            0,
            data,
            columns,
            rows,
        );
        assert!(held.error && !held.busy, "{what}: held: {held:?}");
        assert_eq!(held.error_id, ERROR_BLOCK_SIZE, "{what}");
        cycle += 2;
    }
    assert_eq!(client.sent(), 0, "no block left the PLC");
    let mut blocks = 0;
    let answered = server
        .poll_rows(|_, _, _| {
            blocks += 1;
            hli::calls::reply(&FifoReply::default())
        })
        .unwrap();
    assert_eq!((answered, blocks), (0, 0), "the CNC saw no block");
}

/// Runs `write` with Execute high until it is no longer Busy, answering each block on the
/// row service with `row = rows`; returns the blocks seen (kind, columns, rows, values).
fn send_and_answer(
    write: &mut FifoWrite,
    server: &AcyclicServer,
    client: &mut AcyclicClient,
    memory: &hli::ImageMemory,
    data: &[f64],
    columns: u32,
    rows: u32,
) -> Vec<(u32, u32, u32, Vec<f64>)> {
    let out = write.cycle(&mut io(memory, client, 0), true, 0, data, columns, rows);
    assert!(out.busy && !out.error, "sent: {out:?}");
    let mut seen = Vec::new();
    server
        .poll_rows(|_, header, values| {
            seen.push((header.kind, header.columns, header.rows, values.to_vec()));
            hli::calls::reply(&FifoReply {
                row: header.rows,
                ..FifoReply::default()
            })
        })
        .unwrap();
    let mut cycle = 1;
    let out = loop {
        let out = write.cycle(&mut io(memory, client, cycle), true, 0, data, columns, rows);
        cycle += 1;
        if !out.busy {
            break out;
        }
        assert!(cycle < 100_000, "watchdog: no answer");
        std::thread::yield_now();
    };
    assert!(out.done && !out.error, "{out:?}");
    assert_eq!(out.extra.row, rows);
    seen
}

/// The bounds are inclusive: a block of exactly FIFO_BLOCK_VALUES values, and the first rows
/// of an array longer than the block, are sent whole (the values the block names, no more).
#[test]
fn a_block_of_exactly_one_call_or_the_first_rows_of_an_array_is_sent() {
    hli_transport::init_logging();
    let instance = tests::unique_instance("fifo-block-sizes-ok");
    let server = AcyclicServer::open(&instance).unwrap();
    let mut client = AcyclicClient::open(&instance).unwrap();
    let memory = hli::image::heap_image(0, 1);

    let data: Vec<f64> = (0..FIFO_BLOCK_VALUES + 3).map(|k| k as f64).collect();
    let rows = (FIFO_BLOCK_VALUES / 2) as u32;
    let mut write = FifoWrite::default();
    let seen = send_and_answer(&mut write, &server, &mut client, &memory, &data, 2, rows);
    assert_eq!(seen.len(), 1);
    let (kind, columns, got_rows, values) = &seen[0];
    assert_eq!(
        (*kind, *columns, *got_rows),
        (CallKind::FIFO_WRITE_ROWS.raw(), 2, rows)
    );
    assert_eq!(values.as_slice(), &data[..FIFO_BLOCK_VALUES]);

    let array = [0.0, 0.1, 0.2, 1.0, 1.1, 1.2, 2.0, 2.1, 2.2, 3.0];
    let mut overwrite = FifoWrite::overwrite();
    let seen = send_and_answer(&mut overwrite, &server, &mut client, &memory, &array, 3, 2);
    assert_eq!(seen.len(), 1);
    let (kind, columns, got_rows, values) = &seen[0];
    assert_eq!(
        (*kind, *columns, *got_rows),
        (CallKind::FIFO_OVERWRITE_ROWS.raw(), 3, 2)
    );
    assert_eq!(values.as_slice(), &array[..6]);
    assert_eq!(client.sent(), 2);
}
