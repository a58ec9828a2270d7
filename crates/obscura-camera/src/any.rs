//! The closed set of camera models as one enum.

use crate::camera::{
    Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample, traceable,
};
use crate::cube_face::CubeFaceCamera;
use crate::cylindrical::CylindricalCamera;
use crate::environment::EnvironmentCamera;
use crate::fisheye::FisheyeCamera;
use crate::octahedral::OctahedralCamera;
use crate::ods::OdsCamera;
use crate::opencv::OpenCvCamera;
use crate::opencv_fisheye::OpenCvFisheyeCamera;
use crate::orthographic::OrthographicCamera;
use crate::perspective::PerspectiveCamera;
use crate::realistic::RealisticCamera;
use obscura_space::{Point2, Point3, Raster, World};

/// Any of the camera models, dispatched by `match` (no trait objects on the per-ray path).
// An explicit one-byte tag: left to rustc, the tag was a niche in a 16-byte field, which made
// each dispatch (and the `Option<AnyCamera>` check) a 128-bit compare and range computation.
#[derive(Debug, Clone)]
#[repr(u8)]
pub enum AnyCamera {
    /// A perspective camera.
    Perspective(PerspectiveCamera),
    /// An orthographic camera.
    Orthographic(OrthographicCamera),
    /// An environment camera.
    Environment(EnvironmentCamera),
    /// An ideal fisheye camera.
    Fisheye(FisheyeCamera),
    /// A cylindrical panorama camera.
    Cylindrical(CylindricalCamera),
    /// An equal-area octahedral panorama camera.
    Octahedral(OctahedralCamera),
    /// One face of a cube map.
    CubeFace(CubeFaceCamera),
    /// An omni-directional stereo panorama camera.
    Ods(OdsCamera),
    /// An OpenCV pinhole camera with distortion.
    OpenCv(OpenCvCamera),
    /// An OpenCV (Kannala-Brandt) fisheye camera.
    OpenCvFisheye(OpenCvFisheyeCamera),
    /// A lens system traced element by element.
    Realistic(RealisticCamera),
}

macro_rules! dispatch {
    ($self:ident, $c:ident => $e:expr) => {
        match $self {
            AnyCamera::Perspective($c) => $e,
            AnyCamera::Orthographic($c) => $e,
            AnyCamera::Environment($c) => $e,
            AnyCamera::Fisheye($c) => $e,
            AnyCamera::Cylindrical($c) => $e,
            AnyCamera::Octahedral($c) => $e,
            AnyCamera::CubeFace($c) => $e,
            AnyCamera::Ods($c) => $e,
            AnyCamera::OpenCv($c) => $e,
            AnyCamera::OpenCvFisheye($c) => $e,
            AnyCamera::Realistic($c) => $e,
        }
    };
}

impl Camera for AnyCamera {
    // Every model's ray passes one check here: under extreme parameters (found by the camera
    // fuzz target: an orthographic screen window of 1e34 and a film position of 1e30; a thin
    // lens whose radius and focal distance are 1e-22, where squaring underflows) a model's
    // arithmetic can give a NaN origin or a direction that is not unit length.
    #[inline]
    fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        dispatch!(self, c => c.generate_ray(sample))
            .filter(|r| traceable(r.ray.origin, r.ray.direction))
    }
    #[inline]
    fn generate_ray_differential(&self, sample: &CameraSample) -> Option<CameraRayDifferential> {
        dispatch!(self, c => c.generate_ray_differential(sample)).filter(|r| {
            traceable(r.ray.origin, r.ray.direction)
                && traceable(r.rx_origin, r.rx_direction)
                && traceable(r.ry_origin, r.ry_direction)
        })
    }
    // As for rays: a projection that overflowed (a cylindrical camera of fov 1e-45 degrees,
    // found by the camera fuzz target) is None, not infinite.
    #[inline]
    fn project(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
        dispatch!(self, c => c.project(p, time)).filter(|q| q.x.is_finite() && q.y.is_finite())
    }
    #[inline]
    fn base(&self) -> &CameraBase {
        dispatch!(self, c => c.base())
    }
    #[inline]
    fn uses_lens_sample(&self) -> bool {
        dispatch!(self, c => c.uses_lens_sample())
    }
    #[inline]
    fn uses_time_sample(&self) -> bool {
        dispatch!(self, c => c.uses_time_sample())
    }
}

impl From<PerspectiveCamera> for AnyCamera {
    fn from(c: PerspectiveCamera) -> Self {
        AnyCamera::Perspective(c)
    }
}
impl From<OrthographicCamera> for AnyCamera {
    fn from(c: OrthographicCamera) -> Self {
        AnyCamera::Orthographic(c)
    }
}
impl From<EnvironmentCamera> for AnyCamera {
    fn from(c: EnvironmentCamera) -> Self {
        AnyCamera::Environment(c)
    }
}
impl From<FisheyeCamera> for AnyCamera {
    fn from(c: FisheyeCamera) -> Self {
        AnyCamera::Fisheye(c)
    }
}
impl From<CylindricalCamera> for AnyCamera {
    fn from(c: CylindricalCamera) -> Self {
        AnyCamera::Cylindrical(c)
    }
}
impl From<OctahedralCamera> for AnyCamera {
    fn from(c: OctahedralCamera) -> Self {
        AnyCamera::Octahedral(c)
    }
}
impl From<CubeFaceCamera> for AnyCamera {
    fn from(c: CubeFaceCamera) -> Self {
        AnyCamera::CubeFace(c)
    }
}
impl From<OdsCamera> for AnyCamera {
    fn from(c: OdsCamera) -> Self {
        AnyCamera::Ods(c)
    }
}
impl From<OpenCvCamera> for AnyCamera {
    fn from(c: OpenCvCamera) -> Self {
        AnyCamera::OpenCv(c)
    }
}
impl From<OpenCvFisheyeCamera> for AnyCamera {
    fn from(c: OpenCvFisheyeCamera) -> Self {
        AnyCamera::OpenCvFisheye(c)
    }
}
impl From<RealisticCamera> for AnyCamera {
    fn from(c: RealisticCamera) -> Self {
        AnyCamera::Realistic(c)
    }
}
