//! The demo machine's PLC program in Structured Text against the same program in Rust, whole
//! process against whole process: `cnc demo --lockstep --st` and `cnc demo --lockstep` (the
//! same machine, the same 14.5 s, the same lockstep trace; the PLC a process of its own), in
//! interleaved rounds. The figure is the PLC task's duration per cycle as the PLC process
//! reports it (the mean, and the p99 in whole us, over all cycles of a run: the runtime's
//! cycle with the program, its blocks and the image's handshakes), the median over the
//! rounds. Target: ST <= 3x (the means).
//! Beside it, in one process (the machine on a heap image, the PLC program run after each
//! tick as `cnc run --lockstep` runs it, the calls answered between): the program's cycle
//! alone, timed around each call (two clock readings included in both), the sum over the run
//! per cycle, the median of interleaved rounds. The whole-process figure holds what the
//! in-process one leaves out: a PLC woken once per tick starts with caches the CNC used.
//! Run: `cargo bench -p cnc-app --bench demo_st` (`DEMO_ST_ROUNDS` sets the rounds, 5).

use bench_kit::{median, smoke};
use cnc_app::scenario::machine::{BuiltIn, InProcess};
use std::process::Command;
use std::time::{Duration, Instant};

/// The mean and the p99 of the PLC task (us) of one `cnc demo --lockstep` run, `--st` with `st`.
fn run(st: bool, round: usize) -> (f64, f64) {
    let out_dir =
        std::env::temp_dir().join(format!("demo-st-bench-{}-{round}", std::process::id()));
    let mut c = Command::new(env!("CARGO_BIN_EXE_cnc"));
    c.args(["demo", "--lockstep", "--out"]).arg(&out_dir).args([
        "--instance",
        &format!("demo-st-bench-{}-{round}-{st}", std::process::id()),
    ]);
    if st {
        c.arg("--st");
    }
    if smoke() {
        c.args(["--ticks", "2000"]);
    }
    let out = c.output().expect("cnc demo");
    let _ = std::fs::remove_dir_all(&out_dir);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "cnc demo failed: {text}");
    // "PLC task: 14500 cycles, duration p50 12 us p99 20 us max 90.1 us mean 11.52 us, .."
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("PLC task: "))
        .expect("the PLC task's line");
    let after = |key: &str| -> f64 {
        let rest = &line[line.find(key).expect(key) + key.len()..];
        let number: String = rest
            .trim_start()
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '.')
            .collect();
        number.parse().expect("a number")
    };
    (after("mean"), after("p99"))
}

/// The mean of the PLC program's cycle (us) over the demo run in one process, the ST
/// program with `st`, and the saw's and lifter's last set-points (the runs must agree).
fn in_process(st: bool) -> (f64, [u64; 2]) {
    let scenario = cnc_app::demo::scenario().expect("the demo");
    let ticks = if smoke() {
        2000
    } else {
        scenario.ticks.unwrap_or(0) as usize
    };
    let mut run = InProcess::new(&scenario, 1).expect("in process");
    if st {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios/demo/plc.st");
        let program = plc_shim::st::StProgram::load(&[path.into()], 1).expect("plc.st");
        run.program = Some(BuiltIn(Box::new(program)));
    }
    let mut spent = Duration::ZERO;
    for _ in 0..ticks {
        run.machine.tick(&run.memory);
        run.answer_calls();
        let t = Instant::now();
        run.run_program();
        spent += t.elapsed();
        run.machine.serve_channels();
    }
    let leaf = |p: &str| {
        let v = hli::access::Leaf::resolve(p).expect(p).read(&run.memory);
        v.as_f64().to_bits()
    };
    let ends = [
        leaf("gpAx[28]^lr_state.command_position_acs_r"),
        leaf("gpAx[26]^lr_state.command_position_acs_r"),
    ];
    (spent.as_secs_f64() * 1e6 / ticks.max(1) as f64, ends)
}

fn main() {
    let rounds = std::env::var("DEMO_ST_ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(if smoke() { 1 } else { 5 });
    let (mut rust, mut st) = ((Vec::new(), Vec::new()), (Vec::new(), Vec::new()));
    for round in 0..rounds {
        let (p50, p99) = run(false, round);
        rust.0.push(p50);
        rust.1.push(p99);
        let (p50, p99) = run(true, round);
        st.0.push(p50);
        st.1.push(p99);
    }
    let (r50, r99, s50, s99) = (median(rust.0), median(rust.1), median(st.0), median(st.1));
    println!("| demo machine's PLC task, per cycle ({rounds} rounds) | mean us | p99 us |");
    println!("| --- | ---: | ---: |");
    println!("| Structured Text (`cnc demo --st`) | {s50:.2} | {s99:.0} |");
    println!("| Rust (`cnc demo`, baseline) | {r50:.2} | {r99:.0} |");
    let ratio = s50 / r50;
    let verdict = if ratio <= 3.0 { "met" } else { "missed" };
    println!(
        "TARGET | demo machine's PLC program: ST task cycle <= 3x the Rust program's (mean) | {s50:.2} us against {r50:.2} us ({ratio:.1}x) | {verdict}"
    );
    let (mut rust, mut st) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        let (r, r_ends) = in_process(false);
        let (s, s_ends) = in_process(true);
        assert_eq!(r_ends, s_ends, "both programs end the machine alike");
        rust.push(r);
        st.push(s);
    }
    let (r, s) = (median(rust), median(st));
    println!();
    println!(
        "| demo machine's PLC program in one process, per cycle ({rounds} rounds) | mean us |"
    );
    println!("| --- | ---: |");
    println!("| Structured Text | {s:.3} |");
    println!("| Rust (baseline) | {r:.3} |");
    println!("(in one process: {:.1}x)", s / r);
}
