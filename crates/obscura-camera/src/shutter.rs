//! When within the shutter interval a ray is taken: the shutter curve (how open the shutter is
//! over the interval) and the rolling shutter (which rows are exposed when). Every camera
//! model reads its ray times through here (`CameraBase::ray_time`).

use crate::error::CameraError;
use crate::film::{FilmGeometry, Shutter};
use obscura_sample::PiecewiseShutterCurve;
use obscura_space::{Point2, Raster};
use std::str::FromStr;
use std::sync::Arc;

/// The order in which a rolling shutter reads the sensor out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RollingDirection {
    /// Row 0 (the image's top) first.
    TopToBottom,
    /// The bottom row first.
    BottomToTop,
    /// Column 0 (the image's left) first.
    LeftToRight,
    /// The rightmost column first.
    RightToLeft,
}

impl FromStr for RollingDirection {
    type Err = CameraError;
    fn from_str(s: &str) -> Result<Self, CameraError> {
        Ok(match s {
            "top_to_bottom" => RollingDirection::TopToBottom,
            "bottom_to_top" => RollingDirection::BottomToTop,
            "left_to_right" => RollingDirection::LeftToRight,
            "right_to_left" => RollingDirection::RightToLeft,
            other => return Err(CameraError::UnknownRollingDirection(other.to_string())),
        })
    }
}

/// A rolling shutter: the sensor's rows (or columns) are exposed one after another, each for
/// the same time, the last starting `readout` (less one row's share) after the first.
///
/// With the shutter `[open, close]`, `T = close - open`, `n` rows (columns) and `k` the
/// index of a row in readout order (0 for the row read first), row `k` is exposed over
///
/// ```text
/// [open + readout * k / n,  open + readout * k / n + (T - readout)]
/// ```
///
/// So the first row opens at `open`, every window lasts `T - readout`, and every window lies
/// inside `[open, close]` (the last ends at `close - readout / n`): the scene's motion, given
/// at shutter open and close, needs no extrapolation. `readout = T` gives each row an
/// instant; `readout = 0` is the global shutter. A film point's row is the pixel row
/// `floor(y)` (its column `floor(x)` for the horizontal directions) of the full image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RollingShutter {
    /// Time from the first row's opening to the last row's, plus one row's share: seconds
    /// (the shutter interval's unit).
    pub readout: f32,
    /// Readout order.
    pub direction: RollingDirection,
}

/// How the times of a camera's rays are spread over its shutter interval, beyond the uniform
/// default: a [`PiecewiseShutterCurve`] (times drawn by inverting its integral, so equal-weight
/// time strata stay equal-weight) applied within each row's window, and a [`RollingShutter`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ShutterTiming {
    /// The shutter's openness over the (row's) interval; None: open all at once.
    pub curve: Option<Arc<PiecewiseShutterCurve>>,
    /// The rolling shutter; None: every row exposed over the whole interval.
    pub rolling: Option<RollingShutter>,
}

impl ShutterTiming {
    /// Checks the timing against the shutter: a finite readout in `[0, close - open]`.
    pub fn validate(&self, shutter: Shutter) -> Result<(), CameraError> {
        if let Some(rolling) = self.rolling {
            let interval = shutter.close - shutter.open;
            if !(rolling.readout.is_finite()
                && rolling.readout >= 0.0
                && rolling.readout <= interval)
            {
                return Err(CameraError::RollingReadout {
                    readout: rolling.readout,
                    interval,
                });
            }
        }
        Ok(())
    }

    /// True when the timing is the default (uniform over the interval, global shutter).
    pub fn is_uniform(&self) -> bool {
        self.curve.is_none() && self.rolling.is_none()
    }

