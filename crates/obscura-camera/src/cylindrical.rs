//! The cylindrical panorama camera.

use crate::camera::{Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample};
use crate::chain::{self, CameraRayParts, PoseCache};
use crate::error::{CameraError, finite};
use core::f64::consts::TAU;
use glam::DVec3;
use obscura_space::{Point2, Point3, Raster, World};

/// A 360-degree cylindrical panorama around camera +y: columns are the environment camera's
/// azimuths, rows are linear in height on the unit-radius cylinder around the eye (the central
/// cylindrical projection: a direction's image is where it meets the cylinder, unrolled, as
/// for the cylindrical panoramas of Szeliski's "Computer Vision: Algorithms and
/// Applications"). For raster `(x, y)` on a `W x H` film and the vertical field of view `fov`:
///
/// `phi = 2 pi (x / W - 0.5)` (from camera +z towards +x),
/// `h = tan(fov / 2) (1 - 2 y / H)` (`tan(fov / 2)` at the top edge, minus it at the bottom),
/// `d = normalize(sin phi, h, cos phi)`.
///
/// The image centre looks along +z, the right half right (+x), the top row up at `fov / 2`
/// above the horizon. Every film point gives a ray, from the eye, clipped by distance
/// (`[t_min, t_max] = [near, far]`). [`Camera::project`] maps every direction but the two
/// poles (straight up or down have no azimuth), including those above or below the field of
/// view (they land above or below the image); the seam is at `x = 0` (azimuth -pi) and
/// `x = W` (+pi), and `project` returns `x` in `[0, W]`.
#[derive(Debug, Clone)]
pub struct CylindricalCamera {
    base: CameraBase,
    pose: PoseCache,
    /// `tan(fov / 2)`: the cylinder's height at the top edge.
    tan_half_fov: f64,
}

impl CylindricalCamera {
    /// A cylindrical panorama with the vertical field of view `fov_degrees`. Errors: a
    /// non-finite fov ([`CameraError::NonFinite`]), one outside (0, 180) degrees
    /// ([`CameraError::Fov`]), and the base's errors (`near < 0`, `near >= far`, a bad shutter).
    pub fn new(base: CameraBase, fov_degrees: f32) -> Result<CylindricalCamera, CameraError> {
        base.validate(false)?;
        finite("fov", fov_degrees)?;
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(CameraError::Fov { got: fov_degrees });
        }
        Ok(CylindricalCamera {
            pose: PoseCache::new(&base),
            base,
            tan_half_fov: (0.5 * f64::from(fov_degrees).to_radians()).tan(),
        })
    }

    /// The pose, shutter, film and clip range.
    pub fn base(&self) -> &CameraBase {
        &self.base
    }

    /// The camera-space unit direction of a film point.
    pub fn direction(&self, p_film: Point2<Raster>) -> DVec3 {
        let [width, height] = self.base.film.resolution().map(f64::from);
        // Azimuth and height on the unit cylinder.
        let phi = TAU * (f64::from(p_film.x) / width - 0.5);
        let h = self.tan_half_fov * (1.0 - 2.0 * f64::from(p_film.y) / height);
        let (sin_phi, cos_phi) = phi.sin_cos();
        DVec3::new(sin_phi, h, cos_phi).normalize()
    }

    /// The camera-space ray of a film point.
    #[inline]
    fn ray_at(&self, p_film: Point2<Raster>) -> Option<CameraRayParts> {
        Some(CameraRayParts::by_distance(
            DVec3::ZERO,
            self.direction(p_film),
            &self.base,
        ))
    }
}

impl Camera for CylindricalCamera {
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
        // Azimuth and height on the unit cylinder; the poles have neither.
        let horizontal = d.x.hypot(d.z);
        if horizontal == 0.0 {
            return None;
        }
        let phi = d.x.atan2(d.z);
        let h = d.y / horizontal;
        let [width, height] = self.base.film.resolution().map(f64::from);
        Some(Point2::new(
            (width * (phi / TAU + 0.5)) as f32,
            (0.5 * height * (1.0 - h / self.tan_half_fov)) as f32,
        ))
    }

    fn uses_lens_sample(&self) -> bool {
        false
    }
}
