//! The runtime's three ways agree (native code, operations, the tree): random programs (assignments of every class of value,
//! arrays, pointers, IF, CASE, FOR, WHILE and REPEAT with EXIT and CONTINUE, the standard
//! blocks, a function block with inputs and outputs, an array of them at computed indices,
//! a function) run as operations and by
//! walking the tree, cycle by cycle; after each cycle both hold the same memory, and both
//! stop on the same fault at the same place with the same numbers (a division by zero, an
//! index outside its array, a real that is not finite, an endless loop's budget).
//! `TWO_WAYS_CASES` sets the cases (CI runs 100: each is compiled to native code by an
//! unoptimized code generator in the test build; 20,000 by hand).

use plc_st::vm::Program;
use proptest::prelude::*;

/// A small deterministic generator of program text from a seed.
struct Gen {
    state: u64,
    depth: u32,
    loops: u32,
}

impl Gen {
    fn next(&mut self) -> u64 {
        // xorshift64*
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        self.state.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn pick(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    fn int_var(&mut self) -> String {
        format!("i{}", self.pick(4))
    }

    fn int(&mut self, depth: u32) -> String {
        if depth == 0 {
            return match self.pick(4) {
                0 => format!("{}", self.pick(7) as i64 - 2),
                // Typed: it wraps DINT's arithmetic at run time (an untyped literal's
                // constant expression is folded at load, and refused where it does not fit).
                1 => "DINT#2147483000".into(),
                _ => self.int_var(),
            };
        }
        let d = depth - 1;
        match self.pick(11) {
            0 => format!("({} + {})", self.int(d), self.int(d)),
            1 => format!("({} - {})", self.int(d), self.int(d)),
            2 => format!("({} * {})", self.int(d), self.int(d)),
            3 => format!("({} / {})", self.int(d), self.int(d)),
            4 => format!("({} MOD {})", self.int(d), self.int(d)),
            5 => format!("a[{} + {}]", self.int_var(), self.int(d)),
            6 => format!("ABS({})", self.int(d)),
            7 => format!("MIN({}, {})", self.int(d), self.int(d)),
            8 => format!("SEL({}, {}, {})", self.boolean(d), self.int(d), self.int(d)),
            9 => match self.pick(3) {
                0 => format!("Twice({})", self.int(d)),
                // Functions that write what the expression around them reads.
                1 => format!("({} + Bump())", self.int_var()),
                _ => "(g + Inc())".into(),
            },
            _ => format!("-{}", self.int(d)),
        }
    }

    fn boolean(&mut self, depth: u32) -> String {
        if depth == 0 {
            return format!("b{}", self.pick(3));
        }
        let d = depth - 1;
        match self.pick(9) {
            0 => format!("NOT {}", self.boolean(d)),
            1 => format!("({} AND {})", self.boolean(d), self.boolean(d)),
            // The right value only when needed: a fault in it only then.
            7 => format!("({} AND_THEN {})", self.boolean(d), self.boolean(d)),
            8 => format!("(p = 0 OR_ELSE {} OR_ELSE p^ > 0)", self.boolean(d)),
            2 => format!("({} OR {})", self.boolean(d), self.boolean(d)),
            3 => format!("({} XOR {})", self.boolean(d), self.boolean(d)),
            4 => format!("({} < {})", self.int(d), self.int(d)),
            5 => format!("({} = {})", self.int(d), self.int(d)),
            _ => format!("({} >= {})", self.real(d), self.real(d)),
        }
    }

    fn real(&mut self, depth: u32) -> String {
        if depth == 0 {
            return match self.pick(3) {
                0 => "1.5".into(),
                _ => format!("r{}", self.pick(2)),
            };
        }
        let d = depth - 1;
        match self.pick(5) {
            0 => format!("({} * {})", self.real(d), self.real(d)),
            1 => format!("({} + DINT_TO_LREAL({}))", self.real(d), self.int(d)),
            2 => format!("({} / {})", self.real(d), self.real(d)),
            3 => format!("SQRT(ABS({}))", self.real(d)),
            _ => format!("({} - {})", self.real(d), self.real(d)),
        }
    }

    fn statements(&mut self, n: u64) -> String {
        (0..1 + self.pick(n)).map(|_| self.statement()).collect()
    }

    fn statement(&mut self) -> String {
        let deep = self.depth >= 3;
        let kind = if deep { self.pick(8) } else { self.pick(17) };
        self.depth += 1;
        let s = match kind {
            0 | 1 => format!("{} := {};\n", self.int_var(), self.int(2)),
            2 => format!("b{} := {};\n", self.pick(3), self.boolean(2)),
            3 => format!("r{} := {};\n", self.pick(2), self.real(2)),
            4 => format!("a[{} - 1] := {};\n", self.int_var(), self.int(1)),
            5 => format!("t(IN := {}, PT := T#20MS);\nb0 := t.Q;\n", self.boolean(1)),
            6 => match self.pick(5) {
                // A later input that reads what an earlier one stored, or that faults
                // after it was stored.
                3 => {
                    let b = match self.pick(3) {
                        0 => format!("pr.a + {}", self.int_var()),
                        1 => format!("1000 / ({} - 1)", self.int_var()),
                        _ => self.int(1),
                    };
                    format!(
                        "pr(a := {}, b := {b}, s => {});\n",
                        self.int(1),
                        self.int_var()
                    )
                }
                0 => format!("fb(x := {}, y => {});\n", self.int(1), self.int_var()),
                // An instance of an array at an index known when it runs (beyond it: the
                // index's fault), and an element's output read at another.
                1 => format!(
                    "fbs[{} MOD 4](x := {}, y => {});\n",
                    self.int_var(),
                    self.int(1),
                    self.int_var()
                ),
                // At a variable's index: the call in one operation, its instance found
                // when it runs and its output read from there.
                4 => format!(
                    "fbs[{}](x := {}, y => {});\n",
                    ["k", "i0", "i1"][self.pick(3) as usize],
                    self.int(1),
                    self.int_var()
                ),
                _ => format!("{} := fbs[{} - 1].y;\n", self.int_var(), self.int_var()),
            },
            7 => match self.pick(3) {
                0 => format!("p := ADR({});\np^ := {};\n", self.int_var(), self.int(1)),
                // Pointers in an array, to structures with arrays (as gpCh[0]^.unit.field).
                1 => format!(
                    "pa[{}] := ADR(q{});\npa[{}]^.v[{}] := {};\n",
                    self.pick(2),
                    self.pick(2),
                    self.pick(2),
                    self.pick(3),
                    self.int(1)
                ),
                _ => format!(
                    "{} := pa[{}]^.v[{}] + pa[{}]^.x;\n",
                    self.int_var(),
                    self.pick(2),
                    self.pick(3),
                    self.pick(2)
                ),
            },
            8 => format!(
                "IF {} THEN\n{}ELSIF {} THEN\n{}ELSE\n{}END_IF\n",
                self.boolean(1),
                self.statements(2),
                self.boolean(1),
                self.statements(2),
                self.statements(2)
            ),
            9 => format!(
                "CASE {} OF\n0: {}1, 2: {}3..5: {}7..9: {}ELSE\n{}END_CASE\n",
                self.int_var(),
                self.statements(2),
                self.statements(2),
                self.statements(2),
                self.statements(1),
                self.statements(1)
            ),
            10 | 11 => self.for_loop(),
            12 => {
                let v = self.int_var();
                format!(
                    "WHILE {v} < {} DO\n{v} := {v} + 1;\n{}END_WHILE\n",
                    self.pick(20),
                    self.looped()
                )
            }
            13 => format!(
                "REPEAT\n{}UNTIL {}\nEND_REPEAT\n",
                self.looped(),
                self.boolean(1)
            ),
            14 => format!("c(CU := {}, PV := 3);\nb1 := c.Q;\n", self.boolean(1)),
            15 if self.loops > 0 => match self.pick(3) {
                0 => "EXIT;\n".into(),
                1 => "CONTINUE;\n".into(),
                // A FOR's body may move its control variable.
                _ => "k := k + 1;\n".into(),
            },
            15 => "RETURN;\n".into(),
            _ => format!("{} := fb.y + Twice({});\n", self.int_var(), self.int(1)),
        };
        self.depth -= 1;
        s
    }

    fn looped(&mut self) -> String {
        self.loops += 1;
        let body = self.statements(3);
        self.loops -= 1;
        body
    }

    fn for_loop(&mut self) -> String {
        let (from, to) = (self.pick(5) as i64 - 1, self.pick(7) as i64 - 1);
        let by = [1, 2, -1, 1][self.pick(4) as usize];
        format!(
            "FOR k := {from} TO {to} BY {by} DO\n{}END_FOR\n",
            self.looped()
        )
    }

    fn program(&mut self) -> String {
        let body = self.statements(8);
        format!(
            "FUNCTION Twice : DINT
VAR_INPUT x : DINT; END_VAR
    Twice := x * 2;
END_FUNCTION
FUNCTION Bump : DINT
    gp^ := gp^ + 1;
    Bump := 0;
END_FUNCTION
FUNCTION Inc : DINT
    g := g + 1;
    Inc := g MOD 3;
END_FUNCTION
VAR_GLOBAL
    g : DINT := Twice(3);
    gp : POINTER TO DINT;
END_VAR
FUNCTION_BLOCK Acc
VAR_INPUT x : DINT; END_VAR
VAR_OUTPUT y : DINT; END_VAR
VAR s : DINT; END_VAR
    s := s + x;
    y := s MOD 1000;
END_FUNCTION_BLOCK
FUNCTION_BLOCK Pair
VAR_INPUT a, b : DINT; END_VAR
VAR_OUTPUT s : DINT; END_VAR
    s := a * 3 + b;
END_FUNCTION_BLOCK
TYPE S : STRUCT x : DINT; v : ARRAY[0..2] OF DINT; END_STRUCT END_TYPE
PROGRAM MAIN
VAR
    q0, q1 : S;
    pa : ARRAY[0..1] OF POINTER TO S;
    i0, i1, i2 : DINT := 1; i3 : DINT := -7;
    b0, b1 : BOOL; b2 : BOOL := TRUE;
    r0 : LREAL := 0.25; r1 : LREAL := -3.0;
    a : ARRAY[0..4] OF DINT;
    k : INT;
    p : POINTER TO DINT;
    t : TON;
    c : CTU;
    fb : Acc;
    fbs : ARRAY[0..2] OF Acc;
    pr : Pair;
END_VAR
gp := ADR(i1);
{body}END_PROGRAM
"
        )
    }
}

/// Runs `text` three ways for `cycles` cycles: natively, as operations and as the tree; the
/// same memory after each, the same fault.
fn both_ways(text: &str, cycles: i64) -> Result<(), String> {
    let load = || Program::load(&[("gen.st", text)]).map_err(|e| format!("{e:?}"));
    let (mut native, mut ops, mut tree) = (load()?, load()?, load()?);
    if !native.is_native() {
        return Err("no native code on this machine".into());
    }
    ops.operations_only();
    tree.interpret_only();
    for p in [&mut native, &mut ops, &mut tree] {
        p.set_budget(5_000);
    }
    for k in 0..cycles {
        let now = k * 7_000_000;
        let (n, a, b) = (native.cycle(now), ops.cycle(now), tree.cycle(now));
        if a != b {
            return Err(format!("cycle {k}: operations {a:?}, tree {b:?}"));
        }
        if n != b {
            return Err(format!("cycle {k}: native {n:?}, tree {b:?}"));
        }
        if ops.memory() != tree.memory() {
            return Err(format!("cycle {k}: the memories differ (operations)"));
        }
        if native.memory() != tree.memory() {
            return Err(format!("cycle {k}: the memories differ (native)"));
        }
        if a.is_err() {
            break;
        }
    }
    Ok(())
}

fn cases() -> u32 {
    std::env::var("TWO_WAYS_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn random_programs_run_alike_both_ways(seed in any::<u64>()) {
        let mut g = Gen { state: seed | 1, depth: 0, loops: 0 };
        let text = g.program();
        if let Err(e) = both_ways(&text, 12) {
            prop_assert!(false, "{e}\n{text}");
        }
    }
}

/// The generator's programs load (a generator that wrote nothing the checker takes would
/// test nothing), and some of them fault.
#[test]
fn the_generated_programs_load_and_some_fault() {
    let (mut loaded, mut faulted) = (0, 0);
    for seed in 1..200u64 {
        let mut g = Gen {
            state: seed * 0x9E37_79B9,
            depth: 0,
            loops: 0,
        };
        let text = g.program();
        let mut p = Program::load(&[("gen.st", &text)]).unwrap_or_else(|e| panic!("{e:?}\n{text}"));
        loaded += 1;
        p.set_budget(5_000);
        if (0..12).any(|k| p.cycle(k * 7_000_000).is_err()) {
            faulted += 1;
        }
    }
    assert_eq!(loaded, 199);
    assert!((10..190).contains(&faulted), "{faulted} of 199 faulted");
}
