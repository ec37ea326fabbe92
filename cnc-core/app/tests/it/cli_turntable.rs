//! Seed 003's application example 4 with the PLC as a program (`turntable-hybrid`,
//! `turntable-plc-only`, built on the dynamic-CS and M-function blocks) in its own process, in
//! lockstep: each run's trace is bit for bit the trace of the timeline version, whose outcome
//! `scenarios.rs` checks (the robot on the programmed square of the turning workpiece), and
//! the program's report shows the handshakes it made.

fn run(dir: &str, file: &str) -> (String, Vec<u8>) {
    let path = tests::cli::repo_root().join(format!("scenarios/{dir}/{file}"));
    tests::cli::cnc_run_lockstep(env!("CARGO_BIN_EXE_cnc"), &path, "tt")
}

#[test]
fn the_hybrid_program_does_what_the_timeline_does() {
    let (report, program) = run("example4-turntable-hybrid", "program.toml");
    // The NC switches; the PLC only commands the frame while ACTIVE, every cycle.
    assert!(
        report.contains("turntable (Hybrid): transitions sent 0 done 0 failed 0, M functions 0"),
        "{report}"
    );
    assert!(
        report.contains("frames 7201 (waited 0), error 0x0"),
        "{report}"
    );
    let (_, timeline) = run("example4-turntable-hybrid", "scenario.toml");
    assert!(
        program == timeline,
        "the program's trace differs from the timeline's"
    );
}

#[test]
fn the_plc_only_program_switches_on_m100_and_m101() {
    let (report, program) = run("example4-turntable-plc", "program.toml");
    // Two transitions (ON on M100, OFF on M101), both Done (ACTIVE, then INACTIVE seen; the
    // OFF in the CNC's last tick, which lockstep gives the PLC a cycle for), and both M
    // functions acknowledged.
    assert!(
        report.contains(
            "turntable (PlcOnly): transitions sent 2 done 2 failed 0, M functions 2 acknowledged 2"
        ),
        "{report}"
    );
    assert!(
        // FILTER=0 shows ACTIVATING for one tick before the frames of ACTIVE.
        report.contains("frames 7200 (waited 0), error 0x0"),
        "{report}"
    );
    let (_, timeline) = run("example4-turntable-plc", "scenario.toml");
    assert!(
        program == timeline,
        "the program's trace differs from the timeline's"
    );
}
