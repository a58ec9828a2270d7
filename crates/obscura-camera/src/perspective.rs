//! The perspective camera, pinhole or thin lens.

use crate::camera::{
    Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample, PoseFrame, ThinLens,
    differential_at, differential_film_points, ray_time,
};
use crate::error::{CameraError, finite};
use crate::film::FovAxis;
use crate::projective::{ProjectiveCamera, from_rows};
use glam::{Vec2, Vec3, Vec3A};
use obscura_space::{Point2, Point3, Raster, Ray, Vector3, World};

/// A perspective camera: the projection plane at camera z = 1 scaled so that the field of view
/// spans the screen window's half-extent along [`FovAxis`]; rays from the eye (or, with a thin
/// lens, from a point of the aperture) through the film point, clipped to camera z in
/// `[near, far]`.
///
/// `screen_from_camera` is pbrt's perspective matrix with the scale `s = h / tan(fov / 2)`
/// (`h` the half-extent the fov spans):
///
/// ```text
/// [ s  0  0            0            ]          screen x = s x / z,  screen y = s y / z,
/// [ 0  s  0            0            ]          screen z = f (z - n) / ((f - n) z):
/// [ 0  0  f / (f - n)  -f n / (f - n)]          0 at z = n, 1 at z = f.
/// [ 0  0  1            0            ]
/// ```
///
/// Its inverse is written in closed form (last two rows `[0 0 0 1]` and
/// `[0 0 1/f - 1/n  1/n]`), so `far = 1e30` costs no precision.
#[derive(Debug, Clone)]
pub struct PerspectiveCamera {
    projective: ProjectiveCamera,
    fov_degrees: f32,
    fov_axis: FovAxis,
    /// Film to the camera plane z = 1: `(x', y') = scale * p_raster + offset` (screen x and
    /// y over `s`), pose-independent (see `ProjectiveCamera::film_map`).
    plane_from_raster: (Vec3A, Vec3A),
    /// The pose cache of a fixed pose, computed once; None when the pose moves.
    fixed: Option<PerspectiveCache>,
    /// The tilted plane of focus's slopes ([`ThinLens::tilt_slopes`]); None untilted.
    tilt: Option<Vec2>,
}

/// The per-pose cache of [`PerspectiveCamera::ray`]: the pose's linear part `R` (its columns,
/// the world images of camera +x, +y, +z) and the eye. With `q = (x', y', 1)` the film point
/// on the camera plane z = 1 (from the pose-independent `plane_from_raster`), the world
/// direction through the lens centre is `R q = x * x' + y * y' + z`: a 2D affine map and a 3x3
/// linear one instead of a 4x4 projective map with a divide and a pose transform.
///
/// The clip range follows without a divide: camera z along `R q` grows by exactly 1 per unit
/// of `R q`, so with `len = |R q|` the points at camera z = near and far are at distances
/// `near * len` and `far * len` along the unit direction (for any affine pose, scaled or not).
///
/// Precision of that "exactly 1" (u = 2^-24). `q` is formed in camera space first, so its z is
/// exactly 1, and the rounding of `x' = scale * p_raster + offset` (which cancels: `offset`
/// reaches the window's half-extent over `s` against `|q|` ~ 1 at the centre rows) only moves
/// the film point within the plane, by an f32 step of the raster position. Then `R q` rounds
/// each world component by at most `3u sum_j |R_ij| |q_j|`, a vector of length at most
/// `3 sqrt(3) u |q|`: camera z is `1 + d` with `|d| <= 5.2u |q|`, relative to the `|q|` the
/// tests measure rays by. The rounding of `len` cancels (the direction is divided by it, `t`
/// multiplied by it). Folding the film offset into a world constant would let it cancel in
/// camera z too (see docs/performance.md).
#[derive(Debug, Clone, Copy)]
struct PerspectiveCache {
    /// World images of camera +x, +y and +z.
    x: Vec3A,
    y: Vec3A,
    z: Vec3A,
    eye: Vec3A,
    /// The aperture's axes: `x` and `y` again, as separate copies so that LLVM does not load
    /// them into registers before the lens test (see docs/performance.md).
    lens_x: Vec3A,
    lens_y: Vec3A,
}

/// Checks a perspective field of view: finite and in (0, 180) degrees. What
/// [`PerspectiveCamera::new`] checks; public so that a scene layer can check its key before
/// building a camera.
pub fn validate_fov(fov_degrees: f32) -> Result<(), CameraError> {
    finite("fov", fov_degrees)?;
    if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
        return Err(CameraError::Fov { got: fov_degrees });
    }
    Ok(())
}

