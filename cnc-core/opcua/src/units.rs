//! Engineering units of the leaves whose HLI unit is known: positions in 0.1 um (0.0001
//! degree on a rotary axis), velocities in 0.1 um/s, the path feed in 1 um/s, overrides in
//! parts per million. Each is served scaled beside its raw leaf, with its UNECE unit.

/// An engineering unit (UNECE common code, as OPC UA's `EUInformation` names it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Eu {
    /// Millimetre (MMT).
    Mm,
    /// Degree (DD).
    Deg,
    /// Millimetre per second (C16).
    MmPerS,
    /// Degree per second (E96).
    DegPerS,
    /// Millimetre per second squared (M41).
    MmPerS2,
    /// Degree per second squared (M45).
    DegPerS2,
    /// Percent (P1).
    Percent,
    /// Microsecond (B98).
    Us,
}

impl Eu {
    /// The UNECE common code.
    pub fn code(self) -> &'static str {
        match self {
            Eu::Mm => "MMT",
            Eu::Deg => "DD",
            Eu::MmPerS => "C16",
            Eu::DegPerS => "E96",
            Eu::MmPerS2 => "M41",
            Eu::DegPerS2 => "M45",
            Eu::Percent => "P1",
            Eu::Us => "B98",
        }
    }

    /// What a panel shows.
    pub fn symbol(self) -> &'static str {
        match self {
            Eu::Mm => "mm",
            Eu::Deg => "deg",
            Eu::MmPerS => "mm/s",
            Eu::DegPerS => "deg/s",
            Eu::MmPerS2 => "mm/s^2",
            Eu::DegPerS2 => "deg/s^2",
            Eu::Percent => "%",
            Eu::Us => "us",
        }
    }

    /// The unit id OPC UA derives from the code (its letters as bytes of an integer).
    pub fn unit_id(self) -> i32 {
        self.code()
            .bytes()
            .fold(0i32, |id, b| (id << 8) | i32::from(b))
    }
}

/// A leaf's unit: raw increments per unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    /// Raw increments per engineering unit.
    pub per_unit: f64,
    /// The unit.
    pub eu: Eu,
}

const fn unit(per_unit: f64, eu: Eu) -> Option<Unit> {
    Some(Unit { per_unit, eu })
}

/// The axis index of a path under `gpAx[i]^`.
fn axis_of(path: &str) -> Option<usize> {
    path.strip_prefix("gpAx[")?.split(']').next()?.parse().ok()
}

/// The unit of the leaf at `path`, when known; `rotary` lists the axes in degrees.
pub fn unit_of(path: &str, rotary: &[usize]) -> Option<Unit> {
    let last = path.rsplit(['.', '^']).next()?;
    if path.starts_with("gpAx[") {
        let turns = axis_of(path).is_some_and(|a| rotary.contains(&a));
        let (pos, vel, acc) = if turns {
            (Eu::Deg, Eu::DegPerS, Eu::DegPerS2)
        } else {
            (Eu::Mm, Eu::MmPerS, Eu::MmPerS2)
        };
        return match last {
            "command_position_acs_r"
            | "current_position_acs_r"
            | "following_error_r"
            | "drive_following_error_r" => unit(1e4, pos),
            "command_velocity_r" | "current_velocity_r" => unit(1e4, vel),
            "command_acceleration_r" => unit(1e3, acc),
            _ => None,
        };
    }
    if path.contains(".translation[") {
        return unit(1e4, Eu::Mm);
    }
    if path.contains(".rotation[") {
        return unit(1e4, Eu::Deg);
    }
    match last {
        "w0_position_r" | "position_dyncs_r" | "command_position_r" => unit(1e4, Eu::Mm),
        "path_feed_r" => unit(1e3, Eu::MmPerS),
        "override_r" | "override_target_r" if path.starts_with("gpFifo[") => unit(1e4, Eu::Percent),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_follow_the_hli_and_rotary_axes_turn_in_degrees() {
        let u = |p| unit_of(p, &[3]);
        assert_eq!(
            u("gpAx[0]^lr_state.current_position_acs_r"),
            unit(1e4, Eu::Mm)
        );
        assert_eq!(
            u("gpAx[3]^lr_state.current_position_acs_r"),
            unit(1e4, Eu::Deg)
        );
        assert_eq!(
            u("gpAx[3]^lr_state.current_velocity_r"),
            unit(1e4, Eu::DegPerS)
        );
        assert_eq!(
            u("gpAx[1]^lr_state.command_acceleration_r"),
            unit(1e3, Eu::MmPerS2)
        );
        assert_eq!(u("gpAx[1]^lr_state.axis_state_r"), None);
        assert_eq!(
            u("gpCh[0]^bahn_state.coord_r[2].command_position_r"),
            unit(1e4, Eu::Mm)
        );
        assert_eq!(u("gpCh[0]^bahn_state.path_feed_r"), unit(1e3, Eu::MmPerS));
        assert_eq!(
            u("gpCh[0]^channel_mc_control.dyn_cs.command_w.rotation[1]"),
            unit(1e4, Eu::Deg)
        );
        assert_eq!(u("gpFifo[2]^override_r"), unit(1e4, Eu::Percent));
        assert_eq!(Eu::Mm.unit_id(), 0x4D4D54);
        assert_eq!(Eu::Deg.unit_id(), 0x4444);
    }
}
