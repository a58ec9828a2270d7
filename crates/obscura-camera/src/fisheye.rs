//! The ideal fisheye cameras: equidistant, equisolid, stereographic and orthographic.

use crate::camera::{Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample};
use crate::chain::{self, CameraRayParts, PoseCache};
use crate::error::{CameraError, finite};
use core::str::FromStr;
use glam::DVec3;
use obscura_space::{Point2, Point3, Raster, World};

/// How far past half the field of view (radians) [`Camera::project`] still maps a direction:
/// the f32 rounding of a rim ray taken to the world and back.
const RIM_SLACK: f64 = 1e-5;

/// The radial mapping of an ideal fisheye: the image radius `r` of a direction at angle
/// `theta` from the optical axis, for a focal length `f` (Kannala and Brandt, "A Generic
/// Camera Model and Calibration Method for Conventional, Wide-Angle, and Fish-Eye Lenses",
/// IEEE PAMI 28(8), 2006, equations 2-5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FisheyeProjection {
    /// `r = f theta` (equal angles, equal radii); `fov` up to 360 degrees.
    Equidistant,
    /// `r = 2 f sin(theta / 2)` (equal solid angles, equal areas); `fov` up to 360 degrees.
    Equisolid,
    /// `r = 2 f tan(theta / 2)` (conformal); `fov` below 360 degrees.
    Stereographic,
    /// `r = f sin theta`; `fov` below 180 degrees.
    Orthographic,
}

impl FisheyeProjection {
    /// The scene format's name: `"equidistant"`, `"equisolid"`, `"stereographic"` or
    /// `"orthographic"`.
    pub fn name(self) -> &'static str {
        match self {
            FisheyeProjection::Equidistant => "equidistant",
            FisheyeProjection::Equisolid => "equisolid",
            FisheyeProjection::Stereographic => "stereographic",
            FisheyeProjection::Orthographic => "orthographic",
        }
    }

    /// The largest full field of view in degrees, and whether it is itself allowed.
    pub fn max_fov(self) -> (f32, bool) {
        match self {
            FisheyeProjection::Equidistant | FisheyeProjection::Equisolid => (360.0, true),
            FisheyeProjection::Stereographic => (360.0, false),
            FisheyeProjection::Orthographic => (180.0, false),
        }
    }

    /// `r / f` of a direction at `theta` radians from the optical axis.
    #[inline]
    pub fn radius(self, theta: f64) -> f64 {
        match self {
            FisheyeProjection::Equidistant => theta,
            FisheyeProjection::Equisolid => 2.0 * (0.5 * theta).sin(),
            FisheyeProjection::Stereographic => 2.0 * (0.5 * theta).tan(),
            FisheyeProjection::Orthographic => theta.sin(),
        }
    }

    /// The angle from the optical axis (radians) of the image radius `r / f`: the inverse of
    /// [`FisheyeProjection::radius`] over the projection's range (arguments of the arcsines
    /// are clamped to 1 against rounding at the rim).
    #[inline]
    pub fn angle(self, r_over_f: f64) -> f64 {
        match self {
            FisheyeProjection::Equidistant => r_over_f,
            FisheyeProjection::Equisolid => 2.0 * (0.5 * r_over_f).min(1.0).asin(),
            FisheyeProjection::Stereographic => 2.0 * (0.5 * r_over_f).atan(),
            FisheyeProjection::Orthographic => r_over_f.min(1.0).asin(),
        }
    }
}

impl FromStr for FisheyeProjection {
    type Err = CameraError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "equidistant" => Ok(FisheyeProjection::Equidistant),
            "equisolid" => Ok(FisheyeProjection::Equisolid),
            "stereographic" => Ok(FisheyeProjection::Stereographic),
            "orthographic" => Ok(FisheyeProjection::Orthographic),
            _ => Err(CameraError::UnknownFisheyeProjection(s.to_owned())),
        }
    }
}

