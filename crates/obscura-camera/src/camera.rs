//! The `Camera` trait, the samples it takes and the rays it gives, and what all models share:
//! the pose, the shutter, the film and the clip range.

use crate::aperture::Aperture;
use crate::error::{CameraError, finite};
use crate::film::{FilmGeometry, Shutter, validate_clip};
use crate::shutter::ShutterTiming;
use glam::DVec3;
use obscura_sample::SampleStream;
use obscura_space::{
    AnimatedTransform, Camera as CameraSpace, Point2, Point3, Raster, Ray, Transform, Vector3,
    World,
};

/// The default near clip distance of the scene format.
pub const DEFAULT_NEAR: f32 = 0.001;
/// The default far clip distance of the scene format (effectively none).
pub const DEFAULT_FAR: f32 = 1.0e30;

/// The canonical numbers one camera ray is made from, filled in by the sampler.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraSample {
    /// The film position in raster space (pixel `(i, j)` covers `[i, i+1) x [j, j+1)`).
    pub p_film: Point2<Raster>,
    /// The lens sample in `[0, 1)^2`, warped onto the aperture by the camera.
    pub p_lens: glam::Vec2,
    /// The time sample `u` in `[0, 1)`, mapped onto the shutter interval by the camera.
    pub time: f32,
}

impl CameraSample {
    /// The sample of pixel `pixel` drawn from `stream`: the film position inside the pixel,
    /// the lens sample only when `lens` and the time only when `time` (else the lens centre
    /// and time 0, as [`CameraSample::at`]), from the stream's camera dimensions (see
    /// [`SampleStream::camera_with`]). Pass the camera's [`Camera::uses_lens_sample`] and
    /// [`Camera::uses_time_sample`]: a dimension the camera ignores is then not computed.
    #[inline]
    pub fn from_stream(
        stream: &mut SampleStream<'_>,
        pixel: [u32; 2],
        lens: bool,
        time: bool,
    ) -> CameraSample {
        let (film, p_lens, time) = stream.camera_with(lens, time);
        let p_film = glam::Vec2::new(pixel[0] as f32, pixel[1] as f32) + film;
        CameraSample {
            p_film: Point2::from_glam(p_film),
            p_lens,
            time,
        }
    }

    /// A sample at a film position through the lens centre at shutter open: what a pinhole
    /// camera needs.
    pub fn at(p_film: Point2<Raster>) -> Self {
        CameraSample {
            p_film,
            p_lens: glam::Vec2::splat(0.5),
            time: 0.0,
        }
    }
}

/// A world-space ray with a unit direction, its `[t_min, t_max]` the visible range, and the
/// weight the radiance along it gets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraRay {
    /// The ray; `t` is a distance along it, since the direction is unit length.
    pub ray: Ray<World>,
    /// The ray's weight: 1 for every model but the realistic camera, whose weight carries
    /// its radiometry (see [`RealisticCamera`](crate::RealisticCamera)).
    pub weight: f32,
}

/// A camera ray with the rays of the film positions one pixel to the right (`rx`) and one
/// pixel down (`ry`), with the same lens sample and time. Directions are unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraRayDifferential {
    /// The main ray, as [`Camera::generate_ray`] gives it.
    pub ray: Ray<World>,
    /// Origin of the ray one pixel to the right.
    pub rx_origin: Point3<World>,
    /// Direction of the ray one pixel to the right.
    pub rx_direction: Vector3<World>,
    /// Origin of the ray one pixel down.
    pub ry_origin: Point3<World>,
    /// Direction of the ray one pixel down.
    pub ry_direction: Vector3<World>,
    /// The main ray's weight.
    pub weight: f32,
}

/// True when `origin` is finite and `direction` a unit vector to 1e-3: a ray a renderer can
/// trace (a NaN direction fails the comparison too).
///
/// Written without branches, since every camera ray through [`AnyCamera`](crate::AnyCamera)
/// takes it: `0 x` is 0 for a finite `x` and NaN for an infinite or NaN one, so the sum of
/// the three is 0 exactly when the origin is finite.
#[inline]
pub(crate) fn traceable(origin: Point3<World>, direction: Vector3<World>) -> bool {
    let (o, d) = (origin.to_glam(), direction.to_glam());
    let finite = (o * 0.0).element_sum() == 0.0;
    let unit = (d.length_squared() - 1.0).abs() <= 1e-3;
    finite & unit
}

