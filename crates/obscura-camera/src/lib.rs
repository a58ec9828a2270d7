//! Camera models for ray tracing: orthographic and perspective projection, each with an
//! optional thin lens (depth of field), the 360-degree environment camera, and camera motion
//! over an open shutter.
//!
//! A camera turns a [`CameraSample`] (a film position in raster space, a lens sample and a time
//! sample, all filled in by a sampler) into a world-space [`CameraRay`] with a unit direction,
//! a time and a visible `[t_min, t_max]`; [`Camera::project`] is the inverse, a world point to
//! its raster position. The models are [`PerspectiveCamera`], [`OrthographicCamera`] and
//! [`EnvironmentCamera`], gathered in [`AnyCamera`]; they share a [`CameraBase`] (pose,
//! [`Shutter`], [`FilmGeometry`], clip range) and, for the projective two, a
//! [`ProjectiveCamera`] holding the chain camera -> screen -> NDC -> raster as typed
//! transforms (`screen_from_camera`, `raster_from_screen`, `camera_from_raster`...). Errors are
//! [`CameraError`].
//!
//! Beyond the lecture: the ideal fisheyes [`FisheyeCamera`] ([`FisheyeProjection`]), the
//! panoramas [`CylindricalCamera`], [`OctahedralCamera`] (equal-area) and [`CubeFaceCamera`]
//! ([`CubeFace`]), the omni-directional stereo panorama [`OdsCamera`], and the lens system
//! [`RealisticCamera`] (a [`LensPrescription`] traced element by element); each doc comment
//! gives its formulas, its source and the film points from which no ray leaves.
//!
//! Photographic controls: an [`Aperture`] (round, blades, an [`ApertureImage`] of weights, an
//! anamorphic squeeze) is the thin lens's opening, which [`ThinLens`] may also tilt
//! (Scheimpflug); [`ShutterTiming`] (a piecewise-linear shutter curve, a [`RollingShutter`])
//! spreads every model's ray times; [`Exposure`] is the f-number, shutter time, ISO and
//! compensation a renderer scales radiance by.
//!
//! What is not here: films with pixels, filters, samplers, scene files, geometry. This crate
//! knows nothing of BVHs, images or files; it depends on `obscura-space`, `obscura-sample`
//! (for the aperture warps) and glam.
//!
//! The design decision: **the pose is separate from the projection**. The projection chain is
//! built once (in f64, with closed-form inverses, so `far = 1e30` is safe); the pose is an
//! [`AnimatedTransform`](obscura_space::AnimatedTransform) evaluated at each ray's own time,
//! which is all camera motion blur needs. Conventions (axes, windows, pixel centres, the
//! environment mapping, the time mapping) are those of the scene format: camera +z is the view,
//! +y up, +x the image's right, which makes the camera frame left-handed in a right-handed
//! world.
//!
//! Rays: each model builds them in one function (`ray`, private), used by
//! [`Camera::generate_ray`] and [`Camera::generate_ray_differential`] alike, that reads as the
//! pbrt chain: film point -> camera_from_raster (an affine map of raster x and y) -> lens ->
//! clip -> world_from_camera(t). The pose enters through a small private cache (the pose's
//! axes and eye in f32; for a perspective pinhole the world direction is then `R q` for the
//! film point `q` on the camera plane z = 1, one normalisation, no 4x4 divide), computed once
//! for a fixed pose and per ray for a moving one, with the same function, so a moving camera at
//! a keyframe's time gives the fixed camera's rays bit for bit. Poses must be affine (every
//! look-at is); the transforms of [`ProjectiveCamera`] stay the reference the rays are tested
//! against, and `project` uses them.
//!
//! ```
//! use obscura_camera::{
//!     Camera, CameraBase, CameraSample, FilmGeometry, FovAxis, LookAt, PerspectiveCamera,
//!     Shutter, ThinLens, look_at_pose,
//! };
//! use obscura_space::{Point2, Point3, Vector3};
//!
//! // A 2 x 2 image, fov 90 degrees, eye at the origin looking down world -z.
//! let shutter = Shutter::new(0.0, 1.0)?;
//! let eye = LookAt::new(Point3::new(0.0, 0.0, 0.0), Point3::new(0.0, 0.0, -1.0), Vector3::new(0.0, 1.0, 0.0));
//! let base = CameraBase::new(look_at_pose(eye, None, shutter)?, shutter, FilmGeometry::new([2, 2], None, None)?);
//! let camera = PerspectiveCamera::new(base, 90.0, FovAxis::Smaller, ThinLens::PINHOLE)?;
//!
//! // Pixel (0, 0), centre (0.5, 0.5): NDC (0.25, 0.25), screen (-0.5, 0.5), camera direction
//! // normalize(-0.5, 0.5, 1), which in the world is up and to the left of -z.
//! let ray = camera.generate_ray(&CameraSample::at(Point2::new(0.5, 0.5))).unwrap().ray;
//! let expected = glam::Vec3::new(-0.5, 0.5, -1.0).normalize();
//! assert!((ray.direction.to_glam() - expected).length() < 1e-6);
//! // And back: the point 3 units along the ray projects to the same raster position.
//! let p_raster = camera.project(ray.at(3.0), 0.0).unwrap();
//! assert!((p_raster.x - 0.5).abs() < 1e-4 && (p_raster.y - 0.5).abs() < 1e-4);
//! # Ok::<(), obscura_camera::CameraError>(())
//! ```
#![deny(missing_docs)]

mod any;
mod aperture;
mod camera;
mod chain;
mod cube_face;
mod cylindrical;
mod environment;
mod error;
mod exposure;
mod film;
mod fisheye;
mod octahedral;
mod ods;
mod opencv;
mod opencv_fisheye;
mod orthographic;
mod perspective;
mod projective;
mod realistic;
mod shutter;
mod stereo;

pub use any::AnyCamera;
pub use aperture::{Aperture, ApertureImage, ApertureShape, MAX_BLADES};
pub use camera::{
    Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample, DEFAULT_FAR, DEFAULT_NEAR,
    LookAt, ThinLens, look_at_pose,
};
pub use cube_face::{CubeFace, CubeFaceCamera};
pub use cylindrical::CylindricalCamera;
pub use environment::EnvironmentCamera;
pub use error::CameraError;
pub use exposure::{Exposure, ISO_CALIBRATION};
pub use film::{FilmGeometry, FovAxis, MAX_RESOLUTION, ScreenWindow, Shutter, validate_clip};
pub use fisheye::{FisheyeCamera, FisheyeProjection};
pub use octahedral::OctahedralCamera;
pub use ods::{OdsCamera, OdsEye};
pub use opencv::{
    OPENCV_INVERSE_TOLERANCE_PX, OPENCV_MAX_RADIUS, OpenCvCamera, OpenCvIntrinsics, opencv_pose,
};
pub use opencv_fisheye::{FISHEYE_INVERSE_TOLERANCE_PX, OpenCvFisheyeCamera};
pub use orthographic::OrthographicCamera;
pub use perspective::{PerspectiveCamera, validate_fov};
pub use projective::ProjectiveCamera;
pub use realistic::{
    DEFAULT_FILM_DIAGONAL, LensPrescription, LensSurface, MM_PER_UNIT, PROJECT_TOLERANCE_MM,
    PUPIL_SEGMENTS, RealisticCamera, RealisticLens,
};
pub use shutter::{RollingDirection, RollingShutter, ShutterTiming};
pub use stereo::{StereoEye, StereoRig};
