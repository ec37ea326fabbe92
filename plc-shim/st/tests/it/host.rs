//! Blocks a host runs (`Program::load_with`): found at load wherever they are declared, called
//! with their inputs stored, their outputs written by the host; refused in a FUNCTION.

use plc_st::vm::{BlockIo, Fault, Host, Program};

/// A block the host runs: `Out := In + 1` and how often this instance ran.
const LIBRARY: &str = "FUNCTION_BLOCK FB_Inc
VAR_INPUT In : DINT; END_VAR
VAR_OUTPUT Out : DINT; Calls : UDINT; END_VAR
END_FUNCTION_BLOCK
";

/// Counts the calls per instance (by its slot) and writes `In + 1`.
struct Counter(Vec<u32>);

impl Host for Counter {
    fn call(&mut self, block: usize, io: &mut BlockIo<'_>) -> Result<(), Fault> {
        assert_eq!(block, 0);
        let calls = self.0.get_mut(io.slot()).ok_or(Fault::BadPointer)?;
        *calls += 1;
        let input = io.int(0).unwrap_or(0);
        io.set(1, (input + 1) as f64);
        io.set(2, f64::from(*calls));
        Ok(())
    }
}

fn load(main: &str) -> Result<Program, String> {
    Program::load_with(&[("lib.st", LIBRARY), ("main.st", main)], &["FB_Inc"])
        .map_err(|e| e.iter().map(|d| d.to_string() + "\n").collect())
}

#[test]
fn every_instance_is_found_at_load_and_runs_on_the_host() {
    let main =
        "FUNCTION_BLOCK FB_Pair VAR a, b : FB_Inc; END_VAR VAR_OUTPUT s : DINT; c : UDINT; END_VAR
    a(In := 10); b(In := 20); s := a.Out + b.Out; c := b.Calls;
END_FUNCTION_BLOCK
VAR_GLOBAL g : FB_Inc; END_VAR
PROGRAM MAIN
VAR pairs : ARRAY[0..2] OF FB_Pair; x, y, sum : DINT; n : UDINT; END_VAR
    g(In := 1, Out => x);
    pairs[1](s => y);
    pairs[2]();
    sum := x + y;
    n := pairs[2].c;
END_PROGRAM";
    let mut p = load(main).unwrap();
    // g, then the three pairs' two blocks each.
    assert_eq!(p.library_instances().len(), 7);
    let mut host = Counter(vec![0; 7]);
    for k in 0..3 {
        p.cycle_with(k, None, Some(&mut host)).unwrap();
    }
    assert_eq!(p.read_var("MAIN.x"), Some(2.0));
    assert_eq!(p.read_var("MAIN.y"), Some(32.0), "11 + 21");
    assert_eq!(p.read_var("MAIN.sum"), Some(34.0));
    assert_eq!(p.read_var("MAIN.n"), Some(3.0));
    assert_eq!(
        host.0.iter().filter(|c| **c == 3).count(),
        5,
        "{:?}",
        host.0
    );
    // Without the host, a call of a library block faults.
    assert_eq!(p.cycle(9).unwrap_err().fault, Fault::NoHost);
}

#[test]
fn a_library_block_in_a_function_or_with_statements_is_refused() {
    let e = load(
        "FUNCTION F : DINT VAR b : FB_Inc; END_VAR b(In := 1); F := b.Out; END_FUNCTION\n\
         PROGRAM MAIN VAR x : DINT; END_VAR x := F(); END_PROGRAM",
    )
    .unwrap_err();
    assert!(
        e.contains("main.st:1:23: error: FUNCTION F: a library block keeps its state"),
        "{e}"
    );
    let e = Program::load_with(
        &[(
            "lib.st",
            "FUNCTION_BLOCK FB_Inc VAR x : INT; END_VAR x := 1; END_FUNCTION_BLOCK",
        )],
        &["FB_Inc", "FB_Missing"],
    )
    .unwrap_err();
    let text: String = e.iter().map(|d| d.to_string() + "\n").collect();
    assert!(
        text.contains("library block FB_Inc: has statements"),
        "{text}"
    );
    assert!(
        text.contains("library block FB_Missing: is not declared"),
        "{text}"
    );
}
