//! A running FIFO group allocates and frees nothing: the machine tick of a six-axis group
//! with a PT-2 override change, the rows arriving through the row service (the PLC's
//! FiFoWrite block sending, the CNC answering) in the same loop, an underrun and the stop.
//! The row service (the call mailbox's bulk slots) is counted apart: nothing either (it
//! allocated 3 per block when it was iceoryx2's request-response).

use cnc_app::scenario::{InProcess, Scenario};
use hli::calls::fifo::{
    FifoIntegrateCall, FifoOverrideCall, FifoReply, FifoStartCall, FifoStopCall,
};
use hli::calls::AcyclicCall;
use hli::enums::FifoGroupState;
use hli::views::{CncView, PlcView};
use hli_transport::rpc::{AcyclicClient, AcyclicServer};
use plc_shim::blocks::fifo::FifoWrite;
use plc_shim::runtime::PlcIo;

use crate::counting_alloc;
use counting_alloc::{allocations, deallocations};

const N: usize = 6;

#[derive(Default)]
struct Counts {
    /// The machine tick and the engine's row handler.
    ours: usize,
    /// Their frees.
    ours_freed: usize,
    /// The row service (iceoryx2) on both sides.
    transport: usize,
    /// Blocks sent.
    blocks: usize,
}

fn call<C: AcyclicCall<Reply = FifoReply>>(run: &mut InProcess, body: C) -> u32 {
    let view = CncView::new(&run.memory);
    run.machine
        .call(&view, 0, &body)
        .expect("answered")
        .error_id
}

/// The PLC's side: one FiFoWrite instance sending up to 100 rows whenever it may.
struct Plc {
    client: AcyclicClient,
    write: FifoWrite,
    sent: usize,
    sending: usize,
    lowering: bool,
    cycle: u64,
}

impl Plc {
    /// `n` times: CNC tick, the row service answered, PLC cycle; allocations counted apart.
    fn steps(
        &mut self,
        n: usize,
        run: &mut InProcess,
        server: &AcyclicServer,
        rows: &[f64],
        counts: &mut Counts,
    ) {
        for _ in 0..n {
            let (a0, d0) = (allocations(), deallocations());
            run.machine.tick(&run.memory);
            counts.ours += allocations() - a0;
            counts.ours_freed += deallocations() - d0;
            let machine = &mut run.machine;
            let a0 = allocations();
            let (mut handler, mut freed) = (0, 0);
            server
                .poll_rows(|_, header, values| {
                    let (h0, f0) = (allocations(), deallocations());
                    let reply = machine.dispatch_bulk(header, values);
                    handler += allocations() - h0;
                    freed += deallocations() - f0;
                    reply
                })
                .unwrap();
            counts.ours += handler;
            counts.ours_freed += freed;
            counts.transport += allocations() - a0 - handler;
            let free = PlcView::new(&run.memory).fifo_group(0).unwrap().free_r as usize;
            let mut io = PlcIo {
                view: PlcView::new(&run.memory),
                memory: &run.memory,
                acyclic: &mut self.client,
                cycle: self.cycle,
                link: plc_shim::runtime::Link::Operational,
            };
            self.cycle += 1;
            if self.sending == 0 && !self.lowering && self.sent < ROWS {
                self.sending = (ROWS - self.sent).min(free).min(100);
                counts.blocks += usize::from(self.sending > 0);
            }
            let execute = self.sending > 0 && !self.lowering;
            let data = &rows[self.sent * N..];
            let a0 = allocations();
            let out = self
                .write
                .cycle(&mut io, execute, 0, data, N as u32, self.sending as u32);
            counts.transport += allocations() - a0;
            if self.lowering {
                self.lowering = false;
            } else if out.done {
                self.sent += self.sending;
                self.sending = 0;
                self.lowering = true;
            } else if out.error {
                self.sending = 0;
                self.lowering = true;
            }
        }
    }
}

const ROWS: usize = 3000;

#[test]
fn a_running_group_and_its_row_blocks_allocate_nothing() {
    let mut toml = String::from("cycle_ms = 1.0\nticks = 10\n");
    for i in 0..N {
        toml.push_str(&format!("[[axis]]\nname = \"A{i}\"\npower = true\n"));
    }
    toml.push_str(
        "[[fifo_group]]\ndimension = 6\nrows = 400\nfifo_cycle_ms = 1.5\n\
         override = \"pt2\"\npt2_t0_ms = 20.0\n",
    );
    let s = Scenario::parse("no-alloc.toml", &toml, |f| panic!("{f}")).unwrap();
    let mut run = InProcess::new(&s, 0).unwrap();
    let instance = tests::unique_instance("fifo-no-alloc");
    let server = AcyclicServer::open(&instance).unwrap();
    let client = AcyclicClient::open(&instance).unwrap();
    run.step(0.001);
    for axis in 0..N as u32 {
        let integrate = FifoIntegrateCall {
            axis,
            group_position: axis + 1,
        };
        assert_eq!(call(&mut run, integrate), 0);
    }
    // 3000 rows of a slow sweep, written in blocks of up to 100 rows while the group runs.
    let rows: Vec<f64> = (0..ROWS)
        .flat_map(|k| (0..N).map(move |c| (k as f64 * 0.001 * (c + 1) as f64).sin()))
        .map(|v| v - 0.0)
        .collect();
    let mut plc = Plc {
        client,
        write: FifoWrite::default(),
        sent: 0,
        sending: 0,
        lowering: false,
        cycle: 0,
    };
    let mut counts = Counts::default();
    // Warm-up: the ports' first use, the first blocks, the start.
    plc.steps(20, &mut run, &server, &rows, &mut counts);
    assert_eq!(call(&mut run, FifoStartCall::default()), 0);
    plc.steps(50, &mut run, &server, &rows, &mut counts);
    counts = Counts::default();
    // An override change (PT-2) while rows stream in.
    let change = FifoOverrideCall {
        override_ppm: 600_000,
    };
    assert_eq!(call(&mut run, change), 0);
    plc.steps(2000, &mut run, &server, &rows, &mut counts);
    // The rest of the rows, the FIFO running dry (underrun), the stop.
    let (a, d) = (allocations(), deallocations());
    for _ in 0..5000 {
        run.machine.tick(&run.memory);
    }
    let dry = PlcView::new(&run.memory).fifo_group(0).unwrap();
    assert!(
        dry.underrun_ticks_r > 1000,
        "ran dry: {}",
        dry.underrun_ticks_r
    );
    assert_eq!(call(&mut run, FifoStopCall::default()), 0);
    for _ in 0..600 {
        run.machine.tick(&run.memory);
    }
    counts.ours += allocations() - a;
    counts.ours_freed += deallocations() - d;
    assert_eq!(
        counts.ours, 0,
        "allocations of the tick and the row handler"
    );
    assert_eq!(
        counts.ours_freed, 0,
        "frees of the tick and the row handler"
    );
    // The mailbox allocates nothing per block (iceoryx2's request-response allocated 3).
    let blocks = counts.blocks;
    assert!(blocks > 20, "{blocks} blocks in the measured loop");
    assert_eq!(
        counts.transport, 0,
        "the transport's allocations for {blocks} blocks"
    );
    let status = PlcView::new(&run.memory).fifo_group(0).unwrap();
    assert_eq!(status.group_state_r, FifoGroupState::Idle.raw());
    assert!(
        plc.sent > 1000,
        "{} rows went through the row service",
        plc.sent
    );
}
