//! The public settings types of a validated scene file.

use crate::error::RenderError;
use obscura_accel::TriangleMesh;
use obscura_camera::{
    CubeFace, Exposure, FisheyeProjection, FovAxis, LensPrescription, LookAt, OpenCvIntrinsics,
    ScreenWindow, Shutter, ShutterTiming, StereoEye, StereoRig, ThinLens,
};
use obscura_sample::SamplerKind;
use obscura_space::{Camera as CameraSpace, Object, Transform, World};
use std::path::PathBuf;

/// Three numbers of the scene file: a point, vector or colour.
pub(crate) type V3 = [f32; 3];

/// A validated scene file: every value checked, paths resolved against the file's folder.
#[derive(Clone, Debug)]
pub struct SceneDescription {
    /// The scene file itself.
    pub file: PathBuf,
    /// `[film]`.
    pub film: FilmSettings,
    /// `[sampler]`.
    pub sampler: SamplerSettings,
    /// `[integrator]`.
    pub integrator: IntegratorSettings,
    /// `[camera]`.
    pub camera: CameraSettings,
    /// `[materials.NAME]`, in name order; shapes refer to them by index.
    pub materials: Vec<(String, MaterialSettings)>,
    /// `[[shapes]]`, in file order.
    pub shapes: Vec<ShapeSettings>,
    /// `[[lights]]`, in file order.
    pub lights: Vec<LightSettings>,
    /// Keys that were given but that the chosen model ignores (e.g. `fov` on an orthographic
    /// camera): worth a note to the user, not an error.
    pub ignored: Vec<String>,
    /// Meshes given in memory (by an importer), under the resolved path a `mesh` shape names:
    /// [`RenderScene::build`](crate::RenderScene::build) takes them instead of reading the file.
    pub meshes: std::sync::Arc<std::collections::HashMap<PathBuf, std::sync::Arc<TriangleMesh>>>,
    /// Environment maps given in memory (by an importer), under the resolved path a light's
    /// `file` names: [`RenderScene::build`](crate::RenderScene::build) takes them instead of
    /// reading the file.
    pub maps: std::sync::Arc<std::collections::HashMap<PathBuf, std::sync::Arc<crate::Image>>>,
    /// The file's text, read once: errors found after parsing (a mesh that fails to load, a
    /// camera the command line's resolution does not suit) find their key's line in it.
    pub(crate) source: std::sync::Arc<str>,
}

impl SceneDescription {
    /// A scene error at `key`, with the key's line in the file.
    pub(crate) fn error(&self, key: impl Into<String>, message: impl Into<String>) -> RenderError {
        RenderError::at_key(&self.file, &self.source, &key.into(), message)
    }
}

/// The camera's part of a scene file, validated as [`SceneDescription`]'s is: `[camera]`,
/// `[film]` and `[sampler] type`, and nothing of the scene the camera looks at. Made by
/// [`parse_camera_description`](crate::parse_camera_description); its camera is
/// [`CameraDescription::camera`].
#[derive(Clone, Debug)]
pub struct CameraDescription {
    /// The scene file itself.
    pub file: PathBuf,
    /// `[film]`.
    pub film: FilmSettings,
    /// `[sampler] type`: the sampler that draws the camera's film, lens and time samples.
    pub sampler: SamplerKind,
    /// `[camera]`.
    pub camera: CameraSettings,
    /// `[camera]` keys that were given but that the chosen model ignores, as in
    /// [`SceneDescription::ignored`].
    pub ignored: Vec<String>,
    /// The file's text: errors found after parsing find their key's line in it.
    pub(crate) source: std::sync::Arc<str>,
}

/// `[film]`: the image's size and reconstruction filter.
#[derive(Clone, Debug)]
pub struct FilmSettings {
    /// Width and height in pixels, each >= 1.
    pub resolution: [u32; 2],
    /// The reconstruction filter.
    pub filter: FilterSettings,
    /// Optional crop window in NDC: x0, x1, y0, y1 (an extension of the format).
    pub crop: Option<[f32; 4]>,
}

/// A reconstruction filter and its radius in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FilterSettings {
    /// Constant over [-r, r]^2; default radius 0.5 (each sample counts for its own pixel only).
    Box {
        /// Radius in pixels.
        radius: f32,
    },
    /// A tent falling linearly to zero at the radius; default radius 1.
    Triangle {
        /// Radius in pixels.
        radius: f32,
    },
    /// A Gaussian of standard deviation `sigma`, shifted down to zero at the radius:
    /// `exp(-d^2 / 2 sigma^2) - exp(-r^2 / 2 sigma^2)` (pbrt-v4's and Mitsuba 3's form).
    /// Defaults: radius 1.5, sigma radius / 3 ([`FilterSettings::gaussian`]).
    Gaussian {
        /// Radius in pixels.
        radius: f32,
        /// Standard deviation in pixels.
        sigma: f32,
    },
    /// Mitchell-Netravali with B = C = 1/3; default radius 2.
    Mitchell {
        /// Radius in pixels.
        radius: f32,
    },
}

