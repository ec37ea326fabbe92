//! Reproducible noise for the tests that feed random input (the hostile PLC, fuzzing, the
//! soak): xorshift64*, from a seed, so a failing case names its seed and comes back.

/// A seeded stream of 64-bit numbers.
#[derive(Debug, Clone)]
pub struct Noise(u64);

impl Noise {
    /// The stream of `seed` (any value; 0 is made odd).
    pub fn new(seed: u64) -> Self {
        Noise(seed | 1)
    }

    /// The next number.
    #[allow(clippy::should_implement_trait)] // an endless stream, not an iterator's Option
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// A number in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}
