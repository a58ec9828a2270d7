//! A short, branch-light sine and cosine for the per-ray warps and cameras, where libm's
//! general `sin`/`cos` (a call, a range reduction for any argument, branches) costs more than
//! the rest of the ray.
//!
//! Arguments are in half-turns (`x` stands for the angle `pi x`), as in C's `sinpi`: angles in
//! the samplers and cameras are rational fractions of `pi` (a quarter of the disk, a row of
//! the image), so they are formed without multiplying by a rounded `pi`, and the reduction to
//! `[-1/4, 1/4]` is exact.

use core::ops::{Add, Mul, Sub};

use glam::{BVec4A, Vec4};

/// `sin(pi r) = 4 r - r (D0 - r^2 P(r^2))` on `|r| <= 1/4`, `D0 = 4 - pi` and `P` below: a
/// near-minimax fit of `sin(pi r) / r` by a cubic in `r^2` (Lawson's iteratively reweighted
/// least squares on 4000 Chebyshev-spaced points in f64), maximum error 9.7e-9 before rounding
/// to f32, i.e. a relative error of 3.1e-9 in the sine; the fitted constant term 3.14159264 is
/// kept as `4 - D0` because `4 r` is exact and `r D0` small, which halves the rounding error of
/// the leading term (2.1 ulp worst case as `r (pi + ...)`, 1.2 ulp this way). Taylor, for
/// comparison: `-pi^3/3!, pi^5/5!, -pi^7/7!` = -5.16771, 2.55016, -0.59926; the fit trades the
/// degree-9 term for these small changes.
const SIN_D0: f32 = 0.858_407_4;
/// The rest of the sine's fit: the coefficients of `r^3, r^5, r^7` in `sin(pi r)`.
const SIN_P: [f32; 3] = [-5.167_708, 2.549_767_3, -0.589_078_6];

/// `cos(pi r) = 1 + r^2 Q(r^2)` on `|r| <= 1/4`: fitted as [`SIN_P`] (by a quartic), maximum
/// absolute error
/// 5.4e-11 before rounding to f32 (Taylor: -pi^2/2!, pi^4/4!, -pi^6/6!, pi^8/8! = -4.93480,
/// 4.05871, -1.33526, 0.23533).
const COS_Q: [f32; 4] = [-4.934_802, 4.058_708, -1.335_058_5, 0.231_429_55];

/// `1.5 * 2^23`: adding and subtracting it rounds an f32 of magnitude at most `2^22` to the
/// nearest integer, ties to even (the sum lies in `[2^23, 2^24)`, where the spacing of f32 is
/// 1), without the libm call `f32::round` is on targets without SSE4.1, and lane-wise.
const ROUNDING_MAGIC: f32 = 12_582_912.0;

/// Numbers the kernel and the reduction run on: `f32`, and glam's [`Vec4`] (four lanes at once,
/// SSE2 on x86-64) for callers with several angles per sample. The same sequence of IEEE
/// operations runs on each lane, so a lane of the `Vec4` version equals the `f32` version bit
/// for bit.
pub(crate) trait Lanes:
    Copy
    + Add<Self, Output = Self>
    + Sub<Self, Output = Self>
    + Mul<Self, Output = Self>
    + Add<f32, Output = Self>
    + Sub<f32, Output = Self>
    + Mul<f32, Output = Self>
{
    /// A per-lane truth value.
    type Mask: Copy;
    /// `x` in every lane.
    fn splat(x: f32) -> Self;
    /// Per-lane `|self|`.
    fn abs(self) -> Self;
    /// Per-lane `self > bound`.
    fn greater_than(self, bound: f32) -> Self::Mask;
    /// Per lane, `if_true` where the mask holds, else `if_false`.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
    /// Per lane, the magnitude of `self` with the sign of `sign`.
    fn copysign(self, sign: Self) -> Self;
}

impl Lanes for f32 {
    type Mask = bool;
    #[inline(always)]
    fn splat(x: f32) -> f32 {
        x
    }
    #[inline(always)]
    fn abs(self) -> f32 {
        f32::abs(self)
    }
    #[inline(always)]
    fn greater_than(self, bound: f32) -> bool {
        self > bound
    }
    #[inline(always)]
    fn select(mask: bool, if_true: f32, if_false: f32) -> f32 {
        if mask { if_true } else { if_false }
    }
    #[inline(always)]
    fn copysign(self, sign: f32) -> f32 {
        f32::copysign(self, sign)
    }
}

