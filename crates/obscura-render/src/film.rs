//! The film: reconstruction filters, per-tile accumulation and the final pixel values.
//!
//! Every sample is splatted into each pixel whose filter support holds it, with the filter's
//! weight. A pixel's value is the weighted mean of its samples' radiance (misses count as 0),
//! and its alpha the weighted fraction of samples whose camera ray hit geometry.
//!
//! Tiles accumulate into their own buffers (their pixels plus a margin as wide as the filter)
//! and are merged into the film in tile order, so the sums, and the image, are bit-identical
//! whatever the number of threads or the order tiles finish in.

use crate::scene::FilterSettings;
use glam::{Vec2, Vec3, Vec4};
use rayon::prelude::*;

/// A separable reconstruction filter `f(dx) f(dy)`, with `dx`, `dy` in pixels from the pixel's
/// centre.
#[derive(Clone, Copy, Debug)]
pub struct Filter {
    settings: FilterSettings,
    /// For the Gaussian: `exp(-r^2 / (2 sigma^2))`, subtracted so the filter reaches 0 at r.
    gaussian_floor: f32,
    /// For the Gaussian: `1 / (2 sigma^2)`.
    gaussian_rate: f32,
}

impl Filter {
    /// A filter from validated settings.
    pub fn new(settings: FilterSettings) -> Self {
        let r = settings.radius();
        let sigma = r / 3.0;
        Self {
            settings,
            gaussian_floor: (-(r * r) / (2.0 * sigma * sigma)).exp(),
            gaussian_rate: 1.0 / (2.0 * sigma * sigma),
        }
    }

    /// The radius of support in pixels.
    pub fn radius(&self) -> f32 {
        self.settings.radius()
    }

    /// The one-dimensional profile at offset `d` (zero outside the support).
    pub fn eval_1d(&self, d: f32) -> f32 {
        let r = self.radius();
        let a = d.abs();
        if a >= r {
            // The box includes -r but not +r, so that every point falls in exactly one pixel.
            return if matches!(self.settings, FilterSettings::Box { .. }) && d == -r {
                1.0
            } else {
                0.0
            };
        }
        match self.settings {
            FilterSettings::Box { .. } => 1.0,
            FilterSettings::Triangle { .. } => 1.0 - a / r,
            FilterSettings::Gaussian { .. } => self.gaussian(Vec4::splat(a)).x,
            FilterSettings::Mitchell { .. } => mitchell(2.0 * a / r),
        }
    }

    /// [`Filter::eval_1d`] at four offsets at once: lane `i` of the result is exactly
    /// `eval_1d(d[i])`. The Gaussian's four exponentials are one four-lane `exp4`.
    #[inline]
    pub fn eval_1d_x4(&self, d: Vec4) -> Vec4 {
        match self.settings {
            FilterSettings::Gaussian { .. } => {
                let a = d.abs();
                Vec4::select(
                    a.cmplt(Vec4::splat(self.radius())),
                    self.gaussian(a),
                    Vec4::ZERO,
                )
            }
            _ => Vec4::from_array(d.to_array().map(|d| self.eval_1d(d))),
        }
    }

    /// The Gaussian's profile at distances `a` inside the support.
    #[inline]
    fn gaussian(&self, a: Vec4) -> Vec4 {
        (exp4(-(a * a) * self.gaussian_rate) - Vec4::splat(self.gaussian_floor)).max(Vec4::ZERO)
    }

    /// The profile at the `n <= SPAN` offsets `c - (first + k + 0.5)`, `k = 0..n`, from a
    /// sample coordinate `c` to the centres of the pixels `first..first + n` (a splat's
    /// columns or rows); the lanes from `n` on are not to be read.
    #[inline]
    fn weights(&self, c: f32, first: u32, n: usize) -> [f32; SPAN] {
        const STEPS: [Vec4; 2] = [Vec4::new(0.5, 1.5, 2.5, 3.5), Vec4::new(4.5, 5.5, 6.5, 7.5)];
        let base = Vec4::splat(first as f32);
        let mut w = [0.0; SPAN];
        for (half, steps) in STEPS.iter().enumerate().take(n.div_ceil(4)) {
            let d = Vec4::splat(c) - (base + *steps);
            w[4 * half..4 * half + 4].copy_from_slice(&self.eval_1d_x4(d).to_array());
        }
        w
    }

