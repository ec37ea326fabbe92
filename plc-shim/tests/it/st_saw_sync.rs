//! The flying saw's `SyncMode : ST_SyncMode` in Structured Text (seed 001 12.3.1): its mode
//! and flags become the call's sync mode and mask, bit for bit; `CheckMask` and `OpMask`
//! given too replace its flags; a mode the seed does not name is refused at load.

use hli::calls::saw::{sync_mask, SawGearInCall};
use hli::calls::ErrorCode;
use plc_shim::st::StProgram;
use stand_in::StandIn;

use crate::stand_in;

const PROGRAM: &str = "PROGRAM MAIN
VAR
    axMaster, axSaw : AXIS_REF;
    stSync : ST_SyncMode;
    fbSync : MC_GearInVelo;
    nErrorId : UDINT;
END_VAR
    axMaster.AxisIndex := 0;
    axSaw.AxisIndex := 1;
    stSync.GearInSyncMode := GEARINSYNCMODE_TIMEBASED;
    stSync.GearInSync_CheckMask_MinPos := TRUE;
    stSync.GearInSync_CheckMask_MaxJerk := TRUE;
    stSync.GearInSync_CheckMask_UndershootVeloZero := TRUE;
    stSync.GearInSync_OpMask_RollbackLock := TRUE;
    stSync.GearInSync_OpMask_DetailedErrorCodes := TRUE;
    fbSync(Master := axMaster, Slave := axSaw, Execute := TRUE, RatioNumerator := 1.0,
        RatioDenominator := 1, SyncMode := stSync, ErrorID => nErrorId);
END_PROGRAM
";

/// The sync mode and mask the program's first cycle sends (`None`: nothing sent), and its
/// ErrorID.
fn sent(text: &str, case: &str) -> (Option<(u32, u32)>, f64) {
    let mut cnc = StandIn::new(case, 2);
    let mut p = StProgram::from_texts(&[("main.st".into(), text.into())], 1).unwrap();
    cnc.cycle(&mut p);
    let mut call = None;
    cnc.server
        .poll(|_, request| {
            let c: SawGearInCall = hli::calls::decode_body(request)?;
            call = Some((c.sync_mode, c.mask));
            Err(ErrorCode::InvalidData)
        })
        .unwrap();
    (call, p.program().read_var("MAIN.nErrorId").unwrap())
}

#[test]
fn st_sync_mode_becomes_the_calls_mode_and_mask_bit_for_bit() {
    let bits = sync_mask::MINPOS
        | sync_mask::MAXJERK
        | sync_mask::UNDERSHOOTVELOZERO
        | sync_mask::ROLLBACKLOCK
        | sync_mask::DETAILEDERRORCODES;
    assert_eq!(sent(PROGRAM, "st-sync-struct"), (Some((1, bits)), 0.0));
}

#[test]
fn check_mask_and_op_mask_given_too_replace_its_flags() {
    let text = PROGRAM.replace(
        "SyncMode := stSync,",
        "SyncMode := stSync, CheckMask := GearInSync_CheckMask_MAXVELO, OpMask := 0,",
    );
    let (call, _) = sent(&text, "st-sync-masks");
    assert_eq!(call, Some((1, sync_mask::MAXVELO)));
}

#[test]
fn a_mode_the_seed_does_not_name_is_refused_at_load() {
    let text = PROGRAM.replace(
        "stSync.GearInSyncMode := GEARINSYNCMODE_TIMEBASED;",
        "stSync.GearInSyncMode := 7;",
    );
    let refused = StProgram::from_texts(&[("main.st".into(), text)], 1).unwrap_err();
    assert!(
        refused.contains("main.st:10:30: error: DINT where E_GearInSyncMode is wanted"),
        "{refused}"
    );
}
