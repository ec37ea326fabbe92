//! The `cnc check` command-line contract.

use std::path::PathBuf;
use std::process::Command;

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("cnc-check-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(name: &str, text: &str) -> String {
    let path = dir().join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

fn cnc(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cnc"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn clean_program_exits_0_silently() {
    let f = write(
        "clean.nc",
        "%p\nN10 G1 X10 Y20 F100\n#TRACK CS ON [ID=0 FILTER=10]\nM30\n",
    );
    let (code, out, _) = cnc(&["check", &f]);
    assert_eq!(code, 0);
    assert!(out.is_empty(), "{out}");
}

#[test]
fn errors_exit_1_with_file_line_col_and_the_offending_text() {
    let f = write(
        "bad.nc",
        "N10 G1 X10 F100\nN20 #TRACK CS ON [CH=1 ID=2]\nN30 Q5\n",
    );
    let (code, out, _) = cnc(&["check", &f]);
    assert_eq!(code, 1);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 2, "{out}");
    assert_eq!(
        lines[0],
        format!("{f}:2:5: error: #TRACK CS: give the source as CH=.. or ID=.., not both (at \"#TRACK CS ON [CH=1 ID=2]\")")
    );
    assert!(
        lines[1].starts_with(&format!("{f}:3:5: error: unknown axis \"Q\"")),
        "{}",
        lines[1]
    );
    assert!(lines[1].ends_with("(at \"Q5\")"), "{}", lines[1]);
}

#[test]
fn blocks_prints_absolute_targets_for_every_axis() {
    let f = write(
        "blocks.nc",
        "N10 G1 G90 X10 Y20 F1000\nN20 G91 X5\nN30 G90 G92 Z100\nN40 Z1\n",
    );
    let (code, out, _) = cnc(&["check", "--blocks", &f]);
    assert_eq!(code, 0);
    assert_eq!(
        out,
        "{\"line\":1,\"motion\":\"G1\",\"feed\":1000,\"target\":{\"X\":10,\"Y\":20,\"Z\":0,\"A\":0,\"B\":0,\"C\":0}}\n\
         {\"line\":2,\"motion\":\"G1\",\"feed\":1000,\"target\":{\"X\":15,\"Y\":20,\"Z\":0,\"A\":0,\"B\":0,\"C\":0}}\n\
         {\"line\":4,\"motion\":\"G1\",\"feed\":1000,\"target\":{\"X\":15,\"Y\":20,\"Z\":101,\"A\":0,\"B\":0,\"C\":0}}\n"
    );
}

#[test]
fn axes_option_names_the_channel_axes_and_errors_print_no_blocks() {
    let f = write("axes.nc", "AB=90\nAM=1 AA=25.44\n");
    let (code, out, _) = cnc(&["check", "--axes", "AB,AM,AA", "--blocks", &f]);
    assert_eq!(code, 0, "{out}");
    assert!(
        out.lines()
            .last()
            .unwrap()
            .ends_with("\"target\":{\"AB\":90,\"AM\":1,\"AA\":25.44}}"),
        "{out}"
    );
    // With the default axes the same program has errors: no block is printed.
    let (code, out, _) = cnc(&["check", "--blocks", &f]);
    assert_eq!(code, 1);
    assert!(!out.contains("\"motion\""), "{out}");
}

#[test]
fn several_files_and_unreadable_ones() {
    let good = write("good.nc", "X1\n");
    let (code, _, err) = cnc(&["check", &good, "/nonexistent/prog.nc"]);
    assert_eq!(code, 1);
    assert!(
        err.contains("/nonexistent/prog.nc:1:1: error: cannot read the file"),
        "{err}"
    );
}

#[test]
fn bad_axis_lists_are_refused_before_any_file() {
    let file = write("axes_list.nc", "N10 G1 X1 F100\n");
    for (axes, why) in [
        ("X,Y,X", "given twice"),
        ("X,1Y", "upper-case letters then digits"),
        ("A,B,C,D,E,F,G,H,I,J,K,L,M,N,O,P,Q", "1 to 16 axes"),
    ] {
        let (code, out, err) = cnc(&["check", "--axes", axes, &file]);
        assert_eq!(code, 2, "{axes}: {out}{err}");
        assert!(err.contains(why), "{axes}: {err}");
        assert!(out.is_empty());
    }
}
