//! The flying-saw blocks' inputs in a timeline `call`, under the seed's names (case and
//! underscores do not matter: `RatioNumerator` = `ratio_numerator`). The slave is the
//! instance's axis, given as `Slave` (or `axis`).
//!
//! ```toml
//! [[step]]
//! call = { block = "MC_GearInPos", instance = "saw", Slave = 1, Master = 0,
//!          RatioNumerator = 1.0, RatioDenominator = 1, MasterSyncPosition = 500.0,
//!          SlaveSyncPosition = 100.0, CheckMask = ["MAXVELO", "MAXACC"],
//!          OpMask = ["ROLLBACKLOCK"] }
//! [[step]]
//! wait = "saw.InSync"
//! [[step]]
//! call = { block = "MC_ReadFlyingSawCharacteristics", instance = "charac", Slave = 1 }
//! [[step]]
//! call = { block = "MC_GearOut", instance = "out", Slave = 1 }
//! ```
//!
//! `SyncMode` is `"position-based"` (the default) or `"time-based"` (MC_GearInVelo only; the
//! CNC refuses it for MC_GearInPos). `CheckMask` and `OpMask` are integers (the raw bits, sent
//! as given: the CNC refuses bits it does not know) or lists of flag names, with or without
//! the `GearInSync_CheckMask_` / `GearInSync_OpMask_` prefix.

use super::{McGearInPos, McGearInVelo};
use crate::timeline::registry::{InputSpec, Kind, StForm, Value};
use hli::calls::saw::{sync_mask, SawSyncMode};

/// `(name, bit)` of `sync_mask` flags: a flag's short name is its constant's name.
macro_rules! flags {
    ($($flag:ident),* $(,)?) => {
        &[$((stringify!($flag), sync_mask::$flag)),*]
    };
}

/// The prefixes of the seed's flag constants (`GearInSync_CheckMask_MAXACC`).
const FLAG_PREFIXES: &[&str] = &["GearInSync_CheckMask_", "GearInSync_OpMask_"];

/// The check flags of `ST_SyncMode` by short name (`GearInSync_CheckMask_<name>`).
const CHECK_MASK: Kind = Kind::Flags {
    flags: flags![
        MINPOS,
        MAXPOS,
        MAXVELO,
        MAXACC,
        MAXDEC,
        MAXJERK,
        OVERSHOOTPOS,
        UNDERSHOOTPOS,
        OVERSHOOTVELO,
        UNDERSHOOTVELO,
        OVERSHOOTVELOZERO,
        UNDERSHOOTVELOZERO,
    ],
    prefixes: FLAG_PREFIXES,
};

/// The operation flags of `ST_SyncMode` by short name (`GearInSync_OpMask_<name>`).
const OP_MASK: Kind = Kind::Flags {
    flags: flags![
        ROLLBACKLOCK,
        INSTANTSTOPONROLLBACK,
        PREFERCONSTVELO,
        IGNOREMASTERACC,
        IGNORESLAVEACC,
        DETAILEDERRORCODES,
    ],
    prefixes: FLAG_PREFIXES,
};

/// `SyncMode`: `"position-based"` or `"time-based"` under any spelling of the wire enum's
/// names (`"GEARINSYNCMODE_TIMEBASED"`), or the raw 0 / 1: whether it is time-based.
const SYNC_MODE: Kind = Kind::Parsed {
    parse: |value| {
        time_based(value).map(Value::Bool).ok_or_else(|| {
            format!("call: `SyncMode` = {value}: \"position-based\" or \"time-based\"")
        })
    },
    example: "\"time-based\"",
};

/// The seed's `ST_SyncMode` (001 12.3.1) in Structured Text: the mode, then one BOOL per
/// check flag and per operation flag, in the order of [`CHECK_MASK`] and [`OP_MASK`].
const ST_SYNC_MODE: &str = "TYPE
    E_GearInSyncMode : (GEARINSYNCMODE_POSITIONBASED := 0, GEARINSYNCMODE_TIMEBASED := 1);
    ST_SyncMode :
    STRUCT
        GearInSyncMode : E_GearInSyncMode;
        GearInSync_CheckMask_MinPos : BOOL;
        GearInSync_CheckMask_MaxPos : BOOL;
        GearInSync_CheckMask_MaxVelo : BOOL;
        GearInSync_CheckMask_MaxAcc : BOOL;
        GearInSync_CheckMask_MaxDec : BOOL;
        GearInSync_CheckMask_MaxJerk : BOOL;
        GearInSync_CheckMask_OvershootPos : BOOL;
        GearInSync_CheckMask_UndershootPos : BOOL;
        GearInSync_CheckMask_OvershootVelo : BOOL;
        GearInSync_CheckMask_UndershootVelo : BOOL;
        GearInSync_CheckMask_OvershootVeloZero : BOOL;
        GearInSync_CheckMask_UndershootVeloZero : BOOL;
        GearInSync_OpMask_RollbackLock : BOOL;
        GearInSync_OpMask_InstantStopOnRollback : BOOL;
        GearInSync_OpMask_PreferConstVelo : BOOL;
        GearInSync_OpMask_IgnoreMasterAcc : BOOL;
        GearInSync_OpMask_IgnoreSlaveAcc : BOOL;
        GearInSync_OpMask_DetailedErrorCodes : BOOL;
    END_STRUCT
