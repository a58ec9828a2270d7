//! The equal-area octahedral panorama camera.

use crate::camera::{Camera, CameraBase, CameraRay, CameraRayDifferential, CameraSample};
use crate::chain::{self, CameraRayParts, PoseCache};
use crate::error::CameraError;
use core::f64::consts::{FRAC_2_PI, FRAC_PI_4};
use glam::DVec3;
use obscura_space::{Point2, Point3, Raster, World};

/// The whole sphere on a square image by Clarberg's equal-area octahedral map (Petrik
/// Clarberg, "Fast Equal-Area Mapping of the (Hemi)Sphere using SIMD", Journal of Graphics
/// Tools 13(3), 2008; the same map as pbrt-v4's `EqualAreaSquareToSphere`): every pixel
/// subtends the same solid angle, `4 pi / (W H)`.
///
/// Square coordinates: `u = 2 x / W - 1` (right positive), `v = 1 - 2 y / H` (up positive),
/// both in `[-1, 1]`. With `d = 1 - (|u| + |v|)` (signed distance from the diamond
/// `|u| + |v| = 1`) and `r = 1 - |d|`:
///
/// `z = sign(d) (1 - r^2)`, `phi = (pi / 4) ((|v| - |u|) / r + 1)` (and `pi / 4` at `r = 0`),
/// `d_camera = (sign(u) cos phi r sqrt(2 - r^2), sign(v) sin phi r sqrt(2 - r^2), z)`.
///
/// Orientation: the image centre looks along camera +z (forward), the inner diamond is the
/// hemisphere in front, the diamond's edge the horizon-like great circle `z = 0`, the four
/// corners look straight back (-z); the right half looks right (+x), the top half up (+y).
/// The map's Jacobian is the constant `pi` (square area 4 onto sphere area 4 pi).
///
/// The inverse (for [`Camera::project`]) is the published one: `r = sqrt(1 - |z|)`,
/// `v' = r (2 / pi) atan2(|y|, |x|)`, `u' = r - v'`, then for `z < 0` the fold
/// `(u', v') -> (1 - v', 1 - u')`, and the signs of x and y. The square's outer border folds
/// onto itself (`(1, v)` and `(1, -v)` look the same way), so `project` of such a direction
/// returns one of its two raster points. Every film point gives a ray from the eye, clipped by
/// distance (`[t_min, t_max] = [near, far]`); every direction projects.
#[derive(Debug, Clone)]
pub struct OctahedralCamera {
    base: CameraBase,
    pose: PoseCache,
}

impl OctahedralCamera {
    /// An octahedral panorama. Errors: a non-square film ([`CameraError::FilmShape`]; the map
    /// is equal-area only on a square) and the base's errors (`near < 0`, `near >= far`, a bad
    /// shutter).
    pub fn new(base: CameraBase) -> Result<OctahedralCamera, CameraError> {
        base.validate(false)?;
        let [width, height] = base.film.resolution();
        if width != height {
            return Err(CameraError::FilmShape {
                model: "octahedral",
                need: "a square",
                got: [width, height],
            });
        }
        Ok(OctahedralCamera {
            pose: PoseCache::new(&base),
            base,
        })
    }

    /// The pose, shutter, film and clip range.
    pub fn base(&self) -> &CameraBase {
        &self.base
    }

    /// Clarberg's map from the square `[-1, 1]^2` to the unit sphere (centre -> +z).
    pub fn square_to_sphere(u: f64, v: f64) -> DVec3 {
        // Signed distance from the diamond |u| + |v| = 1, and the radius it gives.
        let (au, av) = (u.abs(), v.abs());
        let signed_distance = 1.0 - (au + av);
        let r = 1.0 - signed_distance.abs();
        // Azimuth within the quadrant, linear along the square's concentric diamonds.
        let phi = if r == 0.0 {
            FRAC_PI_4
        } else {
            FRAC_PI_4 * ((av - au) / r + 1.0)
        };
        // Height: equal area needs 1 - |z| = r^2.
        let z = (1.0 - r * r).copysign(signed_distance);
        // Back to the original quadrant.
        let (sin_phi, cos_phi) = phi.sin_cos();
        let s = r * (2.0 - r * r).max(0.0).sqrt();
        DVec3::new(cos_phi.copysign(u) * s, sin_phi.copysign(v) * s, z)
    }