impl FilterSettings {
    /// The widest filter radius, and the widest Gaussian sigma, in pixels.
    pub const MAX_RADIUS: f32 = 16.0;

    /// How many radii a Gaussian's sigma may be at most: wider, every weight is a difference
    /// of two exponentials within 0.13% of each other, and f32 keeps too few of its digits.
    pub const MAX_SIGMA_PER_RADIUS: f32 = 20.0;

    /// Whether `sigma` is a standard deviation the Gaussian of `radius` takes: in
    /// `(0, MAX_RADIUS]` and at most `MAX_SIGMA_PER_RADIUS` radii (false for NaN).
    pub fn sigma_fits(radius: f32, sigma: f32) -> bool {
        sigma > 0.0 && sigma <= Self::MAX_RADIUS && sigma <= Self::MAX_SIGMA_PER_RADIUS * radius
    }

    /// The Gaussian of a radius with its default standard deviation, a third of the radius
    /// (pbrt-v4's default pair is radius 1.5, sigma 0.5).
    pub fn gaussian(radius: f32) -> Self {
        FilterSettings::Gaussian {
            radius,
            sigma: radius / 3.0,
        }
    }

    /// The filter's radius in pixels.
    pub fn radius(&self) -> f32 {
        match *self {
            FilterSettings::Box { radius }
            | FilterSettings::Triangle { radius }
            | FilterSettings::Gaussian { radius, .. }
            | FilterSettings::Mitchell { radius } => radius,
        }
    }
    /// The filter's name in the scene format.
    pub fn name(&self) -> &'static str {
        match self {
            FilterSettings::Box { .. } => "box",
            FilterSettings::Triangle { .. } => "triangle",
            FilterSettings::Gaussian { .. } => "gaussian",
            FilterSettings::Mitchell { .. } => "mitchell",
        }
    }
}

/// `[sampler]`.
#[derive(Clone, Copy, Debug)]
pub struct SamplerSettings {
    /// Which sampler.
    pub kind: SamplerKind,
    /// Samples per pixel, >= 1.
    pub spp: u32,
    /// The seed every sample value derives from.
    pub seed: u64,
}

/// What the integrator computes per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Path-traced radiance.
    Path,
    /// Camera-space z of the first hit.
    Depth,
    /// Distance from the ray's origin to the first hit.
    Distance,
    /// World-space position of the first hit.
    Position,
    /// World-space shading normal of the first hit, facing the viewer.
    Normal,
    /// The material's reflectance at the first hit.
    Albedo,
}

impl IntegratorKind {
    /// Every integrator, in the order the scene format lists them.
    pub const ALL: [IntegratorKind; 6] = [
        IntegratorKind::Path,
        IntegratorKind::Depth,
        IntegratorKind::Distance,
        IntegratorKind::Position,
        IntegratorKind::Normal,
        IntegratorKind::Albedo,
    ];
    /// The scene-format name.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Path => "path",
            IntegratorKind::Depth => "depth",
            IntegratorKind::Distance => "distance",
            IntegratorKind::Position => "position",
            IntegratorKind::Normal => "normal",
            IntegratorKind::Albedo => "albedo",
        }
    }
    /// Parses a scene-format name.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// `[integrator]`.
#[derive(Clone, Copy, Debug)]
pub struct IntegratorSettings {
    /// Which integrator.
    pub kind: IntegratorKind,
    /// Longest path (path integrator only), >= 1.
    pub max_depth: u32,
}

/// Which camera model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraKind {
    /// Perspective projection (with an optional thin lens).
    Perspective,
    /// Orthographic projection (with an optional thin lens).
    Orthographic,
    /// Equirectangular 360 x 180 degree environment camera.
    Environment,
    /// OpenCV's pinhole model with distortion (`type = "opencv"`).
    OpenCv,
    /// OpenCV's fisheye model, Kannala-Brandt (`type = "opencv_fisheye"`).
    OpenCvFisheye,
    /// An ideal fisheye (`type = "fisheye"`, with `projection`).
    Fisheye,
    /// A cylindrical panorama, 360 degrees around camera +y.
    Cylindrical,
    /// Clarberg's equal-area octahedral panorama of the whole sphere.
    Octahedral,
    /// One 90-degree face of a cube map (`face`).
    CubeFace,
    /// Omni-directional stereo: both eyes' equirectangular panoramas, left on top.
    Ods,
    /// A lens system traced element by element (`type = "realistic"`, with `lens_file`).
    Realistic,
}

