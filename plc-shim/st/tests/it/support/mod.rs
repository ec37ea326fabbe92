//! What the runtime's test files share: a program loaded (or its refusal), and run.
#![allow(dead_code)]

use plc_st::vm::Program;

/// `text` as `main.st`, loaded; a refusal fails the test with every diagnostic.
pub fn load(text: &str) -> Program {
    Program::load(&[("main.st", text)]).unwrap_or_else(|e| {
        panic!(
            "{}",
            e.iter().map(|d| d.to_string() + "\n").collect::<String>()
        )
    })
}

/// `text` loaded and run `cycles` cycles, 10 ms apart from 0.
pub fn run(text: &str, cycles: u32) -> Program {
    let mut p = load(text);
    for k in 0..cycles {
        if let Err(f) = p.cycle(i64::from(k) * 10_000_000) {
            panic!("{}", p.fault_text(&f));
        }
    }
    p
}

/// What loading `text` refuses, one diagnostic a line.
pub fn refused(text: &str) -> String {
    match Program::load(&[("main.st", text)]) {
        Ok(_) => panic!("loaded: {text}"),
        Err(e) => e.iter().map(|d| d.to_string() + "\n").collect(),
    }
}
