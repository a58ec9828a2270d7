//! The film: reconstruction filters, per-tile accumulation and the final pixel values.
//!
//! Every sample is splatted into each pixel whose filter support holds it, with the filter's
//! weight. A pixel's value is the weighted mean of its samples' radiance (misses count as 0),
//! and its alpha the weighted fraction of samples whose camera ray hit geometry.
//!
//! Tiles accumulate into their own buffers (their pixels plus a margin as wide as the filter)
//! and are added into the film's fixed-point sums ([`PixelSums`]), exactly: the sums, and the
//! image, are bit-identical whatever the number of threads, the order tiles finish in, or how
//! the passes and tiles were split between processes or machines and merged.

mod filter;
mod tile;

pub use filter::Filter;
pub use tile::TileBuffer;

use rayon::prelude::*;

/// Fractional bits of the film's fixed-point sums: a sum `s` stands for `s / 2^64`.
pub const FIXED_FRACTION_BITS: u32 = 64;

/// `2^FIXED_FRACTION_BITS` as an f64 (a power of two, so scaling by it is exact).
const FIXED_ONE: f64 = 18_446_744_073_709_551_616.0;

/// A tile's f32 sum as a fixed-point integer: exact for `2^-41 <= |v| < 2^63` (an f32 has 24
/// significant bits); smaller magnitudes drop the bits below `2^-64` (towards zero), larger
/// ones saturate. One value always gives the same integer, so whatever is added from it later
/// is exact and independent of order.
pub(crate) fn to_fixed(v: f32) -> i128 {
    // From the bits: v = m 2^(e - 150) for a normal f32 (m with its implicit 24th bit), so
    // v 2^64 = m 2^(e - 86); subnormals have e = 1 without the implicit bit. A shift is
    // cheaper than the library's f64 -> i128 conversion, and gives the same integer
    // (truncation towards zero, saturation).
    let bits = v.to_bits();
    let e = ((bits >> 23) & 0xff) as i32;
    let frac = bits & 0x7f_ffff;
    if e == 0xff {
        // Infinities saturate; NaN (which the renderer drops before it gets here) is 0.
        return match (frac, bits >> 31) {
            (0, 0) => i128::MAX,
            (0, _) => i128::MIN,
            _ => 0,
        };
    }
    let (m, shift) = if e == 0 {
        (frac, 1 - 86)
    } else {
        (frac | 0x80_0000, e - 86)
    };
    let m = i128::from(m);
    let magnitude = match shift {
        s if s >= 104 => i128::MAX,
        s if s >= 0 => m << s,
        s if s > -24 => m >> -s,
        _ => 0,
    };
    if bits >> 31 == 0 {
        magnitude
    } else if magnitude == i128::MAX {
        i128::MIN
    } else {
        -magnitude
    }
}

/// A fixed-point sum as an f64 (rounded to nearest).
fn from_fixed(v: i128) -> f64 {
    v as f64 / FIXED_ONE
}

/// The running sums of one pixel, in fixed point with [`FIXED_FRACTION_BITS`] fractional bits.
///
/// Integers, so that additions are exact and associative: a film is the same bits whatever
/// order its tiles and passes are added in, which is what lets a render be split into slices
/// (of passes or tiles) on several machines and merged to the one-machine image bit for bit,
/// and a checkpoint be resumed exactly. The range is `+-2^63` (about 9.2e18) per sum; past it
/// additions saturate, so an absurdly bright pixel stays finite and bright. Saturating sums of
/// one sign are still associative; only sums that mix signs (negative filter lobes) and pass
/// the range may then depend on the order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PixelSums {
    /// Sum of weight times radiance.
    pub radiance: [i128; 3],
    /// Sum of weights.
    pub weight: i128,
    /// Sum of weights of samples whose camera ray hit geometry.
    pub coverage: i128,
}

impl PixelSums {
    fn add(&mut self, o: &PixelSums) {
        for c in 0..3 {
            self.radiance[c] = self.radiance[c].saturating_add(o.radiance[c]);
        }
        self.weight = self.weight.saturating_add(o.weight);
        self.coverage = self.coverage.saturating_add(o.coverage);
    }

    /// The pixel's value: weighted mean radiance and coverage, (0, 0, 0, 0) with no weight.
    pub fn resolve(&self) -> [f32; 4] {
        if self.weight == 0 {
            return [0.0; 4];
        }
        let inv = 1.0 / from_fixed(self.weight);
        [
            (from_fixed(self.radiance[0]) * inv) as f32,
            (from_fixed(self.radiance[1]) * inv) as f32,
            (from_fixed(self.radiance[2]) * inv) as f32,
            (from_fixed(self.coverage) * inv) as f32,
        ]
    }
}

/// A rectangle of pixels `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl PixelRect {
    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }
    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }
    /// Number of pixels.
    pub fn area(&self) -> u64 {
        u64::from(self.width()) * u64::from(self.height())
    }
}

/// The whole film's sums over its pixel bounds (the crop window).
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    bounds: PixelRect,
    sums: Vec<PixelSums>,
}

