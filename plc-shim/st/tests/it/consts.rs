//! Named integer constants in array bounds and STRING lengths, as TwinCAT and CODESYS take
//! them: a global list's and the POU's own, their arithmetic and chains; and the refusals of
//! what is no such constant, each with its place.

use plc_st::vm::Program;

fn load(files: &[(&str, &str)]) -> Result<Program, Vec<String>> {
    Program::load(files).map_err(|e| e.iter().map(|d| d.to_string()).collect())
}

const GLOBALS: &str = "
VAR_GLOBAL CONSTANT
    N_AXES : INT := 4;
    LAST : INT := N_AXES - 1;
    MSG_LEN : INT := 20;
END_VAR
";

#[test]
fn bounds_and_string_lengths_take_named_constants() {
    let main = "
TYPE ST_Station : STRUCT
    aTarget : ARRAY[1..N_AXES] OF LREAL;   (* a type's bounds: the global list's *)
END_STRUCT END_TYPE
PROGRAM MAIN
VAR CONSTANT
    ROWS : INT := LAST + 2;   (* the POU's own, from a global's *)
END_VAR
VAR
    aPos : ARRAY[0..LAST] OF LREAL;
    aGrid : ARRAY[1..ROWS, 0..N_AXES - 1] OF INT;
    sMsg : STRING(MSG_LEN);
    k, nGrid : INT;
    stStation : ST_Station;
    n : UDINT;
    fLast : LREAL;
END_VAR
    FOR k := 0 TO LAST DO
        aPos[k] := INT_TO_LREAL(k) * 1.5;
    END_FOR
    aGrid[ROWS, LAST] := 7;
    fLast := aPos[LAST];
    nGrid := aGrid[5, 3];
    n := SIZEOF(aGrid) + SIZEOF(sMsg) + SIZEOF(stStation);
END_PROGRAM
";
    let mut p = load(&[("globals.st", GLOBALS), ("main.st", main)]).unwrap_or_else(|e| {
        panic!("{e:#?}");
    });
    p.cycle(0).unwrap();
    assert_eq!(p.read_var("MAIN.fLast"), Some(4.5));
    assert_eq!(p.read_var("MAIN.nGrid"), Some(7.0));
    // 5 rows of 4 INTs, 20 characters with their NUL, 4 LREALs.
    assert_eq!(p.read_var("MAIN.n"), Some(40.0 + 21.0 + 32.0));
}

#[test]
fn a_pous_own_constant_hides_a_global_one_of_its_name() {
    let main = "
PROGRAM MAIN
VAR CONSTANT
    LAST : INT := 1;
END_VAR
VAR
    a : ARRAY[0..LAST] OF INT;
    n : UDINT;
END_VAR
    n := SIZEOF(a);
END_PROGRAM
PROGRAM OTHER
VAR
    b : ARRAY[0..LAST] OF INT;
    n : UDINT;
END_VAR
    n := SIZEOF(b);
END_PROGRAM
";
    let mut p = load(&[("globals.st", GLOBALS), ("main.st", main)]).unwrap();
    p.cycle(0).unwrap();
    assert_eq!(p.read_var("MAIN.n"), Some(4.0), "MAIN's own LAST: two INTs");
    assert_eq!(p.read_var("OTHER.n"), Some(8.0), "the global LAST: four");
}

#[test]
fn what_is_no_named_integer_constant_is_refused_with_its_place() {
    let main = "
VAR_GLOBAL
    nVar : INT := 3;
END_VAR
VAR_GLOBAL CONSTANT
    F : LREAL := 2.0;
    A : INT := B + 1;
    B : INT := A;
    NONE : INT;
END_VAR
PROGRAM MAIN
VAR
    a1 : ARRAY[0..nVar] OF INT;
    a2 : ARRAY[0..F] OF INT;
    a3 : ARRAY[0..A] OF INT;
    a4 : ARRAY[0..NONE] OF INT;
    a5 : ARRAY[0..NOWHERE] OF INT;
END_VAR
END_PROGRAM
";
    let Err(e) = load(&[("main.st", main)]) else {
        panic!("refused");
    };
    let has = |what: &str| e.iter().any(|d| d.contains(what));
    assert!(
        has("main.st:13:19: error: `nVar` is no named integer constant"),
        "{e:#?}"
    );
    assert!(
        has("main.st:14:19: error: constant `F` is of no integer type"),
        "{e:#?}"
    );
    assert!(has("error: constant `A` is defined by itself"), "{e:#?}");
    assert!(
        has("main.st:16:19: error: constant `NONE` has no initial value"),
        "{e:#?}"
    );
    assert!(
        has("main.st:17:19: error: `NOWHERE` is no named integer constant"),
        "{e:#?}"
    );
}

