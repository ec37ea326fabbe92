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
/// letters or digits (`X`, `AB`, `X1`), none twice, and room for them in its
/// [`AxisLayout`].
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
    let slots = AxisLayout::new(axes).len();
    if slots > MAX_CHANNEL_AXES {
        return Err(format!(
            "{} axes besides X Y Z A B C take {slots} places with the six pose places, \
             more than the {MAX_CHANNEL_AXES} a channel holds",
            slots - POSE_AXES.len()
        ));
    }
    Ok(())
}

/// The pose axes in their slot order.
pub const POSE_AXES: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];

/// Where a channel keeps its axes' values: six pose slots X Y Z A B C first (what the
/// kinematics, `#CS`, the dynamic CS and the plane's arcs read), then the channel's other axes.
///
/// A channel of six axes or more keeps its configuration's order when no pose name stands
/// out of its place: its first six axes are the pose slots whatever their names (the
/// manual's example 1 names them AM AH AA A B C). Any other channel (a mill's X Y Z, a 5-axis
/// X Y Z A C, a pose name out of its place) has its pose axes put in their slots by name, the
/// slots it lacks held empty (their value 0, their name empty: no word matches it), and its
/// other axes after them in configuration order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AxisLayout {
    /// Per slot: the axis's name, empty for a pose slot the channel lacks.
    names: Vec<String>,
    /// Per configured axis (configuration order): its slot.
    slots: Vec<usize>,
}

impl AxisLayout {
    /// The layout of a channel with these axis names (checked by [`check_channel_axes`]).
    pub fn new(axes: &[String]) -> Self {
        let in_place = |(i, a): (usize, &String)| match POSE_AXES.iter().position(|p| p == a) {
            Some(slot) => slot == i,
            None => true,
        };
        if axes.len() >= POSE_AXES.len() && axes.iter().enumerate().all(in_place) {
            return Self {
                names: axes.to_vec(),
                slots: (0..axes.len()).collect(),
            };
        }
        let mut names: Vec<String> = vec![String::new(); POSE_AXES.len()];
        let mut slots = Vec::with_capacity(axes.len());
        for a in axes {
            match POSE_AXES.iter().position(|p| p == a) {
                Some(slot) => {
                    names[slot] = a.clone();
                    slots.push(slot);
                }
                None => {
                    slots.push(names.len());
                    names.push(a.clone());
                }
            }
        }
        Self { names, slots }
    }

    /// Per slot: the axis's name, empty for a pose slot the channel lacks.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Per configured axis, in configuration order: its slot.
    pub fn slots(&self) -> &[usize] {
        &self.slots
    }

    /// How many slots (the length of the channel's set-points).
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Never: a layout holds the six pose slots at least.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Whether slot `slot` holds an axis of the channel.
    pub fn has(&self, slot: usize) -> bool {
        self.names.get(slot).is_some_and(|n| !n.is_empty())
    }

    /// Whether the channel has all six pose axes (what a transformation needs).
    pub fn has_pose(&self) -> bool {
        (0..POSE_AXES.len()).all(|s| self.has(s))
    }

    /// The pose axes the channel lacks, e.g. "A B C".
    pub fn missing_pose(&self) -> String {
        let missing: Vec<&str> = (0..POSE_AXES.len())
            .filter(|&s| !self.has(s))
            .map(|s| POSE_AXES[s])
            .collect();
        missing.join(" ")
    }

    /// Values given in configuration order (as many as given, at most one per axis) in slot
    /// order; the other slots keep what `out` holds.
    pub fn place(&self, configured: &[f64], out: &mut [f64]) {
        for (&slot, &v) in self.slots.iter().zip(configured) {
            if let Some(o) = out.get_mut(slot) {
                *o = v;
            }
        }
    }
}
