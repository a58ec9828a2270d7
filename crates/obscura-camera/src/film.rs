//! Film geometry (resolution, screen window, crop window), the field-of-view axis and the
//! shutter interval.

use crate::error::{CameraError, finite};
use core::str::FromStr;

/// The largest width or height accepted: up to 2^24 every raster coordinate and pixel edge is
/// exact in f32.
pub const MAX_RESOLUTION: u32 = 1 << 24;

/// The interval the shutter stays open, in the scene's time unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shutter {
    /// Opening time.
    pub open: f32,
    /// Closing time (`>= open`; equal for an instantaneous shutter).
    pub close: f32,
}

impl Shutter {
    /// The shutter `[0, 1]` (the scene format's default).
    pub const UNIT: Shutter = Shutter {
        open: 0.0,
        close: 1.0,
    };

    /// A shutter open over `[open, close]`. Errors unless both are finite and `open <= close`.
    pub fn new(open: f32, close: f32) -> Result<Shutter, CameraError> {
        if !(open.is_finite() && close.is_finite()) || open > close {
            return Err(CameraError::Shutter { open, close });
        }
        Ok(Shutter { open, close })
    }

    /// The time of a sample's canonical `u` in `[0, 1)`: `open + u * (close - open)`
    /// (SCENE_FORMAT.md).
    #[inline]
    pub fn time_at(&self, u: f32) -> f32 {
        self.open + u * (self.close - self.open)
    }
}

impl Default for Shutter {
    fn default() -> Self {
        Shutter::UNIT
    }
}

/// A rectangle of the image plane: screen space for the perspective camera, camera-space world
/// units for the orthographic one. NDC `[0, 1]^2` spans it, NDC y pointing down from `y_max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenWindow {
    /// Left edge.
    pub x_min: f32,
    /// Right edge.
    pub x_max: f32,
    /// Bottom edge.
    pub y_min: f32,
    /// Top edge.
    pub y_max: f32,
}

impl ScreenWindow {
    /// A window from its bounds. Errors unless finite with `x_min < x_max` and `y_min < y_max`.
    pub fn new(x_min: f32, x_max: f32, y_min: f32, y_max: f32) -> Result<Self, CameraError> {
        let w = ScreenWindow {
            x_min,
            x_max,
            y_min,
            y_max,
        };
        w.validate()?;
        Ok(w)
    }

    /// The default window of SCENE_FORMAT.md for a resolution: `[-a, a] x [-1, 1]` when the
    /// aspect ratio `a = width / height >= 1`, else `[-1, 1] x [-1/a, 1/a]`. A zero width or
    /// height is read as 1 ([`FilmGeometry::new`] refuses it anyway).
    pub fn default_for(resolution: [u32; 2]) -> ScreenWindow {
        let width = resolution[0].max(1) as f32;
        let height = resolution[1].max(1) as f32;
        let aspect = width / height;
        if aspect >= 1.0 {
            ScreenWindow {
                x_min: -aspect,
                x_max: aspect,
                y_min: -1.0,
                y_max: 1.0,
            }
        } else {
            ScreenWindow {
                x_min: -1.0,
                x_max: 1.0,
                y_min: -1.0 / aspect,
                y_max: 1.0 / aspect,
            }
        }
    }

    /// The bounds as the scene format writes them: `[xmin, xmax, ymin, ymax]`.
    pub fn to_array(self) -> [f32; 4] {
        [self.x_min, self.x_max, self.y_min, self.y_max]
    }

    /// The window moved by a lens shift `[sx, sy]`, in fractions of its own width and height
    /// (+x right, +y up), as an architectural camera's rising front moves the lens: `sy = 0.1`
    /// shows a tenth of an image more at the top and as much less at the bottom, with vertical
    /// lines kept parallel. Errors: a non-finite shift.
    pub fn lens_shifted(self, shift: [f32; 2]) -> Result<ScreenWindow, CameraError> {
        if !shift.iter().all(|v| v.is_finite()) {
            let got = if shift[0].is_finite() {
                shift[1]
            } else {
                shift[0]
            };
            return Err(CameraError::NonFinite {
                what: "lens_shift",
                got,
            });
        }
        let dx = shift[0] * (self.x_max - self.x_min);
        let dy = shift[1] * (self.y_max - self.y_min);
        ScreenWindow::new(
            self.x_min + dx,
            self.x_max + dx,
            self.y_min + dy,
            self.y_max + dy,
        )
    }