/// A camera model: rays from samples, and the inverse, world points to raster positions.
pub trait Camera: Send + Sync {
    /// The world-space ray of a sample, at time `shutter().time_at(sample.time)`, with a unit
    /// direction and `[t_min, t_max]` set to the camera's clip range. `None` when the sample
    /// gives no ray (a non-finite film position). Through [`AnyCamera`](crate::AnyCamera),
    /// also `None` when the numbers overflow or underflow (a film position far outside the
    /// image, or lens and focus sizes near 1e-22): its rays always have finite origins and
    /// unit directions.
    fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay>;

    /// [`Camera::generate_ray`] plus the rays one pixel right and one pixel down, with the same
    /// lens sample and time.
    fn generate_ray_differential(&self, sample: &CameraSample) -> Option<CameraRayDifferential>;

    /// Raster position of a world point at `time` (pinhole through the lens centre). None when
    /// no ray of the camera can see it (behind a projective camera / outside [near, far] / at the
    /// origin); positions outside the image rectangle ARE returned (renderers use them for
    /// screen velocities).
    fn project(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>>;

    /// What every model has: the pose over the shutter, the shutter, the film and the clip
    /// range. The accessors below read it.
    fn base(&self) -> &CameraBase;

    /// The film geometry: resolution, screen window, crop.
    #[inline]
    fn film(&self) -> &FilmGeometry {
        &self.base().film
    }

    /// The shutter interval.
    #[inline]
    fn shutter(&self) -> Shutter {
        self.base().shutter
    }

    /// The camera's pose over the shutter interval.
    #[inline]
    fn world_from_camera(&self) -> &AnimatedTransform<World, CameraSpace> {
        &self.base().world_from_camera
    }

    /// Whether rays depend on [`CameraSample::p_lens`]: true for a thin lens with an
    /// aperture. When false, every lens sample gives the same ray, so a renderer may leave
    /// `p_lens` at [`CameraSample::at`]'s lens centre instead of drawing it. The default,
    /// true, is always safe.
    fn uses_lens_sample(&self) -> bool {
        true
    }

    /// Whether rays depend on [`CameraSample::time`]: true when the shutter stays open over
    /// an interval. When false, every time sample maps to the opening time (`time_at(u)` is
    /// `open + u * 0`), so a renderer may leave `time` at 0 instead of drawing it.
    fn uses_time_sample(&self) -> bool {
        let shutter = self.shutter();
        shutter.open < shutter.close
    }
}

/// Checks a `focal_plane_tilt` (degrees about camera x and y): each angle finite and in
/// (-90, 90).
pub(crate) fn validate_tilt(tilt: [f32; 2]) -> Result<(), CameraError> {
    if tilt.iter().all(|a| a.is_finite() && a.abs() < 90.0) {
        Ok(())
    } else {
        Err(CameraError::FocalPlaneTilt { got: tilt })
    }
}

/// The slopes `(tan(b), tan(a))` of the plane of focus tilted by `[a, b]` degrees: its z
/// grows by these per unit of x and y.
pub(crate) fn tilt_slopes(tilt: [f32; 2]) -> glam::DVec2 {
    let [a, b] = tilt.map(|d| f64::from(d).to_radians().tan());
    glam::DVec2::new(b, a)
}

/// A thin lens: the aperture radius, the distance of the plane in focus, the aperture's
/// shape, and (perspective and orthographic) the tilt of the plane of focus.
///
/// With a tilt `[a, b]` (degrees about camera x, then y) the plane of focus is
/// `z = focal_distance + y tan(a) + x tan(b)` in camera space (Scheimpflug): the plane
/// `z = focal_distance` turned by `a` about the x-parallel line through `(0, 0,
/// focal_distance)` and by `b` about the y-parallel one. A positive `a` moves its top away
/// from the camera (a table top seen from above is sharp front to back), a positive `b` its
/// right side.
#[derive(Debug, Clone, PartialEq)]
pub struct ThinLens {
    /// Aperture radius in camera-space units; 0 is a pinhole.
    pub radius: f32,
    /// Camera-space z of the plane in perfect focus (on the optical axis, when tilted); > 0.
    pub focal_distance: f32,
    /// The aperture's shape in units of the radius.
    pub aperture: Aperture,
    /// The plane of focus's tilt in degrees about camera x and camera y, each in (-90, 90);
    /// `[0, 0]` for none.
    pub focal_plane_tilt: [f32; 2],
}

impl ThinLens {
    /// The pinhole: radius 0 (the focal distance then does not matter).
    pub const PINHOLE: ThinLens = ThinLens {
        radius: 0.0,
        focal_distance: 1.0,
        aperture: Aperture::CIRCLE,
        focal_plane_tilt: [0.0, 0.0],
    };

