//! Samplers put exactly one sample in each stratum where they claim to.

use obscura_sample::{SOBOL_DIMENSIONS, Sampler, SamplerKind};
use proptest::prelude::*;

use crate::sampler;

/// Which of `count` equal intervals `x` falls in; `x * count` is exact in f64 for the
/// counts used here (24-bit mantissa times at most 2^20).
fn interval(x: f32, count: u32) -> u32 {
    assert!((0.0..1.0).contains(&x), "value {x} outside [0, 1)");
    (f64::from(x) * f64::from(count)).floor() as u32
}

/// Asserts that samples `first .. first + n` of `pixel`, in dimensions `dx` and `dy`, put one
/// sample in each cell of the `cx x cy` grid (`cx * cy == n`).
fn assert_one_per_cell(s: &Sampler, pixel: [u32; 2], first: u32, dims: [u32; 2], cells: [u32; 2]) {
    let [cx, cy] = cells;
    let n = cx * cy;
    let mut seen = vec![false; n as usize];
    for index in first..first + n {
        let i = interval(s.value(pixel, index, dims[0]), cx);
        let j = interval(s.value(pixel, index, dims[1]), cy);
        let cell = (j * cx + i) as usize;
        assert!(
            !seen[cell],
            "{} spp {} seed {} pixel {pixel:?} dims {dims:?}: cell ({i}, {j}) of {cx}x{cy} twice",
            s.kind().name(),
            s.samples_per_pixel(),
            s.seed()
        );
        seen[cell] = true;
    }
}

/// Asserts that samples `first .. first + n` put one sample in each of `n` intervals of
/// `dimension`.
fn assert_one_per_interval(s: &Sampler, pixel: [u32; 2], first: u32, dimension: u32, n: u32) {
    assert_one_per_cell(s, pixel, first, [dimension, dimension], [n, 1]);
}

#[test]
fn stratified_is_jittered_per_pair_and_latin_per_dimension() {
    for spp in [1, 2, 3, 5, 7, 8, 12, 16, 30, 64, 100] {
        for seed in [0, 1, 99] {
            let s = sampler(SamplerKind::Stratified, spp, seed);
            let [nx, ny] = s.stratified_grid();
            assert_eq!(nx * ny, spp);
            for pixel in [[0, 0], [1, 0], [17, 33]] {
                // The first pattern and the second (indices spp .. 2 spp).
                for first in [0, spp] {
                    for pair in 0..6 {
                        assert_one_per_cell(&s, pixel, first, [2 * pair, 2 * pair + 1], [nx, ny]);
                        assert_one_per_interval(&s, pixel, first, 2 * pair, spp);
                        assert_one_per_interval(&s, pixel, first, 2 * pair + 1, spp);
                    }
                }
            }
        }
    }
}

#[test]
fn stratified_grid_hand_cases() {
    // 36 = 6 x 6; 24 = 4 x 6 (4 is the largest divisor <= sqrt 24 = 4.9); 13 is prime.
    assert_eq!(
        sampler(SamplerKind::Stratified, 36, 0).stratified_grid(),
        [6, 6]
    );
    assert_eq!(
        sampler(SamplerKind::Stratified, 24, 0).stratified_grid(),
        [4, 6]
    );
    assert_eq!(
        sampler(SamplerKind::Stratified, 13, 0).stratified_grid(),
        [1, 13]
    );
}

#[test]
fn sobol_fills_every_elementary_interval_at_powers_of_two() {
    for seed in [0, 5] {
        for pixel in [[0, 0], [3, 9], [640, 480]] {
            for m in 0..=10u32 {
                // At 2^m spp every pair's pass is a (0,m,2)-net.
                let s = sampler(SamplerKind::Sobol, 1 << m, seed);
                for pair in 0..5 {
                    for a in 0..=m {
                        assert_one_per_cell(
                            &s,
                            pixel,
                            0,
                            [2 * pair, 2 * pair + 1],
                            [1 << a, 1 << (m - a)],
                        );
                    }
                }
                // The film pair is not shuffled, so at any spp its first 2^m samples are one.
                let s = sampler(SamplerKind::Sobol, 1000, seed);
                for a in 0..=m {
                    assert_one_per_cell(&s, pixel, 0, [0, 1], [1 << a, 1 << (m - a)]);
                }
            }
        }
    }
}

#[test]
fn sobol_later_passes_are_nets_too() {
    // Samples 16..32 of a 16-spp pixel are its second pass: again one per 4x4 cell.
    let s = sampler(SamplerKind::Sobol, 16, 3);
    for pair in 0..4 {
        assert_one_per_cell(&s, [7, 7], 16, [2 * pair, 2 * pair + 1], [4, 4]);
        assert_one_per_cell(&s, [7, 7], 16, [2 * pair, 2 * pair + 1], [2, 8]);
    }
}

/// Pearson's chi-square statistic of `counts` against equal expected counts.
fn chi_square(counts: &[u32]) -> f64 {
    let total: u32 = counts.iter().sum();
    let expected = f64::from(total) / counts.len() as f64;
    counts
        .iter()
        .map(|&c| (f64::from(c) - expected).powi(2) / expected)
        .sum()
}

