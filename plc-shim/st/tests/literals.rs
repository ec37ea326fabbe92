//! Untyped real literals take the real type they meet, as untyped integer literals take
//! the integer's: `r := r / 2.0;`, `r := -2.5;`, `LIMIT(0.0, r, 1.0)` and `r > 0.1` of a
//! REAL `r` compute in REAL (IEC 61131-3's typing of literals by their context, as TwinCAT
//! and CODESYS accept them). A typed literal (`LREAL#0.1`) keeps its type; a literal a
//! REAL cannot hold is refused where it meets one. `NOT` of an untyped integer literal
//! takes the integer or bit string it meets, NOT in that type's width (`w AND NOT 16#0F`).

mod support;

use support::{refused, run};

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
        "main.st:6:10: error: a LREAL where a REAL is wanted\n"
    );
    assert_eq!(
        refused(&text("    r := MAX(r, -1.0E300);")),
        "main.st:6:17: error: -1e300 does not fit REAL\n"
    );
    assert_eq!(
        refused(&text("    i := i + 2.5;")),
        "main.st:6:10: error: a LREAL where a INT is wanted\n"
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