    /// A round thin lens. Errors as [`ThinLens::validate`].
    pub fn new(radius: f32, focal_distance: f32) -> Result<ThinLens, CameraError> {
        let lens = ThinLens {
            radius,
            focal_distance,
            ..ThinLens::PINHOLE
        };
        lens.validate()?;
        Ok(lens)
    }

    /// The same lens with a polygonal aperture of `blades` blades rotated by `rotation_degrees`
    /// (0 blades for round). Errors as [`ThinLens::validate`].
    pub fn with_blades(self, blades: u32, rotation_degrees: f32) -> Result<ThinLens, CameraError> {
        let aperture = Aperture {
            anamorphic: self.aperture.anamorphic,
            ..Aperture::polygon(blades, rotation_degrees)?
        };
        self.with_aperture(aperture)
    }

    /// The same lens with another aperture. Errors as [`ThinLens::validate`].
    pub fn with_aperture(self, aperture: Aperture) -> Result<ThinLens, CameraError> {
        let lens = ThinLens { aperture, ..self };
        lens.validate()?;
        Ok(lens)
    }

    /// The same lens with its plane of focus tilted by `degrees` about camera x and y (see
    /// [`ThinLens`]). Errors as [`ThinLens::validate`].
    pub fn with_tilt(self, degrees: [f32; 2]) -> Result<ThinLens, CameraError> {
        let lens = ThinLens {
            focal_plane_tilt: degrees,
            ..self
        };
        lens.validate()?;
        Ok(lens)
    }

    /// Checks the parameters: finite numbers, `radius >= 0`, `focal_distance > 0`, a valid
    /// aperture ([`Aperture::validate`]), tilt angles in (-90, 90) degrees, and no tilt on a
    /// pinhole.
    pub fn validate(&self) -> Result<(), CameraError> {
        finite("lens_radius", self.radius)?;
        finite("focal_distance", self.focal_distance)?;
        if self.radius < 0.0 {
            return Err(CameraError::LensRadius { got: self.radius });
        }
        if self.focal_distance <= 0.0 {
            return Err(CameraError::FocalDistance {
                got: self.focal_distance,
            });
        }
        self.aperture.validate()?;
        validate_tilt(self.focal_plane_tilt)?;
        if self.is_tilted() && !self.is_thin_lens() {
            return Err(CameraError::TiltWithoutLens);
        }
        Ok(())
    }

    /// True when the lens has an aperture (radius > 0).
    #[inline]
    pub fn is_thin_lens(&self) -> bool {
        self.radius > 0.0
    }

    /// True when the plane of focus is tilted.
    #[inline]
    pub fn is_tilted(&self) -> bool {
        self.focal_plane_tilt != [0.0, 0.0]
    }

    /// The tilted plane's slopes `(tan(b), tan(a))`: camera z on the plane of focus grows by
    /// these per unit of camera x and y.
    pub fn tilt_slopes(&self) -> glam::Vec2 {
        tilt_slopes(self.focal_plane_tilt).as_vec2()
    }

    /// The camera-space z at which the ray through the lens centre with camera-space
    /// direction `(x, y, 1)` meets the plane of focus: `focal_distance` untilted, else
    /// `focal_distance / (1 - x tan(b) - y tan(a))`, or None when that ray never meets the
    /// plane in front of the lens (it is then in focus at infinity).
    #[inline]
    pub fn focus_depth(&self, slopes: glam::Vec2, x: f32, y: f32) -> Option<f32> {
        let denominator = 1.0 - x * slopes.x - y * slopes.y;
        let z = self.focal_distance / denominator;
        (denominator > 0.0 && z.is_finite()).then_some(z)
    }

