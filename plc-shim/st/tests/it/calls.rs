//! Calls of the program's own functions and function blocks: a FUNCTION's VAR_IN_OUT
//! (copied in and back, bound at its turn among the values), and structure and array
//! outputs of a function block, with the refusals of what a call may not give.

use crate::support::{refused, run};

/// A function's VAR_IN_OUT: the caller's variable copied in before the call and back after
/// it (an array, an elementary value), named or by position among the inputs.
#[test]
fn a_functions_var_in_out_writes_the_callers_variable() {
    let text = "
FUNCTION F_SumClear : LREAL
VAR_IN_OUT a : ARRAY[0..3] OF LREAL; END_VAR
VAR_INPUT scale : LREAL; END_VAR
VAR k : INT; END_VAR
    FOR k := 0 TO 3 DO
        F_SumClear := F_SumClear + a[k] * scale;
        a[k] := 0.0;
    END_FOR
END_FUNCTION
FUNCTION F_Bump : BOOL
VAR_IN_OUT n : DINT; END_VAR
    n := n + 1;
    F_Bump := n > 2;
END_FUNCTION
PROGRAM MAIN
VAR
    x : ARRAY[0..3] OF LREAL := [1.0, 2.0, 3.0, 4.0];
    s, x3 : LREAL;
    c : DINT;
    b : BOOL;
END_VAR
    s := s + F_SumClear(a := x, scale := 2.0);
    x3 := x[3];
    b := F_Bump(c);
END_PROGRAM";
    let p = run(text, 1);
    assert_eq!(p.read_var("MAIN.s"), Some(20.0));
    assert_eq!(
        p.read_var("MAIN.x3"),
        Some(0.0),
        "cleared through the VAR_IN_OUT"
    );
    assert_eq!(p.read_var("MAIN.c"), Some(1.0));
    assert_eq!(p.read_var("MAIN.b"), Some(0.0));
    let p = run(text, 3);
    assert_eq!(p.read_var("MAIN.s"), Some(20.0), "nothing left to sum");
    assert_eq!(
        (p.read_var("MAIN.c"), p.read_var("MAIN.b")),
        (Some(3.0), Some(1.0))
    );
    let e = refused(
        "FUNCTION F : BOOL VAR_IN_OUT n : DINT; END_VAR F := n > 0; END_FUNCTION
PROGRAM MAIN VAR r : LREAL; b : BOOL; END_VAR
b := F(n := r);
b := F(5);
END_PROGRAM",
    );
    assert!(
        e.contains("main.st:3:13: error: a LREAL for a VAR_IN_OUT of DINT"),
        "{e}"
    );
    assert!(e.contains("main.st:4:8: error:"), "{e}");
}