    /// Half the width and half the height.
    pub fn half_extent(self) -> [f32; 2] {
        [
            0.5 * (self.x_max - self.x_min),
            0.5 * (self.y_max - self.y_min),
        ]
    }

    fn validate(self) -> Result<(), CameraError> {
        let a = self.to_array();
        let ok = a.iter().all(|v| v.is_finite())
            && self.x_min < self.x_max
            && self.y_min < self.y_max
            && (self.x_max - self.x_min).is_finite()
            && (self.y_max - self.y_min).is_finite();
        if ok {
            Ok(())
        } else {
            Err(CameraError::ScreenWindow { got: a })
        }
    }
}

/// The axis along which a perspective camera's field of view is measured: the fov spans the
/// screen window's half-extent along it (for `Diagonal`, half the window's diagonal).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FovAxis {
    /// The axis with the smaller half-extent (the scene format's default).
    #[default]
    Smaller,
    /// The axis with the larger half-extent.
    Larger,
    /// The horizontal axis.
    X,
    /// The vertical axis.
    Y,
    /// The window's diagonal.
    Diagonal,
}

impl FovAxis {
    /// The half-extent of `window` along this axis (the fov spans the default window's).
    pub fn half_extent(self, window: ScreenWindow) -> f32 {
        let [hx, hy] = window.half_extent();
        match self {
            FovAxis::Smaller => hx.min(hy),
            FovAxis::Larger => hx.max(hy),
            FovAxis::X => hx,
            FovAxis::Y => hy,
            FovAxis::Diagonal => hx.hypot(hy),
        }
    }

    /// The perspective scale `s = h / tan(fov / 2)` of a film of `resolution`, `h` the
    /// default window's half-extent along this axis: pbrt's screen space, onto which a screen
    /// window given in the scene is a window.
    pub(crate) fn perspective_scale(self, resolution: [u32; 2], fov_degrees: f32) -> f64 {
        let half_extent = f64::from(self.half_extent(ScreenWindow::default_for(resolution)));
        half_extent / (0.5 * f64::from(fov_degrees)).to_radians().tan()
    }

    /// The scene-file name: `"smaller"`, `"larger"`, `"x"`, `"y"` or `"diagonal"`.
    pub fn name(self) -> &'static str {
        match self {
            FovAxis::Smaller => "smaller",
            FovAxis::Larger => "larger",
            FovAxis::X => "x",
            FovAxis::Y => "y",
            FovAxis::Diagonal => "diagonal",
        }
    }
}

impl FromStr for FovAxis {
    type Err = CameraError;
    fn from_str(s: &str) -> Result<Self, CameraError> {
        match s {
            "smaller" => Ok(FovAxis::Smaller),
            "larger" => Ok(FovAxis::Larger),
            "x" => Ok(FovAxis::X),
            "y" => Ok(FovAxis::Y),
            "diagonal" => Ok(FovAxis::Diagonal),
            other => Err(CameraError::UnknownFovAxis(other.to_owned())),
        }
    }
}

/// What the camera needs to know of the film: its resolution, the screen window that the
/// image spans and the pixels to render (the crop window). It holds no pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmGeometry {
    resolution: [u32; 2],
    screen_window: ScreenWindow,
    crop_window: [f32; 4],
    pixel_bounds: [u32; 4],
}

