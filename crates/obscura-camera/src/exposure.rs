//! Exposure as a photographer sets it: f-number, shutter time, ISO and compensation, turned
//! into the one factor a renderer scales its radiance by.

use crate::error::CameraError;

/// The calibration constant of [`Exposure::scale`]: the ISO speed at which one second at f/1
/// passes radiance through unchanged.
///
/// ISO 12232's saturation-based sensitivity is `S = 78 / H_sat` (lux seconds), and a sensor
/// value is proportional to the photographic exposure `H = q L t / N^2`. pbrt-v4's
/// `PixelSensor` (src/pbrt/film.cpp, in its photometric form) writes the resulting imaging
/// ratio as `pi t S K_m / (C N^2)` with the calibration `C = 100 pi` chosen so that `t = 1`,
/// `S = 100`, `N = 1` give a ratio of one (instead of the 312.5 of light meters); in RGB
/// units, `K_m` is 1. That is `t S / (100 N^2)`: this constant is the 100.
pub const ISO_CALIBRATION: f32 = 100.0;

/// The photographic exposure settings (the scene format's `f_number`, `shutter_time`, `iso`
/// and `exposure_compensation`). Radiance is scaled by
///
/// ```text
/// scale = (t / N^2) * (S / 100) * 2^EV
/// ```
///
/// (`t` shutter time in seconds, `N` the f-number, `S` the ISO speed, `EV` the compensation
/// in stops): the photographic exposure `H = L t / N^2` times the sensor's sensitivity, as in
/// pbrt-v4's imaging ratio ([`ISO_CALIBRATION`]). Defaults (1 s, f/1, ISO 100, 0 EV) give 1.
/// The shutter time scales brightness only: motion blur follows the camera's `shutter`
/// interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exposure {
    /// The f-number `N` (focal length over the aperture's diameter), > 0.
    pub f_number: f32,
    /// Exposure time in seconds, > 0.
    pub shutter_time: f32,
    /// ISO speed (saturation-based sensitivity), > 0.
    pub iso: f32,
    /// Exposure compensation in stops (each doubles the brightness).
    pub compensation: f32,
}

impl Exposure {
    /// The settings that scale by 1: f/1, 1 s, ISO 100, no compensation.
    pub const UNIT: Exposure = Exposure {
        f_number: 1.0,
        shutter_time: 1.0,
        iso: 100.0,
        compensation: 0.0,
    };

    /// Checks the settings: finite, and `f_number`, `shutter_time`, `iso` > 0; a scale that
    /// is finite and positive.
    pub fn validate(&self) -> Result<(), CameraError> {
        for (what, got) in [
            ("f_number", self.f_number),
            ("shutter_time", self.shutter_time),
            ("iso", self.iso),
        ] {
            if !(got.is_finite() && got > 0.0) {
                return Err(CameraError::Exposure {
                    what,
                    need: "a finite number > 0",
                    got,
                });
            }
        }
        if !self.compensation.is_finite() {
            return Err(CameraError::Exposure {
                what: "exposure_compensation",
                need: "a finite number of stops",
                got: self.compensation,
            });
        }
        let scale = self.scale();
        if !(scale.is_finite() && scale > 0.0) {
            // Each setting's share of the scale, in stops; the one that pushes furthest the
            // way the scale ran out of range (too large or too small) is named.
            let shares = [
                (
                    "f_number",
                    self.f_number,
                    -2.0 * f64::from(self.f_number).log2(),
                ),
                (
                    "shutter_time",
                    self.shutter_time,
                    f64::from(self.shutter_time).log2(),
                ),
                (
                    "iso",
                    self.iso,
                    (f64::from(self.iso) / f64::from(ISO_CALIBRATION)).log2(),
                ),
                (
                    "exposure_compensation",
                    self.compensation,
                    f64::from(self.compensation),
                ),
            ];
            let sign = if scale > 0.0 { 1.0 } else { -1.0 };
            let (what, got, _) =
                shares.into_iter().fold(
                    shares[0],
                    |a, b| if b.2 * sign > a.2 * sign { b } else { a },
                );
            return Err(CameraError::Exposure {
                what,
                need: "a value that, with the other exposure settings, gives a finite, \
                       non-zero exposure scale t S 2^EV / (100 N^2)",
                got,
            });
        }
        Ok(())
    }

    /// The factor radiance is scaled by: `t S 2^EV / (100 N^2)`.
    pub fn scale(&self) -> f32 {
        let (n, t, s) = (
            f64::from(self.f_number),
            f64::from(self.shutter_time),
            f64::from(self.iso),
        );
        (t / (n * n) * (s / f64::from(ISO_CALIBRATION)) * f64::from(self.compensation).exp2())
            as f32
    }

    /// The thin-lens radius of this f-number for a lens of focal length `focal_length`:
    /// `focal_length / (2 N)` (the f-number is the focal length over the aperture's diameter).
    pub fn lens_radius(&self, focal_length: f32) -> f32 {
        focal_length / (2.0 * self.f_number)
    }
}

impl Default for Exposure {
    fn default() -> Self {
        Exposure::UNIT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_hand_cases() {
        assert_eq!(Exposure::UNIT.scale(), 1.0);
        // 1/100 s at f/2.8, ISO 400, +1 EV: 0.01 / 7.84 * 4 * 2 = 0.0102040...
        let e = Exposure {
            f_number: 2.8,
            shutter_time: 0.01,
            iso: 400.0,
            compensation: 1.0,
        };
        assert!((e.scale() - 0.08 / 7.84).abs() < 1e-7);
        assert_eq!(
            Exposure {
                f_number: 4.0,
                ..Exposure::UNIT
            }
            .lens_radius(0.05),
            0.00625
        );
    }

    #[test]
    fn validation() {
        for bad in [
            Exposure {
                f_number: 0.0,
                ..Exposure::UNIT
            },
            Exposure {
                shutter_time: -1.0,
                ..Exposure::UNIT
            },
            Exposure {
                iso: f32::NAN,
                ..Exposure::UNIT
            },
            Exposure {
                compensation: 1000.0,
                ..Exposure::UNIT
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        assert!(Exposure::UNIT.validate().is_ok());
    }

    #[test]
    fn an_exposure_out_of_range_names_the_setting_that_took_it_there() {
        let named = |e: Exposure| match e.validate() {
            Err(CameraError::Exposure { what, got, .. }) => (what, got),
            other => panic!("{e:?}: {other:?}"),
        };
        // f/1e-30 alone makes 1e60: too large for f32, and f_number pushed it there.
        let tiny_n = Exposure {
            f_number: 1e-30,
            ..Exposure::UNIT
        };
        assert_eq!(named(tiny_n), ("f_number", 1e-30));
        // 1e38 s is 2^126 and ISO 1e38 is 2^120 over ISO 100: the shutter time is named.
        let long = Exposure {
            shutter_time: 1e38,
            iso: 1e38,
            ..Exposure::UNIT
        };
        assert_eq!(named(long), ("shutter_time", 1e38));
        // Too small: 1e-30 s (2^-100) at f/1e10 (2^-66) is 1e-50.
        let dark = Exposure {
            f_number: 1e10,
            shutter_time: 1e-30,
            ..Exposure::UNIT
        };
        assert_eq!(named(dark), ("shutter_time", 1e-30));
        let minus = Exposure {
            compensation: -1000.0,
            ..Exposure::UNIT
        };
        assert_eq!(named(minus), ("exposure_compensation", -1000.0));
    }
}
