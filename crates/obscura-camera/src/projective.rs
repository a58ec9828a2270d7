//! The projective chain shared by the orthographic and perspective cameras: camera, screen,
//! NDC and raster spaces, each transform stored with its inverse.

use crate::camera::{CameraBase, ThinLens};
use crate::error::CameraError;
use glam::{DMat4, DVec2, DVec3, Vec3A};
use obscura_space::{Camera as CameraSpace, Ndc, Point2, Point3, Raster, Screen, Transform};

/// The space chain of a projective camera, named the way the matrices compose:
/// `camera_from_raster = camera_from_screen * screen_from_raster`, and so on.
///
/// - Screen space: the image plane; x and y over the [screen window](crate::ScreenWindow), z
///   0 on the near plane and 1 on the far plane.
/// - NDC: `[0, 1]^2` across the screen window, y down (from the window's top edge).
/// - Raster: NDC scaled by the resolution; pixel `(i, j)` has its centre at `(i + .5, j + .5)`.
///
/// All maps except `screen_from_camera` are affine and built, with their inverses, in closed
/// form in f64 and rounded once to f32; `screen_from_camera` comes from the model (also with
/// a closed-form inverse), so far planes like `1e30` lose no precision to a numerical inverse.
#[derive(Debug, Clone)]
pub struct ProjectiveCamera {
    base: CameraBase,
    lens: ThinLens,
    screen_from_camera: Transform<Screen, CameraSpace>,
    ndc_from_screen: Transform<Ndc, Screen>,
    raster_from_ndc: Transform<Raster, Ndc>,
    raster_from_screen: Transform<Raster, Screen>,
    camera_from_raster: Transform<CameraSpace, Raster>,
    screen_from_raster_xy: (DVec2, DVec2),
}

/// Rows written as a matrix is printed, for readability of the closed forms.
pub(crate) fn from_rows(rows: [[f64; 4]; 4]) -> DMat4 {
    DMat4::from_cols_array_2d(&rows).transpose()
}

fn typed<To: obscura_space::Space, From: obscura_space::Space>(
    m: DMat4,
    m_inv: DMat4,
) -> Transform<To, From> {
    Transform::from_matrix_and_inverse(m.as_mat4(), m_inv.as_mat4())
}

impl ProjectiveCamera {
    /// The chain for a model's projection `screen_from_camera` (given in f64 with its inverse,
    /// both in closed form). Checks the base (with `near > 0` when `positive_near`), the lens,
    /// and that every map came out finite.
    pub(crate) fn build(
        base: CameraBase,
        lens: ThinLens,
        screen_from_camera: (DMat4, DMat4),
        positive_near: bool,
    ) -> Result<ProjectiveCamera, CameraError> {
        base.validate(positive_near)?;
        lens.validate()?;
        let (s_from_c, c_from_s) = screen_from_camera;
        let window = base.film.screen_window();
        let [width, height] = base.film.resolution().map(f64::from);
        let (x_min, y_max) = (f64::from(window.x_min), f64::from(window.y_max));
        let dx = f64::from(window.x_max) - x_min;
        let dy = y_max - f64::from(window.y_min);
        // NDC from screen: x from the window's left edge, y down from its top edge, z kept.
        let ndc_from_screen = DMat4::from_scale(DVec3::new(1.0 / dx, -1.0 / dy, 1.0))
            * DMat4::from_translation(DVec3::new(-x_min, -y_max, 0.0));
        let screen_from_ndc = DMat4::from_translation(DVec3::new(x_min, y_max, 0.0))
            * DMat4::from_scale(DVec3::new(dx, -dy, 1.0));
        // Raster from NDC: scale by the resolution.
        let raster_from_ndc = DMat4::from_scale(DVec3::new(width, height, 1.0));
        let ndc_from_raster = DMat4::from_scale(DVec3::new(1.0 / width, 1.0 / height, 1.0));
        let raster_from_screen = raster_from_ndc * ndc_from_screen;
        let screen_from_raster = screen_from_ndc * ndc_from_raster;
        let camera_from_raster = c_from_s * screen_from_raster;
        let raster_from_camera = raster_from_screen * s_from_c;
        let all = [
            s_from_c,
            c_from_s,
            camera_from_raster,
            raster_from_camera,
            raster_from_screen,
            screen_from_raster,
        ];
        if all.iter().any(|m| !m.as_mat4().is_finite()) {
            return Err(CameraError::ScreenWindow {
                got: window.to_array(),
            });
        }
        Ok(ProjectiveCamera {
            base,
            lens,
            screen_from_camera: typed(s_from_c, c_from_s),
            ndc_from_screen: typed(ndc_from_screen, screen_from_ndc),
            raster_from_ndc: typed(raster_from_ndc, ndc_from_raster),
            raster_from_screen: typed(raster_from_screen, screen_from_raster),
            camera_from_raster: typed(camera_from_raster, raster_from_camera),
            screen_from_raster_xy: (
                DVec2::new(dx / width, -dy / height),
                DVec2::new(x_min, y_max),
            ),
        })
    }

