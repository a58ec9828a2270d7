//! The orthographic camera, pinhole or thin lens.

use crate::camera::{
    Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample, PoseFrame, ThinLens,
    differential_at, differential_film_points, is_unit_length, ray_time,
};
use crate::error::CameraError;
use crate::projective::{ProjectiveCamera, from_rows};
use glam::{Vec2, Vec3, Vec3A};
use obscura_space::{Point2, Point3, Raster, Ray, Vector3, World};

/// An orthographic camera: a parallel projection of the box between `near` and `far` whose
/// cross-section is the screen window, in camera-space world units. Rays start on the plane
/// camera z = 0 at the film point and run along +z; `t` (the camera z) is clipped to
/// `[near, far]`, and `near` may be 0.
///
/// `screen_from_camera` keeps x and y and maps z from `[near, far]` to `[0, 1]`:
///
/// ```text
/// [ 1 0 0        0           ]        inverse:  [ 1 0 0      0 ]
/// [ 0 1 0        0           ]                  [ 0 1 0      0 ]
/// [ 0 0 1/(f-n)  -n/(f-n)    ]                  [ 0 0 f - n  n ]
/// [ 0 0 0        1           ]                  [ 0 0 0      1 ]
/// ```
///
/// With a thin lens the lens point is offset from the film point's own ray origin (not from
/// the camera centre), and every lens sample meets that ray at camera z = focal distance, or,
/// with the plane of focus tilted by `[a, b]` ([`ThinLens::focal_plane_tilt`]), where the ray
/// meets the plane `z = focal_distance + y tan(a) + x tan(b)`: at the film point `(x, y)`'s own
/// depth `focal_distance + x tan(b) + y tan(a)`.
#[derive(Debug, Clone)]
pub struct OrthographicCamera {
    projective: ProjectiveCamera,
    /// Film to camera x and y in world units: `(x', y') = scale * p_raster + offset`,
    /// pose-independent (see `ProjectiveCamera::film_map`).
    film_from_raster: (Vec3A, Vec3A),
    /// The pose cache of a fixed pose, computed once; None when the pose moves.
    fixed: Option<OrthographicCache>,
    /// The tilted plane of focus's slopes ([`ThinLens::tilt_slopes`]); None untilted.
    tilt: Option<Vec2>,
}

/// The per-pose cache of [`OrthographicCamera::ray`]. The film point `(x', y')` (camera
/// space, from the pose-independent `film_from_raster`) has its ray start at world
/// `eye + R (x', y', 0) = eye + x * x' + y * y'` and run along `R z`.
///
/// Precision: the origin's camera z is 0 up to the rounding of that sum, at most about
/// `3 * 2^-24 (|x'| + |y'| + |eye|)`, small against the origin's own size; the film offset is
/// kept out of the world constants so that its cancellation stays within the film plane.
#[derive(Debug, Clone, Copy)]
struct OrthographicCache {
    eye: Vec3A,
    /// World images of camera +x, +y and +z.
    x: Vec3A,
    y: Vec3A,
    axis: Vec3A,
    /// The aperture's axes: `x` and `y` again (as in the perspective cache, separate copies
    /// keep LLVM from loading them into registers before the lens test).
    lens_x: Vec3A,
    lens_y: Vec3A,
    /// `axis` normalised, and the distances to camera z = near and far along it: exactly
    /// `[near, far]` when the pose is rigid (`|axis|` is 1 up to rounding).
    direction: Vec3A,
    t_min: f32,
    t_max: f32,
}

