//! The orthographic camera, pinhole or thin lens.

use crate::camera::{
    CameraBase, CameraRayModel, PoseFrame, ThinLens, fixed_map_of, is_unit_length,
};
use crate::error::CameraError;
use crate::projective::{ProjectiveCamera, from_rows};
use glam::{Vec2, Vec3, Vec3A};
use obscura_space::{Camera as CameraSpace, Point2, Point3, Raster, Ray, Vector3, World};

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
/// the camera centre), and every lens sample meets that ray at camera z = focal distance.
#[derive(Debug, Clone)]
pub struct OrthographicCamera {
    projective: ProjectiveCamera,
    /// Film to camera x and y in world units: `(x', y') = scale * p_raster + offset`,
    /// pose-independent (see `ProjectiveCamera::film_map`).
    film_from_raster: (Vec3A, Vec3A),
    /// The fast path's constants of a fixed pose.
    fixed: Option<OrthographicMap>,
}

/// Per-pose constants of the fast path. The film point `(x', y')` (camera space, from
/// [`OrthographicCamera`]'s pose-independent `film_from_raster`) has its ray start at world
/// `eye + R (x', y', 0) = eye + x * x' + y * y'` and run along `R z`.
///
/// Precision: the origin's camera z is 0 up to the rounding of that sum, at most about
/// `3 * 2^-24 (|x'| + |y'| + |eye|)`, small against the origin's own size. (An earlier form
/// folded the film offset into `o_1 = eye + R (offset, 0)`, whose rounding, up to
/// `2^-24 |offset|` with `|offset|` the window's half-extent, reached camera z too.)
#[derive(Debug, Clone, Copy)]
pub(crate) struct OrthographicMap {
    eye: Vec3A,
    /// World images of camera +x, +y and +z.
    x: Vec3A,
    y: Vec3A,
    axis: Vec3A,
    /// The aperture's axes: `x` and `y` again (as in `PerspectiveMap`, separate copies keep
    /// LLVM from loading them into registers before the lens test).
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
    /// shutter or lens (see [`ThinLens::validate`]).
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
        let projective =
            ProjectiveCamera::build(base, lens, (screen_from_camera, camera_from_screen), false)?;
        let mut camera = OrthographicCamera {
            film_from_raster: projective.film_map(1.0),
            projective,
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
    /// The lens.
    #[inline]
    pub fn lens(&self) -> ThinLens {
        self.projective.lens()
    }
}

impl CameraRayModel for OrthographicCamera {
    type WorldMap = OrthographicMap;

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
        // The film point (x, y) in world units; its ray starts on z = 0 and runs along +z.
        let p_camera = self.projective.film_point(p_film);
        let p_origin = Point3::new(p_camera.x, p_camera.y, 0.0);
        let d_camera = Vector3::new(0.0, 0.0, 1.0);
        if self.projective.lens().is_thin_lens() {
            self.projective.through_lens(p_origin, d_camera, u_lens)
        } else {
            self.projective.clipped(p_origin, d_camera)
        }
    }

    #[inline]
    fn world_map(&self, frame: &PoseFrame) -> OrthographicMap {
        let base = self.projective.base();
        let axis = Vec3A::from(frame.z.as_vec3());
        let length = axis.length();
        let (t_min, t_max) = if is_unit_length(length) {
            (base.near, base.far)
        } else {
            (base.near * length, base.far * length)
        };
        OrthographicMap {
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

    #[inline]
    fn fixed_map(&self) -> Option<&OrthographicMap> {
        self.fixed.as_ref()
    }

    // Always: the per-ray body; left to LLVM it fell out of line once the aperture warp
    // was inlined, costing a call and spills (perspective pinhole 84 -> 104 instructions).
    #[inline(always)]
    fn ray_world(&self, map: &OrthographicMap, p_film: Point2<Raster>, u_lens: Vec2) -> Ray<World> {
        let lens = self.projective.lens();
        // The film point in camera space (see OrthographicMap on precision), then its world
        // position eye + R (x', y', 0).
        let (film_scale, film_offset) = self.film_from_raster;
        let q = film_scale * Vec3A::new(p_film.x, p_film.y, 0.0) + film_offset;
        let p_center = map.x * q.x + map.y * q.y + map.eye;
        if !lens.is_thin_lens() {
            return Ray {
                origin: Point3::from_glam(Vec3::from(p_center)),
                direction: Vector3::from_glam(Vec3::from(map.direction)),
                time: 0.0,
                t_min: map.t_min,
                t_max: map.t_max,
            };
        }
        // Thin lens: from the lens point p_center + R (a.x, a.y, 0) to the focus point
        // p_center + focal_distance R z: direction R (-a.x, -a.y, focal_distance), whose camera
        // z is focal_distance, so camera z = near is at distance near * len / focal_distance.
        let base = self.projective.base();
        let a = lens.aperture_point(u_lens);
        let offset = map.lens_x * a.x + map.lens_y * a.y;
        let v = map.axis * lens.focal_distance - offset;
        let length = v.length();
        let per_z = length / lens.focal_distance;
        Ray {
            origin: Point3::from_glam(Vec3::from(p_center + offset)),
            direction: Vector3::from_glam(Vec3::from(v / length)),
            time: 0.0,
            t_min: base.near * per_z,
            t_max: base.far * per_z,
        }
    }
}

impl OrthographicCamera {
    /// The raster position of world point `p` at `time` (see [`Camera::project`](crate::Camera::project)).
    fn project_world(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
        let camera_from_world = self.base().pose(time).inverse();
        self.projective.project_camera(camera_from_world.point(p))
    }
}

crate::camera::camera_via_model!(OrthographicCamera, project_world);
