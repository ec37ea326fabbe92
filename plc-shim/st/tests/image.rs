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
