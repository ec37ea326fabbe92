//! Text in Structured Text: a STRING variable given a literal, passed on as
//! ChannelSelectProgram's `ProgramName`, reaches the channel's command in the image byte for
//! byte; an empty name, or one with a character that is no printable ASCII, ends the command
//! with 0x4227 and writes nothing; a literal longer than its STRING is refused at load; a
//! name the PLC builds (`CONCAT(..)`) goes to `ProgramName` straight.

use hli::symbols::SymbolTable;
use plc_shim::st::host::INVALID_INPUT;
use plc_shim::st::StProgram;
use stand_in::StandIn;

use crate::stand_in;

const PROGRAM: &str = "PROGRAM MAIN
VAR
    sName : STRING(40);
    fbSelect : ChannelSelectProgram;
    bError : BOOL;
    nErrorId : UDINT;
END_VAR
    sName := 'sub/part 2.nc';
    fbSelect(Channel := 0, Execute := TRUE, ProgramName := sName, Error => bError,
        ErrorID => nErrorId);
END_PROGRAM
";

/// The program name the command in the image holds after one cycle, and the ErrorID.
fn selected(text: &str, case: &str) -> (String, f64) {
    let mut cnc = StandIn::new(case, 1);
    let mut p = StProgram::from_texts(&[("main.st".into(), text.into())], 1).unwrap();
    cnc.cycle(&mut p);
    let memory = &cnc.memory;
    let at = SymbolTable::global()
        .lookup("gpCh[0]^channel_control.command_w.program")
        .expect("the command's program name")
        .offset;
    let name: Vec<u8> = (0..64)
        .map(|k| memory.place::<u8>(at + k).load())
        .take_while(|b| *b != 0)
        .collect();
    let id = p.program().read_var("MAIN.nErrorId").unwrap();
    (String::from_utf8(name).unwrap(), id)
}

#[test]
fn a_string_variable_reaches_the_channels_command_as_program_name() {
    assert_eq!(selected(PROGRAM, "st-text"), ("sub/part 2.nc".into(), 0.0));
}

#[test]
fn a_name_the_plc_builds_goes_straight_to_program_name() {
    let text = PROGRAM.replace(
        "ProgramName := sName",
        "ProgramName := CONCAT('sub/part ', INT_TO_STRING(2), '.nc')",
    );
    assert_eq!(
        selected(&text, "st-text-built"),
        ("sub/part 2.nc".into(), 0.0)
    );
}

#[test]
fn an_empty_name_or_a_control_character_ends_the_command_with_0x4227() {
    for (case, name) in [("empty", "''"), ("tab", "'a$Tb.nc'")] {
        let text = PROGRAM.replace("'sub/part 2.nc'", name);
        let (sent, id) = selected(&text, &format!("st-text-{case}"));
        assert_eq!(
            (sent.as_str(), id),
            ("", f64::from(INVALID_INPUT)),
            "{case}"
        );
    }
}

#[test]
fn a_literal_longer_than_its_string_is_refused_at_load() {
    let text = PROGRAM.replace("STRING(40)", "STRING(8)");
    let refused = StProgram::from_texts(&[("main.st".into(), text)], 1).unwrap_err();
    assert!(
        refused.contains(
            "main.st:8:14: error: 'sub/part 2.nc' has 13 characters: a STRING(8) holds 8"
        ),
        "{refused}"
    );
}
