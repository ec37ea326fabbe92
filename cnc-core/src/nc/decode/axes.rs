//! A channel's axes: their names, checked, and one value per axis stored inline.

use crate::nc::ast::AxisName;

/// Most axes one channel can have.
pub const MAX_CHANNEL_AXES: usize = 16;

/// One value per channel axis, in channel order, stored inline: a decoded block needs no heap
/// allocation, and the channel's tick can copy targets freely.
#[derive(Clone, Copy, PartialEq)]
pub struct AxisValues {
    len: u8,
    /// Slots beyond `len` stay 0, so the derived equality compares only the used ones.
    values: [f64; MAX_CHANNEL_AXES],
}

impl AxisValues {
    /// `n` zeros; `n` is cut to [`MAX_CHANNEL_AXES`] ([`check_channel_axes`] refuses more).
    pub fn zeros(n: usize) -> Self {
        Self {
            len: n.min(MAX_CHANNEL_AXES) as u8,
            values: [0.0; MAX_CHANNEL_AXES],
        }
    }

    /// The values of `slice` (cut to [`MAX_CHANNEL_AXES`]).
    pub fn from_slice(slice: &[f64]) -> Self {
        let mut v = Self::zeros(slice.len());
        let n = v.len();
        v.values[..n].copy_from_slice(&slice[..n]);
        v
    }
}

impl core::ops::Deref for AxisValues {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.values[..self.len as usize]
    }
}

impl core::ops::DerefMut for AxisValues {
    fn deref_mut(&mut self) -> &mut [f64] {
        &mut self.values[..self.len as usize]
    }
}

impl core::fmt::Debug for AxisValues {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

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
