//! What the cam read blocks show in Structured Text as outputs of their own (seed 000): the
//! slave dynamics of MC_ReadCamTableSlaveDynamics (5.1.11), the characteristic values of
//! MC_ReadCamTableCharacteristics (`MC_TableCharacValues`, 5.1.16.9) and of the flying saw's
//! MC_ReadFlyingSawCharacteristics (`MC_FlyingSawCharacValues`, 001 12.3), a point of
//! MC_ReadMotionFunctionPoint (`MC_MotionFunctionPoint`), the coupling's state of
//! MC_CamInfo (`MC_CamInfoData`, 5.1.16.14) and the slave position of the compatibility
//! block CamTableReadSlavePos (5.2.1.6). Each is filled, leaf by leaf, from the values the
//! read answered, when it is Done.

use crate::timeline::registry::Results;

/// MC_ReadCamTableSlaveDynamics: position, velocity, acceleration at the master position.
pub const SLAVE_DYNAMICS: Results = Results {
    outputs: &[
        ("SlavePosition", "LREAL"),
        ("SlaveVelocity", "LREAL"),
        ("SlaveAcceleration", "LREAL"),
    ],
    declaration: "",
    type_name: "",
};

/// CamTableReadSlavePos: `fSlavePos`.
pub const SLAVE_POS: Results = Results {
    outputs: &[("fSlavePos", "LREAL")],
    declaration: "",
    type_name: "",
};

/// MC_ReadMotionFunctionPoint: the point (the library's `MC_MotionFunctionPoint`).
pub const POINT: Results = Results {
    outputs: &[("Point", "MC_MotionFunctionPoint")],
    declaration: "",
    type_name: "",
};

/// The fields of `MC_TableCharacValues` (000 5.1.16.9) and of the flying saw's
/// `MC_FlyingSawCharacValues` (001 12.3), which lay them out alike.
macro_rules! charac_fields {
    () => {
        "        fMasterVeloNom : LREAL;
        fMasterPosStart : LREAL;
        fSlavePosStart : LREAL;
        fSlaveVeloStart : LREAL;
        fSlaveAccStart : LREAL;
        fSlaveJerkStart : LREAL;
        fMasterPosEnd : LREAL;
        fSlavePosEnd : LREAL;
        fSlaveVeloEnd : LREAL;
        fSlaveAccEnd : LREAL;
        fSlaveJerkEnd : LREAL;
        fMPosAtSPosMin : LREAL;
        fSlavePosMin : LREAL;
        fMPosAtSVeloMin : LREAL;
        fSlaveVeloMin : LREAL;
        fMPosAtSAccMin : LREAL;
        fSlaveAccMin : LREAL;
        fSVeloAtSAccMin : LREAL;
        fSlaveJerkMin : LREAL;
        fSlaveDynMomMin : LREAL;
        fMPosAtSPosMax : LREAL;
        fSlavePosMax : LREAL;
        fMPosAtSVeloMax : LREAL;
        fSlaveVeloMax : LREAL;
        fMPosAtSAccMax : LREAL;
        fSlaveAccMax : LREAL;
        fSVeloAtSAccMax : LREAL;
        fSlaveJerkMax : LREAL;
        fSlaveDynMomMax : LREAL;
        fSlaveVeloMean : LREAL;
        fSlaveAccEff : LREAL;
        reserved : ARRAY[32..47] OF LREAL;
        CamTableID : UDINT;
        NumberOfRows : UDINT;
        NumberOfColumns : UDINT;
        TableType : UINT;
        Periodic : BOOL;
        reserved2 : ARRAY[1..121] OF BYTE;
"
    };
}

/// MC_ReadCamTableCharacteristics: `CamTableCharac : MC_TableCharacValues`.
pub const CHARACTERISTICS: Results = Results {
    outputs: &[("CamTableCharac", "MC_TableCharacValues")],
    declaration: concat!(
        "TYPE\n    MC_TableCharacValues :\n    STRUCT\n",
        charac_fields!(),
        "    END_STRUCT\nEND_TYPE\n"
    ),
    type_name: "MC_TableCharacValues",
};

