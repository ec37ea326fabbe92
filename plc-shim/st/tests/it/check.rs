//! The checker on programs in the manuals' style and on programs with mistakes: every
//! refusal with its file, line and column, all of them in one pass.

use plc_st::check::{check, Checked, Type};
use plc_st::types::Elem;
use plc_st::{parse_file, Diagnostic};

fn data(name: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    std::fs::read_to_string(path).unwrap()
}

fn checked(files: &[(&str, &str)]) -> Result<Checked, Vec<Diagnostic>> {
    let units: Vec<(String, plc_st::ast::Unit)> = files
        .iter()
        .map(|(name, text)| (name.to_string(), parse_file(name, text).unwrap()))
        .collect();
    check(&units)
}

/// The refusals of one program `body` inside `PROGRAM P` with `vars`, as text.
fn refusals(vars: &str, body: &str) -> Vec<String> {
    let text = format!("PROGRAM P\nVAR\n{vars}\nEND_VAR\n{body}\nEND_PROGRAM\n");
    match checked(&[("p.st", &text)]) {
        Ok(_) => Vec::new(),
        Err(e) => e.iter().map(|d| d.to_string()).collect(),
    }
}

#[test]
fn the_master_program_checks_against_the_hli_types() {
    let hli = hli::st_prelude::generate();
    let main = data("rotary_master.st");
    let c = checked(&[("hli.st", &hli), ("rotary_master.st", &main)]).unwrap_or_else(|e| {
        panic!(
            "{}",
            e.iter().map(|d| d.to_string() + "\n").collect::<String>()
        )
    });
    let main = c.pous.iter().find(|p| p.name == "MAIN").unwrap();
    let pointer = main.vars.iter().find(|v| v.name == "pDynCs").unwrap();
    let unit = c
        .structs
        .iter()
        .position(|s| s.name == "MC_CONTROL_DYN_CS_UNIT")
        .unwrap();
    assert_eq!(pointer.ty, Type::Pointer(Box::new(Type::Struct(unit))));
    let table = c.enums.iter().find(|e| e.name == "E_TableStep").unwrap();
    assert_eq!(table.base, Elem::Int);
    assert_eq!(table.values[3], ("Disable".to_string(), 3));
}

#[test]
fn mistakes_are_refused_each_with_its_place() {
    let cases: &[(&str, &str, &str)] = &[
        (
            "x : INT;",
            "x := 70000;",
            "p.st:5:6: error: 70000 does not fit INT",
        ),
        ("x : INT;", "x := y;", "p.st:5:6: error: unknown name `y`"),
        (
            "x : INT; d : DINT;",
            "x := d;",
            "p.st:5:6: error: DINT where INT is wanted",
        ),
        (
            "b : BOOL;",
            "IF 1 THEN b := TRUE; END_IF",
            "p.st:5:4: error: a condition is BOOL, not DINT",
        ),
        ("b : BOOL;", "b := b + 1;", "p.st:5:8: error: `+` of BOOL"),
        (
            "x : INT;",
            "x := DINT#70000;",
            "p.st:5:6: error: DINT where INT is wanted",
        ),
        (
            "x : INT;",
            "x := INT#70000;",
            "p.st:5:10: error: 70000 does not fit INT",
        ),
        (
            "a : ARRAY[0..2] OF INT;",
            "a[3] := 1;",
            "p.st:5:3: error: index 3 outside [0..2]",
        ),
        (
            "t : TON;",
            "t(IN := TRUE, PT := 5);",
            "p.st:5:21: error: DINT where TIME is wanted",
        ),
        (
            "t : TON;",
            "t(IN := TRUE, Q := TRUE);",
            "p.st:5:15: error: `Q` is an output",
        ),
        (
            "t : TON;",
            "t.Q := TRUE;",
            "p.st:5:1: error: an instance's inputs are set in its call",
        ),
        (
            "",
            "EXIT;",
            "p.st:5:1: error: EXIT and CONTINUE belong in a loop",
        ),
        (
            "r : REAL;",
            "r := SQRT(TRUE);",
            "p.st:5:6: error: SQRT does not take these values",
        ),
        (
            "p : POINTER TO INT; x : DINT;",
            "p := ADR(x);",
            "p.st:5:6: error: POINTER TO DINT where POINTER TO INT is wanted",
        ),
        (
            "x : INT;",
            "x.Y := 1;",
            "p.st:5:3: error: `.Y` of a value without fields",
        ),
        (
            "s : UNKNOWN_T;",
            "",
            "p.st:3:5: error: unknown type `UNKNOWN_T`",
        ),
        (
            "x : INT := TRUE;",
            "",
            "p.st:3:12: error: BOOL where INT is wanted",
        ),
    ];
    for (vars, body, expect) in cases {
        let got = refusals(vars, body);
        assert!(
            got.iter().any(|g| g.starts_with(expect)),
            "{vars} / {body}:\n  got {got:?}\n  want {expect}"
        );
    }
}

