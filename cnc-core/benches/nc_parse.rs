//! Parse + decode of a generated 100,000-block program, against LinuxCNC's standalone
//! interpreter `rs274 -g` on the same file in the same run (skipped, and said so, when `rs274`
//! is not installed; Debian package `linuxcnc-uspace`).
//!
//! Run: `cargo bench -p cnc-core --bench nc_parse`. Reports medians over repeats.
//!
//! Ours is timed twice. **Cold**: each parse in a fresh process (this bench started again as a
//! child), as `cnc check` meets a program and as rs274 runs, with fresh memory to fault in.
//! **Warm**: parses repeated in one process, where the allocator hands back the memory of the
//! tree dropped before (a controller loading programs again and again). The comparison with
//! rs274 and the targets use the cold time.

use bench_kit::median;
use cnc_core::nc::decode::ZeroVars;
use cnc_core::nc::{parse, Decoded, DecoderState};
use std::hint::black_box;
use std::process::{Command, Stdio};
use std::time::Instant;

const BLOCKS: usize = 100_000;

fn program() -> String {
    let mut s = String::with_capacity(BLOCKS * 48);
    let mut seed = 0x1234_5678_9abc_def0u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f64 / (1u64 << 24) as f64
    };
    for i in 0..BLOCKS {
        s.push_str(&format!(
            "N{} G1 X{:.3} Y{:.3} Z{:.3} F{}\n",
            (i + 1) * 10,
            next() * 500.0,
            next() * 500.0 - 250.0,
            next() * 100.0,
            500 + (i % 7) * 100
        ));
    }
    s.push_str("M2\n");
    s
}

/// Parses the program, then decodes it block by block into a reused buffer, the way a channel
/// consumes it (and the way rs274 interprets: block after block, nothing kept).
/// Returns the whole time and the part spent parsing.
fn parse_and_decode(src: &str, axes: &[String]) -> (f64, f64) {
    let t0 = Instant::now();
    let (tree, diags) = parse(black_box(src));
    let parsed = t0.elapsed().as_secs_f64();
    let mut decoder = DecoderState::new(axes);
    let mut out = Vec::with_capacity(8);
    let mut motions = 0usize;
    for index in 0..tree.blocks.len() {
        out.clear();
        let semantic = decoder.decode_block_unlocated(&tree, index, src, &ZeroVars, &mut out);
        assert!(semantic.is_empty());
        motions += out
            .iter()
            .filter(|d| matches!(d, Decoded::Motion(_)))
            .count();
        black_box(&out);
    }
    let elapsed = t0.elapsed().as_secs_f64();
    assert!(diags.is_empty());
    assert_eq!(motions, BLOCKS);
    (elapsed, parsed)
}

fn run_rs274(path: &std::path::Path) -> f64 {
    let t0 = Instant::now();
    let status = Command::new("rs274")
        .arg("-g")
        .arg(path)
        .arg("/dev/null")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .expect("run rs274");
    assert!(status.success(), "rs274 failed on the program");
    t0.elapsed().as_secs_f64()
}

/// In a child (`NC_BENCH_CHILD=<program file>`): one parse + decode of the file, its times
/// printed as `elapsed parsed` on stdout.
fn child(path: &str) {
    let src = std::fs::read_to_string(path).expect("read the program");
    let axes: Vec<String> = ["X", "Y", "Z", "A", "B", "C"].map(String::from).to_vec();
    let (elapsed, parsed) = parse_and_decode(&src, &axes);
    println!("{elapsed} {parsed}");
}

/// One cold parse + decode: this bench again, as a fresh process.
fn cold_parse_and_decode(path: &std::path::Path) -> (f64, f64) {
    let exe = std::env::current_exe().expect("own path");
    let out = Command::new(exe)
        .env("NC_BENCH_CHILD", path)
        .stdin(Stdio::null())
        .stderr(Stdio::inherit())
        .output()
        .expect("run the bench as a child");
    assert!(out.status.success(), "the child parse failed");
    let text = String::from_utf8_lossy(&out.stdout);
    let mut times = text
        .split_whitespace()
        .map(|t| t.parse::<f64>().expect("a time"));
    let elapsed = times.next().expect("elapsed");
    let parsed = times.next().expect("parse time");
    (elapsed, parsed)
}

fn best((a, a_parsed): (f64, f64), (b, b_parsed): (f64, f64)) -> (f64, f64) {
    if a <= b {
        (a, a_parsed)
    } else {
        (b, b_parsed)
    }
}