impl Lanes for Vec4 {
    type Mask = BVec4A;
    #[inline(always)]
    fn splat(x: f32) -> Vec4 {
        Vec4::splat(x)
    }
    #[inline(always)]
    fn abs(self) -> Vec4 {
        Vec4::abs(self)
    }
    #[inline(always)]
    fn greater_than(self, bound: f32) -> BVec4A {
        self.cmpgt(Vec4::splat(bound))
    }
    #[inline(always)]
    fn select(mask: BVec4A, if_true: Vec4, if_false: Vec4) -> Vec4 {
        Vec4::select(mask, if_true, if_false)
    }
    #[inline(always)]
    fn copysign(self, sign: Vec4) -> Vec4 {
        Vec4::copysign(self, sign)
    }
}

/// `(sin(pi r), cos(pi r))` for `|r| <= 1/4` (the kernel; no reduction).
#[inline(always)]
pub(crate) fn sin_cos_pi_kernel<T: Lanes>(r: T) -> (T, T) {
    let z = r * r;
    // sin = 4 r - r (D0 - p) = 4 r + r (p - D0); the negation is exact, so either form
    // rounds the same.
    let p = ((z * SIN_P[2] + SIN_P[1]) * z + SIN_P[0]) * z;
    let sin = r * 4.0 + r * (p - SIN_D0);
    let cos = ((((z * COS_Q[3] + COS_Q[2]) * z + COS_Q[1]) * z + COS_Q[0]) * z) + 1.0;
    (sin, cos)
}

/// `(sin(pi x), cos(pi x))`: the sine and cosine of the angle `x` in half-turns, for any
/// finite `x` (non-finite `x` gives NaN for both).
///
/// Accuracy (tested against f64 on a dense grid of `[-4, 4]` and at the quadrant ends):
/// absolute error at most `7.5e-8` in each of the sine and the cosine (about 1.2 ulp of values
/// in `[1/2, 1)`; libm's `sinf` is within 0.5 ulp), a relative error below `2^-22` (2 ulp) for
/// small sines, and `sin^2 + cos^2` within `2e-7` of 1.
/// The multiples of one half are exact: `sin_cos_pi(1.0) == (0.0, -1.0)`,
/// `sin_cos_pi(0.5) == (1.0, 0.0)` (up to the sign of zero). Odd and even: `sin_cos_pi(-x)`
/// is `(-sin, cos)` of `sin_cos_pi(x)`, exactly.
///
/// How, without branches or libm: `n`, the integer nearest `x`, is found by the
/// add-and-subtract rounding trick; `y = x - n` is then exact (Sterbenz) and in `[-1/2, 1/2]`;
/// where `|y| > 1/4` the complement `1/2 - |y|` (exact too) goes to the polynomials instead and
/// the sine and cosine swap; the sign of `y` gives the sine's sign and the parity of `n` flips
/// both. Arguments beyond `2^21` (where f32 spacing is already 1/4) are first reduced exactly
/// modulo 2 on a slow path. [`sin_cos_pi_vec4`] does four angles at once.
///
/// ```
/// use obscura_sample::sin_cos_pi;
///
/// let (sin, cos) = sin_cos_pi(1.0 / 6.0); // 30 degrees
/// assert!((sin - 0.5).abs() < 1e-7 && (cos - 0.75f32.sqrt()).abs() < 1e-7);
/// assert_eq!(sin_cos_pi(-0.5), (-1.0, 0.0));
/// ```
#[inline]
pub fn sin_cos_pi(x: f32) -> (f32, f32) {
    // False for NaN too, which then takes the slow path.
    let in_fast_range = x.abs() <= FAST_RANGE;
    if in_fast_range {
        sin_cos_pi_reduced(x)
    } else {
        sin_cos_pi_slow(x)
    }
}

/// [`sin_cos_pi`] of each lane: `(sin(pi x), cos(pi x))` lane by lane, each lane bit for bit
/// what [`sin_cos_pi`] gives, at about the cost of one scalar call for all four on x86-64.
///
/// ```
/// use glam::Vec4;
/// use obscura_sample::{sin_cos_pi, sin_cos_pi_vec4};
///
/// let x = Vec4::new(0.1, -0.7, 1.25, 3.0);
/// let (sin, cos) = sin_cos_pi_vec4(x);
/// assert_eq!((sin.z, cos.z), sin_cos_pi(1.25));
/// ```
#[inline]
pub fn sin_cos_pi_vec4(x: Vec4) -> (Vec4, Vec4) {
    // All lanes in range (false for NaN too).
    if x.abs().cmple(Vec4::splat(FAST_RANGE)).all() {
        sin_cos_pi_reduced(x)
    } else {
        sin_cos_pi_vec4_slow(x)
    }
}

/// The largest argument of the fast path, `2^21`: `x + MAGIC` must round to an integer.
const FAST_RANGE: f32 = 2_097_152.0;