/// An ideal fisheye: a direction at angle `theta` from the optical axis (camera +z) and
/// azimuth `psi` around it lands at radius `r(theta)` ([`FisheyeProjection`]) from the centre
/// of the image circle, in the direction `psi`:
///
/// `d = (sin theta cos psi, sin theta sin psi, cos theta)`, raster
/// `(c_x + r cos psi, c_y - r sin psi)`.
///
/// Conventions: image right is camera +x, image up is camera +y (raster y points down, hence
/// the minus). The image circle's diameter is the smaller image dimension, so its radius is
/// `R = min(W, H) / 2`; its centre is `c = (W/2 - s_x W, H/2 + s_y H)` for the lens shift
/// `[s_x, s_y]` (fractions of the image size, +x right, +y up): the picture moves as a
/// perspective camera's does under the same shift, so `s_y > 0` shows more above, as a rising
/// front does. `fov` is the full angle across
/// the image circle, so the focal length in pixels follows from `f r(fov / 2) = R`.
///
/// Valid region: film points with `|p - c| <= R` (the rim included) give rays; points outside
/// the circle give none. [`Camera::project`] maps every direction within `fov / 2` of the
/// axis (with a slack of 1e-5 rad for rounding at the rim), including the back pole of a
/// 360-degree lens (the whole rim; its centre-right point is returned), and gives None
/// beyond. Rays start at the eye and are clipped by distance, `[t_min, t_max] = [near, far]`.
#[derive(Debug, Clone)]
pub struct FisheyeCamera {
    base: CameraBase,
    pose: PoseCache,
    projection: FisheyeProjection,
    /// Half the field of view, radians.
    half_fov: f64,
    /// Focal length in pixels.
    focal: f64,
    /// The image circle's centre (raster) and radius (pixels).
    centre: [f64; 2],
    radius: f64,
}

impl FisheyeCamera {
    /// A fisheye of the given projection and full field of view `fov_degrees`, its view
    /// shifted by `lens_shift` (fractions of the image size, +x right, +y up, as for the
    /// perspective camera: the image circle moves the other way; `[0, 0]` centres it). Errors: non-finite numbers ([`CameraError::NonFinite`]), a field of view
    /// outside the projection's range ([`CameraError::FisheyeFov`]: `(0, 360]` equidistant and
    /// equisolid, `(0, 360)` stereographic, `(0, 180)` orthographic), and the base's errors
    /// (`near < 0`, `near >= far`, a bad shutter).
    pub fn new(
        base: CameraBase,
        projection: FisheyeProjection,
        fov_degrees: f32,
        lens_shift: [f32; 2],
    ) -> Result<FisheyeCamera, CameraError> {
        base.validate(false)?;
        finite("fov", fov_degrees)?;
        finite("lens_shift", lens_shift[0])?;
        finite("lens_shift", lens_shift[1])?;
        let (max, max_inclusive) = projection.max_fov();
        let below_max = if max_inclusive {
            fov_degrees <= max
        } else {
            fov_degrees < max
        };
        if !(fov_degrees > 0.0 && below_max) {
            return Err(CameraError::FisheyeFov {
                projection: projection.name(),
                max,
                max_inclusive,
                got: fov_degrees,
            });
        }
        let [width, height] = base.film.resolution().map(f64::from);
        let half_fov = 0.5 * f64::from(fov_degrees).to_radians();
        let radius = 0.5 * width.min(height);
        let focal = radius / projection.radius(half_fov);
        let centre = [
            width * (0.5 - f64::from(lens_shift[0])),
            height * (0.5 + f64::from(lens_shift[1])),
        ];
        Ok(FisheyeCamera {
            pose: PoseCache::new(&base),
            base,
            projection,
            half_fov,
            focal,
            centre,
            radius,
        })
    }

    /// The pose, shutter, film and clip range.
    pub fn base(&self) -> &CameraBase {
        &self.base
    }

    /// The radial mapping.
    pub fn projection(&self) -> FisheyeProjection {
        self.projection
    }

