//! How late the CNC's tick starts after its deadline, whole process against whole process, on
//! the whole demo machine (`scenarios/demo`: four robots, cams, the saw, its PLC process)
//! and on example 4 alone, each with the real-time options (SCHED_FIFO 80, locked memory,
//! timer slack 1 ns, CPU wake-up latency 0 as cyclictest holds it; the PLC process at
//! SCHED_FIFO 79) and on the default scheduler, beside
//! `cyclictest -m -i 1000` (rt-tests) with `-p 80`, and without a priority with `--laptop`
//! (no wake-up latency request either: like `cnc run` without options), in the same run. Interleaved
//! rounds; per round p50/p99 of the start lateness, the tick compute p99/p50 and the PLC's
//! overruns; medians over rounds; the ratios the targets are stated in. The lateness is the
//! time from the absolute deadline to the first instruction of the tick. A peer that is
//! absent is skipped and said so. `CNC_BENCH_SMOKE=1`: one short round (CI: no timing
//! asserted). Run: `cargo bench -p cnc-app --bench tick_latency`.
//!
//! At 250 µs, example 4 and the demo each run twice per round: with the default wake path
//! (the event) and with `--rt-wake spin --rt-cpu 1` (the PLC spins for its ticks on CPU 0,
//! beside the CNC's thread on CPU 1), the latter against `cyclictest -a 1` on the same CPU;
//! both against cyclictest's loops late by a whole cycle (issue 55's overrun target). The
//! pinned rows need two CPUs and are skipped, and said so, with one.
//!
//! Beside them, the floor of any two-task design at 250 µs: a timer task at SCHED_FIFO 80
//! that wakes a second task at 79 by futex for every slot, with no work, counting the slots
//! the second misses as the PLC counts its overruns (`two_task_chain`).
//!
//! The compute target's baseline is a constant job in the same shape as the demo: this bench
//! started again as two processes ([`peer`]), one at SCHED_FIFO 80 that wakes every 1 ms at an
//! absolute deadline and runs the same pass over 512 KiB each time (timed as the CNC times its
//! tick), and one at SCHED_FIFO 79 that wakes every 1 ms for the same pass over its own
//! memory (the PLC's place).
//! Whatever spreads the constant job's time (cold caches after the sleep, the VM, the other
//! process) spreads the tick's too: its p99/p50 is what this machine allows.

use bench_kit::{median, smoke};
use std::path::{Path, PathBuf};
use std::process::Command;

/// One run's figures: start lateness p50/p99 (us), compute p50/p99 (us), PLC overruns.
#[derive(Debug, Clone, Copy, Default)]
struct Figures {
    late: (f64, f64),
    compute: (f64, f64),
    plc_overruns: f64,
}

fn scenario(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios")
        .join(name)
        .join("scenario.toml")
}

/// The number after `key` in `text`'s line that holds `anchor`.
fn number(text: &str, anchor: &str, key: &str) -> Option<f64> {
    let line = text.lines().find(|l| l.contains(anchor))?;
    let rest = &line[line.find(anchor)?..];
    let at = rest.find(key)? + key.len();
    rest[at..]
        .trim_start()
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .next()?
        .parse()
        .ok()
}

/// `cnc run` of `path` for `ticks` of `cycle_us`, with the real-time options when `rt`.
fn cnc(path: &Path, ticks: u64, rt: bool, cycle_us: u32, extra: &[&str]) -> Option<Figures> {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cnc"));
    c.args(["run", path.to_str()?, "--ticks", &ticks.to_string()]);
    c.args(["--cycle-ms", &(f64::from(cycle_us) / 1000.0).to_string()]);
    c.args([
        "--instance",
        &format!("bench-latency-{}", std::process::id()),
    ]);
    if rt {
        c.args(plc_shim::realtime::RealtimeOptions::measured().to_args());
    }
    c.args(extra);
    let out = c.output().ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    if rt && extra.contains(&"--rt-cpu") && cycle_us < 1000 {
        let plc = text.lines().find(|l| l.starts_with("plc: real-time "));
        assert!(
            plc.is_some_and(
                |l| l.contains("CPU 0") && l.contains("wake-up by a timed sleep and a spin")
            ),
            "the PLC spins for its ticks on CPU 0: {text}"
        );
    }
    let ns = |anchor: &str, key: &str| number(&text, anchor, key).map(|v| v / 1000.0);
    Some(Figures {
        late: (ns("start lateness", "p50 ")?, ns("start lateness", "p99 ")?),
        compute: (ns("tick compute", "p50 ")?, ns("tick compute", "p99 ")?),
        plc_overruns: number(&text, "plc: task", "overruns ").unwrap_or(f64::NAN),
    })
}

