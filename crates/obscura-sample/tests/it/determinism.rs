//! Values are pure functions: the same on every call, in every thread, from value() and
//! from the stream; and decorrelated between pixels and between film and lens.

use glam::Vec2;
use obscura_sample::{Sampler, SamplerKind};
use proptest::prelude::*;

use crate::sampler;

/// Every value of an 8x8-pixel block, 8 samples, 10 dimensions, in the given pixel order.
fn block_values(s: &Sampler, pixels: &[[u32; 2]]) -> Vec<([u32; 2], u32, u32, u32)> {
    let mut out = Vec::new();
    for &pixel in pixels {
        for index in 0..8 {
            for dimension in 0..10 {
                out.push((
                    pixel,
                    index,
                    dimension,
                    s.value(pixel, index, dimension).to_bits(),
                ));
            }
        }
    }
    out
}

#[test]
fn same_numbers_whatever_the_thread_count_or_order() {
    let pixels: Vec<[u32; 2]> = (0..64).map(|k| [k % 8, k / 8]).collect();
    for kind in SamplerKind::ALL {
        let s = sampler(kind, 8, 42);
        let mut serial = block_values(&s, &pixels);
        serial.sort();
        // Four threads, each taking every fourth pixel, in reverse order.
        let mut threaded: Vec<_> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..4)
                .map(|t| {
                    let s = s.clone();
                    let mine: Vec<[u32; 2]> =
                        pixels.iter().rev().skip(t).step_by(4).copied().collect();
                    scope.spawn(move || block_values(&s, &mine))
                })
                .collect();
            handles
                .into_iter()
                .flat_map(|h| h.join().expect("worker thread"))
                .collect()
        });
        threaded.sort();
        assert_eq!(serial, threaded, "{}", kind.name());
    }
}

#[test]
fn the_seed_changes_the_numbers() {
    for kind in SamplerKind::ALL {
        let a = sampler(kind, 16, 1);
        let b = sampler(kind, 16, 2);
        let differ = (0..16)
            .filter(|&i| a.value([5, 5], i, 0) != b.value([5, 5], i, 0))
            .count();
        assert!(
            differ >= 12,
            "{}: only {differ} of 16 film values changed",
            kind.name()
        );
    }
}

#[test]
fn lens_samples_in_neighbouring_pixels_differ() {
    for kind in SamplerKind::ALL {
        let s = sampler(kind, 16, 0);
        for pixel in [[10u32, 10u32], [0, 0], [100, 7]] {
            for neighbour in [[pixel[0] + 1, pixel[1]], [pixel[0], pixel[1] + 1]] {
                let lens = |p: [u32; 2], i| Vec2::new(s.value(p, i, 2), s.value(p, i, 3));
                let same = (0..16)
                    .filter(|&i| lens(pixel, i) == lens(neighbour, i))
                    .count();
                assert_eq!(
                    same,
                    0,
                    "{}: {pixel:?} and {neighbour:?} share lens samples",
                    kind.name()
                );
                // Not just shifted a little: the lens pattern of sample 0 moves by a lot on
                // average over the 16 samples.
                let mean_distance: f32 = (0..16)
                    .map(|i| lens(pixel, i).distance(lens(neighbour, i)))
                    .sum::<f32>()
                    / 16.0;
                assert!(
                    mean_distance > 0.15,
                    "{}: mean distance {mean_distance}",
                    kind.name()
                );
            }
        }
    }
}

#[test]
fn lens_strata_do_not_follow_film_strata() {
    // A correlated sampler would give every sample the lens cell of its film cell (fraction
    // 1). Decorrelated, the lens cell matches the film cell 1 time in 16 on average.
    for kind in SamplerKind::ALL {
        let s = sampler(kind, 16, 0);
        let mut matches = 0;
        let mut total = 0;
        for k in 0..256u32 {
            let pixel = [k % 16, k / 16];
            for index in 0..16 {
                let cell = |dx, dy| {
                    let x = (s.value(pixel, index, dx) * 4.0) as u32;
                    let y = (s.value(pixel, index, dy) * 4.0) as u32;
                    y * 4 + x
                };
                matches += u32::from(cell(0, 1) == cell(2, 3));
                total += 1;
            }
        }
        let fraction = matches as f32 / total as f32;
        assert!(
            fraction < 0.12,
            "{}: lens cell = film cell {fraction} of the time",
            kind.name()
        );
    }
}

