//! The `cnc cam eval|charac|plot` command-line contract.

use tests::{Cli, Scratch};

fn example(name: &str) -> String {
    tests::cli::repo_root()
        .join("scenarios/cams")
        .join(name)
        .display()
        .to_string()
}

fn cnc(args: &[&str]) -> (i32, String, String) {
    tests::cli::code_and_text(env!("CARGO_BIN_EXE_cnc"), args)
}

#[test]
fn eval_prints_the_raw_cam_as_csv() {
    let (code, out, err) = cnc(&[
        "cam",
        "eval",
        &example("seed_example.json"),
        "--from",
        "0",
        "--to",
        "360",
        "--step",
        "10",
    ]);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "master,position,velocity,acceleration,jerk");
    assert_eq!(lines.len(), 1 + 37);
    let row = |m: &str| {
        lines
            .iter()
            .find(|l| l.starts_with(&format!("{m},")))
            .unwrap()
            .split(',')
            .map(|c| c.parse::<f64>().unwrap())
            .collect::<Vec<_>>()
    };
    let r = row("200");
    assert!(
        (r[1] - 20.0 - 50.0 * 20.0 / 90.0).abs() < 1e-6 && (r[2] - 20.0 / 90.0).abs() < 1e-6,
        "{r:?}"
    );
    // A step that does not lead to --to is refused with the seed's increment code.
    let (code, _, err) = cnc(&[
        "cam",
        "eval",
        &example("seed_example.json"),
        "--from",
        "0",
        "--to",
        "360",
        "--step",
        "-1",
    ]);
    assert_eq!(code, 1);
    assert!(err.contains("0x4B38"), "{err}");
}

#[test]
fn charac_prints_every_field_of_mc_table_charac_values() {
    let (code, out, err) = cnc(&[
        "cam",
        "charac",
        &example("stroke_table.json"),
        "--master-velocity",
        "2",
    ]);
    assert_eq!(code, 0, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).expect("valid JSON");
    assert_eq!(json.as_object().unwrap().len(), 31);
    // In the seed's field order.
    assert!(out.starts_with("{\"fMasterVeloNom\":"), "{out}");
    assert!(out.contains(",\"fSlaveAccEff\":"));
    assert!(out.find("fSlavePosMin").unwrap() < out.find("fMPosAtSPosMax").unwrap());
    assert_eq!(json["fMasterVeloNom"], 2.0);
    assert_eq!(json["fSlavePosMax"], 16.0);
    assert_eq!(json["fMPosAtSPosMax"], 180.0);
}

#[test]
fn plot_writes_an_svg_with_three_labelled_panels() {
    let dir = Scratch::new("cam-plot");
    let out = dir.join("seed.svg");
    let (code, _, err) = cnc(&[
        "cam",
        "plot",
        &example("seed_example.json"),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.starts_with("<svg"));
    for label in [
        "slave position",
        "slave velocity",
        "slave acceleration",
        "master position",
    ] {
        assert!(svg.contains(label), "{label}");
    }
}

#[test]
fn refused_files_name_the_code_and_the_point_and_exit_1() {
    let dir = Scratch::new("cam-bad");
    let bad = dir.join("bad.json");
    std::fs::write(
        &bad,
        r#"{"kind":"motion_function","points":[
        {"index":1,"function":"POLYNOM1","point_type":"REST","master":0,"slave":0},
        {"index":2,"function":"POLYNOM1","point_type":"REST","master":10,"slave":0},
        {"index":3,"function":"POLYNOM1","point_type":"REST","master":5,"slave":0}]}"#,
    )
    .unwrap();
    let (code, out, err) = cnc(&["cam", "charac", bad.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(out.is_empty());
    assert!(
        err.contains("error 0x4B38 (MC_ERROR_INCREMENT_INVALID): point 3"),
        "{err}"
    );
    let (code, _, err) = cnc(&["cam", "charac", "/nonexistent/cam.json"]);
    assert_eq!(code, 2, "{err}");
}

#[test]
fn binary_tables_are_read_with_their_interpolation() {
    let dir = Scratch::new("cam-bin");
    let path = dir.join("table.bin");
    let rows: Vec<[f64; 2]> = (0..=8).map(|i| [i as f64, (i * i) as f64]).collect();
    std::fs::write(&path, cnc_core::cam::file::write_binary(&rows).unwrap()).unwrap();
    let (code, out, err) = cnc(&[
        "cam",
        "eval",
        path.to_str().unwrap(),
        "--from",
        "2.5",
        "--to",
        "2.5",
        "--step",
        "1",
        "--interpolation",
        "spline",
    ]);
    assert_eq!(code, 0, "{err}");
    let value: f64 = out
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        (value - 6.25).abs() < 1e-9,
        "a spline through x^2 is x^2: {value}"
    );
}

#[test]
fn a_closed_pipe_ends_eval_quietly() {
    let (first, out) = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args([
            "cam",
            "eval",
            &example("seed_example.json"),
            "--from",
            "0",
            "--to",
            "360",
            "--step",
            "0.0001",
        ])
        .first_line()
        .unwrap();
    assert_eq!(first.trim(), "master,position,velocity,acceleration,jerk");
    // The reader went after the first line: the 3.6 million rows behind it met a closed pipe.
    assert!(out.status.success(), "{:?}", out.status);
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
