//! How late the CNC's tick starts after its deadline, whole process against whole process:
//! `cnc run` (real time, example 4 with its PLC process) with the real-time options
//! (SCHED_FIFO 80, locked memory, timer slack 1 ns) and on the default scheduler, beside
//! `cyclictest -m -p 80 -i 1000` (rt-tests) in the same run. Interleaved rounds; p50/p99 of
//! each round; medians over rounds; the ratio cnc p99 / cyclictest p99. The lateness is the
//! time from the absolute deadline to the first instruction of the tick. A peer that is absent
//! is skipped and said so. Run: `cargo bench -p cnc-app --bench tick_latency`.

use std::path::PathBuf;
use std::process::Command;

const TICKS: u32 = 5000;
const ROUNDS: usize = 3;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// (p50, p99) start lateness in us from the run report.
fn cnc(rt: bool) -> Option<(f64, f64)> {
    let scenario = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios/example4-turntable-plc/scenario.toml");
    let mut c = Command::new(env!("CARGO_BIN_EXE_cnc"));
    c.args(["run", scenario.to_str()?, "--ticks", &TICKS.to_string()]);
    if rt {
        c.args([
            "--rt-priority",
            "80",
            "--rt-lock-memory",
            "--rt-timer-slack-ns",
            "1",
        ]);
    }
    let out = c.output().ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().find(|l| l.contains("start lateness"))?;
    let rest = &line[line.find("start lateness")?..];
    let ns = |key: &str| -> Option<f64> {
        let at = rest.find(key)? + key.len();
        rest[at..].split_whitespace().next()?.parse::<f64>().ok()
    };
    let (p50, p99) = (ns("p50 ")?, ns("p99 ")?);
    Some((p50 / 1000.0, p99 / 1000.0))
}

/// (p50, p99) latency in us from cyclictest's histogram, or None when it is not installed.
fn cyclictest() -> Option<(f64, f64)> {
    let out = Command::new("cyclictest")
        .args([
            "-m",
            "-p",
            "80",
            "-i",
            "1000",
            "-l",
            &TICKS.to_string(),
            "-q",
            "-h",
            "5000",
        ])
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let mut histogram: Vec<(f64, u64)> = Vec::new();
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let mut cells = line.split_whitespace();
        let (Some(us), Some(n)) = (cells.next(), cells.next()) else {
            continue;
        };
        if let (Ok(us), Ok(n)) = (us.parse::<f64>(), n.parse::<u64>()) {
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
        5000.0
    };
    Some((quantile(0.5), quantile(0.99)))
}

fn main() {
    let present = Command::new("cyclictest").arg("--help").output().is_ok();
    if !present {
        println!("cyclictest (rt-tests) is not installed: the peer is skipped");
    }
    let mut rows: [Vec<(f64, f64)>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    for _ in 0..ROUNDS {
        if present {
            rows[0].extend(cyclictest());
        }
        rows[1].extend(cnc(true));
        rows[2].extend(cnc(false));
    }
    println!("tick start lateness, {TICKS} ticks of 1 ms per run, medians of {ROUNDS} interleaved rounds");
    println!("{:<52} {:>9} {:>9}", "", "p50 us", "p99 us");
    let names = [
        "cyclictest -m -p 80 -i 1000",
        "cnc run, SCHED_FIFO 80 + mlockall + slack 1 ns",
        "cnc run, default scheduler",
    ];
    let mut p99 = [None; 3];
    for (i, name) in names.iter().enumerate() {
        if rows[i].is_empty() {
            println!("{name:<52} {:>9} {:>9}", "-", "-");
            continue;
        }
        let a = median(rows[i].iter().map(|r| r.0).collect());
        let b = median(rows[i].iter().map(|r| r.1).collect());
        p99[i] = Some(b);
        println!("{name:<52} {a:>9.1} {b:>9.1}");
    }
    if let (Some(c), Some(r)) = (p99[0], p99[1]) {
        println!(
            "p99 ratio cnc (real-time options) / cyclictest: {:.2} (target <= 1.5)",
            r / c
        );
    }
}