impl FilmGeometry {
    /// Film geometry for `resolution` (width, height), with the screen window given or
    /// [`ScreenWindow::default_for`] the resolution, and an optional crop window in NDC
    /// (`[x0, x1, y0, y1]`, y down) restricting the pixels to render.
    ///
    /// Errors: a zero or too large width or height, a degenerate screen window, a crop window
    /// outside `[0, 1]^2`, empty, or covering no pixel.
    pub fn new(
        resolution: [u32; 2],
        screen_window: Option<ScreenWindow>,
        crop_window: Option<[f32; 4]>,
    ) -> Result<FilmGeometry, CameraError> {
        if resolution[0] == 0 || resolution[1] == 0 {
            return Err(CameraError::Resolution { got: resolution });
        }
        if resolution[0] > MAX_RESOLUTION || resolution[1] > MAX_RESOLUTION {
            return Err(CameraError::ResolutionTooLarge { got: resolution });
        }
        let screen_window = screen_window.unwrap_or_else(|| ScreenWindow::default_for(resolution));
        screen_window.validate()?;
        let crop_window = crop_window.unwrap_or([0.0, 1.0, 0.0, 1.0]);
        let [x0, x1, y0, y1] = crop_window;
        let in_unit =
            |a: f32, b: f32| a.is_finite() && b.is_finite() && 0.0 <= a && a < b && b <= 1.0;
        if !(in_unit(x0, x1) && in_unit(y0, y1)) {
            return Err(CameraError::CropWindow { got: crop_window });
        }
        // pbrt's rule: pixel i is rendered when its index lies in [ceil(res * c0), ceil(res * c1)),
        // the product taken in f32 as pbrt's Float (in f64, 0.1f32 * 60 is 6.00000009, whose
        // ceiling is 7; the f32 product rounds to 6).
        let edge = |res: u32, c: f32| ((res as f32 * c).ceil() as u32).min(res);
        let pixel_bounds = [
            edge(resolution[0], x0),
            edge(resolution[0], x1),
            edge(resolution[1], y0),
            edge(resolution[1], y1),
        ];
        if pixel_bounds[0] >= pixel_bounds[1] || pixel_bounds[2] >= pixel_bounds[3] {
            return Err(CameraError::CropWindow { got: crop_window });
        }
        Ok(FilmGeometry {
            resolution,
            screen_window,
            crop_window,
            pixel_bounds,
        })
    }

    /// Width and height in pixels.
    #[inline]
    pub fn resolution(&self) -> [u32; 2] {
        self.resolution
    }

    /// The screen window the full image spans (the crop window does not change it).
    #[inline]
    pub fn screen_window(&self) -> ScreenWindow {
        self.screen_window
    }

    /// The crop window in NDC, `[x0, x1, y0, y1]` (`[0, 1, 0, 1]` when none was given).
    #[inline]
    pub fn crop_window(&self) -> [f32; 4] {
        self.crop_window
    }

    /// The pixels to render, `[x0, x1) x [y0, y1)` as `[x0, x1, y0, y1]`: from the crop window
    /// as pbrt does, `ceil(resolution * crop)`. Never empty.
    #[inline]
    pub fn pixel_bounds(&self) -> [u32; 4] {
        self.pixel_bounds
    }
}