impl CameraKind {
    /// Every model, in the order the scene format lists them.
    pub const ALL: [CameraKind; 11] = [
        CameraKind::Perspective,
        CameraKind::Orthographic,
        CameraKind::Environment,
        CameraKind::OpenCv,
        CameraKind::OpenCvFisheye,
        CameraKind::Fisheye,
        CameraKind::Cylindrical,
        CameraKind::Octahedral,
        CameraKind::CubeFace,
        CameraKind::Ods,
        CameraKind::Realistic,
    ];

    /// The model's `type` in the scene file.
    pub fn name(self) -> &'static str {
        match self {
            CameraKind::Perspective => "perspective",
            CameraKind::Orthographic => "orthographic",
            CameraKind::Environment => "environment",
            CameraKind::OpenCv => "opencv",
            CameraKind::OpenCvFisheye => "opencv_fisheye",
            CameraKind::Fisheye => "fisheye",
            CameraKind::Cylindrical => "cylindrical",
            CameraKind::Octahedral => "octahedral",
            CameraKind::CubeFace => "cube_face",
            CameraKind::Ods => "ods",
            CameraKind::Realistic => "realistic",
        }
    }

    /// The model of a scene file's `type`.
    pub fn from_name(name: &str) -> Option<CameraKind> {
        CameraKind::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// OpenCV extrinsics: the pose as `cv::projectPoints` takes it, world -> OpenCV camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extrinsics {
    /// Rotation as a Rodrigues vector (axis times angle in radians).
    pub rvec: [f64; 3],
    /// Translation, world units.
    pub tvec: [f64; 3],
}

/// How `obscura render` lays out a stereo pair (`[camera.stereo] layout`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StereoLayout {
    /// One image twice as wide: left eye on the left.
    SideBySide,
    /// Two files, `NAME-left.EXT` and `NAME-right.EXT`.
    Separate,
    /// A red-cyan anaglyph: red from the left eye's luminance, green and blue from the right.
    Anaglyph,
}

impl StereoLayout {
    /// The layout of a scene file's name.
    pub fn from_name(name: &str) -> Option<StereoLayout> {
        match name {
            "side_by_side" => Some(StereoLayout::SideBySide),
            "separate" => Some(StereoLayout::Separate),
            "anaglyph" => Some(StereoLayout::Anaglyph),
            _ => None,
        }
    }
}

/// `[camera.stereo]`, validated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StereoSettings {
    /// The rig: interaxial and convergence distances.
    pub rig: StereoRig,
    /// How the pair is written.
    pub layout: StereoLayout,
}

/// A camera pose as a matrix: world from camera.
pub type CameraPose = Transform<World, CameraSpace>;

/// `[camera]`, validated: the camera crate's own types, each checked by the camera crate.
#[derive(Clone, Debug)]
pub struct CameraSettings {
    /// The model.
    pub kind: CameraKind,
    /// The pose at shutter open.
    pub start: LookAt,
    /// The pose at shutter close, when the camera moves.
    pub end: Option<LookAt>,
    /// Full field of view in degrees along `fov_axis` (perspective; checked only there).
    pub fov: f32,
    /// The axis `fov` spans.
    pub fov_axis: FovAxis,
    /// Optional screen window.
    pub screen_window: Option<ScreenWindow>,
    /// Near clip.
    pub near: f32,
    /// Far clip.
    pub far: f32,
    /// The lens: radius (0 for a pinhole), focal distance, aperture (blades and rotation, an
    /// image, the anamorphic squeeze) and the focal plane's tilt.
    pub lens: ThinLens,
    /// Shutter open and close times.
    pub shutter: Shutter,
    /// How ray times spread over the shutter: `shutter_curve` and `rolling_shutter`.
    pub timing: ShutterTiming,
    /// `f_number`, `shutter_time`, `iso`, `exposure_compensation`, when any is given: the
    /// path integrator's radiance is then scaled by [`Exposure::scale`].
    pub exposure: Option<Exposure>,
    /// OpenCV extrinsics `rvec`, `tvec`: when given, the pose instead of the look-at.
    pub extrinsics: Option<Extrinsics>,
    /// `fx`, `fy`, `cx`, `cy` of the OpenCV models.
    pub intrinsics: Option<OpenCvIntrinsics>,
    /// `distortion` of the OpenCV models, in OpenCV's `distCoeffs` order.
    pub distortion: Vec<f64>,
    /// The ideal fisheye's projection.
    pub projection: FisheyeProjection,
    /// The cube-map face.
    pub face: CubeFace,
    /// Lens shift `[sx, sy]` in fractions of the image (perspective, orthographic, fisheye).
    pub lens_shift: [f32; 2],
    /// `[camera.stereo]`: an off-axis pair (perspective) or the ODS viewing circle.
    pub stereo: Option<StereoSettings>,
    /// Which eye of the stereo pair this description renders; None for the rig's centre.
    pub eye: Option<StereoEye>,
    /// `pose` (and `pose_end`): world from camera as matrices, instead of the look-at; any
    /// affine matrix, so also a pose that mirrors the image as pbrt's look-at does.
    pub pose: Option<(CameraPose, Option<CameraPose>)>,
    /// The realistic camera's lens system and settings (None for the other models).
    pub realistic: Option<RealisticSettings>,
}

