//! Progress of a long run: drawn on a terminal (a pseudo-terminal from `script`), absent when
//! stderr is a pipe.

use tests::{Cli, Scratch};

fn scenario() -> String {
    tests::cli::repo_root()
        .join("scenarios/example4-turntable-plc/program.toml")
        .display()
        .to_string()
}

#[test]
fn a_run_shows_progress_on_a_terminal_only() {
    let cnc = env!("CARGO_BIN_EXE_cnc");
    // A pipe: nothing but the report.
    let out = Cli::new(cnc)
        .args(["run", &scenario(), "--ticks", "1500"])
        .args(["--instance", &tests::unique_instance("progress-pipe")])
        .output()
        .unwrap();
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains('\r') && !err.contains("ticks ("), "{err}");
    // A terminal: the bar, with the run's length. `script` gives the run a pseudo-terminal.
    if Cli::new("script").arg("--version").output().is_err() {
        eprintln!("skipped the terminal half: no `script` (util-linux) on this machine");
        return;
    }
    let scratch = Scratch::new("progress");
    let log = scratch.join("progress.log");
    let command = format!(
        "{cnc} run {} --ticks 1500 --instance {}",
        scenario(),
        tests::unique_instance("progress-tty")
    );
    let status = Cli::new("script")
        .args(["-qec", &command])
        .arg(&log)
        .output()
        .unwrap();
    assert!(status.status.success(), "{status:?}");
    let text = String::from_utf8_lossy(&std::fs::read(&log).unwrap()).into_owned();
    assert!(text.contains("/1500 ticks"), "{text}");
}