impl Film {
    /// A zeroed film covering `bounds`.
    pub fn new(bounds: PixelRect) -> Self {
        Self {
            bounds,
            sums: vec![PixelSums::default(); bounds.area() as usize],
        }
    }

    /// The pixels this film covers.
    pub fn bounds(&self) -> PixelRect {
        self.bounds
    }

    /// The sums, row by row over [`Film::bounds`].
    pub fn sums(&self) -> &[PixelSums] {
        &self.sums
    }

    /// A film from saved sums (a checkpoint); `None` if the count does not match.
    pub fn from_sums(bounds: PixelRect, sums: Vec<PixelSums>) -> Option<Self> {
        (sums.len() as u64 == bounds.area()).then_some(Self { bounds, sums })
    }

    /// Adds a tile's sums. Exact: the film is the same bits whatever order tiles come in.
    pub fn merge(&mut self, tile: &TileBuffer) {
        let t = tile.rect;
        let (width, film_width) = (t.width() as usize, self.bounds.width() as usize);
        if width == 0 {
            return;
        }
        // Row by row: one slice of each per row, no index arithmetic per pixel.
        let first =
            (t.y0 - self.bounds.y0) as usize * film_width + (t.x0 - self.bounds.x0) as usize;
        for (j, src_row) in tile.sums.chunks_exact(width).enumerate() {
            let start = first + j * film_width;
            for (d, src) in self.sums[start..start + width].iter_mut().zip(src_row) {
                let [r, g, b, w] = src.weighted.to_array().map(to_fixed);
                d.add(&PixelSums {
                    radiance: [r, g, b],
                    weight: w,
                    coverage: to_fixed(src.coverage),
                });
            }
        }
    }

    /// Adds `other`'s sums pixel by pixel (films of the same bounds). Exact, so films may be
    /// added in any order and grouping (passes, slices) to the same bits.
    pub fn add(&mut self, other: &Film) {
        debug_assert_eq!(self.bounds, other.bounds);
        self.sums
            .par_chunks_mut(4096)
            .zip(other.sums.par_chunks(4096))
            .for_each(|(a, b)| a.iter_mut().zip(b).for_each(|(a, b)| a.add(b)));
    }

    /// Adds `other`'s sums into this film and zeroes `other`, in one sweep over both (films of
    /// the same bounds): [`Film::add`] then [`Film::clear`] of `other`, with half the memory
    /// traffic.
    pub fn absorb(&mut self, other: &mut Film) {
        debug_assert_eq!(self.bounds, other.bounds);
        self.sums
            .par_chunks_mut(4096)
            .zip(other.sums.par_chunks_mut(4096))
            .for_each(|(a, b)| {
                a.iter_mut().zip(b).for_each(|(a, b)| {
                    a.add(b);
                    *b = PixelSums::default();
                })
            });
    }

    /// Sets every sum back to zero.
    pub fn clear(&mut self) {
        self.sums
            .par_chunks_mut(4096)
            .for_each(|a| a.fill(PixelSums::default()));
    }

    /// The image: RGBA per pixel, row 0 at the top.
    pub fn resolve(&self) -> Image {
        Image {
            width: self.bounds.width(),
            height: self.bounds.height(),
            pixels: self.sums.iter().map(PixelSums::resolve).collect(),
        }
    }
}

/// A finished image of linear RGBA floats, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` RGBA values.
    pub pixels: Vec<[f32; 4]>,
}

impl Image {
    /// The pixel at column `x`, row `y`.
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[(y * self.width + x) as usize]
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::scene::FilterSettings;
    use glam::{Vec2, Vec3};

    /// The film rectangle `[0, w) x [0, h)`.
    pub(crate) fn film_rect(w: u32, h: u32) -> PixelRect {
        PixelRect {
            x0: 0,
            y0: 0,
            x1: w,
            y1: h,
        }
    }

    #[test]
    fn pixel_value_is_the_weighted_mean_and_alpha_the_coverage() {
        // Two samples in pixel (0, 0) with the box filter: radiance 1 (hit) and 0 (miss).
        let filter = Filter::new(FilterSettings::Box { radius: 0.5 });
        let mut tile = TileBuffer::new(film_rect(1, 1), film_rect(1, 1), filter);
        tile.add_sample(Vec2::new(0.25, 0.25), Vec3::new(1.0, 2.0, 3.0), true);
        tile.add_sample(Vec2::new(0.75, 0.75), Vec3::ZERO, false);
        let mut film = Film::new(film_rect(1, 1));
        film.merge(&tile);
        assert_eq!(film.resolve().pixel(0, 0), [0.5, 1.0, 1.5, 0.5]);
    }
    #[test]
    fn fixed_point_values_are_exact_in_range_and_saturate_outside() {
        // Expected integers from the definition s = v * 2^64, worked by hand.
        assert_eq!(to_fixed(1.0), 1i128 << 64);
        assert_eq!(to_fixed(-0.5), -(1i128 << 63));
        assert_eq!(to_fixed(1.5 * 2f32.powi(-60)), 24);
        assert_eq!(to_fixed(2f32.powi(-64)), 1);
        // Below the quantum: dropped towards zero.
        assert_eq!(to_fixed(2f32.powi(-66)), 0);
        assert_eq!(to_fixed(-(2f32.powi(-66))), 0);
        assert_eq!(to_fixed(f32::MAX), i128::MAX);
        assert_eq!(to_fixed(f32::MIN), i128::MIN);
        assert_eq!(from_fixed(3i128 << 62), 0.75);
    }

