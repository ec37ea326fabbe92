//! Programs on the HLI image, as the manuals write them: pointers from `gpCh` into the
//! channel's units, typed literals into the image's integer units, and the CNC's leaves
//! refused for writing (at load where the path says so, in the cycle where a pointer hides it).

use hli::access::{Leaf, Value};
use plc_st::vm::{Fault, Program};

const MASTER: &str = "
PROGRAM MAIN
VAR
    pDynCs : POINTER TO MC_CONTROL_DYN_CS_UNIT;
    nState : UDINT;
END_VAR
    pDynCs := ADR(gpCh[0]^channel_mc_control.dyn_cs);
    pDynCs^.enable_w := TRUE;
    pDynCs^.command_w.translation[0] := DINT#-13059200;
    nState := pDynCs^.state_r.actual_state;
END_PROGRAM";

fn load(main: &str) -> Result<Program, String> {
    let prelude = hli::st_prelude::generate();
    Program::load(&[("hli.st", &prelude), ("main.st", main)])
        .map(|mut p| {
            p.bind_image();
            p
        })
        .map_err(|e| e.iter().map(|d| d.to_string() + "\n").collect())
}

fn leaf(path: &str) -> Leaf {
    Leaf::resolve(path).unwrap()
}

#[test]
fn a_program_writes_and_reads_the_channel_unit_through_its_pointer() {
    let image = hli::image::heap_image(1, 6);
    leaf("gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state")
        .write(&image, Value::Unsigned(2));
    let mut p = load(MASTER).unwrap();
    p.cycle_on(0, Some(&image)).unwrap();
    let enable = leaf("gpCh[0]^channel_mc_control.dyn_cs.enable_w").read(&image);
    assert_eq!(enable, Value::Unsigned(1));
    let x = leaf("gpCh[0]^channel_mc_control.dyn_cs.command_w.translation[0]").read(&image);
    assert_eq!(x, Value::Int(-13_059_200));
    assert_eq!(
        p.read_var("MAIN.nState"),
        Some(2.0),
        "read from the CNC's leaf"
    );
}

#[test]
fn a_write_to_a_cnc_leaf_is_refused_at_load_with_its_place() {
    let text = "PROGRAM MAIN VAR p : POINTER TO MC_CONTROL_DYN_CS_UNIT; END_VAR\n\
                p := ADR(gpCh[0]^channel_mc_control.dyn_cs);\n\
                p^.state_r.actual_state := 3;\nEND_PROGRAM";
    let e = load(text).unwrap_err();
    assert!(
        e.contains("main.st:3:1: error: `state_r` of the image is written by the CNC"),
        "{e}"
    );
}

#[test]
fn a_write_to_a_cnc_leaf_through_a_bare_pointer_faults_in_the_cycle() {
    // A pointer to the CNC's UDINT leaf itself: the path says nothing, the cycle refuses it.
    let text = "PROGRAM MAIN VAR p : POINTER TO UDINT; END_VAR\n\
                p := ADR(gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state);\n\
                p^ := 3;\nEND_PROGRAM";
    let image = hli::image::heap_image(1, 6);
    let mut p = load(text).unwrap();
    let fault = p.cycle_on(0, Some(&image)).unwrap_err();
    assert_eq!(fault.fault, Fault::ReadOnly);
    assert!(p
        .fault_text(&fault)
        .starts_with("main.st:3:1: fault: a write to a leaf of the image the CNC writes"));
    // Without an image, a pointer into it is a bad pointer, not a write to nowhere.
    let mut p = load(text).unwrap();
    assert_eq!(p.cycle(0).unwrap_err().fault, Fault::BadPointer);
}

#[test]
fn a_real_of_the_image_that_is_not_finite_faults_where_it_is_read() {
    let text = "PROGRAM MAIN VAR x : LREAL; END_VAR\n\
                x := gpAx[0]^.drive_state.probe_r[1].recorded_position_r;\nEND_PROGRAM";
    let path = "gpAx[0]^drive_state.probe_r[1].recorded_position_r";
    let image = hli::image::heap_image(1, 6);
    let mut p = load(text).unwrap();
    leaf(path).write(&image, Value::Real(12.5));
    p.cycle_on(0, Some(&image)).unwrap();
    assert_eq!(p.read_var("MAIN.x"), Some(12.5));
    leaf(path).write(&image, Value::Real(f64::NAN));
    let fault = p.cycle_on(1_000_000, Some(&image)).unwrap_err();
    assert_eq!(fault.fault, Fault::NotFinite);
    assert!(p
        .fault_text(&fault)
        .starts_with("main.st:2:1: fault: a real of the image that is not finite"));
}

/// Native code reaches the image as the operations do: the same values in the image and the
/// program, the same fault at the same place (a leaf read and written through a pointer of
/// each width, a pointer past a leaf's start, a write to the CNC's leaf, a real that is not
/// finite).
#[test]
fn native_code_reaches_the_image_as_the_operations_do() {
    let cases = [
        "pDynCs^.command_w.translation[1] := DINT#-7; nState := pDynCs^.state_r.actual_state;",
        "pDynCs^.enable_w := NOT pDynCs^.enable_w; nState := pDynCs^.state_r.actual_state + 1;",
        "pU := ADR(pDynCs^.state_r.actual_state); nState := pU^ + 2;",
        "pU := ADR(pDynCs^.state_r.actual_state) + 1; nState := pU^;",
        "pU := ADR(pDynCs^.state_r.actual_state); pU^ := 9;",
        "x := gpAx[0]^.drive_state.probe_r[1].recorded_position_r;",
    ];
    for (k, body) in cases.iter().enumerate() {
        let text = format!(
            "PROGRAM MAIN\nVAR\n pDynCs : POINTER TO MC_CONTROL_DYN_CS_UNIT;\n pU : POINTER TO UDINT;\n \
             nState : UDINT;\n x : LREAL;\nEND_VAR\n\
             pDynCs := ADR(gpCh[0]^channel_mc_control.dyn_cs);\n{body}\nEND_PROGRAM"
        );
        let runs: Vec<_> = [true, false]
            .into_iter()
            .map(|native| {
                let image = hli::image::heap_image(1, 6);
                leaf("gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state")
                    .write(&image, Value::Unsigned(4));
                let probe = leaf("gpAx[0]^drive_state.probe_r[1].recorded_position_r");
                probe.write(
                    &image,
                    Value::Real(if k == 5 { f64::INFINITY } else { 1.5 }),
                );
                let mut p = load(&text).unwrap();
                if native {
                    assert!(p.is_native(), "case {k}");
                } else {
                    p.operations_only();
                }
                let r = (0..2)
                    .map(|c| p.cycle_on(c, Some(&image)))
                    .collect::<Vec<_>>();
                (r, p.memory().to_vec(), image.snapshot())
            })
            .collect();
        assert_eq!(runs[0].0, runs[1].0, "case {k}: the cycles' results");
        let fault = runs[0].0[0].err().map(|f| f.fault);
        let want = [
            None,
            None,
            None,
            Some(Fault::BadPointer),
            Some(Fault::ReadOnly),
        ];
        let want = want.get(k).copied().unwrap_or(Some(Fault::NotFinite));
        assert_eq!(fault, want, "case {k}");
        assert!(runs[0].1 == runs[1].1, "case {k}: the programs' memory");
        assert!(runs[0].2 == runs[1].2, "case {k}: the images");
    }
}
