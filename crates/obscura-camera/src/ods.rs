//! The omni-directional stereo (ODS) panorama camera.

use crate::camera::{Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample};
use crate::chain::{self, CameraRayParts, PoseCache};
use crate::error::{CameraError, finite};
use core::f64::consts::{PI, TAU};
use glam::DVec3;
use obscura_space::{Point2, Point3, Raster, World};

/// One eye of an ODS panorama.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum OdsEye {
    /// The left eye: the image's top half.
    Left,
    /// The right eye: the image's bottom half.
    Right,
}

/// An omni-directional stereo panorama for VR, after Google's "Rendering Omni-directional
/// Stereo Content" (Google Inc., the white paper accompanying its Jump VR cameras): the image's
/// top half is the left eye's panorama, the bottom half the right eye's, each an
/// equirectangular `W x H/2` image with the environment camera's mapping (SCENE_FORMAT.md).
/// For raster `(x, y)`, the eye's own row `y' = y` (left, `y < H/2`) or `y - H/2` (right),
/// and `r = interaxial / 2`:
///
/// `phi = 2 pi (x / W - 0.5)` (azimuth from camera +z towards +x),
/// `theta = pi y' / (H / 2)` (polar angle from camera +y),
/// `d = (sin theta sin phi, cos theta, sin theta cos phi)`,
/// `o = s (cos phi, 0, -sin phi)` with `s = -r` for the left eye and `+r` for the right.
///
/// Every ray starts on the viewing circle of diameter `interaxial` in the camera's horizontal
/// plane (`y = 0`) and is tangent to it (`o . d = 0`): the eyes of a head turned towards azimuth
/// `phi`, the left one on the head's left (looking along +z, the left eye sits at `(-r, 0, 0)`,
/// camera -x being the image's left). Google's document writes this in an OpenGL frame
/// (forward -z, its `theta` our `phi`); with Obscura's forward +z, its origin
/// `(cos theta, 0, sin theta) * scale`, `scale = -ipd / 2` for the left eye, becomes the `o`
/// above (POV-Ray's ODS camera in its left-handed frame, the same as Obscura's, reads the
/// same). The radius is kept constant up to the poles, as in the document's basic form. Rays
/// are clipped by distance from their origin, `[t_min, t_max] = [near, far]`;
/// `interaxial = 0` gives two copies of the environment camera's panorama.
///
/// [`Camera::project`] gives the left eye's image of a point (use [`OdsCamera::project_eye`]
/// for the right's): the tangent from the point to the circle on that eye's side. A point
/// closer to the vertical axis than `r` lies inside the viewing circle, where no ray passes:
/// None. `x` is returned in `[0, W)`, the seam at the image's left and right edges looking back.
#[derive(Debug, Clone)]
pub struct OdsCamera {
    base: CameraBase,
    pose: PoseCache,
    /// The viewing circle's radius, `interaxial / 2`.
    radius: f64,
}

impl OdsCamera {
    /// An ODS panorama with eyes `interaxial` apart (scene units, e.g. metres). Errors: a
    /// non-finite or negative interaxial ([`CameraError::NonFinite`],
    /// [`CameraError::Interaxial`]), a film of odd height ([`CameraError::FilmShape`]: each eye
    /// gets exactly half the rows), and the base's errors (`near < 0`, `near >= far`, a bad
    /// shutter).
    pub fn new(base: CameraBase, interaxial: f32) -> Result<OdsCamera, CameraError> {
        base.validate(false)?;
        finite("interaxial", interaxial)?;
        if interaxial < 0.0 {
            return Err(CameraError::Interaxial { got: interaxial });
        }
        let [width, height] = base.film.resolution();
        if height % 2 != 0 {
            return Err(CameraError::FilmShape {
                model: "ods",
                need: "an even-height",
                got: [width, height],
            });
        }
        Ok(OdsCamera {
            pose: PoseCache::new(&base),
            base,
            radius: 0.5 * f64::from(interaxial),
        })
    }

    /// The pose, shutter, film and clip range.
    pub fn base(&self) -> &CameraBase {
        &self.base
    }

    /// The distance between the eyes.
    pub fn interaxial(&self) -> f32 {
        (2.0 * self.radius) as f32
    }

    /// The eye a film point belongs to: the left for the top half (`y < H / 2`), else the right.
    pub fn eye_of(&self, p_film: Point2<Raster>) -> OdsEye {
        if f64::from(p_film.y) < self.half_height() {
            OdsEye::Left
        } else {
            OdsEye::Right
        }
    }

