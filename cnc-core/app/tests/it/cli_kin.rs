//! The `cnc kin` command-line contract.

fn cnc(args: &[&str]) -> (bool, String, String) {
    let (code, out, err) = tests::cli::code_and_text(env!("CARGO_BIN_EXE_cnc"), args);
    (code == 0, out.trim().to_string(), err)
}

fn numbers(json: &str) -> Vec<f64> {
    json.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
        .filter(|t| !t.is_empty() && *t != "-")
        .map(|t| t.parse().unwrap())
        .collect()
}

#[test]
fn fk_of_the_kr6_r900_sixx_zero_position() {
    let (ok, out, _) = cnc(&[
        "kin",
        "fk",
        "--id",
        "45",
        "--robot",
        "kr6r900sixx",
        "0",
        "0",
        "0",
        "0",
        "0",
        "0",
    ]);
    assert!(ok);
    assert_eq!(out, r#"{"x":980,"y":0,"z":435,"a":0,"b":-90,"c":0}"#);
}

#[test]
fn ik_inverts_fk_for_every_robot() {
    for robot in ["kr6r900sixx", "kr6r700sixx", "irb2400"] {
        let joints = ["10", "-30", "40", "-20", "35", "60"];
        let mut args = vec!["kin", "fk", "--id", "45", "--robot", robot];
        args.extend(joints);
        let (ok, pose, err) = cnc(&args);
        assert!(ok, "{err}");
        let p: Vec<String> = numbers(&pose).iter().map(|v| v.to_string()).collect();
        let mut args = vec!["kin", "ik", "--id", "45", "--robot", robot];
        args.extend(p.iter().map(String::as_str));
        args.push("--current");
        args.extend(["9", "-29", "41", "-21", "34", "61"]);
        let (ok, out, err) = cnc(&args);
        assert!(ok, "{robot}: {err}");
        let got = numbers(&out);
        for (g, want) in got.iter().zip([10.0, -30.0, 40.0, -20.0, 35.0, 60.0]) {
            assert!((g - want).abs() < 1e-6, "{robot}: {out}");
        }
        let mut all_args = args.clone();
        all_args.push("--all");
        let (ok, out, _) = cnc(&all_args);
        assert!(
            ok && out.starts_with("[[") && out.matches('[').count() >= 3,
            "{out}"
        );
    }
}

#[test]
fn errors_exit_1_with_the_reason() {
    let (ok, out, err) = cnc(&[
        "kin", "ik", "--id", "45", "--robot", "irb2400", "5000", "0", "0", "0", "0", "0",
    ]);
    assert!(!ok && out.is_empty());
    assert!(err.contains("unreachable"), "{err}");
    let (ok, _, err) = cnc(&[
        "kin", "fk", "--id", "45", "--robot", "kr1000", "0", "0", "0", "0", "0", "0",
    ]);
    assert!(!ok && err.contains("unknown robot"), "{err}");
    let (ok, _, err) = cnc(&["kin", "fk", "--id", "45", "0", "0", "0", "0", "0", "0"]);
    assert!(!ok && err.contains("--robot"), "{err}");
    let (ok, _, err) = cnc(&["kin", "fk", "--id", "7", "0", "0", "0", "0", "0", "0"]);
    assert!(!ok && err.contains("kinematic id"), "{err}");
    let (ok, _, _) = cnc(&[
        "kin", "fk", "--id", "45", "--robot", "irb2400", "0", "0", "0",
    ]);
    assert!(!ok, "needs six joint values");
    let (ok, _, err) = cnc(&[
        "kin", "fk", "--id", "45", "--robot", "irb2400", "NaN", "0", "0", "0", "0", "0",
    ]);
    assert!(!ok && err.contains("not finite"), "{err}");
}
