//! The perspective camera, pinhole or thin lens.

use crate::camera::{CameraBase, CameraRayModel, PoseFrame, ThinLens, fixed_map_of};
use crate::error::{CameraError, finite};
use crate::film::FovAxis;
use crate::projective::{ProjectiveCamera, from_rows};
use glam::{Vec2, Vec3, Vec3A};
use obscura_space::{Camera as CameraSpace, Point2, Point3, Raster, Ray, Vector3, World};

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
    /// The fast path's constants of a fixed pose.
    fixed: Option<PerspectiveMap>,
}

/// Per-pose constants of the fast path: the pose's linear part `R` (its columns, the world
/// images of camera +x, +y, +z) and the eye. With `q = (x', y', 1)` the film point on the camera
/// plane z = 1 (from [`PerspectiveCamera`]'s pose-independent `plane_from_raster`), the world
/// direction through the lens centre is `R q = x * x' + y * y' + z`: a 2D affine map and a 3x3
/// linear one instead of a 4x4 projective map with a divide and a pose transform.
///
/// The clip range follows without a divide: camera z along `R q` grows by exactly 1 per unit
/// of `R q`, so with `len = |R q|` the points at camera z = near and far are at distances
/// `near * len` and `far * len` along the unit direction (for any affine pose, scaled or not).
///
/// Precision of that "exactly 1" (u = 2^-24). `q` is formed in camera space first, so its z is
/// exactly 1, and the rounding of `x' = scale * p_raster + offset` (which cancels: `offset`
/// reaches the window's half-extent over `s`, e.g. 74.7 on a 4 x 528 film, against `|q|` ~ 1
/// at the centre rows) only moves the film point within the plane, by an f32 step of the raster
/// position. Then `R q` rounds each world component by at most `3u sum_j |R_ij| |q_j|`, a
/// vector of length at most `3 sqrt(3) u |q|`: camera z is `1 + d` with `|d| <= 5.2u |q|`,
/// relative to the `|q|` the tests measure rays by. The rounding of `len` cancels (the
/// direction is divided by it, `t` multiplied by it). An earlier form folded the film offset
/// into the world constant `d_1 = R (offset, 1)`, so that `w = d_x x + d_y y + d_1` cancelled in
/// all three world components, camera z included: errors of order `u |offset|`, measured at
/// 60u at the centre rows of that tall film, where the tests allow `16.8u |q|` ~ 20u.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PerspectiveMap {
    /// World images of camera +x, +y and +z.
    x: Vec3A,
    y: Vec3A,
    z: Vec3A,
    eye: Vec3A,
    /// The aperture's axes: `x` and `y` again. Separate copies measure 2 instructions fewer
    /// per pinhole ray (callgrind): with shared ones LLVM loads them into registers before the
    /// lens test.
    lens_x: Vec3A,
    lens_y: Vec3A,
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
        finite("fov", fov_degrees)?;
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(CameraError::Fov { got: fov_degrees });
        }
        base.validate(true)?;
        // The fov spans the chosen half-extent h of the window: s = h / tan(fov / 2).
        let half_extent = f64::from(fov_axis.half_extent(base.film.screen_window()));
        let scale = half_extent / (0.5 * f64::from(fov_degrees)).to_radians().tan();
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
        let projective =
            ProjectiveCamera::build(base, lens, (screen_from_camera, camera_from_screen), true)?;
        let mut camera = PerspectiveCamera {
            plane_from_raster: projective.film_map(1.0 / scale),
            projective,
            fov_degrees,
            fov_axis,
            fixed: None,
        };
        camera.fixed = fixed_map_of(&camera);
        Ok(camera)
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
    pub fn lens(&self) -> ThinLens {
        self.projective.lens()
    }
}

impl CameraRayModel for PerspectiveCamera {
    type WorldMap = PerspectiveMap;

    #[inline]
    fn base(&self) -> &CameraBase {
        self.projective.base()
    }

    #[inline]
    fn uses_lens(&self) -> bool {
        self.projective.lens().is_thin_lens()
    }

    #[inline]
    fn ray_camera(&self, p_film: Point2<Raster>, u_lens: glam::Vec2) -> Ray<CameraSpace> {
        // The film point on the near plane gives the pinhole direction from the eye.
        let p_camera = self.projective.film_point(p_film);
        let d_camera = p_camera.to_vector().normalize();
        if self.projective.lens().is_thin_lens() {
            self.projective
                .through_lens(Point3::ORIGIN, d_camera, u_lens)
        } else {
            self.projective.clipped(Point3::ORIGIN, d_camera)
        }
    }

    #[inline]
    fn world_map(&self, frame: &PoseFrame) -> PerspectiveMap {
        PerspectiveMap {
            x: frame.x.as_vec3().into(),
            y: frame.y.as_vec3().into(),
            z: frame.z.as_vec3().into(),
            eye: frame.eye.as_vec3().into(),
            lens_x: frame.x.as_vec3().into(),
            lens_y: frame.y.as_vec3().into(),
        }
    }

    #[inline]
    fn fixed_map(&self) -> Option<&PerspectiveMap> {
        self.fixed.as_ref()
    }

    // Always: the per-ray body; left to LLVM it fell out of line once the aperture warp
    // was inlined, costing a call and spills (perspective pinhole 84 -> 104 instructions).
    #[inline(always)]
    fn ray_world(&self, map: &PerspectiveMap, p_film: Point2<Raster>, u_lens: Vec2) -> Ray<World> {
        let base = self.projective.base();
        let lens = self.projective.lens();
        // The film point on the plane z = 1, in camera space so that its z stays exactly 1
        // (see PerspectiveMap on precision), then the direction through the lens centre, R q.
        let (plane_scale, plane_offset) = self.plane_from_raster;
        let q = plane_scale * Vec3A::new(p_film.x, p_film.y, 0.0) + plane_offset;
        let w = map.x * q.x + map.y * q.y + map.z;
        if !lens.is_thin_lens() {
            let length = w.length();
            return Ray {
                origin: Point3::from_glam(Vec3::from(map.eye)),
                direction: Vector3::from_glam(Vec3::from(w / length)),
                time: 0.0,
                t_min: base.near * length,
                t_max: base.far * length,
            };
        }
        // Thin lens: the centre ray reaches the plane of focus at eye + focal_distance * R q;
        // the sample ray goes there from the lens point eye + R (a.x, a.y, 0). Its direction
        // R (focal_distance q - a) has camera z focal_distance, so camera z = near is at
        // distance near * len / focal_distance along the unit direction.
        let a = lens.aperture_point(u_lens);
        let offset = map.lens_x * a.x + map.lens_y * a.y;
        let v = w * lens.focal_distance - offset;
        let length = v.length();
        let per_z = length / lens.focal_distance;
        Ray {
            origin: Point3::from_glam(Vec3::from(map.eye + offset)),
            direction: Vector3::from_glam(Vec3::from(v / length)),
            time: 0.0,
            t_min: base.near * per_z,
            t_max: base.far * per_z,
        }
    }
}

impl PerspectiveCamera {
    /// The raster position of world point `p` at `time` (see [`Camera::project`](crate::Camera::project)).
    fn project_world(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
        let camera_from_world = self.base().pose(time).inverse();
        self.projective.project_camera(camera_from_world.point(p))
    }
}

crate::camera::camera_via_model!(PerspectiveCamera, project_world);