/// MC_ReadFlyingSawCharacteristics: `CamTableCharac : MC_FlyingSawCharacValues`.
pub const FLYING_SAW_CHARAC: Results = Results {
    outputs: &[("CamTableCharac", "MC_FlyingSawCharacValues")],
    declaration: concat!(
        "TYPE\n    MC_FlyingSawCharacValues :\n    STRUCT\n",
        charac_fields!(),
        "    END_STRUCT\nEND_TYPE\n"
    ),
    type_name: "MC_FlyingSawCharacValues",
};

/// The characteristic values read (31, then the five organisation fields) with the reserved
/// block (16 LREALs) between, as the structure's leaves run: how many written.
pub fn characteristics(values: &[f64], out: &mut [f64]) -> usize {
    let (named, organisation) = values.split_at(values.len().min(31));
    let leaves = named
        .iter()
        .chain(&[0.0; 16])
        .chain(organisation.iter().take(5));
    let mut n = 0;
    for (slot, v) in out.iter_mut().zip(leaves) {
        *slot = *v;
        n += 1;
    }
    n
}

/// MC_CamInfo: `CamInfo : MC_CamInfoData` (its 40 values in order; IDs and modes UDINT).
pub const CAM_INFO: Results = Results {
    outputs: &[("CamInfo", "MC_CamInfoData")],
    declaration: "TYPE
    MC_CamInfoData :
    STRUCT
        CamTableID : UDINT;
        TableType : UDINT;
        Periodic : BOOL;
        InterpolationType : UDINT;
        NumberOfRows : UDINT;
        NumberOfColumns : UDINT;
        MasterCamStartPos : LREAL;
        SlaveCamStartPos : LREAL;
        RawMasterPeriod : LREAL;
        RawSlaveStroke : LREAL;
        MasterAxisCouplingPos : LREAL;
        SlaveAxisCouplingPos : LREAL;
        MasterAbsolute : BOOL;
        SlaveAbsolute : BOOL;
        MasterOffset : LREAL;
        SlaveOffset : LREAL;
        MasterScaling : LREAL;
        SlaveScaling : LREAL;
        SumOfSlaveStrokes : LREAL;
        SumOfSuperpositionDistance : LREAL;
        ActualMasterAxisPos : LREAL;
        ActualSlaveAxisPos : LREAL;
        ActualMasterCamPos : LREAL;
        ActualSlaveCamPos : LREAL;
        ScalingPending : BOOL;
        ScalingActivationMode : UDINT;
        ScalingActivationPos : LREAL;
        ScalingMasterScalingMode : UDINT;
        ScalingSlaveScalingMode : UDINT;
        CamDataQueued : BOOL;
        OnlineChangeActivationMode : UDINT;
        OnlineChangeActivationPos : LREAL;
        OnlineChangeMasterScalingMode : UDINT;
        OnlineChangeSlaveScalingMode : UDINT;
        CamTableQueued : BOOL;
        CamExchangeCamTableID : UDINT;
        CamExchangeActivationMode : UDINT;
        CamExchangeActivationPos : LREAL;
        CamExchangeMasterScalingMode : UDINT;
        CamExchangeSlaveScalingMode : UDINT;
    END_STRUCT
END_TYPE
",
    type_name: "MC_CamInfoData",
};

/// `values` into `out`, as many as fit: how many.
pub fn copied(values: &[f64], out: &mut [f64]) -> usize {
    let n = values.len().min(out.len());
    out[..n].copy_from_slice(&values[..n]);
    n
}

/// `values` as the LREALs of a program's array (little-endian), as many as `out` holds: the
/// bytes written.
pub fn lreal_bytes(values: &[f64], out: &mut [u8]) -> usize {
    let mut written = 0;
    for (value, slot) in values.iter().zip(out.chunks_exact_mut(8)) {
        slot.copy_from_slice(&value.to_le_bytes());
        written += 8;
    }
    written
}
