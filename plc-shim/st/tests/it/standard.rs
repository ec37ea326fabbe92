//! Standard functions and blocks beyond the ones the manuals' programs use: CTUD, EXPT, MOVE,
//! each against the standard's rules; and TwinCAT's and CODESYS's AND_THEN and OR_ELSE.

use plc_st::vm::Program;

use crate::support::{refused, run};

/// CTUD: LOAD sets CV to PV, rising CU counts up, rising CD down, both rising at once leave
/// CV, RESET wins over everything; QU is CV >= PV, QD is CV <= 0.
#[test]
fn an_up_down_counter_counts_edges_and_obeys_reset_before_load() {
    let p = run(
        "PROGRAM MAIN
VAR
    c : CTUD;
    n : INT;
    cu, cd, rst, ld : BOOL;
    cvs : LINT;
    qus, qds : DINT;
END_VAR
    cu := FALSE; cd := FALSE; rst := FALSE; ld := FALSE;
    CASE n OF
        0: ld := TRUE;
        1, 2: cu := TRUE;
        4: cu := TRUE; cd := TRUE;
        6, 8: cd := TRUE;
        9: rst := TRUE; cu := TRUE;
        10: ld := TRUE; rst := TRUE;
    END_CASE
    c(CU := cu, CD := cd, RESET := rst, LOAD := ld, PV := 2);
    cvs := cvs * 10 + c.CV;
    qus := qus * 2 + BOOL_TO_DINT(c.QU);
    qds := qds * 2 + BOOL_TO_DINT(c.QD);
    n := n + 1;
END_PROGRAM",
        11,
    );
    // Cycle by cycle: load 2, up, held, -, both, -, down, -, down, reset (CU ignored),
    // reset with load.
    assert_eq!(p.read_var("MAIN.cvs"), Some(23_333_322_100.0));
    assert_eq!(p.read_var("MAIN.qus"), Some(f64::from(0b111_1111_1000)));
    assert_eq!(p.read_var("MAIN.qds"), Some(f64::from(0b000_0000_0011)));
}

