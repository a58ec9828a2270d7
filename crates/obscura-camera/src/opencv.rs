//! The OpenCV pinhole camera with lens distortion (`cv::projectPoints`), and the OpenCV
//! extrinsics (`rvec`, `tvec`) as a camera pose. The pieces shared with
//! [`OpenCvFisheyeCamera`](crate::OpenCvFisheyeCamera) (intrinsics, frames,
//! distortion checks) live here too; the per-ray chain is [`crate::chain`]'s.

use crate::camera::{Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample};
use crate::chain::{self, CameraRayParts, PoseCache};
use crate::error::CameraError;
use glam::{DMat2, DMat3, DVec2, DVec3};
use obscura_space::{
    AnimatedTransform, Camera as CameraSpace, Point2, Point3, Raster, Transform, World,
};

/// The pixel intrinsics of an OpenCV camera matrix `K = [fx 0 cx; 0 fy cy; 0 0 1]`, in OpenCV's
/// pixel units (pixel centres at integers).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OpenCvIntrinsics {
    /// Focal length along image x, in pixels (> 0).
    pub fx: f64,
    /// Focal length along image y (down), in pixels (> 0).
    pub fy: f64,
    /// Principal point x, in OpenCV pixels (pixel centres at integers).
    pub cx: f64,
    /// Principal point y, in OpenCV pixels (pixel centres at integers).
    pub cy: f64,
}

impl OpenCvIntrinsics {
    /// Checks the numbers: all finite (else [`CameraError::NonFinite`]), `fx > 0` and `fy > 0`
    /// (else [`CameraError::FocalLength`]).
    pub fn validate(&self) -> Result<(), CameraError> {
        for (what, v) in [
            ("fx", self.fx),
            ("fy", self.fy),
            ("cx", self.cx),
            ("cy", self.cy),
        ] {
            if !v.is_finite() {
                return Err(CameraError::NonFinite {
                    what,
                    got: v as f32,
                });
            }
        }
        for (what, v) in [("fx", self.fx), ("fy", self.fy)] {
            if v <= 0.0 {
                return Err(CameraError::FocalLength { what, got: v });
            }
        }
        Ok(())
    }

    /// The normalised image point (OpenCV frame, y down) of an Obscura raster position:
    /// OpenCV pixel `(u, v) = (x - 0.5, y - 0.5)`, then `((u - cx) / fx, (v - cy) / fy)`.
    #[inline]
    pub fn normalised(&self, p_film: Point2<Raster>) -> DVec2 {
        DVec2::new(
            (f64::from(p_film.x) - 0.5 - self.cx) / self.fx,
            (f64::from(p_film.y) - 0.5 - self.cy) / self.fy,
        )
    }

    /// The Obscura raster position (f64) of a normalised image point: `u = fx x + cx`, `v = fy
    /// y + cy`, plus 0.5 for Obscura's pixel centres.
    #[inline]
    pub fn raster(&self, q: DVec2) -> DVec2 {
        DVec2::new(self.fx * q.x + self.cx + 0.5, self.fy * q.y + self.cy + 0.5)
    }
}

/// Checks distortion coefficients: the length is one of `lengths` (else
/// [`CameraError::DistortionLength`]), every entry finite (else [`CameraError::NonFinite`]).
pub(crate) fn check_distortion(
    model: &'static str,
    distortion: &[f64],
    lengths: &[usize],
) -> Result<(), CameraError> {
    if !lengths.contains(&distortion.len()) {
        return Err(CameraError::DistortionLength {
            model,
            got: distortion.len(),
        });
    }
    if let Some(&bad) = distortion.iter().find(|v| !v.is_finite()) {
        return Err(CameraError::NonFinite {
            what: "distortion",
            got: bad as f32,
        });
    }
    Ok(())
}

/// The rotation matrix of a Rodrigues vector (as `cv::Rodrigues`): angle `|r|` about `r / |r|`,
/// `R = cos t I + (1 - cos t) k k^T + sin t [k]x`.
pub(crate) fn rodrigues(rvec: DVec3) -> DMat3 {
    let theta = rvec.length();
    if theta < 1e-12 {
        // First order: I + [r]x (exact to rounding at this size).
        return DMat3::from_cols(
            DVec3::new(1.0, rvec.z, -rvec.y),
            DVec3::new(-rvec.z, 1.0, rvec.x),
            DVec3::new(rvec.y, -rvec.x, 1.0),
        );
    }
    let k = rvec / theta;
    let (s, c) = theta.sin_cos();
    let cross = DMat3::from_cols(
        DVec3::new(0.0, k.z, -k.y),
        DVec3::new(-k.z, 0.0, k.x),
        DVec3::new(k.y, -k.x, 0.0),
    );
    let outer = DMat3::from_cols(k * k.x, k * k.y, k * k.z);
    DMat3::IDENTITY * c + outer * (1.0 - c) + cross * s
}

