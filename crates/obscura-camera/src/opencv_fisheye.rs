//! The OpenCV fisheye camera (Kannala-Brandt, `cv::fisheye::projectPoints`).

use crate::camera::{Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample};
use crate::chain::{self, CameraRayParts, PoseCache};
use crate::error::CameraError;
use crate::opencv::{OpenCvIntrinsics, check_distortion, flip_y};
use core::f64::consts::PI;
use glam::{DVec2, DVec3};
use obscura_space::{Point2, Point3, Raster, World};

/// The inverse accepts an angle whose re-projection is within this many pixels (in f64); the
/// stated tolerance is 1e-4 px, this is the margin the solver actually keeps.
pub const FISHEYE_INVERSE_TOLERANCE_PX: f64 = 1e-6;

/// The OpenCV fisheye camera: Kannala and Brandt's polynomial in the angle from the optical
/// axis, as `cv::fisheye::projectPoints` (OpenCV's documentation of the fisheye namespace,
/// with skew `alpha = 0`). A point of OpenCV's camera frame `(X, Y, Z)` (x right, y down, z
/// forward) maps to
///
/// ```text
/// r = sqrt(X^2 + Y^2),  theta = atan2(r, Z)
/// theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)
/// x' = (theta_d / r) X,  y' = (theta_d / r) Y      (x' = y' = 0 on the axis)
/// u = fx x' + cx,  v = fy y' + cy
/// ```
///
/// For `Z > 0` this is OpenCV's `theta = atan(|(X/Z, Y/Z)|)`; `atan2` carries it past 90
/// degrees, so fields of view beyond 180 degrees work (OpenCV itself folds points behind the
/// camera onto the front).
///
/// Conventions: as [`OpenCvCamera`](crate::OpenCvCamera): Obscura's camera frame is OpenCV's
/// with y flipped (+y up); OpenCV pixel `(u, v)` is Obscura raster `(u + 0.5, v + 0.5)`; the
/// screen window is unused.
///
/// Valid region: `theta < theta_max`, where `theta_max` is the first angle in `(0, pi]` at which
/// `d theta_d / d theta = 1 + 3 k1 theta^2 + 5 k2 theta^4 + 7 k3 theta^6 + 9 k4 theta^8` stops
/// being positive (found once at construction by a scan and bisection), or `pi` (straight
/// back) when it never does. Points at or past it are not projected; raster points whose
/// `|(x', y')|` reaches `theta_d(theta_max)` give no ray.
///
/// Inverse: `theta_d = |(x', y')|` is monotone in `theta` on `[0, theta_max)`, so Newton's
/// method on `theta` inside that bracket (falling back to bisection when a step leaves it)
/// finds the angle; the direction is `(sin theta x' / theta_d, sin theta y' / theta_d, cos
/// theta)` in OpenCV's frame, y flipped for Obscura's. Rays run from the eye, clipped to
/// distance in `[near, far]` along the unit direction (as the environment camera: a fisheye
/// sees behind its image plane).
#[derive(Debug, Clone)]
pub struct OpenCvFisheyeCamera {
    base: CameraBase,
    intrinsics: OpenCvIntrinsics,
    k: [f64; 4],
    theta_max: f64,
    /// `theta_d(theta_max)`: the largest distorted radius with a ray.
    theta_d_max: f64,
    pose: PoseCache,
}

impl OpenCvFisheyeCamera {
    /// An OpenCV fisheye camera; `distortion = [k1, k2, k3, k4]`.
    ///
    /// Errors: [`CameraError::NonFinite`] (an intrinsic or distortion entry),
    /// [`CameraError::FocalLength`] (`fx` or `fy` not > 0), [`CameraError::DistortionLength`]
    /// (not 4 entries), and the base's: a bad shutter, `near < 0`, `near >= far`.
    pub fn new(
        base: CameraBase,
        intrinsics: OpenCvIntrinsics,
        distortion: &[f64],
    ) -> Result<OpenCvFisheyeCamera, CameraError> {
        base.validate(false)?;
        intrinsics.validate()?;
        check_distortion("opencv_fisheye", distortion, &[4])?;
        let k = [distortion[0], distortion[1], distortion[2], distortion[3]];
        let theta_max = fold_angle(&k);
        Ok(OpenCvFisheyeCamera {
            pose: PoseCache::new(&base),
            base,
            intrinsics,
            k,
            theta_max,
            theta_d_max: theta_d(&k, theta_max).0,
        })
    }

    /// The pose, shutter, film and clip range.
    #[inline]
    pub fn base(&self) -> &CameraBase {
        &self.base
    }

    /// The intrinsics.
    #[inline]
    pub fn intrinsics(&self) -> OpenCvIntrinsics {
        self.intrinsics
    }

    /// The distortion coefficients `[k1, k2, k3, k4]`.
    #[inline]
    pub fn distortion(&self) -> [f64; 4] {
        self.k
    }

    /// The largest angle from the optical axis (radians) that is seen: the fold, or pi.
    #[inline]
    pub fn max_angle(&self) -> f64 {
        self.theta_max
    }

