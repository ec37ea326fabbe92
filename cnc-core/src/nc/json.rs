//! Numbers in the JSON the decoded block stream and the command-line tools print.

/// A number rounded to 1e-9 (so 979.9999999999999 prints as 980), never `-0`.
pub fn number(value: f64) -> String {
    let mut s = String::new();
    push_number(&mut s, value);
    s
}

/// [`number`] appended to `out`, without a String of its own. A value that is not finite
/// (which the decoder never lets through) prints as `null`, so the output stays JSON.
pub fn push_number(out: &mut String, value: f64) {
    use std::fmt::Write as _;
    if !value.is_finite() {
        out.push_str("null");
        return;
    }
    // Below a million the value in billionths is a whole number a u64 holds exactly, and its
    // decimal digits are what the shortest round-trip form of the rounded value prints (two
    // decimals nine places apart are further apart than the spacing of doubles there): printed
    // as integers, five times faster than the float formatter `cnc check --blocks` spends most
    // of its time in otherwise.
    let billionths = (value * 1e9).round();
    if billionths.abs() < 1e15 {
        if billionths == 0.0 {
            out.push('0');
            return;
        }
        let n = billionths.abs() as u64;
        if billionths < 0.0 {
            out.push('-');
        }
        let (whole, mut frac) = (n / 1_000_000_000, n % 1_000_000_000);
        let _ = write!(out, "{whole}");
        if frac != 0 {
            let mut digits = 9;
            while frac % 10 == 0 {
                frac /= 10;
                digits -= 1;
            }
            let _ = write!(out, ".{frac:0digits$}");
        }
        return;
    }
    let rounded = billionths / 1e9;
    let rounded = if rounded == 0.0 || !rounded.is_finite() {
        if rounded.is_finite() {
            0.0
        } else {
            value
        }
    } else {
        rounded
    };
    let _ = write!(out, "{rounded}");
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    proptest! {
        /// The integer path prints exactly what the float formatter prints for the rounded
        /// value.
        #[test]
        fn the_fast_path_prints_what_the_float_formatter_prints(v in -2e6f64..2e6, k in 0u32..10) {
            let v = (v * 10f64.powi(k as i32)).round() / 10f64.powi(k as i32);
            let rounded = (v * 1e9).round() / 1e9;
            let rounded = if rounded == 0.0 { 0.0 } else { rounded };
            prop_assert_eq!(super::number(v), format!("{rounded}"));
        }
    }

    #[test]
    fn rounds_noise_and_negative_zero() {
        assert_eq!(super::number(979.999_999_999_999_9), "980");
        assert_eq!(super::number(-0.0), "0");
        assert_eq!(super::number(-1e-12), "0");
        assert_eq!(super::number(1305.92), "1305.92");
    }
}