/// (p50, p99) latency in us from cyclictest's histogram (every `interval_us`), `None`
/// when it is not installed.
fn cyclictest(loops: u64, rt: bool, interval_us: u32, cpu: Option<u32>) -> Option<Figures> {
    let mut c = Command::new("cyclictest");
    c.args([
        "-m",
        "-i",
        &interval_us.to_string(),
        "-l",
        &loops.to_string(),
        "-q",
        "-h",
        "10000",
    ]);
    if let Some(cpu) = cpu {
        c.args(["-a", &cpu.to_string()]);
    }
    if rt {
        c.args(["-p", "80"]);
    } else {
        // Without options, like `cnc run` without them: cyclictest otherwise holds the CPUs'
        // wake-up latency at 0 (`/dev/cpu_dma_latency`) even without a priority.
        c.arg("--laptop");
    }
    let out = c.output().ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let mut histogram: Vec<(f64, u64)> = Vec::new();
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let mut cells = line.split_whitespace();
        if let (Some(Ok(us)), Some(Ok(n))) = (
            cells.next().map(str::parse::<f64>),
            cells.next().map(str::parse::<u64>),
        ) {
            histogram.push((us, n));
        }
    }
    let total: u64 = histogram.iter().map(|h| h.1).sum();
    if total == 0 {
        return None;
    }
    let quantile = |q: f64| {
        let mut seen = 0;
        for (us, n) in &histogram {
            seen += n;
            if seen as f64 >= q * total as f64 {
                return *us;
            }
        }
        10_000.0
    };
    // Wake-ups later than a whole cycle: what makes a task of this cycle miss its slot on
    // this machine, whatever runs in it (shown in the overruns column).
    let overflows = text
        .lines()
        .find_map(|l| l.strip_prefix("# Histogram Overflows:"))
        .and_then(|v| v.split_whitespace().next()?.parse::<u64>().ok())
        .unwrap_or(0);
    let late_cycles = histogram
        .iter()
        .filter(|(us, _)| *us >= f64::from(interval_us))
        .map(|h| h.1)
        .sum::<u64>()
        + overflows;
    Some(Figures {
        late: (quantile(0.5), quantile(0.99)),
        plc_overruns: late_cycles as f64,
        ..Figures::default()
    })
}

/// The constant job: one pass over `memory` (a word of every cache line, read and written,
/// each step depending on the last): the same work every time, with a working set like the
/// demo machine's, so the caches' state after the sleep counts as it does for the tick.
fn constant_job(memory: &mut [u64]) -> u64 {
    let mut x = 0x9E37_79B9_7F4A_7C15_u64;
    for word in memory.iter_mut().step_by(8) {
        x = x.rotate_left(5) ^ *word;
        *word = x;
    }
    x
}

/// Words the constant job walks (512 KiB; the companion walks as much of its own).
const JOB_WORDS: usize = 64 * 1024;

/// The bench started again as a peer process (`TICK_LATENCY_PEER`): `constant LOOPS` (the
/// constant job every 1 ms at SCHED_FIFO 80; prints `constant p50 P p99 Q` in ns) or
/// `companion LOOPS` (a short job every 1 ms at SCHED_FIFO 79). `None`: not a peer.
fn peer() -> Option<()> {
    let mode = std::env::var("TICK_LATENCY_PEER").ok()?;
    let mut words = mode.split_whitespace();
    let (kind, loops) = (words.next()?, words.next()?.parse::<usize>().ok()?);
    let constant = kind != "companion";
    // As `cnc run` with the real-time options (the companion as its PLC, one below).
    let _ = cnc_os::realtime::set_fifo_priority(if constant { 80 } else { 79 });
    let _ = cnc_os::realtime::lock_memory();
    let _ = cnc_os::realtime::set_timer_slack(1);
    let _ = cnc_os::realtime::hold_cpu_wake_latency(0);
    if kind == "chain" {
        let us = words.next()?.parse::<u64>().ok()?;
        two_task_chain(loops, std::time::Duration::from_micros(us));
        return Some(());
    }
    let mut took = Vec::with_capacity(loops);
    let mut memory = vec![1u64; JOB_WORDS];
    let period = std::time::Duration::from_millis(1);
    let mut deadline = cnc_os::monotonic::now() + period;
    for _ in 0..loops {
        cnc_os::monotonic::sleep_until(deadline);
        let start = cnc_os::monotonic::now();
        std::hint::black_box(constant_job(&mut memory));
        took.push((cnc_os::monotonic::now() - start).as_nanos() as f64);
        deadline += period;
    }
    if constant {
        took.sort_by(f64::total_cmp);
        let at = |q: f64| took[((took.len() - 1) as f64 * q) as usize];
        println!("constant p50 {:.0} p99 {:.0}", at(0.5), at(0.99));
    }
    Some(())
}

