//! `cnc check` against LinuxCNC's `rs274 -g`, whole process against whole process: the same
//! 100,000-block program (lines and arcs, centre and radius forms), each program started, run
//! and waited for, in interleaved rounds; medians, the ratio taken per round, and each
//! process's peak memory (its maximum resident set, `cnc_os::wait_with_peak_memory`). rs274 is skipped, and the
//! report says so, when it is not installed (Debian package `linuxcnc-uspace`).
//!
//! Three of ours: `cnc check FILE` (parse, run and check every block; prints nothing for a
//! clean program), `cnc check --blocks FILE` (also prints every motion block as a JSON line,
//! the counterpart of rs274 printing its canonical calls), both to /dev/null like rs274's
//! output. The in-process figure (parse + decode without the process) is `benches/nc_parse.rs`.
//!
//! Run: `cargo bench -p cnc-app --bench nc_check` (`NC_CHECK_ROUNDS` sets the rounds, 9).

use bench_kit::median;
use std::process::{Command, Stdio};
use std::time::Instant;

const BLOCKS: usize = 100_000;

/// The program's body: three lines, then an arc, by turns (a centre-form half circle or a
/// radius-form arc), written the same for both interpreters.
fn body() -> String {
    let mut s = String::with_capacity(BLOCKS * 48);
    let mut seed = 0x1234_5678_9abc_def0u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f64 / (1u64 << 24) as f64
    };
    let (mut x, mut y) = (0.0f64, 0.0f64);
    for i in 0..BLOCKS {
        let n = (i + 1) * 10;
        match i % 8 {
            3 => {
                let r = (1.0 + next() * 49.0) * 1000.0;
                let r = r.round() / 1000.0;
                x += 2.0 * r;
                s.push_str(&format!("N{n} G3 X{x:.3} Y{y:.3} I{r:.3} J0 F800\n"));
            }
            7 => {
                let r = ((5.0 + next() * 45.0) * 1000.0).round() / 1000.0;
                x += r;
                s.push_str(&format!("N{n} G2 X{x:.3} Y{y:.3} R{r:.3} F800\n"));
            }
            _ => {
                x = (next() * 500_000.0).round() / 1000.0;
                y = (next() * 500_000.0 - 250_000.0).round() / 1000.0;
                let z = (next() * 100_000.0).round() / 1000.0;
                s.push_str(&format!(
                    "N{n} G1 X{x:.3} Y{y:.3} Z{z:.3} F{}\n",
                    500 + (i % 7) * 100
                ));
            }
        }
    }
    s
}

/// Runs `cmd` to its end; wall time (s) and peak resident memory (KiB).
fn run(cmd: &mut Command) -> (f64, i64) {
    let t0 = Instant::now();
    let child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start the program");
    let (success, peak) = cnc_os::wait_with_peak_memory(child).expect("wait4");
    let elapsed = t0.elapsed().as_secs_f64();
    assert!(success, "{cmd:?} failed");
    (elapsed, peak)
}