    /// The chain for any projection `screen_from_camera` (its inverse as stored in the
    /// transform), for models beyond the two here. Errors: an invalid base or lens, or a map
    /// that is not finite.
    pub fn new(
        base: CameraBase,
        lens: ThinLens,
        screen_from_camera: Transform<Screen, CameraSpace>,
    ) -> Result<ProjectiveCamera, CameraError> {
        let pair = (
            screen_from_camera.matrix().as_dmat4(),
            screen_from_camera.inverse_matrix().as_dmat4(),
        );
        Self::build(base, lens, pair, false)
    }

    /// The pose, shutter, film and clip range.
    #[inline]
    pub fn base(&self) -> &CameraBase {
        &self.base
    }
    /// The lens (radius 0 for a pinhole).
    #[inline]
    pub fn lens(&self) -> &ThinLens {
        &self.lens
    }
    /// Camera space to screen space: the model's projection.
    #[inline]
    pub fn screen_from_camera(&self) -> Transform<Screen, CameraSpace> {
        self.screen_from_camera
    }
    /// Screen space to camera space (closed-form inverse of the projection).
    #[inline]
    pub fn camera_from_screen(&self) -> Transform<CameraSpace, Screen> {
        self.screen_from_camera.inverse()
    }
    /// Screen space to NDC.
    #[inline]
    pub fn ndc_from_screen(&self) -> Transform<Ndc, Screen> {
        self.ndc_from_screen
    }
    /// NDC to screen space.
    #[inline]
    pub fn screen_from_ndc(&self) -> Transform<Screen, Ndc> {
        self.ndc_from_screen.inverse()
    }
    /// NDC to raster space.
    #[inline]
    pub fn raster_from_ndc(&self) -> Transform<Raster, Ndc> {
        self.raster_from_ndc
    }
    /// Raster space to NDC.
    #[inline]
    pub fn ndc_from_raster(&self) -> Transform<Ndc, Raster> {
        self.raster_from_ndc.inverse()
    }
    /// Screen space to raster space (`raster_from_ndc * ndc_from_screen`).
    #[inline]
    pub fn raster_from_screen(&self) -> Transform<Raster, Screen> {
        self.raster_from_screen
    }
    /// Raster space to screen space.
    #[inline]
    pub fn screen_from_raster(&self) -> Transform<Screen, Raster> {
        self.raster_from_screen.inverse()
    }
    /// Raster space to camera space (`camera_from_screen * screen_from_raster`): a raster point
    /// at screen z = 0 lands on the near plane.
    #[inline]
    pub fn camera_from_raster(&self) -> Transform<CameraSpace, Raster> {
        self.camera_from_raster
    }
    /// Camera space to raster space (`raster_from_screen * screen_from_camera`).
    #[inline]
    pub fn raster_from_camera(&self) -> Transform<Raster, CameraSpace> {
        self.camera_from_raster.inverse()
    }

    /// The models' film map (their camera_from_raster step): screen x and y of a raster position times `factor` (the
    /// perspective model's `1 / s`, giving the film point on the plane z = 1; 1 for the
    /// orthographic model) as `scale * p_raster + offset`, composed in f64 and rounded once,
    /// in the first two lanes of `(scale, offset)` (the third 0) so that it is one SIMD
    /// multiply and add per ray.
    ///
    /// Why the models apply it per ray in camera space rather than fold it into their pose
    /// caches: `offset` reaches the window's half-extent while the film point near the
    /// window's centre is ~1, so the affine map cancels. In camera space that cancellation
    /// only moves the film point within its plane, by an f32 step of the raster position;
    /// folded into world constants it would cancel in all three world components, the view
    /// axis included, and put the clip range (camera z) off by about `2^-24 * offset`.
    pub(crate) fn film_map(&self, factor: f64) -> (Vec3A, Vec3A) {
        let (scale, offset) = self.screen_from_raster_xy;
        (
            (scale * factor).as_vec2().extend(0.0).into(),
            (offset * factor).as_vec2().extend(0.0).into(),
        )
    }

    /// The raster position of a camera-space point, or None outside `[near, far]` in z.
    #[inline]
    pub(crate) fn project_camera(&self, p_camera: Point3<CameraSpace>) -> Option<Point2<Raster>> {
        // Written so that NaN fails the test.
        if !(p_camera.z >= self.base.near && p_camera.z <= self.base.far) {
            return None;
        }
        let p_raster = self.raster_from_camera().point(p_camera);
        Some(Point2::new(p_raster.x, p_raster.y))
    }
}
