//! The environment (equirectangular) camera.

use crate::camera::{
    Camera, CameraBase, CameraRay, CameraRayDifferential, CameraRayModel, CameraSample, generate,
    generate_differential,
};
use crate::error::CameraError;
use crate::film::{FilmGeometry, Shutter};
use core::f32::consts::{PI, TAU};
use obscura_space::{
    AnimatedTransform, Camera as CameraSpace, Point2, Point3, Raster, Ray, Vector3, World,
};

/// A 360 x 180 degree camera: every ray starts at the eye, and raster `(x, y)` maps to the
/// direction of SCENE_FORMAT.md, polar angle `theta = pi * y / height` from camera +y and
/// azimuth `phi = 2 pi (x / width - 0.5)` from camera +z towards camera +x:
///
/// `d = (sin theta sin phi, cos theta, sin theta cos phi)`.
///
/// The image centre looks along +z (the view direction), the top row up (+y) and the right
/// half right (+x; the camera frame is left-handed in the world, so this is the image's right
/// as seen by the viewer). There is no projection matrix, and the screen window is unused.
/// `[t_min, t_max] = [near, far]` is a distance, since directions are unit.
#[derive(Debug, Clone)]
pub struct EnvironmentCamera {
    base: CameraBase,
}

impl EnvironmentCamera {
    /// An environment camera. Errors: non-finite numbers, `near < 0`, `near >= far`, a bad
    /// shutter.
    pub fn new(base: CameraBase) -> Result<EnvironmentCamera, CameraError> {
        base.validate(false)?;
        Ok(EnvironmentCamera { base })
    }

    /// The pose, shutter, film and clip range.
    #[inline]
    pub fn base(&self) -> &CameraBase {
        &self.base
    }

    /// The camera-space unit direction of a raster position.
    #[inline]
    pub fn direction(&self, p_film: Point2<Raster>) -> Vector3<CameraSpace> {
        let [width, height] = self.base.film.resolution().map(|r| r as f32);
        // Spherical angles of the raster position.
        let theta = PI * p_film.y / height;
        let phi = TAU * (p_film.x / width - 0.5);
        let (sin_theta, cos_theta) = theta.sin_cos();
        let (sin_phi, cos_phi) = phi.sin_cos();
        Vector3::new(sin_theta * sin_phi, cos_theta, sin_theta * cos_phi)
    }
}

impl CameraRayModel for EnvironmentCamera {
    #[inline]
    fn base(&self) -> &CameraBase {
        &self.base
    }

    #[inline]
    fn ray_camera(&self, p_film: Point2<Raster>, _u_lens: glam::Vec2) -> Ray<CameraSpace> {
        Ray::new(Point3::ORIGIN, self.direction(p_film), 0.0)
            .with_range(self.base.near, self.base.far)
    }
}

impl Camera for EnvironmentCamera {
    #[inline]
    fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        generate(self, sample)
    }
    #[inline]
    fn generate_ray_differential(&self, sample: &CameraSample) -> Option<CameraRayDifferential> {
        generate_differential(self, sample)
    }
    /// The inverse mapping: `theta = acos(d.y)`, `phi = atan2(d.x, d.z)` in `(-pi, pi]`, so `x`
    /// lies in `(0, width]` (the seam `phi = pi` goes to the right edge) and `y` in
    /// `[0, height]`. None at the eye or outside `[near, far]` in distance.
    fn project(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
        let camera_from_world = self.base.pose(time).inverse();
        let v_camera = camera_from_world.point(p).to_vector();
        let distance = v_camera.length();
        if !(distance > 0.0 && distance >= self.base.near && distance <= self.base.far) {
            return None;
        }
        let d_camera = v_camera / distance;
        let theta = d_camera.y.clamp(-1.0, 1.0).acos();
        let phi = d_camera.x.atan2(d_camera.z);
        let [width, height] = self.base.film.resolution().map(|r| r as f32);
        Some(Point2::new(width * (phi / TAU + 0.5), height * theta / PI))
    }
    #[inline]
    fn film(&self) -> &FilmGeometry {
        &self.base.film
    }
    #[inline]
    fn shutter(&self) -> Shutter {
        self.base.shutter
    }
    #[inline]
    fn world_from_camera(&self) -> &AnimatedTransform<World, CameraSpace> {
        &self.base.world_from_camera
    }
}
