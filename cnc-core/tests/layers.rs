//! The layers a newcomer can see: the CNC library (machine, channels, axes, cams, NC language)
//! imports neither the PLC crate nor the application tree; only `app` and the binary may.

use std::path::{Path, PathBuf};

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn the_library_knows_no_plc_code_and_no_application() {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    for module in ["machine", "channel", "axis", "cam", "nc"] {
        sources(&src.join(module), &mut files);
    }
    assert!(files.len() > 30, "found only {} files", files.len());
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        for forbidden in ["plc_shim", "crate::app", "cnc_core::app"] {
            assert!(
                !text.contains(forbidden),
                "{} uses {forbidden}",
                file.display()
            );
        }
    }
}