    /// The inverse of [`OctahedralCamera::square_to_sphere`] for a unit direction.
    pub fn sphere_to_square(d: DVec3) -> [f64; 2] {
        let (ax, ay, az) = (d.x.abs(), d.y.abs(), d.z.abs());
        // Radius from the height, then the split of the radius between u and v by azimuth.
        let r = (1.0 - az).max(0.0).sqrt();
        let phi = if ax == 0.0 && ay == 0.0 {
            0.5
        } else {
            ay.atan2(ax) * FRAC_2_PI
        };
        let mut v = phi * r;
        let mut u = r - v;
        // The back hemisphere folds out over the diamond's edge.
        if d.z < 0.0 {
            (u, v) = (1.0 - v, 1.0 - u);
        }
        [u.copysign(d.x), v.copysign(d.y)]
    }

    /// The camera-space unit direction of a film point.
    pub fn direction(&self, p_film: Point2<Raster>) -> DVec3 {
        let [width, height] = self.base.film.resolution().map(f64::from);
        let mut u = 2.0 * f64::from(p_film.x) / width - 1.0;
        let mut v = 1.0 - 2.0 * f64::from(p_film.y) / height;
        // Film points just outside the image (a differential's neighbour) continue across the
        // border's fold: (1 + e, v) looks where (1 - e, -v) does.
        if u.abs() > 1.0 {
            (u, v) = (2.0f64.copysign(u) - u, -v);
        }
        if v.abs() > 1.0 {
            (u, v) = (-u, 2.0f64.copysign(v) - v);
        }
        Self::square_to_sphere(u.clamp(-1.0, 1.0), v.clamp(-1.0, 1.0)).normalize()
    }

    /// The camera-space ray of a film point.
    #[inline]
    fn ray_at(&self, p_film: Point2<Raster>) -> Option<CameraRayParts> {
        Some(CameraRayParts::by_distance(
            DVec3::ZERO,
            self.direction(p_film),
            &self.base,
        ))
    }
}

impl Camera for OctahedralCamera {
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
        // World -> camera, a unit direction within the clip range.
        let v = chain::camera_point(&self.base, &self.pose, p, time);
        let d = chain::direction_within_clip(&self.base, v)?;
        // Square coordinates, then raster (y down).
        let [u, v] = Self::sphere_to_square(d);
        let [width, height] = self.base.film.resolution().map(f64::from);
        Some(Point2::new(
            (0.5 * width * (u + 1.0)) as f32,
            (0.5 * height * (1.0 - v)) as f32,
        ))
    }

    fn uses_lens_sample(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn landmarks() {
        // Centre: r = 0, z = 1. Diamond corner (1, 0): d = 0, r = 1, phi = 0 -> (1, 0, 0).
        // Square corner (1, 1): d = -1, r = 0 -> z = -1. Edge midpoint (1/2, 1/2): on the
        // diamond, r = 1, phi = pi/4 -> (sqrt(1/2), sqrt(1/2), 0).
        let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-12;
        assert!(close(
            OctahedralCamera::square_to_sphere(0.0, 0.0),
            DVec3::Z
        ));
        assert!(close(
            OctahedralCamera::square_to_sphere(1.0, 0.0),
            DVec3::X
        ));
        assert!(close(
            OctahedralCamera::square_to_sphere(0.0, 1.0),
            DVec3::Y
        ));
        assert!(close(
            OctahedralCamera::square_to_sphere(-1.0, 0.0),
            -DVec3::X
        ));
        assert!(close(
            OctahedralCamera::square_to_sphere(1.0, 1.0),
            -DVec3::Z
        ));
        assert!(close(
            OctahedralCamera::square_to_sphere(-1.0, -1.0),
            -DVec3::Z
        ));
        let h = 0.5f64.sqrt();
        assert!(close(
            OctahedralCamera::square_to_sphere(0.5, -0.5),
            DVec3::new(h, -h, 0.0)
        ));
    }
}