/// The floor of a two-task design (the CNC's tick, then the PLC woken for it): a task at
/// SCHED_FIFO 80 that wakes at absolute deadlines every `interval`, raises a counter and
/// wakes a second task at 79 with one `futex(2)` call, the second counting the slots it
/// missed as the PLC counts its overruns (the counter moved by more than one between two of
/// its wake-ups). No work in either: what it misses is the machine's. Two threads of one
/// process (the same tasks to the scheduler as two processes); prints `chain misses N`.
fn two_task_chain(loops: usize, interval: std::time::Duration) {
    use std::sync::atomic::{AtomicU32, Ordering};
    let word = std::sync::Arc::new(AtomicU32::new(0));
    let second = {
        let word = std::sync::Arc::clone(&word);
        std::thread::spawn(move || {
            let _ = cnc_os::realtime::set_fifo_priority(79);
            let _ = cnc_os::realtime::set_timer_slack(1);
            let (mut seen, mut missed) = (0u32, 0u64);
            while (seen as usize) < loops {
                let now = word.load(Ordering::Acquire);
                if now == seen {
                    let _ = cnc_os::futex::wait(&word, seen, std::time::Duration::from_millis(100));
                    continue;
                }
                missed += u64::from(now - seen - 1);
                seen = now;
            }
            missed
        })
    };
    let mut deadline = cnc_os::monotonic::now() + interval;
    for k in 1..=loops {
        cnc_os::monotonic::sleep_until(deadline);
        word.store(k as u32, Ordering::Release);
        let _ = cnc_os::futex::wake(&word, 1);
        deadline += interval;
    }
    let missed = second.join().unwrap_or(u64::MAX);
    println!("chain misses {missed}");
}

/// The two-task chain at `interval_us` for `loops` slots: its missed slots (in the PLC
/// overruns column), `None` if the peer could not run.
fn chain(loops: u64, interval_us: u32) -> Option<Figures> {
    let out = Command::new(std::env::current_exe().ok()?)
        .env("TICK_LATENCY_PEER", format!("chain {loops} {interval_us}"))
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    Some(Figures {
        plc_overruns: number(&text, "chain", "misses ")?,
        ..Figures::default()
    })
}

/// The constant job beside its companion, both as processes of their own: its time p50/p99
/// (us), `None` if a peer could not run.
fn constant_work(loops: u64) -> Option<Figures> {
    let exe = std::env::current_exe().ok()?;
    let start = |kind: &str| {
        Command::new(&exe)
            .env("TICK_LATENCY_PEER", format!("{kind} {loops}"))
            .stdout(std::process::Stdio::piped())
            .spawn()
            .ok()
    };
    let companion = start("companion")?;
    let constant = start("constant")?.wait_with_output().ok()?;
    let _ = companion.wait_with_output();
    let text = String::from_utf8_lossy(&constant.stdout);
    let us = |key: &str| number(&text, "constant", key).map(|v| v / 1000.0);
    Some(Figures {
        compute: (us("p50 ")?, us("p99 ")?),
        ..Figures::default()
    })
}

