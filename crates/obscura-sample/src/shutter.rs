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

/// A shutter's openness over the normalised interval `[0, 1]` as a piecewise-linear curve
/// through `(t, openness)` points (the scene format's `shutter_curve`), zero before the first
/// point and after the last.
///
/// Times are drawn by inverting the curve's integral: with `O(t)` the openness and
/// `A = integral of O over [0, 1]`, [`PiecewiseShutterCurve::sample`] returns the `t` with
/// `integral of O over [0, t] = u A`. On a segment from `(t0, o0)` to `(t1, o1)` with slope
/// `a = (o1 - o0) / (t1 - t0)` the area `r` past `t0` is reached at
/// `s = 2 r / (o0 + sqrt(o0^2 + 2 a r))` (the stable root of `a s^2 / 2 + o0 s = r`). The map
/// is monotonic, so equal-weight strata of `u` stay equal-weight strata of exposure.
/// [`ShutterCurve::Trapezoid`] is the closed-form special case `[[0, 0], [r, 1], [1 - r, 1], [1, 0]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseShutterCurve {
    /// The points, `t` strictly increasing in `[0, 1]`.
    points: Vec<[f64; 2]>,
    /// `cumulative[i]`: the area under the curve from `t = points[0].t` to `points[i].t`.
    cumulative: Vec<f64>,
}

impl PiecewiseShutterCurve {
    /// The curve through `points` (`[t, openness]`). Errors unless there are at least two
    /// points, every number is finite, `t` is strictly increasing within `[0, 1]`, openness
    /// is `>= 0`, and the area under the curve is positive.
    pub fn new(points: &[[f32; 2]]) -> Result<PiecewiseShutterCurve, SampleError> {
        let bad = |point: Option<usize>, reason: String| {
            Err(SampleError::InvalidShutterCurve { reason, point })
        };
        if points.len() < 2 {
            return bad(
                None,
                format!(
                    "needs at least two [t, openness] points, got {}",
                    points.len()
                ),
            );
        }
        for (i, &[t, o]) in points.iter().enumerate() {
            if !(t.is_finite() && o.is_finite()) {
                return bad(Some(i), format!("point {i} [{t}, {o}] is not finite"));
            }
            if !(0.0..=1.0).contains(&t) {
                return bad(
                    Some(i),
                    format!(
                        "point {i} has t = {t}; times are fractions of the shutter interval in [0, 1]"
                    ),
                );
            }
            if o < 0.0 {
                return bad(Some(i), format!("point {i} has negative openness {o}"));
            }
            if i > 0 && t <= points[i - 1][0] {
                return bad(
                    Some(i),
                    format!(
                        "t must increase from point to point, but point {i} has t = {t} after {}",
                        points[i - 1][0]
                    ),
                );
            }
        }
        let points: Vec<[f64; 2]> = points
            .iter()
            .map(|&[t, o]| [f64::from(t), f64::from(o)])
            .collect();
        let mut cumulative = Vec::with_capacity(points.len());
        let mut area = 0.0;
        cumulative.push(0.0);
        for pair in points.windows(2) {
            area += 0.5 * (pair[0][1] + pair[1][1]) * (pair[1][0] - pair[0][0]);
            cumulative.push(area);
        }
        if area <= 0.0 {
            return bad(
                None,
                "the shutter is never open (the area under the curve is 0)".to_string(),
            );
        }
        Ok(PiecewiseShutterCurve { points, cumulative })
    }

    /// The points as given.
    pub fn points(&self) -> Vec<[f32; 2]> {
        self.points
            .iter()
            .map(|p| [p[0] as f32, p[1] as f32])
            .collect()
    }

    /// The area under the curve over `[0, 1]`.
    fn area(&self) -> f64 {
        self.cumulative[self.cumulative.len() - 1]
    }

    /// The openness at normalised time `t` (linear between points, 0 outside them).
    pub fn openness(&self, t: f32) -> f32 {
        let t = f64::from(t);
        let first = self.points[0][0];
        let last = self.points[self.points.len() - 1][0];
        if !(first..=last).contains(&t) {
            return 0.0;
        }
        let i = self
            .points
            .partition_point(|p| p[0] <= t)
            .clamp(1, self.points.len() - 1);
        let ([t0, o0], [t1, o1]) = (self.points[i - 1], self.points[i]);
        (o0 + (o1 - o0) * (t - t0) / (t1 - t0)) as f32
    }

    /// The density of [`PiecewiseShutterCurve::sample`] at `t`: openness over the area.
    pub fn pdf(&self, t: f32) -> f32 {
        (f64::from(self.openness(t)) / self.area()) as f32
    }