/// The camera pose of OpenCV extrinsics, exactly as `cv::projectPoints` takes them: a point
/// `X` of the world is at `X_cv = R X + t` in OpenCV's camera frame (x right, y down, z
/// forward), with `R` the rotation of the Rodrigues vector `rvec`. Obscura's camera frame is
/// OpenCV's with y flipped (`F = diag(1, -1, 1)`, +y up), so
/// `world_from_camera = [R^T F | -R^T t]` and its inverse `[F R | F t]`, both written in
/// closed form. Like a look-at pose it has determinant -1. The result is fixed (no motion).
///
/// Errors: [`CameraError::NonFinite`] for a non-finite entry (named `rvec` or `tvec`).
pub fn opencv_pose(
    rvec: [f64; 3],
    tvec: [f64; 3],
) -> Result<AnimatedTransform<World, CameraSpace>, CameraError> {
    for (what, v) in [("rvec", rvec), ("tvec", tvec)] {
        if let Some(&bad) = v.iter().find(|x| !x.is_finite()) {
            return Err(CameraError::NonFinite {
                what,
                got: bad as f32,
            });
        }
    }
    let r = rodrigues(DVec3::from(rvec));
    let t = DVec3::from(tvec);
    let flip = DMat3::from_diagonal(DVec3::new(1.0, -1.0, 1.0));
    let world_from_camera = r.transpose() * flip;
    let eye = -(r.transpose() * t);
    let camera_from_world = flip * r;
    let m = glam::DMat4::from_cols(
        world_from_camera.x_axis.extend(0.0),
        world_from_camera.y_axis.extend(0.0),
        world_from_camera.z_axis.extend(0.0),
        eye.extend(1.0),
    );
    let m_inv = glam::DMat4::from_cols(
        camera_from_world.x_axis.extend(0.0),
        camera_from_world.y_axis.extend(0.0),
        camera_from_world.z_axis.extend(0.0),
        (flip * t).extend(1.0),
    );
    // Finite inputs give finite f64 matrices; a huge tvec can still overflow f32.
    if !(m.as_mat4().is_finite() && m_inv.as_mat4().is_finite()) {
        return Err(CameraError::NonFinite {
            what: "tvec",
            got: f32::INFINITY,
        });
    }
    Ok(AnimatedTransform::fixed(
        Transform::from_matrix_and_inverse(m.as_mat4(), m_inv.as_mat4()),
    ))
}

/// Converts between Obscura's camera frame (+y up) and OpenCV's (+y down): flips y.
#[inline]
pub(crate) fn flip_y(v: DVec3) -> DVec3 {
    DVec3::new(v.x, -v.y, v.z)
}

/// How far out the fold search of [`OpenCvCamera`] looks, in normalised radius (`tan` of the
/// angle from the axis: 1000 is 89.94 degrees). Past it no ray is given even without a fold.
pub const OPENCV_MAX_RADIUS: f64 = 1000.0;

/// Newton's inverse accepts a solution whose re-projection is within this many pixels (in
/// f64); the stated tolerance is 1e-4 px, this is the margin the solver actually keeps.
pub const OPENCV_INVERSE_TOLERANCE_PX: f64 = 1e-6;

/// OpenCV's distortion coefficients, zero-padded to the 12-entry form
/// `k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4` (zeros make the missing terms vanish: a zero `k4..k6`
/// is a denominator of 1).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Distortion {
    k: [f64; 6],
    p: [f64; 2],
    s: [f64; 4],
}

impl Distortion {
    fn from_slice(c: &[f64]) -> Distortion {
        let mut all = [0.0; 12];
        all[..c.len()].copy_from_slice(c);
        Distortion {
            k: [all[0], all[1], all[4], all[5], all[6], all[7]],
            p: [all[2], all[3]],
            s: [all[8], all[9], all[10], all[11]],
        }
    }

