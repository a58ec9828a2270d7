//! The `[camera]` keys: each maps onto a camera-crate type or check (`LookAt`, `FovAxis`,
//! `ScreenWindow`, `ThinLens`, `Shutter`, `StereoRig`, `validate_fov`, `validate_clip`, the
//! models' constructors), and a [`CameraError`] maps back onto the key at fault and its line.
//! The camera crate holds the only set of checks: what needs the film (a model's valid field of
//! view, a square film) is checked by building the camera once at parse time.

use super::parse::Cx;
use super::raw::RawCamera;
use super::settings::{
    CameraKind, CameraSettings, Extrinsics, RealisticSettings, StereoLayout, StereoSettings, V3,
};
use crate::error::RenderError;
use obscura_camera::{
    Aperture, ApertureImage, CameraError, CubeFace, DEFAULT_FILM_DIAGONAL, Exposure,
    FisheyeProjection, FovAxis, LensPrescription, LookAt, OpenCvIntrinsics, RollingDirection,
    RollingShutter, ScreenWindow, Shutter, ShutterTiming, StereoRig, ThinLens, opencv_pose,
    validate_clip, validate_fov,
};
use obscura_sample::PiecewiseShutterCurve;
use obscura_space::{Camera as CameraSpace, Point3, SpaceError, Transform, Vector3, World};
use std::path::Path;
use std::sync::Arc;

/// The realistic camera's focus distance when the scene gives none (world units, metres):
/// 10, as pbrt-v4's.
pub const DEFAULT_FOCUS_DISTANCE: f32 = 10.0;

/// The interaxial distance when `[camera.stereo]` does not give one: 65 mm, a typical adult's
/// distance between the pupils, in metres.
pub const DEFAULT_INTERAXIAL: f32 = 0.065;

/// The scene key a camera-crate error is about.
pub(crate) fn camera_key(e: &CameraError) -> &'static str {
    match e {
        CameraError::NonFinite { what, .. } => match *what {
            "near" => "camera.near",
            "far" => "camera.far",
            "fov" => "camera.fov",
            "lens_radius" => "camera.lens_radius",
            "focal_distance" => "camera.focal_distance",
            "aperture rotation" | "aperture_rotation" => "camera.aperture_rotation",
            "anamorphic" => "camera.anamorphic",
            "lens_shift" => "camera.lens_shift",
            "fx" => "camera.fx",
            "fy" => "camera.fy",
            "cx" => "camera.cx",
            "cy" => "camera.cy",
            "distortion" => "camera.distortion",
            "rvec" => "camera.rvec",
            "tvec" => "camera.tvec",
            "interaxial" => "camera.stereo.interaxial",
            "convergence" => "camera.stereo.convergence",
            "aperture_diameter" => "camera.aperture_diameter",
            "focus_distance" => "camera.focus_distance",
            "film_diagonal" => "camera.film_diagonal",
            _ => "camera",
        },
        CameraError::Fov { .. } | CameraError::FisheyeFov { .. } => "camera.fov",
        CameraError::UnknownFovAxis(_) => "camera.fov_axis",
        CameraError::Near { .. } => "camera.near",
        CameraError::NearFar { .. } => "camera.far",
        CameraError::LensRadius { .. } => "camera.lens_radius",
        CameraError::FocalDistance { .. } => "camera.focal_distance",
        CameraError::Blades { .. } => "camera.aperture_blades",
        CameraError::ScreenWindow { .. } => "camera.screen_window",
        CameraError::Shutter { .. } => "camera.shutter",
        CameraError::Resolution { .. }
        | CameraError::ResolutionTooLarge { .. }
        | CameraError::FilmShape { .. } => "film.resolution",
        CameraError::CropWindow { .. } => "film.crop",
        CameraError::ProjectivePose | CameraError::Pose(_) => "camera",
        CameraError::UnknownFisheyeProjection(_) => "camera.projection",
        CameraError::UnknownCubeFace(_) => "camera.face",
        CameraError::Interaxial { .. } => "camera.stereo.interaxial",
        CameraError::Convergence { .. } => "camera.stereo.convergence",
        CameraError::FocalLength { what, .. } => match *what {
            "fy" => "camera.fy",
            _ => "camera.fx",
        },
        CameraError::DistortionLength { .. } => "camera.distortion",
        CameraError::LensPrescription { .. } => "camera.lens_file",
        CameraError::ApertureDiameter { .. } => "camera.aperture_diameter",
        CameraError::FocusDistance { .. } => "camera.focus_distance",
        CameraError::FilmDiagonal { .. } => "camera.film_diagonal",
        CameraError::ApertureImage { .. } => "camera.aperture_image",
        CameraError::Anamorphic { .. } => "camera.anamorphic",
        CameraError::ShutterCurve(_) => "camera.shutter_curve",
        CameraError::RollingReadout { .. } | CameraError::UnknownRollingDirection(_) => {
            "camera.rolling_shutter"
        }
        CameraError::FocalPlaneTilt { .. }
        | CameraError::TiltOutOfReach { .. }
        | CameraError::TiltWithoutLens => "camera.focal_plane_tilt",
        CameraError::Exposure { what, .. } => match *what {
            "f_number" => "camera.f_number",
            "shutter_time" => "camera.shutter_time",
            "iso" => "camera.iso",
            _ => "camera.exposure_compensation",
        },
        CameraError::LensRadiusDisagrees { .. } => "camera.lens_radius",
    }
}

