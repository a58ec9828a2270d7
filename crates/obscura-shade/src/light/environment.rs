//! The environment light: constant radiance, or an equirectangular map importance-sampled by
//! luminance.

use super::{LightSample, TINY, luminance};
use crate::error::{ShadeError, check_non_negative};
use core::f32::consts::{FRAC_PI_2, PI, TAU};
use glam::{Mat3, Mat4, Vec2, Vec3};
use obscura_accel::Pages;
use obscura_sample::{Distribution2D, GridCell, SearchStart};
use obscura_sample::{square_to_uniform_sphere, uniform_sphere_pdf};

/// Light from every direction at infinity: a constant radiance or an equirectangular map.
#[derive(Debug, Clone)]
pub struct EnvironmentLight {
    kind: EnvironmentKind,
}

/// What an [`EnvironmentLight`] holds.
#[derive(Debug, Clone)]
enum EnvironmentKind {
    Constant(Vec3),
    Map(Box<LatLongMap>),
}

/// An equirectangular (latitude-longitude) radiance map with its sampling distribution.
#[derive(Debug, Clone)]
struct LatLongMap {
    /// The texels' sampling density, each cell carrying its texel's radiance: the grid of
    /// the distribution is the map's, so a texel and its density are one load apart. Lookups
    /// take the nearest texel, unfiltered: the radiance is piecewise constant exactly like
    /// the sampling density. On huge pages: every light sample and every escaped ray reads
    /// the grid at random, and a map of a few megapixels spans thousands of ordinary pages.
    distribution: Distribution2D<Pages<GridCell>>,
    world_from_light: Mat3,
    light_from_world: Mat3,
}

impl EnvironmentLight {
    /// A uniform environment of the given radiance.
    pub fn constant(radiance: Vec3) -> Result<EnvironmentLight, ShadeError> {
        check_non_negative(radiance, "radiance")?;
        Ok(EnvironmentLight {
            kind: EnvironmentKind::Constant(radiance),
        })
    }

    /// An equirectangular map of `width x height` linear-RGB texels, row 0 at the top
    /// (`+y` of the light's frame), with the light's frame placed in the world by the rotation
    /// `world_from_light` (its translation is ignored; its linear part must be orthonormal).
    pub fn from_texels(
        width: u32,
        height: u32,
        texels: Vec<Vec3>,
        world_from_light: Mat4,
    ) -> Result<EnvironmentLight, ShadeError> {
        if width == 0 || height == 0 {
            return Err(ShadeError::OutOfRange {
                parameter: "environment map size",
                expected: "at least 1 x 1",
            });
        }
        let expected = u64::from(width) * u64::from(height);
        if texels.len() as u64 != expected {
            return Err(ShadeError::TexelCount {
                expected,
                actual: texels.len(),
            });
        }
        for t in &texels {
            check_non_negative(*t, "environment map texel")?;
        }
        if !world_from_light.is_finite() {
            return Err(ShadeError::NotFinite {
                parameter: "environment transform",
            });
        }
        let rotation = Mat3::from_mat4(world_from_light);
        let gram = rotation.transpose() * rotation;
        if !gram.abs_diff_eq(Mat3::IDENTITY, 1e-3) {
            return Err(ShadeError::OutOfRange {
                parameter: "environment transform",
                expected: "a rotation (orthonormal linear part)",
            });
        }
        // Weights: luminance times sin(theta) at the row's centre (rows near the poles cover
        // less solid angle).
        let (w, h) = (width as usize, height as usize);
        let mut weights = Vec::with_capacity(w * h);
        for y in 0..h {
            let sin_theta = (PI * (y as f32 + 0.5) / h as f32).sin();
            for x in 0..w {
                weights.push(luminance(texels[y * w + x]) * sin_theta);
            }
        }
        let distribution = Distribution2D::with_values_stored(&weights, &texels, w, h, Pages::new);
        Ok(EnvironmentLight {
            kind: EnvironmentKind::Map(Box::new(LatLongMap {
                distribution,
                world_from_light: rotation,
                light_from_world: rotation.transpose(),
            })),
        })
    }

    /// The radiance arriving from world direction `d_world` (unit), i.e. seen looking along it.
    pub fn radiance(&self, d_world: Vec3) -> Vec3 {
        self.radiance_at(d_world, None)
    }

    /// [`EnvironmentLight::radiance`], given the map coordinates of `d_world` when the caller
    /// has them: `uv` must be what [`EnvironmentLight::prefetch_lookup`] returned for the same
    /// direction (`None`: found here).
    #[inline]
    pub fn radiance_at(&self, d_world: Vec3, uv: Option<Vec2>) -> Vec3 {
        match &self.kind {
            EnvironmentKind::Constant(l) => *l,
            EnvironmentKind::Map(map) => {
                let uv = uv.unwrap_or_else(|| direction_to_uv(map.light_from_world * d_world));
                map.distribution.value(uv)
            }
        }
    }