#[test]
fn sobol_past_its_dimensions_is_uniform_and_independent() {
    // Past SOBOL_DIMENSIONS the values are hashes: not one per stratum, but uniform on the
    // square of a pair. 4096 points (64 pixels x 64 samples) per pair in a 16 x 16 grid:
    // chi-square with 255 degrees of freedom, whose 0.999 quantile is 330.5 (the
    // Wilson-Hilferty approximation: 255 (1 - 2/2295 + 3.090 sqrt(2/2295))^3). A pair whose
    // halves were equal, or a hash that ignored the index, would put every point on a line or
    // in one cell, a statistic in the tens of thousands.
    let s = sampler(SamplerKind::Sobol, 64, 4);
    for first in [
        SOBOL_DIMENSIONS,
        SOBOL_DIMENSIONS + 2,
        SOBOL_DIMENSIONS + 30,
    ] {
        let mut counts = [0u32; 256];
        for p in 0..64u32 {
            for index in 0..64 {
                let pixel = [p % 8, p / 8];
                let i = interval(s.value(pixel, index, first), 16);
                let j = interval(s.value(pixel, index, first + 1), 16);
                counts[(j * 16 + i) as usize] += 1;
            }
        }
        let chi2 = chi_square(&counts);
        assert!(
            chi2 < 330.5,
            "dimensions {first}, {}: chi-square {chi2}",
            first + 1
        );
    }
    // The last stratified pair is still a net; the first pair after it need not be (and with
    // 64 points in 64 cells of a hash, is not).
    let last = SOBOL_DIMENSIONS - 2;
    assert_one_per_cell(&s, [3, 3], 0, [last, last + 1], [8, 8]);
    let mut seen = [false; 64];
    let mut twice = false;
    for index in 0..64 {
        let i = interval(s.value([3, 3], index, SOBOL_DIMENSIONS), 8);
        let j = interval(s.value([3, 3], index, SOBOL_DIMENSIONS + 1), 8);
        twice |= std::mem::replace(&mut seen[(j * 8 + i) as usize], true);
    }
    assert!(
        twice,
        "the pair past SOBOL_DIMENSIONS is a net: it is still stratified"
    );
}

#[test]
fn halton_fills_its_prime_power_strata() {
    // Dimension d uses the d-th prime: 2, 3, 5, 7, 11, 13, ...
    let bases = [2u32, 3, 5, 7, 11, 13, 17, 19];
    for seed in [0, 8] {
        let s = sampler(SamplerKind::Halton, 64, seed);
        for pixel in [[0, 0], [12, 5]] {
            // Film: the first 2^a 3^b samples fill the 2^a x 3^b grid.
            for (a, b) in [(1, 1), (2, 1), (3, 2), (4, 3), (5, 2)] {
                assert_one_per_cell(&s, pixel, 0, [0, 1], [1 << a, 3u32.pow(b)]);
            }
            // Each dimension alone: the first b^k samples fill b^k intervals.
            for (dimension, &base) in bases.iter().enumerate() {
                let mut n = base;
                while n <= 2000 {
                    assert_one_per_interval(&s, pixel, 0, dimension as u32, n);
                    n *= base;
                }
            }
            // Lens (bases 5 and 7): 5 x 7 = 35 samples fill the 5 x 7 grid.
            assert_one_per_cell(&s, pixel, 0, [2, 3], [5, 7]);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn every_value_is_in_the_unit_interval(
        kind in prop::sample::select(SamplerKind::ALL.to_vec()),
        spp in 1u32..5000,
        seed: u64,
        pixel: [u32; 2],
        index: u32,
        dimension in 0u32..5000,
    ) {
        let s = sampler(kind, spp, seed);
        let u = s.value(pixel, index, dimension);
        prop_assert!((0.0..1.0).contains(&u), "{} gave {u}", kind.name());
    }

    #[test]
    fn stratified_stratifies_for_any_seed_pixel_and_count(seed: u64, pixel: [u32; 2], spp in 1u32..200) {
        let s = sampler(SamplerKind::Stratified, spp, seed);
        let grid = s.stratified_grid();
        for pair in [0, 1, 2, 7] {
            assert_one_per_cell(&s, pixel, 0, [2 * pair, 2 * pair + 1], grid);
            assert_one_per_interval(&s, pixel, 0, 2 * pair + 1, spp);
        }
    }

    #[test]
    fn sobol_is_a_net_for_any_seed_and_pixel(
        seed: u64,
        pixel: [u32; 2],
        m in 0u32..9,
        pair in 0u32..SOBOL_DIMENSIONS / 2,
    ) {
        let s = sampler(SamplerKind::Sobol, 1 << m, seed);
        for a in 0..=m {
            assert_one_per_cell(&s, pixel, 0, [2 * pair, 2 * pair + 1], [1 << a, 1 << (m - a)]);
        }
    }

    #[test]
    fn halton_film_is_stratified_for_any_seed_and_pixel(seed: u64, pixel: [u32; 2]) {
        let s = sampler(SamplerKind::Halton, 72, seed);
        // 72 = 2^3 * 3^2.
        assert_one_per_cell(&s, pixel, 0, [0, 1], [8, 9]);
    }
}
