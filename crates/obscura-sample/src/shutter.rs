//! The shutter: how a canonical time sample becomes a time in the shutter interval.

use crate::error::SampleError;
use crate::hash::ONE_MINUS_EPSILON;

/// How open the shutter is over the normalised interval `[0, 1)`, as a density of time.
///
/// A real shutter does not open instantly. [`ShutterCurve::Trapezoid`] opens linearly over
/// the first `ramp` of the interval, stays open, and closes linearly over the last `ramp`, so
/// motion blur fades in and out instead of ending in hard edges. Use it either as a warp
/// ([`ShutterCurve::sample`]: times are drawn with density [`ShutterCurve::pdf`], every
/// sample weighs one) or as a weight (draw times uniformly and weight each sample by
/// `pdf(t)`); the two have the same mean. [`shutter_time`] then maps the normalised time into
/// the scene's `shutter = [open, close]`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ShutterCurve {
    /// Open all at once for the whole interval: uniform times.
    #[default]
    Box,
    /// Opening linearly over the first `ramp` of the interval and closing linearly over the
    /// last `ramp`. Valid ramps are in `[0, 0.5]` (0 is the box, 0.5 a triangle); build with
    /// [`ShutterCurve::trapezoid`] to have them checked. The methods read a NaN ramp as 0 and
    /// clamp others into `[0, 0.5]`.
    Trapezoid {
        /// Fraction of the interval spent opening (and again closing), in `[0, 0.5]`.
        ramp: f32,
    },
}

impl ShutterCurve {
    /// A trapezoidal curve, or an error if `ramp` is not a finite number in `[0, 0.5]`.
    pub fn trapezoid(ramp: f32) -> Result<ShutterCurve, SampleError> {
        if ramp.is_finite() && (0.0..=0.5).contains(&ramp) {
            Ok(ShutterCurve::Trapezoid { ramp })
        } else {
            Err(SampleError::InvalidShutterRamp { ramp })
        }
    }

    /// The ramp as used by the methods: NaN reads as 0, the rest clamps into `[0, 0.5]`.
    #[inline]
    fn ramp(&self) -> f32 {
        match *self {
            ShutterCurve::Box => 0.0,
            ShutterCurve::Trapezoid { ramp } if ramp.is_nan() => 0.0,
            ShutterCurve::Trapezoid { ramp } => ramp.clamp(0.0, 0.5),
        }
    }

    /// Warps a canonical `u` in `[0, 1)` to a normalised time in `[0, 1)` with density
    /// [`ShutterCurve::pdf`] (the inverse of the curve's distribution function).
    #[inline]
    pub fn sample(&self, u: f32) -> f32 {
        let ramp = self.ramp();
        let u = u.clamp(0.0, ONE_MINUS_EPSILON);
        if ramp == 0.0 {
            return u;
        }
        // The trapezoid's area is 1 - ramp (two triangles of area ramp/2 and a plateau
        // 1 - 2 ramp); v is u measured in that area.
        let area = 1.0 - ramp;
        let v = u * area;
        let t = if v <= 0.5 * ramp {
            // Opening ramp: area t^2 / (2 ramp) = v.
            (2.0 * ramp * v).sqrt()
        } else if v <= 1.0 - 1.5 * ramp {
            // Plateau: area ramp/2 + (t - ramp) = v.
            v + 0.5 * ramp
        } else {
            // Closing ramp: remaining area (1 - t)^2 / (2 ramp) = area - v.
            1.0 - (2.0 * ramp * (area - v).max(0.0)).sqrt()
        };
        t.clamp(0.0, ONE_MINUS_EPSILON)
    }

    /// The density of [`ShutterCurve::sample`] at normalised time `t`; zero outside `[0, 1]`.
    /// It integrates to one over `[0, 1]`.
    #[inline]
    pub fn pdf(&self, t: f32) -> f32 {
        if !(0.0..=1.0).contains(&t) {
            return 0.0;
        }
        let ramp = self.ramp();
        if ramp == 0.0 {
            return 1.0;
        }
        // Openness: t / ramp rising, 1 on the plateau, (1 - t) / ramp falling.
        let openness = (t / ramp).min((1.0 - t) / ramp).min(1.0);
        openness / (1.0 - ramp)
    }

    /// The distribution function: the `u` that [`ShutterCurve::sample`] maps to `t`.
    #[inline]
    pub fn invert(&self, t: f32) -> f32 {
        let ramp = self.ramp();
        let t = t.clamp(0.0, 1.0);
        let u = if ramp == 0.0 {
            t
        } else {
            let area = 1.0 - ramp;
            let v = if t <= ramp {
                t * t / (2.0 * ramp)
            } else if t <= 1.0 - ramp {
                0.5 * ramp + (t - ramp)
            } else {
                area - (1.0 - t) * (1.0 - t) / (2.0 * ramp)
            };
            v / area
        };
        u.clamp(0.0, ONE_MINUS_EPSILON)
    }
}

/// Maps a normalised time `u` in `[0, 1)` into the shutter interval `[open, close]` of the
/// scene format: `open + u * (close - open)`.
#[inline]
pub fn shutter_time(u: f32, shutter: [f32; 2]) -> f32 {
    shutter[0] + u * (shutter[1] - shutter[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoid_hand_cases() {
        // ramp 0.25: area 0.75, plateau pdf 1/0.75 = 4/3.
        let curve = ShutterCurve::trapezoid(0.25).unwrap();
        assert!((curve.pdf(0.5) - 4.0 / 3.0).abs() < 1e-6);
        // Half-way up the opening ramp: openness 0.5, pdf 0.5/0.75 = 2/3.
        assert!((curve.pdf(0.125) - 2.0 / 3.0).abs() < 1e-6);
        // The opening triangle holds (0.25/2)/0.75 = 1/6 of the samples: u = 1/6 -> t = 0.25.
        assert!((curve.sample(1.0 / 6.0) - 0.25).abs() < 1e-6);
        // By symmetry u = 1/2 -> t = 1/2.
        assert!((curve.sample(0.5) - 0.5).abs() < 1e-6);
        assert!((curve.invert(0.25) - 1.0 / 6.0).abs() < 1e-6);
        // Box: identity.
        assert_eq!(ShutterCurve::Box.sample(0.3), 0.3);
        assert_eq!(ShutterCurve::Box.pdf(0.3), 1.0);
    }

    #[test]
    fn trapezoid_rejects_bad_ramps() {
        for ramp in [-0.1, 0.6, f32::NAN, f32::INFINITY] {
            assert!(ShutterCurve::trapezoid(ramp).is_err(), "{ramp}");
        }
        assert!(ShutterCurve::trapezoid(0.5).is_ok());
    }

    #[test]
    fn shutter_time_hand_case() {
        // open 2, close 4, u = 0.25 -> 2 + 0.25 * 2 = 2.5.
        assert_eq!(shutter_time(0.25, [2.0, 4.0]), 2.5);
    }
}
