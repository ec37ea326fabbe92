//! METHODs and ACTIONs of function blocks and programs (TwinCAT 3's, CODESYS 3's): run on
//! their instance, with variables of their own that start from their initial values at
//! every call, a value, outputs and VAR_IN_OUTs as a function's; PRIVATE ones called from
//! inside only; `THIS^.x` is the instance's own `x`.

use crate::support::{refused, run};

const AXIS: &str = "
FUNCTION_BLOCK FB_Axis
VAR_INPUT
    fMax : LREAL := 100.0;
END_VAR
VAR_OUTPUT
    fPos : LREAL;
    nMoves : DINT;
END_VAR
VAR
    tonSettle : TON;
    bBusy : BOOL;
END_VAR
    tonSettle(IN := bBusy, PT := T#20MS);
    IF tonSettle.Q THEN
        bBusy := FALSE;
    END_IF
    THIS^.A_Count();

METHOD M_MoveTo : BOOL
VAR_INPUT
    fTarget : LREAL;
END_VAR
VAR
    nCalls : INT := 10;
END_VAR
    nCalls := nCalls + 1;
    IF fTarget > fMax THEN
        RETURN;
    END_IF
    THIS^.fPos := fTarget;
    bBusy := TRUE;
    M_MoveTo := nCalls = 11;
END_METHOD

METHOD PRIVATE M_Clamp : LREAL
VAR_INPUT
    f : LREAL;
END_VAR
    M_Clamp := LIMIT(0.0, f, fMax);
END_METHOD

ACTION A_Count:
    nMoves := nMoves + 1;
END_ACTION

END_FUNCTION_BLOCK

METHOD M_Step
VAR_INPUT
    fBy : LREAL;
END_VAR
VAR_OUTPUT
    fNow : LREAL;
END_VAR
VAR_IN_OUT
    nSteps : INT;
END_VAR
    M_MoveTo(fTarget := M_Clamp(fPos + fBy));
    fNow := fPos;
    nSteps := nSteps + 1;
END_METHOD
";

#[test]
fn methods_run_on_their_instance_with_variables_of_their_own() {
    let text = format!(
        "{AXIS}
PROGRAM MAIN
VAR
    fbX : FB_Axis;
    aAxes : ARRAY[0..1] OF FB_Axis;
    bFirst, bSecond, bTooFar : BOOL;
    fNow : LREAL;
    nSteps : INT := 5;
    k : INT := 1;
    fPos, fPos1 : LREAL;
    nMoves : DINT;
END_VAR
    bFirst := fbX.M_MoveTo(fTarget := 12.5);
    bSecond := fbX.M_MoveTo(20.0);
    bTooFar := fbX.M_MoveTo(500.0);
    fbX.M_Step(fBy := 200.0, fNow => fNow, nSteps := nSteps);
    fbX();
    fbX.A_Count();
    aAxes[k].M_MoveTo(7.0);
    fPos := fbX.fPos;
    fPos1 := aAxes[1].fPos;
    nMoves := fbX.nMoves;
END_PROGRAM"
    );
    let p = run(&text, 1);
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    // Each call's own variables start from their initial value (nCalls 10 -> 11).
    assert_eq!(var("bFirst"), 1.0);
    assert_eq!(var("bSecond"), 1.0);
    assert_eq!(var("bTooFar"), 0.0);
    // M_Step: M_MoveTo of the clamped target (100.0, the instance's fMax), its output and
    // its VAR_IN_OUT back in the caller's.
    assert_eq!(var("fNow"), 100.0);
    assert_eq!(var("nSteps"), 6.0);
    assert_eq!(var("fPos"), 100.0);
    // The body's call of the action and the program's: the instance's count.
    assert_eq!(var("nMoves"), 2.0);
    assert_eq!(var("fPos1"), 7.0);
    // The tools see the instance's variables, not the methods' room.
    let paths: Vec<String> = p.symbols(10_000).into_iter().map(|s| s.path).collect();
    assert!(paths.iter().any(|s| s == "MAIN.fbX.fPos"), "{paths:?}");
    assert!(!paths.iter().any(|s| s.contains("M_MoveTo")), "{paths:?}");
}

/// A method that calls another of the same instance keeps its own variables: each
/// method's room in the instance is its own, and a call clears its own room only (here
/// M_Outer's `flag` lies right after M_Inner's SINT value, within what M_Inner's frame
/// would take aligned).
#[test]
fn a_method_calling_another_of_its_instance_keeps_its_own_variables() {
    let p = run(
        "FUNCTION_BLOCK FB_Pair
VAR
    nBase : DINT := 100;
END_VAR
METHOD M_Inner : SINT
VAR_INPUT
    b : SINT;
END_VAR
VAR
    x : SINT := 3;
END_VAR
    M_Inner := x + b;
END_METHOD
METHOD M_Outer : DINT
VAR
    flag : BOOL := TRUE;
    y : DINT := 40;
END_VAR
    M_Outer := M_Inner(2) + y + nBase + BOOL_TO_DINT(flag);
END_METHOD
END_FUNCTION_BLOCK
PROGRAM MAIN
VAR
    fb : FB_Pair;
    n : DINT;
END_VAR
    n := fb.M_Outer();
END_PROGRAM",
        1,
    );
    assert_eq!(p.read_var("MAIN.n"), Some(146.0));
}

#[test]
fn a_programs_actions_and_methods_run_on_its_variables() {
    let p = run(
        "PROGRAM MAIN
VAR
    nCount : INT;
    nTwice : INT;
END_VAR
    A_Init();
    nTwice := M_Twice(nCount);
ACTION A_Init:
    nCount := nCount + 1;
END_ACTION
METHOD M_Twice : INT
VAR_INPUT
    n : INT;
END_VAR
    M_Twice := 2 * n;
END_METHOD
END_PROGRAM",
        3,
    );
    assert_eq!(p.read_var("MAIN.nCount"), Some(3.0));
    assert_eq!(p.read_var("MAIN.nTwice"), Some(6.0));
}

#[test]
fn what_a_method_may_not_do_is_refused_with_its_place() {
    let with_main = |body: &str| {
        format!("{AXIS}\nPROGRAM MAIN\nVAR fbX : FB_Axis; f : LREAL; b : BOOL; END_VAR\n{body}\nEND_PROGRAM")
    };
    let e = refused(&with_main("f := fbX.M_Clamp(3.0);"));
    assert!(e.contains("error: `M_Clamp` is PRIVATE to FB_Axis"), "{e}");
    let e = refused(&with_main("b := fbX.A_Count();"));
    assert!(
        e.contains("error: `A_Count` is an ACTION: call it as a statement"),
        "{e}"
    );
    let e = refused(&with_main("fbX.M_Nothing();"));
    assert!(e.contains("error: "), "{e}");
    let e = refused(
        "FUNCTION_BLOCK FB_R
METHOD M_A : INT
    M_A := M_B();
END_METHOD
METHOD M_B : INT
    M_B := M_A();
END_METHOD
END_FUNCTION_BLOCK",
    );
    assert!(e.contains("calls itself"), "{e}");
    let e = refused(
        "FUNCTION_BLOCK FB_N
VAR
    M_X : INT;
END_VAR
METHOD M_X : INT
    M_X := 1;
END_METHOD
END_FUNCTION_BLOCK",
    );
    assert!(e.contains("`M_X` names a variable and a method"), "{e}");
    let e = refused("FUNCTION F : INT\n    F := 1;\nEND_FUNCTION\nMETHOD M : INT\nEND_METHOD\n");
    assert!(
        e.contains("a METHOD or ACTION follows its FUNCTION_BLOCK or PROGRAM"),
        "{e}"
    );
    let e = refused(
        "FUNCTION_BLOCK FB\nACTION A:\nVAR x : INT; END_VAR\nEND_ACTION\nEND_FUNCTION_BLOCK\n",
    );
    assert!(e.contains("an ACTION has no variables of its own"), "{e}");
    for (text, expect) in [
        (
            "FUNCTION_BLOCK FB\nVAR n : INT; END_VAR\nMETHOD M\nVAR_INST k : INT; END_VAR\n  k := k + 1;\nEND_METHOD\nEND_FUNCTION_BLOCK\n",
            "main.st:4:1: error: `VAR_INST` is not supported",
        ),
        (
            "FUNCTION_BLOCK FB\nVAR n : INT; END_VAR\nMETHOD M\n  SUPER^.M();\nEND_METHOD\nEND_FUNCTION_BLOCK\n",
            "main.st:4:11: error: `SUPER^` is not supported",
        ),
        (
            "PROGRAM MAIN\nVAR n : INT; END_VAR\nACTION A:\n n := 1;\nEND_ACTION\nEND_PROGRAM\nPROGRAM P2\n  MAIN.A();\nEND_PROGRAM\n",
            "main.st:8:9: error: `MAIN.A`: a PROGRAM's methods and actions are called inside it only",
        ),
        (
            "FUNCTION_BLOCK FB\nVAR n : INT; END_VAR\nEND_FUNCTION_BLOCK\nPROGRAM P\nVAR fb : FB; END_VAR\n  fb.M_None();\nEND_PROGRAM\n",
            "main.st:6:12: error: FB has no method `M_None`",
        ),
    ] {
        let e = refused(text);
        assert!(e.starts_with(expect), "{text}:\n{e}");
    }
}

/// Inside its POU a method's name wins over a text function's (LEFT, DELETE) and a global
/// function's (as in TwinCAT), in the checker and in the compiled code alike (an operator's
/// name, MAX or ADR, is refused as a method's); a
/// method's value is read from the instance it ran on, even when the call moved the index
/// that found it; a method may be called `Private`.
#[test]
fn a_methods_name_wins_inside_its_pou_and_its_value_comes_from_its_instance() {
    let p = run(
        "VAR_GLOBAL gI : INT; END_VAR
FUNCTION Init : INT
    Init := -1;
END_FUNCTION
FUNCTION_BLOCK FB_List
VAR_INPUT nId : INT; END_VAR
VAR_OUTPUT nDeleted, nMax, nInit, nMine : INT; END_VAR
    Delete(idx := 3);
    nMax := Left(2, 9);
    nInit := THIS^.Init();
    Private();
METHOD Delete
VAR_INPUT idx : INT; END_VAR
    nDeleted := idx;
END_METHOD
METHOD Left : INT
VAR_INPUT a, b : INT; END_VAR
    Left := a * b;
END_METHOD
METHOD Init : INT
    Init := 7;
END_METHOD
METHOD Private
    nMine := 1;
END_METHOD
METHOD Next : INT
    gI := gI + 1;
    Next := nId;
END_METHOD
END_FUNCTION_BLOCK
PROGRAM MAIN
VAR
    fb : FB_List;
    aLists : ARRAY[0..2] OF FB_List;
    nDeleted, nMax, nInit, nMine, nNext, nGlobal : INT;
END_VAR
    fb();
    nDeleted := fb.nDeleted;
    nMax := fb.nMax;
    nInit := fb.nInit;
    nMine := fb.nMine;
    aLists[0](nId := 10);
    aLists[1](nId := 11);
    nNext := aLists[gI].Next();
    nGlobal := Init();
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!(var("nDeleted"), 3.0);
    assert_eq!(var("nMax"), 18.0);
    assert_eq!(var("nInit"), 7.0);
    assert_eq!(var("nMine"), 1.0);
    // The instance it ran on: aLists[0], though gI is 1 after the call.
    assert_eq!(var("nNext"), 10.0);
    assert_eq!(var("nGlobal"), -1.0);
    let e = refused(
        "VAR_GLOBAL g : INT; END_VAR
FUNCTION_BLOCK FB
VAR n : INT; END_VAR
    n := THIS^.g;
END_FUNCTION_BLOCK",
    );
    assert!(
        e.contains("main.st:4:16: error: `g` is no member of FB (THIS^)"),
        "{e}"
    );
    for op in ["Max", "ADR", "SIZEOF", "INT_TO_REAL", "TO_INT"] {
        let e = refused(&format!(
            "FUNCTION_BLOCK FB\nMETHOD {op} : INT\n    {op} := 1;\nEND_METHOD\nEND_FUNCTION_BLOCK"
        ));
        assert!(
            e.contains(&format!(
                "main.st:2:8: error: `{op}` is an operator of the language"
            )),
            "{e}"
        );
    }
}