    /// The weight of a sample at offset `d` from a pixel centre.
    pub fn eval(&self, d: Vec2) -> f32 {
        self.eval_1d(d.x) * self.eval_1d(d.y)
    }
}

/// The widest splat footprint, in pixels per axis, whose weights [`TileBuffer::add_sample`]
/// evaluates once per column and row (every filter at its default radius fits).
const SPAN: usize = 8;

/// `e^x` in four lanes, for `x <= 0` (the Gaussian's exponents): within one ulp of the
/// correctly rounded value over a dense sweep of `[-87, 0]` (the tests allow two), `e^-87`
/// below that and 1 above 0. Four lanes of SSE arithmetic instead of four calls into libm's
/// `expf`, which were a quarter of a splat's instructions.
///
/// Cody and Waite's reduction: `x = n ln 2 + r` with `n` the nearest integer to `x / ln 2`, so
/// `|r| <= ln 2 / 2`; `ln 2` is split into a high part with few enough bits that `n` times it
/// is exact and a low part for the rest. Then `e^r` is its Taylor series to `r^7` (the first
/// term left out is below `8e-9 e^r`, a tenth of an ulp), and `2^n` is built in the exponent
/// bits.
#[inline]
fn exp4(x: Vec4) -> Vec4 {
    /// `ln 2` to 9 bits (355 / 512), so that `n * LN2_HI` is exact for `|n| < 2^15`.
    const LN2_HI: f32 = 0.693_359_4;
    /// `ln 2 - LN2_HI`.
    const LN2_LO: f32 = -2.121_944_4e-4;
    /// 1.5 * 2^23: adding it rounds a float below 2^22 in magnitude to an integer, which
    /// then sits in the sum's low mantissa bits.
    const ROUND: f32 = 12_582_912.0;
    let x = x.clamp(Vec4::splat(-87.0), Vec4::ZERO);
    let k = x * core::f32::consts::LOG2_E + Vec4::splat(ROUND);
    let n = k - Vec4::splat(ROUND);
    let r = x - n * LN2_HI - n * LN2_LO;
    // 1 + r + r^2/2! + ... + r^7/7!, by Horner's rule.
    let mut p = Vec4::splat(1.0 / 5040.0);
    for c in [
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ] {
        p = p * r + Vec4::splat(c);
    }
    // n is in [-126, 0], so 2^n is the normal float with biased exponent n + 127; k's bits
    // are n plus a constant whose own bits all shift out past bit 31.
    let two_n = k
        .to_array()
        .map(|k| f32::from_bits(k.to_bits().wrapping_add(127) << 23));
    p * Vec4::from_array(two_n)
}

/// Mitchell-Netravali with B = C = 1/3 on x in [0, 2].
fn mitchell(x: f32) -> f32 {
    const B: f32 = 1.0 / 3.0;
    const C: f32 = 1.0 / 3.0;
    let x2 = x * x;
    let x3 = x2 * x;
    if x < 1.0 {
        ((12.0 - 9.0 * B - 6.0 * C) * x3 + (-18.0 + 12.0 * B + 6.0 * C) * x2 + (6.0 - 2.0 * B))
            / 6.0
    } else if x < 2.0 {
        ((-B - 6.0 * C) * x3
            + (6.0 * B + 30.0 * C) * x2
            + (-12.0 * B - 48.0 * C) * x
            + (8.0 * B + 24.0 * C))
            / 6.0
    } else {
        0.0
    }
}