    proptest::proptest! {
        /// The bit-level conversion gives the integer that exact arithmetic gives: f32 -> f64
        /// and the power-of-two scale are exact, and Rust's float -> int `as` truncates and
        /// saturates.
        #[test]
        fn to_fixed_equals_the_exact_product(bits in proptest::prelude::any::<u32>()) {
            let v = f32::from_bits(bits);
            let want = if v.is_nan() { 0 } else { (f64::from(v) * FIXED_ONE) as i128 };
            proptest::prop_assert_eq!(to_fixed(v), want, "{:e}", v);
        }
    }

    #[test]
    fn absorb_is_add_then_clear() {
        let mut a = pass_film(4, 3, &[(0.3, 0.6, 2.0, true), (0.9, 0.1, -1.0, false)]);
        let mut b = pass_film(4, 3, &[(0.5, 0.5, 7.0, true)]);
        let mut want = a.clone();
        want.add(&b);
        a.absorb(&mut b);
        assert_eq!(a, want);
        assert_eq!(b, Film::new(film_rect(4, 3)));
    }

    #[test]
    fn sums_past_the_range_saturate_in_any_order() {
        let big = PixelSums {
            radiance: [i128::MAX - 5, 7, i128::MIN + 1],
            weight: 1 << 64,
            coverage: 0,
        };
        let more = PixelSums {
            radiance: [10, 1, -3],
            weight: 1 << 64,
            coverage: 1,
        };
        let (mut a, mut b) = (big, more);
        a.add(&more);
        a.add(&more);
        b.add(&more);
        b.add(&big);
        assert_eq!(a, b);
        assert_eq!(a.radiance, [i128::MAX, 9, i128::MIN]);
        let [r, _, bl, _] = a.resolve();
        assert!(r > 1e18 && r.is_finite() && bl < -1e18 && bl.is_finite());
    }

    /// A pass of random samples over a `w x h` film with a Gaussian filter (margins overlap
    /// neighbouring tiles, as in a render), tiles of 2x2 pixels.
    fn pass_film(w: u32, h: u32, samples: &[(f32, f32, f32, bool)]) -> Film {
        let filter = Filter::new(FilterSettings::gaussian(1.5));
        let mut film = Film::new(film_rect(w, h));
        for (k, &(x, y, l, hit)) in samples.iter().enumerate() {
            let (x, y) = (x * w as f32, y * h as f32);
            let (tx, ty) = ((x as u32).min(w - 1) & !1, (y as u32).min(h - 1) & !1);
            let tile = PixelRect {
                x0: tx,
                y0: ty,
                x1: (tx + 2).min(w),
                y1: (ty + 2).min(h),
            };
            let mut buffer = TileBuffer::new(tile, film_rect(w, h), filter);
            let l = Vec3::new(l, l * 0.37 + k as f32, -l * 1e-9);
            buffer.add_sample(Vec2::new(x, y), l, hit);
            film.merge(&buffer);
        }
        film
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

        /// The property that slices rest on: cut the passes `[0, spp)` into contiguous ranges
        /// anywhere, sum each range's passes, add the ranges' films in any order: the same bits
        /// as the passes summed one after the other.
        #[test]
        fn any_split_of_the_passes_sums_to_the_same_bits(
            passes in proptest::collection::vec(
                proptest::collection::vec((0f32..1.0, 0f32..1.0, -1e4f32..1e4, proptest::bool::ANY), 0..6),
                1..12,
            ),
            cuts in proptest::collection::vec(0usize..12, 0..5),
            rotate in 0usize..8,
        ) {
            let (w, h) = (5, 4);
            let films: Vec<Film> = passes.iter().map(|p| pass_film(w, h, p)).collect();
            let mut whole = Film::new(film_rect(w, h));
            for f in &films {
                whole.add(f);
            }
            let mut bounds: Vec<usize> = cuts.into_iter().map(|c| c % (films.len() + 1)).collect();
            bounds.extend([0, films.len()]);
            bounds.sort_unstable();
            bounds.dedup();
            let mut slices: Vec<Film> = bounds
                .windows(2)
                .map(|r| {
                    let mut s = Film::new(film_rect(w, h));
                    films[r[0]..r[1]].iter().for_each(|f| s.add(f));
                    s
                })
                .collect();
            let n = slices.len();
            slices.rotate_left(rotate % n);
            let mut merged = Film::new(film_rect(w, h));
            for s in slices.iter().rev() {
                merged.add(s);
            }
            proptest::prop_assert_eq!(merged.sums(), whole.sums());
            proptest::prop_assert_eq!(merged.resolve(), whole.resolve());
        }
    }
}