    /// The point of the aperture (camera space, on the plane z = 0) of a lens sample in
    /// `[0, 1)^2`: [`Aperture::sample`] scaled by the radius.
    #[inline]
    pub fn aperture_point(&self, u: glam::Vec2) -> glam::Vec2 {
        self.radius * self.aperture.sample(u)
    }
}

impl Default for ThinLens {
    fn default() -> Self {
        ThinLens::PINHOLE
    }
}

/// What every camera model has: its pose over the shutter, the shutter, the film and the clip
/// range (camera-space z for projective cameras, distance for the environment camera).
#[derive(Debug, Clone)]
pub struct CameraBase {
    /// The pose: camera space to world space, evaluated at each ray's time.
    pub world_from_camera: AnimatedTransform<World, CameraSpace>,
    /// The shutter interval.
    pub shutter: Shutter,
    /// The film geometry.
    pub film: FilmGeometry,
    /// Near clip (>= 0; > 0 for perspective).
    pub near: f32,
    /// Far clip (> near, finite; [`DEFAULT_FAR`] for "none").
    pub far: f32,
    /// How ray times spread over the shutter: curve and rolling shutter (uniform by default).
    pub timing: ShutterTiming,
}

impl CameraBase {
    /// A base with the default clip range [`DEFAULT_NEAR`], [`DEFAULT_FAR`].
    pub fn new(
        world_from_camera: AnimatedTransform<World, CameraSpace>,
        shutter: Shutter,
        film: FilmGeometry,
    ) -> CameraBase {
        CameraBase {
            world_from_camera,
            shutter,
            film,
            near: DEFAULT_NEAR,
            far: DEFAULT_FAR,
            timing: ShutterTiming::default(),
        }
    }

    /// The same base with a shutter curve or rolling shutter (checked by the camera
    /// constructors).
    pub fn with_timing(self, timing: ShutterTiming) -> CameraBase {
        CameraBase { timing, ..self }
    }

    /// The same base with the clip range `[near, far]` (checked by the camera constructors).
    pub fn with_clip(self, near: f32, far: f32) -> CameraBase {
        CameraBase { near, far, ..self }
    }

    /// Checks the pose, the shutter and the clip range; `positive_near` refuses `near == 0`.
    /// The pose must be affine at every keyframe (a projective pose has no camera frame to
    /// build rays from; look-at poses and their interpolations are always affine).
    pub(crate) fn validate(&self, positive_near: bool) -> Result<(), CameraError> {
        if self
            .world_from_camera
            .keyframes()
            .any(|(_, key)| key.matrix().row(3) != glam::Vec4::W)
        {
            return Err(CameraError::ProjectivePose);
        }
        Shutter::new(self.shutter.open, self.shutter.close)?;
        self.timing.validate(self.shutter)?;
        validate_clip(self.near, self.far, positive_near)
    }

    /// The pose at `time`, with its inverse (for `project`).
    #[inline]
    pub(crate) fn pose(&self, time: f32) -> Transform<World, CameraSpace> {
        self.world_from_camera.at(time)
    }

    /// The camera frame of the pose at `time`: the forward matrix only (a moving pose skips
    /// the interpolated inverse). Affine, as [`CameraBase::validate`] checked.
    #[inline]
    pub(crate) fn frame_at(&self, time: f32) -> PoseFrame {
        PoseFrame::of(self.world_from_camera.matrix_at(time))
    }

    /// The camera frame of a fixed pose, None for a moving one: what the models turn into
    /// their per-pose cache at construction.
    pub(crate) fn fixed_frame(&self) -> Option<PoseFrame> {
        (!self.world_from_camera.is_animated()).then(|| self.frame_at(0.0))
    }
}

/// A look-at: the camera at `eye` looks towards `target`, with `up` towards the image's top.
/// World space throughout.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LookAt {
    /// The camera position.
    pub eye: Point3<World>,
    /// A point the camera looks at (the image centre).
    pub target: Point3<World>,
    /// The up direction; need not be unit length or orthogonal to the view.
    pub up: Vector3<World>,
}

impl LookAt {
    /// The look-at from `eye` towards `target` with `up`.
    pub const fn new(eye: Point3<World>, target: Point3<World>, up: Vector3<World>) -> LookAt {
        LookAt { eye, target, up }
    }

    /// The camera pose of this look-at. Errors: `eye == target`, `up` parallel to the view,
    /// non-finite numbers.
    pub fn pose(&self) -> Result<Transform<World, CameraSpace>, CameraError> {
        Ok(Transform::look_at(self.eye, self.target, self.up)?)
    }
}

