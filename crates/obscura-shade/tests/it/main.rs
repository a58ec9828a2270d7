//! Integration tests of obscura-shade: BSDF properties, light sampling and the path tracer.

mod bsdf;
mod integrator;
mod lights;

use glam::{Vec2, Vec3};
use obscura_shade::SampleDims;

/// A small deterministic generator for tests (SplitMix64), so statistical tests are repeatable.
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03)
    }
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1) with 24 bits.
    pub fn uniform(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }
    /// A uniformly distributed unit vector.
    pub fn direction(&mut self) -> Vec3 {
        obscura_sample::square_to_uniform_sphere(Vec2::new(self.uniform(), self.uniform()))
    }
}

impl SampleDims for Rng {
    fn next_1d(&mut self) -> f32 {
        self.uniform()
    }
    fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.uniform(), self.uniform())
    }
}

/// Mean and standard error of the mean.
pub fn mean_and_error(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}
