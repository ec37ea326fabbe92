//! The demo machine's PLC program in Structured Text against the same program in Rust, whole
//! process against whole process: `cnc demo --lockstep --st` and `cnc demo --lockstep` (the
//! same machine, the same 14.5 s, the same lockstep trace; the PLC a process of its own), in
//! interleaved rounds. The figure is the PLC task's duration per cycle as the PLC process
//! reports it (the mean, and the p99 in whole us, over all cycles of a run: the runtime's
//! cycle with the program, its blocks and the image's handshakes), the median over the
//! rounds. Target: ST <= 3x (the means).
//! Run: `cargo bench -p cnc-app --bench demo_st` (`DEMO_ST_ROUNDS` sets the rounds, 5).

use bench_kit::{median, smoke};
use std::process::Command;

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
}
