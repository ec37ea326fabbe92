//! Programs run: their values after cycles, the standard blocks on the cycle's clock, and the
//! faults a program can make, each with its place.

use plc_st::vm::{Fault, Program};

use crate::support::{load, refused, run};

#[test]
fn variables_keep_their_values_from_cycle_to_cycle() {
    let p = run(
        "PROGRAM MAIN VAR n : INT := 5; END_VAR n := n + 1; END_PROGRAM",
        3,
    );
    assert_eq!(p.read_var("MAIN.n"), Some(8.0));
}

#[test]
fn loops_arrays_functions_and_cases_compute() {
    let text = "
TYPE E_Mode : (Idle, Sum, Done); END_TYPE
FUNCTION Square : DINT
VAR_INPUT x : DINT; END_VAR
    Square := x * x;
END_FUNCTION
PROGRAM MAIN
VAR
    a : ARRAY[1..10] OF DINT;
    i : INT;
    total : DINT;
    mode : E_Mode := E_Mode.Idle;
    r : LREAL;
    w : WORD := 16#00F0;
    s : INT;
END_VAR
CASE mode OF
    E_Mode.Idle:
        FOR i := 1 TO 10 DO
            a[i] := Square(i);
        END_FOR
        mode := Sum;
    E_Mode.Sum:
        total := 0;
        i := 10;
        WHILE i >= 1 DO
            total := total + a[i];
            i := i - 1;
            IF i < 1 THEN EXIT; END_IF
        END_WHILE
        r := SQRT(DINT_TO_LREAL(total)) + LIMIT(0.0, -2.5, 1.0);
        w := ROL(w, 4) OR SHR(w, 4);
        s := 32767;
        s := s + 1;
        mode := Done;
END_CASE
END_PROGRAM";
    let p = run(text, 2);
    assert_eq!(p.read_var("MAIN.total"), Some(385.0));
    assert_eq!(p.read_var("MAIN.mode"), Some(2.0));
    assert!((p.read_var("MAIN.r").unwrap() - 385f64.sqrt()).abs() < 1e-12);
    assert_eq!(p.read_var("MAIN.w"), Some(f64::from(0x0F00 | 0x000F)));
    assert_eq!(p.read_var("MAIN.s"), Some(-32768.0), "INT wraps");
}