    /// Half the film's height: the height of one eye's panorama.
    #[inline]
    fn half_height(&self) -> f64 {
        0.5 * f64::from(self.base.film.resolution()[1])
    }

    /// The signed circle radius `s` of an eye and the raster row its panorama starts at.
    #[inline]
    fn eye_constants(&self, eye: OdsEye) -> (f64, f64) {
        match eye {
            OdsEye::Left => (-self.radius, 0.0),
            OdsEye::Right => (self.radius, self.half_height()),
        }
    }

    /// The camera-space origin and unit direction of film point `p_film` in `eye`'s panorama
    /// (rows beyond the eye's half continue its mapping, for differentials).
    pub fn eye_ray(&self, eye: OdsEye, p_film: Point2<Raster>) -> (DVec3, DVec3) {
        let (s, row0) = self.eye_constants(eye);
        let width = f64::from(self.base.film.resolution()[0]);
        // The eye's spherical angles.
        let phi = TAU * (f64::from(p_film.x) / width - 0.5);
        let theta = PI * (f64::from(p_film.y) - row0) / self.half_height();
        let (sin_phi, cos_phi) = phi.sin_cos();
        let (sin_theta, cos_theta) = theta.sin_cos();
        // Direction as the environment camera's; origin on the circle, perpendicular to it.
        let direction = DVec3::new(sin_theta * sin_phi, cos_theta, sin_theta * cos_phi);
        let origin = s * DVec3::new(cos_phi, 0.0, -sin_phi);
        (origin, direction)
    }

    /// The raster position of world point `p` at `time` in `eye`'s panorama; None inside the
    /// viewing circle, at the ray's origin, or outside `[near, far]`.
    pub fn project_eye(&self, p: Point3<World>, time: f32, eye: OdsEye) -> Option<Point2<Raster>> {
        // World -> camera.
        let v = chain::camera_point(&self.base, &self.pose, p, time);
        let (s, row0) = self.eye_constants(eye);
        // The tangent from the point's horizontal position to the circle on this eye's side:
        // with the point at azimuth alpha and horizontal distance rho, sin(alpha - phi) = s / rho.
        let rho = v.x.hypot(v.z);
        if rho < self.radius {
            return None;
        }
        let alpha = v.x.atan2(v.z);
        let phi = if s == 0.0 {
            alpha
        } else {
            alpha - (s / rho).clamp(-1.0, 1.0).asin()
        };
        // Distance along the tangent: horizontally sqrt(rho^2 - s^2), then the height.
        let horizontal = (rho * rho - s * s).max(0.0).sqrt();
        let distance = horizontal.hypot(v.y);
        let (near, far) = (f64::from(self.base.near), f64::from(self.base.far));
        if !(distance > 0.0 && distance >= near && distance <= far) {
            return None;
        }
        let theta = horizontal.atan2(v.y);
        // Raster, the azimuth wrapped to [-pi, pi).
        let phi = (phi + PI).rem_euclid(TAU) - PI;
        let width = f64::from(self.base.film.resolution()[0]);
        Some(Point2::new(
            (width * (phi / TAU + 0.5)) as f32,
            (row0 + self.half_height() * theta / PI) as f32,
        ))
    }

    /// The camera-space ray of a film point in a given eye's panorama.
    #[inline]
    fn ray_at(&self, eye: OdsEye, p_film: Point2<Raster>) -> Option<CameraRayParts> {
        let (origin, direction) = self.eye_ray(eye, p_film);
        Some(CameraRayParts::by_distance(origin, direction, &self.base))
    }
}

impl Camera for OdsCamera {
    #[inline]
    fn base(&self) -> &CameraBase {
        &self.base
    }

    fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        let eye = self.eye_of(sample.p_film);
        chain::generate(&self.base, &self.pose, sample, |p| self.ray_at(eye, p))
    }

    /// The neighbours stay in the main ray's eye (the row below the left eye's last one
    /// continues the left panorama, it does not jump to the right eye).
    fn generate_ray_differential(&self, sample: &CameraSample) -> Option<CameraRayDifferential> {
        let eye = self.eye_of(sample.p_film);
        chain::generate_differential(&self.base, &self.pose, sample, |p| self.ray_at(eye, p))
    }

    fn project(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
        self.project_eye(p, time, OdsEye::Left)
    }

    fn uses_lens_sample(&self) -> bool {
        false
    }
}
