//! REFERENCE TO (TwinCAT 3, CODESYS 3): bound with `REF=`, read and written without `^`,
//! `__ISVALIDREF` tells whether it is bound; an unbound one faults where it is used, as a
//! NULL pointer does. What the runtime does not take is refused by name.

use crate::support::{refused, run};
use plc_st::vm::{Fault, Program};

#[test]
fn a_reference_reads_and_writes_the_variable_it_is_bound_to() {
    let p = run(
        "TYPE ST_Axis : STRUCT fPos : LREAL; nState : INT; END_STRUCT END_TYPE
VAR_GLOBAL
    gAxes : ARRAY[0..2] OF ST_Axis;
    gRef : REFERENCE TO INT;
END_VAR
FUNCTION_BLOCK FB_Pick
VAR_INPUT k : INT; END_VAR
VAR refAxis : REFERENCE TO ST_Axis; END_VAR
VAR_OUTPUT fSeen : LREAL; END_VAR
    refAxis REF= gAxes[k];
    refAxis.nState := refAxis.nState + 1;
    fSeen := refAxis.fPos;
END_FUNCTION_BLOCK
PROGRAM MAIN
VAR
    n, m : INT := 5;
    refN : REFERENCE TO INT;
    refOther : REFERENCE TO INT;
    bBefore, bAfter : BOOL;
    fb : FB_Pick;
    fSeen : LREAL;
    nState : INT;
END_VAR
    bBefore := __ISVALIDREF(refN);
    refN REF= n;
    bAfter := __ISVALIDREF(refN);
    refN := refN + 10;
    refOther REF= refN;
    refOther := refOther * 2;
    gRef REF= m;
    gRef := 1;
    gAxes[2].fPos := 7.5;
    fb(k := 2, fSeen => fSeen);
    nState := gAxes[2].nState;
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!((var("bBefore"), var("bAfter")), (0.0, 1.0));
    // Through refN, then through refOther bound to what refN stands for: n itself.
    assert_eq!(var("n"), 30.0);
    assert_eq!(var("m"), 1.0);
    assert_eq!(var("fSeen"), 7.5);
    assert_eq!(var("nState"), 1.0);
}

/// `r2 REF= r1` copies what r1 stands for, bound or not (an unbound r1 leaves r2 unbound,
/// no fault); `THIS^.r REF= x` and `__ISVALIDREF(THIS^.r)` in a block; a typed literal's
/// enumeration value named as a reference is the value.
#[test]
fn rebinding_copies_what_a_reference_stands_for() {
    let p = run(
        "TYPE E_State : (Idle, Busy) INT; END_TYPE
FUNCTION_BLOCK FB
VAR r : REFERENCE TO INT; x : INT := 4; END_VAR
VAR_OUTPUT bBound : BOOL; n : INT; END_VAR
    THIS^.r REF= x;
    bBound := __ISVALIDREF(THIS^.r);
    n := r;
END_FUNCTION_BLOCK
PROGRAM MAIN
VAR
    refA, refB : REFERENCE TO INT;
    Busy : REFERENCE TO INT;
    e : E_State;
    bB, bBound : BOOL;
    fb : FB;
    n : INT;
END_VAR
    refB REF= refA;
    bB := __ISVALIDREF(refB);
    e := E_State#Busy;
    fb(bBound => bBound, n => n);
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!(var("bB"), 0.0);
    assert_eq!(var("e"), 1.0);
    assert_eq!((var("bBound"), var("n")), (1.0, 4.0));
}

#[test]
fn an_unbound_reference_faults_where_it_is_used() {
    let mut p = Program::load(&[(
        "main.st",
        "PROGRAM MAIN VAR r : REFERENCE TO DINT; x : DINT; END_VAR\n  x := 1;\n  x := r;\nEND_PROGRAM",
    )])
    .unwrap();
    let f = p.cycle(0).unwrap_err();
    assert_eq!(f.fault, Fault::BadPointer);
    assert!(p.fault_text(&f).starts_with("main.st:3:3: fault:"));
}

#[test]
fn what_a_reference_may_not_be_is_refused_by_name() {
    for (text, expect) in [
        (
            "FUNCTION_BLOCK FB VAR_INPUT r : REFERENCE TO INT; END_VAR END_FUNCTION_BLOCK",
            "main.st:1:33: error: a REFERENCE TO input, output or VAR_IN_OUT is not supported",
        ),
        (
            "PROGRAM MAIN VAR a : ARRAY[0..1] OF REFERENCE TO INT; END_VAR END_PROGRAM",
            "main.st:1:37: error: REFERENCE TO inside a type",
        ),
        (
            "PROGRAM MAIN VAR x : INT; r : REFERENCE TO INT := x; END_VAR END_PROGRAM",
            "main.st:1:31: error: a REFERENCE TO has no initial value",
        ),
        (
            "PROGRAM MAIN VAR x, y : INT; END_VAR\n  x REF= y;\nEND_PROGRAM",
            "main.st:2:3: error: REF= binds a REFERENCE TO variable",
        ),
        (
            "PROGRAM MAIN VAR x : INT; b : BOOL; END_VAR\n  b := __ISVALIDREF(x);\nEND_PROGRAM",
            "main.st:2:21: error: __ISVALIDREF of `x`, which is no REFERENCE TO",
        ),
        (
            "PROGRAM MAIN VAR r : REFERENCE TO INT; END_VAR\n  r REF= 5;\nEND_PROGRAM",
            "main.st:2:10: error: REF= binds a REFERENCE TO INT to a variable, not a value",
        ),
        (
            "FUNCTION_BLOCK FB END_FUNCTION_BLOCK\nPROGRAM MAIN VAR r : REFERENCE TO FB; fb : FB; END_VAR\n  r REF= fb;\nEND_PROGRAM",
            "main.st:3:10: error: ADR of a function block instance",
        ),
        (
            "FUNCTION_BLOCK FB VAR_IN_OUT io : INT; END_VAR VAR r : REFERENCE TO INT; END_VAR\n  r REF= io;\nEND_FUNCTION_BLOCK",
            "main.st:2:10: error: REF= of a VAR_IN_OUT",
        ),
        (
            "FUNCTION_BLOCK FB VAR_IN_OUT io : INT; END_VAR VAR p : POINTER TO INT; END_VAR\n  p := ADR(io);\nEND_FUNCTION_BLOCK",
            "main.st:2:12: error: ADR of a VAR_IN_OUT",
        ),
        (
            "PROGRAM MAIN VAR CONSTANT r : REFERENCE TO INT; END_VAR END_PROGRAM",
            "main.st:1:31: error: a REFERENCE TO is no CONSTANT",
        ),
        (
            "PROGRAM MAIN VAR r : REFERENCE TO INT; q : REFERENCE TO LREAL; END_VAR\n  r REF= q;\nEND_PROGRAM",
            "main.st:2:10: error: REF= binds a REFERENCE TO INT, not a REFERENCE TO LREAL",
        ),
        (
            "PROGRAM MAIN VAR r : REFERENCE TO INT; x : LREAL; END_VAR\n  r REF= x;\nEND_PROGRAM",
            "main.st:2:10: error: REF= binds a REFERENCE TO INT to a variable of that type, not a LREAL",
        ),
    ] {
        let e = refused(text);
        assert!(e.starts_with(expect), "{text}:\n{e}");
    }
}