/// EXPT(ANY_REAL, ANY_NUM) and MOVE: an integer exponent taken as a real, a REAL's power a
/// REAL; a power that is no number is a fault (as SQRT(-1.0) is); MOVE gives its value.
#[test]
fn expt_takes_a_real_to_a_power_and_move_gives_its_value() {
    let p = run(
        "PROGRAM MAIN
VAR
    r1, r2 : LREAL;
    f : REAL;
    n : INT := 3;
    m : DINT;
END_VAR
    r1 := EXPT(2.0, 10);
    r2 := EXPT(r1, 0.5);
    f := EXPT(REAL#1.5, n);
    m := MOVE(DINT#-7);
END_PROGRAM",
        1,
    );
    assert_eq!(p.read_var("MAIN.r1"), Some(1024.0));
    assert_eq!(p.read_var("MAIN.r2"), Some(32.0));
    assert_eq!(p.read_var("MAIN.f"), Some(3.375));
    assert_eq!(p.read_var("MAIN.m"), Some(-7.0));
    let mut p = Program::load(&[(
        "main.st",
        "PROGRAM MAIN VAR r : LREAL := -8.0; END_VAR\n  r := EXPT(r, 0.5);\nEND_PROGRAM",
    )])
    .unwrap();
    let f = p.cycle(0).unwrap_err();
    assert_eq!(
        p.fault_text(&f),
        "main.st:2:3: fault: a conversion of a value its type cannot hold"
    );
}

/// What EXPT and MOVE do not take is refused at load with its place.
#[test]
fn expt_of_an_integer_base_or_move_of_no_value_is_refused() {
    for (text, want) in [
        (
            "n := EXPT(n, 2);",
            "main.st:2:8: error: EXPT does not take these values",
        ),
        (
            "n := MOVE(n, n);",
            "main.st:2:8: error: MOVE does not take these values",
        ),
        (
            "r := EXPT(2.0, T#1S);",
            "main.st:2:8: error: EXPT does not take these values",
        ),
        (
            "r := EXPT(2.0, WORD#3);",
            "main.st:2:8: error: EXPT does not take these values",
        ),
    ] {
        let src = format!("PROGRAM MAIN VAR n : DINT; r : LREAL; END_VAR\n  {text}\nEND_PROGRAM");
        let e = refused(&src);
        assert!(e.contains(want), "{text}: {e}");
    }
}

/// AND_THEN and OR_ELSE compute their right value only when the left does not decide: a
/// NULL pointer is not read behind `p <> 0 AND_THEN`, a function on the right is not called;
/// in an IF's condition as in an assignment.
#[test]
fn and_then_and_or_else_compute_the_right_value_only_when_needed() {
    let p = run(
        "FUNCTION Count : BOOL
VAR_INPUT v : BOOL; END_VAR
    g := g + 1;
    Count := v;
END_FUNCTION
VAR_GLOBAL g : DINT; END_VAR
PROGRAM MAIN
VAR
    p : POINTER TO DINT;
    n : DINT := 5;
    a, b, c, d, e, f : BOOL;
    k : DINT;
END_VAR
    a := p <> 0 AND_THEN p^ > 3;
    IF p = 0 OR_ELSE p^ < 0 THEN k := k + 1; END_IF
    p := ADR(n);
    b := p <> 0 AND_THEN p^ > 3;
    c := p = 0 OR_ELSE p^ < 0;
    g := 0;
    d := Count(TRUE) OR_ELSE Count(TRUE);
    e := Count(FALSE) AND_THEN Count(TRUE);
    f := Count(TRUE) OR_ELSE Count(FALSE) AND_THEN Count(FALSE);
    k := k + 10 * g;
END_PROGRAM",
        1,
    );
    let var = |n: &str| p.read_var(n);
    assert_eq!(var("MAIN.a"), Some(0.0), "NULL: its value not read");
    assert_eq!(
        var("MAIN.k"),
        Some(31.0),
        "the IF's THEN, and one call each for d, e, f"
    );
    assert_eq!((var("MAIN.b"), var("MAIN.c")), (Some(1.0), Some(0.0)));
    assert_eq!((var("MAIN.d"), var("MAIN.e")), (Some(1.0), Some(0.0)));
    assert_eq!(var("MAIN.f"), Some(1.0), "AND_THEN binds before OR_ELSE");
    let e = refused(
        "PROGRAM MAIN VAR n : DINT; b : BOOL; END_VAR\n  b := n AND_THEN TRUE;\nEND_PROGRAM",
    );
    assert!(e.contains("main.st:2:10: error: AND_THEN of"), "{e}");
}

/// `TIME()` and `LTIME()` (TwinCAT): the PLC's clock, the one its timers run on; a duration
/// measured as their difference.
#[test]
fn time_and_ltime_read_the_plcs_clock() {
    let p = run(
        "PROGRAM MAIN
VAR
    t0, t, d : TIME;
    lt : LTIME;
    started : BOOL;
END_VAR
    IF NOT started THEN t0 := TIME(); started := TRUE; END_IF
    t := TIME();
    lt := LTIME();
    d := TIME() - t0;
END_PROGRAM",
        4,
    );
    // The fourth cycle, at 30 ms.
    assert_eq!(p.read_var("MAIN.t"), Some(30.0));
    assert_eq!(p.read_var("MAIN.lt"), Some(30_000_000.0));
    assert_eq!(p.read_var("MAIN.d"), Some(30.0));
    let e = refused("PROGRAM MAIN VAR t : TIME; END_VAR\n  t := TIME(1);\nEND_PROGRAM");
    assert!(
        e.contains("main.st:2:8: error: TIME does not take these values"),
        "{e}"
    );
}

/// `S=` and `R=` (TwinCAT, CODESYS): the target set (reset) while the condition holds, kept
/// otherwise; a target that is no BOOL is refused.
#[test]
fn set_and_reset_assignments_latch() {
    let p = run(
        "PROGRAM MAIN
VAR
    n : INT;
    bOn : BOOL;
    bOff : BOOL := TRUE;
    nOnAt, nOffAt : INT := -1;
END_VAR
    bOn S= n = 2;
    bOff R= n >= 3;
    IF bOn AND nOnAt < 0 THEN nOnAt := n; END_IF
    IF NOT bOff AND nOffAt < 0 THEN nOffAt := n; END_IF
    n := n + 1;
END_PROGRAM",
        5,
    );
    assert_eq!(p.read_var("MAIN.bOn"), Some(1.0), "set at 2, kept after");
    assert_eq!(p.read_var("MAIN.nOnAt"), Some(2.0));
    assert_eq!(p.read_var("MAIN.bOff"), Some(0.0));
    assert_eq!(p.read_var("MAIN.nOffAt"), Some(3.0));
    let e = refused("PROGRAM MAIN VAR n : INT; END_VAR\n  n S= TRUE;\nEND_PROGRAM");
    assert!(
        e.starts_with("main.st:2:5: error: BOOL where INT is wanted"),
        "{e}"
    );
}

/// TRUNC_INT (CODESYS's and TwinCAT's): a real cut toward zero to an INT; one an INT cannot
/// hold is a fault, as TRUNC's beyond DINT.
#[test]
fn trunc_int_cuts_toward_zero_to_an_int() {
    let p = crate::support::run(
        "PROGRAM MAIN VAR up, down : INT; r : REAL := -2.7; END_VAR
    up := TRUNC_INT(2.7);
    down := TRUNC_INT(r);
END_PROGRAM",
        1,
    );
    assert_eq!(p.read_var("MAIN.up"), Some(2.0));
    assert_eq!(p.read_var("MAIN.down"), Some(-2.0));
    let mut p = Program::load(&[(
        "main.st",
        "PROGRAM MAIN VAR i : INT; r : LREAL := 40000.0; END_VAR\n  i := TRUNC_INT(r);\nEND_PROGRAM",
    )])
    .unwrap();
    let f = p.cycle(0).unwrap_err();
    assert_eq!(
        p.fault_text(&f),
        "main.st:2:3: fault: a conversion of a value its type cannot hold"
    );
}