/// A VAR_IN_OUT is bound when the call starts: a body that moves the index the caller gave
/// does not move where the value goes back; an index a function computes is refused (it
/// would be computed twice), as is a parameter given twice.
#[test]
fn a_var_in_out_goes_back_where_it_came_from() {
    let p = run(
        "VAR_GLOBAL i : INT; END_VAR
FUNCTION F_Next : INT
VAR_IN_OUT v : INT; END_VAR
    v := v + 10;
    i := i + 1;
    F_Next := v;
END_FUNCTION
FUNCTION Bump : INT
    i := i + 1;
    Bump := 0;
END_FUNCTION
FUNCTION G : INT
VAR_IN_OUT v : INT; END_VAR
VAR_INPUT k : INT; END_VAR
    v := v + 20;
    G := k;
END_FUNCTION
PROGRAM MAIN
VAR a, b : ARRAY[0..3] OF INT; r, s, a0, a1, b1, b2 : INT; END_VAR
    IF i = 0 THEN
        r := F_Next(a[i]);          (* the body moves i to 1 *)
        s := G(b[i], Bump());       (* b[1] given; the later value moves i to 2 *)
    END_IF
    a0 := a[0];
    a1 := a[1];
    b1 := b[1];
    b2 := b[2];
END_PROGRAM",
        1,
    );
    assert_eq!(
        (p.read_var("MAIN.a0"), p.read_var("MAIN.a1")),
        (Some(10.0), Some(0.0))
    );
    assert_eq!(p.read_var("MAIN.r"), Some(10.0));
    assert_eq!(
        (p.read_var("MAIN.b1"), p.read_var("MAIN.b2")),
        (Some(20.0), Some(0.0))
    );
    let e = refused(
        "FUNCTION F : INT VAR_IN_OUT v : INT; END_VAR VAR_INPUT k : INT; END_VAR F := k; END_FUNCTION
PROGRAM MAIN VAR a : ARRAY[0..3] OF INT; b, r : INT; END_VAR
r := F(a[F(b, 1)], 2);
r := F(b, 1, k := 2);
END_PROGRAM",
    );
    assert!(
        e.contains("main.st:4:14: error: F: `k` is given twice"),
        "{e}"
    );
    let e = refused(
        "FUNCTION F : INT VAR_IN_OUT v : INT; END_VAR VAR_INPUT k : INT; END_VAR F := k; END_FUNCTION
PROGRAM MAIN VAR b, r : INT; END_VAR
r := F(k := 2, b);
END_PROGRAM",
    );
    assert!(
        e.contains("main.st:3:16: error: a value by position after a named one"),
        "{e}"
    );
    let e = refused(
        "PROGRAM MAIN VAR r : INT; END_VAR
CASE r OF 0: r := 1; 3..1: r := 0; END_CASE
END_PROGRAM",
    );
    assert!(
        e.contains("main.st:2:22: error: CASE range 3..1 holds no value"),
        "{e}"
    );
    let e = refused(
        "FUNCTION F : INT VAR_IN_OUT v : INT; END_VAR F := v; END_FUNCTION
PROGRAM MAIN VAR a : ARRAY[0..3] OF INT; b, r : INT; END_VAR
r := F(a[F(b)]);
END_PROGRAM",
    );
    assert!(
        e.contains("main.st:3:8: error: a VAR_IN_OUT's variable at an index a function computes"),
        "{e}"
    );
}

/// A function block's output of a structure or an array type goes to the caller's variable
/// of that type after the call, leaf by leaf.
#[test]
fn structure_and_array_outputs_reach_the_callers_variables() {
    let text = "
TYPE ST_Pos : STRUCT x, y : LREAL; n : INT; END_STRUCT END_TYPE
FUNCTION_BLOCK FB_Next
VAR_INPUT k : INT; END_VAR
VAR_OUTPUT stPos : ST_Pos; aOut : ARRAY[0..2] OF INT; END_VAR
    stPos.x := INT_TO_LREAL(k) * 1.5;
    stPos.y := -stPos.x;
    stPos.n := k;
    aOut[2] := k * 2;
END_FUNCTION_BLOCK
PROGRAM MAIN
VAR fb : FB_Next; myPos : ST_Pos; myArr : ARRAY[0..2] OF INT; y : LREAL; n, a2 : INT; END_VAR
    fb(k := 4, stPos => myPos, aOut => myArr);
    y := myPos.y;
    n := myPos.n;
    a2 := myArr[2];
END_PROGRAM";
    let p = run(text, 1);
    assert_eq!(p.read_var("MAIN.y"), Some(-6.0));
    assert_eq!(p.read_var("MAIN.n"), Some(4.0));
    assert_eq!(p.read_var("MAIN.a2"), Some(8.0));
    let wrong = text.replace("myArr : ARRAY[0..2]", "myArr : ARRAY[0..3]");
    let e = refused(&wrong);
    assert!(e.contains("main.st:13:40: error:"), "{e}");
}

/// An array input comes from the caller's array of that type, leaf by leaf.
#[test]
fn an_array_input_comes_from_the_callers_array() {
    let p = run(
        "FUNCTION_BLOCK FB_Sum
VAR_INPUT aIn : ARRAY[0..2] OF INT; END_VAR
VAR_OUTPUT nSum : INT; END_VAR
    nSum := aIn[0] + aIn[1] + aIn[2];
END_FUNCTION_BLOCK
PROGRAM MAIN
VAR fb : FB_Sum; a : ARRAY[0..2] OF INT := [1, 2, 3]; n : INT; END_VAR
    fb(aIn := a, nSum => n);
END_PROGRAM",
        1,
    );
    assert_eq!(p.read_var("MAIN.n"), Some(6.0));
}

