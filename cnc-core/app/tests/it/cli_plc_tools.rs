//! `plc get`, `plc set`, `plc watch` (here as `cnc plc ...`, the same code as the `plc`
//! binary) against a live CNC: values read and written by ST path, writes held to the
//! handshake protocol, bad input refused with its exit code and nothing written, and a clear
//! message once no CNC runs. Waits are polls with watchdogs.

use std::path::PathBuf;
use std::process::Stdio;
use tests::cli::wait_until;
use tests::{ChildGuard, Cli, Scratch};

const ENABLE: &str = "gpCh[0]^channel_mc_control.dyn_cs.enable_w";
const ROTATION: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_w.rotation[2]";
const COMMAND_SEM: &str = "gpCh[0]^channel_mc_control.dyn_cs.command_semaphore_rw";
const ACK_CODE: &str = "gpCh[0]^channel_mc_control.m_function.ack_w.m_code";
const ACK_SEM: &str = "gpCh[0]^channel_mc_control.m_function.ack_semaphore_rw";
const STATE: &str = "gpCh[0]^channel_mc_control.dyn_cs.state_r.actual_state";
const BEAT: &str = "header.cnc_heartbeat";

fn tool(instance: &str, args: &[&str]) -> (i32, String, String) {
    let mut all = vec!["plc"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--instance", instance]);
    tests::cli::code_and_text(env!("CARGO_BIN_EXE_cnc"), &all)
}

/// The value `plc get` prints for `path`.
fn get(instance: &str, path: &str) -> String {
    let (code, out, err) = tool(instance, &["get", path]);
    assert_eq!(code, 0, "{err}");
    out.trim()
        .strip_prefix(&format!("{path} = "))
        .unwrap_or_else(|| panic!("{out}"))
        .to_string()
}

/// `cnc run` of the folder's `scenario.toml` on `instance`, for ten minutes at most (the
/// test ends it).
fn run_cnc(instance: &str, dir: &Scratch) -> ChildGuard {
    Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["run", dir.join("scenario.toml").to_str().unwrap()])
        .args(["--instance", instance, "--ticks", "600000"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Until the CNC on `instance` has ticked.
fn wait_ticking(instance: &str) {
    wait_until("the CNC ticks", || {
        let (code, out, _) = tool(instance, &["get", BEAT]);
        code == 0 && !out.trim().ends_with(" 0")
    });
}

/// A CNC running a scenario without a PLC, for ten minutes at most (the test ends it), and
/// the scratch folder of its scenario.
fn start_cnc(instance: &str) -> (ChildGuard, Scratch) {
    let dir = Scratch::new("plc-tools");
    let program = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/supervision/long.nc");
    std::fs::write(
        dir.join("scenario.toml"),
        format!(
            "cycle_ms = 1.0\n[[channel]]\nname = \"portal\"\naxes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\nprogram = {:?}\n",
            program.display().to_string()
        ),
    )
    .unwrap();
    (run_cnc(instance, &dir), dir)
}

#[test]
fn get_set_and_watch_a_live_cnc_by_st_path() {
    let instance = tests::unique_instance("plctools");
    let (mut child, _dir) = start_cnc(&instance);
    wait_ticking(&instance);

    // A plain PLC leaf: read, written, read back.
    assert_eq!(get(&instance, ENABLE), "FALSE");
    let (code, out, err) = tool(&instance, &["set", ENABLE, "TRUE"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.trim(), format!("{ENABLE} := TRUE"));
    assert_eq!(get(&instance, ENABLE), "TRUE");

    // A dynamic-CS command published with its semaphore: the CNC takes it (clears the
    // semaphore) in its next tick.
    let (code, _, err) = tool(
        &instance,
        &["set", ROTATION, "-900000", COMMAND_SEM, "TRUE"],
    );
    assert_eq!(code, 0, "{err}");
    wait_until("the CNC takes the command", || {
        get(&instance, COMMAND_SEM) == "FALSE"
    });
    assert_eq!(get(&instance, ROTATION), "-900000");

    // An M-function acknowledge nobody awaits stays pending: its payload is then refused
    // (exit 4) and keeps its value, and so is a second publish.
    let (code, _, err) = tool(&instance, &["set", ACK_CODE, "5", ACK_SEM, "TRUE"]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = tool(&instance, &["set", ACK_CODE, "6"]);
    assert_eq!(code, 4, "{err}");
    assert!(err.contains("has not taken the previous datum"), "{err}");
    assert_eq!(get(&instance, ACK_CODE), "5");
    let (code, _, err) = tool(&instance, &["set", ACK_SEM, "TRUE"]);
    assert_eq!(code, 4, "{err}");

    // The CNC's own leaves are read-only.
    let (code, _, err) = tool(&instance, &["set", STATE, "2"]);
    assert_eq!(code, 4, "{err}");
    assert!(err.contains("written by the CNC"), "{err}");

    // Bad input: exit 2, nothing written (the first, valid pair is not written either).
    for (pairs, message) in [
        (
            vec![ENABLE, "FALSE", "gpCh[0]^nope", "1"],
            "no symbol `gpCh[0]^nope`",
        ),
        (vec![ENABLE, "FALSE", ROTATION, "0.5"], "does not fit"),
        (vec![ENABLE, "FALSE", ROTATION, "lots"], "is not a number"),
        (vec![ENABLE, "2"], "does not fit"),
    ] {
        let mut args = vec!["set"];
        args.extend(pairs);
        let (code, _, err) = tool(&instance, &args);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(message), "{err}");
        assert_eq!(get(&instance, ENABLE), "TRUE");
    }
    let (code, _, err) = tool(&instance, &["get", "gpAx[99]^lr_state"]);
    assert_eq!(code, 2, "{err}");

    // Watch: a header, then one line per interval with the CNC's tick rising.
    let (code, out, err) = tool(
        &instance,
        &["watch", BEAT, ENABLE, "--interval", "20", "--count", "3"],
    );
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], format!("cnc_tick {BEAT} {ENABLE}"));
    assert_eq!(lines.len(), 4, "{out}");
    let ticks: Vec<u64> = lines[1..]
        .iter()
        .map(|l| l.split(' ').next().unwrap().parse().unwrap())
        .collect();
    assert!(ticks.windows(2).all(|w| w[0] < w[1]), "{ticks:?}");
    assert!(lines[1..].iter().all(|l| l.ends_with(" TRUE")), "{out}");

    // The CNC ends: the tools say so with exit 1.
    assert!(child.signal("TERM"));
    let _ = child.wait_with_output(tests::cli::default_watchdog());
    let (code, _, err) = tool(&instance, &["get", ENABLE]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("is the CNC running?"), "{err}");
}

/// `plc call`: a block of the library run against a live CNC by its name and timeline
/// inputs, for commissioning: MC_Power, then MC_MoveAbsolute to 100 mm (exit 0, its Done
/// reported; `plc get` reads the axis there); a move beyond the soft limit ends in the
/// block's Error (exit 4, the code shown); bad input exits 2 before anything is sent.
#[test]
fn plc_call_runs_one_block_against_a_live_cnc() {
    let instance = tests::unique_instance("plccall");
    let dir = Scratch::new("plc-call");
    std::fs::write(
        dir.join("scenario.toml"),
        "cycle_ms = 1.0\nticks = 600000\n[[axis]]\nname = \"Slide\"\nsoft_limits = [-10.0, 500.0]\n\
         velocity = 200.0\nacceleration = 2000.0\ndeceleration = 2000.0\njerk = 50000.0\n",
    )
    .unwrap();
    let mut cnc = run_cnc(&instance, &dir);
    wait_ticking(&instance);
    let (code, out, err) = tool(&instance, &["call", "MC_Power", "axis=0", "enable=true"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("Status"), "{out}");
    let (code, out, err) = tool(
        &instance,
        &[
            "call",
            "MC_MoveAbsolute",
            "axis=0",
            "position=100.0",
            "velocity=200.0",
            "acceleration=2000.0",
            "deceleration=2000.0",
            "jerk=50000.0",
        ],
    );
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("Done"), "{out}");
    assert_eq!(
        get(&instance, "gpAx[0]^lr_state.command_position_acs_r"),
        "1000000"
    );
    let (code, _, err) = tool(
        &instance,
        &[
            "call",
            "MC_MoveAbsolute",
            "axis=0",
            "position=900.0",
            "velocity=200.0",
            "acceleration=2000.0",
            "deceleration=2000.0",
            "jerk=50000.0",
        ],
    );
    assert_eq!(code, 4, "{err}");
    assert!(err.contains("ErrorID 0x4225"), "{err}");
    let (code, _, err) = tool(&instance, &["call", "MC_Teleport", "axis=0"]);
    assert_eq!(code, 2, "{err}");
    assert!(cnc.signal("TERM"));
    let _ = cnc.wait_with_output(tests::cli::default_watchdog());
}

/// Commissioning a flying saw without a PLC program (manual 001, chapter 11): `plc call`
/// runs the master on MC_MoveVelocity (InVelocity), couples the saw with MC_GearInVelo at
/// half the master's velocity (InSync: the image shows it synchronous, state 13, coupled),
/// and MC_GearOut decouples it (Done, the saw free at the velocity it had).
#[test]
fn plc_call_commissions_a_flying_saw() {
    let instance = tests::unique_instance("plccallsaw");
    let dir = Scratch::new("plc-call-saw");
    let axis = |name: &str| {
        format!(
            "[[axis]]\nname = \"{name}\"\npower = true\nsoft_limits = [-1000.0, 1e6]\nvelocity = 1000.0\n\
             acceleration = 5000.0\ndeceleration = 5000.0\njerk = 100000.0\n"
        )
    };
    std::fs::write(
        dir.join("scenario.toml"),
        format!(
            "cycle_ms = 1.0\nticks = 600000\n{}{}",
            axis("Master"),
            axis("Saw")
        ),
    )
    .unwrap();
    let mut cnc = run_cnc(&instance, &dir);
    wait_ticking(&instance);
    let calls: [&[&str]; 3] = [
        &[
            "MC_MoveVelocity",
            "axis=0",
            "direction=1",
            "velocity=200.0",
            "acceleration=5000.0",
            "deceleration=5000.0",
            "jerk=100000.0",
        ],
        &[
            "MC_GearInVelo",
            "Master=0",
            "Slave=1",
            "RatioNumerator=0.5",
            "RatioDenominator=1",
            "Acceleration=2500.0",
            "Deceleration=2500.0",
            "Jerk=50000.0",
        ],
        &["MC_GearOut", "Slave=1"],
    ];
    for (k, (call, ends)) in calls
        .iter()
        .zip(["InVelocity", "InSync", "Done"])
        .enumerate()
    {
        let mut args = vec!["call"];
        args.extend_from_slice(call);
        let (code, out, err) = tool(&instance, &args);
        assert_eq!(code, 0, "{call:?}: {out}{err}");
        assert!(out.contains(ends), "{call:?}: {out}");
        if k == 1 {
            assert_eq!(get(&instance, "gpAx[1]^lr_state.axis_state_r"), "13");
            assert_ne!(get(&instance, "gpAx[1]^lr_state.coupling_state_r"), "0");
            // Half the master's 200 mm/s, in 0.1 um/s.
            assert_eq!(
                get(&instance, "gpAx[1]^lr_state.command_velocity_r"),
                "1000000"
            );
        }
    }
    assert_eq!(get(&instance, "gpAx[1]^lr_state.coupling_state_r"), "0");
    assert!(cnc.signal("TERM"));
    let _ = cnc.wait_with_output(tests::cli::default_watchdog());
}

/// The variables of a live ST PLC by name: `plc get` reads them, `plc set` writes through
/// the PLC (a value the type cannot hold is refused, exit 2), `plc watch` follows them beside
/// the image's leaves; when the run ends, the PLC's object is gone with it.
#[test]
fn get_set_and_watch_an_st_plcs_variables_by_name() {
    let instance = tests::unique_instance("plcstvars");
    let dir = Scratch::new("plc-st-vars");
    std::fs::write(
        dir.join("count.st"),
        "VAR_GLOBAL gTotal : LREAL; END_VAR\n\
         PROGRAM MAIN VAR nCount : DINT; bRun : BOOL := TRUE; nSmall : INT;\n\
         sPart : STRING(20) := 'part_7.nc'; END_VAR\n\
         IF bRun THEN nCount := nCount + 1; gTotal := gTotal + 0.5; END_IF\nEND_PROGRAM\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("scenario.toml"),
        "cycle_ms = 1.0\nticks = 600000\n[[axis]]\nname = \"X\"\n[plc]\nst = [\"count.st\"]\n",
    )
    .unwrap();
    let mut child = run_cnc(&instance, &dir);
    wait_until("the ST PLC counts", || {
        let (code, out, _) = tool(&instance, &["get", "MAIN.nCount"]);
        code == 0 && out.trim() != "MAIN.nCount = 0"
    });
    assert_eq!(get(&instance, "main.brun"), "TRUE");
    assert_ne!(get(&instance, "gTotal"), "0", "a global by its bare name");

    let (code, out, err) = tool(&instance, &["set", "MAIN.bRun", "FALSE"]);
    assert_eq!((code, out.trim()), (0, "MAIN.bRun := FALSE"), "{err}");
    let stopped = get(&instance, "MAIN.nCount");
    let (code, out, err) = tool(
        &instance,
        &["watch", "MAIN.nCount", "MAIN.bRun", "--count", "2"],
    );
    assert_eq!(code, 0, "{err}");
    assert!(
        out.lines()
            .skip(1)
            .all(|l| l.ends_with(&format!(" {stopped} FALSE"))),
        "{out}"
    );

    let (code, _, err) = tool(&instance, &["set", "MAIN.nSmall", "40000"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("40000 is not a value of INT"), "{err}");
    let (code, _, err) = tool(&instance, &["get", "MAIN.nothing"]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(
        get(&instance, "MAIN.sPart"),
        "'part_7.nc'",
        "a STRING as ST writes it"
    );
    let (code, _, err) = tool(&instance, &["set", "MAIN.sPart", "1"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("`MAIN.sPart` is a STRING"), "{err}");

    assert!(child.signal("TERM"));
    let _ = child.wait_with_output(tests::cli::default_watchdog());
    let (code, _, err) = tool(&instance, &["get", "MAIN.nCount"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("no symbol `MAIN.nCount`"), "{err}");
    assert!(err.contains("is an ST PLC running"), "{err}");
}