impl PerspectiveCamera {
    /// A perspective camera with a full field of view of `fov_degrees` along `fov_axis`.
    ///
    /// Errors: fov not in (0, 180), non-finite numbers, `near <= 0`, `near >= far`, a bad
    /// shutter or lens (see [`ThinLens::validate`]).
    pub fn new(
        base: CameraBase,
        fov_degrees: f32,
        fov_axis: FovAxis,
        lens: ThinLens,
    ) -> Result<PerspectiveCamera, CameraError> {
        validate_fov(fov_degrees)?;
        base.validate(true)?;
        let scale = fov_axis.perspective_scale(base.film.resolution(), fov_degrees);
        if !(scale as f32).is_finite() || scale as f32 <= 0.0 {
            return Err(CameraError::Fov { got: fov_degrees });
        }
        let (n, f) = (f64::from(base.near), f64::from(base.far));
        let screen_from_camera = from_rows([
            [scale, 0.0, 0.0, 0.0],
            [0.0, scale, 0.0, 0.0],
            [0.0, 0.0, f / (f - n), -f * n / (f - n)],
            [0.0, 0.0, 1.0, 0.0],
        ]);
        let camera_from_screen = from_rows([
            [1.0 / scale, 0.0, 0.0, 0.0],
            [0.0, 1.0 / scale, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0 / f - 1.0 / n, 1.0 / n],
        ]);
        let tilt = lens.is_tilted().then(|| lens.tilt_slopes());
        let projective =
            ProjectiveCamera::build(base, lens, (screen_from_camera, camera_from_screen), true)?;
        Ok(PerspectiveCamera {
            tilt,
            plane_from_raster: projective.film_map(1.0 / scale),
            fixed: projective.base().fixed_frame().map(|f| Self::cache(&f)),
            projective,
            fov_degrees,
            fov_axis,
        })
    }

    /// The projective chain (screen, NDC and raster transforms).
    #[inline]
    pub fn projective(&self) -> &ProjectiveCamera {
        &self.projective
    }
    /// The full field of view in degrees.
    #[inline]
    pub fn fov_degrees(&self) -> f32 {
        self.fov_degrees
    }
    /// The axis the field of view is measured along.
    #[inline]
    pub fn fov_axis(&self) -> FovAxis {
        self.fov_axis
    }
    /// The lens.
    #[inline]
    pub fn lens(&self) -> &ThinLens {
        self.projective.lens()
    }
}

impl PerspectiveCamera {
    /// The pose cache of a camera frame: the fixed pose's at construction, the pose's at the
    /// ray's time for a moving camera (the same function, so a moving camera at a keyframe's
    /// time gives the fixed camera's rays bit for bit).
    #[inline]
    fn cache(frame: &PoseFrame) -> PerspectiveCache {
        PerspectiveCache {
            x: frame.x.as_vec3().into(),
            y: frame.y.as_vec3().into(),
            z: frame.z.as_vec3().into(),
            eye: frame.eye.as_vec3().into(),
            lens_x: frame.x.as_vec3().into(),
            lens_y: frame.y.as_vec3().into(),
        }
    }

    /// The world ray of a film point and lens sample (time 0): where this model's rays are
    /// built, for `generate_ray` and the differentials alike. `cache` is the pose at the
    /// ray's time. Inlined always: it is the per-ray body, and out of line it costs a call and
    /// spills.
    #[inline(always)]
    fn ray(&self, cache: &PerspectiveCache, p_film: Point2<Raster>, u_lens: Vec2) -> Ray<World> {
        let base = self.projective.base();
        let lens = self.projective.lens();
        // Film point -> camera_from_raster: the affine plane map onto the plane z = 1, in
        // camera space so that its z stays exactly 1: q = (x', y', 1).
        let (plane_scale, plane_offset) = self.plane_from_raster;
        let q = plane_scale * Vec3A::new(p_film.x, p_film.y, 0.0) + plane_offset;
        // world_from_camera(t) of the pinhole direction, through the cache: R q.
        let w = cache.x * q.x + cache.y * q.y + cache.z;
        if !lens.is_thin_lens() {
            // Clip: camera z along R q grows by 1 per unit of R q (see PerspectiveCache).
            let length = w.length();
            return Ray {
                origin: Point3::from_glam(Vec3::from(cache.eye)),
                direction: Vector3::from_glam(Vec3::from(w / length)),
                time: 0.0,
                t_min: base.near * length,
                t_max: base.far * length,
            };
        }
        // Lens: the centre ray reaches the plane of focus at depth z (focal_distance, or
        // where it meets the tilted plane) at eye + z R q; the sample ray goes there from
        // the lens point eye + R (a.x, a.y, 0), along R (z q - a).
        let a = lens.aperture_point(u_lens);
        let offset = cache.lens_x * a.x + cache.lens_y * a.y;
        let focus = match self.tilt {
            None => Some(lens.focal_distance),
            Some(slopes) => lens.focus_depth(slopes, q.x, q.y),
        };
        let (v, focus) = match focus {
            Some(z) => (w * z - offset, z),
            // The centre ray never meets the tilted plane in front: in focus at infinity,
            // every lens point's ray parallel to it (camera z 1 per unit of R q).
            None => (w, 1.0),
        };
        // Clip: that direction has camera z `focus`, so camera z = near is at distance
        // near * len / focus along the unit direction.
        let length = v.length();
        let per_z = length / focus;
        // world_from_camera(t) of the origin: the lens point.
        Ray {
            origin: Point3::from_glam(Vec3::from(cache.eye + offset)),
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
        cache: &PerspectiveCache,
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

impl Camera for PerspectiveCamera {
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
            None => self.ray(
                &Self::cache(&self.projective.base().frame_at(time)),
                sample.p_film,
                sample.p_lens,
            ),
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
                &Self::cache(&self.projective.base().frame_at(time)),
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