/// [`sin_cos_pi`] for `|x| <= 2^21`, on any [`Lanes`].
#[inline(always)]
fn sin_cos_pi_reduced<T: Lanes>(x: T) -> (T, T) {
    // The nearest integer n and the exact remainder y in [-1/2, 1/2].
    let n = (x + ROUNDING_MAGIC) - ROUNDING_MAGIC;
    let y = x - n;
    // Fold |y| into [0, 1/4]: past a quarter turn, sin(pi a) = cos(pi (1/2 - a)) and back.
    let a = y.abs();
    let swap = a.greater_than(0.25);
    let r = T::select(swap, T::splat(0.5) - a, a);
    let (sin_r, cos_r) = sin_cos_pi_kernel(r);
    let sin_abs = T::select(swap, cos_r, sin_r);
    let cos = T::select(swap, sin_r, cos_r);
    // The sine is odd in y; an odd n adds a half turn, which negates both. The parity: half of
    // n (exact) minus its rounding is 0 for even n and +-1/2 for odd n, so `parity_sign` is
    // exactly 1 or -1.
    let half_n = n * 0.5;
    let half_n_rounded = (half_n + ROUNDING_MAGIC) - ROUNDING_MAGIC;
    let parity_sign = T::splat(1.0) - (half_n - half_n_rounded).abs() * 4.0;
    (sin_abs.copysign(y) * parity_sign, cos * parity_sign)
}

/// [`sin_cos_pi`] beyond `2^21` and for non-finite arguments: out of line, off the hot path.
#[cold]
#[inline(never)]
fn sin_cos_pi_slow(x: f32) -> (f32, f32) {
    if x.is_finite() {
        // Exact: the remainder of f32 division is representable, and below 2 in magnitude.
        sin_cos_pi_reduced(x % 2.0)
    } else {
        (f32::NAN, f32::NAN)
    }
}