END_TYPE
";

/// `ST_SyncMode`'s fields as `SyncMode`, `CheckMask` and `OpMask`: the mode an INT at 0, the
/// flags a BOOL each from byte 2 on (the library's layout).
fn read_sync_mode(
    field: &dyn Fn(u32, u8) -> Option<i64>,
    set: &mut dyn FnMut(&'static str, &Value),
) -> bool {
    let time_based = match field(0, 2) {
        Some(0) => false,
        Some(1) => true,
        _ => return false,
    };
    let (Kind::Flags { flags: checks, .. }, Kind::Flags { flags: ops, .. }) = (CHECK_MASK, OP_MASK)
    else {
        return false;
    };
    let mut at = 2;
    let mut mask = |flags: &[(&str, u32)]| {
        let mut bits = 0;
        for (_, bit) in flags {
            if field(at, 1).is_some_and(|v| v != 0) {
                bits |= bit;
            }
            at += 1;
        }
        i64::from(bits)
    };
    let (check, op) = (mask(checks), mask(ops));
    set("SyncMode", &Value::Bool(time_based));
    set("CheckMask", &Value::Int(check));
    set("OpMask", &Value::Int(op));
    true
}

/// `SyncMode : ST_SyncMode` in Structured Text (a call's `CheckMask` and `OpMask`, given
/// too, replace its flags).
const SYNC_MODE_ST: StForm = StForm::Struct {
    name: "SyncMode",
    ty: "ST_SyncMode",
    declaration: ST_SYNC_MODE,
    read: read_sync_mode,
};

/// Our `MasterSource`, as MC_CamIn's: the master's set-point or its actual values.
const MASTER_SOURCE: Kind = Kind::OneOf(&[("\"set_point\"", 0), ("\"actual\"", 1)]);

/// The inputs MC_GearInVelo and MC_GearInPos share, under the seed's names, then our
/// `MasterSource`; `$sync` are the sync positions of MC_GearInPos.
macro_rules! gear_in_inputs {
    ($(#[doc = $doc:literal])* $list:ident, $set:ident: $block:ty { $($sync:tt)* }) => {
        inputs! {
            $(#[doc = $doc])*
            $list, $set: $block {
                required "Master": Kind::Count => master,
                "RatioNumerator": Kind::Real => inputs.ratio_numerator,
                "RatioDenominator": Kind::Range(0, u16::MAX as i64) => inputs.ratio_denominator,
                $($sync)*
                "SyncMode" as SYNC_MODE_ST: SYNC_MODE => inputs.sync_mode.time_based,
                "CheckMask": CHECK_MASK => inputs.sync_mode.check_mask,
                "OpMask": OP_MASK => inputs.sync_mode.op_mask,
                "Velocity": Kind::Real => inputs.velocity,
                "Acceleration": Kind::Real => inputs.acceleration,
                "Deceleration": Kind::Real => inputs.deceleration,
                "Jerk": Kind::Real => inputs.jerk,
                "MasterSource": MASTER_SOURCE => inputs.master_actual,
            }
        }
    };
}

gear_in_inputs! {
    /// MC_GearInVelo's inputs.
    GEAR_IN_VELO, set_gear_in_velo: McGearInVelo {}
}

gear_in_inputs! {
    /// MC_GearInPos's inputs: MC_GearInVelo's and the two sync positions.
    GEAR_IN_POS, set_gear_in_pos: McGearInPos {
        required "MasterSyncPosition": Kind::Real => master_sync_position,
        required "SlaveSyncPosition": Kind::Real => slave_sync_position,
    }
}

/// MC_GearInVelo's inputs.
pub(super) const VELO: &[InputSpec] = &GEAR_IN_VELO;
/// MC_GearInPos's inputs.
pub(super) const POS: &[InputSpec] = &GEAR_IN_POS;

/// Sets input `key` of MC_GearInVelo.
pub(super) fn set_velo(block: &mut McGearInVelo, key: &str, value: &Value) {
    set_gear_in_velo(block, key, value);
}

/// Sets input `key` of MC_GearInPos.
pub(super) fn set_pos(block: &mut McGearInPos, key: &str, value: &Value) {
    set_gear_in_pos(block, key, value);
}

/// `SyncMode`: a name (`"time-based"`, `"GEARINSYNCMODE_TIMEBASED"`, ...) or the raw 0 / 1.
fn time_based(value: &toml::Value) -> Option<bool> {
    let mode = match value {
        toml::Value::String(name) => {
            // The wire enum's names with letters and digits only, in lower case.
            let letters = |name: &str| -> String {
                name.chars()
                    .filter(char::is_ascii_alphanumeric)
                    .collect::<String>()
                    .to_ascii_lowercase()
            };
            let name = letters(name);
            let name = name.strip_prefix("gearinsyncmode").unwrap_or(&name);
            SawSyncMode::ALL
                .iter()
                .copied()
                .find(|m| letters(m.name()) == name)
        }
        toml::Value::Integer(raw) => u32::try_from(*raw).ok().and_then(SawSyncMode::from_raw),
        _ => None,
    }?;
    Some(mode == SawSyncMode::TimeBased)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::timeline::instances::inputs_of;
    use crate::timeline::registry::{find, TimelineBlock};

    /// MC_GearInPos after a call of `kind` with `text`'s inputs (MC_GearInVelo's are set on
    /// a MC_GearInVelo and copied over).
    fn parsed(kind: &str, text: &str) -> Result<McGearInPos, String> {
        let table: toml::Table = toml::from_str(text).unwrap();
        let (inputs, _, _) = inputs_of(find(kind)?, &table)?;
        let mut pos = McGearInPos::default();
        let mut velo = McGearInVelo::default();
        for (key, value) in &inputs {
            pos.set(key, value);
            velo.set(key, value);
        }
        if kind == "MC_GearInVelo" {
            (pos.inputs, pos.master) = (velo.inputs, velo.master);
        }
        Ok(pos)
    }

    #[test]
    fn inputs_take_the_seed_names_and_flag_lists() {
        let text = "Slave = 1\nMaster = 0\nratio_numerator = -0.5\nRatioDenominator = 4\n\
                    MasterSyncPosition = 500\nSlaveSyncPosition = 100.0\nJerk = 1e5\n\
                    CheckMask = [\"MAXACC\", \"GearInSync_CheckMask_MaxJerk\"]\n\
                    OpMask = [\"rollback_lock\"]";
        let i = parsed("MC_GearInPos", text).unwrap();
        assert_eq!(i.master, 0);
        assert_eq!(
            (i.master_sync_position, i.slave_sync_position),
            (500.0, 100.0)
        );
        assert_eq!(
            (i.inputs.ratio_numerator, i.inputs.ratio_denominator),
            (-0.5, 4)
        );
        assert_eq!(i.inputs.jerk, 1e5);
        let bits = sync_mask::MAXACC | sync_mask::MAXJERK | sync_mask::ROLLBACKLOCK;
        assert_eq!(i.inputs.sync_mode.mask(), bits);
        assert!(!i.inputs.sync_mode.time_based);
        assert!(!i.inputs.master_actual, "the set-point by default");
        let i = parsed("MC_GearInVelo", "Master = 0\nmaster_source = \"actual\"").unwrap();
        assert!(i.inputs.master_actual);

        let i = parsed(
            "MC_GearInVelo",
            "Master = 2\nSyncMode = \"time-based\"\nOpMask = 3",
        )
        .unwrap();
        assert!(i.inputs.sync_mode.time_based);
        assert_eq!(i.inputs.sync_mode.mask(), 3, "raw bits go as given");
        assert_eq!(i.inputs.ratio_denominator, 1, "ratio 1:1 by default");
        for (mode, time_based) in [
            ("\"GEARINSYNCMODE_TIMEBASED\"", true),
            ("\"position_based\"", false),
            ("1", true),
            ("0", false),
        ] {
            let i = parsed("MC_GearInVelo", &format!("Master = 0\nSyncMode = {mode}")).unwrap();
            assert_eq!(i.inputs.sync_mode.time_based, time_based, "{mode}");
        }
    }

    #[test]
    fn wrong_inputs_are_named() {
        let err = |kind, text| parsed(kind, text).unwrap_err();
        assert!(err("MC_GearInVelo", "Slave = 1").contains("needs `Master`"));
        assert!(err("MC_GearInPos", "Master = 0\nMasterSyncPosition = 1.0")
            .contains("SlaveSyncPosition"));
        assert!(err("MC_GearInVelo", "Master = 0\nMasterSyncPosition = 1.0")
            .contains("has no input `MasterSyncPosition`"));
        assert!(err("MC_GearOut", "Master = 0").contains("has no input `Master`"));
        assert!(err(
            "MC_GearInVelo",
            "Master = 0\nCheckMask = [\"ROLLBACKLOCK\"]"
        )
        .contains("unknown flag"));
        assert!(err("MC_GearInVelo", "Master = 0\nSyncMode = \"fast\"").contains("time-based"));
        assert!(err("MC_GearInVelo", "Master = 0\nRatioDenominator = 70000").contains("0..=65535"));
        assert!(err("MC_GearInVelo", "Master = 0\nmaster = 1").contains("given twice"));
        assert!(
            err("MC_GearInVelo", "Master = 0\nMasterSource = \"encoder\"")
                .contains("\"set_point\" or \"actual\"")
        );
        assert!(parsed("MC_ReadFlyingSawCharacteristics", "slave = 1").is_ok());
    }
}
