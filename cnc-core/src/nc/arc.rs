//! Circle geometry of G02/G03 blocks: the plane's axes, the centre from the centre form
//! (I J K) or the radius form (R), and the checks that make an arc well defined.

/// The working plane: which main axes (the channel's first three) span the circle, and which
/// is the normal (helix and tool-length axis).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Plane {
    /// G17: X-Y, normal Z (the default).
    #[default]
    Xy,
    /// G18: Z-X, normal Y.
    Zx,
    /// G19: Y-Z, normal X.
    Yz,
}

impl Plane {
    /// Channel axis indices: first and second axis of the plane, then its normal. Seen from
    /// the normal's positive side, first -> second is counter-clockwise.
    pub fn axes(self) -> [usize; 3] {
        match self {
            Plane::Xy => [0, 1, 2],
            Plane::Zx => [2, 0, 1],
            Plane::Yz => [1, 2, 0],
        }
    }

    /// "G17", "G18", "G19".
    pub fn name(self) -> &'static str {
        match self {
            Plane::Xy => "G17",
            Plane::Zx => "G18",
            Plane::Yz => "G19",
        }
    }
}

/// A decoded arc: its plane, centre and turning direction. Start and end are the block's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcMove {
    /// The plane.
    pub plane: Plane,
    /// Centre in the plane's first and second axis (channel coordinates).
    pub center: [f64; 2],
    /// G03 (counter-clockwise seen from the normal's positive side).
    pub ccw: bool,
    /// Start and end coincide: one full turn.
    pub full_turn: bool,
}

impl ArcMove {
    /// The angle swept from `start` to `end` (plane coordinates), positive, in radians.
    pub fn sweep(&self, start: [f64; 2], end: [f64; 2]) -> f64 {
        let a0 = (start[1] - self.center[1]).atan2(start[0] - self.center[0]);
        let a1 = (end[1] - self.center[1]).atan2(end[0] - self.center[0]);
        let tau = core::f64::consts::TAU;
        let mut d = if self.ccw { a1 - a0 } else { a0 - a1 };
        d = d.rem_euclid(tau);
        if self.full_turn || d < 1e-12 {
            d = if self.full_turn { tau } else { d };
        }
        d
    }
}

/// Why an arc is not well defined.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ArcError {
    /// Neither I/J/K nor R.
    NoCenter,
    /// Both a centre and R.
    CenterAndRadius,
    /// R with start = end: a full circle needs the centre form.
    FullCircleWithRadius,
    /// |R| is less than half the chord.
    RadiusTooSmall {
        /// |R|.
        radius: f64,
        /// Half the distance start-end.
        half_chord: f64,
    },
    /// The start lies on the centre.
    ZeroRadius,
    /// Start and end radius differ by more than the tolerance.
    EndNotOnCircle {
        /// Start radius.
        start: f64,
        /// End radius.
        end: f64,
        /// The tolerance.
        tolerance: f64,
    },
}

impl core::fmt::Display for ArcError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ArcError::NoCenter => f.write_str("G2/G3 needs a centre (I, J, K) or a radius (R)"),
            ArcError::CenterAndRadius => {
                f.write_str("G2/G3 takes a centre (I, J, K) or a radius (R), not both")
            }
            ArcError::FullCircleWithRadius => f.write_str(
                "a full circle (end = start) cannot be given by R: program its centre with I, J, K",
            ),
            ArcError::RadiusTooSmall { radius, half_chord } => write!(
                f,
                "radius {radius} is less than half the distance to the end point ({half_chord})"
            ),
            ArcError::ZeroRadius => f.write_str("the arc's centre lies on its start point"),
            ArcError::EndNotOnCircle {
                start,
                end,
                tolerance,
            } => write!(
                f,
                "the end point is not on the circle: start radius {start}, end radius {end} (tolerance {tolerance} mm)"
            ),
        }
    }
}

/// The centre of an arc from `start` to `end` (plane coordinates) with radius `r` (R form:
/// positive for at most half a turn, negative for more).
pub fn center_from_radius(
    start: [f64; 2],
    end: [f64; 2],
    r: f64,
    ccw: bool,
) -> Result<[f64; 2], ArcError> {
    let (dx, dy) = (end[0] - start[0], end[1] - start[1]);
    let chord = dx.hypot(dy);
    if chord < 1e-9 {
        return Err(ArcError::FullCircleWithRadius);
    }
    let half = chord / 2.0;
    let radius = r.abs();
    if radius < half - 1e-9 * radius.max(1.0) {
        return Err(ArcError::RadiusTooSmall {
            radius,
            half_chord: half,
        });
    }
    let h = (radius * radius - half * half).max(0.0).sqrt();
    // Left of the chord start->end is (-dy, dx). A short counter-clockwise arc has its centre
    // on the left; clockwise or a long arc flips it.
    let left = ccw == (r > 0.0);
    let s = if left { 1.0 } else { -1.0 } * h / chord;
    Ok([start[0] + dx / 2.0 - s * dy, start[1] + dy / 2.0 + s * dx])
}

/// Checks that `end` lies on the circle through `start` about `center` within `tolerance`.
pub fn check_on_circle(
    start: [f64; 2],
    end: [f64; 2],
    center: [f64; 2],
    tolerance: f64,
) -> Result<(), ArcError> {
    let r0 = (start[0] - center[0]).hypot(start[1] - center[1]);
    let r1 = (end[0] - center[0]).hypot(end[1] - center[1]);
    if r0 < 1e-9 {
        return Err(ArcError::ZeroRadius);
    }
    if (r0 - r1).abs() > tolerance {
        return Err(ArcError::EndNotOnCircle {
            start: r0,
            end: r1,
            tolerance,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radius_form_picks_the_centre_by_direction_and_sign() {
        // Quarter circle from (10, 0) to (0, 10) about the origin is counter-clockwise.
        let c = center_from_radius([10.0, 0.0], [0.0, 10.0], 10.0, true).unwrap();
        assert!(c[0].abs() < 1e-12 && c[1].abs() < 1e-12, "{c:?}");
        // The same end points clockwise with R>0: the other centre, (10, 10).
        let c = center_from_radius([10.0, 0.0], [0.0, 10.0], 10.0, false).unwrap();
        assert!(
            (c[0] - 10.0).abs() < 1e-12 && (c[1] - 10.0).abs() < 1e-12,
            "{c:?}"
        );
        // R<0 counter-clockwise: the long way, centre (10, 10).
        let c = center_from_radius([10.0, 0.0], [0.0, 10.0], -10.0, true).unwrap();
        assert!((c[0] - 10.0).abs() < 1e-12, "{c:?}");
        let arc = ArcMove {
            plane: Plane::Xy,
            center: c,
            ccw: true,
            full_turn: false,
        };
        let sweep = arc.sweep([10.0, 0.0], [0.0, 10.0]);
        assert!(
            (sweep - 1.5 * core::f64::consts::PI).abs() < 1e-12,
            "{sweep}"
        );
        assert_eq!(
            center_from_radius([0.0, 0.0], [0.0, 0.0], 5.0, true),
            Err(ArcError::FullCircleWithRadius)
        );
        assert!(matches!(
            center_from_radius([0.0, 0.0], [30.0, 0.0], 10.0, true),
            Err(ArcError::RadiusTooSmall { .. })
        ));
    }
}
