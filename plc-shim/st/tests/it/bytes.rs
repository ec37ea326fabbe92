//! TwinCAT's byte functions of Tc2_System (MEMCPY, MEMMOVE, MEMSET, MEMCMP) on the
//! program's own memory, and UPPER_BOUND / LOWER_BOUND of an array. The image's leaves are
//! read and written one at a time, by their rules, so a byte function that reaches into
//! the image faults; so does one that leaves the program's memory.

use crate::support::{refused, run};
use plc_st::vm::{Fault, Program};

#[test]
fn memcpy_memmove_memset_and_memcmp_work_on_the_programs_bytes() {
    let p = run(
        "TYPE ST_Pair : STRUCT a : DINT; b : LREAL; END_STRUCT END_TYPE
PROGRAM MAIN
VAR
    aSrc : ARRAY[0..3] OF DINT := [1, 2, 3, 4];
    aDst : ARRAY[0..3] OF DINT;
    aRing : ARRAY[0..3] OF INT := [10, 20, 30, 40];
    stA : ST_Pair := (a := 7, b := 2.5);
    stB : ST_Pair;
    aZero : ARRAY[0..2] OF BYTE := [1, 1, 1];
    nSame, nLess, nMore : DINT;
    d0, d3, r0, r1, r3, z1, z2, ba, bb : LREAL;
END_VAR
    MEMCPY(ADR(aDst), ADR(aSrc), SIZEOF(aSrc));
    MEMCPY(ADR(stB), ADR(stA), SIZEOF(stA));
    MEMMOVE(ADR(aRing[1]), ADR(aRing[0]), 3 * SIZEOF(aRing[0]));
    MEMSET(ADR(aZero[1]), 0, 2);
    nSame := MEMCMP(ADR(aSrc), ADR(aDst), SIZEOF(aSrc));
    aDst[2] := 5;
    nLess := MEMCMP(ADR(aSrc), ADR(aDst), SIZEOF(aSrc));
    nMore := MEMCMP(ADR(aDst), ADR(aSrc), SIZEOF(aSrc));
    d0 := aDst[0]; d3 := aDst[3];
    r0 := aRing[0]; r1 := aRing[1]; r3 := aRing[3];
    z1 := aZero[0]; z2 := aZero[2];
    ba := stB.a; bb := stB.b;
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!((var("d0"), var("d3")), (1.0, 4.0));
    assert_eq!((var("ba"), var("bb")), (7.0, 2.5));
    // MEMMOVE of overlapping bytes: as if through a buffer.
    assert_eq!((var("r0"), var("r1"), var("r3")), (10.0, 10.0, 30.0));
    assert_eq!((var("z1"), var("z2")), (1.0, 0.0));
    assert_eq!((var("nSame"), var("nLess"), var("nMore")), (0.0, -1.0, 1.0));
}

#[test]
fn bytes_beyond_the_program_or_in_the_image_fault() {
    let fault = |body: &str| {
        let text = format!(
            "PROGRAM MAIN VAR a : ARRAY[0..3] OF DINT; p : POINTER TO DINT; n : INT := -1; END_VAR\n{body}\nEND_PROGRAM"
        );
        let mut p = Program::load(&[("main.st", &text)]).unwrap();
        let f = p.cycle(0).unwrap_err();
        (f.fault, p.fault_text(&f))
    };
    let (f, text) = fault("MEMSET(ADR(a), 0, 1000000);");
    assert_eq!(f, Fault::BadPointer);
    assert_eq!(
        text,
        "main.st:2:1: fault: a pointer that is NULL or points outside the program"
    );
    assert_eq!(fault("MEMCPY(p, ADR(a), 4);").0, Fault::BadPointer);
    // A negative count is a count of bytes beyond the program.
    assert_eq!(fault("MEMCPY(ADR(a[1]), ADR(a), n);").0, Fault::BadPointer);
    let prelude = hli::st_prelude::generate();
    let main = "PROGRAM MAIN VAR a : ARRAY[0..1] OF UDINT; END_VAR\n\
                MEMCPY(ADR(a), ADR(gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state), 4);\n\
                END_PROGRAM";
    let mut p = Program::load(&[("hli.st", &prelude), ("main.st", main)]).unwrap();
    p.bind_image();
    let image = hli::image::heap_image(1, 6);
    let f = p.cycle_on(0, Some(&image)).unwrap_err();
    assert_eq!(f.fault, Fault::ImageCopy);
    assert!(
        p.fault_text(&f).starts_with(
            "main.st:2:1: fault: a whole structure, MEMCPY, MEMSET or MEMCMP to or from the image"
        ),
        "{}",
        p.fault_text(&f)
    );
}

#[test]
fn byte_functions_take_pointers_and_memcpy_is_a_statement() {
    let text = |body: &str| {
        format!(
            "PROGRAM MAIN VAR a, b : ARRAY[0..3] OF DINT; n : UDINT; END_VAR\n{body}\nEND_PROGRAM"
        )
    };
    assert_eq!(
        refused(&text("MEMCPY(a, b, 16);")),
        "main.st:2:1: error: MEMCPY does not take these values\n"
    );
    assert_eq!(
        refused(&text("n := MEMCPY(ADR(a), ADR(b), 16);")),
        "main.st:2:6: error: MEMCPY's value (call it as a statement) is not supported by the runtime yet\n"
    );
}

#[test]
fn upper_and_lower_bound_are_the_arrays_own() {
    let p = run(
        "PROGRAM MAIN
VAR
    aBuf : ARRAY[0..9] OF INT;
    aGrid : ARRAY[1..3, -2..5] OF LREAL;
    hi, lo, hi2, lo2, sum : DINT;
    i : INT;
END_VAR
    hi := UPPER_BOUND(aBuf, 1);
    lo := LOWER_BOUND(aBuf, 1);
    hi2 := UPPER_BOUND(aGrid, 2);
    lo2 := LOWER_BOUND(aGrid, 2);
    FOR i := LOWER_BOUND(aBuf, 1) TO UPPER_BOUND(aBuf, 1) DO
        aBuf[i] := i;
        sum := sum + aBuf[i];
    END_FOR
END_PROGRAM",
        1,
    );
    let var = |name: &str| p.read_var(&format!("MAIN.{name}")).expect(name);
    assert_eq!((var("hi"), var("lo")), (9.0, 0.0));
    assert_eq!((var("hi2"), var("lo2")), (5.0, -2.0));
    assert_eq!(var("sum"), 45.0);
    let text = |body: &str| {
        format!(
            "PROGRAM MAIN VAR a : ARRAY[0..3] OF DINT; x, n : DINT; END_VAR\n{body}\nEND_PROGRAM"
        )
    };
    assert_eq!(
        refused(&text("n := UPPER_BOUND(a, 2);")),
        "main.st:2:21: error: the dimension is a constant 1..1 of this array\n"
    );
    assert_eq!(
        refused(&text("n := UPPER_BOUND(x, 1);")),
        "main.st:2:21: error: UPPER_BOUND and LOWER_BOUND take an array\n"
    );
}
