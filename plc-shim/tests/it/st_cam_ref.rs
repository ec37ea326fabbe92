//! Tables from a PLC program's arrays (seed 000 5.1.16.2, `MC_CAM_REF`): MC_CamTableSelect
//! sends the rows an MC_CAM_REF describes, MC_WriteMotionFunction its points; a description
//! its array does not match ends the command with the seed's code before anything is sent;
//! a NULL address, an array beyond the program's memory or the room, or a value that is not
//! finite ends it with 0x4227; taking tables at the edges allocates nothing; a read's
//! MC_CAM_REF is checked the same way before the read is sent.

use hli::calls::cam::{CamPointsWriteCall, CamRowsWriteCall};
use hli::calls::ErrorCode;
use plc_shim::st::host::INVALID_INPUT;
use plc_shim::st::StProgram;

use crate::counting_alloc;
use crate::stand_in;

/// A 5-row table (y = x^2) selected through an MC_CAM_REF whose fields the test sets.
const SELECT: &str = "PROGRAM MAIN
VAR
    aTable : ARRAY[1..5, 1..2] OF LREAL := [0.0, 0.0, 1.0, 1.0, 2.0, 4.0, 3.0, 9.0, 4.0, 16.0];
    stCamRef : MC_CAM_REF;
    fbSelect : MC_CamTableSelect;
    axLifter : AXIS_REF;
    bExecute : BOOL := TRUE;
    bError : BOOL;
    nErrorId : UDINT;
END_VAR
    axLifter.AxisIndex := 1;
    stCamRef.pArray := ADR(aTable);
    stCamRef.nArraySize := SIZEOF(aTable);
    stCamRef.nTableType := 10;
    stCamRef.nNoOfRows := 3;
    stCamRef.nNoOfCols := 2;
    fbSelect(Axis := axLifter, Execute := bExecute, Table := 7, CamTable := stCamRef,
        Error => bError, ErrorID => nErrorId);
END_PROGRAM
";

/// Two points of a motion function written through an MC_CAM_REF.
const WRITE: &str = "PROGRAM MAIN
VAR
    aPoints : ARRAY[1..2] OF MC_MotionFunctionPoint;
    stCamRef : MC_CAM_REF;
    fbWrite : MC_WriteMotionFunction;
    axLifter : AXIS_REF;
    bError : BOOL;
    nErrorId : UDINT;
END_VAR
    aPoints[1].PointIndex := 3; aPoints[1].FunctionType := 1; aPoints[1].PointType := 2;
    aPoints[1].RelIndexNextPoint := 1; aPoints[1].MasterPos := 150.0; aPoints[1].SlavePos := 15.0;
    aPoints[2].PointIndex := 4; aPoints[2].FunctionType := 15; aPoints[2].PointType := 2;
    aPoints[2].RelIndexNextPoint := 1; aPoints[2].MasterPos := 240.0; aPoints[2].SlavePos := 30.0;
    stCamRef.pArray := ADR(aPoints);
    stCamRef.nArraySize := SIZEOF(aPoints);
    stCamRef.nTableType := 22;
    stCamRef.nNoOfRows := 2;
    stCamRef.nNoOfCols := 1;
    axLifter.AxisIndex := 1;
    fbWrite(Axis := axLifter, Execute := TRUE, Table := 1, CamTable := stCamRef,
        Error => bError, ErrorID => nErrorId);
END_PROGRAM
";

use stand_in::StandIn as Cnc;

fn load(text: &str) -> StProgram {
    StProgram::from_texts(&[("main.st".into(), text.into())], 1).unwrap()
}

fn var(p: &StProgram, name: &str) -> f64 {
    p.program().read_var(&format!("MAIN.{name}")).unwrap()
}

