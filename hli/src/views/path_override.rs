//! The path override unit's values as the PLC commands them, validated.

use crate::layout::HliChannelOverrideUnit;

/// Path override and feed hold as the PLC commands them, validated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PathOverride {
    /// Feed override, 0.1 % (0..=2000).
    pub feed_permille: u32,
    /// Rapid override, 0.1 % (0..=1000).
    pub rapid_permille: u32,
    /// Feed hold.
    pub feed_hold: bool,
}

/// A PLC-written override value outside its range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum OverrideError {
    /// Feed override above 200.0 %.
    #[error("feed_override_w {0} above 2000 (0.1 %)")]
    Feed(u32),
    /// Rapid override above 100.0 %.
    #[error("rapid_override_w {0} above 1000 (0.1 %)")]
    Rapid(u32),
    /// Feed-hold byte neither FALSE nor TRUE.
    #[error("feed_hold_w byte {0} is neither FALSE nor TRUE")]
    FeedHold(u8),
}

/// The override and feed hold a freshly created image holds for every channel: 100 %, no
/// hold (a zeroed image would mean 0 %, a machine that never moves).
pub const DEFAULT_PATH_OVERRIDE: PathOverride = PathOverride {
    feed_permille: 1000,
    rapid_permille: 1000,
    feed_hold: false,
};

/// Largest feed override, 0.1 %.
pub const MAX_FEED_OVERRIDE: u32 = 2000;
/// Largest rapid override, 0.1 %.
pub const MAX_RAPID_OVERRIDE: u32 = 1000;

pub(super) fn validate_override(
    unit: &HliChannelOverrideUnit,
) -> Result<PathOverride, OverrideError> {
    if unit.feed_override_w > MAX_FEED_OVERRIDE {
        return Err(OverrideError::Feed(unit.feed_override_w));
    }
    if unit.rapid_override_w > MAX_RAPID_OVERRIDE {
        return Err(OverrideError::Rapid(unit.rapid_override_w));
    }
    let feed_hold = unit.feed_hold_w.get().map_err(OverrideError::FeedHold)?;
    Ok(PathOverride {
        feed_permille: unit.feed_override_w,
        rapid_permille: unit.rapid_override_w,
        feed_hold,
    })
}
