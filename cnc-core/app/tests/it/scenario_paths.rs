//! A path in a scenario stays inside the scenario's folder unless it is absolute, and the
//! files the shipped scenarios keep as copies stay equal to their originals.

use cnc_app::scenario::Scenario;
use std::path::PathBuf;

fn parse(extra: &str) -> Result<Scenario, String> {
    let toml = format!("cycle_ms = 1.0\nticks = 10\n{extra}");
    Scenario::parse("dir/machine.toml", &toml, |f| {
        Ok((PathBuf::from(f), "%p\nG1 X10 F600\nM30\n".to_string()))
    })
    .map_err(|e| e.to_string())
}

const CHANNEL: &str = "[[channel]]\nname = \"c\"\naxes = [\"X\"]\n";

#[test]
fn a_relative_path_that_leaves_the_folder_is_refused_naming_file_and_key() {
    for (extra, key) in [
        (
            format!("{CHANNEL}program = \"../p.nc\"\n"),
            "[[channel]] program",
        ),
        (
            format!("{CHANNEL}program = \"sub/../../p.nc\"\n"),
            "[[channel]] program",
        ),
        (
            format!("{CHANNEL}program = \"p.nc\"\nnc = {{ search_path = [\"../lib\"] }}\n"),
            "[[channel]] nc.search_path",
        ),
        (
            format!("{CHANNEL}program = \"p.nc\"\n[plc]\ntimeline = \"../plc.toml\"\n"),
            "[plc] timeline",
        ),
        (
            format!("{CHANNEL}program = \"p.nc\"\n[plc]\nprogram = \"fifo-stream\"\nfile = \"../../etc/rows.csv\"\n"),
            "[plc] file",
        ),
        (
            format!("{CHANNEL}program = \"p.nc\"\n[[cam_table]]\nfile = \"../cam.json\"\n"),
            "[[cam_table]] file",
        ),
    ] {
        let e = parse(&extra).expect_err(&extra);
        assert!(e.starts_with("dir/machine.toml: "), "{e}");
        assert!(
            e.contains(key) && e.contains("leaves the scenario's folder"),
            "{e}"
        );
    }
}

#[test]
fn paths_inside_the_folder_and_absolute_paths_are_taken() {
    for extra in [
        format!("{CHANNEL}program = \"p.nc\"\n"),
        format!("{CHANNEL}program = \"sub/../p.nc\"\n"),
        format!("{CHANNEL}program = \"./nc/p.nc\"\n"),
        format!("{CHANNEL}program = \"/srv/cnc/p.nc\"\n"),
    ] {
        parse(&extra).unwrap_or_else(|e| panic!("{extra}: {e}"));
    }
}

/// `text` without the lines the demo adds to the manual's programs for continuous path.
fn without_continuous_path(text: &str) -> String {
    text.lines()
        .filter(|l| !cnc_app::demo::continuous_path_line(l))
        .map(|l| format!("{l}\n"))
        .collect()
}

/// The demo's NC programs are the examples' own, with continuous path switched on where the
/// manual's programs allow it.
#[test]
fn the_demos_copies_are_the_files_they_copy() {
    let scenarios = tests::cli::repo_root().join("scenarios");
    for (copy, original) in [
        ("demo/master.nc", "example3-moving-workpiece/master.nc"),
        (
            "demo/slave-left.nc",
            "example3-moving-workpiece/slave-left.nc",
        ),
        (
            "demo/slave-right.nc",
            "example3-moving-workpiece/slave-right.nc",
        ),
        ("demo/robot.nc", "example4-turntable-plc/robot.nc"),
        ("demo/seed_example.json", "cams/seed_example.json"),
        ("cam-data/seed_example.json", "cams/seed_example.json"),
        ("cam-conveyor/seed_example.json", "cams/seed_example.json"),
        (
            "cam-conveyor-program/seed_example.json",
            "cams/seed_example.json",
        ),
    ] {
        let read = |p: &str| std::fs::read_to_string(scenarios.join(p)).unwrap();
        assert!(
            without_continuous_path(&read(copy)) == read(original),
            "{copy} differs from {original}"
        );
    }
}
