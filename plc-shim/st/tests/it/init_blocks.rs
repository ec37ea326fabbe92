//! A function block instance's declaration gives initial values to its inputs, as TwinCAT
//! and CODESYS programs write timers: `fbDelay : TON := (PT := T#20MS);`. Standard blocks,
//! the program's own blocks (the instance's value wins over the block's declared one),
//! arrays of instances and global instances; what is no input is refused by name.

use crate::support::{refused, run};

/// A block of the program's own, with declared initial values.
const FB_SCALE: &str = "FUNCTION_BLOCK FB_Scale
VAR_INPUT
    x : LREAL;
    factor : LREAL := 1.0;
    offset : LREAL := 5.0;
END_VAR
VAR_OUTPUT
    y : LREAL;
END_VAR
    y := x * factor + offset;
END_FUNCTION_BLOCK
";

/// [`FB_SCALE`] and a program whose instances' declarations give inputs.
fn program() -> String {
    FB_SCALE.to_string()
        + "
VAR_GLOBAL
    gDelay : TON := (PT := T#30MS);
END_VAR

PROGRAM MAIN
VAR
    fbDelay : TON := (PT := T#20MS);
    aDelays : ARRAY[0..1] OF TON := [(PT := T#10MS), (PT := T#40MS)];
    fbScale : FB_Scale := (factor := 2.0);
    q, q0, q1, gq : BOOL;
    y : LREAL;
    pt, pt1 : TIME;
END_VAR
    fbDelay(IN := TRUE);
    aDelays[0](IN := TRUE);
    aDelays[1](IN := TRUE);
    gDelay(IN := TRUE);
    fbScale(x := 3.0);
    q := fbDelay.Q;
    q0 := aDelays[0].Q;
    q1 := aDelays[1].Q;
    gq := gDelay.Q;
    y := fbScale.y;
    pt := fbDelay.PT;
    pt1 := aDelays[1].PT;
END_PROGRAM"
}

#[test]
fn an_instances_declaration_sets_its_inputs() {
    // Cycles at 0, 10 and 20 ms: the timers started at 0.
    let p = run(&program(), 3);
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!(var("pt"), 20.0);
    assert_eq!((var("q"), var("q0"), var("q1")), (1.0, 1.0, 0.0));
    assert_eq!(var("pt1"), 40.0);
    assert_eq!(var("gq"), 0.0, "30 ms not reached at 20 ms");
    // factor from the instance (2.0 over the block's 1.0), offset the block's own.
    assert_eq!(var("y"), 11.0);
}

#[test]
fn what_is_no_input_of_the_block_is_refused_by_name() {
    let with = |decl: &str| program().replace("fbDelay : TON := (PT := T#20MS);", decl);
    assert_eq!(
        refused(&with("fbDelay : TON := (Q := TRUE);")),
        "main.st:19:23: error: `Q` is no input of TON: an instance's declaration gives initial \
         values to its inputs\n"
    );
    assert_eq!(
        refused(&with("fbDelay : TON := (PX := T#1S);")),
        "main.st:19:23: error: TON has no input `PX`\n"
    );
    assert_eq!(
        refused(&with("fbDelay : TON := (PT := TRUE);")),
        "main.st:19:29: error: BOOL where TIME is wanted\n"
    );
    let output = program().replace("(factor := 2.0)", "(y := 2.0)");
    assert_eq!(
        refused(&output),
        "main.st:21:28: error: `y` is no input of FB_Scale: an instance's declaration gives \
         initial values to its inputs\n"
    );
}

/// A block's own initial value that reads a global (a CONSTANT) sees it set: the globals'
/// own initial values run before the instances', only the instances' initialisers after.
#[test]
fn a_blocks_own_initial_value_reads_the_globals_set_before_it() {
    let p = run(
        "VAR_GLOBAL CONSTANT
    cLim : INT := 10;
END_VAR
VAR_GLOBAL
    gAx : FB_A;
    gAy : FB_A := (scale := 3);
END_VAR
FUNCTION_BLOCK FB_A
VAR_INPUT
    scale : INT := 2;
END_VAR
VAR_OUTPUT
    lim : INT := cLim;
END_VAR
END_FUNCTION_BLOCK
PROGRAM MAIN
VAR
    x, y, s : INT;
END_VAR
    x := gAx.lim;
    y := gAy.lim;
    s := gAy.scale;
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!((var("x"), var("y"), var("s")), (10.0, 10.0, 3.0));
}

/// A function's block instances start from their initial values at every call, as its other
/// variables do: the block's declared ones (they were never set: 0) and the instance's
/// initialiser.
#[test]
fn a_functions_block_instances_start_from_their_initial_values() {
    let p = run(
        &(FB_SCALE.to_string()
            + "FUNCTION F_Scaled : LREAL
VAR_INPUT
    v : LREAL;
END_VAR
VAR
    plain : FB_Scale;
    doubled : FB_Scale := (factor := 2.0);
END_VAR
    plain(x := v);
    doubled(x := v);
    F_Scaled := plain.y * 100.0 + doubled.y;
END_FUNCTION
PROGRAM MAIN
VAR
    a, b : LREAL;
END_VAR
    a := F_Scaled(1.0);
    b := F_Scaled(2.0);
END_PROGRAM"),
        2,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    // plain: v + 5, doubled: 2 v + 5, at every call.
    assert_eq!((var("a"), var("b")), (607.0, 709.0));
}