/// [`sin_cos_pi_vec4`] when a lane is beyond `2^21` or not finite: lane by lane.
#[cold]
#[inline(never)]
fn sin_cos_pi_vec4_slow(x: Vec4) -> (Vec4, Vec4) {
    let lanes = x.to_array().map(sin_cos_pi);
    (
        Vec4::from_array(lanes.map(|(sin, _)| sin)),
        Vec4::from_array(lanes.map(|(_, cos)| cos)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The largest absolute errors of the sine, the cosine and `sin^2 + cos^2 - 1` over `xs`,
    /// against f64's sine and cosine of `pi x` (x is exact in f64, `pi x` carries a relative
    /// error of 1e-16, far below what is measured).
    fn max_errors(xs: impl Iterator<Item = f32>) -> (f64, f64, f64) {
        let mut worst = (0.0f64, 0.0f64, 0.0f64);
        for x in xs {
            let (sin, cos) = sin_cos_pi(x);
            let (sin_64, cos_64) = (PI * f64::from(x)).sin_cos();
            let (sin, cos) = (f64::from(sin), f64::from(cos));
            worst.0 = worst.0.max((sin - sin_64).abs());
            worst.1 = worst.1.max((cos - cos_64).abs());
            worst.2 = worst.2.max((sin * sin + cos * cos - 1.0).abs());
        }
        worst
    }

    #[test]
    fn dense_grid_error_bound() {
        // 2^22 + 1 points over [-4, 4]: two full turns each way, every quadrant many times.
        let n = 1 << 22;
        let grid = (0..=n).map(|i| -4.0 + 8.0 * (i as f32 / n as f32));
        let (sin, cos, norm) = max_errors(grid);
        assert!(sin <= 7.5e-8, "sine error {sin:e}");
        assert!(cos <= 7.5e-8, "cosine error {cos:e}");
        assert!(norm <= 2e-7, "sin^2 + cos^2 - 1 = {norm:e}");
    }

    #[test]
    fn kernel_range_ends_and_neighbours() {
        // The ends of the kernel's range, +-1/4 (45 degrees), and the f32 numbers around each
        // multiple of 1/4 up to two turns, where the reduction switches quadrant.
        let mut xs = Vec::new();
        for quarter in -8..=8 {
            let x = quarter as f32 * 0.25;
            let mut below = x;
            let mut above = x;
            for _ in 0..64 {
                xs.extend([below, above]);
                below = below.next_down();
                above = above.next_up();
            }
        }
        let (sin, cos, norm) = max_errors(xs.into_iter());
        assert!(sin <= 7.5e-8 && cos <= 7.5e-8, "{sin:e} {cos:e}");
        assert!(norm <= 2e-7, "{norm:e}");
    }

    #[test]
    fn small_sines_have_a_small_relative_error() {
        // Near a zero of the sine the absolute bound says little: check the relative error
        // on a geometric grid from 1e-30 to 1e-2 half-turns, around 0 and around 1.
        let mut x = 1e-30f32;
        while x < 1e-2 {
            for at in [x, -x, 1.0 - x, 1.0 + x] {
                let (sin, _) = sin_cos_pi(at);
                // sin(pi a) = (-1)^n sin(pi (a - n)) with n the integer nearest a; the
                // difference a - n is exact in f64.
                let n = f64::from(at.round());
                let exact = (PI * (f64::from(at) - n)).sin() * if n == 0.0 { 1.0 } else { -1.0 };
                if exact == 0.0 {
                    assert_eq!(sin, 0.0, "sin(pi {at})");
                    continue;
                }
                let relative = (f64::from(sin) - exact).abs() / exact.abs();
                assert!(
                    relative <= 2f64.powi(-22),
                    "sin(pi {at}) = {sin}, want {exact}"
                );
            }
            x *= 1.37;
        }
    }

    #[test]
    fn vec4_lanes_equal_the_scalar_bit_for_bit_and_the_sine_is_odd() {
        // A grid over [-3, 3] that is not aligned with the quarters, four lanes at a time,
        // one lane out of the fast range half of the time (then the whole vector takes the
        // slow path, which must agree too).
        for i in 0..100_000 {
            let x0 = -3.0 + 6.0 * (i as f32 / 100_000.0) + 1e-5;
            let far = if i % 2 == 0 { 1.0e7 + x0 } else { x0 * 0.5 };
            let x = Vec4::new(x0, -x0, 0.25 * x0, far);
            let (sin, cos) = sin_cos_pi_vec4(x);
            for lane in 0..4 {
                let (s, c) = sin_cos_pi(x[lane]);
                assert_eq!(sin[lane].to_bits(), s.to_bits(), "sin, lane {lane} of {x}");
                assert_eq!(cos[lane].to_bits(), c.to_bits(), "cos, lane {lane} of {x}");
            }
            // Odd and even, exactly: the reduction works on |y| and copies the sign back.
            assert_eq!((sin.y, cos.y), (-sin.x, cos.x), "{x0}");
        }
    }

    #[test]
    fn multiples_of_a_half_are_exact() {
        // sin(pi k/2), cos(pi k/2) for k = -4..4: the kernel at r = 0 gives (0, 1) exactly,
        // and the quadrant rotation only swaps and negates.
        let expected = [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0)];
        for k in -4i32..=4 {
            let (sin, cos) = sin_cos_pi(0.5 * k as f32);
            // `==` on f32 ignores the sign of zero.
            assert_eq!((sin, cos), expected[k.rem_euclid(4) as usize], "k = {k}");
        }
    }

    #[test]
    fn hand_values() {
        // 30 degrees = 1/6 half-turn: (1/2, sqrt(3)/2); 45 degrees = 1/4: (sqrt(1/2), sqrt(1/2));
        // 135 degrees = 3/4: (sqrt(1/2), -sqrt(1/2)); -60 degrees = -1/3: (-sqrt(3)/2, 1/2).
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let s3 = 0.75f32.sqrt();
        for (x, s, c) in [
            (1.0 / 6.0, 0.5, s3),
            (0.25, h, h),
            (0.75, h, -h),
            (-1.0 / 3.0, -s3, 0.5),
        ] {
            let (sin, cos) = sin_cos_pi(x);
            assert!((sin - s).abs() <= 7.5e-8, "sin(pi {x}) = {sin}, want {s}");
            assert!((cos - c).abs() <= 7.5e-8, "cos(pi {x}) = {cos}, want {c}");
        }
    }

    #[test]
    fn large_and_non_finite_arguments() {
        // Beyond 2^21 the slow path reduces modulo 2 exactly: 2^21 + 0.25 is a quarter turn
        // past an even number of half-turns (2^21 = 2 * 2^20), so (sqrt(1/2), sqrt(1/2)).
        let h = std::f32::consts::FRAC_1_SQRT_2;
        // (Spacing of f32 at 2^21 is 1/4, so the sum is exact.)
        let (sin, cos) = sin_cos_pi(2_097_152.0 + 0.25);
        assert!((sin - h).abs() <= 7.5e-8 && (cos - h).abs() <= 7.5e-8);
        // 3 * 2^22 + 1 is odd: (0, -1). f32::MAX is even: (0, 1).
        assert_eq!(sin_cos_pi(12_582_913.0).1, -1.0);
        assert_eq!(sin_cos_pi(f32::MAX).1, 1.0);
        assert_eq!(sin_cos_pi(-f32::MAX).1, 1.0);
        for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let (sin, cos) = sin_cos_pi(x);
            assert!(sin.is_nan() && cos.is_nan(), "{x}");
            // One bad lane does not spoil the others.
            let (sin, cos) = sin_cos_pi_vec4(Vec4::new(0.5, x, 0.0, 1.0));
            assert!(sin.y.is_nan() && cos.y.is_nan(), "{x}");
            assert_eq!(
                (sin.x, cos.x, sin.z, cos.z, cos.w),
                (1.0, 0.0, 0.0, 1.0, -1.0)
            );
        }
    }
}
