//! Numbers for the JSON the CLI prints.

/// A number rounded to 1e-9 (so 979.9999999999999 prints as 980), never `-0`.
pub fn number(value: f64) -> String {
    let rounded = (value * 1e9).round() / 1e9;
    let rounded = if rounded == 0.0 { 0.0 } else { rounded };
    format!("{rounded}")
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