/// Whether a model reads a `[camera]` key (the look-at, clip range and shutter every model
/// reads); keys a model does not read are noted as ignored, so one scene can switch `type`.
fn reads(kind: CameraKind, key: &str) -> bool {
    use CameraKind::*;
    match key {
        "fov" => matches!(kind, Perspective | Fisheye | Cylindrical),
        "fov_axis" => kind == Perspective,
        "screen_window" | "lens_radius" | "focal_distance" | "focal_length" => {
            matches!(kind, Perspective | Orthographic)
        }
        "aperture_blades" | "aperture_rotation" | "aperture_image" | "anamorphic" => {
            matches!(kind, Perspective | Orthographic | Realistic)
        }
        "lens_file" | "aperture_diameter" | "focus_distance" | "film_diagonal" => kind == Realistic,
        "focal_plane_tilt" => matches!(kind, Perspective | Orthographic | Realistic),
        "lens_shift" => matches!(kind, Perspective | Orthographic | Fisheye),
        "fx" | "fy" | "cx" | "cy" | "distortion" => matches!(kind, OpenCv | OpenCvFisheye),
        "projection" => kind == Fisheye,
        "face" => kind == CubeFace,
        "stereo" => matches!(kind, Perspective | Ods),
        _ => true,
    }
}

impl Cx<'_> {
    /// A camera-crate error as a scene error at its key and line.
    pub(super) fn camera_err(&self, e: CameraError) -> RenderError {
        self.err(camera_key(&e), e.to_string())
    }

    pub(super) fn camera(
        &self,
        c: RawCamera,
        base: &Path,
        ignored: &mut Vec<String>,
    ) -> Result<CameraSettings, RenderError> {
        let name = c.kind.as_deref().unwrap_or("perspective");
        let Some(kind) = CameraKind::from_name(name) else {
            let names: Vec<&str> = CameraKind::ALL.iter().map(|k| k.name()).collect();
            return Err(self.err(
                "camera.type",
                format!(
                    "unknown camera `{name}`, expected one of {}",
                    names.join(", ")
                ),
            ));
        };
        let given = [
            ("fov", c.fov.is_some()),
            ("fov_axis", c.fov_axis.is_some()),
            ("screen_window", c.screen_window.is_some()),
            ("lens_radius", c.lens_radius.is_some()),
            ("focal_distance", c.focal_distance.is_some()),
            ("aperture_blades", c.aperture_blades.is_some()),
            ("aperture_rotation", c.aperture_rotation.is_some()),
            ("lens_shift", c.lens_shift.is_some()),
            ("fx", c.fx.is_some()),
            ("fy", c.fy.is_some()),
            ("cx", c.cx.is_some()),
            ("cy", c.cy.is_some()),
            ("distortion", c.distortion.is_some()),
            ("projection", c.projection.is_some()),
            ("face", c.face.is_some()),
            ("stereo", c.stereo.is_some()),
            ("lens_file", c.lens_file.is_some()),
            ("aperture_diameter", c.aperture_diameter.is_some()),
            ("focus_distance", c.focus_distance.is_some()),
            ("film_diagonal", c.film_diagonal.is_some()),
            ("aperture_image", c.aperture_image.is_some()),
            ("anamorphic", c.anamorphic.is_some()),
            ("focal_plane_tilt", c.focal_plane_tilt.is_some()),
            ("focal_length", c.focal_length.is_some()),
        ];
        for (key, _) in given.iter().filter(|(k, g)| *g && !reads(kind, k)) {
            ignored.push(format!("camera.{key} is ignored by the {name} camera"));
        }

        // The pose: a look-at (at shutter open, and at close when the camera moves), or OpenCV
        // extrinsics, never both.
        let look_given = [
            &c.eye,
            &c.target,
            &c.up,
            &c.eye_end,
            &c.target_end,
            &c.up_end,
        ]
        .iter()
        .any(|v| v.is_some());
        let extrinsics = match (c.rvec, c.tvec) {
            (None, None) => None,
            (Some(rvec), Some(tvec)) => {
                if look_given {
                    return Err(self.err(
                        "camera.rvec",
                        "give the pose either as a look-at (eye, target, up) or as OpenCV \
                         extrinsics (rvec, tvec), not both",
                    ));
                }
                opencv_pose(rvec, tvec).map_err(|e| self.camera_err(e))?;
                Some(Extrinsics { rvec, tvec })
            }
            (Some(_), None) => {
                return Err(self.err("camera.rvec", "rvec needs tvec beside it"));
            }
            (None, Some(_)) => {
                return Err(self.err("camera.tvec", "tvec needs rvec beside it"));
            }
        };
        // Or as matrices, world from camera (what an imported scene's camera transform is).
        let pose = match (c.pose, c.pose_end) {
            (None, None) => None,
            (None, Some(_)) => {
                return Err(self.err("camera.pose_end", "pose_end needs pose beside it"));
            }
            (Some(start), end) => {
                if look_given || extrinsics.is_some() {
                    return Err(self.err(
                        "camera.pose",
                        "give the pose one way only: a look-at (eye, target, up), OpenCV \
                         extrinsics (rvec, tvec) or a matrix (pose)",
                    ));
                }
                let matrix = |key: &str, m: [f32; 16]| {
                    self.finite(key, &m)?;
                    Transform::<World, CameraSpace>::from_rows(m)
                        .map_err(|e| self.err(key, e.to_string()))
                };
                let end = end.map(|m| matrix("camera.pose_end", m)).transpose()?;
                Some((matrix("camera.pose", start)?, end))
            }
        };
        let v3 = |key: &str, v: Option<V3>, default: V3| -> Result<V3, RenderError> {
            let v = v.unwrap_or(default);
            self.finite(&format!("camera.{key}"), &v)?;
            Ok(v)
        };
        let look = |eye: V3, target: V3, up: V3| {
            LookAt::new(
                Point3::new(eye[0], eye[1], eye[2]),
                Point3::new(target[0], target[1], target[2]),
                Vector3::new(up[0], up[1], up[2]),
            )
        };
        let (eye, target, up) = (
            v3("eye", c.eye, [0.0, 0.0, 0.0])?,
            v3("target", c.target, [0.0, 0.0, -1.0])?,
            v3("up", c.up, [0.0, 1.0, 0.0])?,
        );
        let start = look(eye, target, up);
        let end = if c.eye_end.is_some() || c.target_end.is_some() || c.up_end.is_some() {
            Some(look(
                v3("eye_end", c.eye_end, eye)?,
                v3("target_end", c.target_end, target)?,
                v3("up_end", c.up_end, up)?,
            ))
        } else {
            None
        };
        self.look_at(false, &start)?;
        if let Some(end) = &end {
            self.look_at(true, end)?;
        }

        let perspective = kind == CameraKind::Perspective;
        let fov = c.fov.unwrap_or(match kind {
            CameraKind::Fisheye => 180.0,
            _ => 90.0,
        });
        if perspective {
            validate_fov(fov).map_err(|e| self.camera_err(e))?;
        }
        let fov_axis = match c.fov_axis.as_deref() {
            Some(name) => name.parse::<FovAxis>().map_err(|e| self.camera_err(e))?,
            None => FovAxis::Smaller,
        };
        let screen_window = match c.screen_window {
            Some(w) => {
                Some(ScreenWindow::new(w[0], w[1], w[2], w[3]).map_err(|e| self.camera_err(e))?)
            }
            None => None,
        };
        let near = c.near.unwrap_or(if perspective { 0.001 } else { 0.0 });
        let far = c.far.unwrap_or(1.0e30);
        validate_clip(near, far, perspective).map_err(|e| self.camera_err(e))?;
        let shutter = c.shutter.unwrap_or([0.0, 1.0]);
        let shutter = Shutter::new(shutter[0], shutter[1]).map_err(|e| self.camera_err(e))?;
        let exposure = self.exposure(&c)?;
        let lens_radius = self.lens_radius(&c, exposure.as_ref())?;
        let lens = ThinLens::new(lens_radius, c.focal_distance.unwrap_or(1.0))
            .and_then(|lens| {
                lens.with_blades(
                    c.aperture_blades.unwrap_or(0),
                    c.aperture_rotation.unwrap_or(0.0),
                )
            })
            .map_err(|e| self.camera_err(e))?;
        let lens = match &c.aperture_image {
            Some(file) => {
                if c.aperture_blades.is_some() {
                    return Err(self.err(
                        "camera.aperture_image",
                        "give the aperture either as blades (aperture_blades) or as an image \
                         (aperture_image), not both",
                    ));
                }
                let image = self.aperture_image(file)?;
                lens.with_aperture(Aperture::image(image))
                    .map_err(|e| self.camera_err(e))?
            }
            None => lens,
        };
        let lens = match c.anamorphic {
            Some(squeeze) => {
                let aperture = lens
                    .aperture
                    .clone()
                    .with_anamorphic(squeeze)
                    .map_err(|e| self.camera_err(e))?;
                lens.with_aperture(aperture)
                    .map_err(|e| self.camera_err(e))?
            }
            None => lens,
        };
        let lens = match c.focal_plane_tilt {
            Some(tilt) => {
                self.finite("camera.focal_plane_tilt", &tilt)?;
                if matches!(kind, CameraKind::Perspective | CameraKind::Orthographic) {
                    lens.with_tilt(tilt).map_err(|e| self.camera_err(e))?
                } else {
                    lens
                }
            }
            None => lens,
        };
        let timing = self.timing(&c, shutter)?;
        if extrinsics.is_some() && end.is_some() {
            return Err(self.err(
                "camera.rvec",
                "OpenCV extrinsics give a fixed pose; a moving camera needs eye_end, target_end \
                 or up_end with a look-at",
            ));
        }

        let realistic = if kind == CameraKind::Realistic {
            Some(self.realistic(
                c.lens_file,
                [c.aperture_diameter, c.focus_distance, c.film_diagonal],
                c.focal_plane_tilt,
                base,
            )?)
        } else {
            None
        };

        // The OpenCV models' intrinsics (pixels) and distortion (checked by the model).
        let opencv = matches!(kind, CameraKind::OpenCv | CameraKind::OpenCvFisheye);
        let intrinsics = match (c.fx, c.fy, c.cx, c.cy) {
            (Some(fx), Some(fy), Some(cx), Some(cy)) if opencv => {
                Some(OpenCvIntrinsics { fx, fy, cx, cy })
            }
            _ if opencv => {
                let missing = [("fx", c.fx), ("fy", c.fy), ("cx", c.cx), ("cy", c.cy)]
                    .into_iter()
                    .find(|(_, v)| v.is_none())
                    .map_or("fx", |(k, _)| k);
                return Err(self.err(
                    &format!("camera.{missing}"),
                    format!(
                        "an {name} camera needs fx, fy, cx and cy (pixels); {missing} is missing"
                    ),
                ));
            }
            _ => None,
        };
        let distortion = c.distortion.unwrap_or_else(|| vec![0.0; 4]);

        let projection = match c.projection {
            Some(p) => p
                .parse::<FisheyeProjection>()
                .map_err(|e| self.camera_err(e))?,
            None => FisheyeProjection::Equidistant,
        };
        let face = match c.face {
            Some(f) => f.parse::<CubeFace>().map_err(|e| self.camera_err(e))?,
            None => CubeFace::PositiveZ,
        };
        let lens_shift = c.lens_shift.unwrap_or([0.0, 0.0]);
        self.finite("camera.lens_shift", &lens_shift)?;

        // [camera.stereo]: an off-axis pair needs its convergence distance; the ODS camera
        // reads only the interaxial.
        let stereo = match c.stereo {
            Some(raw) if reads(kind, "stereo") => {
                let interaxial = raw.interaxial.unwrap_or(DEFAULT_INTERAXIAL);
                let convergence = match (raw.convergence, kind) {
                    (Some(c), _) => c,
                    // The ODS camera reads only the interaxial; any valid convergence will do.
                    (None, CameraKind::Ods) => 1.0,
                    (None, _) => {
                        return Err(self.err(
                            "camera.stereo",
                            "an off-axis stereo pair needs `convergence`, the distance of its \
                             zero-parallax plane",
                        ));
                    }
                };
                if kind == CameraKind::Ods {
                    for (key, g) in [
                        ("convergence", raw.convergence.is_some()),
                        ("layout", raw.layout.is_some()),
                    ] {
                        if g {
                            ignored
                                .push(format!("camera.stereo.{key} is ignored by the ods camera"));
                        }
                    }
                }
                let rig =
                    StereoRig::new(interaxial, convergence).map_err(|e| self.camera_err(e))?;
                let layout = match raw.layout.as_deref() {
                    None => StereoLayout::SideBySide,
                    Some(l) => StereoLayout::from_name(l).ok_or_else(|| {
                        self.err(
                            "camera.stereo.layout",
                            format!(
                                "unknown layout `{l}`, expected side_by_side, separate or anaglyph"
                            ),
                        )
                    })?,
                };
                if pose.is_some() && kind == CameraKind::Perspective {
                    return Err(self.err(
                        "camera.stereo",
                        "an off-axis stereo pair moves its eyes along the look-at; give the \
                         pose as eye, target and up, not as a matrix (pose)",
                    ));
                }
                Some(StereoSettings { rig, layout })
            }
            _ => None,
        };

        Ok(CameraSettings {
            kind,
            start,
            end,
            fov,
            fov_axis,
            screen_window,
            near,
            far,
            lens,
            shutter,
            timing,
            exposure,
            extrinsics,
            intrinsics,
            distortion,
            projection,
            face,
            lens_shift,
            stereo,
            eye: None,
            pose,
            realistic,
        })
    }

    /// The realistic camera's keys: the lens file read (relative to the scene file) and
    /// parsed, the numbers checked for finiteness (the camera checks the rest when built).
    /// `numbers` are `aperture_diameter`, `focus_distance` and `film_diagonal`.
    fn realistic(
        &self,
        lens_file: Option<String>,
        numbers: [Option<f32>; 3],
        focal_plane_tilt: Option<[f32; 2]>,
        base: &Path,
    ) -> Result<RealisticSettings, RenderError> {
        let [aperture_diameter, focus_distance, film_diagonal] = numbers;
        let Some(file) = lens_file else {
            return Err(self.err(
                "camera.lens_file",
                "a realistic camera needs `lens_file`, a lens prescription (see scenes/lenses/)",
            ));
        };
        let lens_file = base.join(&file);
        let text = std::fs::read_to_string(&lens_file).map_err(|e| {
            self.err(
                "camera.lens_file",
                format!("cannot read the lens file {}: {e}", lens_file.display()),
            )
        })?;
        let prescription = LensPrescription::parse(&text)
            .map_err(|e| self.err("camera.lens_file", format!("{}: {e}", lens_file.display())))?;
        let focus_distance = focus_distance.unwrap_or(DEFAULT_FOCUS_DISTANCE);
        let film_diagonal = film_diagonal.unwrap_or(DEFAULT_FILM_DIAGONAL);
        self.finite("camera.focus_distance", &[focus_distance])?;
        self.finite("camera.film_diagonal", &[film_diagonal])?;
        if let Some(a) = aperture_diameter {
            self.finite("camera.aperture_diameter", &[a])?;
        }
        Ok(RealisticSettings {
            lens_file,
            prescription,
            aperture_diameter,
            focus_distance,
            film_diagonal,
            focal_plane_tilt: focal_plane_tilt.unwrap_or([0.0, 0.0]),
        })
    }

    /// `f_number`, `shutter_time`, `iso`, `exposure_compensation`: None when none is given
    /// (the image is then unchanged), else the settings with the others at their defaults.
    fn exposure(&self, c: &RawCamera) -> Result<Option<Exposure>, RenderError> {
        if c.f_number.is_none()
            && c.shutter_time.is_none()
            && c.iso.is_none()
            && c.exposure_compensation.is_none()
        {
            return Ok(None);
        }
        let exposure = Exposure {
            f_number: c.f_number.unwrap_or(Exposure::UNIT.f_number),
            shutter_time: c.shutter_time.unwrap_or(Exposure::UNIT.shutter_time),
            iso: c.iso.unwrap_or(Exposure::UNIT.iso),
            compensation: c.exposure_compensation.unwrap_or(0.0),
        };
        exposure.validate().map_err(|e| self.camera_err(e))?;
        Ok(Some(exposure))
    }

    /// `lens_radius`, or `focal_length / (2 f_number)` when `focal_length` is given (which
    /// needs `f_number`); both given and disagreeing is an error.
    fn lens_radius(&self, c: &RawCamera, exposure: Option<&Exposure>) -> Result<f32, RenderError> {
        let Some(focal_length) = c.focal_length else {
            return Ok(c.lens_radius.unwrap_or(0.0));
        };
        if !(focal_length.is_finite() && focal_length > 0.0) {
            return Err(self.err(
                "camera.focal_length",
                format!("focal_length must be a finite number > 0, got {focal_length}"),
            ));
        }
        let Some(exposure) = exposure.filter(|_| c.f_number.is_some()) else {
            return Err(self.err(
                "camera.focal_length",
                "focal_length gives lens_radius = focal_length / (2 f_number): f_number is \
                 missing",
            ));
        };
        let derived = exposure.lens_radius(focal_length);
        // NaN never agrees.
        let agrees = |given: f32| (given - derived).abs() <= 1e-4 * derived;
        if let Some(given) = c.lens_radius
            && !agrees(given)
        {
            return Err(self.camera_err(CameraError::LensRadiusDisagrees {
                lens_radius: given,
                derived,
            }));
        }
        Ok(derived)
    }

    /// The aperture image relative to the scene file: an OpenEXR file's linear values, or a
    /// PNG (any format the image crate reads) sRGB-decoded; the weights are Rec. 709 luminance
    /// times alpha.
    fn aperture_image(&self, file: &str) -> Result<ApertureImage, RenderError> {
        let path = self.file.parent().unwrap_or(Path::new("")).join(file);
        let cannot = |e: &dyn std::fmt::Display| {
            self.err(
                "camera.aperture_image",
                format!("cannot read the aperture image {}: {e}", path.display()),
            )
        };
        let luminance = |rgb: [f32; 3], alpha: f32| obscura_shade::luminance(rgb.into()) * alpha;
        let exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        let (weights, width, height) = if exr {
            let (image, _) = crate::read_exr(&path).map_err(|e| cannot(&e))?;
            let weights = image
                .pixels
                .iter()
                .map(|p| luminance([p[0], p[1], p[2]], p[3]))
                .collect::<Vec<f32>>();
            (weights, image.width, image.height)
        } else {
            let rgba = image::open(&path).map_err(|e| cannot(&e))?.to_rgba8();
            let (width, height) = rgba.dimensions();
            let weights = rgba
                .pixels()
                .map(|p| {
                    luminance(
                        [p[0], p[1], p[2]].map(srgb_to_linear),
                        f32::from(p[3]) / 255.0,
                    )
                })
                .collect::<Vec<f32>>();
            (weights, width, height)
        };
        ApertureImage::new(&weights, width as usize, height as usize).map_err(|e| {
            self.err(
                "camera.aperture_image",
                format!("{} ({})", e, path.display()),
            )
        })
    }

    /// `shutter_curve` and `rolling_shutter`.
    fn timing(&self, c: &RawCamera, shutter: Shutter) -> Result<ShutterTiming, RenderError> {
        let curve = match &c.shutter_curve {
            Some(points) => Some(Arc::new(PiecewiseShutterCurve::new(points).map_err(
                |e| {
                    // A point at fault is named by its index, so the message finds its row.
                    let key = match &e {
                        obscura_sample::SampleError::InvalidShutterCurve {
                            point: Some(i), ..
                        } => format!("camera.shutter_curve[{i}]"),
                        _ => "camera.shutter_curve".to_string(),
                    };
                    self.err(&key, CameraError::ShutterCurve(e.to_string()).to_string())
                },
            )?)),
            None => None,
        };
        let rolling = match &c.rolling_shutter {
            Some(r) => {
                let Some(readout) = r.readout else {
                    return Err(self.err(
                        "camera.rolling_shutter",
                        "rolling_shutter needs `readout`, the seconds from the first row's \
                         opening to the last's",
                    ));
                };
                let direction = match &r.direction {
                    Some(d) => d
                        .parse::<RollingDirection>()
                        .map_err(|e| self.camera_err(e))?,
                    None => RollingDirection::TopToBottom,
                };
                Some(RollingShutter { readout, direction })
            }
            None => None,
        };
        let timing = ShutterTiming { curve, rolling };
        timing.validate(shutter).map_err(|e| self.camera_err(e))?;
        Ok(timing)
    }

    /// Checks a look-at frame by building its pose; a degenerate one is reported at the key
    /// that makes it so (`target` for eye == target, `up` for a bad up vector).
    fn look_at(&self, end: bool, l: &LookAt) -> Result<(), RenderError> {
        match l.pose() {
            Ok(_) => Ok(()),
            Err(CameraError::Pose(SpaceError::DegenerateLookAt(why))) => {
                let key = match (why.starts_with("up"), end) {
                    (true, false) => "camera.up",
                    (true, true) => "camera.up_end",
                    (false, false) => "camera.target",
                    (false, true) => "camera.target_end",
                };
                Err(self.err(key, why))
            }
            Err(e) => Err(self.err(if end { "camera.eye_end" } else { "camera" }, e.to_string())),
        }
    }
}

