//! The overloaded conversions `TO_<type>(x)` of IEC 61131-3 (TwinCAT 3, CODESYS): each is the
//! named conversion from its value's type (`TO_LREAL(n)` of a DINT is `DINT_TO_LREAL(n)`),
//! to and from STRING too, nested, in initial values; a value of no elementary type or
//! STRING, and a POU taking such a name, are refused at load.

use plc_st::vm::Program;

fn load(text: &str) -> Program {
    Program::load(&[("main.st", text)]).unwrap_or_else(|e| {
        panic!(
            "{}",
            e.iter().map(|d| d.to_string() + "\n").collect::<String>()
        )
    })
}

fn refused(text: &str) -> String {
    match Program::load(&[("main.st", text)]) {
        Ok(_) => panic!("loaded: {text}"),
        Err(e) => e.iter().map(|d| d.to_string() + "\n").collect(),
    }
}

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
END_VAR
    rHalf := TO_LREAL(n) / 2.0;
    i := TO_INT(rHalf);
    s := TO_STRING(n);
    nBack := TO_DINT(TO_STRING(i + 38));
    rTime := TO_LREAL(t);
    b := TO_BOOL(u);
    bOk := TO_STRING(rHalf) = '3.5' AND TO_UINT(TO_STRING(TO_USINT(300 - 45))) = 255;
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
}

#[test]
fn to_type_of_no_elementary_value_or_as_a_name_is_refused() {
    let e = refused(
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
    let e = refused("PROGRAM MAIN VAR i : INT; END_VAR i := TO_INT(nope) + TO_INT(i); END_PROGRAM");
    assert_eq!(
        e.trim(),
        "main.st:1:47: error: unknown name `nope`",
        "the value's own error, once"
    );
    let e = refused("FUNCTION TO_LREAL : LREAL TO_LREAL := 1.0; END_FUNCTION");
    assert!(e.contains("`TO_LREAL` is a standard name"), "{e}");
    let e = refused("PROGRAM MAIN VAR s : STRING; END_VAR s := TO_STRING(1, 2); END_PROGRAM");
    assert!(
        e.contains("main.st:1:43: error: TO_STRING takes one value, by position"),
        "{e}"
    );
}
