//! Golden files: `test_data/ok/NNNN_name.nc` must check clean, and their canonical printout and
//! decoded motion blocks equal `NNNN_name.expected`; `test_data/err/NNNN_name.nc` must produce
//! exactly the diagnostics in `NNNN_name.expected`. `UPDATE_GOLDEN=1` rewrites the expectations
//! (review the diff before committing).

use cnc_core::nc::check::{check_source, motion_json};
use cnc_core::nc::{parse, print, Decoded};
use std::path::{Path, PathBuf};

const AXES: [&str; 8] = ["X", "Y", "Z", "A", "B", "C", "AB", "X1"];

fn axes() -> Vec<String> {
    AXES.map(String::from).to_vec()
}

fn render(case: &Path, ok: bool) -> String {
    let src = std::fs::read_to_string(case).unwrap();
    let (diags, decoded) = check_source(&src, &axes());
    let mut out = String::new();
    if ok {
        assert!(diags.is_empty(), "{}: {diags:#?}", case.display());
        out.push_str(&print(&parse(&src).0));
        out.push_str("---\n");
        for d in &decoded {
            if let Decoded::Motion(m) = d {
                out.push_str(&motion_json(m, &axes()));
                out.push('\n');
            }
        }
    } else {
        assert!(
            !diags.is_empty(),
            "{}: expected diagnostics",
            case.display()
        );
        for d in &diags {
            out.push_str(&d.render("FILE"));
            out.push('\n');
        }
    }
    out
}

fn check(dir: &str, ok: bool) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("test_data")
        .join(dir);
    let mut cases: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "nc"))
        .collect();
    cases.sort();
    assert!(!cases.is_empty());
    for case in cases {
        let actual = render(&case, ok);
        let expected_path = case.with_extension("expected");
        if std::env::var_os("UPDATE_GOLDEN").is_some() {
            std::fs::write(&expected_path, &actual).unwrap();
            continue;
        }
        let expected = std::fs::read_to_string(&expected_path)
            .unwrap_or_else(|_| panic!("missing {}", expected_path.display()));
        assert_eq!(actual, expected, "golden mismatch for {}", case.display());
    }
}

#[test]
fn ok_programs_match_their_golden_output() {
    check("ok", true);
}

#[test]
fn err_programs_match_their_golden_diagnostics() {
    check("err", false);
}

#[test]
fn canonical_printout_reparses_to_the_same_tree() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("test_data/ok");
    for entry in std::fs::read_dir(root).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "nc") {
            let (tree, _) = parse(&std::fs::read_to_string(&path).unwrap());
            let (again, diags) = parse(&print(&tree));
            assert!(diags.is_empty(), "{}: {diags:?}", path.display());
            assert_eq!(again, tree, "{}", path.display());
        }
    }
}
