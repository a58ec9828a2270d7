//! The crate's one error type.

use obscura_space::SpaceError;

/// Why a camera (or a piece of one) could not be built. Every message names the parameter and
/// the offending value, so it stands alone in a user's terminal.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CameraError {
    /// A parameter was NaN or infinite.
    #[error("{what} must be a finite number, got {got}")]
    NonFinite {
        /// The parameter's name as the scene format spells it, e.g. `"near"`.
        what: &'static str,
        /// The value given.
        got: f32,
    },
    /// The field of view is not in (0, 180) degrees.
    #[error("fov must be in (0, 180) degrees, got {got}")]
    Fov {
        /// The value given, in degrees.
        got: f32,
    },
    /// An unknown `fov_axis` name.
    #[error(
        "fov_axis must be one of \"smaller\", \"larger\", \"x\", \"y\", \"diagonal\", got {0:?}"
    )]
    UnknownFovAxis(String),
    /// `near` is negative (or, for a perspective camera, not positive).
    #[error(
        "near must be {}, got {got}",
        if *positive { "> 0 for a perspective camera" } else { ">= 0" }
    )]
    Near {
        /// The value given.
        got: f32,
        /// True when zero is also refused (perspective cameras).
        positive: bool,
    },
    /// `near >= far`.
    #[error("far must be greater than near, got near = {near} and far = {far}")]
    NearFar {
        /// The near value given.
        near: f32,
        /// The far value given.
        far: f32,
    },
    /// A negative lens radius.
    #[error("lens_radius must be >= 0, got {got}")]
    LensRadius {
        /// The value given.
        got: f32,
    },
    /// A focal distance that is not positive.
    #[error("focal_distance must be > 0, got {got}")]
    FocalDistance {
        /// The value given.
        got: f32,
    },
    /// An aperture with one or two blades, or more than [`MAX_BLADES`](crate::MAX_BLADES).
    #[error(
        "aperture_blades must be 0 (a round aperture) or 3 to {}, got {got}",
        crate::MAX_BLADES
    )]
    Blades {
        /// The value given.
        got: u32,
    },
    /// An aperture image that cannot be sampled.
    #[error("aperture_image: {reason}")]
    ApertureImage {
        /// What is wrong with it.
        reason: String,
    },
    /// An anamorphic squeeze below 1.
    #[error("anamorphic must be >= 1 (the horizontal squeeze of the aperture), got {got}")]
    Anamorphic {
        /// The value given.
        got: f32,
    },
    /// A shutter curve that is not a density over the shutter interval.
    #[error("{0}")]
    ShutterCurve(String),
    /// A rolling-shutter readout that is negative or longer than the shutter interval.
    #[error(
        "rolling_shutter readout must be in [0, close - open] = [0, {interval}] seconds (the rows' windows lie inside the shutter interval), got {readout}"
    )]
    RollingReadout {
        /// The readout given.
        readout: f32,
        /// The shutter interval's length.
        interval: f32,
    },
    /// An unknown rolling-shutter direction.
    #[error(
        "rolling_shutter direction must be one of \"top_to_bottom\", \"bottom_to_top\", \"left_to_right\", \"right_to_left\", got {0:?}"
    )]
    UnknownRollingDirection(String),
    /// A focal-plane tilt outside (-90, 90) degrees.
    #[error("focal_plane_tilt angles must be in (-90, 90) degrees, got [{}, {}]", got[0], got[1])]
    FocalPlaneTilt {
        /// The angles given, about camera x then y.
        got: [f32; 2],
    },
    /// A realistic camera's tilted plane of focus that its lens cannot image onto a film
    /// behind it: the plane comes nearer than the lens can focus, or the film tilted to its
    /// image would reach more than halfway to the rear element.
    #[error(
        "focal_plane_tilt [{}, {}]: this lens cannot image the tilted plane onto a film behind it (the plane comes nearer than the lens can focus, or the film would have to tilt into the lens); tilt less or focus farther",
        got[0], got[1]
    )]
    TiltOutOfReach {
        /// The angles given, about camera x then y.
        got: [f32; 2],
    },
    /// A focal-plane tilt on a camera that cannot tilt it.
    #[error(
        "focal_plane_tilt needs a perspective or orthographic camera with a thin lens (lens_radius > 0) or a realistic camera: a pinhole or another model has no plane of focus to tilt"
    )]
    TiltWithoutLens,
    /// An exposure setting out of range.
    #[error("{what} must be {need}, got {got:?}")]
    Exposure {
        /// The key, e.g. `"f_number"`.
        what: &'static str,
        /// What would be accepted.
        need: &'static str,
        /// The value given.
        got: f32,
    },
    /// `lens_radius` given together with `focal_length` and `f_number`, disagreeing.
    #[error(
        "lens_radius = {lens_radius} disagrees with focal_length / (2 f_number) = {derived}: give one or the other"
    )]
    LensRadiusDisagrees {
        /// The radius given.
        lens_radius: f32,
        /// The radius the focal length and f-number give.
        derived: f32,
    },
    /// A zero width or height.
    #[error("resolution must be at least 1 x 1 pixels, got {} x {}", got[0], got[1])]
    Resolution {
        /// The resolution given, width then height.
        got: [u32; 2],
    },
    /// A width or height above [`MAX_RESOLUTION`](crate::MAX_RESOLUTION), where raster
    /// coordinates stop being exact in f32.
    #[error(
        "resolution must be at most {} pixels along each axis, got {} x {}",
        crate::MAX_RESOLUTION,
        got[0],
        got[1]
    )]
    ResolutionTooLarge {
        /// The resolution given, width then height.
        got: [u32; 2],
    },
    /// A screen window with a non-positive extent (or a non-finite bound).
    #[error("screen_window must be finite with xmin < xmax and ymin < ymax, got {got:?}")]
    ScreenWindow {
        /// The window given: xmin, xmax, ymin, ymax.
        got: [f32; 4],
    },
    /// A crop window outside [0, 1]^2, empty, or covering no pixel.
    #[error(
        "crop window must satisfy 0 <= x0 < x1 <= 1 and 0 <= y0 < y1 <= 1 and cover at least one pixel, got {got:?}"
    )]
    CropWindow {
        /// The window given: x0, x1, y0, y1 in NDC.
        got: [f32; 4],
    },
    /// A shutter that closes before it opens (or a non-finite time).
    #[error("shutter must be finite with open <= close, got [{open}, {close}]")]
    Shutter {
        /// The opening time given.
        open: f32,
        /// The closing time given.
        close: f32,
    },
    /// A pose whose matrix is projective (bottom row not `[0 0 0 1]`): cameras need an
    /// affine pose, as every look-at is.
    #[error("camera pose must be affine (rotation, scale, translation), got a projective matrix")]
    ProjectivePose,
    /// The camera pose could not be built (a degenerate look-at, mirrored keyframes...).
    #[error("camera pose: {0}")]
    Pose(#[from] SpaceError),
    /// An unknown fisheye `projection` name.
    #[error(
        "projection must be one of \"equidistant\", \"equisolid\", \"stereographic\", \"orthographic\", got {0:?}"
    )]
    UnknownFisheyeProjection(String),
    /// A fisheye field of view outside its projection's range.
    #[error(
        "fov of the {projection} fisheye must be in (0, {max}{} degrees, got {got}",
        if *max_inclusive { "]" } else { ")" }
    )]
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
    #[error("face must be one of \"+x\", \"-x\", \"+y\", \"-y\", \"+z\", \"-z\", got {0:?}")]
    UnknownCubeFace(String),
    /// A film whose shape the camera model cannot use (a non-square octahedral or cube-face
    /// film, an ODS film of odd height).
    #[error("the {model} camera needs {need} film, got {} x {}", got[0], got[1])]
    FilmShape {
        /// The camera model's scene name, e.g. `"octahedral"`.
        model: &'static str,
        /// What the model needs, e.g. `"a square"`.
        need: &'static str,
        /// The resolution given, width then height.
        got: [u32; 2],
    },
    /// A negative ODS `interaxial` distance.
    #[error("interaxial must be >= 0, got {got}")]
    Interaxial {
        /// The value given.
        got: f32,
    },
    /// A stereo convergence distance that is not positive.
    #[error("convergence must be > 0, got {got}")]
    Convergence {
        /// The value given.
        got: f32,
    },
    /// A focal length (`fx` or `fy`, in pixels) that is not positive.
    #[error("{what} must be > 0 pixels, got {got}")]
    FocalLength {
        /// The parameter's name, `"fx"` or `"fy"`.
        what: &'static str,
        /// The value given.
        got: f64,
    },
    /// A distortion list of a length the model does not read.
    #[error(
        "distortion of the {model} camera must have {} entries, got {got}",
        if *model == "opencv" { "4, 5, 8 or 12" } else { "4" }
    )]
    DistortionLength {
        /// The camera type, `"opencv"` or `"opencv_fisheye"`.
        model: &'static str,
        /// The number of entries given.
        got: usize,
    },
    /// A lens prescription that does not parse or describes no usable lens.
    #[error(
        "lens prescription{}: {message}",
        match line { Some(l) => format!(", line {l}"), None => String::new() }
    )]
    LensPrescription {
        /// The 1-based line at fault, when one is.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// An aperture diameter that is not positive or exceeds the stop's diameter.
    #[error(
        "aperture_diameter must be > 0 mm and at most the stop's diameter of {stop} mm, got {got}"
    )]
    ApertureDiameter {
        /// The value given (mm).
        got: f32,
        /// The stop's diameter in the prescription (mm).
        stop: f32,
    },
    /// A focus distance the lens cannot focus at (not positive, or closer than its closest
    /// focus).
    #[error("focus_distance must be > 0 and beyond the lens's closest focus, got {got}")]
    FocusDistance {
        /// The value given (world units).
        got: f32,
    },
    /// A film diagonal that is not positive.
    #[error("film_diagonal must be > 0 mm, got {got}")]
    FilmDiagonal {
        /// The value given (mm).
        got: f32,
    },
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
            "far must be greater than near, got near = 2 and far = 1"
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