/// Camera pose from look-at at shutter open and, optionally, at shutter close (the scene
/// format's `eye_end`, `target_end`, `up_end`). The result is fixed when `end` is None or the
/// shutter is instantaneous (`open == close`; the start pose is then used).
///
/// The camera frame is left-handed in the right-handed world (determinant -1); both keyframes
/// share that, so they interpolate rigidly. Errors: a degenerate look-at (eye == target, up
/// parallel to the view, non-finite numbers).
pub fn look_at_pose(
    start: LookAt,
    end: Option<LookAt>,
    shutter: Shutter,
) -> Result<AnimatedTransform<World, CameraSpace>, CameraError> {
    let start_pose = start.pose()?;
    match end {
        Some(end) if shutter.open < shutter.close => {
            let end_pose = end.pose()?;
            Ok(AnimatedTransform::new(
                start_pose,
                shutter.open,
                end_pose,
                shutter.close,
            )?)
        }
        _ => Ok(AnimatedTransform::fixed(start_pose)),
    }
}

/// Assembles a differential from three world rays.
#[inline]
pub(crate) fn differential(
    ray: Ray<World>,
    rx: Ray<World>,
    ry: Ray<World>,
) -> CameraRayDifferential {
    CameraRayDifferential {
        ray,
        rx_origin: rx.origin,
        rx_direction: rx.direction,
        ry_origin: ry.origin,
        ry_direction: ry.direction,
        weight: 1.0,
    }
}

/// The affine part of a pose, `p_world = x * p.x + y * p.y + z * p.z + eye`, in f64 so that the
/// per-pose constants the models derive from it are rounded to f32 once.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PoseFrame {
    /// World image of camera +x (not necessarily unit: the pose may scale).
    pub x: DVec3,
    /// World image of camera +y.
    pub y: DVec3,
    /// World image of camera +z.
    pub z: DVec3,
    /// World position of the camera origin.
    pub eye: DVec3,
}

impl PoseFrame {
    /// The frame of an affine matrix (bottom row `[0 0 0 1]`, which [`CameraBase::validate`]
    /// checks for every keyframe; interpolations of affine keyframes are affine).
    #[inline]
    fn of(m: glam::Mat4) -> PoseFrame {
        PoseFrame {
            x: m.x_axis.truncate().as_dvec3(),
            y: m.y_axis.truncate().as_dvec3(),
            z: m.z_axis.truncate().as_dvec3(),
            eye: m.w_axis.truncate().as_dvec3(),
        }
    }
}

/// True when a world-space length that should be 1 is 1 up to f32 rounding: the test that
/// keeps a rigid pose's clip range exactly `[near, far]` (the models' caches, `chain::to_world`).
#[inline]
pub(crate) fn is_unit_length(length: f32) -> bool {
    (length - 1.0).abs() <= 1e-5
}

/// True when every number of the sample is finite.
///
/// One branch-free test instead of five: `0 * v` is (signed) 0 for finite `v` and NaN for an
/// infinity or NaN, so the sum of the five products is 0 exactly when all five are finite (NaN
/// never compares equal, and sums of zeros cannot overflow).
#[inline]
fn sample_is_finite(sample: &CameraSample) -> bool {
    let v = glam::Vec4::new(
        sample.p_film.x,
        sample.p_film.y,
        sample.p_lens.x,
        sample.p_lens.y,
    );
    (v * 0.0).element_sum() + sample.time * 0.0 == 0.0
}

/// The time of a sample's ray on the base's shutter (through its curve and rolling shutter,
/// when it has them), or None when a number of the sample is not finite (such a sample gives
/// no ray): the first step of every model's `generate_ray`.
#[inline]
pub(crate) fn ray_time(base: &CameraBase, sample: &CameraSample) -> Option<f32> {
    if !sample_is_finite(sample) {
        return None;
    }
    if base.timing.is_uniform() {
        return Some(base.shutter.time_at(sample.time));
    }
    Some(timed_ray_time(base, sample))
}

/// [`ray_time`] through a shutter curve or rolling shutter: out of line, so that the common
/// uniform shutter's path stays short.
#[cold]
#[inline(never)]
fn timed_ray_time(base: &CameraBase, sample: &CameraSample) -> f32 {
    base.timing
        .time(base.shutter, &base.film, sample.p_film, sample.time)
}

/// The film points of a differential's three rays: the sample's and its neighbours one pixel
/// right and one pixel down.
#[inline(always)]
pub(crate) fn differential_film_points(p_film: Point2<Raster>) -> [Point2<Raster>; 3] {
    [
        Point2::new(p_film.x + 0.0, p_film.y + 0.0),
        Point2::new(p_film.x + 1.0, p_film.y + 0.0),
        Point2::new(p_film.x + 0.0, p_film.y + 1.0),
    ]
}

