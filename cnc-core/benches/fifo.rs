//! What a FIFO group costs, and how fast rows cross from a PLC process into the FIFO.
//!
//! 1. **Tick.** The whole machine tick (axes sense, the FIFO engine, axes act, the image
//!    writes) of six single axes, in turn as a running 6-axis FIFO group (T_f = 1 tick, PT-2
//!    override, the FIFO refilled between the measured batches) and standing uncoupled (the
//!    in-run baseline); medians over interleaved repeats; the extra per group-tick is the
//!    difference. Beside it the pure set-point step (`FifoGenerator::step` with the override
//!    filter) of six axes. Target: <= 0.5 us per group-tick.
//! 2. **Rows across processes.** A child process (this binary again) sends 1,000,002 rows of
//!    six axes in blocks of 1,365 rows (64 KiB) over the row service, each written in place
//!    into shared memory, waiting for each reply; this process answers with the FIFO engine
//!    (every block checked and queued into a 2^20-row FIFO) or, as the in-run baseline, with
//!    a handler that only reads the block's first value. Medians over interleaved repeats,
//!    rows/s from the child's first send to its last reply. Target: >= 1,000,000 rows/s.
//!
//! Run: `cargo bench -p cnc-core --bench fifo`.

use bench_kit::{median, scaled};
use cnc_core::axis::config::AxisConfig;
use cnc_core::fifo::machine::FifoEngine;
use cnc_core::fifo::{FifoGenerator, FifoParams, OverrideFilter, OverrideType, RowRing};
use cnc_core::machine::{Machine, MachineSetup};
use hli::calls::fifo::{
    rows_header, FifoIntegrateCall, FifoOverrideCall, FifoReply, FifoStartCall,
};
use hli::calls::AcyclicCall;
use hli::views::CncView;
use hli::ImageMemory;
use hli_transport::rpc::{AcyclicClient, AcyclicServer};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::Instant;

const N: usize = 6;
const TICK: f64 = 0.001;
const BATCH: usize = 1000;
const REPEATS: usize = 15;
const BLOCK_ROWS: usize = 1365;
const BLOCKS: usize = 733;

fn call<C: AcyclicCall<Reply = FifoReply>>(machine: &mut Machine, memory: &ImageMemory, body: C) {
    let reply = machine
        .call(&CncView::new(memory), 0, &body)
        .expect("answered");
    assert_eq!(reply.error_id, 0, "{:?}", C::KIND);
}

fn machine(fifo_rows: usize) -> (Machine, ImageMemory) {
    let axes = (0..N)
        .map(|i| {
            let mut c = AxisConfig::linear(&format!("A{i}"), i as u32 + 1);
            c.soft_limits = None;
            c
        })
        .collect();
    let params = FifoParams::new(N, fifo_rows, TICK, OverrideType::Pt2 { t0_s: 0.02 }).unwrap();
    let engine = FifoEngine::new(&[params], TICK).unwrap();
    let mut machine = Machine::new(MachineSetup {
        channels: Vec::new(),
        axes,
        engines: vec![Box::new(engine)],
        cycle_s: TICK,
    })
    .unwrap();
    for i in 0..N {
        machine.axes_mut().axis_mut(i).unwrap().switch_on().unwrap();
    }
    let memory = hli::image::heap_image(0, N as u32);
    machine.tick(&memory);
    (machine, memory)
}

/// Row `k` of a smooth six-axis sweep.
fn row(k: usize) -> [f64; N] {
    let t = k as f64 * TICK;
    std::array::from_fn(|c| (c + 1) as f64 * (t * (0.3 + 0.1 * c as f64)).sin())
}

fn refill(machine: &mut Machine, next: &mut usize, rows: usize) {
    let values: Vec<f64> = (*next..*next + rows).flat_map(row).collect();
    let header = rows_header(0, N as u32, rows as u32, false);
    let (body, len) = machine.dispatch_bulk(&header, &values).unwrap();
    let reply: FifoReply = bytemuck::pod_read_unaligned(&body[..len as usize]);
    assert_eq!(reply.error_id, 0);
    *next += rows;
}

