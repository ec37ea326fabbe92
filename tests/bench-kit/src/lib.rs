//! The bench kit: the helpers every benchmark of the workspace shares, in one place (no
//! dependencies, so any package takes it as a dev-dependency without building the others).
//!
//! * [`smoke`]: `CNC_BENCH_SMOKE=1` (CI) asks for a run that only shows the bench reaches its
//!   end; [`scaled`] cuts a count for it.
//! * [`median`], [`median_u64`]: the middle of a set of samples (the upper middle for an even
//!   count), the figure every bench reports over its interleaved repeats.

#![forbid(unsafe_code)]

/// Whether this is the CI's smoke run (`CNC_BENCH_SMOKE=1`): its figures mean nothing.
pub fn smoke() -> bool {
    std::env::var("CNC_BENCH_SMOKE").is_ok_and(|v| v == "1")
}

/// `full` in a real run; in the smoke run a thousandth of it, at least 1.
pub fn scaled(full: usize) -> usize {
    if smoke() {
        (full / 1000).max(1)
    } else {
        full
    }
}

/// The median of `v` (NaN sorted last); panics on an empty set, which no bench takes.
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The median of integer samples (nanoseconds, counts).
pub fn median_u64(mut v: Vec<u64>) -> u64 {
    v.sort_unstable();
    v[v.len() / 2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_take_the_middle_sample() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 3.0);
        assert_eq!(median_u64(vec![9, 1, 5]), 5);
    }
}
