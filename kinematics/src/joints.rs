//! Joint vectors and solution sets without heap allocation.

/// Axis values of a kinematic, degrees for rotary and mm for linear axes. Kinematics with
/// fewer than six axes leave the rest 0.
pub type Joints = [f64; 6];

/// Up to eight inverse solutions (the closed-form 6-axis robot has eight).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solutions {
    items: [Joints; 8],
    len: usize,
}

impl Default for Solutions {
    fn default() -> Self {
        Self {
            items: [[0.0; 6]; 8],
            len: 0,
        }
    }
}

impl Solutions {
    /// Adds a solution; ignored beyond eight.
    pub fn push(&mut self, joints: Joints) {
        if self.len < self.items.len() {
            self.items[self.len] = joints;
            self.len += 1;
        }
    }

    /// The solutions.
    pub fn as_slice(&self) -> &[Joints] {
        &self.items[..self.len]
    }

    /// Number of solutions.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// Limits of one joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimit {
    /// Lower limit.
    pub min: f64,
    /// Upper limit.
    pub max: f64,
}

impl JointLimit {
    /// No limit.
    pub const NONE: JointLimit = JointLimit {
        min: f64::NEG_INFINITY,
        max: f64::INFINITY,
    };

    /// Whether `value` lies within.
    pub fn contains(&self, value: f64) -> bool {
        value >= self.min && value <= self.max
    }
}

/// Moves a rotary joint value by whole turns to lie as close as possible to `reference`
/// while staying within `limit`; `None` when no turn fits.
pub fn nearest_turn(value: f64, reference: f64, limit: &JointLimit) -> Option<f64> {
    // Fast path (the common case): already within limits and within half a turn.
    if limit.contains(value) && (value - reference).abs() <= 180.0 {
        return Some(value);
    }
    // Turns k that keep value + 360 k within the limits form an interval; the distance to the
    // reference grows monotonically away from the ideal k, so clamping the ideal k is optimal.
    let k_min = ceil((limit.min - value) / 360.0);
    let k_max = floor((limit.max - value) / 360.0);
    if k_min > k_max {
        return None;
    }
    let ideal = floor((reference - value) / 360.0 + 0.5);
    Some(value + 360.0 * ideal.clamp(k_min, k_max))
}

/// `f64::floor` without a library call (the baseline x86-64 target has no rounding
/// instruction); exact for |x| < 2^52, infinities pass through.
fn floor(x: f64) -> f64 {
    if x.abs() >= 4_503_599_627_370_496.0 || x.is_nan() {
        return x;
    }
    let t = (x as i64) as f64;
    if t > x {
        t - 1.0
    } else {
        t
    }
}

fn ceil(x: f64) -> f64 {
    -floor(-x)
}

/// Squared distance between two joint vectors.
pub fn distance_sq(a: &Joints, b: &Joints) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turns_are_chosen_near_the_reference_within_limits() {
        let wide = JointLimit {
            min: -350.0,
            max: 350.0,
        };
        assert_eq!(nearest_turn(170.0, -170.0, &wide), Some(-190.0));
        assert_eq!(nearest_turn(10.0, 700.0, &wide), Some(10.0));
        assert_eq!(nearest_turn(10.0, 300.0, &wide), Some(10.0));
        assert_eq!(nearest_turn(-10.0, 300.0, &wide), Some(350.0));
        let tight = JointLimit {
            min: -170.0,
            max: 170.0,
        };
        assert_eq!(nearest_turn(175.0, 0.0, &tight), None);
        assert_eq!(nearest_turn(-185.0, 0.0, &tight), None);
        assert_eq!(nearest_turn(-190.0, 0.0, &tight), Some(170.0));
        assert_eq!(
            nearest_turn(5.0, 1e9, &JointLimit::NONE).map(|v| (v - 1e9).abs() < 360.0),
            Some(true)
        );
        for x in [
            -2.5,
            -2.0,
            -0.5,
            0.0,
            0.5,
            2.0,
            2.5,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ] {
            assert_eq!(floor(x), x.floor());
            assert_eq!(ceil(x), x.ceil());
        }
    }
}
