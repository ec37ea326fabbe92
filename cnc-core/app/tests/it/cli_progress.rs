//! Progress of a long run: drawn on a terminal (a pseudo-terminal from `script`), absent when
//! stderr is a pipe.

use std::path::PathBuf;
use std::process::Command;

fn scenario() -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios/example4-turntable-plc/program.toml")
        .display()
        .to_string()
}

#[test]
fn a_run_shows_progress_on_a_terminal_only() {
    let pid = std::process::id();
    let cnc = env!("CARGO_BIN_EXE_cnc");
    // A pipe: nothing but the report.
    let out = Command::new(cnc)
        .args(["run", &scenario(), "--ticks", "1500"])
        .args(["--instance", &format!("progress-pipe-{pid}")])
        .output()
        .unwrap();
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains('\r') && !err.contains("ticks ("), "{err}");
    // A terminal: the bar, with the run's length. `script` gives the run a pseudo-terminal.
    if Command::new("script").arg("--version").output().is_err() {
        eprintln!("skipped the terminal half: no `script` (util-linux) on this machine");
        return;
    }
    let log = std::env::temp_dir().join(format!("progress-{pid}.log"));
    let command = format!(
        "{cnc} run {} --ticks 1500 --instance progress-tty-{pid}",
        scenario()
    );
    let status = Command::new("script")
        .args(["-qec", &command])
        .arg(&log)
        .output()
        .unwrap();
    assert!(status.status.success(), "{status:?}");
    let text = String::from_utf8_lossy(&std::fs::read(&log).unwrap()).into_owned();
    let _ = std::fs::remove_file(&log);
    assert!(text.contains("/1500 ticks"), "{text}");
}