    /// The exposure window `[start, end]` of the row (column) of film point `p_film`.
    pub fn window(
        &self,
        shutter: Shutter,
        film: &FilmGeometry,
        p_film: Point2<Raster>,
    ) -> [f32; 2] {
        let Some(rolling) = self.rolling else {
            return [shutter.open, shutter.close];
        };
        let [width, height] = film.resolution();
        let (n, position) = match rolling.direction {
            RollingDirection::TopToBottom | RollingDirection::BottomToTop => (height, p_film.y),
            RollingDirection::LeftToRight | RollingDirection::RightToLeft => (width, p_film.x),
        };
        // floor, clamped into the image (film points on its far edge belong to the last row).
        let index = (position.floor().max(0.0) as u32).min(n - 1);
        let k = match rolling.direction {
            RollingDirection::TopToBottom | RollingDirection::LeftToRight => index,
            RollingDirection::BottomToTop | RollingDirection::RightToLeft => n - 1 - index,
        };
        let exposure = (shutter.close - shutter.open) - rolling.readout;
        let start = shutter.open + rolling.readout * (k as f32 / n as f32);
        [start, start + exposure]
    }

    /// The time of canonical `u` in `[0, 1)` for film point `p_film`: within its row's window,
    /// through the curve.
    #[inline]
    pub fn time(
        &self,
        shutter: Shutter,
        film: &FilmGeometry,
        p_film: Point2<Raster>,
        u: f32,
    ) -> f32 {
        let [start, end] = self.window(shutter, film, p_film);
        let t = match &self.curve {
            Some(curve) => curve.sample(u),
            None => u,
        };
        start + t * (end - start)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(resolution: [u32; 2]) -> FilmGeometry {
        FilmGeometry::new(resolution, None, None).unwrap()
    }

    #[test]
    fn rolling_windows_hand_cases() {
        // 4 rows, shutter [0, 1], readout 0.5: windows of length 0.5 starting at 0, 1/8, 2/8, 3/8.
        let timing = ShutterTiming {
            curve: None,
            rolling: Some(RollingShutter {
                readout: 0.5,
                direction: RollingDirection::TopToBottom,
            }),
        };
        let shutter = Shutter::new(0.0, 1.0).unwrap();
        let f = film([2, 4]);
        assert_eq!(
            timing.window(shutter, &f, Point2::new(0.5, 0.5)),
            [0.0, 0.5]
        );
        assert_eq!(
            timing.window(shutter, &f, Point2::new(1.5, 2.5)),
            [0.25, 0.75]
        );
        assert_eq!(
            timing.window(shutter, &f, Point2::new(1.5, 4.0)),
            [0.375, 0.875]
        );
        let up = ShutterTiming {
            rolling: Some(RollingShutter {
                readout: 0.5,
                direction: RollingDirection::BottomToTop,
            }),
            ..timing.clone()
        };
        assert_eq!(
            up.window(shutter, &f, Point2::new(0.5, 0.5)),
            [0.375, 0.875]
        );
        // Columns: 2 columns, right to left: column 1 first.
        let left = ShutterTiming {
            rolling: Some(RollingShutter {
                readout: 0.5,
                direction: RollingDirection::RightToLeft,
            }),
            ..timing.clone()
        };
        assert_eq!(left.window(shutter, &f, Point2::new(1.5, 0.5)), [0.0, 0.5]);
        assert_eq!(
            left.window(shutter, &f, Point2::new(0.5, 0.5)),
            [0.25, 0.75]
        );
        // u = 0.5 lies in the middle of its window.
        assert_eq!(timing.time(shutter, &f, Point2::new(0.5, 2.5), 0.5), 0.5);
    }

    #[test]
    fn readout_validation() {
        let shutter = Shutter::new(0.0, 0.5).unwrap();
        for readout in [-0.1, 0.6, f32::NAN] {
            let timing = ShutterTiming {
                curve: None,
                rolling: Some(RollingShutter {
                    readout,
                    direction: RollingDirection::TopToBottom,
                }),
            };
            assert!(timing.validate(shutter).is_err(), "{readout}");
        }
        assert!("sideways".parse::<RollingDirection>().is_err());
        assert_eq!(
            "left_to_right".parse::<RollingDirection>(),
            Ok(RollingDirection::LeftToRight)
        );
    }
}
