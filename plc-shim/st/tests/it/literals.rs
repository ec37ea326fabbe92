//! Untyped real literals take the real type they meet, as untyped integer literals take
//! the integer's: `r := r / 2.0;`, `r := -2.5;`, `LIMIT(0.0, r, 1.0)` and `r > 0.1` of a
//! REAL `r` compute in REAL (IEC 61131-3's typing of literals by their context, as TwinCAT
//! and CODESYS accept them). A typed literal (`LREAL#0.1`) keeps its type; a literal a
//! REAL cannot hold is refused where it meets one. `NOT` of an untyped integer literal
//! takes the integer or bit string it meets, NOT in that type's width (`w AND NOT 16#0F`).

use crate::support::{refused, run};

#[test]
fn real_literals_compute_in_the_real_they_meet() {
    let p = run(
        "PROGRAM MAIN
VAR
    r : REAL := -1.5;
    third, tenth, limited, most, lr : REAL;
    d : LREAL;
    below, above, typed : BOOL;
    k : INT;
END_VAR
    r := -2.5 * r;
    third := 1.0;
    third := third / 3.0;
    tenth := 0.1;
    below := tenth > 0.1;
    typed := tenth > LREAL#0.1;
    above := tenth >= 0.1;
    limited := LIMIT(0.0, r, 1.0);
    most := MAX(tenth, 0.5);
    lr := ABS(tenth - 0.5);
    d := 1.0;
    d := d / 3.0;
    k := REAL_TO_INT(2.7);
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!(var("r"), 3.75);
    // REAL's rounding: one third and one tenth as 32 bits hold them.
    assert_eq!(var("third"), f64::from(1.0f32 / 3.0f32));
    assert_eq!(var("tenth"), f64::from(0.1f32));
    // Compared in REAL: the literal rounded as the variable was. As LREAL (the typed
    // literal) the REAL's 0.1 is the larger.
    assert_eq!(var("below"), 0.0);
    assert_eq!(var("above"), 1.0);
    assert_eq!(var("typed"), 1.0);
    assert_eq!(var("limited"), 1.0);
    assert_eq!(var("most"), 0.5);
    assert_eq!(var("lr"), f64::from((0.1f32 - 0.5f32).abs()));
    assert_eq!(var("d"), 1.0 / 3.0);
    assert_eq!(var("k"), 3.0);
}

#[test]
fn a_literal_a_real_cannot_hold_is_refused_where_it_meets_one() {
    let text = |body: &str| {
        format!("PROGRAM MAIN\nVAR\n    r : REAL;\n    i : INT;\nEND_VAR\n{body}\nEND_PROGRAM")
    };
    assert_eq!(
        refused(&text("    r := 1.0E300;")),
        "main.st:6:10: error: LREAL where REAL is wanted\n"
    );
    assert_eq!(
        refused(&text("    r := MAX(r, -1.0E300);")),
        "main.st:6:17: error: -1e300 does not fit REAL\n"
    );
    assert_eq!(
        refused(&text("    i := i + 2.5;")),
        "main.st:6:10: error: LREAL where INT is wanted\n"
    );
}

#[test]
fn not_of_an_integer_literal_is_taken_in_the_width_it_meets() {
    let p = run(
        "PROGRAM MAIN
VAR
    w : WORD := 16#00FF;
    b : BYTE := NOT 1;
    d : DINT := 7;
END_VAR
    w := w AND NOT 16#0F;
    d := d AND NOT 1;
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!((var("w"), var("b"), var("d")), (240.0, 254.0, 6.0));
    assert_eq!(
        refused(
            "PROGRAM MAIN\nVAR\n    w : WORD;\nEND_VAR\n    w := w AND NOT 70000;\nEND_PROGRAM"
        ),
        "main.st:5:12: error: AND of WORD and DINT\n"
    );
}

/// An untyped real beside integers only keeps its LREAL (`MAX(i, 2.5)` of an INT `i`), and
/// a conversion still takes any integer literal (`TIME_TO_DINT(5)`, as before real literals
/// took their context's type); what does not fit a REAL is named as written.
#[test]
fn a_real_literal_beside_integers_stays_an_lreal() {
    let p = run(
        "PROGRAM MAIN
VAR
    i : INT := 1;
    lr : LREAL;
    d : DINT;
END_VAR
    lr := MAX(i, 2.5);
    d := TIME_TO_DINT(5);
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!((var("lr"), var("d")), (2.5, 5.0));
    assert_eq!(
        refused("PROGRAM MAIN\nVAR\n    r : REAL;\nEND_VAR\n    r := MAX(r, NOT 5);\nEND_PROGRAM"),
        "main.st:5:17: error: NOT 5 does not fit REAL\n"
    );
}

/// A constant expression of untyped literals is folded at load and then taken as one
/// literal: an INT takes `200 * 2`, a REAL `100.0 / 60.0`, a CASE label `2 * 3`; one that
/// a type cannot hold is refused with its value (before, `200 * 2` was a DINT an INT
/// refused, and `2147483647 + 1` wrapped in DINT at run time).
#[test]
fn constant_expressions_of_literals_take_the_type_they_meet() {
    let p = run(
        "PROGRAM MAIN
VAR
    i, j, m, q, c : INT;
    b : BYTE;
    r : REAL;
    lr : LREAL;
    big : LINT;
END_VAR
    i := 200 * 2;
    j := -(60 * 10) + 7 / 2;
    m := -7 MOD 3;
    b := 16#F0 + 15;
    r := 100.0 / 60.0;
    lr := 10 ** 2;
    big := 2147483647 + 1;
    q := i * (2 + 1);
    CASE j OF
        -2 * 300 + 3: c := 1;
    ELSE
        c := 2;
    END_CASE
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!(var("i"), 400.0);
    assert_eq!(var("j"), -597.0);
    assert_eq!(var("m"), -1.0);
    assert_eq!(var("b"), 255.0);
    assert_eq!(var("r"), f64::from((100.0f64 / 60.0) as f32));
    assert_eq!(var("big"), 2147483648.0);
    assert_eq!(var("lr"), 100.0);
    assert_eq!(var("q"), 1200.0);
    assert_eq!(var("c"), 1.0);
    let text = |body: &str| {
        format!("PROGRAM MAIN\nVAR\n    i : INT;\n    d : DINT;\nEND_VAR\n{body}\nEND_PROGRAM")
    };
    assert_eq!(
        refused(&text("    i := 30000 + 30000;")),
        "main.st:6:10: error: 60000 does not fit INT\n"
    );
    assert_eq!(
        refused(&text("    d := 2147483647 + 1;")),
        "main.st:6:10: error: 2147483648 does not fit DINT\n"
    );
}

/// SEL, MUX, MIN, MAX and LIMIT of untyped literals take the type they meet as the
/// literals would (`nSpeed := SEL(bFast, 10, 100);` of an INT was refused: DINT where INT is
/// wanted); a literal the type cannot hold is still refused.
#[test]
fn selections_of_literals_take_the_type_they_meet() {
    let p = run(
        "PROGRAM MAIN
VAR
    fast : BOOL := TRUE;
    k : INT := 2;
    s, m, x, l : INT;
    r : REAL;
    b : BYTE;
END_VAR
    s := SEL(fast, 10, 100);
    m := MUX(k, 1, 2, 3);
    x := MAX(5, 7, -3);
    l := LIMIT(0, 500, 100);
    r := SEL(fast, 0.5, 1.5);
    b := MIN(255, 200);
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!(var("s"), 100.0);
    assert_eq!(var("m"), 3.0);
    assert_eq!(var("x"), 7.0);
    assert_eq!(var("l"), 100.0);
    assert_eq!(var("r"), 1.5);
    assert_eq!(var("b"), 200.0);
    let text = |body: &str| {
        format!("PROGRAM MAIN\nVAR\n    i : INT;\n    c : BOOL;\nEND_VAR\n{body}\nEND_PROGRAM")
    };
    assert_eq!(
        refused(&text("    i := SEL(c, 1, 70000);")),
        "main.st:6:10: error: DINT where INT is wanted\n"
    );
    assert_eq!(
        refused(&text("    i := MIN(c, 1);")),
        "main.st:6:10: error: BOOL where INT is wanted\n"
    );
}