    /// The angle from the optical axis of a distorted radius `theta_d`, by safeguarded Newton;
    /// None at or past `theta_d(theta_max)`.
    pub fn angle_of(&self, rho: f64) -> Option<f64> {
        if !(rho >= 0.0 && rho < self.theta_d_max) {
            return None;
        }
        let (mut lo, mut hi) = (0.0, self.theta_max);
        let mut theta = rho.min(0.5 * (lo + hi));
        for _ in 0..100 {
            let (f, df) = theta_d(&self.k, theta);
            let residual = f - rho;
            if residual == 0.0 {
                break;
            }
            // theta_d increases on the bracket: keep the root between lo and hi.
            if residual > 0.0 {
                hi = theta;
            } else {
                lo = theta;
            }
            let mut next = theta - residual / df;
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            if next == theta {
                break;
            }
            theta = next;
        }
        let scale = self.intrinsics.fx.max(self.intrinsics.fy);
        ((theta_d(&self.k, theta).0 - rho).abs() * scale <= FISHEYE_INVERSE_TOLERANCE_PX
            && theta < self.theta_max)
            .then_some(theta)
    }

    /// The camera-space unit direction (Obscura frame, +y up) of a raster position, or None
    /// where no ray leaves (past the fold).
    pub fn direction(&self, p_film: Point2<Raster>) -> Option<DVec3> {
        let q = self.intrinsics.normalised(p_film);
        let rho = q.length();
        let theta = self.angle_of(rho)?;
        if rho == 0.0 {
            return Some(DVec3::Z);
        }
        let (sin, cos) = theta.sin_cos();
        let d_cv = DVec3::new(sin * q.x / rho, sin * q.y / rho, cos);
        Some(flip_y(d_cv).normalize())
    }

    /// The raster position (f64) of a camera-space point (Obscura frame), or None at the eye,
    /// outside `[near, far]` in distance, or at or past the fold angle.
    pub fn project_camera(&self, p: DVec3) -> Option<DVec2> {
        // A unit direction within the clip range (the angles do not depend on the length).
        let p_cv = flip_y(chain::direction_within_clip(&self.base, p)?);
        let r = p_cv.x.hypot(p_cv.y);
        let theta = r.atan2(p_cv.z);
        if theta.is_nan() || theta >= self.theta_max {
            return None;
        }
        let q = if r > 0.0 {
            let scale = theta_d(&self.k, theta).0 / r;
            DVec2::new(p_cv.x * scale, p_cv.y * scale)
        } else {
            DVec2::ZERO
        };
        Some(self.intrinsics.raster(q))
    }

    /// The camera-space ray of a raster position: from the eye along the unit direction,
    /// clipped by distance; None past the fold.
    #[inline]
    fn ray_at(&self, p_film: Point2<Raster>) -> Option<CameraRayParts> {
        let direction = self.direction(p_film)?;
        Some(CameraRayParts::by_distance(
            DVec3::ZERO,
            direction,
            &self.base,
        ))
    }
}

/// `theta_d(theta) = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)` and its
/// derivative `1 + 3 k1 theta^2 + 5 k2 theta^4 + 7 k3 theta^6 + 9 k4 theta^8`.
#[inline]
fn theta_d(k: &[f64; 4], theta: f64) -> (f64, f64) {
    let t2 = theta * theta;
    let [k1, k2, k3, k4] = *k;
    let poly = 1.0 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4)));
    let derivative = 1.0 + t2 * (3.0 * k1 + t2 * (5.0 * k2 + t2 * (7.0 * k3 + t2 * 9.0 * k4)));
    (theta * poly, derivative)
}

/// The first angle in `(0, pi]` where `d theta_d / d theta` stops being positive (a scan of
/// 4096 steps, then bisection), or pi.
fn fold_angle(k: &[f64; 4]) -> f64 {
    const STEPS: usize = 4096;
    let ok = |theta: f64| theta_d(k, theta).1 > 0.0;
    let mut lo = 0.0;
    for i in 1..=STEPS {
        let theta = PI * i as f64 / STEPS as f64;
        if !ok(theta) {
            let mut hi = theta;
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if ok(mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return lo;
        }
        lo = theta;
    }
    PI
}

impl Camera for OpenCvFisheyeCamera {
    #[inline]
    fn base(&self) -> &CameraBase {
        &self.base
    }

    fn generate_ray(&self, sample: &CameraSample) -> Option<CameraRay> {
        chain::generate(&self.base, &self.pose, sample, |p| self.ray_at(p))
    }

    fn generate_ray_differential(&self, sample: &CameraSample) -> Option<CameraRayDifferential> {
        chain::generate_differential(&self.base, &self.pose, sample, |p| self.ray_at(p))
    }

    fn project(&self, p: Point3<World>, time: f32) -> Option<Point2<Raster>> {
        if !time.is_finite() {
            return None;
        }
        let v = chain::camera_point(&self.base, &self.pose, p, time);
        chain::raster_f32(self.project_camera(v)?)
    }

    fn uses_lens_sample(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fold_angle_of_a_negative_k1() {
        // theta_d' = 1 + 3 k1 theta^2 = 0 at theta = 1 / sqrt(-3 k1); k1 = -1/3 gives 1 rad.
        assert!((fold_angle(&[-1.0 / 3.0, 0.0, 0.0, 0.0]) - 1.0).abs() < 1e-12);
        // The equidistant fisheye (all zero) never folds: the whole sphere up to pi.
        assert_eq!(fold_angle(&[0.0; 4]), PI);
    }

    #[test]
    fn derivative_matches_finite_differences() {
        let k = [0.1, -0.05, 0.01, -0.002];
        for theta in [0.1, 0.7, 1.5, 2.5] {
            let h = 1e-6;
            let fd = (theta_d(&k, theta + h).0 - theta_d(&k, theta - h).0) / (2.0 * h);
            assert!((theta_d(&k, theta).1 - fd).abs() < 1e-8);
        }
    }
}