/// A chain of constants across scopes is no cycle; a VAR_EXTERNAL names the global one; a
/// variable of the POU's (an input's CONSTANT too, which a caller may give) hides a global
/// constant of its name.
#[test]
fn a_constants_scope_is_where_it_is_declared() {
    let main = "
VAR_GLOBAL CONSTANT
    N : INT := 4;
    M : INT := N + 1;
END_VAR
PROGRAM MAIN
VAR_EXTERNAL CONSTANT
    M : INT;
END_VAR
VAR CONSTANT
    N : INT := M;               (* the global M, itself of the global N: 5 *)
END_VAR
VAR
    a : ARRAY[1..N] OF INT;
    b : ARRAY[0..M] OF INT;
    nSize : UDINT;
END_VAR
    nSize := SIZEOF(a) + SIZEOF(b);
END_PROGRAM
";
    let mut p = load(&[("main.st", main)]).unwrap_or_else(|e| panic!("{e:#?}"));
    p.cycle(0).unwrap();
    assert_eq!(p.read_var("MAIN.nSize"), Some(10.0 + 12.0));
    let hidden = "
VAR_GLOBAL CONSTANT
    LAST : INT := 3;
END_VAR
FUNCTION_BLOCK FB
VAR_INPUT CONSTANT
    LAST : INT := 3;
END_VAR
VAR
    a : ARRAY[0..LAST] OF INT;
END_VAR
END_FUNCTION_BLOCK
";
    let Err(e) = load(&[("main.st", hidden)]) else {
        panic!("refused");
    };
    assert!(
        e.iter()
            .any(|d| d.contains("main.st:10:18: error: `LAST` is no named integer constant")),
        "{e:#?}"
    );
}

/// An enumeration's values bound an array (`ARRAY[E_Axis.X..E_Axis.C]`, `E_Axis#Z`) and
/// index it, also in a structure declared before the enumeration; a name that is no
/// enumeration, or a value it does not have, is refused with its place.
#[test]
fn enumeration_values_bound_and_index_arrays() {
    let main = "
TYPE E_Axis : (X, Y, Z := 5, C); END_TYPE
PROGRAM MAIN
VAR
    aPos : ARRAY[E_Axis.X..E_Axis.C] OF LREAL;
    aB : ARRAY[1..E_Axis#Z] OF INT;
    eAxis : E_Axis := E_Axis.Z;
    fY, fZ : LREAL;
    nSize : UDINT;
END_VAR
    aPos[E_Axis.Y] := 2.5;
    aPos[eAxis] := 4.0;
    fY := aPos[E_Axis.Y];
    fZ := aPos[5];
    nSize := SIZEOF(aPos) + SIZEOF(aB);
END_PROGRAM
";
    let mut p = load(&[("main.st", main)]).unwrap_or_else(|e| panic!("{e:#?}"));
    p.cycle(0).unwrap();
    assert_eq!(
        (p.read_var("MAIN.fY"), p.read_var("MAIN.fZ")),
        (Some(2.5), Some(4.0))
    );
    // X..C is 0..6: 7 LREALs; 1..5: 5 INTs.
    assert_eq!(p.read_var("MAIN.nSize"), Some(56.0 + 10.0));
    let bad = "
TYPE ST_Early : STRUCT a : ARRAY[0..E_Late.B] OF INT; END_STRUCT END_TYPE
TYPE E_Late : (A, B); END_TYPE
PROGRAM MAIN
VAR
    a1 : ARRAY[0..E_None.A] OF INT;
    a2 : ARRAY[0..E_Late.Q] OF INT;
END_VAR
END_PROGRAM
";
    let Err(e) = load(&[("main.st", bad)]) else {
        panic!("refused");
    };
    let has = |what: &str| e.iter().any(|d| d.contains(what));
    assert_eq!(
        e.len(),
        2,
        "ST_Early's bound names E_Late declared later: {e:#?}"
    );
    assert!(
        has("main.st:6:19: error: an integer constant is wanted here"),
        "{e:#?}"
    );
    assert!(
        has("main.st:7:26: error: enumeration `E_Late` has no value `Q` here"),
        "{e:#?}"
    );
}

/// Enumerations resolve before structures, in any file order; a value may name an earlier
/// one of its enumeration; a constant index by an enumeration's value outside the bounds is
/// refused at load as a number's is; a typed number of no elementary type in a bound, and a
/// variable's field there, are refused.
#[test]
fn enumeration_values_in_any_order_and_their_refusals() {
    let a = "TYPE ST_A : STRUCT v : ARRAY[0..E_B.N] OF INT; END_STRUCT END_TYPE
PROGRAM MAIN
VAR st : ST_A; nSize : UDINT; END_VAR
    nSize := SIZEOF(st);
END_PROGRAM
";
    let b = "TYPE E_B : (X, Y, N := E_B.Y + 1); END_TYPE\n";
    let mut p = load(&[("a.st", a), ("b.st", b)]).unwrap_or_else(|e| panic!("{e:#?}"));
    p.cycle(0).unwrap();
    assert_eq!(p.read_var("MAIN.nSize"), Some(6.0), "0..2: three INTs");
    let bad = "TYPE E : (X, Y, Z := 5); END_TYPE
TYPE ST_Cfg : STRUCT n : INT; END_STRUCT END_TYPE
PROGRAM MAIN
VAR
    a : ARRAY[0..2] OF INT;
    a2 : ARRAY[0..Foo#3] OF INT;
    stCfg : ST_Cfg;
    a3 : ARRAY[0..stCfg.n] OF INT;
END_VAR
    a[E.Z] := 1;
END_PROGRAM
";
    let Err(e) = load(&[("main.st", bad)]) else {
        panic!("refused");
    };
    let has = |what: &str| e.iter().any(|d| d.contains(what));
    assert!(has("main.st:10:7: error: index 5 outside [0..2]"), "{e:#?}");
    assert!(
        has("main.st:6:19: error: `Foo#..`: an enumeration's value is named"),
        "{e:#?}"
    );
    assert!(
        has("main.st:8:19: error: an integer constant is wanted here"),
        "{e:#?}"
    );
}
