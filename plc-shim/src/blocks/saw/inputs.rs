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

use super::GearInInputs;
use crate::timeline::registry::number;
use hli::calls::saw::{sync_mask, SawSyncMode};

/// `(name, bit)` of `sync_mask` flags: a flag's short name is its constant's name.
macro_rules! flags {
    ($($flag:ident),* $(,)?) => {
        [$((stringify!($flag), sync_mask::$flag)),*]
    };
}

/// The check flags of `ST_SyncMode` by short name (`GearInSync_CheckMask_<name>`).
const CHECK_FLAGS: [(&str, u32); 12] = flags![
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
];

/// The operation flags of `ST_SyncMode` by short name (`GearInSync_OpMask_<name>`).
const OPERATION_FLAGS: [(&str, u32); 6] = flags![
    ROLLBACKLOCK,
    INSTANTSTOPONROLLBACK,
    PREFERCONSTVELO,
    IGNOREMASTERACC,
    IGNORESLAVEACC,
    DETAILEDERRORCODES,
];

/// The inputs of a flying-saw call.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct SawInputs {
    pub(super) master: u32,
    pub(super) gear: GearInInputs,
    /// MasterSyncPosition, SlaveSyncPosition.
    pub(super) sync_positions: [f64; 2],
}

/// The inputs of MC_GearInPos under the seed's names, in the order an error lists them, and
/// our `MasterSource` ("set_point" or "actual", as MC_CamIn's).
const GEAR_IN_POS: [&str; 14] = [
    "Slave",
    "Master",
    "RatioNumerator",
    "RatioDenominator",
    "MasterSyncPosition",
    "SlaveSyncPosition",
    "SyncMode",
    "CheckMask",
    "OpMask",
    "Velocity",
    "Acceleration",
    "Deceleration",
    "Jerk",
    "MasterSource",
];

/// The inputs of `kind` under the seed's names (`Slave` is every kind's: the axis).
/// MC_GearInVelo has MC_GearInPos's but the two sync positions.
fn inputs_of(kind: &str) -> Vec<&'static str> {
    match kind {
        "MC_GearInPos" => GEAR_IN_POS.to_vec(),
        "MC_GearInVelo" => GEAR_IN_POS
            .into_iter()
            .filter(|name| !name.ends_with("SyncPosition"))
            .collect(),
        _ => vec!["Slave"],
    }
}

/// A key without underscores, in lower case: `ratio_numerator` and `RatioNumerator` meet.
fn folded(key: &str) -> String {
    key.chars()
        .filter(|c| *c != '_')
        .collect::<String>()
        .to_ascii_lowercase()
}

/// `Slave = N` under any spelling, for the caller's axis.
pub(super) fn slave(table: &toml::Table) -> Option<&toml::Value> {
    table
        .iter()
        .find(|(key, _)| folded(key) == "slave")
        .map(|(_, value)| value)
}

/// Checks the inputs of a flying-saw `call` table (`block`, `instance`, `axis`, `execute`
/// are the caller's; `Slave` is read by the caller as the axis).
pub(super) fn parse(kind: &str, table: &toml::Table) -> Result<SawInputs, String> {
    let mut inputs = SawInputs::default();
    let mut master = None;
    let mut sync_positions = [None, None];
    let (mut checks, mut operations) = (0, 0);
    let known = inputs_of(kind);
    if let (Some(s), Some(a)) = (slave(table), table.get("axis")) {
        if s != a {
            return Err(format!(
                "call: {kind}: `Slave` = {s} and `axis` = {a} differ"
            ));
        }
    }
    for (key, value) in table {
        if crate::timeline::registry::CALL_KEYS.contains(&key.as_str()) {
            continue;
        }
        let Some(name) = known.iter().find(|n| folded(n) == folded(key)) else {
            return Err(format!(
                "call: {kind} has no input `{key}` (inputs: {})",
                known.join(", ")
            ));
        };
        let bad = |what: &str| format!("call: {kind} input `{key}` = {value}: {what}");
        let gear = &mut inputs.gear;
        match *name {
            "Slave" => {} // the axis, read by the caller
            "Master" => {
                master = Some(
                    value
                        .as_integer()
                        .filter(|m| (0..i64::from(u32::MAX)).contains(m))
                        .ok_or_else(|| bad("an axis index"))? as u32,
                )
            }
            "RatioDenominator" => {
                gear.ratio_denominator = value
                    .as_integer()
                    .filter(|d| (0..=i64::from(u16::MAX)).contains(d))
                    .ok_or_else(|| bad("a UINT, 0..=65535"))?
                    as u32
            }
            "SyncMode" => {
                gear.sync_mode.time_based =
                    time_based(value).ok_or_else(|| bad("\"position-based\" or \"time-based\""))?
            }
            "CheckMask" => checks = mask(value, &CHECK_FLAGS).map_err(|e| bad(&e))?,
            "MasterSource" => {
                gear.master_actual = match value.as_str() {
                    Some("set_point") => false,
                    Some("actual") => true,
                    _ => return Err(bad("\"set_point\" or \"actual\"")),
                }
            }
            "OpMask" => operations = mask(value, &OPERATION_FLAGS).map_err(|e| bad(&e))?,
            other => {
                let v = number(value)
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| bad("a finite number"))?;
                match other {
                    "RatioNumerator" => gear.ratio_numerator = v,
                    "MasterSyncPosition" => sync_positions[0] = Some(v),
                    "SlaveSyncPosition" => sync_positions[1] = Some(v),
                    "Velocity" => gear.velocity = v,
                    "Acceleration" => gear.acceleration = v,
                    "Deceleration" => gear.deceleration = v,
                    _ => gear.jerk = v,
                }
            }
        }
    }
    inputs.gear.sync_mode.mask = checks | operations;
    // The master by its NC axis ID (`master_id`) is set by the timeline's instances.
    if known.contains(&"Master") && !table.contains_key("master_id") {
        inputs.master = master.ok_or_else(|| format!("call: {kind} needs `Master`"))?;
    }
    if known.contains(&"MasterSyncPosition") {
        match sync_positions {
            [Some(m), Some(s)] => inputs.sync_positions = [m, s],
            _ => {
                return Err(format!(
                    "call: {kind} needs `MasterSyncPosition` and `SlaveSyncPosition`"
                ))
            }
        }
    }
    Ok(inputs)
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

