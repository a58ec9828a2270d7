//! The environment (equirectangular) camera.

use crate::camera::{
    Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample, PoseFrame, differential_at,
    differential_film_points, is_unit_length, ray_time,
};
use crate::error::CameraError;
use core::f32::consts::{PI, TAU};
use glam::{Vec2, Vec3, Vec3A, Vec4};
use obscura_sample::sin_cos_pi_vec4;
use obscura_space::{Camera as CameraSpace, Point2, Point3, Raster, Ray, Vector3, World};

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
    /// Half-turns per raster unit: `2 / width` for phi, `1 / height` for theta (angles are
    /// kept in units of pi, so that [`sin_cos_pi_vec4`] reduces them exactly and the poles and the
    /// image centre get exact sines and cosines).
    half_turns_per_raster: Vec2,
    /// The pose cache of a fixed pose, computed once; None when the pose moves.
    fixed: Option<EquirectFrame>,
}

/// The per-pose cache of [`EnvironmentCamera::ray`]: the world images of the camera axes, the
/// eye, and whether the pose is rigid (then the clip range stays exactly `[near, far]`).
#[derive(Debug, Clone, Copy)]
struct EquirectFrame {
    x: Vec3A,
    y: Vec3A,
    z: Vec3A,
    eye: Vec3A,
    rigid: bool,
}

impl EnvironmentCamera {
    /// An environment camera. Errors: non-finite numbers, `near < 0`, `near >= far`, a bad
    /// shutter.
    pub fn new(base: CameraBase) -> Result<EnvironmentCamera, CameraError> {
        base.validate(false)?;
        let [width, height] = base.film.resolution().map(|r| r as f32);
        Ok(EnvironmentCamera {
            fixed: base.fixed_frame().map(|f| Self::cache(&f)),
            base,
            half_turns_per_raster: Vec2::new(2.0 / width, 1.0 / height),
        })
    }

    /// The pose, shutter, film and clip range.
    #[inline]
    pub fn base(&self) -> &CameraBase {
        &self.base
    }

    /// The camera-space unit direction of a raster position.
    #[inline]
    pub fn direction(&self, p_film: Point2<Raster>) -> Vector3<CameraSpace> {
        // Spherical angles of the raster position, in half-turns: theta / pi = y / height,
        // phi / pi = 2 x / width - 1.
        let theta = self.half_turns_per_raster.y * p_film.y;
        let phi = self.half_turns_per_raster.x * p_film.x - 1.0;
        // Both at once, in two lanes.
        let (sin, cos) = sin_cos_pi_vec4(Vec4::new(theta, phi, 0.0, 0.0));
        let (sin_theta, cos_theta, sin_phi, cos_phi) = (sin.x, cos.x, sin.y, cos.y);
        Vector3::new(sin_theta * sin_phi, cos_theta, sin_theta * cos_phi)
    }
}

impl EnvironmentCamera {
    /// The pose cache of a camera frame: the fixed pose's at construction, the pose's at the
    /// ray's time for a moving camera (the same function, so a moving camera at a keyframe's
    /// time gives the fixed camera's rays bit for bit).
    #[inline]
    fn cache(frame: &PoseFrame) -> EquirectFrame {
        let (x, y, z) = (frame.x, frame.y, frame.z);
        // Rigid: orthonormal axes up to f32 rounding.
        let rigid = [x.length(), y.length(), z.length()]
            .iter()
            .all(|&l| is_unit_length(l as f32))
            && [x.dot(y), y.dot(z), z.dot(x)]
                .iter()
                .all(|d| d.abs() <= 1e-5);
        EquirectFrame {
            x: x.as_vec3().into(),
            y: y.as_vec3().into(),
            z: z.as_vec3().into(),
            eye: frame.eye.as_vec3().into(),
            rigid,
        }
    }

    /// The world ray of a film point (time 0): where this model's rays are built, for
    /// `generate_ray` and the differentials alike. `cache` is the pose at the ray's time.
    /// Inlined always: it is the per-ray body.
    #[inline(always)]
    fn ray(&self, cache: &EquirectFrame, p_film: Point2<Raster>) -> Ray<World> {
        // Film point -> camera direction: the equirectangular map (no lens, no projection).
        let d_camera = self.direction(p_film);
        // world_from_camera(t) of the direction, through the cache.
        let w = cache.x * d_camera.x + cache.y * d_camera.y + cache.z * d_camera.z;
        // Clip: [near, far] is a distance; a pose with scale stretches it.
        let length = w.length();
        let (t_min, t_max) = if cache.rigid {
            (self.base.near, self.base.far)
        } else {
            (self.base.near * length, self.base.far * length)
        };
        Ray {
            origin: Point3::from_glam(Vec3::from(cache.eye)),
            direction: Vector3::from_glam(Vec3::from(w / length)),
            time: 0.0,
            t_min,
            t_max,
        }
    }

    /// The three rays of a differential ([`differential_film_points`]) at `time`, with `cache`
    /// the pose at that time. Calls [`Self::ray`] directly for each (no closure between), so
    /// that all three are inlined.
    #[inline(always)]
    fn differential(
        &self,
        cache: &EquirectFrame,
        sample: &CameraSample,
        time: f32,
    ) -> CameraRayDifferential {
        let [p, px, py] = differential_film_points(sample.p_film);
        differential_at(
            time,
            [self.ray(cache, p), self.ray(cache, px), self.ray(cache, py)],
        )
    }
}

impl Camera for EnvironmentCamera {
    #[inline]
    fn base(&self) -> &CameraBase {
        &self.base
    }

    #[inline]
    fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        let time = ray_time(&self.base, sample)?;
        // The call in each arm (not through one merged cache reference) lets LLVM keep the
        // fixed cache's fields where they are.
        let mut ray = match &self.fixed {
            Some(cache) => self.ray(cache, sample.p_film),
            None => self.ray(&Self::cache(&self.base.frame_at(time)), sample.p_film),
        };
        ray.time = time;
        Some(CameraRay { ray, weight: 1.0 })
    }

    #[inline]
    fn generate_ray_differential(&self, sample: &CameraSample) -> Option<CameraRayDifferential> {
        let time = ray_time(&self.base, sample)?;
        // As in generate_ray: the call in each arm keeps the fixed cache read in place.
        Some(match &self.fixed {
            Some(cache) => self.differential(cache, sample, time),
            None => self.differential(&Self::cache(&self.base.frame_at(time)), sample, time),
        })
    }

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
    fn uses_lens_sample(&self) -> bool {
        false
    }
}
