//! Numbers for the JSON the CLI prints.

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
    let rounded = (value * 1e9).round() / 1e9;
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
    #[test]
    fn rounds_noise_and_negative_zero() {
        assert_eq!(super::number(979.999_999_999_999_9), "980");
        assert_eq!(super::number(-0.0), "0");
        assert_eq!(super::number(-1e-12), "0");
        assert_eq!(super::number(1305.92), "1305.92");
    }
}