#[test]
fn mc_cam_table_select_sends_the_rows_its_mc_cam_ref_describes() {
    let mut cnc = Cnc::new("st-camref-rows", 2);
    let mut p = load(SELECT);
    cnc.cycle(&mut p);
    assert_eq!(var(&p, "bError"), 0.0);
    let mut sent = None;
    cnc.server
        .poll(|_, request| {
            let call: CamRowsWriteCall = hli::calls::decode_body(request)?;
            let rows = call.rows[..call.count as usize].to_vec();
            sent = Some((call.total, call.table_type, rows));
            Err(ErrorCode::InvalidData)
        })
        .unwrap();
    let rows = vec![[0.0, 0.0], [1.0, 1.0], [2.0, 4.0]];
    assert_eq!(
        sent,
        Some((3, 10, rows)),
        "three rows of five, as described"
    );
}

#[test]
fn a_description_its_array_does_not_match_ends_with_the_seeds_code() {
    for (case, from, to, code) in [
        ("size", "SIZEOF(aTable)", "72", 0x4B31),
        ("type", "nTableType := 10", "nTableType := 12", 0x4B35),
        ("rows", "nNoOfRows := 3", "nNoOfRows := 6", 0x4B36),
        ("columns", "nNoOfCols := 2", "nNoOfCols := 3", 0x4B37),
        ("null", "stCamRef.pArray := ADR(aTable);", "", INVALID_INPUT),
        ("beyond", "SIZEOF(aTable)", "16#7FFFFFFF", INVALID_INPUT),
    ] {
        let mut cnc = Cnc::new(&format!("st-camref-{case}"), 2);
        let mut p = load(&SELECT.replace(from, to));
        cnc.cycle(&mut p);
        assert_eq!(cnc.client.sent(), 0, "{case}: nothing sent");
        assert_eq!(var(&p, "bError"), 1.0, "{case}");
        assert_eq!(var(&p, "nErrorId"), f64::from(code), "{case}");
    }
}

#[test]
fn a_value_that_is_not_finite_ends_with_0x4227() {
    // The program cannot compute a NaN (that faults), but an array of other words may hold
    // one's bits: pArray takes any address.
    let mut cnc = Cnc::new("st-camref-nan", 2);
    let text = SELECT
        .replace(
            "bExecute : BOOL := TRUE;",
            "bExecute : BOOL := TRUE;\n    aBits : ARRAY[1..4] OF LWORD := [0, 0, 16#7FF8000000000000, 0];",
        )
        .replace("ADR(aTable)", "ADR(aBits)")
        .replace("SIZEOF(aTable)", "SIZEOF(aBits)")
        .replace("nNoOfRows := 3", "nNoOfRows := 2");
    let mut p = load(&text);
    cnc.cycle(&mut p);
    assert_eq!(cnc.client.sent(), 0);
    assert_eq!(var(&p, "nErrorId"), f64::from(INVALID_INPUT));
}

#[test]
fn mc_write_motion_function_sends_the_points_of_its_mc_cam_ref() {
    let mut cnc = Cnc::new("st-camref-points", 2);
    let mut p = load(WRITE);
    cnc.cycle(&mut p);
    assert_eq!(var(&p, "bError"), 0.0);
    let mut sent = None;
    cnc.server
        .poll(|_, request| {
            let call: CamPointsWriteCall = hli::calls::decode_body(request)?;
            let points: Vec<_> = call.points[..call.count as usize]
                .iter()
                .map(|q| (q.point_index, q.function_type, q.master_pos, q.slave_pos))
                .collect();
            sent = Some((call.first, call.total, points));
            Err(ErrorCode::InvalidData)
        })
        .unwrap();
    let points = vec![(3, 1, 150.0, 15.0), (4, 15, 240.0, 30.0)];
    assert_eq!(sent, Some((3, 2, points)));

    // Rows are a position table's, not a motion function's points.
    let mut cnc = Cnc::new("st-camref-points-type", 2);
    let mut p = load(&WRITE.replace("nTableType := 22", "nTableType := 10"));
    cnc.cycle(&mut p);
    assert_eq!(cnc.client.sent(), 0);
    assert_eq!(var(&p, "nErrorId"), f64::from(0x4B35));
}

