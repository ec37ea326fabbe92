//! What Structured Text costs: a cycle of a 1,000-statement program of arithmetic and logic
//! (ns per statement, us per cycle; target <= 50 us per cycle), and loading a 10,000-line
//! program (parse, check, lower, memory laid out; target <= 1 s), with the memory the loaded
//! program holds. The in-run baseline is the same arithmetic as Rust code over an array, so
//! the ratio says what the tree-walking runtime costs over native code.
//! Each figure is the median of 21 interleaved repeats. Run: `cargo bench -p plc-st --bench st`.

use bench_kit::{median, scaled};
use plc_st::vm::Program;
use std::hint::black_box;
use std::time::Instant;

const REPEATS: usize = 21;

/// A program of `n` statements over 8 variables: sums, products, comparisons, IFs.
fn program(n: usize) -> String {
    let mut body = String::new();
    for k in 0..n {
        let (a, b, c) = (k % 8, (k + 3) % 8, (k + 5) % 8);
        let line = match k % 5 {
            0 => format!("x{a} := x{b} + x{c} * 3;\n"),
            1 => format!("x{a} := (x{b} - x{c}) / 7 + {k};\n"),
            2 => format!("b{a} := x{b} > x{c} AND NOT b{c};\n"),
            3 => format!("IF b{a} THEN x{a} := x{a} + 1; ELSE x{a} := x{a} - 1; END_IF\n"),
            _ => format!("r{a} := r{b} * 0.5 + DINT_TO_LREAL(x{c});\n"),
        };
        body.push_str(&line);
    }
    let vars: String = (0..8)
        .map(|i| format!("x{i} : DINT := {i}; b{i} : BOOL; r{i} : LREAL;\n"))
        .collect();
    format!("PROGRAM MAIN\nVAR\n{vars}END_VAR\n{body}END_PROGRAM\n")
}

/// The same kind of arithmetic in Rust, over `n` steps: the native floor.
fn native(x: &mut [i64; 8], r: &mut [f64; 8], n: usize) {
    for k in 0..n {
        let (a, b, c) = (k % 8, (k + 3) % 8, (k + 5) % 8);
        match k % 5 {
            0 => x[a] = x[b].wrapping_add(x[c].wrapping_mul(3)) as i32 as i64,
            1 => x[a] = ((x[b] - x[c]) / 7 + k as i64) as i32 as i64,
            2 => x[a] = i64::from(x[b] > x[c]),
            3 => x[a] += if x[a] & 1 == 0 { 1 } else { -1 },
            _ => r[a] = r[b] * 0.5 + x[c] as f64,
        }
    }
}

fn main() {
    let statements = 1000;
    let mut p = Program::load(&[("bench.st", &program(statements))]).expect("the bench's program");
    let cycles = scaled(2000);
    let mut tree = p.clone();
    tree.interpret_only();
    let (mut st_us, mut native_us, mut tree_us) = (Vec::new(), Vec::new(), Vec::new());
    let (mut x, mut r) = ([0i64; 8], [0f64; 8]);
    for rep in 0..REPEATS {
        let t = Instant::now();
        for k in 0..cycles {
            p.cycle((rep * cycles + k) as i64 * 1_000_000)
                .expect("a cycle");
        }
        st_us.push(t.elapsed().as_secs_f64() * 1e6 / cycles as f64);
        let t = Instant::now();
        for k in 0..cycles {
            tree.cycle((rep * cycles + k) as i64 * 1_000_000)
                .expect("a cycle");
        }
        tree_us.push(t.elapsed().as_secs_f64() * 1e6 / cycles as f64);
        let t = Instant::now();
        for _ in 0..cycles {
            native(black_box(&mut x), black_box(&mut r), statements);
        }
        native_us.push(t.elapsed().as_secs_f64() * 1e6 / cycles as f64);
    }
    let (st, nat, walked) = (median(st_us), median(native_us), median(tree_us));
    println!("| program | us per cycle | ns per statement |");
    println!("| --- | ---: | ---: |");
    println!(
        "| 1,000 ST statements | {st:.2} | {:.1} |",
        st * 1e3 / statements as f64
    );
    println!(
        "| the same, the tree walked (the runtime's other way) | {walked:.2} | {:.1} |",
        walked * 1e3 / statements as f64
    );
    println!(
        "| the same in Rust (baseline) | {nat:.2} | {:.1} |",
        nat * 1e3 / statements as f64
    );
    let verdict = if st <= 50.0 { "met" } else { "missed" };
    println!("TARGET | 1,000-statement ST program <= 50 us per cycle | {st:.2} us ({:.0}x native) | {verdict}", st / nat);

    let lines = 10_000;
    let text = program(lines - 28);
    let (mut load_ms, mut memory) = (Vec::new(), 0);
    for _ in 0..scaled(REPEATS).max(3) {
        let t = Instant::now();
        let big = black_box(Program::load(&[("big.st", &text)]).expect("the big program"));
        load_ms.push(t.elapsed().as_secs_f64() * 1e3);
        memory = big.code().layout.size;
    }
    let ms = median(load_ms);
    let verdict = if ms <= 1000.0 { "met" } else { "missed" };
    println!("TARGET | load and compile of a {}-line ST program <= 1 s | {ms:.1} ms (its variables' memory {memory} bytes) | {verdict}", text.lines().count());
}
