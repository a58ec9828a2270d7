//! The per-ray chain shared by the fisheye, cylindrical, octahedral, cube-face, ODS and OpenCV
//! (pinhole and fisheye) cameras: each model supplies only its film -> camera-space ray map
//! (and its forward map for `project`); this module does the rest of the chain the same way for
//! all of them.
//!
//! The chain: check the sample is finite -> time on the shutter -> the model's camera-space
//! origin and unit direction (None: no ray leaves this film point) -> clip range `[near, far]`
//! as a distance along the unit direction (the environment camera's rule) or a model-given
//! range -> world space through the pose at that time, direction renormalised.

use crate::camera::{
    CameraBase, CameraRay, CameraRayDifferential, CameraSample, differential, is_unit_length,
    ray_time,
};
use glam::DVec3;
use obscura_space::{
    Camera as CameraSpace, Point2, Point3, Raster, Ray, Transform, Vector3, World,
};

/// A camera-space ray as a model computes it, in f64: origin, unit direction, and the visible
/// range `[t_min, t_max]` along the unit direction.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CameraRayParts {
    /// Camera-space origin.
    pub origin: DVec3,
    /// Camera-space unit direction.
    pub direction: DVec3,
    /// Start of the visible range along the unit direction.
    pub t_min: f32,
    /// End of the visible range along the unit direction.
    pub t_max: f32,
}

impl CameraRayParts {
    /// A ray from `origin` along the unit `direction`, visible over the distances `[near, far]`.
    #[inline]
    pub(crate) fn by_distance(origin: DVec3, direction: DVec3, base: &CameraBase) -> Self {
        CameraRayParts {
            origin,
            direction,
            t_min: base.near,
            t_max: base.far,
        }
    }
}

/// The pose of a fixed camera, cached at construction with its inverse (None when it moves).
#[derive(Debug, Clone)]
pub(crate) struct PoseCache {
    fixed: Option<(Transform<World, CameraSpace>, Transform<CameraSpace, World>)>,
}

impl PoseCache {
    /// The cache for `base`'s pose.
    pub(crate) fn new(base: &CameraBase) -> PoseCache {
        let fixed = (!base.world_from_camera.is_animated()).then(|| {
            let pose = base.world_from_camera.at(0.0);
            (pose, pose.inverse())
        });
        PoseCache { fixed }
    }

    /// World from camera at `time`.
    #[inline]
    pub(crate) fn world_from_camera(
        &self,
        base: &CameraBase,
        time: f32,
    ) -> Transform<World, CameraSpace> {
        match &self.fixed {
            Some((pose, _)) => *pose,
            None => base.world_from_camera.at(time),
        }
    }

    /// Camera from world at `time`.
    #[inline]
    pub(crate) fn camera_from_world(
        &self,
        base: &CameraBase,
        time: f32,
    ) -> Transform<CameraSpace, World> {
        match &self.fixed {
            Some((_, inverse)) => *inverse,
            None => base.world_from_camera.at(time).inverse(),
        }
    }
}

/// Moves a camera-space ray to world space: the pose applied, the direction renormalised, and
/// the range rescaled when the pose stretches lengths (so it keeps the same points).
#[inline]
pub(crate) fn to_world(
    pose: &Transform<World, CameraSpace>,
    parts: CameraRayParts,
    time: f32,
) -> Ray<World> {
    let ray = Ray::new(
        Point3::from_glam(parts.origin.as_vec3()),
        Vector3::from_glam(parts.direction.as_vec3()),
        time,
    )
    .with_range(parts.t_min, parts.t_max);
    let ray = pose.ray(ray);
    let length = ray.direction.length();
    let direction = ray.direction / length;
    // A rigid pose (a look-at) changes lengths only by rounding.
    if is_unit_length(length) {
        return Ray { direction, ..ray };
    }
    Ray {
        direction,
        t_min: ray.t_min * length,
        t_max: ray.t_max * length,
        ..ray
    }
}