#[test]
fn time_does_not_follow_film_x() {
    // Correlation coefficient of film x and time over many pixels and samples: near zero.
    for kind in SamplerKind::ALL {
        let s = sampler(kind, 16, 3);
        let pairs: Vec<(f64, f64)> = (0..1024u32)
            .flat_map(|k| (0..16).map(move |i| ([k % 32, k / 32], i)))
            .map(|(p, i)| (f64::from(s.value(p, i, 0)), f64::from(s.value(p, i, 4))))
            .collect();
        let n = pairs.len() as f64;
        let (mx, my) = pairs
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let cov: f64 = pairs.iter().map(|(x, y)| (x - mx) * (y - my)).sum::<f64>() / n;
        let var_x: f64 = pairs.iter().map(|(x, _)| (x - mx).powi(2)).sum::<f64>() / n;
        let var_y: f64 = pairs.iter().map(|(_, y)| (y - my).powi(2)).sum::<f64>() / n;
        let r = cov / (var_x * var_y).sqrt();
        assert!(r.abs() < 0.05, "{}: correlation {r}", kind.name());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn repeated_calls_and_clones_agree(
        kind in prop::sample::select(SamplerKind::ALL.to_vec()),
        seed: u64, pixel: [u32; 2], index in 0u32..100_000, dimension in 0u32..64,
    ) {
        let s = sampler(kind, 64, seed);
        let again = s.clone();
        let u = s.value(pixel, index, dimension);
        prop_assert_eq!(u.to_bits(), s.value(pixel, index, dimension).to_bits());
        prop_assert_eq!(u.to_bits(), again.value(pixel, index, dimension).to_bits());
        let rebuilt = sampler(kind, 64, seed);
        prop_assert_eq!(u.to_bits(), rebuilt.value(pixel, index, dimension).to_bits());
    }

    #[test]
    fn stream_reads_the_documented_dimensions(
        kind in prop::sample::select(SamplerKind::ALL.to_vec()),
        seed: u64, pixel: [u32; 2], index in 0u32..1000,
    ) {
        let s = sampler(kind, 16, seed);
        let v = |d| s.value(pixel, index, d);
        let mut stream = s.stream(pixel, index);
        let (film, lens, time) = stream.camera();
        prop_assert_eq!(film, Vec2::new(v(0), v(1)));
        prop_assert_eq!(lens, Vec2::new(v(2), v(3)));
        prop_assert_eq!(time, v(4));
        prop_assert_eq!(stream.next_1d(), v(5));
        prop_assert_eq!(stream.next_2d(), Vec2::new(v(6), v(7)));
        prop_assert_eq!(stream.next_1d(), v(8));
        prop_assert_eq!(stream.next_2d(), Vec2::new(v(10), v(11)));
    }

    /// A camera that skips its lens or time reads the same film values, gets the neutral
    /// values for what it skips, and leaves every later dimension as it was.
    #[test]
    fn skipping_camera_dimensions_changes_nothing_after_them(
        kind in prop::sample::select(SamplerKind::ALL.to_vec()),
        seed: u64, pixel: [u32; 2], index in 0u32..1000, lens: bool, time: bool,
    ) {
        let s = sampler(kind, 16, seed);
        let v = |d| s.value(pixel, index, d);
        let mut stream = s.stream(pixel, index);
        let (film, lens_dims, time_dims) = stream.camera_with(lens, time);
        prop_assert_eq!(film, Vec2::new(v(0), v(1)));
        let lens_value = if lens { Vec2::new(v(2), v(3)) } else { Vec2::splat(0.5) };
        prop_assert_eq!(lens_dims, lens_value);
        prop_assert_eq!(time_dims, if time { v(4) } else { 0.0 });
        prop_assert_eq!(stream.next_1d(), v(5));
        prop_assert_eq!(stream.next_2d(), Vec2::new(v(6), v(7)));
    }

    /// Any mix of single and paired reads (and skips) gives exactly the sampler's values for
    /// the dimensions read (the stream keeps a Sobol pair's shared part between single reads;
    /// that must never change a value).
    #[test]
    fn any_mix_of_reads_gives_the_sampler_values(
        kind in prop::sample::select(SamplerKind::ALL.to_vec()),
        seed: u64, pixel: [u32; 2], index in 0u32..1000,
        reads in prop::collection::vec(any::<bool>(), 1..24),
    ) {
        let s = sampler(kind, 16, seed);
        let v = |d| s.value(pixel, index, d).to_bits();
        let mut stream = s.stream(pixel, index);
        // The cursor as the documented layout moves it, kept here, not read from the stream.
        let mut d = 0;
        if reads[0] {
            stream.camera();
            d = 5;
        }
        for (k, &single) in reads[1..].iter().enumerate() {
            if single && k % 3 == 2 {
                // Every third single read is skipped: later reads must not notice.
                stream.skip_1d();
                d += 1;
            } else if single {
                prop_assert_eq!(stream.next_1d().to_bits(), v(d));
                d += 1;
            } else {
                let first = d + d % 2;
                let u2 = stream.next_2d();
                prop_assert_eq!((u2.x.to_bits(), u2.y.to_bits()), (v(first), v(first + 1)));
                d = first + 2;
            }
            prop_assert_eq!(stream.dimension(), d);
        }
    }
}
