//! The orthographic camera, pinhole or thin lens.

use crate::camera::{
    Camera, CameraBase, CameraRay, CameraRayDifferential, CameraRayModel, CameraSample, ThinLens,
    generate, generate_differential,
};
use crate::error::CameraError;
use crate::film::{FilmGeometry, Shutter};
use crate::projective::{ProjectiveCamera, from_rows};
use obscura_space::{
    AnimatedTransform, Camera as CameraSpace, Point2, Point3, Raster, Ray, Vector3, World,
};

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
        Ok(OrthographicCamera { projective })
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
    #[inline]
    fn base(&self) -> &CameraBase {
        self.projective.base()
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
}

impl Camera for OrthographicCamera {
    #[inline]
    fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        generate(self, sample)
    }
    #[inline]
    fn generate_ray_differential(&self, sample: &CameraSample) -> Option<CameraRayDifferential> {
        generate_differential(self, sample)
    }
    fn project(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
        let camera_from_world = self.base().pose(time).inverse();
        self.projective.project_camera(camera_from_world.point(p))
    }
    #[inline]
    fn film(&self) -> &FilmGeometry {
        &self.base().film
    }
    #[inline]
    fn shutter(&self) -> Shutter {
        self.base().shutter
    }
    #[inline]
    fn world_from_camera(&self) -> &AnimatedTransform<World, CameraSpace> {
        &self.base().world_from_camera
    }
}
