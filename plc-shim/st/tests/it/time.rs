//! TIME (ms in 32 bits) and LTIME (ns in 64 bits) together: an LTIME literal keeps its
//! nanoseconds, a TIME widened or converted to LTIME keeps its length (ms become ns), and a
//! TIME literal TIME cannot hold is refused at load.

use plc_st::vm::Program;

#[test]
fn ltime_counts_ns_and_time_ms_and_each_keeps_its_length_in_the_other() {
    let mut p = Program::load(&[(
        "main.st",
        "PROGRAM MAIN
VAR
    ltLit : LTIME := LTIME#1S5US;
    ltWide : LTIME := T#1S;
    ltSum, ltConv : LTIME;
    tBack : TIME;
    bLonger : BOOL;
END_VAR
    ltSum := ltLit + T#2MS;
    ltConv := TIME_TO_LTIME(T#1M);
    tBack := LTIME_TO_TIME(LTIME#1500MS999US);
    bLonger := ltLit > T#1S;
END_PROGRAM",
    )])
    .unwrap_or_else(|e| panic!("{e:?}"));
    p.cycle(0).unwrap();
    assert_eq!(p.read_var("MAIN.ltLit"), Some(1_000_005_000.0));
    assert_eq!(p.read_var("MAIN.ltWide"), Some(1e9));
    assert_eq!(p.read_var("MAIN.ltSum"), Some(1_002_005_000.0));
    assert_eq!(p.read_var("MAIN.ltConv"), Some(60e9));
    assert_eq!(p.read_var("MAIN.tBack"), Some(1500.0));
    assert_eq!(p.read_var("MAIN.bLonger"), Some(1.0));
}

#[test]
fn a_time_literal_beyond_time_is_refused_with_its_place() {
    let e = Program::load(&[(
        "main.st",
        "PROGRAM MAIN VAR t : TIME; END_VAR\n  t := T#30D;\nEND_PROGRAM",
    )])
    .expect_err("refused");
    let text: String = e.iter().map(|d| d.to_string()).collect();
    assert!(
        text.contains("main.st:2:8: error: a TIME literal beyond TIME's T#24d20h31m23s647ms"),
        "{text}"
    );
    // The same duration as an LTIME loads.
    let ok = Program::load(&[(
        "main.st",
        "PROGRAM MAIN VAR t : LTIME; END_VAR\n  t := LTIME#30D;\nEND_PROGRAM",
    )]);
    assert!(ok.is_ok());
}