fn tick_cost() {
    // Running: integrated, 2000 rows queued, started, override moving (PT-2) now and then.
    let (mut running, memory_r) = machine(4096);
    for axis in 0..N as u32 {
        call(
            &mut running,
            &memory_r,
            FifoIntegrateCall {
                axis,
                group_position: axis + 1,
            },
        );
    }
    let mut next = 0;
    refill(&mut running, &mut next, 2000);
    call(&mut running, &memory_r, FifoStartCall::default());
    // Standing: the same machine, the axes never integrated.
    let (mut standing, memory_s) = machine(4096);
    let mut run_ns = Vec::new();
    let mut stand_ns = Vec::new();
    for r in 0..scaled(REPEATS) {
        let ppm = if r % 2 == 0 { 700_000 } else { 1_000_000 };
        call(
            &mut running,
            &memory_r,
            FifoOverrideCall { override_ppm: ppm },
        );
        let t = Instant::now();
        for _ in 0..scaled(BATCH) {
            running.tick(&memory_r);
        }
        run_ns.push(t.elapsed().as_nanos() as f64 / scaled(BATCH) as f64);
        let t = Instant::now();
        for _ in 0..scaled(BATCH) {
            standing.tick(&memory_s);
        }
        stand_ns.push(t.elapsed().as_nanos() as f64 / scaled(BATCH) as f64);
        let free = hli::views::PlcView::new(&memory_r)
            .fifo_group(0)
            .unwrap()
            .free_r;
        refill(&mut running, &mut next, (free as usize).min(scaled(BATCH)));
        let status = hli::views::PlcView::new(&memory_r).fifo_group(0).unwrap();
        assert_eq!(
            status.flags_r & hli::layout::FIFO_FLAG_UNDERRUN,
            0,
            "ran dry"
        );
    }
    // The pure step: generator and override filter of six axes.
    let mut ring = RowRing::new(N, 1 << 16);
    let mut generator = FifoGenerator::new(N, TICK, TICK * 1.7);
    let mut filter = OverrideFilter::new(OverrideType::Pt2 { t0_s: 0.02 }, TICK);
    let mut step_ns = Vec::new();
    let mut k = 0;
    for r in 0..scaled(REPEATS) {
        ring.clear();
        let block: Vec<f64> = (k..k + 30_000).flat_map(row).collect();
        ring.push_block(&block).unwrap();
        k += 30_000;
        generator.start(&ring);
        filter.set_target(if r % 2 == 0 { 0.8 } else { 1.0 });
        let t = Instant::now();
        let mut sum = 0.0;
        for _ in 0..10_000 {
            let ov = filter.step();
            generator.step(&mut ring, ov);
            sum += generator.position()[N - 1];
        }
        step_ns.push(t.elapsed().as_nanos() as f64 / 10_000.0);
        assert!(sum.is_finite());
    }
    let (run, stand, step) = (median(run_ns), median(stand_ns), median(step_ns));
    println!("FIFO tick, 6 axes, medians of {REPEATS} interleaved batches of {BATCH} ticks:");
    println!("| machine tick | ns |");
    println!("| --- | ---: |");
    println!("| 6 axes in a running FIFO group (PT-2 override) | {run:.0} |");
    println!("| the same 6 axes standing, no group (baseline) | {stand:.0} |");
    println!("| extra per group-tick | {:.0} |", run - stand);
    println!("| set-point step alone (generator + override filter) | {step:.0} |");
    println!(
        "TARGET | FIFO group <= 500 ns extra per group-tick | {:.0} ns over standing axes | {}",
        run - stand,
        if run - stand <= 500.0 {
            "met"
        } else {
            "MISSED"
        }
    );
}