#[test]
fn every_refusal_is_reported_in_one_pass() {
    let got = refusals("x : INT;", "x := y;\nx := z;\nx := TRUE;");
    assert_eq!(got.len(), 3, "{got:?}");
    assert!(got[0].starts_with("p.st:5:"), "{got:?}");
    assert!(got[2].starts_with("p.st:7:"), "{got:?}");
}

#[test]
fn recursion_and_names_declared_twice_are_refused() {
    let text = "FUNCTION A : INT\nVAR_INPUT n : INT; END_VAR\nA := B(n);\nEND_FUNCTION\n\
                FUNCTION B : INT\nVAR_INPUT n : INT; END_VAR\nB := A(n);\nEND_FUNCTION\n";
    let e = checked(&[("r.st", text)]).unwrap_err();
    assert!(e[0].to_string().contains("calls itself"), "{e:?}");
    let twice = "TYPE T : STRUCT a : INT; END_STRUCT END_TYPE\nTYPE T : (X, Y); END_TYPE\n";
    let e = checked(&[("t.st", twice)]).unwrap_err();
    assert!(e[0].to_string().contains("`T` is declared twice"), "{e:?}");
}

#[test]
fn widening_literals_and_standard_blocks_check() {
    let ok = refusals(
        "i : INT; d : DINT; r : REAL; l : LREAL; w : WORD; t : TON; e : R_TRIG; b : BOOL;\n\
         a : ARRAY[1..4] OF LREAL; u : UDINT;",
        "d := i; l := r; r := i; i := -5; w := 16#FFFF; r := 1.5;\n\
         t(IN := b, PT := T#2S); e(CLK := t.Q, Q => b);\n\
         l := MAX(1.0, l, a[1]); i := LIMIT(0, i, 100); u := UDINT#0;\n\
         d := LREAL_TO_DINT(l * 10000.0); b := w.15 AND NOT e.Q;\n\
         FOR i := 1 TO 4 DO a[i] := SEL(b, 0.0, l); END_FOR",
    );
    assert!(ok.is_empty(), "{ok:?}");
}

#[test]
fn adr_of_an_array_points_to_its_elements() {
    assert_eq!(
        refusals(
            "a : ARRAY[0..3, 0..1] OF LREAL; p : POINTER TO LREAL; q : POINTER TO INT;",
            "p := ADR(a); q := ADR(a);"
        ),
        vec!["p.st:5:19: error: POINTER TO ARRAY[0..3, 0..1] OF LREAL where POINTER TO INT is wanted".to_string()]
    );
}

/// An instance's state is its block's: ADR of an instance or of anything in it, and copies of
/// arrays or structures that hold instances, are refused (a library block writes its
/// outputs itself, only when they change).
#[test]
fn adr_of_an_instance_and_copies_of_instances_are_refused() {
    let vars =
        "fbT : TON; aTon, aTof : ARRAY[0..1] OF TON; p : POINTER TO BOOL; q : POINTER TO TON;";
    let refused = refusals(
        vars,
        "p := ADR(fbT.Q);\nq := ADR(fbT);\naTon := aTof;\np := ADR(aTon[1].Q);",
    );
    let adr = "ADR of a function block instance or its member";
    assert_eq!(refused.len(), 4, "{refused:?}");
    assert!(refused[0].starts_with("p.st:5:10: error: ") && refused[0].contains(adr));
    assert!(refused[1].starts_with("p.st:6:10: error: ") && refused[1].contains(adr));
    assert!(refused[2].contains("p.st:7:1: error: function block instances are not copied"));
    assert!(refused[3].starts_with("p.st:8:10: error: ") && refused[3].contains(adr));
}

