//! `plc channel` (here as `cnc plc channel`) against a live CNC in real time: a program
//! selected from the channel's folder and started, a refused second start, feed hold, stop,
//! a program that fails its check refused with FILE:LINE:COL, a channel that does not exist.

use std::process::Stdio;
use tests::cli::wait_until;
use tests::{Cli, Scratch};

fn tool(instance: &str, args: &[&str]) -> (i32, String, String) {
    let mut all = vec!["plc", "channel"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--instance", instance]);
    tests::cli::code_and_text(env!("CARGO_BIN_EXE_cnc"), &all)
}

fn state(instance: &str) -> String {
    let (code, out, err) = tool(instance, &["state"]);
    assert_eq!(code, 0, "{err}");
    out
}

#[test]
fn plc_channel_selects_starts_holds_stops_and_refuses_with_codes() {
    let instance = tests::unique_instance("plcchannel");
    let dir = Scratch::new("plc-channel");
    std::fs::create_dir_all(dir.join("programs")).unwrap();
    std::fs::write(dir.join("programs/part.nc"), "G1 X500 F600\nM30\n").unwrap();
    std::fs::write(dir.join("programs/bad.nc"), "G1 X1 F600\nG1 X=\nM30\n").unwrap();
    std::fs::write(
        dir.join("scenario.toml"),
        "cycle_ms = 1.0\n[[channel]]\nname = \"cell\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprograms = \"programs\"\n",
    )
    .unwrap();
    let mut cnc = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["run", dir.join("scenario.toml").to_str().unwrap()])
        .args(["--instance", &instance, "--ticks", "600000"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_until("the CNC runs", || tool(&instance, &["state"]).0 == 0);
    assert!(state(&instance).contains("state = Idle"));

    let (code, out, err) = tool(&instance, &["start", "--program", "part.nc"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        out.contains("Select: done") && out.contains("Start: done"),
        "{out}"
    );
    assert!(state(&instance).contains("program = part.nc"));
    let (code, _, err) = tool(&instance, &["start"]);
    assert_eq!(code, 4, "{err}");
    assert!(err.contains("0x4A05 Running"), "{err}");

    let (code, _, err) = tool(&instance, &["hold"]);
    assert_eq!(code, 0, "{err}");
    assert!(state(&instance).contains("state = Holding"));
    let (code, _, err) = tool(&instance, &["stop"]);
    assert_eq!(code, 0, "{err}");
    assert!(state(&instance).contains("state = Selected"));

    let (code, _, err) = tool(&instance, &["select", "--program", "bad.nc"]);
    assert_eq!(code, 4, "{err}");
    assert!(
        err.contains("ProgramInvalid") && err.contains("bad.nc:2:"),
        "{err}"
    );
    let (code, _, err) = tool(&instance, &["select", "--program", "missing.nc"]);
    assert_eq!(code, 4, "{err}");
    assert!(err.contains("ProgramNotFound"), "{err}");
    let (code, _, err) = tool(&instance, &["state", "--channel", "3"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("channel 3 does not exist"), "{err}");

    // A PLC attached owns the unit: the tool refuses to send beside it, unless --force.
    let plc = hli_transport::segment::PlcSegment::attach(&instance).unwrap();
    let (code, _, err) = tool(&instance, &["start"]);
    assert_eq!(code, 4, "{err}");
    assert!(err.contains("a PLC (pid"), "{err}");
    assert!(state(&instance).contains("state = Selected"));
    let (code, _, err) = tool(&instance, &["start", "--force"]);
    assert_eq!(code, 0, "{err}");
    drop(plc);
    // Stopped by a signal, the CNC leaves no shared memory behind: segment and mailbox gone.
    assert!(cnc.signal("TERM"));
    let out = cnc.wait_with_output(std::time::Duration::from_secs(60));
    let out = out.unwrap();
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(
        said.contains("SIGTERM") || said.contains("signal"),
        "{said}"
    );
    for object in [
        format!("cncplc_{instance}.hli"),
        format!("cncplc_{instance}.calls"),
    ] {
        let path = std::path::Path::new("/dev/shm").join(&object);
        assert!(!path.exists(), "{object} left behind");
    }
}
