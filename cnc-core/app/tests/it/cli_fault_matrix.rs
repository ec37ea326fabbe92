//! The fault matrix: for every engine, a scenario whose PLC is killed (SIGKILL) or stopped
//! (SIGSTOP, hung) at a random cycle while the engine works: an axis command, a dynamic-CS
//! transition with its M-function handshakes, a cam data transfer, a FIFO row stream, the
//! flying saw's commands (`cli_supervision.rs` has the gear on a channel). Each run must end
//! in a controlled stop that reaches rest, with one line naming the cause, exit code 4, no
//! panic and no segment left.
//! The kill point is drawn from the process id and printed, so a failure names its case.

use super::cli_supervision::{finish, rest_ticks, segment, wait_for_plc_cycles};
use std::process::Stdio;
use tests::child::{plc_pid, signal};
use tests::Cli;

/// A scenario and the PLC cycles between which its engine is busy.
struct Case {
    scenario: &'static str,
    engine: &'static str,
    cycles: (u64, u64),
}

const CASES: &[Case] = &[
    Case {
        scenario: "axes-plcopen",
        engine: "axis commands (MC_MoveAbsolute, MC_MoveVelocity)",
        cycles: (20, 1500),
    },
    Case {
        scenario: "example4-turntable-plc",
        engine: "dynamic-CS transitions and M-function handshakes",
        cycles: (50, 2500),
    },
    Case {
        scenario: "cam-data",
        engine: "cam data transfer",
        cycles: (3, 400),
    },
    Case {
        scenario: "fifo-contour",
        engine: "FIFO row stream",
        cycles: (50, 4000),
    },
    Case {
        scenario: "saw-blocks",
        engine: "flying-saw commands",
        cycles: (30, 3000),
    },
];

/// A kill point in `range`, from `seed`.
fn draw(seed: u64, (lo, hi): (u64, u64)) -> u64 {
    let mixed = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(29);
    lo + mixed % (hi - lo)
}

fn run_case(case: &Case, how: &str, seed: u64) {
    let at = draw(seed, case.cycles);
    let label = format!(
        "{} ({}), SIG{how} at PLC cycle {at}",
        case.scenario, case.engine
    );
    eprintln!("fault matrix: {label}");
    let instance = tests::unique_instance(&format!("fm-{}", how.to_lowercase()));
    let path = tests::cli::repo_root()
        .join("scenarios")
        .join(case.scenario)
        .join("scenario.toml");
    let child = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["run", path.to_str().unwrap(), "--instance", &instance])
        .args(["--ticks", "200000", "--plc-watchdog-ticks", "50"])
        .current_dir(std::env::temp_dir())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for_plc_cycles(&instance, at);
    let pid = plc_pid(&instance).expect("the PLC process");
    assert!(signal(pid, how), "{label}");
    let (code, report) = finish(child);
    let _ = signal(pid, "KILL"); // a stopped PLC: the CNC killed it already; make sure
    assert_eq!(code, 4, "{label}\n{report}");
    assert_eq!(
        report.matches("PLC lost at tick").count(),
        2,
        "{label}: said once, reported once\n{report}"
    );
    assert!(!report.contains("panicked"), "{label}\n{report}");
    assert!(!report.contains("NOT at rest"), "{label}\n{report}");
    let rest = rest_ticks(&report);
    eprintln!("fault matrix: {label}: at rest {rest} ticks after the stop");
    assert!(!segment(&instance).exists(), "{label}: segment left behind");
}

fn seed() -> u64 {
    u64::from(std::process::id()) ^ 0x5EED
}

#[test]
fn a_plc_killed_while_an_engine_works_ends_in_a_controlled_stop() {
    for (i, case) in CASES.iter().enumerate() {
        run_case(case, "KILL", seed() + i as u64);
    }
}

#[test]
fn a_plc_hung_while_an_engine_works_ends_in_a_controlled_stop() {
    for (i, case) in CASES.iter().enumerate() {
        run_case(case, "STOP", seed() + 100 + i as u64);
    }
}