/// [`Camera::generate_ray`](crate::Camera::generate_ray) for a model whose camera-space ray of
/// a film point is `ray_at`.
#[inline]
pub(crate) fn generate(
    base: &CameraBase,
    pose: &PoseCache,
    sample: &CameraSample,
    ray_at: impl Fn(Point2<Raster>) -> Option<CameraRayParts>,
) -> Option<CameraRay> {
    // A finite sample, and its time on the shutter.
    let time = ray_time(base, sample)?;
    // The model's camera-space ray (None: no ray leaves this film point), clip range included.
    let parts = ray_at(sample.p_film)?;
    // World space through the pose at that time.
    let ray = to_world(&pose.world_from_camera(base, time), parts, time);
    Some(CameraRay { ray, weight: 1.0 })
}

/// [`Camera::generate_ray_differential`](crate::Camera::generate_ray_differential) for a model
/// whose camera-space ray of a film point is `ray_at`. A neighbour (one pixel right or down)
/// from which no ray leaves (past an image circle's rim) is replaced by the reflection of the
/// opposite neighbour through the main ray, `2 r(p) - r(p - e)`, so the differential keeps its
/// size at the rim; when both neighbours are missing the differential is zero.
#[inline]
pub(crate) fn generate_differential(
    base: &CameraBase,
    pose: &PoseCache,
    sample: &CameraSample,
    ray_at: impl Fn(Point2<Raster>) -> Option<CameraRayParts>,
) -> Option<CameraRayDifferential> {
    // A finite sample, and its time on the shutter.
    let time = ray_time(base, sample)?;
    // The main camera-space ray and the two neighbours.
    let p = sample.p_film;
    let main = ray_at(p)?;
    let neighbour = |dx: f32, dy: f32| -> CameraRayParts {
        if let Some(parts) = ray_at(Point2::new(p.x + dx, p.y + dy)) {
            return parts;
        }
        match ray_at(Point2::new(p.x - dx, p.y - dy)) {
            Some(opposite) => CameraRayParts {
                origin: 2.0 * main.origin - opposite.origin,
                direction: (2.0 * main.direction - opposite.direction).normalize_or(main.direction),
                ..main
            },
            None => main,
        }
    };
    let (rx, ry) = (neighbour(1.0, 0.0), neighbour(0.0, 1.0));
    // World space through one pose at that time.
    let world_from_camera = pose.world_from_camera(base, time);
    Some(differential(
        to_world(&world_from_camera, main, time),
        to_world(&world_from_camera, rx, time),
        to_world(&world_from_camera, ry, time),
    ))
}

/// The camera-space position of world point `p` at `time`, in f64.
#[inline]
pub(crate) fn camera_point(
    base: &CameraBase,
    pose: &PoseCache,
    p: Point3<World>,
    time: f32,
) -> DVec3 {
    pose.camera_from_world(base, time)
        .point(p)
        .to_glam()
        .as_dvec3()
}

/// The unit direction and distance of a camera-space point from `origin`, when its distance
/// is positive and within `[near, far]`.
#[inline]
pub(crate) fn direction_within_clip(base: &CameraBase, v: DVec3) -> Option<DVec3> {
    let distance = v.length();
    let (near, far) = (f64::from(base.near), f64::from(base.far));
    if !(distance > 0.0 && distance >= near && distance <= far) {
        return None;
    }
    Some(v / distance)
}

/// A raster position computed in f64 as the f32 point `project` returns; None when it does not
/// fit in an f32 (extreme intrinsics or distortion can carry a point past 3.4e38 pixels).
#[inline]
pub(crate) fn raster_f32(r: glam::DVec2) -> Option<Point2<Raster>> {
    let p = Point2::new(r.x as f32, r.y as f32);
    (p.x.is_finite() && p.y.is_finite()).then_some(p)
}