/// The running sums of one pixel. f64, so that long renders and resumed renders add exactly.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelSums {
    /// Sum of weight times radiance.
    pub radiance: [f64; 3],
    /// Sum of weights.
    pub weight: f64,
    /// Sum of weights of samples whose camera ray hit geometry.
    pub coverage: f64,
}

impl PixelSums {
    fn add(&mut self, o: &PixelSums) {
        for c in 0..3 {
            self.radiance[c] += o.radiance[c];
        }
        self.weight += o.weight;
        self.coverage += o.coverage;
    }

    /// The pixel's value: weighted mean radiance and coverage, (0, 0, 0, 0) with no weight.
    pub fn resolve(&self) -> [f32; 4] {
        if self.weight == 0.0 {
            return [0.0; 4];
        }
        let inv = 1.0 / self.weight;
        [
            (self.radiance[0] * inv) as f32,
            (self.radiance[1] * inv) as f32,
            (self.radiance[2] * inv) as f32,
            (self.coverage * inv) as f32,
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

/// One tile's sums: the tile's pixels and a filter-wide margin, clipped to the film.
///
/// A tile holds one pass, so each of its pixels sums at most the few samples its filter
/// reaches (nine for the default Gaussian): f32 is exact enough there (relative error about
/// 1e-6), and it lets a splat be one four-lane multiply-add. The film sums passes in f64.
pub struct TileBuffer {
    rect: PixelRect,
    filter: Filter,
    sums: Vec<TileSums>,
}

/// A tile pixel's sums: `(w r, w g, w b, w)` and the weight of samples that hit geometry.
#[derive(Clone, Copy, Debug, Default)]
struct TileSums {
    weighted: Vec4,
    coverage: f32,
}

impl TileBuffer {
    /// A zeroed buffer for samples of the pixels in `tile`, on a film covering `film`.
    pub fn new(tile: PixelRect, film: PixelRect, filter: Filter) -> Self {
        let mut buffer = Self {
            rect: tile,
            filter,
            sums: Vec::new(),
        };
        buffer.reset(tile, film);
        buffer
    }

    /// Makes this buffer a zeroed one for `tile`, as [`TileBuffer::new`] would, keeping its
    /// memory (the renderer recycles buffers instead of allocating one per tile and pass).
    pub fn reset(&mut self, tile: PixelRect, film: PixelRect) {
        let m = self.filter.radius().ceil() as u32;
        self.rect = PixelRect {
            x0: tile.x0.saturating_sub(m).max(film.x0),
            y0: tile.y0.saturating_sub(m).max(film.y0),
            x1: (tile.x1 + m).min(film.x1),
            y1: (tile.y1 + m).min(film.y1),
        };
        self.sums.clear();
        self.sums
            .resize(self.rect.area() as usize, TileSums::default());
    }

    /// Adds a sample at raster position `p` with radiance `l` into every pixel the filter
    /// reaches. `hit` says whether its camera ray hit geometry. `l` must be finite (the
    /// renderer counts and drops other samples before they get here): a NaN would reach every
    /// pixel of the footprint, zero-weight ones included.
    pub fn add_sample(&mut self, p: Vec2, l: Vec3, hit: bool) {
        let r = self.filter.radius();
        // Pixels whose centre i + 0.5 lies in (p - r, p + r].
        let lo = (floor(p - Vec2::splat(r + 0.5)) + Vec2::ONE)
            .max(Vec2::new(self.rect.x0 as f32, self.rect.y0 as f32));
        let hi = floor(p + Vec2::splat(r - 0.5)).min(Vec2::new(
            self.rect.x1 as f32 - 1.0,
            self.rect.y1 as f32 - 1.0,
        ));
        if lo.x > hi.x || lo.y > hi.y {
            return;
        }
        let (l, coverage) = (l.extend(1.0), if hit { 1.0 } else { 0.0 });
        let (x0, x1) = (lo.x as u32, hi.x as u32);
        let (y0, y1) = (lo.y as u32, hi.y as u32);
        // The profile is separable: evaluate each column's and each row's weight once (for
        // footprints up to SPAN wide, which covers every filter at its default radius).
        let (nx, ny) = ((x1 - x0) as usize + 1, (y1 - y0) as usize + 1);
        if nx > SPAN || ny > SPAN {
            return self.add_sample_wide(p, l, coverage, [x0, x1], [y0, y1]);
        }
        let wx = self.filter.weights(p.x, x0, nx);
        let wy = self.filter.weights(p.y, y0, ny);
        let width = self.rect.width() as usize;
        let first = (y0 - self.rect.y0) as usize * width + (x0 - self.rect.x0) as usize;
        for (j, &w_row) in wy[..ny].iter().enumerate() {
            if w_row == 0.0 {
                continue;
            }
            let row = first + j * width;
            // No test for a zero weight: l is finite (the renderer drops other samples), so
            // such a pixel gains a signed zero, and sums that start at +0 keep their bits.
            for (s, &w_col) in self.sums[row..row + nx].iter_mut().zip(&wx) {
                let w = w_row * w_col;
                s.weighted += l * w;
                s.coverage += w * coverage;
            }
        }
    }

    /// [`TileBuffer::add_sample`] for footprints wider than its fixed weight arrays (filters
    /// given a large radius).
    fn add_sample_wide(&mut self, p: Vec2, l: Vec4, coverage: f32, xs: [u32; 2], ys: [u32; 2]) {
        for y in ys[0]..=ys[1] {
            let wy = self.filter.eval_1d(p.y - (y as f32 + 0.5));
            if wy == 0.0 {
                continue;
            }
            for x in xs[0]..=xs[1] {
                let w = wy * self.filter.eval_1d(p.x - (x as f32 + 0.5));
                if w == 0.0 {
                    continue;
                }
                let i = ((y - self.rect.y0) * self.rect.width() + (x - self.rect.x0)) as usize;
                let s = &mut self.sums[i];
                s.weighted += l * w;
                s.coverage += w * coverage;
            }
        }
    }
}

/// `v.floor()` per lane without a libm call (x86-64's baseline has no rounding instruction):
/// exact for `|x| < 2^31`, which raster positions are.
#[inline]
fn floor(v: Vec2) -> Vec2 {
    let f = |x: f32| {
        let t = x as i32 as f32;
        if t > x { t - 1.0 } else { t }
    };
    Vec2::new(f(v.x), f(v.y))
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

    /// Adds a tile's sums. Merge tiles in a fixed order for bit-identical results.
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
                let [r, g, b, w] = src.weighted.to_array().map(f64::from);
                d.radiance[0] += r;
                d.radiance[1] += g;
                d.radiance[2] += b;
                d.weight += w;
                d.coverage += f64::from(src.coverage);
            }
        }
    }

