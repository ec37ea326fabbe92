//! The `cnc hli` command-line contract.

use tests::{Cli, Scratch};

fn cnc(args: &[&str]) -> std::process::Output {
    Cli::new(env!("CARGO_BIN_EXE_cnc"))
        .args(args)
        .output()
        .expect("run cnc")
}

#[test]
fn symbols_lists_every_node_and_leaf_with_offsets() {
    let out = cnc(&["hli", "symbols"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let table = hli::symbols::SymbolTable::global();
    assert_eq!(text.lines().count(), table.symbols().len());
    let line = text
        .lines()
        .find(|l| l.starts_with("gpCh[0]^channel_mc_control.dyn_cs.command_w.translation[1] "))
        .expect("issue example path");
    let fields: Vec<&str> = line.split_whitespace().collect();
    let expected = table
        .lookup("gpCh[0]^channel_mc_control.dyn_cs.command_w.translation[1]")
        .unwrap();
    assert_eq!(fields[1].parse::<usize>().unwrap(), expected.offset);
    assert_eq!(&fields[2..], &["4", "DINT", "PLC"]);
    assert!(text.contains("\ngpAx[6]^lr_state.current_position_acs_r "));
    for l in text.lines() {
        assert_eq!(l.split_whitespace().count(), 5, "malformed line {l:?}");
    }
}

fn gcc_syntax_check(source: &str, name: &str) -> std::process::Output {
    let dir = Scratch::new("hli-header");
    let path = dir.join(name);
    std::fs::write(&path, source).unwrap();
    Cli::new("gcc")
        .args(["-fsyntax-only", "-std=c11", "-Wall", "-Werror", "-x", "c"])
        .arg(&path)
        .output()
        .expect("gcc is on the machine")
}

#[test]
fn header_compiles_and_its_layout_asserts_bite() {
    let out = cnc(&["hli", "header"]);
    assert!(out.status.success());
    let header = String::from_utf8(out.stdout).unwrap();
    let check = gcc_syntax_check(&header, "hli.h");
    assert!(
        check.status.success(),
        "gcc rejected the header: {}",
        String::from_utf8_lossy(&check.stderr)
    );
    // The asserts are real: one wrong offset makes gcc fail.
    let tampered = header.replace(
        "offsetof(MC_CONTROL_DYN_CS_UNIT, state_r) == 120",
        "offsetof(MC_CONTROL_DYN_CS_UNIT, state_r) == 124",
    );
    assert_ne!(tampered, header);
    let check = gcc_syntax_check(&tampered, "tampered.h");
    assert!(!check.status.success());
    assert!(String::from_utf8_lossy(&check.stderr).contains("MC_CONTROL_DYN_CS_UNIT.state_r"));
}

#[test]
fn unknown_subcommand_fails_with_usage() {
    let out = cnc(&["hli", "nonsense"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("Usage"));
}

/// `cnc hli st` prints the image as ST declarations: the units under the manuals' names, the
/// controller's pointer arrays global (plc-st's tests check programs against it).
#[test]
fn st_prints_the_units_and_the_pointer_arrays() {
    let out = cnc(&["hli", "st"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text, hli::st_prelude::generate());
    assert!(text.contains("    MC_CONTROL_DYN_CS_UNIT :\n    STRUCT\n        enable_w : BOOL;"));
    assert!(text.contains("    gpCh : ARRAY[0..11] OF POINTER TO HLI_CHANNEL;"));
}
