//! The crate's one error type.

use core::fmt;
use obscura_space::SpaceError;

/// Why a camera (or a piece of one) could not be built. Every message names the parameter and
/// the offending value, so it stands alone in a user's terminal.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraError {
    /// A parameter was NaN or infinite.
    NonFinite {
        /// The parameter's name as the scene format spells it, e.g. `"near"`.
        what: &'static str,
        /// The value given.
        got: f32,
    },
    /// The field of view is not in (0, 180) degrees.
    Fov {
        /// The value given, in degrees.
        got: f32,
    },
    /// An unknown `fov_axis` name.
    UnknownFovAxis(String),
    /// `near` is negative (or, for a perspective camera, not positive).
    Near {
        /// The value given.
        got: f32,
        /// True when zero is also refused (perspective cameras).
        positive: bool,
    },
    /// `near >= far`.
    NearFar {
        /// The near value given.
        near: f32,
        /// The far value given.
        far: f32,
    },
    /// A negative lens radius.
    LensRadius {
        /// The value given.
        got: f32,
    },
    /// A focal distance that is not positive.
    FocalDistance {
        /// The value given.
        got: f32,
    },
    /// An aperture with one or two blades.
    Blades {
        /// The value given.
        got: u32,
    },
    /// A zero width or height.
    Resolution {
        /// The resolution given, width then height.
        got: [u32; 2],
    },
    /// A width or height above [`MAX_RESOLUTION`](crate::MAX_RESOLUTION), where raster
    /// coordinates stop being exact in f32.
    ResolutionTooLarge {
        /// The resolution given, width then height.
        got: [u32; 2],
    },
    /// A screen window with a non-positive extent (or a non-finite bound).
    ScreenWindow {
        /// The window given: xmin, xmax, ymin, ymax.
        got: [f32; 4],
    },
    /// A crop window outside [0, 1]^2, empty, or covering no pixel.
    CropWindow {
        /// The window given: x0, x1, y0, y1 in NDC.
        got: [f32; 4],
    },
    /// A shutter that closes before it opens (or a non-finite time).
    Shutter {
        /// The opening time given.
        open: f32,
        /// The closing time given.
        close: f32,
    },
    /// The camera pose could not be built (a degenerate look-at, mirrored keyframes...).
    Pose(SpaceError),
    /// An unknown fisheye `projection` name.
    UnknownFisheyeProjection(String),
    /// A fisheye field of view outside its projection's range.
    FisheyeFov {
        /// The projection's scene name, e.g. `"orthographic"`.
        projection: &'static str,
        /// The largest field of view the projection allows, in degrees.
        max: f32,
        /// Whether `max` itself is allowed.
        max_inclusive: bool,
        /// The value given, in degrees.
        got: f32,
    },
    /// An unknown cube-map `face` name.
    UnknownCubeFace(String),
    /// A film whose shape the camera model cannot use (a non-square octahedral or cube-face
    /// film, an ODS film of odd height).
    FilmShape {
        /// The camera model's scene name, e.g. `"octahedral"`.
        model: &'static str,
        /// What the model needs, e.g. `"a square"`.
        need: &'static str,
        /// The resolution given, width then height.
        got: [u32; 2],
    },
    /// A negative ODS `interaxial` distance.
    Interaxial {
        /// The value given.
        got: f32,
    },
    /// A focal length (`fx` or `fy`, in pixels) that is not positive.
    FocalLength {
        /// The parameter's name, `"fx"` or `"fy"`.
        what: &'static str,
        /// The value given.
        got: f64,
    },
    /// A distortion list of a length the model does not read.
    DistortionLength {
        /// The camera type, `"opencv"` or `"opencv_fisheye"`.
        model: &'static str,
        /// The number of entries given.
        got: usize,
    },
}