    /// The radial factor `c(r^2) = N / D` with `N = 1 + k1 r^2 + k2 r^4 + k3 r^6`,
    /// `D = 1 + k4 r^2 + k5 r^4 + k6 r^6`, and `dc / d(r^2)`; also `D` itself.
    #[inline]
    fn radial(&self, r2: f64) -> (f64, f64, f64) {
        let [k1, k2, k3, k4, k5, k6] = self.k;
        let n = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        let d = 1.0 + r2 * (k4 + r2 * (k5 + r2 * k6));
        let dn = k1 + r2 * (2.0 * k2 + r2 * 3.0 * k3);
        let dd = k4 + r2 * (2.0 * k5 + r2 * 3.0 * k6);
        (n / d, (dn * d - n * dd) / (d * d), d)
    }

    /// True where the radial map `g(r) = r c(r^2)` still increases and its denominator is
    /// positive: `g'(r) = c + 2 r^2 c' > 0` and `D > 0`.
    fn radial_ok(&self, r: f64) -> bool {
        let r2 = r * r;
        let (c, dc, d) = self.radial(r2);
        d > 0.0 && c + 2.0 * r2 * dc > 0.0
    }

    /// The valid radius: the first radius where [`Distortion::radial_ok`] fails (the radial
    /// fold), or, when there are tangential or prism terms, the smaller first radius along any
    /// of 360 directions where the Jacobian determinant of the full 2D map stops being
    /// positive; [`OPENCV_MAX_RADIUS`] when nothing folds before it.
    fn fold_radius(&self) -> f64 {
        let radial = first_failure(|r| self.radial_ok(r), OPENCV_MAX_RADIUS, 8192);
        if self.p == [0.0; 2] && self.s == [0.0; 4] {
            // Radial only: det = c g' with c = g / r > 0 inside, so the radial fold is all.
            return radial;
        }
        const ANGLES: usize = 360;
        let mut r_max = radial;
        for i in 0..ANGLES {
            let (sin, cos) = (core::f64::consts::TAU * i as f64 / ANGLES as f64).sin_cos();
            let direction = DVec2::new(cos, sin);
            let ok = |r: f64| self.apply(direction * r).1.determinant() > 0.0;
            r_max = r_max.min(first_failure(ok, r_max, 256));
        }
        r_max
    }

    /// The radius `r` in `[0, r_max)` with `g(r) = r c(r^2) = rho` (`g` increases there), by
    /// Newton's method kept inside a shrinking bracket (bisection when a step leaves it); a
    /// radius just inside `r_max` when `rho` is at or past `g(r_max)`.
    fn radial_inverse(&self, rho: f64, r_max: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, r_max);
        let mut r = rho.min(0.5 * r_max);
        for _ in 0..100 {
            let r2 = r * r;
            let (c, dc, _) = self.radial(r2);
            let residual = r * c - rho;
            if residual == 0.0 {
                return r;
            }
            if residual > 0.0 {
                hi = r;
            } else {
                lo = r;
            }
            let mut next = r - residual / (c + 2.0 * r2 * dc);
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            if next == r {
                break;
            }
            r = next;
        }
        r.min(0.999 * r_max)
    }

    /// The distorted normalised point of an undistorted one, and the Jacobian of the map
    /// (columns: derivatives by x and by y).
    #[inline]
    fn apply(&self, q: DVec2) -> (DVec2, DMat2) {
        let (x, y) = (q.x, q.y);
        let [p1, p2] = self.p;
        let [s1, s2, s3, s4] = self.s;
        let r2 = x * x + y * y;
        let (c, dc, _) = self.radial(r2);
        let xd = x * c + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) + r2 * (s1 + s2 * r2);
        let yd = y * c + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y + r2 * (s3 + s4 * r2);
        // d(r^2)/dx = 2x, d(r^2)/dy = 2y; the prism terms' derivative by r^2 is s1 + 2 s2 r^2.
        let prism_x = s1 + 2.0 * s2 * r2;
        let prism_y = s3 + 2.0 * s4 * r2;
        let dxd_dx = c + 2.0 * x * x * dc + 2.0 * p1 * y + 6.0 * p2 * x + 2.0 * x * prism_x;
        let dxd_dy = 2.0 * x * y * dc + 2.0 * p1 * x + 2.0 * p2 * y + 2.0 * y * prism_x;
        let dyd_dx = 2.0 * x * y * dc + 2.0 * p1 * x + 2.0 * p2 * y + 2.0 * x * prism_y;
        let dyd_dy = c + 2.0 * y * y * dc + 6.0 * p1 * y + 2.0 * p2 * x + 2.0 * y * prism_y;
        (
            DVec2::new(xd, yd),
            DMat2::from_cols(DVec2::new(dxd_dx, dyd_dx), DVec2::new(dxd_dy, dyd_dy)),
        )
    }
}

