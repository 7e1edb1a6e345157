//! The deterministic random numbers the generated scenes lay themselves out with: a SplitMix64
//! stream (Steele, Lea & Flood, "Fast splittable pseudorandom number generators", OOPSLA
//! 2014; `rand_xoshiro`'s) and the distributions the layouts draw from it, so that a generated
//! scene is the same on every machine, node and run.

use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::SplitMix64;

/// A SplitMix64 stream.
pub(super) struct Random(SplitMix64);

impl Random {
    /// The stream of `seed`.
    pub fn new(seed: u64) -> Self {
        Self(SplitMix64::seed_from_u64(seed))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// A uniform number in [0, 1).
    pub fn unit(&mut self) -> f32 {
        // The top 24 bits: every value exactly representable, never 1.
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A uniform number in [`low`, `high`).
    pub fn range(&mut self, low: f32, high: f32) -> f32 {
        low + (high - low) * self.unit()
    }

    /// A uniform integer in [0, `n`).
    pub fn below(&mut self, n: u32) -> u32 {
        (((self.next_u64() >> 32) * u64::from(n)) >> 32) as u32
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f32) -> bool {
        self.unit() < p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_and_reproducible() {
        let mut a = Random::new(7);
        let values: Vec<f32> = (0..10_000).map(|_| a.unit()).collect();
        assert!(values.iter().all(|&v| (0.0..1.0).contains(&v)));
        let mean = values.iter().sum::<f32>() / values.len() as f32;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
        let mut b = Random::new(7);
        assert!(values.iter().all(|&v| v == b.unit()));
        assert!((0..1000).all(|_| a.below(3) < 3));
    }
}
