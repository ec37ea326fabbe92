//! An ST PLC's variables by name for the tools (`st::vars`): the PLC publishes every
//! variable after a cycle a tool asked for a copy in, and takes a tool's write before the next; a value the type
//! cannot hold is refused; the object is gone when the PLC is.

use plc_shim::st::vars::Variables;
use plc_shim::st::StProgram;
use stand_in::StandIn;

use crate::stand_in;

const PROGRAM: &str = "TYPE ST_P : STRUCT x : LREAL; n : INT; END_STRUCT END_TYPE
PROGRAM MAIN
VAR
    nCount : DINT;
    bRun : BOOL := TRUE;
    fSpeed : LREAL := 1.5;
    aP : ARRAY[0..2] OF ST_P;
    fbT : TON;
    fbMove : MC_MoveVelocity;
    sName : STRING(20) := 'it$'s 100$$';
    sEmpty : STRING;
END_VAR
    IF bRun THEN nCount := nCount + 1; END_IF
    fbT(IN := TRUE, PT := T#250MS);
    aP[2].n := 7;
    fbMove(Execute := FALSE);
END_PROGRAM
";

/// The PLC's side: a stand-in CNC and the program, publishing on `instance`.
struct Plc {
    cnc: StandIn,
    program: StProgram,
}

impl Plc {
    fn new(instance: &str) -> Plc {
        let mut program = StProgram::from_texts(&[("main.st".into(), PROGRAM.into())], 1).unwrap();
        program.publish_on(instance).unwrap();
        Plc {
            cnc: StandIn::new("st-vars-cnc", 2),
            program,
        }
    }

    fn cycle(&mut self) {
        self.cnc.cycle(&mut self.program);
    }
}

#[test]
fn a_tool_reads_and_writes_an_st_plcs_variables_by_name() {
    let instance = tests::unique_instance("st-vars");
    let mut plc = Plc::new(&instance);
    for _ in 0..3 {
        plc.cycle();
    }
    let vars = Variables::open(&instance).unwrap();
    assert_eq!(vars.cycles(), 3);
    let count = vars.find("MAIN.nCount").unwrap();
    assert_eq!(vars.read(count), 0.0, "no copy before a tool asks for one");
    // A copy is made only when a tool asks: the PLC makes it in its next cycle.
    let vars = std::thread::spawn(move || {
        vars.refresh().unwrap();
        vars
    });
    while !vars.is_finished() {
        plc.cycle();
    }
    let vars = vars.join().unwrap();
    let value = |path: &str| vars.read(vars.find(path).unwrap_or_else(|| panic!("{path}")));
    let counted = value("MAIN.nCount");
    assert!(
        counted > 3.0 && counted <= vars.cycles() as f64,
        "a copy made after the request: {counted}"
    );
    assert_eq!(value("main.bRun"), 1.0, "ASCII case ignored");
    assert_eq!(value("MAIN.fSpeed"), 1.5);
    assert_eq!(value("MAIN.aP[2].n"), 7.0);
    assert_eq!(value("MAIN.fbMove.Busy"), 0.0, "a library block's output");
    assert_eq!(value("MAIN.fbT.PT"), 250.0, "a standard block's input (ms)");
    // Its outputs as its last call left them (how far its time ran depends on the cycles
    // the copy waited for).
    let (q, et) = (value("MAIN.fbT.Q"), value("MAIN.fbT.ET"));
    assert!(
        et > 0.0 && et <= 250.0 && (q == 1.0) == (et == 250.0),
        "{q} {et}"
    );
    assert_eq!(value("MAIN.fbT.IN"), 1.0);
    let text = |path: &str| vars.read_text(vars.find(path).unwrap_or_else(|| panic!("{path}")));
    assert_eq!(text("MAIN.sName").as_deref(), Some("'it$'s 100$$'"));
    assert_eq!(text("MAIN.sEmpty").as_deref(), Some("''"));
    assert_eq!(text("MAIN.fSpeed"), None, "no STRING");

    // A write is taken by the PLC before its next cycle: the tool waits for it there.
    let writer = std::thread::spawn(move || {
        let run = vars.find("MAIN.bRun").unwrap();
        let speed = vars.find("MAIN.fSpeed").unwrap();
        let refused = vars.write(vars.find("MAIN.aP[0].n").unwrap(), 40_000.0);
        // A STRING is never written through the tools, whatever a request says.
        let text = vars.write(vars.find("MAIN.sName").unwrap(), 65.0);
        assert!(text
            .unwrap_err()
            .contains("65 is not a value of STRING(20)"));
        let (run, speed) = (vars.write(run, 0.0), vars.write(speed, -2.25));
        (run, speed, refused, vars)
    });
    while !writer.is_finished() {
        plc.cycle();
    }
    let (run, speed, refused, vars) = writer.join().unwrap();
    assert_eq!((run, speed), (Ok(()), Ok(())));
    assert!(refused.unwrap_err().contains("40000 is not a value of INT"));

    // A tool's write to a block's output lasts until the block's next call (as in a PLC,
    // whose block writes its outputs every call), though the block writes them only when
    // they change.
    let reader = std::thread::spawn(move || {
        let busy = vars.find("MAIN.fbMove.Busy").unwrap();
        vars.write(busy, 1.0).unwrap();
        vars.refresh().unwrap();
        vars.read(busy)
    });
    while !reader.is_finished() {
        plc.cycle();
    }
    assert_eq!(reader.join().unwrap(), 0.0, "the block's own Busy again");
    let counted = plc.program.program().read_var("MAIN.nCount").unwrap();
    plc.cycle();
    assert_eq!(
        plc.program.program().read_var("MAIN.nCount"),
        Some(counted),
        "bRun is FALSE"
    );
    assert_eq!(plc.program.program().read_var("MAIN.fSpeed"), Some(-2.25));
    let memory = plc.program.program().memory();
    let name = plc.program.program().symbols(100);
    let name = name.iter().find(|s| s.path == "MAIN.sName").unwrap();
    assert_eq!(memory[name.offset as usize], b'i', "the STRING as it was");

    drop(plc);
    assert!(
        Variables::open(&instance).is_err(),
        "the object is gone with the PLC"
    );
}
