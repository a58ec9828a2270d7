//! Reconstruction filters: the profiles a sample is splatted with.

use crate::scene::FilterSettings;
use glam::{Vec2, Vec4};

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
        // Only the Gaussian reads these; the other filters keep a harmless sigma.
        let sigma = match settings {
            FilterSettings::Gaussian { sigma, .. } => sigma,
            _ => r / 3.0,
        };
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

    /// How many pixels beyond a tile's edge the tile's samples reach with a non-zero weight.
    ///
    /// A sample of pixel `i` lies in `[i, i + 1]` (the far edge when `i + offset` rounds up),
    /// and [`Filter::eval_1d`] is non-zero only closer than the radius `r` to a pixel's
    /// centre, or, for the box, at exactly `-r` (the centre on the side of larger
    /// coordinates). So a centre beyond the edge is reached if it is less than `r` (the box:
    /// at most `r`) from the edge: `ceil(r - 0.5)` pixels, `floor(r - 0.5) + 1` for the box.
    /// The default Gaussian (`r = 1.5`) reaches one, not `ceil(r) = 2`.
    pub fn margin(&self) -> u32 {
        let beyond = self.radius() - 0.5;
        let margin = match self.settings {
            FilterSettings::Box { .. } => beyond.floor() + 1.0,
            _ => beyond.ceil(),
        };
        margin.max(0.0) as u32
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
    pub(super) fn weights(&self, c: f32, first: u32, n: usize) -> [f32; SPAN] {
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
pub(super) const SPAN: usize = 8;

/// `e^x` in four lanes, for `x <= 0` (the Gaussian's exponents): within one ulp of the
/// correctly rounded value over a dense sweep of `[-87, 0]` (the tests allow two), `e^-87`
/// below that and 1 above 0. Four lanes of SSE arithmetic instead of four calls into libm's
/// `expf`.
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
                FilterSettings::gaussian(radius),
                FilterSettings::Mitchell { radius },
            ][kind];
            let filter = Filter::new(settings);
            let got = filter.eval_1d_x4(Vec4::from_array(d)).to_array();
            for lane in 0..4 {
                prop_assert_eq!(got[lane].to_bits(), filter.eval_1d(d[lane]).to_bits());
            }
        }

        /// The Gaussian is `e^(-d^2 / 2 sigma^2) - e^(-r^2 / 2 sigma^2)`, computed here in f64
        /// from the definition, for the default sigma = r / 3 and for sigmas from r / 5 to 2 r
        /// (Mitsuba 3's Gaussian is r = 4 sigma).
        #[test]
        fn gaussian_matches_its_definition(
            d in -3.0f32..3.0,
            radius in 0.5f32..3.0,
            per_radius in proptest::option::of(0.2f32..2.0),
        ) {
            let settings = match per_radius {
                None => FilterSettings::gaussian(radius),
                Some(k) => FilterSettings::Gaussian { radius, sigma: k * radius },
            };
            let filter = Filter::new(settings);
            let (d64, r64) = (f64::from(d), f64::from(radius));
            let sigma = r64 * per_radius.map_or(1.0 / 3.0, f64::from);
            let two_var = 2.0 * sigma * sigma;
            let want = if d64.abs() >= r64 {
                0.0
            } else {
                (-d64 * d64 / two_var).exp() - (-r64 * r64 / two_var).exp()
            };
            prop_assert!((f64::from(filter.eval_1d(d)) - want).abs() < 1e-6, "{d}: {want}");
        }
    }

    /// Mitsuba 3's default `gaussian` (stddev 0.5, radius 4 stddev = 2) worked by hand:
    /// `e^(-2 d^2) - e^(-8)`, so 1 - 0.000335 at 0, e^-2 - e^-8 = 0.135000 at 1 and
    /// e^-4.5 - e^-8 = 0.010774 at 1.5; pbrt-v4's default (radius 1.5, sigma 0.5) is
    /// e^-2 - e^-4.5 = 0.124226 at 1.
    #[test]
    fn gaussians_of_mitsuba_and_pbrt_by_hand() {
        let mitsuba = Filter::new(FilterSettings::Gaussian {
            radius: 2.0,
            sigma: 0.5,
        });
        for (d, want) in [(0.0, 0.999_665), (1.0, 0.135_000), (1.5, 0.010_774)] {
            assert!((mitsuba.eval_1d(d) - want).abs() < 2e-6, "{d}");
        }
        let pbrt = Filter::new(FilterSettings::gaussian(1.5));
        assert!((pbrt.eval_1d(1.0) - 0.124_226).abs() < 2e-6);
    }

    #[test]
    fn filters_fall_to_zero_at_their_radius_and_peak_at_the_centre() {
        for settings in [
            FilterSettings::Triangle { radius: 1.0 },
            FilterSettings::gaussian(1.5),
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
}
