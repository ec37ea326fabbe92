//! Native code at the edges the random programs of `two_ways.rs` do not reach: a FOR whose
//! next value overflows LINT, a CASE table of negative labels and values far from them, an
//! element of an array at the index just past each bound, a pointer into the image with no
//! image. Each program runs natively, as operations and as the tree; after every cycle the
//! three hold the same memory and stop on the same fault.

use plc_st::vm::{Fault, Program};

/// Runs `body` (with `decls` among MAIN's variables) three ways for `cycles` cycles: the
/// first cycle's fault (if any).
fn three_ways(decls: &str, body: &str, cycles: i64) -> Option<Fault> {
    let text = format!("PROGRAM MAIN\nVAR\n{decls}\nEND_VAR\n{body}\nEND_PROGRAM\n");
    let prelude = hli::st_prelude::generate();
    // The image's pointers are bound, but the cycles run without an image.
    let load = || {
        let mut p = Program::load(&[("hli.st", &prelude), ("main.st", &text)]).unwrap();
        p.bind_image();
        p
    };
    let (mut native, mut ops, mut tree) = (load(), load(), load());
    assert!(native.is_native());
    ops.operations_only();
    tree.interpret_only();
    let mut first = None;
    for k in 0..cycles {
        let now = k * 1_000_000;
        let (n, o, t) = (native.cycle(now), ops.cycle(now), tree.cycle(now));
        assert_eq!(n, t, "cycle {k}: native and tree");
        assert_eq!(o, t, "cycle {k}: operations and tree");
        assert!(native.memory() == tree.memory(), "cycle {k}: native memory");
        assert!(
            ops.memory() == tree.memory(),
            "cycle {k}: operations' memory"
        );
        if let Err(f) = t {
            first = first.or(Some(f.fault));
        }
    }
    first
}

#[test]
fn a_for_loop_whose_next_value_overflows_ends() {
    let decls = "l : LINT; n : DINT;";
    let body =
        "FOR l := LINT#9223372036854775800 TO LINT#9223372036854775807 DO n := n + 1; END_FOR";
    assert_eq!(three_ways(decls, body, 2), None);
}

#[test]
fn a_case_table_of_negative_labels_takes_each_value_as_the_tree_does() {
    let decls = "x : LINT; k : DINT; n : DINT; aX : ARRAY[0..6] OF LINT := [-4, -3, -2, 0, 5, \
                 LINT#-9223372036854775807, LINT#9223372036854775807];";
    let body = "FOR k := 0 TO 6 DO x := aX[k];\n\
                CASE x OF -3: n := n + 1; -2, -1: n := n + 10; 0: n := n + 100; 1..2: n := n * 2;\n\
                ELSE n := n - 1; END_CASE\nEND_FOR";
    assert_eq!(three_ways(decls, body, 3), None);
}

#[test]
fn an_element_just_past_each_bound_faults_with_the_index_and_the_bounds() {
    let decls = "a : ARRAY[-2..3] OF INT; k : DINT := -3; n : DINT;";
    for k in ["-3", "4", "3", "-2"] {
        let body = format!("k := {k}; a[k] := 7; n := a[k];");
        let want = matches!(k, "-3" | "4").then_some(Fault::IndexOutOfRange);
        assert_eq!(three_ways(decls, &body, 2), want, "k = {k}");
    }
}

#[test]
fn a_pointer_into_the_image_without_an_image_is_a_bad_pointer() {
    let decls = "p : POINTER TO MC_CONTROL_DYN_CS_UNIT; u : UDINT;";
    for body in [
        "p := ADR(gpCh[0]^channel_mc_control.dyn_cs); u := p^.state_r.actual_state;",
        "p := ADR(gpCh[0]^channel_mc_control.dyn_cs); p^.enable_w := TRUE;",
    ] {
        // The pointer points into an image the cycle does not have.
        assert_eq!(
            three_ways(decls, body, 1),
            Some(Fault::BadPointer),
            "{body}"
        );
    }
}