/// A function's structure and array inputs are passed by value, leaf by leaf, as a
/// block's (`F_Avg(aVals)`; they were refused: "an input that is no elementary value or
/// STRING"): a write to the input inside the function leaves the caller's variable alone.
#[test]
fn a_functions_structure_and_array_inputs_are_copies() {
    let p = run(
        "TYPE ST_Part : STRUCT nId : DINT; fLength : LREAL; END_STRUCT END_TYPE
FUNCTION F_Avg : LREAL
VAR_INPUT a : ARRAY[1..4] OF LREAL; END_VAR
VAR i : INT; sum : LREAL; END_VAR
    FOR i := 1 TO 4 DO
        sum := sum + a[i];
    END_FOR
    a[1] := 100.0;
    F_Avg := sum / 4;
END_FUNCTION
FUNCTION F_Longer : DINT
VAR_INPUT part : ST_Part; limit : LREAL; END_VAR
    IF part.fLength > limit THEN
        F_Longer := part.nId;
    END_IF
END_FUNCTION
PROGRAM MAIN
VAR
    aVals : ARRAY[1..4] OF LREAL := [1.0, 2.0, 3.0, 6.0];
    stPart : ST_Part := (nId := 7, fLength := 12.5);
    fAvg, fFirst : LREAL;
    nLong, nShort : DINT;
END_VAR
    fAvg := F_Avg(aVals);
    fFirst := aVals[1];
    nLong := F_Longer(stPart, 10.0);
    nShort := F_Longer(part := stPart, limit := 20.0);
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!(var("fAvg"), 3.0);
    assert_eq!(var("fFirst"), 1.0);
    assert_eq!(var("nLong"), 7.0);
    assert_eq!(var("nShort"), 0.0);
    let e = refused(
        "FUNCTION F : INT VAR_INPUT a : ARRAY[0..2] OF INT; END_VAR F := a[0]; END_FUNCTION
PROGRAM MAIN VAR b : ARRAY[0..3] OF INT; n : INT; END_VAR n := F(b); END_PROGRAM",
    );
    assert!(
        e.contains("main.st:2:66: error: ARRAY[0..3] OF INT where ARRAY[0..2] OF INT is wanted"),
        "{e}"
    );
}

/// A function's VAR_OUTPUTs given in its call (`frac => f`, as TwinCAT and CODESYS bind
/// them): written after the call to places found then, widened to the place's type, a
/// BOOL's negated with NOT; in a statement of its own as in an expression. What is no
/// elementary output is refused by name (it was "a function: it has no outputs").
#[test]
fn a_functions_outputs_reach_the_places_its_call_names() {
    let text = "
FUNCTION F_Split : BOOL
VAR_INPUT v : LREAL; END_VAR
VAR_OUTPUT whole : DINT; frac : LREAL; negative : BOOL; END_VAR
    whole := LREAL_TO_DINT(TRUNC(v));
    frac := v - DINT_TO_LREAL(whole);
    negative := v < 0.0;
    F_Split := TRUE;
END_FUNCTION
PROGRAM MAIN
VAR
    ok, positive : BOOL;
    w : DINT;
    wide : LINT;
    f : LREAL;
    a : ARRAY[0..1] OF DINT;
    k : INT := 1;
    a1 : DINT;
END_VAR
    ok := F_Split(2.75, whole => w, frac => f);
    F_Split(v := -3.5, whole => wide, NOT negative => positive);
    F_Split(10.5, whole => a[k]);
    a1 := a[1];
END_PROGRAM";
    let p = run(text, 1);
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!((var("ok"), var("w"), var("f")), (1.0, 2.0, 0.75));
    assert_eq!((var("wide"), var("positive")), (-3.0, 0.0));
    assert_eq!(var("a1"), 10.0);
    let refusal = |call: &str| refused(&text.replace("F_Split(10.5, whole => a[k]);", call));
    assert_eq!(
        refusal("F_Split(1.0, rest => w);"),
        "main.st:22:18: error: F_Split has no output `rest`\n"
    );
    assert_eq!(
        refusal("F_Split(1.0, v => w);"),
        "main.st:22:18: error: F_Split has no output `v`\n"
    );
    assert_eq!(
        refusal("F_Split(1.0, frac => w);"),
        "main.st:22:26: error: a LREAL output into a DINT\n"
    );
}

/// An output given to a variable of a type it widens to is converted on the way: an INT's
/// -1 into a DINT stays -1 (it was written as two bytes: 65535), a TIME into an LTIME
/// counts nanoseconds, a REAL into an LREAL keeps its value; for a function block's output
/// (the operations' way) and a function's (the tree's).
#[test]
fn an_output_into_a_wider_type_is_converted() {
    let p = run(
        "FUNCTION_BLOCK FB_Out
VAR_OUTPUT n : INT; t : TIME; r : REAL; END_VAR
    n := -1;
    t := T#1S;
    r := 1.5;
END_FUNCTION_BLOCK
FUNCTION F_Out : BOOL
VAR_OUTPUT t : TIME; n : INT; END_VAR
    t := T#2S;
    n := -2;
    F_Out := TRUE;
END_FUNCTION
PROGRAM MAIN
VAR
    fb : FB_Out;
    d, d2 : DINT;
    lt, lt2 : LTIME;
    lr : LREAL;
    ok : BOOL;
END_VAR
    fb(n => d, t => lt, r => lr);
    ok := F_Out(t => lt2, n => d2);
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!((var("d"), var("lr"), var("d2")), (-1.0, 1.5, -2.0));
    assert_eq!((var("lt"), var("lt2")), (1e9, 2e9));
}

/// A STRING, and a structure holding one, pass as a VAR_IN_OUT and as an input (their bytes
/// copied in and back as 8-byte words and single bytes): a recipe with its name; a
/// function that appends to the caller's STRING (both were refused: "a STRING as a
/// VAR_IN_OUT of a function", "a VAR_IN_OUT of more than 64 values or of this type").
#[test]
fn strings_and_structures_holding_them_pass_by_in_out_and_input() {
    let p = run(
        "TYPE ST_Recipe : STRUCT sName : STRING(30); aSteps : ARRAY[1..3] OF LREAL; nCount : INT; END_STRUCT END_TYPE
FUNCTION_BLOCK FB_Recipe
VAR_IN_OUT stRecipe : ST_Recipe; END_VAR
VAR_OUTPUT fSum : LREAL; END_VAR
VAR i : INT; END_VAR
    fSum := 0.0;
    FOR i := 1 TO stRecipe.nCount DO
        fSum := fSum + stRecipe.aSteps[i];
    END_FOR
    stRecipe.sName := CONCAT(stRecipe.sName, '!');
END_FUNCTION_BLOCK
FUNCTION F_Tag : INT
VAR_IN_OUT s : STRING; END_VAR
VAR_INPUT r : ST_Recipe; END_VAR
    s := CONCAT(s, r.sName);
    F_Tag := LEN(s);
END_FUNCTION
PROGRAM MAIN
VAR
    stR : ST_Recipe := (sName := 'Cake', aSteps := [1.5, 2.5, 9.0], nCount := 2);
    fbR : FB_Recipe;
    sLog : STRING := 'log:';
    n : INT;
    fSum : LREAL;
    bName, bLog : BOOL;
END_VAR
    fbR(stRecipe := stR, fSum => fSum);
    n := F_Tag(sLog, stR);
    bName := stR.sName = 'Cake!';
    bLog := sLog = 'log:Cake!';
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!(var("fSum"), 4.0);
    assert_eq!(var("bName"), 1.0);
    assert_eq!(var("bLog"), 1.0);
    assert_eq!(var("n"), 9.0);
}