/// Checks the clip range shared by all cameras: finite, `0 <= near < far` (`0 < near` when
/// `positive`).
/// Checks a clip range: finite, `near >= 0` (`> 0` when `positive`, as a perspective camera
/// needs), `near < far`. What the camera constructors check; public so that a scene layer can
/// check its keys before building a camera.
pub fn validate_clip(near: f32, far: f32, positive: bool) -> Result<(), CameraError> {
    finite("near", near)?;
    finite("far", far)?;
    if near < 0.0 || (positive && near == 0.0) {
        return Err(CameraError::Near {
            got: near,
            positive,
        });
    }
    if near >= far {
        return Err(CameraError::NearFar { near, far });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_window_follows_the_aspect_ratio() {
        // 640 x 480: a = 4/3 >= 1, so [-4/3, 4/3] x [-1, 1].
        let w = ScreenWindow::default_for([640, 480]);
        assert_eq!(w.to_array(), [-4.0 / 3.0, 4.0 / 3.0, -1.0, 1.0]);
        // 100 x 200: a = 1/2 < 1, so [-1, 1] x [-2, 2].
        let w = ScreenWindow::default_for([100, 200]);
        assert_eq!(w.to_array(), [-1.0, 1.0, -2.0, 2.0]);
    }

    #[test]
    fn pixel_bounds_round_up_like_pbrt() {
        // 10 x 4 with crop [0.25, 0.75] x [0.1, 0.6]: x ceil(2.5) = 3 .. ceil(7.5) = 8,
        // y ceil(0.4) = 1 .. ceil(2.4) = 3.
        let film = FilmGeometry::new([10, 4], None, Some([0.25, 0.75, 0.1, 0.6])).unwrap();
        assert_eq!(film.pixel_bounds(), [3, 8, 1, 3]);
        let full = FilmGeometry::new([10, 4], None, None).unwrap();
        assert_eq!(full.pixel_bounds(), [0, 10, 0, 4]);
        // pbrt multiplies in f32: 60 * 0.1f32 = 6.0000000894 rounds to 6.0 (f32 steps are
        // 4.8e-7 there), ceil 6; 80 * 0.1f32 rounds to 8.0, ceil 8. In f64 both would round up
        // one more row or column.
        let tenth = FilmGeometry::new([80, 60], None, Some([0.1, 0.9, 0.1, 0.9])).unwrap();
        assert_eq!(tenth.pixel_bounds(), [8, 72, 6, 54]);
    }

    #[test]
    fn bad_film_is_an_error() {
        assert!(matches!(
            FilmGeometry::new([0, 4], None, None),
            Err(CameraError::Resolution { .. })
        ));
        assert!(matches!(
            FilmGeometry::new([MAX_RESOLUTION + 1, 4], None, None),
            Err(CameraError::ResolutionTooLarge { .. })
        ));
        // A crop window inside one pixel's interior covers no pixel centre range.
        assert!(FilmGeometry::new([10, 10], None, Some([0.51, 0.55, 0.0, 1.0])).is_err());
        assert!(FilmGeometry::new([10, 10], None, Some([0.5, 0.4, 0.0, 1.0])).is_err());
        assert!(FilmGeometry::new([10, 10], None, Some([0.0, 1.5, 0.0, 1.0])).is_err());
        assert!(ScreenWindow::new(1.0, 1.0, 0.0, 1.0).is_err());
        assert!(ScreenWindow::new(0.0, f32::NAN, 0.0, 1.0).is_err());
    }

    #[test]
    fn shutter_maps_u_linearly_and_validates() {
        let s = Shutter::new(2.0, 6.0).unwrap();
        assert_eq!(s.time_at(0.0), 2.0);
        assert_eq!(s.time_at(0.25), 3.0);
        assert!(Shutter::new(1.0, 0.0).is_err());
        assert!(Shutter::new(0.0, f32::INFINITY).is_err());
        assert!(Shutter::new(1.0, 1.0).is_ok());
    }

    #[test]
    fn fov_axis_parses_scene_names_and_picks_extents() {
        let w = ScreenWindow::new(-2.0, 2.0, -1.0, 1.0).unwrap();
        for (name, half) in [
            ("smaller", 1.0),
            ("larger", 2.0),
            ("x", 2.0),
            ("y", 1.0),
            ("diagonal", 5f32.sqrt()),
        ] {
            let axis: FovAxis = name.parse().unwrap();
            assert_eq!(axis.name(), name);
            assert_eq!(axis.half_extent(w), half);
        }
        assert!("Diagonal".parse::<FovAxis>().is_err());
    }

    #[test]
    fn near_far_rules() {
        assert!(validate_clip(0.0, 1.0, false).is_ok());
        assert!(validate_clip(0.0, 1.0, true).is_err());
        assert!(validate_clip(1.0, 1.0, false).is_err());
        assert!(validate_clip(-1.0, 1.0, false).is_err());
        assert!(validate_clip(0.1, f32::INFINITY, false).is_err());
    }
}