#[test]
fn taking_tables_at_the_edges_allocates_nothing() {
    let mut cnc = Cnc::new("st-camref-alloc", 2);
    // Execute toggles every cycle: a table is taken at every other cycle.
    let text = SELECT.replace(
        "axLifter.AxisIndex := 1;",
        "axLifter.AxisIndex := 1; bExecute := NOT bExecute;",
    );
    let mut p = load(&text);
    for _ in 0..4 {
        cnc.cycle(&mut p);
    }
    let before = counting_alloc::allocations();
    for _ in 0..40 {
        cnc.cycle(&mut p);
    }
    assert_eq!(counting_alloc::allocations() - before, 0);
}

#[test]
fn a_read_into_an_array_its_mc_cam_ref_does_not_describe_ends_before_it_is_sent() {
    let read = "PROGRAM MAIN
VAR
    aPoints : ARRAY[1..4] OF MC_MotionFunctionPoint;
    stCamRef : MC_CAM_REF;
    fbRead : MC_ReadMotionFunction;
    axLifter : AXIS_REF;
    bError : BOOL;
    nErrorId : UDINT;
END_VAR
    stCamRef.pArray := ADR(aPoints);
    stCamRef.nArraySize := SIZEOF(aPoints);
    stCamRef.nTableType := 22;
    stCamRef.nNoOfRows := 4;
    stCamRef.nNoOfCols := 1;
    axLifter.AxisIndex := 1;
    fbRead(Axis := axLifter, Execute := TRUE, Table := 1, PointIndex := 1,
        CamTable := stCamRef, Error => bError, ErrorID => nErrorId);
END_PROGRAM
";
    let mut cnc = Cnc::new("st-camref-read", 2);
    let mut p = load(read);
    cnc.cycle(&mut p);
    assert_eq!(
        (cnc.client.sent(), var(&p, "bError")),
        (1, 0.0),
        "a fitting array"
    );
    for (case, from, to, code) in [
        ("type", "nTableType := 22", "nTableType := 10", 0x4B35),
        ("columns", "nNoOfCols := 1", "nNoOfCols := 2", 0x4B37),
        ("size", "SIZEOF(aPoints)", "100", 0x4B31),
        (
            "null",
            "stCamRef.pArray := ADR(aPoints);",
            "",
            INVALID_INPUT,
        ),
    ] {
        let mut cnc = Cnc::new(&format!("st-camref-read-{case}"), 2);
        let mut p = load(&read.replace(from, to));
        cnc.cycle(&mut p);
        assert_eq!(cnc.client.sent(), 0, "{case}: nothing sent");
        assert_eq!(var(&p, "nErrorId"), f64::from(code), "{case}");
    }
}

/// CamTableWriteData's row count from the program, far beyond any room: refused with the
/// seed's 0x4B31, nothing sent, no overflow on the way.
#[test]
fn rows_beyond_every_room_are_refused_without_overflow() {
    let mut cnc = Cnc::new("st-compat-rows-huge", 2);
    let text = "PROGRAM MAIN
VAR
    aRows : ARRAY[1..2, 1..2] OF LREAL;
    fbWrite : CamTableWriteData;
    bError : BOOL;
    nErrorId : UDINT;
END_VAR
    fbWrite(iAxisId := 1, bExecute := TRUE, iTableId := 21, AdrDataArray := ADR(aRows),
        iSizeOfDataArray := SIZEOF(aRows), iColDim := 2, iRowsToWrite := 16#FFFFFFFF,
        bErr => bError, iErrId => nErrorId);
END_PROGRAM
";
    let mut p = load(text);
    cnc.cycle(&mut p);
    assert_eq!(cnc.client.sent(), 0);
    assert_eq!(
        (var(&p, "bError"), var(&p, "nErrorId")),
        (1.0, f64::from(0x4B31))
    );
}
