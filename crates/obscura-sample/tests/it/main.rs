//! Integration tests of obscura-sample: one binary, one module per concern.

mod determinism;
mod stratification;
mod warps;

use obscura_sample::{Sampler, SamplerKind};

/// A sampler that must exist: the tests only build valid ones.
pub fn sampler(kind: SamplerKind, spp: u32, seed: u64) -> Sampler {
    Sampler::new(kind, spp, seed).expect("valid sampler parameters")
}

/// Asserts two `f32` agree to `tol` (absolute), naming what was compared.
#[macro_export]
macro_rules! assert_close {
    ($a:expr, $b:expr, $tol:expr, $($what:tt)+) => {{
        let (a, b, tol): (f32, f32, f32) = ($a, $b, $tol);
        assert!((a - b).abs() <= tol, "{}: {} vs {} (tolerance {})", format!($($what)+), a, b, tol);
    }};
}