fn main() {
    let rounds: usize = std::env::var("NC_CHECK_ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        // CNC_BENCH_SMOKE=1 (CI): one round, to show the bench runs; no figure is meant.
        .unwrap_or(
            if std::env::var("CNC_BENCH_SMOKE").is_ok_and(|v| v == "1") {
                1
            } else {
                9
            },
        );
    let body = body();
    let dir = std::env::temp_dir();
    let ours = dir.join(format!("nc-check-{}.nc", std::process::id()));
    let theirs = dir.join(format!("nc-check-{}.ngc", std::process::id()));
    std::fs::write(&ours, format!("G17 G90\n{body}M30\n")).unwrap();
    std::fs::write(&theirs, format!("G21 G17 G90 G94 G91.1\n{body}M2\n")).unwrap();
    let cnc = env!("CARGO_BIN_EXE_cnc");
    let have_rs274 = Command::new("rs274")
        .arg("-g")
        .arg("/dev/null")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok();
    let check = || {
        let mut c = Command::new(cnc);
        c.args(["check", "--axes", "X,Y,Z"]).arg(&ours);
        c
    };
    let blocks = || {
        let mut c = Command::new(cnc);
        c.args(["check", "--blocks", "--axes", "X,Y,Z"]).arg(&ours);
        c
    };
    let peer = || {
        let mut c = Command::new("rs274");
        c.arg("-g").arg(&theirs);
        c
    };
    // A warm-up of each: the files in the page cache, the binaries loaded once.
    run(&mut check());
    run(&mut blocks());
    if have_rs274 {
        run(&mut peer());
    }
    let (mut t_check, mut t_blocks, mut t_peer) = (Vec::new(), Vec::new(), Vec::new());
    let (mut r_check, mut r_blocks) = (Vec::new(), Vec::new());
    let (mut m_check, mut m_blocks, mut m_peer) = (0i64, 0i64, 0i64);
    for _ in 0..rounds {
        let (a, ma) = run(&mut check());
        let (b, mb) = run(&mut blocks());
        t_check.push(a);
        t_blocks.push(b);
        m_check = m_check.max(ma);
        m_blocks = m_blocks.max(mb);
        if have_rs274 {
            let (c, mc) = run(&mut peer());
            t_peer.push(c);
            m_peer = m_peer.max(mc);
            r_check.push(c / a);
            r_blocks.push(c / b);
        }
    }
    let _ = std::fs::remove_file(&ours);
    let _ = std::fs::remove_file(&theirs);
    println!(
        "program: {BLOCKS} blocks (3 lines G1, then a G3 centre-form or G2 radius-form arc, by turns), {} bytes; {rounds} interleaved rounds, whole processes",
        body.len()
    );
    println!("| process | median s | blocks/s | peak memory MiB |\n|---|---:|---:|---:|");
    let row = |name: &str, t: &[f64], m: i64| {
        let med = median(t.to_vec());
        println!(
            "| {name} | {med:.4} | {:.0} | {:.1} |",
            BLOCKS as f64 / med,
            m as f64 / 1024.0
        );
    };
    row("cnc check", &t_check, m_check);
    row("cnc check --blocks (to /dev/null)", &t_blocks, m_blocks);
    if have_rs274 {
        row("rs274 -g (to /dev/null)", &t_peer, m_peer);
        let (rc, rb) = (median(r_check.clone()), median(r_blocks.clone()));
        let lo = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = |v: &[f64]| v.iter().copied().fold(0.0f64, f64::max);
        println!(
            "TARGET | cnc check >= 20x faster than rs274 (whole processes) | median {rc:.1}x (min {:.1}x, max {:.1}x) | {}",
            lo(&r_check),
            hi(&r_check),
            if rc >= 20.0 { "met" } else { "MISSED" }
        );
        println!(
            "TARGET | cnc check --blocks >= 10x faster than rs274 | median {rb:.1}x (min {:.1}x, max {:.1}x) | {}",
            lo(&r_blocks),
            hi(&r_blocks),
            if rb >= 10.0 { "met" } else { "MISSED" }
        );
        println!(
            "TARGET | peak memory no more than rs274 | cnc check {:.1} MiB, rs274 {:.1} MiB | {}",
            m_check as f64 / 1024.0,
            m_peer as f64 / 1024.0,
            if m_check <= m_peer && m_blocks <= m_peer {
                "met"
            } else {
                "MISSED"
            }
        );
    } else {
        println!("rs274 is not installed (apt-get install linuxcnc-uspace): no comparison");
        for what in [
            "cnc check >= 20x faster than rs274 (whole processes)",
            "cnc check --blocks >= 10x faster than rs274",
            "peak memory no more than rs274",
        ] {
            println!("TARGET | {what} | - | skipped: rs274 not installed");
        }
    }
    let rate = BLOCKS as f64 / median(t_check);
    println!(
        "TARGET | cnc check >= 2,000,000 blocks/s (whole process) | {rate:.0} | {}",
        if rate >= 2e6 { "met" } else { "MISSED" }
    );
}