/// A mask: the raw bits, or a list of names from `flags`.
fn mask(value: &toml::Value, flags: &[(&str, u32)]) -> Result<u32, String> {
    let names = || {
        let names: Vec<&str> = flags.iter().map(|(n, _)| *n).collect();
        names.join(", ")
    };
    match value {
        toml::Value::Integer(bits) => u32::try_from(*bits).map_err(|_| "a 32-bit mask".to_string()),
        toml::Value::Array(list) => {
            list.iter()
                .try_fold(0u32, |bits, item| -> Result<u32, String> {
                    let name = item
                        .as_str()
                        .ok_or_else(|| format!("flag names ({})", names()))?;
                    let upper = name.replace('_', "").to_ascii_uppercase();
                    let short = ["GEARINSYNCCHECKMASK", "GEARINSYNCOPMASK"]
                        .iter()
                        .find_map(|prefix| upper.strip_prefix(prefix))
                        .unwrap_or(&upper);
                    match flags.iter().find(|(n, _)| *n == short) {
                        Some((_, bit)) => Ok(bits | bit),
                        None => Err(format!("unknown flag {name:?} (known: {})", names())),
                    }
                })
        }
        _ => Err(format!("an integer or a list of flag names ({})", names())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parsed(kind: &str, text: &str) -> Result<SawInputs, String> {
        parse(kind, &toml::from_str(text).unwrap())
    }

    #[test]
    fn inputs_take_the_seed_names_and_flag_lists() {
        let text = "Slave = 1\nMaster = 0\nratio_numerator = -0.5\nRatioDenominator = 4\n\
                    MasterSyncPosition = 500\nSlaveSyncPosition = 100.0\nJerk = 1e5\n\
                    CheckMask = [\"MAXACC\", \"GearInSync_CheckMask_MaxJerk\"]\n\
                    OpMask = [\"rollback_lock\"]";
        let i = parsed("MC_GearInPos", text).unwrap();
        assert_eq!(i.master, 0);
        assert_eq!(i.sync_positions, [500.0, 100.0]);
        assert_eq!(
            (i.gear.ratio_numerator, i.gear.ratio_denominator),
            (-0.5, 4)
        );
        assert_eq!(i.gear.jerk, 1e5);
        let bits = sync_mask::MAXACC | sync_mask::MAXJERK | sync_mask::ROLLBACKLOCK;
        assert_eq!(i.gear.sync_mode.mask, bits);
        assert!(!i.gear.sync_mode.time_based);
        assert!(!i.gear.master_actual, "the set-point by default");
        let i = parsed("MC_GearInVelo", "Master = 0\nmaster_source = \"actual\"").unwrap();
        assert!(i.gear.master_actual);

        let i = parsed(
            "MC_GearInVelo",
            "Master = 2\nSyncMode = \"time-based\"\nOpMask = 3",
        )
        .unwrap();
        assert!(i.gear.sync_mode.time_based);
        assert_eq!(i.gear.sync_mode.mask, 3, "raw bits go as given");
        assert_eq!(i.gear.ratio_denominator, 1, "ratio 1:1 by default");
        for (mode, time_based) in [
            ("\"GEARINSYNCMODE_TIMEBASED\"", true),
            ("\"position_based\"", false),
            ("1", true),
            ("0", false),
        ] {
            let i = parsed("MC_GearInVelo", &format!("Master = 0\nSyncMode = {mode}")).unwrap();
            assert_eq!(i.gear.sync_mode.time_based, time_based, "{mode}");
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
        assert!(err("MC_GearInVelo", "Master = 0\nRatioDenominator = 70000").contains("UINT"));
        assert!(err("MC_GearOut", "Slave = 1\naxis = 2").contains("differ"));
        assert!(
            err("MC_GearInVelo", "Master = 0\nMasterSource = \"encoder\"")
                .contains("\"set_point\" or \"actual\"")
        );
        assert!(parsed("MC_GearOut", "Slave = 1\naxis = 1").is_ok());
        assert!(parsed("MC_ReadFlyingSawCharacteristics", "slave = 1").is_ok());
    }
}