/// The sRGB transfer function's inverse: an 8-bit code to linear.
fn srgb_to_linear(code: u8) -> f32 {
    let v = f32::from(code) / 255.0;
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every camera-crate error that names a `[camera]` key maps onto that key, so that the
    /// message points at the line the user must fix.
    #[test]
    fn camera_errors_map_onto_their_keys() {
        let cases = [
            (CameraError::Fov { got: 180.0 }, "camera.fov"),
            (
                CameraError::NearFar {
                    near: 2.0,
                    far: 1.0,
                },
                "camera.far",
            ),
            (
                CameraError::Near {
                    got: -1.0,
                    positive: false,
                },
                "camera.near",
            ),
            (CameraError::LensRadius { got: -1.0 }, "camera.lens_radius"),
            (
                CameraError::FocalDistance { got: 0.0 },
                "camera.focal_distance",
            ),
            (CameraError::Blades { got: 2 }, "camera.aperture_blades"),
            (
                CameraError::Shutter {
                    open: 1.0,
                    close: 0.0,
                },
                "camera.shutter",
            ),
            (CameraError::UnknownFovAxis("z".into()), "camera.fov_axis"),
            (
                CameraError::NonFinite {
                    what: "aperture rotation",
                    got: f32::NAN,
                },
                "camera.aperture_rotation",
            ),
            (
                CameraError::LensPrescription {
                    line: Some(3),
                    message: "x".into(),
                },
                "camera.lens_file",
            ),
            (
                CameraError::ApertureDiameter {
                    got: 30.0,
                    stop: 17.1,
                },
                "camera.aperture_diameter",
            ),
            (
                CameraError::FocusDistance { got: 0.01 },
                "camera.focus_distance",
            ),
            (
                CameraError::FilmDiagonal { got: 0.0 },
                "camera.film_diagonal",
            ),
            (
                CameraError::NonFinite {
                    what: "focus_distance",
                    got: f32::NAN,
                },
                "camera.focus_distance",
            ),
        ];
        for (e, key) in cases {
            assert_eq!(camera_key(&e), key, "{e}");
        }
    }

    /// The keys a bad value is reported at, through the whole parser: file, key and line.
    #[test]
    fn bad_camera_values_name_key_and_line() {
        let scene = |camera: &str| {
            format!("[film]\nresolution = [8, 8]\n[camera]\neye = [0.0, 0.0, 5.0]\n{camera}\n")
        };
        for (camera, key) in [
            ("fov = 0.0", "camera.fov"),
            ("fov_axis = \"z\"", "camera.fov_axis"),
            ("near = 2.0\nfar = 1.0", "camera.far"),
            ("lens_radius = -0.5", "camera.lens_radius"),
            ("focal_distance = 0.0", "camera.focal_distance"),
            ("aperture_blades = 2", "camera.aperture_blades"),
            ("aperture_blades = 65", "camera.aperture_blades"),
            ("shutter = [1.0, 0.0]", "camera.shutter"),
            ("anamorphic = 0.5", "camera.anamorphic"),
            (
                "shutter_curve = [[0.5, 1.0], [0.2, 1.0]]",
                "camera.shutter_curve[1]",
            ),
            (
                "rolling_shutter = { readout = 2.0 }",
                "camera.rolling_shutter",
            ),
            ("focal_plane_tilt = [5.0, 0.0]", "camera.focal_plane_tilt"),
            ("f_number = -2.0", "camera.f_number"),
            ("iso = 0.0", "camera.iso"),
            ("shutter_time = 0.0", "camera.shutter_time"),
            (
                "exposure_compensation = 500.0",
                "camera.exposure_compensation",
            ),
            ("focal_length = 0.05", "camera.focal_length"),
            (
                "screen_window = [1.0, -1.0, -1.0, 1.0]",
                "camera.screen_window",
            ),
        ] {
            let text = scene(camera);
            let e =
                crate::parse_description(std::path::Path::new("s.toml"), &text).expect_err(camera);
            let line = text
                .lines()
                .position(|l| {
                    // The key's own line (a point of an array: the array's, on one line).
                    let name = key.trim_start_matches("camera.");
                    l.starts_with(name.split('[').next().unwrap_or(name))
                })
                .map(|i| i + 1);
            match e {
                RenderError::Scene {
                    key: Some(k),
                    line: l,
                    ..
                } => {
                    assert_eq!(k, key, "{camera}");
                    assert_eq!(l, line, "{camera}");
                }
                other => panic!("{camera}: {other}"),
            }
        }
    }
    /// `pose` is world-from-camera, row-major: the look-at's own matrix gives the look-at's
    /// camera, and a mirrored matrix the mirrored image.
    #[test]
    fn pose_is_a_world_from_camera_matrix() {
        use obscura_camera::Camera;
        use obscura_space::Point3;
        let look = "eye = [1.0, 2.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]";
        let scene = |camera: &str| {
            format!("[film]\nresolution = [16, 12]\n[camera]\nfov = 40.0\n{camera}\n")
        };
        let path = std::path::Path::new("s.toml");
        let by_look = crate::parse_description(path, &scene(look)).unwrap();
        let m = by_look
            .camera
            .start
            .pose()
            .unwrap()
            .matrix()
            .transpose()
            .to_cols_array();
        let rows = |m: [f32; 16]| format!("{m:?}");
        let by_pose =
            crate::parse_description(path, &scene(&format!("pose = {}", rows(m)))).unwrap();
        // Mirror camera x: the image flips left to right.
        let mut mirrored = m;
        for r in 0..3 {
            mirrored[4 * r] = -mirrored[4 * r];
        }
        let by_mirror =
            crate::parse_description(path, &scene(&format!("pose = {}", rows(mirrored)))).unwrap();
        let (a, b, c) = (
            crate::camera_of(&by_look).unwrap(),
            crate::camera_of(&by_pose).unwrap(),
            crate::camera_of(&by_mirror).unwrap(),
        );
        for p in [[0.3f32, 0.2, 0.1], [-0.5, 0.4, 1.0]] {
            let p = Point3::new(p[0], p[1], p[2]);
            let (ra, rb, rc) = (
                a.project(p, 0.0).unwrap(),
                b.project(p, 0.0).unwrap(),
                c.project(p, 0.0).unwrap(),
            );
            assert!((ra.x - rb.x).abs() < 1e-3 && (ra.y - rb.y).abs() < 1e-3);
            assert!((rc.x - (16.0 - ra.x)).abs() < 1e-3 && (rc.y - ra.y).abs() < 1e-3);
        }
        // One way only; pose_end needs pose; a singular matrix is refused at `camera.pose`.
        for (camera, key) in [
            (
                format!("pose = {}\neye = [0.0, 0.0, 1.0]", rows(m)),
                "camera.pose",
            ),
            (format!("pose_end = {}", rows(m)), "camera.pose_end"),
            (format!("pose = {}", rows([0.0; 16])), "camera.pose"),
            (
                format!("pose = {}\n[camera.stereo]\nconvergence = 2.0", rows(m)),
                "camera.stereo",
            ),
        ] {
            match crate::parse_description(path, &scene(&camera)) {
                Err(RenderError::Scene { key: Some(k), .. }) => assert_eq!(k, key, "{camera}"),
                other => panic!("{camera}: {other:?}"),
            }
        }
    }

    /// An aperture image may be an OpenEXR file (pbrt's apertures often are): its linear
    /// values are the weights. A 4 x 2 image with one lit texel becomes a 4 x 2 aperture; an
    /// all-black one is refused as black, so the weights are the file's.
    #[test]
    fn an_aperture_image_may_be_openexr() {
        let dir = std::env::temp_dir().join(format!("obscura-aperture-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let write = |name: &str, lit: bool| {
            let mut pixels = vec![[0.0, 0.0, 0.0, 1.0]; 8];
            if lit {
                pixels[5] = [2.0, 2.0, 2.0, 1.0];
            }
            let image = crate::Image {
                width: 4,
                height: 2,
                pixels,
            };
            crate::write_image(&dir.join(name), &image, &crate::ImageInfo::default()).unwrap();
        };
        write("lit.exr", true);
        write("black.exr", false);
        let scene = |file: &str| {
            format!(
                "[film]\nresolution = [8, 8]\n[camera]\nlens_radius = 0.1\nfocal_distance = 2.0\n\
                 aperture_image = \"{file}\"\n"
            )
        };
        let path = dir.join("s.toml");
        let d = crate::parse_description(&path, &scene("lit.exr")).unwrap();
        match &d.camera.lens.aperture.shape {
            obscura_camera::ApertureShape::Image(image) => assert_eq!(image.size(), [4, 2]),
            other => panic!("not an image aperture: {other:?}"),
        }
        let e = crate::parse_description(&path, &scene("black.exr")).unwrap_err();
        assert!(e.to_string().contains("black"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
