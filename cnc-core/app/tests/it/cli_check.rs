//! The `cnc check` command-line contract.

use tests::{Cli, Scratch};

/// `text` in the file `name` of a scratch folder of its own (kept while the test holds it).
fn write(name: &str, text: &str) -> (Scratch, String) {
    let dir = Scratch::new("check");
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    (dir, path.display().to_string())
}

fn cnc(args: &[&str]) -> (i32, String, String) {
    tests::cli::code_and_text(env!("CARGO_BIN_EXE_cnc"), args)
}

#[test]
fn clean_program_exits_0_silently() {
    let (_dir, f) = write(
        "clean.nc",
        "%p\nN10 G1 X10 Y20 F100\n#TRACK CS ON [ID=0 FILTER=10]\nM30\n",
    );
    let (code, out, _) = cnc(&["check", &f]);
    assert_eq!(code, 0);
    assert!(out.is_empty(), "{out}");
}

#[test]
fn errors_exit_1_with_file_line_col_and_the_offending_text() {
    let (_dir, f) = write(
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
    let (_dir, f) = write(
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
    let (_dir, f) = write("axes.nc", "AB=90\nAM=1 AA=25.44\n");
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
fn a_three_axis_channel_prints_its_axes_and_refuses_others() {
    let (_dir, f) = write("mill.nc", "G1 X1 Y2 F100\nG2 X3 Y2 I1 J0\n");
    let (code, out, _) = cnc(&["check", "--axes", "X,Y,Z", "--blocks", &f]);
    assert_eq!(code, 0, "{out}");
    assert!(
        out.contains("\"target\":{\"X\":1,\"Y\":2,\"Z\":0}}"),
        "{out}"
    );
    assert!(out.contains("\"center\":{\"X\":"), "{out}");
    let (_dir, f) = write("five.nc", "G1 X1 B2 F100\n");
    let (code, out, _) = cnc(&["check", "--axes", "X,Y,Z,A,C", &f]);
    assert_eq!(code, 1);
    assert!(
        out.contains("five.nc:1:7: error: unknown axis \"B\" for this channel (axes: X Y Z A C)"),
        "{out}"
    );
}

#[test]
fn several_files_and_unreadable_ones() {
    let (_dir, good) = write("good.nc", "X1\n");
    let (code, _, err) = cnc(&["check", &good, "/nonexistent/prog.nc"]);
    assert_eq!(code, 1);
    assert!(
        err.contains("/nonexistent/prog.nc:1:1: error: cannot read the file"),
        "{err}"
    );
}

#[test]
fn bad_axis_lists_are_refused_before_any_file() {
    let (_dir, file) = write("axes_list.nc", "N10 G1 X1 F100\n");
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

#[test]
fn blocks_into_a_closed_pipe_ends_quietly() {
    // `cnc check --blocks F | head -1`: the reader goes after one line; the checker must end
    // without a panic message (it used to panic on the broken pipe).
    let mut text = String::new();
    for i in 0..50_000 {
        text.push_str(&format!("G1 X{} Y{} F1000\n", i % 500, i % 300));
    }
    let (_dir, f) = write("pipe.nc", &text);
    let (first, out) = Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(["check", "--blocks", &f])
        .first_line()
        .unwrap();
    assert!(first.starts_with("{\"line\":1,"), "{first}");
    // The pipe's reader went after the first line.
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.is_empty(), "{stderr}");
    assert_eq!(out.status.code(), Some(0));
}

#[test]
fn subroutine_files_are_found_next_to_the_program_and_on_the_search_path() {
    let scratch = Scratch::new("check-subs");
    let d = scratch.join("subs");
    std::fs::create_dir_all(d.join("lib")).unwrap();
    std::fs::write(
        d.join("side.nc"),
        "G91 G1 X10 F500\nG90\nL corner.nc\nM17\n",
    )
    .unwrap();
    std::fs::write(d.join("lib").join("corner.nc"), "G91 Y5\nG90\nM17\n").unwrap();
    let main = d.join("main.nc");
    std::fs::write(&main, "$FOR P1 = 1, 2\nL side.nc\n$ENDFOR\nM30\n").unwrap();
    let main = main.display().to_string();
    let lib = d.join("lib").display().to_string();
    // Without the search path the nested file is missing: named with its position.
    let (code, stdout, _) = cnc(&["check", &main]);
    assert_eq!(code, 1);
    assert!(
        stdout.contains("side.nc:3:1: error: L corner.nc: subroutine file not found"),
        "{stdout}"
    );
    let (code, stdout, stderr) = cnc(&["check", "--blocks", "--search", &lib, &main]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    let targets: Vec<&str> = stdout
        .lines()
        .map(|l| &l[l.find("\"X\"").unwrap()..l.find(",\"Z\"").unwrap()])
        .collect();
    assert_eq!(
        targets,
        [
            "\"X\":10,\"Y\":0",
            "\"X\":10,\"Y\":5",
            "\"X\":20,\"Y\":5",
            "\"X\":20,\"Y\":10"
        ]
    );
}

#[test]
fn tool_records_come_from_the_command_line() {
    let (_dir, f) = write("tools.nc", "S6000 M03 T24 D1\nG1 Z10 F100\nM30\n");
    let z = |stdout: &str| {
        stdout
            .split("\"Z\":")
            .nth(1)
            .map(|r| r.split(',').next().unwrap().to_string())
    };
    // No tool table given: D1 takes length 0.
    let (code, stdout, _) = cnc(&["check", "--blocks", &f]);
    assert_eq!((code, z(&stdout).as_deref()), (0, Some("10")));
    // D1 of 80 mm along Z.
    let (code, stdout, _) = cnc(&["check", "--blocks", "--tool", "1=80", &f]);
    assert_eq!((code, z(&stdout).as_deref()), (0, Some("90")));
    // A table without D1: the program is refused at D1.
    let (code, stdout, _) = cnc(&["check", "--tool", "2=5", &f]);
    assert_eq!(code, 1);
    assert!(
        stdout.contains("tools.nc:1:15: error: D1: no such tool data record"),
        "{stdout}"
    );
    // A malformed record is an argument error.
    let (code, _, stderr) = cnc(&["check", "--tool", "0=5", &f]);
    assert_eq!(code, 2, "{stderr}");
}
