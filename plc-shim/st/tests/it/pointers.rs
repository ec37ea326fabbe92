//! TwinCAT's pointer arithmetic: a pointer moves by a number of bytes (`p := p +
//! SIZEOF(INT);`), two pointers to one type are ordered (`WHILE p <= pEnd`), and where a
//! moved pointer points is checked where it is read: outside the program's memory it
//! faults instead of reading.

use crate::support::{load, refused, run};

#[test]
fn a_pointer_walks_an_array_by_its_elements_size() {
    let p = run(
        "PROGRAM MAIN
VAR
    a : ARRAY[0..4] OF INT := [1, 2, 3, 4, 5];
    p, pEnd : POINTER TO INT;
    sum : DINT;
    n, m : INT;
    below : BOOL;
END_VAR
    p := ADR(a[0]);
    pEnd := ADR(a[4]);
    below := p < pEnd;
    WHILE p <= pEnd DO
        sum := sum + p^;
        p := p + SIZEOF(INT);
    END_WHILE
    p := pEnd - 2;
    n := p^;
    p := 2 + p;
    m := p^;
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!(
        (var("sum"), var("n"), var("m"), var("below")),
        (15.0, 4.0, 5.0, 1.0)
    );
}

#[test]
fn a_pointer_moved_outside_the_memory_faults_where_it_is_read() {
    let mut p = load(
        "PROGRAM MAIN
VAR
    a : ARRAY[0..1] OF INT;
    p : POINTER TO INT;
    n : INT;
END_VAR
    p := ADR(a[0]) - 64;
    n := p^;
END_PROGRAM",
    );
    let f = p.cycle(0).unwrap_err();
    assert_eq!(
        p.fault_text(&f),
        "main.st:8:5: fault: a pointer that is NULL or points outside the program"
    );
}

#[test]
fn pointers_to_other_types_or_by_a_real_are_refused() {
    let text = |body: &str| {
        format!(
            "PROGRAM MAIN\nVAR\n    p : POINTER TO INT;\n    q : POINTER TO LREAL;\n    \
             b : BOOL;\nEND_VAR\n{body}\nEND_PROGRAM"
        )
    };
    assert_eq!(
        refused(&text("    b := p < q;")),
        "main.st:7:12: error: `<` of POINTER TO INT and POINTER TO LREAL\n"
    );
    assert_eq!(
        refused(&text("    p := p + 1.5;")),
        "main.st:7:12: error: `+` of POINTER TO INT and LREAL\n"
    );
    assert_eq!(
        refused(&text("    p := p * 2;")),
        "main.st:7:12: error: `*` of POINTER TO INT and DINT\n"
    );
}

/// SIZEOF measures a variable, or a type it names (`SIZEOF(INT)` was 0 before: the name was
/// taken for a variable that is not there).
#[test]
fn sizeof_measures_a_type_named_or_a_variable() {
    let p = run(
        "TYPE E_Mode : (Auto, Manual) DINT; END_TYPE
TYPE ST_Pair :
STRUCT
    a : LREAL;
    b : INT;
END_STRUCT
END_TYPE
PROGRAM MAIN
VAR
    pair : ST_Pair;
    n : INT;
    sInt, sLreal, sPair, sVar, sField, sEnum : UDINT;
END_VAR
    sInt := SIZEOF(INT);
    sLreal := SIZEOF(LREAL);
    sPair := SIZEOF(ST_Pair);
    sVar := SIZEOF(pair);
    sField := SIZEOF(pair.b);
    sEnum := SIZEOF(E_Mode);
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!((var("sInt"), var("sLreal")), (2.0, 8.0));
    assert_eq!(
        (var("sPair"), var("sVar"), var("sField")),
        (16.0, 16.0, 2.0)
    );
    assert_eq!(
        refused(
            "PROGRAM MAIN\nVAR\n    s : UDINT;\nEND_VAR\n    s := SIZEOF(nothing);\nEND_PROGRAM"
        ),
        "main.st:5:17: error: unknown name `nothing`\n"
    );
}