/// The first `r` in `(0, r_hi]` where `ok` fails, scanned on a geometric grid of `steps`
/// steps from 1e-3 (`ok` holds at 0 for every caller) and refined by bisection to f64
/// precision; `r_hi` when it never fails on the grid.
fn first_failure(ok: impl Fn(f64) -> bool, r_hi: f64, steps: usize) -> f64 {
    const R_MIN: f64 = 1e-3;
    let ratio = (r_hi / R_MIN).max(1.0).powf(1.0 / steps as f64);
    let mut lo = 0.0;
    let mut r = R_MIN.min(r_hi);
    for _ in 0..=steps {
        if !ok(r) {
            let mut hi = r;
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
        lo = r;
        if r >= r_hi {
            break;
        }
        r = (r * ratio).min(r_hi);
    }
    r_hi
}

/// The OpenCV pinhole camera with distortion, exactly as `cv::projectPoints` (OpenCV's
/// documentation of the calib3d module, "Detailed Description"). A point of OpenCV's camera
/// frame `(X, Y, Z)` (x right, y down, z forward; `Z > 0`) maps to
///
/// ```text
/// x' = X / Z,  y' = Y / Z,  r^2 = x'^2 + y'^2
/// c   = (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6)
/// x'' = x' c + 2 p1 x' y' + p2 (r^2 + 2 x'^2) + s1 r^2 + s2 r^4
/// y'' = y' c + p1 (r^2 + 2 y'^2) + 2 p2 x' y' + s3 r^2 + s4 r^4
/// u = fx x'' + cx,  v = fy y'' + cy
/// ```
///
/// with `distortion` in `distCoeffs` order `k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4]]]` (4, 5,
/// 8 or 12 entries; the missing ones are 0). OpenCV's tilted-sensor terms (14 entries) are not
/// supported.
///
/// Conventions: Obscura's camera frame is OpenCV's with y flipped (+y up), so the model reads
/// camera point `(X, -Y, Z)`; OpenCV's pixel centres are integers, so OpenCV pixel `(u, v)` is
/// Obscura raster `(u + 0.5, v + 0.5)`. The screen window is unused. With a look-at pose the
/// image's top is the look-at's up, its right the look-at's right, as for every camera.
///
/// Valid region: the radial map `g(r) = r c(r^2)` folds over where `g'(r) = c + 2 r^2 dc/dr^2`
/// first stops being positive (or the denominator reaches 0). The tangential and thin-prism
/// terms can fold the 2D map `(x', y') -> (x'', y'')` before that, in some directions only: so
/// the valid radius `r_max` is the smaller of the radial fold and the first radius, along any
/// of 360 directions, where the 2D map's Jacobian determinant stops being positive (for a
/// purely radial model the two agree: the determinant is `c g'`). `r_max` is found once at
/// construction (a geometric scan up to [`OPENCV_MAX_RADIUS`], then bisection) and
/// [`OpenCvCamera::valid_radius`] reports it. A point with `r >= r_max`, or where the
/// determinant is not positive (a fold thinner than the angular scan), is not projected, and no
/// ray leaves towards it.
///
/// Inverse: Newton's method in 2D on `(x', y')` with the closed-form Jacobian, started from
/// the radial-only inverse along the direction of `(x'', y'')` (a 1D safeguarded Newton on
/// `g`), each step halved until it stays inside `r_max` with a positive determinant and lowers
/// the residual. A ray is given only when its point re-projects within
/// [`OPENCV_INVERSE_TOLERANCE_PX`] (well inside the stated 1e-4 px) in f64; otherwise (past
/// the fold, where no point maps) there is none. Rays run from the eye along the unit
/// direction `normalize(x', -y', 1)`, clipped to camera z in `[near, far]` as a perspective
/// camera.
#[derive(Debug, Clone)]
pub struct OpenCvCamera {
    base: CameraBase,
    intrinsics: OpenCvIntrinsics,
    distortion: Distortion,
    coefficients: Vec<f64>,
    r_max: f64,
    pose: PoseCache,
}

impl OpenCvCamera {
    /// An OpenCV camera. `distortion` has 4, 5, 8 or 12 entries in `distCoeffs` order.
    ///
    /// Errors: [`CameraError::NonFinite`] (an intrinsic or distortion entry),
    /// [`CameraError::FocalLength`] (`fx` or `fy` not > 0), [`CameraError::DistortionLength`],
    /// and the base's: a bad shutter, `near < 0`, `near >= far`.
    pub fn new(
        base: CameraBase,
        intrinsics: OpenCvIntrinsics,
        distortion: &[f64],
    ) -> Result<OpenCvCamera, CameraError> {
        base.validate(false)?;
        intrinsics.validate()?;
        check_distortion("opencv", distortion, &[4, 5, 8, 12])?;
        let coefficients = distortion.to_vec();
        let distortion = Distortion::from_slice(distortion);
        let r_max = distortion.fold_radius();
        Ok(OpenCvCamera {
            pose: PoseCache::new(&base),
            base,
            intrinsics,
            distortion,
            coefficients,
            r_max,
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

    /// The distortion coefficients as given.
    #[inline]
    pub fn distortion(&self) -> &[f64] {
        &self.coefficients
    }

    /// The fold radius `r_max` in normalised coordinates (`tan` of the angle from the axis).
    #[inline]
    pub fn valid_radius(&self) -> f64 {
        self.r_max
    }

    /// The distorted normalised point `(x'', y'')` of an undistorted `(x', y')` (OpenCV frame),
    /// or None outside the valid region (`r >= r_max`, or where the map folds).
    pub fn distort(&self, q: DVec2) -> Option<DVec2> {
        let r = q.length();
        if r.is_nan() || r >= self.r_max {
            return None;
        }
        let (d, jacobian) = self.distortion.apply(q);
        (jacobian.determinant() > 0.0).then_some(d)
    }

    /// The undistorted normalised point `(x', y')` whose distortion is `target` (OpenCV frame),
    /// by Newton's method; None when none within the valid region re-projects within
    /// [`OPENCV_INVERSE_TOLERANCE_PX`].
    pub fn undistort(&self, target: DVec2) -> Option<DVec2> {
        if !target.is_finite() {
            return None;
        }
        let d = &self.distortion;
        let scale = DVec2::new(self.intrinsics.fx, self.intrinsics.fy);
        // Residual in pixels (the tolerance is stated in pixels); Euclidean for the descent.
        let error = |f: DVec2| ((f - target) * scale).length();
        // Start from the radial-only inverse along the target's direction: the tangential and
        // prism terms are small corrections to it.
        let rho = target.length();
        let mut q = if rho > 0.0 {
            target * (d.radial_inverse(rho, self.r_max) / rho)
        } else {
            target
        };
        let (mut f, mut jacobian) = d.apply(q);
        // Where the tangential and prism terms fold the map inside r_max, pull the start in
        // towards the centre until it is on the unfolded side (det > 0), and keep every step
        // there: the solution is the preimage in the region `distort` accepts.
        for _ in 0..200 {
            if jacobian.determinant() > 0.0 {
                break;
            }
            q *= 0.95;
            (f, jacobian) = d.apply(q);
        }
        let mut err = error(f);
        for _ in 0..100 {
            if err <= 1e-3 * OPENCV_INVERSE_TOLERANCE_PX {
                break;
            }
            let det = jacobian.determinant();
            if !(det.abs() > 0.0 && det.is_finite()) {
                return None;
            }
            let step = jacobian.inverse() * (f - target);
            // Halve the step until it stays inside r_max, on the unfolded side, and lowers the
            // residual.
            let mut lambda = 1.0;
            let mut moved = false;
            while lambda > 1e-12 {
                let next = q - step * lambda;
                if next.length() < self.r_max {
                    let (f_next, j_next) = d.apply(next);
                    let err_next = error(f_next);
                    if err_next < err && j_next.determinant() > 0.0 {
                        (q, f, jacobian, err) = (next, f_next, j_next, err_next);
                        moved = true;
                        break;
                    }
                }
                lambda *= 0.5;
            }
            if !moved {
                break;
            }
        }
        (((f - target) * scale).abs().max_element() <= OPENCV_INVERSE_TOLERANCE_PX
            && q.length() < self.r_max
            && jacobian.determinant() > 0.0)
            .then_some(q)
    }

    /// The camera-space unit direction (Obscura frame, +y up) of a raster position, or None
    /// where no ray leaves (past the fold).
    pub fn direction(&self, p_film: Point2<Raster>) -> Option<DVec3> {
        let q = self.undistort(self.intrinsics.normalised(p_film))?;
        Some(flip_y(q.extend(1.0)).normalize())
    }

    /// The raster position (f64) of a camera-space point (Obscura frame), or None behind the
    /// camera, outside `[near, far]` in z, or outside the valid region.
    pub fn project_camera(&self, p: DVec3) -> Option<DVec2> {
        let near = f64::from(self.base.near);
        let far = f64::from(self.base.far);
        if !(p.z > 0.0 && p.z >= near && p.z <= far) {
            return None;
        }
        let p_cv = flip_y(p);
        let q = DVec2::new(p_cv.x / p_cv.z, p_cv.y / p_cv.z);
        let d = self.distort(q)?;
        Some(self.intrinsics.raster(d))
    }

    /// The camera-space ray of a raster position: from the eye along the unit direction, None
    /// past the fold.
    #[inline]
    fn ray_at(&self, p_film: Point2<Raster>) -> Option<CameraRayParts> {
        let direction = self.direction(p_film)?;
        // Clip range: camera z in [near, far] is t in [near, far] / d.z along the unit d.
        let inv_dz = (1.0 / direction.z) as f32;
        Some(CameraRayParts {
            origin: DVec3::ZERO,
            direction,
            t_min: self.base.near * inv_dz,
            t_max: self.base.far * inv_dz,
        })
    }
}

impl Camera for OpenCvCamera {
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
    fn rodrigues_quarter_turn_about_z() {
        // A quarter turn about z maps x to y and y to -x.
        let r = rodrigues(DVec3::new(0.0, 0.0, core::f64::consts::FRAC_PI_2));
        assert!((r * DVec3::X - DVec3::Y).length() < 1e-15);
        assert!((r * DVec3::Y + DVec3::X).length() < 1e-15);
        // Tiny vectors: first order.
        let r = rodrigues(DVec3::new(1e-13, 0.0, 0.0));
        assert!((r * DVec3::Y - DVec3::new(0.0, 1.0, 1e-13)).length() < 1e-20);
    }

    #[test]
    fn fold_of_a_negative_k1() {
        // g(r) = r (1 + k1 r^2): g' = 1 + 3 k1 r^2 = 0 at r = 1 / sqrt(-3 k1); k1 = -1/3 gives 1.
        let d = Distortion::from_slice(&[-1.0 / 3.0, 0.0, 0.0, 0.0]);
        assert!((d.fold_radius() - 1.0).abs() < 1e-12);
        // No distortion: no fold before the search bound.
        let d = Distortion::from_slice(&[0.0; 4]);
        assert_eq!(d.fold_radius(), OPENCV_MAX_RADIUS);
        // A denominator reaching 0: 1 - r^2 (k4 = -1) at r = 1, with g' > 0 before it.
        let d = Distortion::from_slice(&[0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]);
        assert!((d.fold_radius() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let d = Distortion::from_slice(&[
            -0.2, 0.05, 0.01, -0.02, 0.003, 0.1, -0.01, 0.002, 0.004, -0.001, 0.002, 0.0005,
        ]);
        for q in [
            DVec2::new(0.3, -0.2),
            DVec2::new(-0.7, 0.4),
            DVec2::new(0.0, 0.0),
        ] {
            let (_, j) = d.apply(q);
            let h = 1e-6;
            let fx = (d.apply(q + DVec2::X * h).0 - d.apply(q - DVec2::X * h).0) / (2.0 * h);
            let fy = (d.apply(q + DVec2::Y * h).0 - d.apply(q - DVec2::Y * h).0) / (2.0 * h);
            assert!((j.x_axis - fx).abs().max_element() < 1e-8, "{j:?} {fx:?}");
            assert!((j.y_axis - fy).abs().max_element() < 1e-8, "{j:?} {fy:?}");
        }
    }
}