#[test]
fn function_blocks_keep_their_state_and_the_timers_run_on_the_clock() {
    let text = "
FUNCTION_BLOCK FB_Count
VAR_INPUT x : BOOL; END_VAR
VAR_OUTPUT n : INT; END_VAR
VAR edge : R_TRIG; END_VAR
    edge(CLK := x);
    IF edge.Q THEN n := n + 1; END_IF
END_FUNCTION_BLOCK
PROGRAM MAIN
VAR
    t : TON;
    blink : BOOL;
    counter : FB_Count;
    edges : INT;
    done : BOOL;
    ctu : CTU;
END_VAR
    t(IN := NOT t.Q, PT := T#30MS);
    IF t.Q THEN blink := NOT blink; END_IF
    counter(x := blink, n => edges);
    ctu(CU := blink, PV := 3, Q => done);
END_PROGRAM";
    // 10 ms per cycle: the timer's Q comes 30 ms after it starts, for one cycle, then it
    // starts again the cycle after: blink toggles every 5 cycles, rises every 10.
    let p = run(text, 40);
    assert_eq!(p.read_var("MAIN.edges"), Some(4.0));
    assert_eq!(p.read_var("MAIN.done"), Some(1.0), "CTU reached 3");
}

/// IEC 61131-3's MUL and DIV of TIME: a duration by an integer in whole milliseconds, by a
/// real rounded to them; the number on either side of `*`; the factor's order kept.
#[test]
fn durations_scale_by_numbers() {
    let p = run(
        "PROGRAM MAIN
VAR
    tBase : TIME := T#1S;
    n : INT := 3;
    f : LREAL := 1.25;
    t1, t2, t3, t4, t5 : TIME;
    fb : TON;
END_VAR
    t1 := tBase * n;
    t2 := 2 * tBase / 8;
    t3 := tBase * f;
    t4 := T#10MS / 3;
    t5 := f * T#3MS;
    fb(IN := TRUE, PT := T#10MS * n);
END_PROGRAM",
        1,
    );
    for (var, ms) in [
        ("t1", 3000.0),
        ("t2", 250.0),
        ("t3", 1250.0),
        ("t4", 3.0),
        ("t5", 4.0),
    ] {
        assert_eq!(p.read_var(&format!("MAIN.{var}")), Some(ms), "{var}");
    }
}

#[test]
fn a_duration_is_scaled_by_numbers_only() {
    let e = refused(
        "PROGRAM MAIN VAR t : TIME; w : WORD; END_VAR
t := t * t;
t := 2 / t;
t := t * w;
END_PROGRAM",
    );
    assert!(e.contains("main.st:2:8: error: `*` of TIME\n"), "{e}");
    assert!(e.contains("main.st:3:8: error: `/` of"), "{e}");
    assert!(
        e.contains("main.st:4:8: error: `*` of TIME and WORD"),
        "{e}"
    );
}

/// An integer literal that scales a TIME is wrapped to its width, as the same value held in
/// a variable and converted is.
#[test]
fn a_durations_literal_factor_is_held_as_a_variables_is() {
    let p = run(
        "PROGRAM MAIN VAR d : LINT := 4294967297; t1, t2, t3, t4 : TIME; END_VAR
t1 := T#1S / 4294967297;
t2 := T#1S / d;
t3 := T#20D / 2;
t4 := T#20D * 0.5;
END_PROGRAM",
        1,
    );
    assert_eq!(p.read_var("MAIN.t1"), Some(1000.0));
    assert_eq!(p.read_var("MAIN.t2"), Some(1000.0));
    // The duration operand as written: by an integer and by a real alike.
    assert_eq!(p.read_var("MAIN.t3"), p.read_var("MAIN.t4"));
}

#[test]
fn a_ton_is_done_when_its_time_has_run() {
    let text = "PROGRAM MAIN VAR t : TON; q : BOOL; et : TIME; END_VAR
        t(IN := TRUE, PT := T#30MS, Q => q, ET => et); END_PROGRAM";
    let mut p = load(text);
    for (k, (q, et)) in [
        (0.0, 0.0),
        (0.0, 10.0),
        (0.0, 20.0),
        (1.0, 30.0),
        (1.0, 30.0),
    ]
    .iter()
    .enumerate()
    {
        p.cycle(k as i64 * 10_000_000).unwrap();
        assert_eq!(
            (p.read_var("MAIN.q"), p.read_var("MAIN.et")),
            (Some(*q), Some(*et)),
            "cycle {k}"
        );
    }
}

#[test]
fn a_tof_holds_q_for_its_time_then_et_stays_at_pt() {
    let text = "PROGRAM MAIN VAR t : TOF; n : INT; q : BOOL; et : TIME; END_VAR
        n := n + 1; t(IN := n <= 2 OR n >= 8, PT := T#20MS, Q => q, ET => et); END_PROGRAM";
    let mut p = load(text);
    // IN is TRUE in cycles 1-2, FALSE in 3-7, TRUE again from 8 (10 ms per cycle).
    let expected = [
        (1, 0),
        (1, 0),
        (1, 0),
        (1, 10),
        (0, 20),
        (0, 20),
        (0, 20),
        (1, 0),
    ];
    for (k, (q, et)) in expected.iter().enumerate() {
        p.cycle(k as i64 * 10_000_000).unwrap();
        let got = (p.read_var("MAIN.q"), p.read_var("MAIN.et"));
        assert_eq!(
            got,
            (Some(f64::from(*q)), Some(f64::from(*et))),
            "cycle {}",
            k + 1
        );
    }
}

const TWICE: &str = "FUNCTION F : INT VAR_INPUT x : INT; END_VAR VAR k : INT := 10; END_VAR
    k := k + x;
    F := k;
END_FUNCTION
";

#[test]
fn a_function_called_in_its_own_argument_starts_from_its_initial_values() {
    let p = run(
        &format!("{TWICE}PROGRAM MAIN VAR y : INT; END_VAR y := F(F(1)); END_PROGRAM"),
        1,
    );
    assert_eq!(p.read_var("MAIN.y"), Some(21.0), "F(1) = 11, F(11) = 21");
}

#[test]
fn a_fault_after_a_call_names_the_callers_statement() {
    let text =
        format!("{TWICE}PROGRAM MAIN VAR y, z : INT; END_VAR\n  y := F(1) / z;\nEND_PROGRAM");
    let (f, text) = fault(&text);
    assert_eq!(f, Fault::DivisionByZero);
    assert!(
        text.starts_with("main.st:6:3: fault: division by zero"),
        "{text}"
    );
}

#[test]
fn pointers_write_where_they_point() {
    let text = "
PROGRAM MAIN
VAR
    a : ARRAY[0..2] OF DINT;
    p : POINTER TO DINT;
    x : DINT;
END_VAR
    p := ADR(a[1]);
    p^ := DINT#-13059200;
    x := a[1];
END_PROGRAM";
    let p = run(text, 1);
    assert_eq!(p.read_var("MAIN.x"), Some(-13_059_200.0));
}

fn fault(text: &str) -> (Fault, String) {
    let mut p = load(text);
    p.set_budget(10_000);
    let e = p.cycle(0).unwrap_err();
    (e.fault, p.fault_text(&e))
}

#[test]
fn faults_stop_the_cycle_and_name_the_statement() {
    let (f, text) = fault("PROGRAM MAIN VAR a, b : INT; END_VAR\n  a := 1 / b;\nEND_PROGRAM");
    assert_eq!(f, Fault::DivisionByZero);
    assert!(
        text.starts_with("main.st:2:3: fault: division by zero"),
        "{text}"
    );
    let (f, text) = fault(
        "PROGRAM MAIN VAR a : ARRAY[0..2] OF INT; i : INT := 3; END_VAR\n  a[i] := 1;\nEND_PROGRAM",
    );
    assert_eq!(f, Fault::IndexOutOfRange);
    assert!(
        text.starts_with("main.st:2:3: fault: index 3 outside [0..2]"),
        "{text}"
    );
    let (f, _) = fault("PROGRAM MAIN VAR b : BOOL := TRUE; END_VAR\n  WHILE b DO b := TRUE; END_WHILE\nEND_PROGRAM");
    assert_eq!(f, Fault::Budget);
    let (f, _) = fault("PROGRAM MAIN VAR p : POINTER TO INT; END_VAR\n  p^ := 1;\nEND_PROGRAM");
    assert_eq!(f, Fault::BadPointer);
    // A field through a NULL pointer (one step from the pointer variable: `p^.b`).
    let (f, text) = fault("TYPE S : STRUCT a : LREAL; b : INT; END_STRUCT END_TYPE\nPROGRAM MAIN VAR p : POINTER TO S; i : INT; END_VAR\n  i := 1;\n  i := p^.b;\nEND_PROGRAM");
    assert_eq!(f, Fault::BadPointer);
    assert!(text.starts_with("main.st:4:3: fault:"), "{text}");
    let (f, _) = fault("PROGRAM MAIN VAR r : LREAL := 1.0E300; i : INT; END_VAR\n  i := LREAL_TO_INT(r);\nEND_PROGRAM");
    assert_eq!(f, Fault::OutOfRange);
    // 2^63 is one past LINT's largest value (it used to wrap to the smallest).
    let (f, _) = fault("PROGRAM MAIN VAR r : LREAL := 9.223372036854775807E18; i : LINT; END_VAR\n  i := LREAL_TO_LINT(r);\nEND_PROGRAM");
    assert_eq!(f, Fault::OutOfRange);
}

use crate::counting_alloc;

/// After the load, a cycle allocates nothing: function blocks, functions and methods (their
/// block instances started from their initial values at each call), loops, the standard
/// blocks and functions included.
#[test]
fn a_cycle_allocates_nothing() {
    let text = "
FUNCTION Twice : LREAL VAR_INPUT x : LREAL; END_VAR Twice := 2.0 * x; END_FUNCTION
FUNCTION_BLOCK FB_Acc VAR_INPUT x : LREAL; END_VAR VAR_OUTPUT sum : LREAL; END_VAR
    sum := sum + Twice(x);
METHOD M_Add : LREAL
VAR_INPUT y : LREAL; END_VAR
VAR t3 : TON := (PT := T#2S); n : INT := 3; END_VAR
    t3(IN := TRUE);
    M_Add := sum + y + INT_TO_LREAL(n);
END_METHOD
END_FUNCTION_BLOCK
FUNCTION Summed : LREAL
VAR_INPUT x : LREAL; END_VAR
VAR accs : ARRAY[0..1] OF FB_Acc; t2 : TON := (PT := T#1S); END_VAR
    accs[1](x := x);
    Summed := accs[1].sum;
END_FUNCTION
PROGRAM MAIN
VAR acc : FB_Acc; t : TON; i : INT; a : ARRAY[0..9] OF LREAL; total, s, m : LREAL; END_VAR
    FOR i := 0 TO 9 DO a[i] := SIN(INT_TO_LREAL(i)); END_FOR
    acc(x := MAX(a[3], a[4], 0.5), sum => total);
    t(IN := TRUE, PT := T#1S);
    s := Summed(1.0);
    m := acc.M_Add(0.0) - total;
END_PROGRAM";
    let mut p = load(text);
    p.cycle(0).unwrap();
    let before = counting_alloc::allocations();
    for k in 1..1000 {
        p.cycle(k * 1_000_000).unwrap();
    }
    assert_eq!(counting_alloc::allocations() - before, 0);
    assert!(p.read_var("MAIN.total").unwrap() > 0.0);
    assert_eq!(p.read_var("MAIN.s"), Some(2.0));
    assert_eq!(p.read_var("MAIN.m"), Some(3.0));
}

#[test]
fn what_the_runtime_cannot_hold_is_refused_at_load_with_its_place() {
    let values = (1..=17)
        .map(|k| k.to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let e = refused(&format!(
        "PROGRAM MAIN VAR m : DINT; END_VAR\n  m := MAX({values});\nEND_PROGRAM"
    ));
    assert!(
        e.contains("main.st:2:8: error: a standard function of more than 16"),
        "{e}"
    );
    let e = refused(
        "FUNCTION G : INT VAR_IN_OUT x : INT; END_VAR G := x; END_FUNCTION\n\
         PROGRAM MAIN VAR a, m : INT; END_VAR\n  m := G();\nEND_PROGRAM",
    );
    assert!(
        e.contains("main.st:3:8: error: G: its VAR_IN_OUT `x` must be given"),
        "{e}"
    );
    let e = refused(
        "PROGRAM MAIN VAR p : POINTER TO ARRAY[0..1000000] OF ARRAY[0..1000000] OF LREAL;\n\
         x : LREAL; END_VAR\n  x := p^[1][1];\nEND_PROGRAM",
    );
    assert!(
        e.contains("main.st:3:8: error: an array larger than 4 GiB"),
        "{e}"
    );
}

#[test]
fn global_variables_start_from_their_initial_values() {
    let p = run(
        "VAR_GLOBAL CONSTANT K : UDINT := 3; END_VAR\n\
         VAR_GLOBAL G : DINT := 7; H : LREAL := K * 2.5; END_VAR\n\
         PROGRAM MAIN VAR a : UDINT; c : DINT; x : LREAL; END_VAR a := K; c := G; x := H; G := G + 1; END_PROGRAM",
        2,
    );
    assert_eq!(p.read_var("MAIN.a"), Some(3.0));
    assert_eq!(
        p.read_var("MAIN.c"),
        Some(8.0),
        "7, then the program's own + 1 once"
    );
    assert_eq!(p.read_var("MAIN.x"), Some(7.5));
    let e = refused("VAR_GLOBAL G : INT := TRUE; END_VAR PROGRAM MAIN END_PROGRAM");
    assert!(
        e.contains("main.st:1:23: error: BOOL where INT is wanted"),
        "{e}"
    );
}

#[test]
fn a_single_bit_is_written_and_read() {
    let p = run(
        "PROGRAM MAIN VAR w : WORD := 16#00F0; i : INT := -1; b3, b4 : BOOL; END_VAR\n\
         w.3 := TRUE; w.4 := FALSE; w.15 := w.5; i.0 := FALSE; b3 := w.3; b4 := w.4;\n\
         END_PROGRAM",
        1,
    );
    assert_eq!(p.read_var("MAIN.w"), Some(f64::from(0x80E8u16)));
    assert_eq!(p.read_var("MAIN.i"), Some(-2.0));
    assert_eq!(
        (p.read_var("MAIN.b3"), p.read_var("MAIN.b4")),
        (Some(1.0), Some(0.0))
    );
}

#[test]
fn arrays_and_structures_start_from_their_initialisers() {
    let p = run(
        "TYPE ST_Point : STRUCT x, y : LREAL; n : INT; END_STRUCT END_TYPE\n\
         VAR_GLOBAL gOrigin : ST_Point := (y := 2.5, n := 7); END_VAR\n\
         PROGRAM MAIN\n\
         VAR a : ARRAY[1..6] OF INT := [1, 2, 3(9)]; m : ARRAY[0..1, 0..1] OF DINT := [10, 11, 12];\n\
             pts : ARRAY[0..1] OF ST_Point := [(x := 1.0), (x := 3.0, n := -1)];\n\
             s, x1, y0 : LREAL; n1, m3 : DINT; END_VAR\n\
         s := INT_TO_LREAL(a[1] + a[2] + a[3] + a[5] + a[6]); x1 := pts[1].x; y0 := gOrigin.y;\n\
         n1 := pts[1].n + gOrigin.n; m3 := m[1, 0] + m[1, 1];\n\
         END_PROGRAM",
        1,
    );
    assert_eq!(p.read_var("MAIN.s"), Some(1.0 + 2.0 + 9.0 + 9.0 + 0.0));
    assert_eq!(p.read_var("MAIN.x1"), Some(3.0));
    assert_eq!(p.read_var("MAIN.y0"), Some(2.5));
    assert_eq!(p.read_var("MAIN.n1"), Some(6.0));
    assert_eq!(
        p.read_var("MAIN.m3"),
        Some(12.0),
        "row-major: m[1,0] = 12, m[1,1] = 0"
    );
}

#[test]
fn an_initialiser_that_does_not_fit_is_refused_with_its_place() {
    let e = refused("PROGRAM MAIN VAR a : ARRAY[0..2] OF INT := [1, 2(3), 4]; END_VAR END_PROGRAM");
    assert!(
        e.contains("main.st:1:18: error: 4 initial values for 3 elements"),
        "{e}"
    );
    let e = refused(
        "TYPE P : STRUCT x : INT; END_STRUCT END_TYPE\n\
         PROGRAM MAIN VAR p : P := (z := 1); b : INT := [1]; q : P := (x := TRUE); END_VAR END_PROGRAM",
    );
    assert!(e.contains("main.st:2:28: error: P has no field `z`"), "{e}");
    assert!(
        e.contains("main.st:2:37: error: an array initialiser for a INT"),
        "{e}"
    );
    assert!(
        e.contains("main.st:2:68: error: BOOL where INT is wanted"),
        "{e}"
    );
    let e =
        refused("PROGRAM MAIN VAR a : ARRAY[0..99999] OF INT := [100000(1)]; END_VAR END_PROGRAM");
    assert!(
        e.contains("main.st:1:18: error: an initialiser of more than 65536 values"),
        "{e}"
    );
}

#[test]
fn a_tool_writes_only_what_the_type_holds_and_sees_no_constants() {
    let mut p = load(
        "VAR_GLOBAL CONSTANT K : INT := 3; END_VAR\n\
         PROGRAM MAIN VAR n : LINT; r : REAL; t : TIME; u : USINT; END_VAR END_PROGRAM",
    );
    let symbols = p.symbols(100);
    let find = |path: &str| {
        let s = symbols.iter().find(|s| s.path == path).unwrap();
        (s.offset, s.elem)
    };
    assert!(
        symbols.iter().all(|s| s.path != "K"),
        "a CONSTANT is not listed"
    );
    let (n, r, t, u) = (
        find("MAIN.n"),
        find("MAIN.r"),
        find("MAIN.t"),
        find("MAIN.u"),
    );
    assert_eq!(
        p.write_symbol(n.0, n.1, 9_223_372_036_854_775_808.0),
        Err(Fault::OutOfRange)
    );
    assert_eq!(
        p.write_symbol(r.0, r.1, 1e39),
        Err(Fault::OutOfRange),
        "beyond REAL"
    );
    assert_eq!(p.write_symbol(u.0, u.1, 256.0), Err(Fault::OutOfRange));
    assert_eq!(
        p.write_symbol(u.0, u.1, 2.5),
        Err(Fault::OutOfRange),
        "not whole"
    );
    p.write_symbol(t.0, t.1, 1500.0).unwrap();
    p.write_symbol(n.0, n.1, -9.0e18).unwrap();
    assert_eq!(p.read_var("MAIN.t"), Some(1500.0));
    assert_eq!(p.read_var("MAIN.n"), Some(-9.0e18));
}

#[test]
fn nested_repetitions_count_toward_the_initialisers_limit() {
    let e = refused(
        "PROGRAM MAIN VAR a : ARRAY[0..299] OF ARRAY[0..299] OF BOOL := [300([300(TRUE)])];\n\
         END_VAR END_PROGRAM",
    );
    assert!(
        e.contains("main.st:1:18: error: an initialiser of more than 65536 values"),
        "{e}"
    );
}

#[test]
fn a_constant_index_far_out_of_bounds_faults_in_the_cycle() {
    let (f, _) = fault(
        "PROGRAM MAIN VAR a : ARRAY[-5..5] OF INT; END_VAR\n  \
         a[LINT#9223372036854775807] := 1;\nEND_PROGRAM",
    );
    assert_eq!(f, Fault::IndexOutOfRange);
}

/// A function block's VAR_IN_OUT: copied in before the call and back after it, so the
/// block's writes reach the caller's variable (an elementary one, and a structure leaf by
/// leaf); a value that is no variable, or a variable of another type, is refused at load.
#[test]
fn var_in_out_of_a_function_block_reaches_the_callers_variable() {
    let text = "TYPE ST_Count : STRUCT n : DINT; x : LREAL; END_STRUCT END_TYPE
FUNCTION_BLOCK FB_Step
VAR_IN_OUT
    nCount : DINT;
    stCount : ST_Count;
END_VAR
VAR_INPUT
    nBy : DINT;
END_VAR
    nCount := nCount + nBy;
    stCount.n := stCount.n + 1;
    stCount.x := stCount.x + 0.5;
END_FUNCTION_BLOCK
PROGRAM MAIN
VAR
    fb : FB_Step;
    n : DINT := 10;
    st : ST_Count;
    n2, m : DINT;
    x : LREAL;
END_VAR
    fb(nCount := n, stCount := st, nBy := 3);
    m := st.n;
    x := st.x;
END_PROGRAM
";
    let p = run(text, 4);
    assert_eq!(p.read_var("MAIN.n"), Some(22.0), "10 + 4 x 3");
    assert_eq!(p.read_var("MAIN.m"), Some(4.0));
    assert_eq!(p.read_var("MAIN.x"), Some(2.0));
    for (call, why) in [
        ("fb(nCount := 5, stCount := st);", "only a variable"),
        (
            "fb(nCount := x, stCount := st);",
            "a LREAL for a VAR_IN_OUT of DINT",
        ),
    ] {
        let bad = text.replace("fb(nCount := n, stCount := st, nBy := 3);", call);
        let refused = Program::load(&[("main.st", &bad)]).unwrap_err();
        let text: Vec<String> = refused.iter().map(|d| d.to_string()).collect();
        assert!(text.iter().any(|t| t.contains(why)), "{call}: {text:?}");
    }
}

/// STRINGs compare by their characters before the NUL: a variable with a literal, two
/// variables of other sizes; `<>` the opposite.
#[test]
fn strings_compare_by_their_characters() {
    let text = "PROGRAM MAIN
VAR
    s : STRING(20) := 'part.nc';
    t : STRING(8) := 'part.nc';
    u : STRING(20) := 'part.n';
    n : INT;
END_VAR
    n := 0;
    IF s = 'part.nc' THEN n := n + 1; END_IF
    IF s = t THEN n := n + 10; END_IF
    IF s <> u THEN n := n + 100; END_IF
    IF u = 'part.nc' THEN n := n + 1000; END_IF
    IF 'part.n' = u THEN n := n + 10000; END_IF
END_PROGRAM
";
    assert_eq!(run(text, 1).read_var("MAIN.n"), Some(10111.0));
}

/// A CASE, an IF or a loop as an arm's statement is a statement, not the next arm's labels
/// (each holds a `:` of its own; the random programs of `two_ways.rs` found it refused).
#[test]
fn statements_with_labels_of_their_own_nest_in_case_arms() {
    let p = run(
        "PROGRAM MAIN VAR i, j, n : DINT; END_VAR
CASE i OF
    0: CASE j OF
            0: n := n + 1;
        ELSE
            n := -100;
        END_CASE
       IF n > 1 THEN CASE n OF 2: i := 1; END_CASE END_IF
    1..2: FOR j := 0 TO 2 DO CASE j OF 2: n := n + 10; END_CASE END_FOR
END_CASE
END_PROGRAM",
        3,
    );
    // Cycle 1: n = 1; cycle 2: n = 2, i = 1; cycle 3: n = 12.
    assert_eq!(p.read_var("MAIN.n"), Some(12.0));
    assert_eq!(p.read_var("MAIN.i"), Some(1.0));
}

/// `TO_<type>(x)`: the named conversion from `x`'s type (`TO_LREAL(n)` of a DINT is
/// `DINT_TO_LREAL(n)`), to and from STRING, nested, in an initial value.
#[test]
fn to_type_converts_from_the_values_type() {
    let mut p = load(
        "PROGRAM MAIN
VAR
    n : DINT := 7;
    r, rHalf, rTime : LREAL;
    i : INT;
    s : STRING;
    t : TIME := T#1500MS;
    u : USINT;
    b : BOOL := TRUE;
    nBack : DINT;
    rInit : LREAL := TO_LREAL(3) / 2.0;
    bOk : BOOL;
    fbs : ARRAY[0..1] OF TON;
    to_time : TON; (* a variable named like a conversion is the variable *)
END_VAR
    rHalf := TO_LREAL(n) / 2.0;
    i := TO_INT(rHalf);
    s := TO_STRING(n);
    nBack := TO_DINT(TO_STRING(i + 38));
    rTime := TO_LREAL(t);
    b := TO_BOOL(u);
    bOk := TO_STRING(rHalf) = '3.5' AND TO_UINT(TO_STRING(TO_USINT(300 - 45))) = 255
        AND TO_STRING(TO_STRING(n)) = '7';
    fbs[TO_INT(rHalf) - 3](IN := TRUE, PT := T#0MS);
    to_time(IN := TRUE, PT := T#0MS);
END_PROGRAM",
    );
    p.cycle(0)
        .unwrap_or_else(|f| panic!("{}", p.fault_text(&f)));
    let v = |name: &str| p.read_var(&format!("MAIN.{name}"));
    assert_eq!(v("rHalf"), Some(3.5));
    assert_eq!(v("i"), Some(4.0), "LREAL_TO_INT rounds");
    assert_eq!(v("nBack"), Some(42.0));
    assert_eq!(v("rTime"), Some(1500.0), "a TIME's ms");
    assert_eq!(v("b"), Some(0.0));
    assert_eq!(v("rInit"), Some(1.5));
    assert_eq!(v("bOk"), Some(1.0));
    let q = |path: &str| {
        p.symbols(100)
            .into_iter()
            .find(|s| s.path == path)
            .map(|s| p.memory()[s.offset as usize])
    };
    assert_eq!(
        q("MAIN.fbs[1].Q"),
        Some(1),
        "the element TO_INT(rHalf) - 3 names"
    );
    assert_eq!(q("MAIN.to_time.Q"), Some(1));
}

/// VAR_EXTERNAL names the global of that name (it declared a separate variable of the
/// POU's: a write through it never reached the global); one without a global of its name
/// and type is refused.
#[test]
fn var_external_names_the_global() {
    let p = run(
        "VAR_GLOBAL g : INT := 5; END_VAR
PROGRAM MAIN
VAR_EXTERNAL g : INT; END_VAR
VAR n : INT; END_VAR
    g := g + 1;
    n := g;
END_PROGRAM
PROGRAM P2
VAR m : INT; END_VAR
    m := g;
END_PROGRAM",
        1,
    );
    assert_eq!(p.read_var("MAIN.n"), Some(6.0));
    assert_eq!(p.read_var("P2.m"), Some(6.0));
    let e = refused("PROGRAM MAIN VAR_EXTERNAL h : INT; END_VAR END_PROGRAM");
    assert!(
        e.contains("main.st:1:27: error: VAR_EXTERNAL `h`: no global variable of that name"),
        "{e}"
    );
    let e = refused(
        "VAR_GLOBAL g : INT; END_VAR\nPROGRAM MAIN VAR_EXTERNAL g : DINT; END_VAR END_PROGRAM",
    );
    assert!(
        e.contains("main.st:2:27: error: VAR_EXTERNAL `g` is DINT: the global is INT"),
        "{e}"
    );
}
