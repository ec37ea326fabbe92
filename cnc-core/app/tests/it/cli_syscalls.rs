//! The CNC's real-time loop makes no system call per tick but its wake-up: `strace -f` on
//! `cnc run` of the demo machine (with its PLC process) counts, for the CNC's loop thread
//! between its first and last sleep, how often each system call came. Per tick there are the
//! sleep to the next deadline (`clock_nanosleep`) and the "tick done" event (`sendto`); every
//! other call comes far less often than once per tick (the PLC's process checked every 64
//! ticks, ...). Skipped, and said so, where strace is not installed (CI installs it).

use std::collections::BTreeMap;
use tests::{Cli, Scratch};

#[test]
fn the_cnc_loop_makes_no_system_call_per_tick_but_its_wake_up() {
    // Installed and allowed to trace here (some containers forbid ptrace).
    let traces = Cli::new("strace")
        .args(["-f", "-o", "/dev/null", "true"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !traces {
        println!("skipped: strace is not installed or may not trace (apt-get install strace)");
        return;
    }
    let dir = Scratch::new("syscalls");
    let log = dir.join("strace.log");
    let scenario = tests::cli::scenario("demo");
    let instance = tests::unique_instance("syscalls");
    let ticks = 2000u64;
    let out = Cli::new("strace")
        .args(["-f", "-o"])
        .arg(&log)
        .arg(env!("CARGO_BIN_EXE_cnc"))
        .arg("run")
        .arg(&scenario)
        .args(["--ticks", &ticks.to_string(), "--instance", &instance])
        // strace slows both processes: the CNC must not take its PLC for lost meanwhile,
        // nor stop for ticks longer than 1 ms (each system call traced costs tens of us:
        // on a slow runner the traced tick's work passed 1 ms and the machine stopped).
        // The calls per tick are the same at any cycle.
        .args(["--plc-watchdog-ticks", "100000", "--cycle-ms", "4"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", tests::cli::report(&out));
    let text = std::fs::read_to_string(&log).unwrap();
    // The CNC's loop runs on the process's main thread: the first pid in the log.
    let main = text.split_whitespace().next().unwrap().to_string();
    let calls: Vec<&str> = text
        .lines()
        .filter_map(|l| l.strip_prefix(&format!("{main} ")))
        .map(|l| l.trim_start())
        .filter(|l| !l.starts_with("<...") && !l.starts_with("+++") && !l.starts_with("---"))
        .filter_map(|l| l.split('(').next())
        .collect();
    // The middle of the loop: from the sleep a tenth in to the one a tenth from the end
    // (start-up and shutdown wait for the PLC with sleeps and process checks of their own).
    let sleeps_at: Vec<usize> = (0..calls.len())
        .filter(|&i| calls[i] == "clock_nanosleep")
        .collect();
    let (first, last) = (
        sleeps_at[sleeps_at.len() / 10],
        sleeps_at[sleeps_at.len() * 9 / 10],
    );
    let mut counts: BTreeMap<&str, u64> = BTreeMap::new();
    for c in &calls[first..=last] {
        *counts.entry(c).or_default() += 1;
    }
    let sleeps = counts["clock_nanosleep"];
    assert!(sleeps * 10 >= ticks * 7, "one sleep per tick: {counts:?}");
    let per_tick = |name: &str| counts.get(name).copied().unwrap_or(0) as f64 / sleeps as f64;
    assert!(per_tick("sendto") <= 1.01, "one event per tick: {counts:?}");
    for (name, n) in &counts {
        if *name != "clock_nanosleep" && *name != "sendto" {
            assert!(
                (*n as f64) < sleeps as f64 / 20.0,
                "{name} {n} times in {sleeps} ticks: a system call in the loop: {counts:?}"
            );
        }
    }
    println!("CNC loop, {sleeps} ticks: {counts:?}");
}