fn main() {
    // As the `cnc` binary does: the tree's arenas in huge pages.
    cnc_core::nc::set_buffer_advice(|p| {
        cnc_os::advise_huge_pages(&mut p.blocks);
        cnc_os::advise_huge_pages(&mut p.items);
    });
    if let Some(path) = std::env::var_os("NC_BENCH_CHILD") {
        child(&path.to_string_lossy());
        return;
    }
    // NC_BENCH_ROUNDS=1 runs one round of one parse each (for profilers: callgrind, perf; the
    // warm parse is the one in this process). NC_BENCH_CHILD=<file> parses one file, cold.
    let rounds: usize = std::env::var("NC_BENCH_ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        // CNC_BENCH_SMOKE=1 (CI): one round, to show the bench runs; no figure is meant.
        .unwrap_or(
            if std::env::var("CNC_BENCH_SMOKE").is_ok_and(|v| v == "1") {
                1
            } else {
                7
            },
        );
    let tries = if rounds == 1 { 1 } else { 3 };
    let src = program();
    let axes: Vec<String> = ["X", "Y", "Z", "A", "B", "C"].map(String::from).to_vec();
    let path = std::env::temp_dir().join(format!("nc-bench-{}.ngc", std::process::id()));
    std::fs::write(&path, &src).unwrap();
    // NC_BENCH_SKIP_PEER=1 times ours alone (for quick iterations; the report says so).
    let skip_peer = std::env::var_os("NC_BENCH_SKIP_PEER").is_some();
    let have_rs274 = !skip_peer
        && Command::new("rs274")
            .arg("-h")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok();

    // Interleaved rounds: each round times ours cold (best of 3 fresh processes), ours warm
    // (best of 3 in this process) and, where present, rs274 once, so all see the same
    // machine state; the ratio is taken per round, cold against rs274.
    let (mut ours, mut warm, mut theirs, mut ratios) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut parse_shares = Vec::new();
    for _ in 0..rounds {
        let (mine, parsed) = (0..tries)
            .map(|_| cold_parse_and_decode(&path))
            .fold((f64::INFINITY, 0.0), best);
        ours.push(mine);
        parse_shares.push(parsed / mine);
        let (mine_warm, _) = (0..tries)
            .map(|_| parse_and_decode(&src, &axes))
            .fold((f64::INFINITY, 0.0), best);
        warm.push(mine_warm);
        if have_rs274 {
            let peer = run_rs274(&path);
            theirs.push(peer);
            ratios.push(peer / mine);
        }
    }
    let _ = std::fs::remove_file(&path);
    let ours_best = ours.iter().copied().fold(f64::INFINITY, f64::min);
    let ours_median = median(ours);
    let rate = BLOCKS as f64 / ours_median;
    let verdict = |ok: bool| if ok { "met" } else { "MISSED" };
    println!(
        "program: {BLOCKS} blocks `N.. G1 X.. Y.. Z.. F..`, {} bytes; {rounds} interleaved rounds",
        src.len()
    );
    let warm_median = median(warm);
    println!("| interpreter | median s | blocks/s |\n|---|---:|---:|");
    println!("| cnc-core parse + decode, cold (fresh process) | {ours_median:.4} | {rate:.0} |");
    println!(
        "| cnc-core parse + decode, warm (repeated in one process) | {warm_median:.4} | {:.0} |",
        BLOCKS as f64 / warm_median
    );
    let parse_share = median(parse_shares);
    println!(
        "fastest cold round: {ours_best:.4} s, {:.0} blocks/s",
        BLOCKS as f64 / ours_best
    );
    if have_rs274 {
        let theirs_median = median(theirs);
        let ratio = median(ratios.clone());
        println!(
            "| LinuxCNC rs274 -g | {theirs_median:.4} | {:.0} |",
            BLOCKS as f64 / theirs_median
        );
        let mut sorted = ratios;
        sorted.sort_by(f64::total_cmp);
        println!(
            "per-round time ratio rs274 / ours: median {ratio:.1}x (min {:.1}x, max {:.1}x)",
            sorted[0],
            sorted[sorted.len() - 1]
        );
        println!(
            "TARGET | parse + decode >= 20x faster than LinuxCNC rs274 | {ratio:.1}x | {}",
            verdict(ratio >= 20.0)
        );
    } else if skip_peer {
        println!("rs274 skipped (NC_BENCH_SKIP_PEER is set)");
        println!("TARGET | parse + decode >= 20x faster than LinuxCNC rs274 | - | skipped: NC_BENCH_SKIP_PEER is set");
    } else {
        println!("rs274 not installed (Debian package linuxcnc-uspace): comparison skipped");
        println!("TARGET | parse + decode >= 20x faster than LinuxCNC rs274 | - | skipped: rs274 not installed");
    }
    println!(
        "TARGET | parse + decode >= 2 million blocks/s (cold process) | {:.2} M | {}",
        rate / 1e6,
        verdict(rate >= 2e6)
    );
    println!(
        "of our time, parsing (source to tree) takes {:.0}%, decoding the rest",
        parse_share * 100.0
    );
}
