//! The environment (equirectangular) camera.

use crate::camera::{CameraBase, CameraRayModel, PoseFrame, fixed_map_of, is_unit_length};
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
    /// The fast path's constants of a fixed pose.
    fixed: Option<EnvironmentMap>,
}

/// Per-pose constants of the fast path: the world images of the camera axes, the eye, and
/// whether the pose is rigid (then the clip range stays exactly `[near, far]`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct EnvironmentMap {
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
        let mut camera = EnvironmentCamera {
            base,
            half_turns_per_raster: Vec2::new(2.0 / width, 1.0 / height),
            fixed: None,
        };
        camera.fixed = fixed_map_of(&camera);
        Ok(camera)
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

impl CameraRayModel for EnvironmentCamera {
    type WorldMap = EnvironmentMap;

    #[inline]
    fn base(&self) -> &CameraBase {
        &self.base
    }

    #[inline]
    fn uses_lens(&self) -> bool {
        false
    }

    #[inline]
    fn ray_camera(&self, p_film: Point2<Raster>, _u_lens: glam::Vec2) -> Ray<CameraSpace> {
        Ray::new(Point3::ORIGIN, self.direction(p_film), 0.0)
            .with_range(self.base.near, self.base.far)
    }

    #[inline]
    fn world_map(&self, frame: &PoseFrame) -> EnvironmentMap {
        let (x, y, z) = (frame.x, frame.y, frame.z);
        // Rigid: orthonormal axes up to f32 rounding (what `to_world` tests per ray).
        let rigid = [x.length(), y.length(), z.length()]
            .iter()
            .all(|&l| is_unit_length(l as f32))
            && [x.dot(y), y.dot(z), z.dot(x)]
                .iter()
                .all(|d| d.abs() <= 1e-5);
        EnvironmentMap {
            x: x.as_vec3().into(),
            y: y.as_vec3().into(),
            z: z.as_vec3().into(),
            eye: frame.eye.as_vec3().into(),
            rigid,
        }
    }

    #[inline]
    fn fixed_map(&self) -> Option<&EnvironmentMap> {
        self.fixed.as_ref()
    }

    // Always: the per-ray body; left to LLVM it fell out of line once the aperture warp
    // was inlined, costing a call and spills (perspective pinhole 84 -> 104 instructions).
    #[inline(always)]
    fn ray_world(&self, map: &EnvironmentMap, p_film: Point2<Raster>, _u_lens: Vec2) -> Ray<World> {
        let d_camera = self.direction(p_film);
        let w = map.x * d_camera.x + map.y * d_camera.y + map.z * d_camera.z;
        let length = w.length();
        let (t_min, t_max) = if map.rigid {
            (self.base.near, self.base.far)
        } else {
            (self.base.near * length, self.base.far * length)
        };
        Ray {
            origin: Point3::from_glam(Vec3::from(map.eye)),
            direction: Vector3::from_glam(Vec3::from(w / length)),
            time: 0.0,
            t_min,
            t_max,
        }
    }
}

impl EnvironmentCamera {
    /// The raster position of world point `p` at `time` (see [`Camera::project`](crate::Camera::project)).
    fn project_world(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
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
}

crate::camera::camera_via_model!(EnvironmentCamera, project_world);