/// The refusals of a whole file `main.st`, as text.
fn refused_text(text: &str) -> String {
    match checked(&[("main.st", text)]) {
        Ok(_) => panic!("checked: {text}"),
        Err(e) => e.iter().map(|d| d.to_string() + "\n").collect(),
    }
}

/// `TO_<type>` of no elementary value or STRING, with another count of values, or as a POU's
/// name: refused with its place.
#[test]
fn to_type_of_no_elementary_value_or_as_a_name_is_refused() {
    let e = refused_text(
        "TYPE E_Step : (Idle, Run); END_TYPE
PROGRAM MAIN VAR e : E_Step; i : INT; END_VAR
    i := TO_INT(e);
END_PROGRAM",
    );
    assert!(
        e.contains("main.st:3:17: error: TO_INT of a E_Step: it converts a value of an elementary type or a STRING"),
        "{e}"
    );
    assert!(!e.contains("unknown function"), "{e}");
    let e = refused_text(
        "PROGRAM MAIN VAR i : INT; END_VAR i := TO_INT(nope) + TO_INT(i); END_PROGRAM",
    );
    assert_eq!(
        e.trim(),
        "main.st:1:47: error: unknown name `nope`",
        "the value's own error, once"
    );
    let e = refused_text("FUNCTION TO_LREAL : LREAL TO_LREAL := 1.0; END_FUNCTION");
    assert!(e.contains("`TO_LREAL` is a standard name"), "{e}");
    let e = refused_text("PROGRAM MAIN VAR s : STRING; END_VAR s := TO_STRING(1, 2); END_PROGRAM");
    assert!(
        e.contains("main.st:1:43: error: TO_STRING takes one value, by position"),
        "{e}"
    );
}

/// What the language reads but the runtime does not hold is refused by name, never taken as
/// something else: a WSTRING is no STRING, a REFERENCE inside another type no POINTER (a
/// variable's own REFERENCE TO is supported: tests/references.rs).
#[test]
fn references_and_wide_strings_are_refused_by_name() {
    let e = refusals("r : ARRAY[0..1] OF REFERENCE TO INT;\nw : WSTRING;", "");
    assert_eq!(e.len(), 2, "{e:?}");
    assert!(
        e[0].starts_with("p.st:3:20: error: REFERENCE TO inside a type"),
        "{e:?}"
    );
    assert!(
        e[1].starts_with("p.st:4:5: error: WSTRING is not supported"),
        "{e:?}"
    );
}

/// The calendar types are refused by name (they were `unknown type`; their literals are
/// refused by the lexer, tests/parse.rs).
#[test]
fn dates_and_times_of_day_are_refused_by_name() {
    let e = refusals("dt : DATE_AND_TIME;\nd : DATE;\ntod : TOD;", "");
    assert_eq!(e.len(), 3, "{e:?}");
    for (k, (line, name)) in [(3, "DATE_AND_TIME"), (4, "DATE"), (5, "TOD")]
        .iter()
        .enumerate()
    {
        let col = if k == 0 {
            6
        } else if k == 1 {
            5
        } else {
            7
        };
        assert_eq!(
            e[k],
            format!(
                "p.st:{line}:{col}: error: DATE, TIME_OF_DAY and DATE_AND_TIME are not \
                 supported: the PLC's clock is TIME() or LTIME(), durations are TIME and \
                 LTIME (`{name}`)"
            )
        );
    }
}

/// `D#On` of an enumeration named D is its typed literal: only a calendar literal (digits
/// after `D#`, `DT#`, ...) is refused.
#[test]
fn an_enumeration_named_like_a_calendar_prefix_keeps_its_typed_literals() {
    let text = "TYPE D : (Off, On); END_TYPE\nPROGRAM P\nVAR x : D; END_VAR\n    x := D#On;\nEND_PROGRAM\n";
    assert!(checked(&[("p.st", text)]).is_ok());
}