impl fmt::Display for CameraError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CameraError::NonFinite { what, got } => {
                write!(f, "{what} must be a finite number, got {got}")
            }
            CameraError::Fov { got } => {
                write!(f, "fov must be in (0, 180) degrees, got {got}")
            }
            CameraError::UnknownFovAxis(name) => write!(
                f,
                "fov_axis must be one of \"smaller\", \"larger\", \"x\", \"y\", \"diagonal\", got {name:?}"
            ),
            CameraError::Near {
                got,
                positive: true,
            } => {
                write!(f, "near must be > 0 for a perspective camera, got {got}")
            }
            CameraError::Near {
                got,
                positive: false,
            } => {
                write!(f, "near must be >= 0, got {got}")
            }
            CameraError::NearFar { near, far } => {
                write!(
                    f,
                    "near must be less than far, got near = {near} and far = {far}"
                )
            }
            CameraError::LensRadius { got } => {
                write!(f, "lens_radius must be >= 0, got {got}")
            }
            CameraError::FocalDistance { got } => {
                write!(f, "focal_distance must be > 0, got {got}")
            }
            CameraError::Blades { got } => write!(
                f,
                "aperture blades must be 0 (a round aperture) or at least 3, got {got}"
            ),
            CameraError::Resolution { got } => write!(
                f,
                "resolution must be at least 1 x 1 pixels, got {} x {}",
                got[0], got[1]
            ),
            CameraError::ResolutionTooLarge { got } => write!(
                f,
                "resolution must be at most {} pixels along each axis, got {} x {}",
                crate::MAX_RESOLUTION,
                got[0],
                got[1]
            ),
            CameraError::ScreenWindow { got } => write!(
                f,
                "screen_window must be finite with xmin < xmax and ymin < ymax, got {got:?}"
            ),
            CameraError::CropWindow { got } => write!(
                f,
                "crop window must satisfy 0 <= x0 < x1 <= 1 and 0 <= y0 < y1 <= 1 and cover at \
                 least one pixel, got {got:?}"
            ),
            CameraError::Shutter { open, close } => write!(
                f,
                "shutter must be finite with open <= close, got [{open}, {close}]"
            ),
            CameraError::Pose(e) => write!(f, "camera pose: {e}"),
            CameraError::UnknownFisheyeProjection(name) => write!(
                f,
                "projection must be one of \"equidistant\", \"equisolid\", \"stereographic\", \
                 \"orthographic\", got {name:?}"
            ),
            CameraError::FisheyeFov {
                projection,
                max,
                max_inclusive,
                got,
            } => write!(
                f,
                "fov of a {projection} fisheye must be in (0, {max}{} degrees, got {got}",
                if *max_inclusive { "]" } else { ")" }
            ),
            CameraError::UnknownCubeFace(name) => write!(
                f,
                "face must be one of \"+x\", \"-x\", \"+y\", \"-y\", \"+z\", \"-z\", got {name:?}"
            ),
            CameraError::FilmShape { model, need, got } => write!(
                f,
                "a {model} camera needs {need} film, got {} x {}",
                got[0], got[1]
            ),
            CameraError::Interaxial { got } => {
                write!(f, "interaxial must be >= 0, got {got}")
            }
            CameraError::FocalLength { what, got } => {
                write!(f, "{what} must be > 0 pixels, got {got}")
            }
            CameraError::DistortionLength { model, got } => {
                let lengths = if *model == "opencv" {
                    "4, 5, 8 or 12"
                } else {
                    "4"
                };
                write!(
                    f,
                    "distortion of an {model} camera must have {lengths} entries, got {got}"
                )
            }
        }
    }
}

impl std::error::Error for CameraError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CameraError::Pose(e) => Some(e),
            _ => None,
        }
    }
}

impl From<SpaceError> for CameraError {
    fn from(e: SpaceError) -> Self {
        CameraError::Pose(e)
    }
}

/// `Ok(x)` when `x` is finite, else the error naming `what`.
pub(crate) fn finite(what: &'static str, x: f32) -> Result<f32, CameraError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(CameraError::NonFinite { what, got: x })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_parameter_and_value() {
        assert_eq!(
            CameraError::Fov { got: 180.0 }.to_string(),
            "fov must be in (0, 180) degrees, got 180"
        );
        assert_eq!(
            CameraError::NearFar {
                near: 2.0,
                far: 1.0
            }
            .to_string(),
            "near must be less than far, got near = 2 and far = 1"
        );
        assert_eq!(
            CameraError::NonFinite {
                what: "near",
                got: f32::NAN
            }
            .to_string(),
            "near must be a finite number, got NaN"
        );
        assert!(
            CameraError::Resolution { got: [0, 5] }
                .to_string()
                .contains("0 x 5")
        );
    }

    #[test]
    fn finite_rejects_nan_and_infinity() {
        assert_eq!(finite("far", 1e30), Ok(1e30));
        assert!(finite("far", f32::INFINITY).is_err());
        assert!(finite("far", f32::NAN).is_err());
    }
}
