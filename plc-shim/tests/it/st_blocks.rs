//! The block library in ST on a stand-in CNC: an instance sends its call on the rising edge
//! of Execute, a value outside its input's kind ends the command with Error and 0x4227 and
//! sends nothing, and a cycle with library blocks (and its variables published) allocates
//! nothing.

use plc_shim::st::host::INVALID_INPUT;
use plc_shim::st::StProgram;

use crate::counting_alloc;
use crate::stand_in;

/// MC_MoveVelocity on gpAx[1] with Execute and Direction from the test.
const PROGRAM: &str = "PROGRAM MAIN
VAR
    axSpindle : AXIS_REF;
    fbRun : MC_MoveVelocity;
    bRun : BOOL;
    nDirection : DINT := 1;
    bBusy, bError : BOOL;
    nErrorId : UDINT;
END_VAR
    axSpindle.AxisIndex := 1;
    fbRun(Axis := axSpindle, Execute := bRun, Velocity := 50.0, Direction := nDirection,
        Acceleration := 500.0, Deceleration := 500.0, Jerk := 10000.0,
        Busy => bBusy, Error => bError, ErrorID => nErrorId);
END_PROGRAM
";

use stand_in::StandIn as Cnc;

/// `PROGRAM` with `Direction` and `Execute` set before the cycle, through its initial values.
fn program(direction: i32, execute: bool) -> StProgram {
    let text = PROGRAM
        .replace(
            "nDirection : DINT := 1;",
            &format!("nDirection : DINT := {direction};"),
        )
        .replace(
            "bRun : BOOL;",
            &format!("bRun : BOOL := {};", if execute { "TRUE" } else { "FALSE" }),
        );
    StProgram::from_texts(&[("main.st".into(), text)], 1).unwrap()
}

fn var(p: &StProgram, name: &str) -> f64 {
    p.program().read_var(&format!("MAIN.{name}")).unwrap()
}

#[test]
fn an_instance_sends_its_call_on_the_rising_edge_of_execute() {
    let mut cnc = Cnc::new("st-blocks-edge", 2);
    let mut p = program(1, true);
    assert_eq!(p.program().library_instances().len(), 1);
    cnc.cycle(&mut p);
    assert_eq!(cnc.client.sent(), 1, "the call went out");
    assert_eq!((var(&p, "bBusy"), var(&p, "bError")), (1.0, 0.0));
    cnc.cycle(&mut p);
    assert_eq!(cnc.client.sent(), 1, "Execute held: no second call");
}

#[test]
fn a_value_outside_its_inputs_kind_ends_the_command_with_0x4227() {
    let mut cnc = Cnc::new("st-blocks-refused", 2);
    let mut p = program(0, true);
    for _ in 0..3 {
        cnc.cycle(&mut p);
        assert_eq!(cnc.client.sent(), 0, "nothing sent");
        assert_eq!((var(&p, "bBusy"), var(&p, "bError")), (0.0, 1.0));
        assert_eq!(var(&p, "nErrorId"), f64::from(INVALID_INPUT));
    }
}

#[test]
fn a_cycle_with_library_blocks_allocates_nothing() {
    let mut cnc = Cnc::new("st-blocks-alloc", 2);
    // Busy: the call is out and waits for its answer, the kernel follows it each cycle; the
    // variables are published for the tools each cycle too.
    let mut p = program(1, true);
    p.publish_on(&tests::unique_instance("st-blocks-alloc-vars"))
        .unwrap();
    cnc.cycle(&mut p);
    let before = counting_alloc::allocations();
    for _ in 0..50 {
        cnc.cycle(&mut p);
    }
    assert_eq!(counting_alloc::allocations() - before, 0);
}

#[test]
fn an_input_no_call_gives_keeps_the_blocks_default() {
    let mut cnc = Cnc::new("st-blocks-default", 2);
    // No Direction in the call: MC_MoveVelocity's own default (positive) holds, where a 0
    // passed on would have been refused.
    let text = PROGRAM
        .replace("Direction := nDirection,", "")
        .replace("bRun : BOOL;", "bRun : BOOL := TRUE;");
    let mut p = StProgram::from_texts(&[("main.st".into(), text)], 1).unwrap();
    cnc.cycle(&mut p);
    assert_eq!(cnc.client.sent(), 1);
    assert_eq!((var(&p, "bBusy"), var(&p, "bError")), (1.0, 0.0));
}

#[test]
fn rows_through_a_null_pointer_end_the_command_with_0x4227_and_send_nothing() {
    let mut cnc = Cnc::new("st-blocks-rows", 2);
    let text = "PROGRAM MAIN VAR fbW : FiFoWrite; bErr : BOOL; nErr : UDINT; END_VAR
        fbW(bExecute := TRUE, iColDim := 2, iRowsToWrite := 1, bErr => bErr, iErrId => nErr);
        END_PROGRAM";
    let mut p = StProgram::from_texts(&[("main.st".into(), text.into())], 1).unwrap();
    cnc.cycle(&mut p);
    assert_eq!(cnc.client.sent(), 0);
    assert_eq!(var(&p, "bErr"), 1.0);
    assert_eq!(var(&p, "nErr"), f64::from(INVALID_INPUT));
}