/// The child: sends `BLOCKS` blocks, prints the elapsed ns.
fn client(instance: &str) {
    let mut client = AcyclicClient::open(instance).expect("client");
    let header = rows_header(0, N as u32, BLOCK_ROWS as u32, false);
    let mut rows = vec![0.0; BLOCK_ROWS * N];
    let start = Instant::now();
    for b in 0..scaled(BLOCKS) {
        let mut loan = client.loan_rows(header, BLOCK_ROWS * N).expect("loan");
        for (i, v) in rows.iter_mut().enumerate() {
            *v = (b * BLOCK_ROWS * N + i) as f64 * 1e-6;
        }
        loan.write(0, &rows);
        let pending = loan.send().expect("send");
        loop {
            match pending.poll::<FifoReply>() {
                Some(Ok(reply)) => {
                    assert_eq!(reply.error_id, 0, "block {b}: {reply:?}");
                    break;
                }
                Some(Err(e)) => panic!("block {b}: {e}"),
                None => std::hint::spin_loop(),
            }
        }
    }
    println!("{}", start.elapsed().as_nanos());
}

/// One run: the child sends, this process answers with `engine` or the baseline.
fn transfer(engine: bool, run: usize) -> f64 {
    let instance = format!("fifo-bench-{}-{run}", std::process::id());
    let server = AcyclicServer::open(&instance).expect("server");
    let (mut machine, _memory) = machine(1 << 20);
    let mut child = Command::new(std::env::current_exe().expect("exe"))
        .env("FIFO_BENCH_CLIENT", &instance)
        .stdout(Stdio::piped())
        .spawn()
        .expect("child");
    let mut answered = 0;
    let mut seen = 0.0;
    while answered < scaled(BLOCKS) {
        answered += if engine {
            server
                .poll_rows(|_, h, v| machine.dispatch_bulk(h, v))
                .expect("poll")
        } else {
            server
                .poll_rows(|_, _, v| {
                    seen += v[0];
                    hli::calls::reply(&FifoReply {
                        row: BLOCK_ROWS as u32,
                        ..FifoReply::default()
                    })
                })
                .expect("poll")
        };
        if answered < scaled(BLOCKS) {
            std::hint::spin_loop();
        }
        if let Ok(Some(status)) = child.try_wait() {
            assert!(status.success(), "the client failed");
            break;
        }
    }
    let mut line = String::new();
    BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut line)
        .expect("line");
    let _ = child.wait();
    assert!(seen.is_finite());
    let ns: f64 = line.trim().parse().expect("ns");
    (scaled(BLOCKS) * BLOCK_ROWS) as f64 / (ns * 1e-9)
}

fn throughput() {
    let mut with_engine = Vec::new();
    let mut baseline = Vec::new();
    for run in 0..5 {
        with_engine.push(transfer(true, 2 * run));
        baseline.push(transfer(false, 2 * run + 1));
    }
    let (e, b) = (median(with_engine), median(baseline));
    println!();
    println!(
        "Rows across processes: {} rows x {N} axes in blocks of {BLOCK_ROWS}, medians of 5 interleaved runs:",
        scaled(BLOCKS) * BLOCK_ROWS
    );
    println!("| receiver | rows/s | MB/s |");
    println!("| --- | ---: | ---: |");
    println!(
        "| FIFO engine (checked, queued) | {e:.0} | {:.0} |",
        e * 48.0 / 1e6
    );
    println!(
        "| reads one value (transport only) | {b:.0} | {:.0} |",
        b * 48.0 / 1e6
    );
    println!("engine / transport: {:.2}", e / b);
    println!(
        "TARGET | FIFO rows across processes >= 1,000,000 rows/s | {e:.0} rows/s | {}",
        if e >= 1e6 { "met" } else { "MISSED" }
    );
}

fn main() {
    hli_transport::init_logging();
    if let Ok(instance) = std::env::var("FIFO_BENCH_CLIENT") {
        client(&instance);
        return;
    }
    tick_cost();
    throughput();
}
