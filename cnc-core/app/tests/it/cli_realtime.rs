//! Real-time options: applied where the system allows, each refused one left out with one
//! warning and the run going on; unknown keys refused.

use tests::Cli;

#[test]
fn a_refused_option_warns_once_and_the_run_goes_on() {
    let scenario = tests::cli::scenario("axes-plcopen");
    let instance = tests::unique_instance("rt");
    let out = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args([
            "run",
            scenario.to_str().unwrap(),
            "--lockstep",
            "--ticks",
            "200",
            "--instance",
            &instance,
        ])
        .args(["--rt-cpu", "4096", "--rt-timer-slack-ns", "1000"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}{stderr}");
    assert_eq!(
        stderr.matches("real-time option CPU 4096 refused").count(),
        1,
        "{stderr}"
    );
    assert!(
        stdout.contains("real-time: timer slack 1000 ns"),
        "{stdout}"
    );
    assert!(stdout.contains("ticks 200"), "{stdout}");
}

#[test]
fn unknown_realtime_keys_are_refused() {
    let toml = "[[axis]]\nname = \"A\"\n[realtime]\npriority = 80\nisolate = true\n";
    let e = cnc_app::scenario::Scenario::parse("rt.toml", toml, |_| unreachable!())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("rt.toml:") && e.contains("unknown field `isolate`"),
        "{e}"
    );
}