#[test]
fn an_input_given_before_the_edge_counts_at_the_edge() {
    let mut cnc = Cnc::new("st-blocks-before", 2);
    // Direction 0 is given while Execute is FALSE; the edge in a later cycle takes it (and
    // refuses it), as a PLC block holds its inputs from call to call.
    let text = "PROGRAM MAIN VAR ax : AXIS_REF; fbRun : MC_MoveVelocity; n : INT; bErr : BOOL;
        nErr : UDINT; END_VAR
        ax.AxisIndex := 1; n := n + 1;
        IF n = 1 THEN fbRun(Axis := ax, Velocity := 50.0, Direction := 0);
        ELSE fbRun(Execute := TRUE, Error => bErr, ErrorID => nErr); END_IF
        END_PROGRAM";
    let mut p = StProgram::from_texts(&[("main.st".into(), text.into())], 1).unwrap();
    cnc.cycle(&mut p);
    cnc.cycle(&mut p);
    assert_eq!(cnc.client.sent(), 0, "nothing sent");
    assert_eq!(var(&p, "bErr"), 1.0);
    assert_eq!(var(&p, "nErr"), f64::from(INVALID_INPUT));
}

#[test]
fn t_timeout_ends_an_unanswered_command_after_its_time() {
    let mut cnc = Cnc::new("st-blocks-timeout", 2);
    // The stand-in CNC announces a 1 ms cycle and never answers: 5 ms are 5 PLC cycles.
    let at = core::mem::offset_of!(hli::layout::HliSegmentHeader, cnc_cycle_ns);
    cnc.memory.place::<u32>(at).store(1_000_000);
    let text = "PROGRAM MAIN VAR fbStart : FiFoStart; bBusy, bErr : BOOL; nErr : UDINT; END_VAR
        fbStart(bExecute := TRUE, tTimeout := T#5MS, bBusy => bBusy, bErr => bErr,
            iErrId => nErr);
        END_PROGRAM";
    let mut p = StProgram::from_texts(&[("main.st".into(), text.into())], 1).unwrap();
    let mut busy_cycles = 0;
    while var(&p, "bErr") == 0.0 && busy_cycles < 100 {
        cnc.cycle(&mut p);
        busy_cycles += u32::from(var(&p, "bBusy") == 1.0);
    }
    // Busy in the edge's cycle and the 5 it waits (the kernel ends a call not answered
    // within tTimeout's cycles in the next one).
    assert_eq!(busy_cycles, 6, "busy for the edge and tTimeout's 5 cycles");
    assert_eq!(
        var(&p, "nErr"),
        f64::from(plc_shim::kernel::ERROR_NO_ANSWER)
    );
    let refused = text.replace("T#5MS", "T#0MS");
    let mut p = StProgram::from_texts(&[("main.st".into(), refused)], 1).unwrap();
    cnc.cycle(&mut p);
    assert_eq!(
        var(&p, "nErr"),
        f64::from(INVALID_INPUT),
        "a tTimeout of 0 is refused"
    );
}

/// A library block's instance takes no initial values for its inputs in its declaration
/// (a standard block's does: `TON := (PT := T#2S)`): the host takes them from its calls,
/// so it is refused with its place instead of being silently ignored.
#[test]
fn an_initial_value_for_a_library_blocks_input_is_refused_with_its_place() {
    let text = PROGRAM.replace(
        "fbRun : MC_MoveVelocity;",
        "fbRun : MC_MoveVelocity := (Velocity := 20.0);",
    );
    let Err(refused) = StProgram::from_texts(&[("main.st".into(), text)], 1) else {
        panic!("loaded");
    };
    assert_eq!(
        refused,
        "main.st:4:5: error: an initial value for an input of library block MC_MoveVelocity: \
         its inputs are given in its calls\n"
    );
}

/// A library block called from a METHOD of the block that holds it (an element of an array
/// of such blocks): the method runs on that instance, so the block's host finds the
/// instance's slot and sends its call on the edge, once.
#[test]
fn a_method_calls_its_instances_library_block() {
    let text = "FUNCTION_BLOCK FB_Spindle
VAR
    stAxis : AXIS_REF;
    fbRun : MC_MoveVelocity;
END_VAR
METHOD M_Run : BOOL
VAR_INPUT nAxis : UDINT; bOn : BOOL; END_VAR
    stAxis.AxisIndex := nAxis;
    fbRun(Axis := stAxis, Execute := bOn, Velocity := 50.0, Direction := 1,
        Acceleration := 500.0, Deceleration := 500.0, Jerk := 10000.0);
    M_Run := fbRun.Busy;
END_METHOD
END_FUNCTION_BLOCK
PROGRAM MAIN
VAR
    aSpindles : ARRAY[0..1] OF FB_Spindle;
    bBusy : BOOL;
END_VAR
    bBusy := aSpindles[1].M_Run(nAxis := 1, bOn := TRUE);
END_PROGRAM
";
    let mut cnc = Cnc::new("st-blocks-method", 2);
    let mut p = StProgram::from_texts(&[("main.st".into(), text.into())], 1).unwrap();
    assert_eq!(p.program().library_instances().len(), 2);
    cnc.cycle(&mut p);
    assert_eq!(cnc.client.sent(), 1, "the call went out");
    assert_eq!(var(&p, "bBusy"), 1.0);
    cnc.cycle(&mut p);
    assert_eq!(cnc.client.sent(), 1, "Execute held: no second call");
}
