//! Mutation fuzzing of the decoders of outside input, on the stable toolchain: the NC
//! checker, scenario files, PLC timelines, cam files (JSON and binary tables), FIFO
//! position files (CSV and binary) and acyclic calls (frames and bulk calls of any kind). Each target takes its seeds (the files the project ships,
//! and `tests/data/fuzz/TARGET/`), mutates them with a seeded generator (bit flips, hostile
//! tokens, deletions, duplications, splices) and feeds every case to the decoder, which must
//! answer with a value or a typed error and never panic; a value must hold no non-finite
//! number. Every file in `tests/data/fuzz/TARGET/` is replayed on every run: a case that ever
//! crashed a decoder is kept there as a named regression.
//!
//! The number of cases per target is fixed (`FUZZ_CASES`, default 1500), so the run is
//! bounded; `FUZZ_CASES=200000 cargo test --release -p cnc-app --test it fuzz` runs longer.
//! Coverage-guided fuzzing is `tests/fuzz` (cargo-fuzz, nightly); its corpus is the same
//! folders, so what libFuzzer found is replayed here on stable in every CI run.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use tests::Noise;

/// Words that break careless decoders.
const TOKENS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e309",
    "-1e309",
    "99999999999999999999",
    "-0",
    "0x",
    "\"",
    "'",
    "=",
    "[[",
    "]]",
    "{",
    "}",
    "[",
    "]",
    ",",
    "\n",
    "#",
    ";",
    "(",
    ")",
    "N",
    "G1 ",
    "X",
    "M30",
    "%",
    "\u{0}",
    "\u{FFFD}",
    "..",
    "/",
    "true",
    "2147483648",
    "-2147483649",
];

/// One to four mutations of `seed`, spliced with `other` now and then.
fn mutate(seed: &[u8], other: &[u8], noise: &mut Noise) -> Vec<u8> {
    let mut case = seed.to_vec();
    for _ in 0..1 + noise.below(4) {
        let at = noise.below(case.len() + 1);
        match noise.below(7) {
            0 if !case.is_empty() => {
                let i = at.min(case.len() - 1);
                case[i] ^= 1 << noise.below(8);
            }
            1 => {
                let token = TOKENS[noise.below(TOKENS.len())].as_bytes();
                case.splice(at..at, token.iter().copied());
            }
            2 => {
                let end = (at + noise.below(64)).min(case.len());
                case.drain(at..end);
            }
            3 => {
                let end = (at + noise.below(64)).min(case.len());
                let copy = case[at..end].to_vec();
                case.splice(at..at, copy);
            }
            4 if !other.is_empty() => {
                let from = noise.below(other.len());
                let end = (from + noise.below(256)).min(other.len());
                case.splice(at..at, other[from..end].iter().copied());
            }
            5 if !case.is_empty() => {
                let i = at.min(case.len() - 1);
                case[i] = noise.next() as u8;
            }
            _ => case.truncate(at),
        }
    }
    case
}

/// Files under `dir` (recursively) whose names end in one of `ends`.
fn files(dir: &Path, ends: &[&str], out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<_> = entries.flatten().map(|e| e.path()).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            files(&path, ends, out);
        } else if ends.iter().any(|e| path.to_string_lossy().ends_with(e)) {
            out.push(path);
        }
    }
}

/// A fuzz target: its name, the file endings of its seeds, and the decoder under test.
struct Target {
    name: &'static str,
    ends: &'static [&'static str],
    decode: fn(&[u8]),
}

/// The shipped scenarios, for the call target's machines.
static SCENARIOS: std::sync::LazyLock<PathBuf> =
    std::sync::LazyLock::new(|| tests::cli::repo_root().join("scenarios"));

#[path = "../../../../tests/support/decoders.rs"]
mod decoders;
use decoders::{calls, cam, fifo_binary, fifo_csv, nc, scenario, timeline};

const TARGETS: &[Target] = &[
    Target {
        name: "nc",
        ends: &[".nc"],
        decode: nc,
    },
    Target {
        name: "scenario",
        ends: &["scenario.toml", "program.toml"],
        decode: scenario,
    },
    Target {
        name: "timeline",
        ends: &["plc.toml", "forth.toml"],
        decode: timeline,
    },
    Target {
        name: "cam",
        ends: &[".json", ".cam"],
        decode: cam,
    },
    Target {
        name: "fifo-csv",
        ends: &[".csv"],
        decode: fifo_csv,
    },
    Target {
        name: "fifo-binary",
        ends: &[".fifo"],
        decode: fifo_binary,
    },
    Target {
        name: "calls",
        ends: &[".call"],
        decode: calls,
    },
];

/// Runs `case` through `target`; a panic is saved as a regression candidate and reported.
fn run_case(target: &Target, case: &[u8], what: &str) {
    if catch_unwind(AssertUnwindSafe(|| (target.decode)(case))).is_ok() {
        return;
    }
    let dir = std::env::temp_dir()
        .join("cncplc-fuzz-crashes")
        .join(target.name);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("crash-{:016x}", fxhash(case)));
    std::fs::write(&path, case).unwrap();
    panic!(
        "fuzz target {}: {what} panicked; the case is {} (keep it as tests/data/fuzz/{}/NAME)",
        target.name,
        path.display(),
        target.name
    );
}

fn fxhash(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x100_0000_01b3)
    })
}

fn seeds(target: &Target) -> Vec<(PathBuf, Vec<u8>)> {
    let root = tests::cli::repo_root();
    let mut paths = Vec::new();
    for dir in ["scenarios", "examples", "cnc-core/app/tests/data"] {
        files(&root.join(dir), target.ends, &mut paths);
    }
    paths.retain(|p| !p.starts_with(root.join("cnc-core/app/tests/data/fuzz")));
    files(
        &root.join("cnc-core/app/tests/data/fuzz").join(target.name),
        &[""],
        &mut paths,
    );
    paths
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap();
            (p, bytes)
        })
        .collect()
}

fn cases() -> usize {
    std::env::var("FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1500)
}

#[test]
fn every_decoder_of_outside_input_survives_mutated_input() {
    let mut report = Vec::new();
    for (t, target) in TARGETS.iter().enumerate() {
        let seeds = seeds(target);
        assert!(!seeds.is_empty(), "{}: no seeds", target.name);
        // Every seed and every kept regression as it is.
        for (path, bytes) in &seeds {
            run_case(target, bytes, &path.display().to_string());
        }
        let mut noise = Noise::new(0xF022_0000 + t as u64);
        let n = cases();
        for k in 0..n {
            let (_, seed) = match seeds.len() {
                0 => (PathBuf::new(), Vec::new()),
                len => seeds[noise.below(len)].clone(),
            };
            let other = seeds
                .get(noise.below(seeds.len()))
                .map(|s| s.1.clone())
                .unwrap_or_default();
            let case = mutate(&seed, &other, &mut noise);
            run_case(target, &case, &format!("case {k}"));
        }
        report.push(format!("{} {} seeds, {n} cases", target.name, seeds.len()));
    }
    eprintln!("fuzz: {}", report.join("; "));
}