    /// The full field of view across the image circle, degrees.
    pub fn fov_degrees(&self) -> f64 {
        2.0 * self.half_fov.to_degrees()
    }

    /// The focal length in pixels, `f` of [`FisheyeProjection::radius`].
    pub fn focal_length(&self) -> f64 {
        self.focal
    }

    /// The image circle: its centre in raster space and its radius in pixels.
    pub fn image_circle(&self) -> (Point2<Raster>, f32) {
        (
            Point2::new(self.centre[0] as f32, self.centre[1] as f32),
            self.radius as f32,
        )
    }

    /// The camera-space unit direction of a film point; None outside the image circle.
    pub fn direction(&self, p_film: Point2<Raster>) -> Option<DVec3> {
        // Offset from the circle's centre, image up positive.
        let u = f64::from(p_film.x) - self.centre[0];
        let v = self.centre[1] - f64::from(p_film.y);
        let r = u.hypot(v);
        if r > self.radius {
            return None;
        }
        // Angle from the optical axis, then the direction at azimuth atan2(v, u).
        let theta = self.projection.angle(r / self.focal);
        if r == 0.0 {
            return Some(DVec3::Z);
        }
        let (sin_theta, cos_theta) = theta.sin_cos();
        Some(DVec3::new(sin_theta * u / r, sin_theta * v / r, cos_theta))
    }

    /// The camera-space ray of a film point.
    #[inline]
    fn ray_at(&self, p_film: Point2<Raster>) -> Option<CameraRayParts> {
        let direction = self.direction(p_film)?;
        Some(CameraRayParts::by_distance(
            DVec3::ZERO,
            direction,
            &self.base,
        ))
    }
}

impl Camera for FisheyeCamera {
    #[inline]
    fn base(&self) -> &CameraBase {
        &self.base
    }

    fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        chain::generate(&self.base, &self.pose, sample, |p| self.ray_at(p))
    }

    fn generate_ray_differential(&self, sample: &CameraSample) -> Option<CameraRayDifferential> {
        chain::generate_differential(&self.base, &self.pose, sample, |p| self.ray_at(p))
    }

    fn project(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
        // World -> camera, a unit direction within the clip range.
        let v = chain::camera_point(&self.base, &self.pose, p, time);
        let d = chain::direction_within_clip(&self.base, v)?;
        // Angle from the axis; nothing past half the field of view.
        let sin_theta = d.x.hypot(d.y);
        let theta = sin_theta.atan2(d.z);
        if theta > self.half_fov + RIM_SLACK {
            return None;
        }
        // Radius along the azimuth (the back pole of a 360-degree lens: the rim's right).
        let r = self.focal * self.projection.radius(theta);
        let (cos_psi, sin_psi) = if sin_theta > 0.0 {
            (d.x / sin_theta, d.y / sin_theta)
        } else {
            (1.0, 0.0)
        };
        Some(Point2::new(
            (self.centre[0] + r * cos_psi) as f32,
            (self.centre[1] - r * sin_psi) as f32,
        ))
    }

    fn uses_lens_sample(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_fail() {
        for p in [
            FisheyeProjection::Equidistant,
            FisheyeProjection::Equisolid,
            FisheyeProjection::Stereographic,
            FisheyeProjection::Orthographic,
        ] {
            assert_eq!(p.name().parse::<FisheyeProjection>(), Ok(p));
        }
        assert_eq!(
            "fisheye".parse::<FisheyeProjection>(),
            Err(CameraError::UnknownFisheyeProjection("fisheye".into()))
        );
    }

    #[test]
    fn angle_inverts_radius() {
        for p in [
            FisheyeProjection::Equidistant,
            FisheyeProjection::Equisolid,
            FisheyeProjection::Stereographic,
            FisheyeProjection::Orthographic,
        ] {
            for theta in [0.0, 0.1, 0.7, 1.2, 1.5] {
                assert!((p.angle(p.radius(theta)) - theta).abs() < 1e-12, "{p:?}");
            }
        }
    }
}
