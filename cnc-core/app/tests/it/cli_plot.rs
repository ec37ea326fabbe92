//! `cnc plot`: a trace CSV drawn as SVG, one panel per unit with a legend; HLI columns scaled
//! to mm and degree; bad input refused with exit 2 and no file. The saw tool's `--plot` and
//! the cam tool's plot go through the same module.

use std::path::PathBuf;
use std::process::Output;
use tests::{Cli, Scratch};

fn cnc(args: &[&str]) -> Output {
    Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(args)
        .output()
        .unwrap()
}

/// The texts of an SVG (axis labels, tick labels, legend entries), trimmed.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let body = &t[t.find('>')? + 1..];
            Some(body[..body.find("</text>")?].trim().to_string())
        })
        .collect()
}

fn has(svg: &str, text: &str) -> bool {
    texts(svg).iter().any(|t| t == text)
}

const POS: &str = "gpAx[0]^lr_state.command_position_acs_r";
const STATE: &str = "gpAx[0]^lr_state.axis_state_r";

fn trace(dir: &Scratch) -> PathBuf {
    let mut csv = format!("tick,time,{POS},{STATE}\n");
    for k in 0..5000 {
        // 0 .. 123.4567 mm in HLI units (0.1 um), one spike the plot must keep.
        let raw = if k == 3210 { 9_999_999 } else { k * 246 };
        csv.push_str(&format!("{k},{},{raw},{}\n", k as f64 * 0.001, k / 1000));
    }
    let path = dir.join("trace.csv");
    std::fs::write(&path, csv).unwrap();
    path
}

#[test]
fn a_trace_becomes_an_svg_with_units_legends_and_every_peak() {
    let dir = Scratch::new("plot-ok");
    let csv = trace(&dir);
    let out = dir.join("plot.svg");
    let o = cnc(&[
        "plot",
        csv.to_str().unwrap(),
        "--signals",
        &format!("{POS},{STATE}"),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..100.min(svg.len())]);
    // Two panels: the position in mm, the state as a raw value; each with its legend.
    assert!(has(&svg, "mm"), "no mm axis label: {:?}", texts(&svg));
    assert!(has(&svg, "value"), "no raw axis label");
    assert!(has(&svg, "time [s]"));
    assert!(has(&svg, POS) && has(&svg, STATE));
    // The spike of 999.9999 mm is inside the y range: the axis is labelled beyond it.
    assert!(
        has(&svg, "1000.0") || has(&svg, "1200.0"),
        "{:?}",
        texts(&svg)
    );
}

#[test]
fn a_unit_can_be_given_and_bad_input_writes_nothing() {
    let dir = Scratch::new("plot-bad");
    let csv = trace(&dir);
    let out = dir.join("plot.svg");
    let o = cnc(&[
        "plot",
        csv.to_str().unwrap(),
        "--signals",
        &format!("{POS}=deg"),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    assert!(std::fs::read_to_string(&out).unwrap().contains("degree"));
    std::fs::remove_file(&out).unwrap();
    for (signals, message) in [
        ("nope", "no column `nope`"),
        (&format!("{POS}=furlong") as &str, "unknown unit `furlong`"),
    ] {
        let o = cnc(&[
            "plot",
            csv.to_str().unwrap(),
            "--signals",
            signals,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2));
        assert!(
            String::from_utf8_lossy(&o.stderr).contains(message),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(!out.exists());
    }
    std::fs::write(dir.join("broken.csv"), "time,a\n0,1\n0.001,oops\n").unwrap();
    let o = cnc(&[
        "plot",
        dir.join("broken.csv").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("broken.csv:3:2: `oops` is not a number"));
    assert!(!out.exists());
}

#[test]
fn the_saw_tool_plots_its_synchronisation() {
    let dir = Scratch::new("plot-saw");
    let out = dir.join("saw.svg");
    let o = cnc(&[
        "saw",
        "plan",
        "--mode",
        "position",
        "--master-position",
        "-500",
        "--master-velocity",
        "500",
        "--slave-position",
        "-250",
        "--slave-velocity",
        "250",
        "--ratio",
        "1",
        "--master-sync",
        "1000",
        "--slave-sync",
        "1000",
        "--velocity",
        "3000",
        "--acceleration",
        "2500",
        "--deceleration",
        "2500",
        "--jerk",
        "10000",
        "--plot",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let svg = std::fs::read_to_string(&out).unwrap();
    for name in [
        "master_position",
        "slave_position",
        "slave_velocity",
        "position",
    ] {
        assert!(has(&svg, name), "{name}: {:?}", texts(&svg));
    }
}