    /// Samples a direction (by luminance for maps, uniformly for a constant).
    pub fn sample_li(&self, u2: Vec2) -> Option<LightSample> {
        self.sample_li_in_row(u2, None)
    }

    /// [`EnvironmentLight::sample_li`], given the map row the sample picks when the caller has
    /// it: `row` must be [`SearchStart::row`] of [`EnvironmentLight::sample_start`] for the
    /// same `u2` (`None`: found here).
    #[inline]
    pub fn sample_li_in_row(&self, u2: Vec2, row: Option<usize>) -> Option<LightSample> {
        match &self.kind {
            EnvironmentKind::Constant(l) => Some(LightSample {
                wi: square_to_uniform_sphere(u2),
                radiance: *l,
                pdf: uniform_sphere_pdf(),
                p_light: None,
                delta: false,
            }),
            EnvironmentKind::Map(map) => {
                let (uv, pdf_uv, radiance) = match row {
                    Some(row) => map.distribution.sample_with_value_in_row(u2, row),
                    None => map.distribution.sample_with_value(u2),
                };
                let sin_theta = (PI * uv.y).sin();
                if pdf_uv <= 0.0 || sin_theta <= TINY {
                    return None;
                }
                let d_light = uv_to_direction(uv);
                Some(LightSample {
                    wi: (map.world_from_light * d_light).normalize(),
                    radiance,
                    pdf: pdf_uv / (2.0 * PI * PI * sin_theta),
                    p_light: None,
                    delta: false,
                })
            }
        }
    }

    /// True for a map (whose lookups read memory at random), false for a constant.
    pub fn is_map(&self) -> bool {
        matches!(self.kind, EnvironmentKind::Map(_))
    }

    /// Where [`EnvironmentLight::sample_li`]'s search of the map for `u2` starts (`None` for
    /// a constant), for a caller to prefetch its cells in turn; reads nothing of the map.
    #[inline]
    pub fn sample_start(&self, u2: Vec2) -> Option<SearchStart<'_>> {
        match &self.kind {
            EnvironmentKind::Map(map) => Some(map.distribution.search_start(u2)),
            EnvironmentKind::Constant(_) => None,
        }
    }

    /// Asks the cache for the line [`EnvironmentLight::radiance_and_pdf`] reads for `d_world`,
    /// and returns the map coordinates it found there (`None` for a constant), for
    /// [`EnvironmentLight::radiance_at`] and [`EnvironmentLight::radiance_and_pdf_at`] to take
    /// instead of finding them again. Changes nothing else.
    #[inline]
    pub fn prefetch_lookup(&self, d_world: Vec3) -> Option<Vec2> {
        let EnvironmentKind::Map(map) = &self.kind else {
            return None;
        };
        let uv = direction_to_uv(map.light_from_world * d_world);
        obscura_accel::prefetch(map.distribution.cell(uv), 0);
        Some(uv)
    }

    /// The solid-angle density with which [`EnvironmentLight::sample_li`] returns `d_world`.
    pub fn pdf_li(&self, d_world: Vec3) -> f32 {
        self.radiance_and_pdf(d_world).1
    }

    /// [`EnvironmentLight::radiance`] and [`EnvironmentLight::pdf_li`] of one direction, with
    /// the direction's map coordinates found once (what a path that escapes needs).
    pub fn radiance_and_pdf(&self, d_world: Vec3) -> (Vec3, f32) {
        self.radiance_and_pdf_at(d_world, None)
    }

    /// [`EnvironmentLight::radiance_and_pdf`], given the map coordinates of `d_world` when the
    /// caller has them: `uv` must be what [`EnvironmentLight::prefetch_lookup`] returned for
    /// the same direction (`None`: found here).
    #[inline]
    pub fn radiance_and_pdf_at(&self, d_world: Vec3, uv: Option<Vec2>) -> (Vec3, f32) {
        match &self.kind {
            EnvironmentKind::Constant(l) => (*l, uniform_sphere_pdf()),
            EnvironmentKind::Map(map) => {
                let d_light = map.light_from_world * d_world;
                let uv = uv.unwrap_or_else(|| direction_to_uv(d_light));
                // sin(theta) from the direction itself: well conditioned at the poles, where
                // going through acos would lose most digits.
                let sin_theta = Vec2::new(d_light.x, d_light.z).length() / d_light.length();
                let (pdf_uv, radiance) = map.distribution.pdf_and_value(uv);
                let pdf = if sin_theta <= TINY {
                    0.0
                } else {
                    pdf_uv / (2.0 * PI * PI * sin_theta)
                };
                (radiance, pdf)
            }
        }
    }
}