fn main() {
    if peer().is_some() {
        return;
    }
    let (rounds, demo_ticks, ex4_ticks, fast_ticks) = if smoke() {
        (1, 300, 300, 300)
    } else {
        (5, 14_500, 5_000, 20_000)
    };
    let present = Command::new("cyclictest").arg("--help").output().is_ok();
    if !present {
        println!("cyclictest (rt-tests) is not installed: the peer is skipped (install rt-tests)");
    }
    let demo = scenario("demo");
    let ex4 = scenario("example4-turntable-plc");
    let names = [
        "cyclictest -m -p 80 -i 1000",
        "cyclictest -m -i 1000 (no priority)",
        "demo, real-time options",
        "demo, default scheduler",
        "example 4, real-time options",
        "example 4, default scheduler",
        "cyclictest -m -p 80 -i 250",
        "example 4 at 250 us, real-time options",
        "constant job every 1 ms beside a companion",
        "cyclictest -m -p 80 -a 1 -i 250",
        "example 4 at 250 us, RT, spin, CPU 1",
        "demo at 250 us, real-time options",
        "demo at 250 us, RT, spin, CPU 1",
        "two-task chain at 250 us (timer -> futex)",
    ];
    // The spinning PLC goes to another CPU than the CNC's: two are needed.
    let two_cpus = std::thread::available_parallelism().is_ok_and(|n| n.get() >= 2);
    // `cnc` checks that the PLC said it spun, on the other CPU.
    const SPIN: [&str; 4] = ["--rt-wake", "spin", "--rt-cpu", "1"];
    let mut rows: Vec<Vec<Figures>> = vec![Vec::new(); names.len()];
    for _ in 0..rounds {
        if present {
            rows[0].extend(cyclictest(demo_ticks, true, 1000, None));
            rows[1].extend(cyclictest(demo_ticks, false, 1000, None));
            rows[6].extend(cyclictest(fast_ticks, true, 250, None));
            if two_cpus {
                rows[9].extend(cyclictest(fast_ticks, true, 250, Some(1)));
            }
        }
        rows[2].extend(cnc(&demo, demo_ticks, true, 1000, &[]));
        rows[3].extend(cnc(&demo, demo_ticks, false, 1000, &[]));
        rows[4].extend(cnc(&ex4, ex4_ticks, true, 1000, &[]));
        rows[5].extend(cnc(&ex4, ex4_ticks, false, 1000, &[]));
        rows[7].extend(cnc(&ex4, fast_ticks, true, 250, &[]));
        rows[11].extend(cnc(&demo, fast_ticks, true, 250, &[]));
        if two_cpus {
            rows[10].extend(cnc(&ex4, fast_ticks, true, 250, &SPIN));
            rows[12].extend(cnc(&demo, fast_ticks, true, 250, &SPIN));
        }
        rows[8].extend(constant_work(demo_ticks));
        rows[13].extend(chain(fast_ticks, 250));
    }
    println!("tick start lateness (us), cycle 1 ms, medians of {rounds} interleaved rounds; demo {demo_ticks} ticks, example 4 {ex4_ticks}");
    println!(
        "{:<40} {:>8} {:>8} {:>12} {:>12} {:>13}",
        "", "p50", "p99", "compute p50", "compute p99", "PLC overruns"
    );
    let mut med = vec![None; names.len()];
    for (i, name) in names.iter().enumerate() {
        if rows[i].is_empty() {
            println!("{name:<40} {:>8}", "-");
            continue;
        }
        let m = |f: fn(&Figures) -> f64| median(rows[i].iter().map(f).collect());
        let f = Figures {
            late: (m(|r| r.late.0), m(|r| r.late.1)),
            compute: (m(|r| r.compute.0), m(|r| r.compute.1)),
            plc_overruns: m(|r| r.plc_overruns),
        };
        med[i] = Some(f);
        if i == 13 {
            println!(
                "{name:<40} {:>8} {:>8} {:>12} {:>12} {:>13.0}",
                "-", "-", "", "", f.plc_overruns
            );
        } else if i == 8 {
            println!(
                "{name:<40} {:>8} {:>8} {:>12.1} {:>12.1} {:>13}",
                "-", "-", f.compute.0, f.compute.1, "-"
            );
        } else if rows_of_cyclictest(i) {
            println!(
                "{name:<40} {:>8.1} {:>8.1} {:>12} {:>12} {:>13.0}",
                f.late.0, f.late.1, "", "", f.plc_overruns
            );
        } else {
            println!(
                "{name:<40} {:>8.1} {:>8.1} {:>12.1} {:>12.1} {:>13.0}",
                f.late.0, f.late.1, f.compute.0, f.compute.1, f.plc_overruns
            );
        }
    }
    targets(&med);
    if let (Some(job), Some(demo)) = (med[8], med[2]) {
        let (r, d) = (
            job.compute.1 / job.compute.0,
            demo.compute.1 / demo.compute.0,
        );
        println!(
            "the constant job's time p99/p50 on this machine: {r:.2} ({:.1} / {:.1} us); the demo tick's: {d:.2}",
            job.compute.1, job.compute.0
        );
    }
}

