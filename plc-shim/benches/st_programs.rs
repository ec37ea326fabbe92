//! The manuals' PLC programs in Structured Text against the same programs in Rust, on the
//! same image, cycle for cycle: the PLC-only turntable of seed 003's example 4 (the ST file
//! of `scenarios/example4-turntable-plc`, the Rust `programs::turntable`) while tracking is
//! ACTIVE: each cycle reads the table's angle and commands the frame (the CNC's side, taking
//! the command, is done between cycles and not counted). Target: ST <= 3x Rust.
//! Each figure is the median of 21 interleaved repeats of whole PLC cycles (the runtime's
//! `PlcProgram::cycle`, the ST runtime's clock and library host included).
//! Run: `cargo bench -p plc-shim --bench st_programs`.

use bench_kit::{median, scaled};
use hli::access::{Leaf, Value};
use hli::views::PlcView;
use hli_transport::rpc::{AcyclicClient, AcyclicServer};
use plc_shim::programs::turntable::{Turntable, Variant};
use plc_shim::runtime::{Link, PlcIo, PlcProgram};
use plc_shim::st::StProgram;
use std::hint::black_box;
use std::time::Instant;

const REPEATS: usize = 21;
const STATE: &str = "gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state";
const SEMAPHORE: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_semaphore_rw";
const ROTATION: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_w.rotation[2]";
const TABLE: &str = "gpAx[6]^lr_state.current_position_acs_r";

/// `cycles` PLC cycles of `program` (none with `None`: the stand-in CNC's part alone), the
/// CNC taking each command between them: us per cycle, the whole loop timed.
fn run(
    mut program: Option<&mut dyn PlcProgram>,
    image: &hli::ImageMemory,
    client: &mut AcyclicClient,
    cycles: usize,
) -> f64 {
    let (semaphore, table) = (
        Leaf::resolve(SEMAPHORE).unwrap(),
        Leaf::resolve(TABLE).unwrap(),
    );
    let t = Instant::now();
    for k in 0..cycles {
        semaphore.write(image, Value::Unsigned(0));
        table.write(image, Value::Int(k as i64 % 3_600_000));
        let mut io = PlcIo {
            view: PlcView::new(image),
            memory: image,
            acyclic: client,
            cycle: k as u64,
            link: Link::Operational,
        };
        if let Some(p) = program.as_deref_mut() {
            p.cycle(&mut io);
        }
        black_box(&io);
    }
    t.elapsed().as_secs_f64() * 1e6 / cycles as f64
}

fn main() {
    let instance = format!("bench-st-programs-{}", std::process::id());
    let _server = AcyclicServer::open(&instance).expect("a stand-in CNC");
    let mut client = AcyclicClient::open(&instance).expect("the PLC's client");
    let image = hli::image::heap_image(1, 7);
    Leaf::resolve(STATE)
        .unwrap()
        .write(&image, Value::Unsigned(2));
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenarios/example4-turntable-plc/plc.st"
    );
    let mut st = StProgram::load(&[path.into()], 1).expect("the turntable in ST");
    let mut rust = Turntable::on(Variant::PlcOnly, 0, 6);
    let cycles = scaled(20_000);
    let (mut st_us, mut rust_us, mut cnc_us) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..REPEATS {
        cnc_us.push(run(None, &image, &mut client, cycles));
        st_us.push(run(Some(&mut st), &image, &mut client, cycles));
        let st_rotation = Leaf::resolve(ROTATION).unwrap().read(&image);
        rust_us.push(run(Some(&mut rust), &image, &mut client, cycles));
        let rust_rotation = Leaf::resolve(ROTATION).unwrap().read(&image);
        assert_eq!(st_rotation, rust_rotation, "both command the same frame");
    }
    let cnc = median(cnc_us);
    let (st, rust) = (median(st_us) - cnc, median(rust_us) - cnc);
    println!("| turntable (PLC-only), one PLC cycle, the stand-in CNC's part taken off | us |");
    println!("| --- | ---: |");
    println!("| Structured Text | {st:.3} |");
    println!("| Rust (baseline) | {rust:.3} |");
    println!("| (the stand-in CNC's part, in both) | {cnc:.3} |");
    let ratio = st / rust;
    let verdict = if ratio <= 3.0 { "met" } else { "missed" };
    println!(
        "TARGET | turntable program: ST cycle <= 3x the Rust program's | {st:.3} us against {rust:.3} us ({ratio:.1}x) | {verdict}"
    );
}
