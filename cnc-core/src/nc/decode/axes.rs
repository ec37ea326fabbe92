//! A channel's axes: their names, checked (the values per axis are
//! [`crate::setpoint::AxisValues`]).

use crate::nc::ast::AxisName;
use crate::setpoint::MAX_CHANNEL_AXES;

/// One-letter words that are never axes: G, M, F, N and the circle, spindle, tool, parameter
/// and call addresses.
pub const RESERVED_ADDRESSES: &[&str] = &[
    "D", "F", "G", "I", "J", "K", "L", "M", "N", "P", "R", "S", "T",
];

/// Checks a channel's axis names: 1 to [`MAX_CHANNEL_AXES`] of them, each a letter followed by
/// letters or digits (`X`, `AB`, `X1`), none twice.
pub fn check_channel_axes(axes: &[String]) -> Result<(), String> {
    if axes.is_empty() || axes.len() > MAX_CHANNEL_AXES {
        return Err(format!(
            "a channel has 1 to {MAX_CHANNEL_AXES} axes, found {}",
            axes.len()
        ));
    }
    for (i, a) in axes.iter().enumerate() {
        let mut chars = a.chars();
        let well_formed = chars.next().is_some_and(|c| c.is_ascii_uppercase())
            && chars.all(|c| c.is_ascii_uppercase() || c.is_ascii_digit())
            && a.len() <= AxisName::CAPACITY;
        if !well_formed {
            return Err(format!(
                "axis name \"{a}\" must be upper-case letters then digits (e.g. X, AB, X1)"
            ));
        }
        if axes[..i].contains(a) {
            return Err(format!("axis name \"{a}\" is given twice"));
        }
        if RESERVED_ADDRESSES.contains(&a.as_str()) {
            return Err(format!(
                "axis name \"{a}\" is an address of the language ({})",
                RESERVED_ADDRESSES.join(" ")
            ));
        }
    }
    Ok(())
}