    /// Adds `other`'s sums pixel by pixel (films of the same bounds). Each pixel gets one
    /// addition, so the result does not depend on how the work is split between threads.
    pub fn add(&mut self, other: &Film) {
        debug_assert_eq!(self.bounds, other.bounds);
        self.sums
            .par_chunks_mut(4096)
            .zip(other.sums.par_chunks(4096))
            .for_each(|(a, b)| a.iter_mut().zip(b).for_each(|(a, b)| a.add(b)));
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
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// How many representable floats lie between `got` and the exactly rounded `e^x`.
    fn ulps_from_exp(got: f32, x: f32) -> u32 {
        let want = f64::from(x).exp() as f32;
        assert!(got > 0.0 && want > 0.0, "e^{x}: {got} against {want}");
        got.to_bits().abs_diff(want.to_bits())
    }

    #[test]
    fn exp4_is_within_two_ulp() {
        // A dense sweep of the whole domain, both ends, and the points where the reduction's
        // integer changes (odd multiples of ln 2 / 2).
        let mut worst = 0;
        let mut xs: Vec<f32> = (0..=400_000)
            .map(|i| -87.0 * i as f32 / 400_000.0)
            .collect();
        xs.extend((0..125).map(|k| -(k as f32 + 0.5) * core::f32::consts::LN_2));
        xs.extend([0.0, -0.0, -f32::MIN_POSITIVE, -1e-30, -87.0]);
        for chunk in xs.chunks(4) {
            let mut lanes = [0.0; 4];
            lanes[..chunk.len()].copy_from_slice(chunk);
            let got = exp4(Vec4::from_array(lanes)).to_array();
            for (&x, &e) in chunk.iter().zip(&got) {
                worst = worst.max(ulps_from_exp(e, x));
            }
        }
        assert!(worst <= 2, "{worst} ulp");
        // Below the domain it flushes to e^-87, above it to 1.
        let edges = exp4(Vec4::new(-100.0, -1e30, 1.0, 0.0)).to_array();
        assert_eq!(edges[0], edges[1]);
        assert!(ulps_from_exp(edges[0], -87.0) <= 2);
        assert_eq!([edges[2], edges[3]], [1.0, 1.0]);
    }

    proptest! {
        #[test]
        fn exp4_is_within_two_ulp_anywhere_in_its_domain(
            x in proptest::array::uniform4(-87.0f32..=0.0),
        ) {
            let got = exp4(Vec4::from_array(x)).to_array();
            for lane in 0..4 {
                prop_assert!(ulps_from_exp(got[lane], x[lane]) <= 2, "e^{}", x[lane]);
            }
        }

        /// The four-lane profile is the one-lane profile, bit for bit, for every filter.
        #[test]
        fn eval_1d_x4_is_eval_1d_lane_by_lane(
            d in proptest::array::uniform4(-6.0f32..6.0),
            kind in 0usize..4,
            radius in 0.5f32..3.0,
        ) {
            let settings = [
                FilterSettings::Box { radius },
                FilterSettings::Triangle { radius },
                FilterSettings::Gaussian { radius },
                FilterSettings::Mitchell { radius },
            ][kind];
            let filter = Filter::new(settings);
            let got = filter.eval_1d_x4(Vec4::from_array(d)).to_array();
            for lane in 0..4 {
                prop_assert_eq!(got[lane].to_bits(), filter.eval_1d(d[lane]).to_bits());
            }
        }

        /// The Gaussian is `e^(-d^2 / 2 sigma^2) - e^(-r^2 / 2 sigma^2)` with sigma = r / 3,
        /// computed here in f64 from the definition.
        #[test]
        fn gaussian_matches_its_definition(d in -2.0f32..2.0, radius in 0.5f32..3.0) {
            let filter = Filter::new(FilterSettings::Gaussian { radius });
            let (d64, r64) = (f64::from(d), f64::from(radius));
            let two_var = 2.0 * (r64 / 3.0).powi(2);
            let want = if d64.abs() >= r64 {
                0.0
            } else {
                (-d64 * d64 / two_var).exp() - (-r64 * r64 / two_var).exp()
            };
            prop_assert!((f64::from(filter.eval_1d(d)) - want).abs() < 1e-6, "{d}: {want}");
        }
    }

    fn film_rect(w: u32, h: u32) -> PixelRect {
        PixelRect {
            x0: 0,
            y0: 0,
            x1: w,
            y1: h,
        }
    }

    #[test]
    fn box_filter_puts_each_sample_in_exactly_one_pixel() {
        let filter = Filter::new(FilterSettings::Box { radius: 0.5 });
        let mut tile = TileBuffer::new(film_rect(4, 4), film_rect(4, 4), filter);
        // On the boundary between pixels 1 and 2 (x = 2.0): it belongs to pixel 2 only.
        tile.add_sample(Vec2::new(2.0, 1.5), Vec3::ONE, true);
        let mut film = Film::new(film_rect(4, 4));
        film.merge(&tile);
        let touched: Vec<(usize, f64)> = film
            .sums()
            .iter()
            .enumerate()
            .filter(|(_, s)| s.weight > 0.0)
            .map(|(i, s)| (i, s.weight))
            .collect();
        assert_eq!(touched, vec![(4 + 2, 1.0)]);
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
    fn filters_fall_to_zero_at_their_radius_and_peak_at_the_centre() {
        for settings in [
            FilterSettings::Triangle { radius: 1.0 },
            FilterSettings::Gaussian { radius: 1.5 },
            FilterSettings::Mitchell { radius: 2.0 },
        ] {
            let f = Filter::new(settings);
            let r = f.radius();
            assert_eq!(f.eval_1d(r), 0.0, "{settings:?}");
            assert!(f.eval_1d(r * 0.999).abs() < 1e-3, "{settings:?}");
            assert!(f.eval_1d(0.0) > f.eval_1d(r * 0.3), "{settings:?}");
        }
        // Triangle at half its radius: 1 - 0.5 = 0.5. Mitchell at 0: (6 - 2/3) / 6 = 8/9.
        assert_eq!(
            Filter::new(FilterSettings::Triangle { radius: 1.0 }).eval_1d(0.5),
            0.5
        );
        assert!(
            (Filter::new(FilterSettings::Mitchell { radius: 2.0 }).eval_1d(0.0) - 8.0 / 9.0).abs()
                < 1e-6
        );
    }

    #[test]
    fn wide_filters_reach_neighbouring_tiles_through_the_margin() {
        let filter = Filter::new(FilterSettings::Gaussian { radius: 1.5 });
        let film_r = film_rect(8, 8);
        let mut tile = TileBuffer::new(
            PixelRect {
                x0: 4,
                y0: 4,
                x1: 8,
                y1: 8,
            },
            film_r,
            filter,
        );
        tile.add_sample(Vec2::new(4.1, 4.1), Vec3::ONE, true);
        let mut film = Film::new(film_r);
        film.merge(&tile);
        // Pixel (3, 3), centre (3.5, 3.5), is 0.6 away on each axis: inside the radius.
        assert!(film.sums()[3 * 8 + 3].weight > 0.0);
        // Pixel (2, 2), centre (2.5, 2.5), is 1.6 away: outside.
        assert_eq!(film.sums()[2 * 8 + 2].weight, 0.0);
    }

    #[test]
    fn floor_matches_the_library_floor() {
        for x in [
            -3.0f32,
            -2.5,
            -1.0,
            -0.75,
            -0.0,
            0.0,
            0.25,
            1.0,
            1.999_999,
            2.0,
            1e6 + 0.5,
        ] {
            let got = floor(Vec2::new(x, -x));
            assert_eq!(got, Vec2::new(x.floor(), (-x).floor()), "{x}");
        }
    }

    /// Every pixel gets exactly the separable weight `f(dx) f(dy)` of the sample, for a
    /// footprint within the fixed weight arrays and for one wider than them.
    #[test]
    fn splat_weights_are_the_filter_product_narrow_and_wide() {
        for settings in [
            FilterSettings::Gaussian { radius: 1.5 },
            FilterSettings::Triangle { radius: 5.3 },
        ] {
            let filter = Filter::new(settings);
            let film_r = film_rect(24, 24);
            let mut tile = TileBuffer::new(film_r, film_r, filter);
            let p = Vec2::new(11.3, 12.8);
            tile.add_sample(p, Vec3::new(2.0, 0.0, 0.0), true);
            let mut film = Film::new(film_r);
            film.merge(&tile);
            let mut touched = 0;
            for y in 0..24u32 {
                for x in 0..24u32 {
                    let want = filter.eval_1d(p.x - (x as f32 + 0.5))
                        * filter.eval_1d(p.y - (y as f32 + 0.5));
                    let s = film.sums()[(y * 24 + x) as usize];
                    assert_eq!(s.weight, f64::from(want), "{settings:?} at ({x}, {y})");
                    assert_eq!(s.radiance[0], f64::from(want * 2.0));
                    touched += usize::from(want != 0.0);
                }
            }
            assert!(touched >= 9, "{settings:?}: {touched} pixels");
        }
    }
}