impl OrthographicCamera {
    /// An orthographic camera. Errors: non-finite numbers, `near < 0`, `near >= far`, a bad
    /// shutter or lens (see [`ThinLens::validate`]; a tilt needs a thin lens).
    pub fn new(base: CameraBase, lens: ThinLens) -> Result<OrthographicCamera, CameraError> {
        base.validate(false)?;
        let (n, f) = (f64::from(base.near), f64::from(base.far));
        let screen_from_camera = from_rows([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0 / (f - n), -n / (f - n)],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let camera_from_screen = from_rows([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, f - n, n],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let tilt = lens.is_tilted().then(|| lens.tilt_slopes());
        let projective =
            ProjectiveCamera::build(base, lens, (screen_from_camera, camera_from_screen), false)?;
        let fixed = projective
            .base()
            .fixed_frame()
            .map(|f| Self::cache(projective.base(), &f));
        Ok(OrthographicCamera {
            film_from_raster: projective.film_map(1.0),
            projective,
            fixed,
            tilt,
        })
    }

    /// The projective chain (screen, NDC and raster transforms).
    #[inline]
    pub fn projective(&self) -> &ProjectiveCamera {
        &self.projective
    }
    /// The lens.
    #[inline]
    pub fn lens(&self) -> &ThinLens {
        self.projective.lens()
    }
}

impl OrthographicCamera {
    /// The pose cache of a camera frame: the fixed pose's at construction, the pose's at the
    /// ray's time for a moving camera (the same function, so a moving camera at a keyframe's
    /// time gives the fixed camera's rays bit for bit).
    #[inline]
    fn cache(base: &CameraBase, frame: &PoseFrame) -> OrthographicCache {
        let axis = Vec3A::from(frame.z.as_vec3());
        let length = axis.length();
        let (t_min, t_max) = if is_unit_length(length) {
            (base.near, base.far)
        } else {
            (base.near * length, base.far * length)
        };
        OrthographicCache {
            eye: frame.eye.as_vec3().into(),
            x: frame.x.as_vec3().into(),
            y: frame.y.as_vec3().into(),
            lens_x: frame.x.as_vec3().into(),
            lens_y: frame.y.as_vec3().into(),
            axis,
            direction: axis / length,
            t_min,
            t_max,
        }
    }

    /// The world ray of a film point and lens sample (time 0): where this model's rays are
    /// built, for `generate_ray` and the differentials alike. `cache` is the pose at the
    /// ray's time. Inlined always: it is the per-ray body.
    #[inline(always)]
    fn ray(&self, cache: &OrthographicCache, p_film: Point2<Raster>, u_lens: Vec2) -> Ray<World> {
        let lens = self.projective.lens();
        // Film point -> camera_from_raster: the affine plane map to camera (x', y') in world
        // units (see OrthographicCache on precision).
        let (film_scale, film_offset) = self.film_from_raster;
        let q = film_scale * Vec3A::new(p_film.x, p_film.y, 0.0) + film_offset;
        // world_from_camera(t) of the film point, through the cache: eye + R (x', y', 0).
        let p_center = cache.x * q.x + cache.y * q.y + cache.eye;
        if !lens.is_thin_lens() {
            // Clip: along R z, [near, far] was scaled once in the cache.
            return Ray {
                origin: Point3::from_glam(Vec3::from(p_center)),
                direction: Vector3::from_glam(Vec3::from(cache.direction)),
                time: 0.0,
                t_min: cache.t_min,
                t_max: cache.t_max,
            };
        }
        // Lens: from the lens point p_center + R (a.x, a.y, 0) to the focus point
        // p_center + z R z, along R (-a.x, -a.y, z), with z the focal distance or the film
        // point's depth on the tilted plane.
        let base = self.projective.base();
        let a = lens.aperture_point(u_lens);
        let offset = cache.lens_x * a.x + cache.lens_y * a.y;
        let focus = match self.tilt {
            None => Some(lens.focal_distance),
            Some(slopes) => {
                let z = lens.focal_distance + q.x * slopes.x + q.y * slopes.y;
                (z > 0.0 && z.is_finite()).then_some(z)
            }
        };
        let (v, focus) = match focus {
            Some(z) => (cache.axis * z - offset, z),
            // The tilted plane is behind the film point: in focus at infinity, every lens
            // point's ray along R z.
            None => (cache.axis, 1.0),
        };
        // Clip: that direction has camera z `focus`, so camera z = near is at distance
        // near * len / focus along the unit direction.
        let length = v.length();
        let per_z = length / focus;
        // world_from_camera(t) of the origin: the lens point.
        Ray {
            origin: Point3::from_glam(Vec3::from(p_center + offset)),
            direction: Vector3::from_glam(Vec3::from(v / length)),
            time: 0.0,
            t_min: base.near * per_z,
            t_max: base.far * per_z,
        }
    }

    /// The three rays of a differential ([`differential_film_points`]) at `time`, with `cache`
    /// the pose at that time. Calls [`Self::ray`] directly for each (no closure between), so
    /// that all three are inlined.
    #[inline(always)]
    fn differential(
        &self,
        cache: &OrthographicCache,
        sample: &CameraSample,
        time: f32,
    ) -> CameraRayDifferential {
        let [p, px, py] = differential_film_points(sample.p_film);
        differential_at(
            time,
            [
                self.ray(cache, p, sample.p_lens),
                self.ray(cache, px, sample.p_lens),
                self.ray(cache, py, sample.p_lens),
            ],
        )
    }
}

impl Camera for OrthographicCamera {
    #[inline]
    fn base(&self) -> &CameraBase {
        self.projective.base()
    }

    #[inline]
    fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        let time = ray_time(self.base(), sample)?;
        // The call in each arm (not through one merged cache reference) lets LLVM keep the
        // fixed cache's fields where they are.
        let mut ray = match &self.fixed {
            Some(cache) => self.ray(cache, sample.p_film, sample.p_lens),
            None => {
                let base = self.projective.base();
                let cache = Self::cache(base, &base.frame_at(time));
                self.ray(&cache, sample.p_film, sample.p_lens)
            }
        };
        ray.time = time;
        Some(CameraRay { ray, weight: 1.0 })
    }

    #[inline]
    fn generate_ray_differential(&self, sample: &CameraSample) -> Option<CameraRayDifferential> {
        let time = ray_time(self.base(), sample)?;
        // As in generate_ray: the call in each arm keeps the fixed cache read in place.
        Some(match &self.fixed {
            Some(cache) => self.differential(cache, sample, time),
            None => self.differential(
                &{
                    let base = self.projective.base();
                    Self::cache(base, &base.frame_at(time))
                },
                sample,
                time,
            ),
        })
    }

    fn project(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
        let camera_from_world = self.projective.base().pose(time).inverse();
        self.projective.project_camera(camera_from_world.point(p))
    }

    #[inline]
    fn uses_lens_sample(&self) -> bool {
        self.projective.lens().is_thin_lens()
    }
}
