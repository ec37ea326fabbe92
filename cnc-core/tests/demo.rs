//! `cnc demo`: the embedded examples 3 and 4 run end to end with a spawned PLC process.

use std::process::Command;

fn demo(extra: &[&str], tag: &str) -> (String, std::path::PathBuf) {
    let out_dir = std::env::temp_dir().join(format!("cnc-demo-{tag}-{}", std::process::id()));
    let instance = format!("demo{tag}-{}", std::process::id());
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .arg("demo")
        .args(extra)
        .args(["--instance", &instance, "--out"])
        .arg(&out_dir)
        .output()
        .expect("run cnc demo");
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (stdout, out_dir)
}

#[test]
fn demo_runs_examples_3_and_4_to_their_end() {
    let (stdout, dir) = demo(&["--lockstep"], "full");
    // Example 3: both slaves switched on, followed, switched off; every program finished.
    assert_eq!(
        stdout.matches("dynCS: is on = DYN_CS_SYNC_ACTIVE").count(),
        3,
        "{stdout}"
    );
    assert_eq!(
        stdout
            .matches("dynCS: is off = DYN_CS_SYNC_INACTIVE")
            .count(),
        3,
        "{stdout}"
    );
    assert!(!stdout.contains("error at line"), "{stdout}");
    assert_eq!(stdout.matches(": finished;").count(), 4, "{stdout}");
    // Example 4: the PLC acknowledged M100 and M101 and commanded the table angle.
    assert!(stdout.contains("M functions acknowledged 2"), "{stdout}");
    assert!(stdout.contains("cmd=ON PLC=1"), "{stdout}");
    assert!(stdout.contains("ended by CncClosed"), "{stdout}");
    assert!(stdout.contains("tick compute p50"), "{stdout}");
    for name in ["example3-moving-workpiece", "example4-turntable-plc"] {
        let trace = std::fs::read_to_string(dir.join(format!("{name}.csv"))).unwrap();
        assert!(trace.starts_with("tick,time,"));
        assert!(trace.lines().count() > 10_000, "{name}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn demo_runs_in_real_time() {
    let (stdout, dir) = demo(&["--ticks", "400"], "rt");
    assert_eq!(stdout.matches("ticks 400;").count(), 2, "{stdout}");
    assert!(stdout.contains("real-time mode"), "{stdout}");
    let _ = std::fs::remove_dir_all(dir);
}
