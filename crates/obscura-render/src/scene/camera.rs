//! The `[camera]` keys: each maps onto a camera-crate type or check (`LookAt`, `FovAxis`,
//! `ScreenWindow`, `ThinLens`, `Shutter`, `validate_fov`, `validate_clip`), and a
//! [`CameraError`] maps back onto the key at fault and its line. The camera crate holds the
//! only set of checks.

use super::parse::Cx;
use super::raw::RawCamera;
use super::settings::{CameraKind, CameraSettings, V3};
use crate::error::RenderError;
use obscura_camera::{
    CameraError, FovAxis, LookAt, ScreenWindow, Shutter, ThinLens, validate_clip, validate_fov,
};
use obscura_space::{Point3, SpaceError, Vector3};

/// The scene key a camera-crate error is about.
fn key_of(e: &CameraError) -> &'static str {
    match e {
        CameraError::NonFinite { what, .. } => match *what {
            "near" => "camera.near",
            "far" => "camera.far",
            "fov" => "camera.fov",
            "lens_radius" => "camera.lens_radius",
            "focal_distance" => "camera.focal_distance",
            "aperture rotation" => "camera.aperture_rotation",
            _ => "camera",
        },
        CameraError::Fov { .. } => "camera.fov",
        CameraError::UnknownFovAxis(_) => "camera.fov_axis",
        CameraError::Near { .. } => "camera.near",
        CameraError::NearFar { .. } => "camera.far",
        CameraError::LensRadius { .. } => "camera.lens_radius",
        CameraError::FocalDistance { .. } => "camera.focal_distance",
        CameraError::Blades { .. } => "camera.aperture_blades",
        CameraError::ScreenWindow { .. } => "camera.screen_window",
        CameraError::Shutter { .. } => "camera.shutter",
        CameraError::Resolution { .. } | CameraError::ResolutionTooLarge { .. } => {
            "film.resolution"
        }
        CameraError::CropWindow { .. } => "film.crop",
        CameraError::ProjectivePose | CameraError::Pose(_) => "camera",
        CameraError::UnknownFisheyeProjection(_) => "camera.projection",
        CameraError::FisheyeFov { .. } => "camera.fov",
        CameraError::UnknownCubeFace(_) => "camera.face",
        CameraError::FilmShape { .. } => "film.resolution",
        CameraError::Interaxial { .. } => "camera.stereo.interaxial",
        CameraError::FocalLength { what, .. } => match *what {
            "fy" => "camera.fy",
            _ => "camera.fx",
        },
        CameraError::DistortionLength { .. } => "camera.distortion",
    }
}

fn kind_name(kind: CameraKind) -> &'static str {
    match kind {
        CameraKind::Perspective => "perspective",
        CameraKind::Orthographic => "orthographic",
        CameraKind::Environment => "environment",
    }
}

impl Cx<'_> {
    /// A camera-crate error as a scene error at its key and line.
    fn camera_err(&self, e: CameraError) -> RenderError {
        self.err(key_of(&e), e.to_string())
    }

    pub(super) fn camera(
        &self,
        c: RawCamera,
        ignored: &mut Vec<String>,
    ) -> Result<CameraSettings, RenderError> {
        let kind = match c.kind.as_deref().unwrap_or("perspective") {
            "perspective" => CameraKind::Perspective,
            "orthographic" => CameraKind::Orthographic,
            "environment" => CameraKind::Environment,
            other => {
                return Err(self.err(
                    "camera.type",
                    format!("unknown camera `{other}`, expected perspective, orthographic or environment"),
                ));
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

        let mut note = |key: &str, given: bool| {
            if given {
                ignored.push(format!(
                    "camera.{key} is ignored by the {} camera",
                    kind_name(kind)
                ));
            }
        };
        let perspective = kind == CameraKind::Perspective;
        let projective = kind != CameraKind::Environment;
        note("fov", !perspective && c.fov.is_some());
        note("fov_axis", !perspective && c.fov_axis.is_some());
        note("screen_window", !projective && c.screen_window.is_some());
        note("lens_radius", !projective && c.lens_radius.is_some());
        note("focal_distance", !projective && c.focal_distance.is_some());

        let fov = c.fov.unwrap_or(90.0);
        if perspective {
            validate_fov(fov).map_err(|e| self.camera_err(e))?;
        }
        let fov_axis = match c.fov_axis {
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
        let lens = ThinLens::new(
            c.lens_radius.unwrap_or(0.0),
            c.focal_distance.unwrap_or(1.0),
        )
        .and_then(|lens| {
            lens.with_blades(
                c.aperture_blades.unwrap_or(0),
                c.aperture_rotation.unwrap_or(0.0),
            )
        })
        .map_err(|e| self.camera_err(e))?;
        let shutter = c.shutter.unwrap_or([0.0, 1.0]);
        let shutter = Shutter::new(shutter[0], shutter[1]).map_err(|e| self.camera_err(e))?;
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
        })
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
        ];
        for (e, key) in cases {
            assert_eq!(key_of(&e), key, "{e}");
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
                .position(|l| l.starts_with(key.trim_start_matches("camera.")))
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
}