/// A differential from the three rays of [`differential_film_points`] (each built at time 0 by
/// the model's per-ray function), all stamped with `time`. The models call their per-ray
/// function directly three times rather than through a closure, so that it is inlined.
#[inline(always)]
pub(crate) fn differential_at(time: f32, rays: [Ray<World>; 3]) -> CameraRayDifferential {
    let [ray, rx, ry] = rays;
    differential(Ray { time, ..ray }, Ray { time, ..rx }, Ray { time, ..ry })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MAX_BLADES;

    #[test]
    fn lens_validation() {
        assert!(ThinLens::new(0.0, 1.0).is_ok());
        assert!(matches!(
            ThinLens::new(-0.1, 1.0),
            Err(CameraError::LensRadius { .. })
        ));
        assert!(matches!(
            ThinLens::new(0.1, 0.0),
            Err(CameraError::FocalDistance { .. })
        ));
        assert!(matches!(
            ThinLens::new(f32::NAN, 1.0),
            Err(CameraError::NonFinite { .. })
        ));
        let lens = ThinLens::new(0.1, 2.0).unwrap();
        assert!(lens.clone().with_blades(2, 0.0).is_err());
        assert!(lens.clone().with_blades(6, 15.0).is_ok());
        assert!(lens.clone().with_blades(MAX_BLADES, 0.0).is_ok());
        assert!(matches!(
            lens.clone().with_blades(MAX_BLADES + 1, 0.0),
            Err(CameraError::Blades { .. })
        ));
    }

    #[test]
    fn aperture_points_stay_inside_the_radius() {
        let lens = ThinLens::new(0.5, 1.0).unwrap();
        let hex = lens.clone().with_blades(6, 0.0).unwrap();
        for i in 0..16 {
            for j in 0..16 {
                let u = glam::Vec2::new(i as f32 / 16.0, j as f32 / 16.0);
                assert!(lens.aperture_point(u).length() <= 0.5 + 1e-6);
                assert!(hex.aperture_point(u).length() <= 0.5 + 1e-6);
            }
        }
        // The centre of the square is the centre of the lens.
        assert_eq!(
            lens.aperture_point(glam::Vec2::splat(0.5)),
            glam::Vec2::ZERO
        );
    }

    #[test]
    fn look_at_pose_is_fixed_without_end_or_with_instant_shutter() {
        let start = LookAt {
            eye: Point3::new(0.0, 0.0, 0.0),
            target: Point3::new(0.0, 0.0, -1.0),
            up: Vector3::new(0.0, 1.0, 0.0),
        };
        let end = LookAt {
            eye: Point3::new(1.0, 0.0, 0.0),
            target: Point3::new(1.0, 0.0, -1.0),
            ..start
        };
        let shutter = Shutter::new(0.0, 1.0).unwrap();
        assert!(!look_at_pose(start, None, shutter).unwrap().is_animated());
        assert!(
            look_at_pose(start, Some(end), shutter)
                .unwrap()
                .is_animated()
        );
        let instant = Shutter::new(0.5, 0.5).unwrap();
        assert!(
            !look_at_pose(start, Some(end), instant)
                .unwrap()
                .is_animated()
        );
        let bad = LookAt {
            target: start.eye,
            ..start
        };
        assert!(matches!(
            look_at_pose(bad, None, shutter),
            Err(CameraError::Pose(_))
        ));
    }

    #[test]
    fn traceable_needs_a_finite_origin_and_a_unit_direction() {
        let unit = Vector3::<World>::new(0.0, 0.6, 0.8);
        assert!(traceable(Point3::new(1e30, -2.0, 0.0), unit));
        for bad in [f32::INFINITY, f32::NEG_INFINITY, f32::NAN] {
            for axis in 0..3 {
                let mut o = [1.0f32, -2.0, 3.0];
                o[axis] = bad;
                assert!(!traceable(Point3::new(o[0], o[1], o[2]), unit), "{o:?}");
            }
        }
        let o = Point3::new(0.0, 0.0, 0.0);
        // The fuzz target's underflowed thin lens normalised to length 1.0075.
        assert!(!traceable(o, Vector3::new(0.0, 0.0, 1.0075)));
        assert!(traceable(o, Vector3::new(0.0, 0.0, 1.0004)));
        assert!(!traceable(o, Vector3::new(0.0, f32::NAN, 1.0)));
        assert!(!traceable(o, Vector3::new(0.0, 0.0, 0.0)));
    }
}