/// Map coordinates of a unit direction in the light's frame: `u = phi / 2pi + 1/2` with
/// `phi = atan2(x, z)` from +z towards +x, `v = theta / pi` with `theta` from +y (the
/// environment camera's mapping).
#[inline]
pub fn direction_to_uv(d_light: Vec3) -> Vec2 {
    // atan2 rather than acos(y): accurate near the poles too.
    let theta = atan2(Vec2::new(d_light.x, d_light.z).length(), d_light.y);
    let phi = atan2(d_light.x, d_light.z);
    let u = (phi / TAU + 0.5).clamp(0.0, 1.0);
    let v = (theta / PI).clamp(0.0, 1.0);
    Vec2::new(u, v)
}

/// `atan2(y, x)` of finite `x`, `y` in `[-pi, pi]`, within a few ulp of the exact value, with
/// libm's signs at zeros and NaN for a NaN input; inlined, where a call to libm's `atan2f`
/// costs more than the rest of a map lookup. `atan(t)` for `t = min / max` in `[0, 1]` is
/// `t P(t^2)`, `P` of degree 9 fitted to `atan` by least squares in relative error (at most
/// 1.4 ulp on `[0, 1]` in `f32`); the octant's symmetries `pi/2 - a`, `pi - a` and the sign of
/// `y` give the rest.
#[inline]
fn atan2(y: f32, x: f32) -> f32 {
    const P: [f32; 10] = [
        1.0,
        -0.333_332_84,
        0.199_982_67,
        -0.142_619_39,
        0.109_420_516,
        -0.083_773_69,
        0.057_552_92,
        -0.030_805_342,
        0.010_727_316,
        -0.001_754_008_4,
    ];
    if x.is_nan() || y.is_nan() {
        return f32::NAN;
    }
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    // Both zero: atan2 of signed zeros is 0 or pi by the signs alone.
    let t = if hi > 0.0 { lo / hi } else { 0.0 };
    let t2 = t * t;
    let mut p = P[9];
    for &c in P[..9].iter().rev() {
        p = p * t2 + c;
    }
    let mut a = t * p;
    if ay > ax {
        a = FRAC_PI_2 - a;
    }
    if x.is_sign_negative() {
        a = PI - a;
    }
    a.copysign(y)
}

/// The inverse of [`direction_to_uv`]: `d = (sin theta sin phi, cos theta, sin theta cos phi)`
/// with `theta = pi v`, `phi = 2 pi (u - 1/2)`.
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let theta = PI * uv.y;
    let phi = TAU * (uv.x - 0.5);
    let (sin_theta, cos_theta) = theta.sin_cos();
    let (sin_phi, cos_phi) = phi.sin_cos();
    Vec3::new(sin_theta * sin_phi, cos_theta, sin_theta * cos_phi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distance from libm's `f64` atan2 in units of the `f32` result's last place.
    fn ulps(y: f32, x: f32) -> f64 {
        let exact = f64::from(y).atan2(f64::from(x));
        let ulp = f64::from((exact as f32).abs().next_up() - (exact as f32).abs());
        (f64::from(atan2(y, x)) - exact).abs() / ulp
    }

    #[test]
    fn atan2_keeps_libm_signs_and_special_values() {
        for (y, x) in [
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (0.0, 0.0),
            (-0.0, 0.0),
            (0.0, -0.0),
            (-0.0, -0.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (1.0, 1.0),
            (-1.0, -1.0),
            (3.0, -4.0),
            (1e-30, 1e30),
            (1e30, -1e-30),
        ] {
            let (fast, libm) = (atan2(y, x), y.atan2(x));
            assert!(
                fast.to_bits() == libm.to_bits() || (fast - libm).abs() <= 2e-7 * libm.abs(),
                "atan2({y}, {x}) = {fast}, libm {libm}"
            );
            assert_eq!(
                fast.is_sign_negative(),
                libm.is_sign_negative(),
                "({y}, {x})"
            );
        }
        assert!(atan2(f32::NAN, 1.0).is_nan());
        assert!(atan2(1.0, f32::NAN).is_nan());
    }

    proptest::proptest! {
        #[test]
        fn atan2_is_within_three_ulp_everywhere(
            y in -1e4f32..1e4,
            x in -1e4f32..1e4,
            scale in -30i32..30,
        ) {
            let s = 2f32.powi(scale);
            let error = ulps(y * s, x * s);
            proptest::prop_assert!(error <= 3.0, "atan2({}, {}): {} ulp", y * s, x * s, error);
        }
    }

    #[test]
    fn atan2_is_within_three_ulp_on_a_dense_sweep_of_the_circle() {
        // Every angle the fit covers, both octants of each quadrant, 400,000 steps.
        let mut worst = 0.0f64;
        for k in 0..400_000 {
            let angle =
                (k as f64 + 0.5) / 400_000.0 * core::f64::consts::TAU - core::f64::consts::PI;
            let (y, x) = (angle.sin() as f32, angle.cos() as f32);
            worst = worst.max(ulps(y, x));
        }
        assert!(worst <= 3.0, "{worst} ulp");
    }
}