    /// Warps a canonical `u` in `[0, 1)` to a normalised time with density
    /// [`PiecewiseShutterCurve::pdf`].
    pub fn sample(&self, u: f32) -> f32 {
        let target = f64::from(u.clamp(0.0, ONE_MINUS_EPSILON)) * self.area();
        // The segment whose area span holds the target, skipping closed (zero-area) ones.
        let n = self.points.len();
        let mut i = self
            .cumulative
            .partition_point(|&c| c <= target)
            .clamp(1, n - 1);
        while i + 1 < n && self.cumulative[i] <= self.cumulative[i - 1] {
            i += 1;
        }
        let ([t0, o0], [t1, o1]) = (self.points[i - 1], self.points[i]);
        let r = (target - self.cumulative[i - 1]).max(0.0);
        let slope = (o1 - o0) / (t1 - t0);
        let root = (o0 * o0 + 2.0 * slope * r).max(0.0).sqrt();
        let s = if o0 + root > 0.0 {
            2.0 * r / (o0 + root)
        } else {
            0.0
        };
        ((t0 + s.min(t1 - t0)) as f32).clamp(0.0, ONE_MINUS_EPSILON)
    }

    /// The distribution function: the `u` that [`PiecewiseShutterCurve::sample`] maps to `t`.
    pub fn invert(&self, t: f32) -> f32 {
        let t = f64::from(t);
        let n = self.points.len();
        if t <= self.points[0][0] {
            return 0.0;
        }
        if t >= self.points[n - 1][0] {
            return ONE_MINUS_EPSILON;
        }
        let i = self.points.partition_point(|p| p[0] <= t).clamp(1, n - 1);
        let ([t0, o0], [t1, o1]) = (self.points[i - 1], self.points[i]);
        let s = t - t0;
        let area = o0 * s + 0.5 * (o1 - o0) / (t1 - t0) * s * s;
        (((self.cumulative[i - 1] + area) / self.area()) as f32).clamp(0.0, ONE_MINUS_EPSILON)
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
    #[test]
    fn piecewise_hand_cases() {
        // A ramp from 0 to 1 over [0, 1]: O(t) = t, area 1/2, CDF t^2, so u = 1/4 -> t = 1/2.
        let ramp = PiecewiseShutterCurve::new(&[[0.0, 0.0], [1.0, 1.0]]).unwrap();
        assert!((ramp.sample(0.25) - 0.5).abs() < 1e-6);
        assert!((ramp.invert(0.5) - 0.25).abs() < 1e-6);
        assert!((ramp.pdf(0.5) - 1.0).abs() < 1e-6);
        // A box over [0.5, 1] with openness 2: uniform there, nothing before.
        let late = PiecewiseShutterCurve::new(&[[0.5, 2.0], [1.0, 2.0]]).unwrap();
        assert!((late.sample(0.5) - 0.75).abs() < 1e-6);
        assert_eq!(late.pdf(0.25), 0.0);
        assert!((late.pdf(0.75) - 2.0).abs() < 1e-6);
        // The trapezoid as points gives the closed form's times.
        let trapezoid = ShutterCurve::trapezoid(0.25).unwrap();
        let points =
            PiecewiseShutterCurve::new(&[[0.0, 0.0], [0.25, 1.0], [0.75, 1.0], [1.0, 0.0]])
                .unwrap();
        for k in 0..20 {
            let u = k as f32 / 20.0;
            assert!((points.sample(u) - trapezoid.sample(u)).abs() < 1e-5, "{u}");
        }
    }

    #[test]
    fn piecewise_rejects_bad_curves() {
        for bad in [
            &[[0.0, 1.0]][..],
            &[[0.0, 1.0], [0.0, 1.0]],
            &[[0.5, 1.0], [0.25, 1.0]],
            &[[0.0, -1.0], [1.0, 1.0]],
            &[[0.0, f32::NAN], [1.0, 1.0]],
            &[[0.0, 1.0], [1.5, 1.0]],
            &[[0.0, 0.0], [1.0, 0.0]],
        ] {
            assert!(PiecewiseShutterCurve::new(bad).is_err(), "{bad:?}");
        }
    }

    proptest::proptest! {
        #[test]
        fn piecewise_sample_inverts(
            opens in proptest::collection::vec(0.0f32..4.0, 2..6),
            u in 0.0f32..1.0,
        ) {
            let n = opens.len();
            let points: Vec<[f32; 2]> = opens
                .iter()
                .enumerate()
                .map(|(i, &o)| [i as f32 / (n - 1) as f32, o])
                .collect();
            if let Ok(curve) = PiecewiseShutterCurve::new(&points) {
                let t = curve.sample(u);
                proptest::prop_assert!((0.0..1.0).contains(&t));
                proptest::prop_assert!((curve.invert(t) - u).abs() < 2e-4, "{} {}", t, u);
            }
        }
    }
}