/// Rows 0, 1, 6 and 9 are cyclictest's (row 8, the constant job, has no lateness).
fn rows_of_cyclictest(i: usize) -> bool {
    matches!(i, 0 | 1 | 6 | 9)
}

/// One `TARGET` line per target, from the medians of the rows.
fn targets(med: &[Option<Figures>]) {
    let verdict = |ok: bool| match (smoke(), ok) {
        (true, _) => "smoke run, no figure meant",
        (false, true) => "met",
        (false, false) => "MISSED",
    };
    let lateness = |what: &str, ours: usize, peer: usize| match (med[ours], med[peer]) {
        (Some(a), Some(b)) => {
            let r = a.late.1 / b.late.1;
            println!(
                "TARGET | {what} | {r:.2} ({:.1} / {:.1} us) | {}",
                a.late.1,
                b.late.1,
                verdict(r <= 1.5)
            );
        }
        (Some(_), None) => {
            println!("TARGET | {what} | - | skipped: cyclictest (rt-tests) not installed")
        }
        _ => println!("TARGET | {what} | - | MISSED: the run gave no figures"),
    };
    let rest = |what: &str, row: usize| {
        let Some(f) = med[row] else {
            println!(
                "TARGET | {what}: tick compute p99 <= 3x p50 | - | MISSED: the run gave no figures"
            );
            return;
        };
        let r = f.compute.1 / f.compute.0;
        println!(
            "TARGET | {what}: tick compute p99 <= 3x p50 | {r:.2} ({:.1} / {:.1} us) | {}",
            f.compute.1,
            f.compute.0,
            verdict(r <= 3.0)
        );
        println!(
            "TARGET | {what}: 0 PLC overruns | {:.0} per run (median) | {}",
            f.plc_overruns,
            verdict(f.plc_overruns == 0.0)
        );
    };
    lateness(
        "demo RT start lateness p99 <= 1.5x cyclictest -p 80 p99",
        2,
        0,
    );
    lateness(
        "demo default start lateness p99 <= 1.5x cyclictest --laptop p99",
        3,
        1,
    );
    rest("demo RT", 2);
    lateness(
        "example 4 at 250 us RT start lateness p99 <= 1.5x cyclictest -p 80 -i 250 p99",
        7,
        6,
    );
    rest("example 4 at 250 us RT", 7);
    lateness(
        "example 4 at 250 us RT, spin wake, CNC on CPU 1: start lateness p99 <= 1.5x cyclictest -p 80 -a 1 -i 250 p99",
        10,
        9,
    );
    rest("example 4 at 250 us RT, spin wake, CNC on CPU 1", 10);
    lateness(
        "demo at 250 us RT: start lateness p99 <= 1.5x cyclictest -p 80 -i 250 p99",
        11,
        6,
    );
    rest("demo at 250 us RT", 11);
    lateness(
        "demo at 250 us RT, spin wake, CNC on CPU 1: start lateness p99 <= 1.5x cyclictest -p 80 -a 1 -i 250 p99",
        12,
        9,
    );
    rest("demo at 250 us RT, spin wake, CNC on CPU 1", 12);
    let overruns = [
        ("example 4 at 250 us RT, event wake", 7, 6),
        ("example 4 at 250 us RT, spin wake, CNC on CPU 1", 10, 9),
        ("demo at 250 us RT, event wake", 11, 6),
        ("demo at 250 us RT, spin wake, CNC on CPU 1", 12, 9),
    ];
    for (what, ours, peer) in overruns {
        match (med[ours], med[peer]) {
            (Some(a), Some(b)) => println!(
                "TARGET | {what}: PLC overruns <= cyclictest's loops late by a cycle | {:.0} against {:.0} per run (medians) | {}",
                a.plc_overruns,
                b.plc_overruns,
                verdict(a.plc_overruns <= b.plc_overruns)
            ),
            _ => println!("TARGET | {what}: PLC overruns <= cyclictest's loops late by a cycle | - | skipped: no figures (cyclictest or a second CPU missing)"),
        }
    }
    if let Some(chain) = med[13] {
        let overruns = |i: usize| med[i].map_or(f64::NAN, |f| f.plc_overruns);
        println!(
            "the floor of two tasks (a timer task waking a second by futex, no work) at 250 us: {:.0} missed slots per run; PLC overruns: demo {:.0} (event) / {:.0} (spin), example 4 {:.0} / {:.0}",
            chain.plc_overruns,
            overruns(11),
            overruns(12),
            overruns(7),
            overruns(10)
        );
    }
}