/// The `[camera]` keys of `type = "realistic"`, with the lens file read and parsed.
#[derive(Clone, Debug, PartialEq)]
pub struct RealisticSettings {
    /// `lens_file`, resolved against the scene file's folder.
    pub lens_file: PathBuf,
    /// The prescription the file holds.
    pub prescription: LensPrescription,
    /// `aperture_diameter` (mm); None for the stop's full diameter.
    pub aperture_diameter: Option<f32>,
    /// `focus_distance` (world units, metres), from the film plane.
    pub focus_distance: f32,
    /// `film_diagonal` (mm).
    pub film_diagonal: f32,
    /// `focal_plane_tilt` (degrees about camera x and y; `[0, 0]` for none): the realistic
    /// camera tilts its film to the tilted plane's image.
    pub focal_plane_tilt: [f32; 2],
}

impl SceneDescription {
    /// The two eyes' descriptions of a perspective stereo scene (left, right), each rendering
    /// one eye's camera; None when the scene has no off-axis pair.
    pub fn stereo_eyes(&self) -> Option<[SceneDescription; 2]> {
        if self.camera.stereo.is_none() || self.camera.kind != CameraKind::Perspective {
            return None;
        }
        let eye = |eye| {
            let mut d = self.clone();
            d.camera.eye = Some(eye);
            d
        };
        Some([eye(StereoEye::Left), eye(StereoEye::Right)])
    }
}

/// A material, validated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialSettings {
    /// Lambertian.
    Diffuse {
        /// Albedo per channel in [0, 1].
        reflectance: V3,
    },
    /// Perfect specular reflector.
    Mirror {
        /// Reflectance per channel in [0, 1].
        reflectance: V3,
    },
    /// Smooth glass.
    Dielectric {
        /// Index of refraction, > 0.
        ior: f32,
    },
    /// GGX rough conductor (an extension).
    RoughConductor {
        /// Reflectance at normal incidence per channel.
        reflectance: V3,
        /// Roughness in (0, 1].
        roughness: f32,
    },
}

/// The geometry of a shape, in its object space.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeGeometry {
    /// An analytic sphere.
    Sphere {
        /// Centre.
        center: V3,
        /// Radius, > 0.
        radius: f32,
    },
    /// The parallelogram origin + s edge_u + t edge_v.
    Quad {
        /// A corner.
        origin: V3,
        /// First edge.
        edge_u: V3,
        /// Second edge.
        edge_v: V3,
    },
    /// A Wavefront OBJ mesh.
    Mesh {
        /// The file, resolved against the scene file's folder.
        file: PathBuf,
    },
}

/// A `[[shapes]]` entry, validated.
#[derive(Clone, Debug)]
pub struct ShapeSettings {
    /// Its position in the file (for messages: `shapes[i]`).
    pub index: usize,
    /// Object-space geometry.
    pub geometry: ShapeGeometry,
    /// Index into [`SceneDescription::materials`], or `None` for the default grey diffuse.
    pub material: Option<usize>,
    /// Emitted radiance, when the shape is an area light.
    pub emission: Option<V3>,
    /// World from object at shutter open.
    pub transform: Transform<World, Object>,
    /// World from object at shutter close, when the shape moves.
    pub transform_end: Option<Transform<World, Object>>,
}

/// A `[[lights]]` entry, validated.
#[derive(Clone, Debug)]
pub enum LightSettings {
    /// A point light.
    Point {
        /// Position.
        position: V3,
        /// Radiant intensity per channel (W/sr).
        intensity: V3,
    },
    /// A light at infinity.
    Distant {
        /// The way the light travels.
        direction: V3,
        /// Irradiance on a surface facing it.
        irradiance: V3,
    },
    /// Light from every direction: constant or an equirectangular map.
    Environment {
        /// Constant radiance (or a scale on the map; default 1).
        radiance: V3,
        /// The map, resolved against the scene file's folder.
        file: Option<PathBuf>,
        /// World from light.
        transform: Transform<World, World>,
    },
}
