//! `cnc hli-demo` end to end: a real PLC process, every handshake kind completed, a trace written.

use std::process::Command;

#[test]
fn hli_demo_exchanges_every_unit_with_a_spawned_plc() {
    let out_dir = std::env::temp_dir().join(format!("cnc-demo-test-{}", std::process::id()));
    let instance = format!("demotest-{}", std::process::id());
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .args([
            "hli-demo",
            "--ticks",
            "400",
            "--m-every",
            "100",
            "--instance",
            &instance,
            "--out",
        ])
        .arg(&out_dir)
        .output()
        .expect("run cnc hli-demo");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Tracking switched on by the PLC's transition, through the filter, to ACTIVE.
    assert!(stdout.contains(": Activating"), "{stdout}");
    assert!(stdout.contains(": Active"), "{stdout}");
    assert!(stdout.contains("transitions 1"), "{stdout}");
    assert!(stdout.contains("protocol violations 0"), "{stdout}");
    assert!(
        stdout.contains("M functions announced 4 / acknowledged"),
        "{stdout}"
    );
    assert!(stdout.contains("ended by CncClosed"), "{stdout}");
    assert!(stdout.contains("protocol errors 0"), "{stdout}");
    // The table axis: powered and turned by the PLC's motion blocks, without an axis error.
    assert!(stdout.contains("table in velocity true"), "{stdout}");
    assert!(stdout.contains("nAxisState 2, error 0x0"), "{stdout}");
    let trace = std::fs::read_to_string(out_dir.join("trace.csv")).unwrap();
    let mut lines = trace.lines();
    assert!(lines.next().unwrap().starts_with("tick,time,"));
    assert_eq!(lines.count(), 400);
}
