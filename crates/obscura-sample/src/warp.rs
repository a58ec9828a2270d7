//! Warps: maps from the canonical square `[0, 1)^2` to the shapes a renderer samples, with
//! their densities and, where a camera needs them, their inverses.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI, TAU};

use glam::{Vec2, Vec3};

use crate::hash::ONE_MINUS_EPSILON;
use crate::trig::sin_cos_pi_kernel;

/// Clamps a canonical coordinate to `[0, 1)`.
#[inline]
fn clamp_unit(x: f32) -> f32 {
    x.clamp(0.0, ONE_MINUS_EPSILON)
}

/// Shirley and Chiu's concentric map from the square `[0, 1)^2` to the unit disk.
///
/// Concentric squares go to concentric circles, so strata stay compact and adjacent, and the
/// map preserves area up to a constant: uniform in, uniform out (density `1 / pi`, see
/// [`concentric_disk_pdf`]). Its inverse is [`concentric_disk_to_square`].
#[inline]
pub fn square_to_concentric_disk(u: Vec2) -> Vec2 {
    // Map u to [-1, 1]^2 around the centre.
    let offset = 2.0 * u - Vec2::ONE;
    if offset.x == 0.0 && offset.y == 0.0 {
        return Vec2::ZERO;
    }
    // Pick the triangle: the larger coordinate is the radius r, the other over it, t in
    // [-1, 1], the position along the triangle's edge.
    let swap = offset.x.abs() <= offset.y.abs();
    let (r, other) = if swap {
        (offset.y, offset.x)
    } else {
        (offset.x, offset.y)
    };
    // The angle pi/4 t from the radius axis, in half-turns t/4 (exact), within [-1/4, 1/4].
    let (sin, cos) = sin_cos_pi_kernel(0.25 * (other / r));
    // Left and right triangles: r (cos, sin). Top and bottom: the angle is measured from +y
    // the other way round, pi/2 - pi/4 t, and (cos, sin)(pi/2 - a) = (sin, cos)(a).
    if swap {
        r * Vec2::new(sin, cos)
    } else {
        r * Vec2::new(cos, sin)
    }
}

/// The inverse of [`square_to_concentric_disk`]: a point of the unit disk back to `[0, 1)^2`.
///
/// Points outside the disk are mapped as if projected radially onto the square's boundary
/// and the result is clamped to `[0, 1)^2`.
#[inline]
pub fn concentric_disk_to_square(p: Vec2) -> Vec2 {
    let rho = p.length();
    if rho == 0.0 {
        return Vec2::splat(0.5);
    }
    // Angle in [-pi/4, 7pi/4): the four triangles start at -pi/4, pi/4, 3pi/4 and 5pi/4.
    let mut phi = p.y.atan2(p.x);
    if phi < -FRAC_PI_4 {
        phi += TAU;
    }
    // Undo the forward map triangle by triangle (r may be negative in the left and bottom
    // triangles, where the forward map's angle is phi - pi).
    let offset = if phi < FRAC_PI_4 {
        Vec2::new(rho, rho * phi / FRAC_PI_4)
    } else if phi < 3.0 * FRAC_PI_4 {
        Vec2::new(rho * (FRAC_PI_2 - phi) / FRAC_PI_4, rho)
    } else if phi < 5.0 * FRAC_PI_4 {
        Vec2::new(-rho, -rho * (phi - PI) / FRAC_PI_4)
    } else {
        Vec2::new(-rho * (FRAC_PI_2 - (phi - PI)) / FRAC_PI_4, -rho)
    };
    let u = 0.5 * (offset + Vec2::ONE);
    Vec2::new(clamp_unit(u.x), clamp_unit(u.y))
}

/// The density of [`square_to_concentric_disk`] with respect to area on the disk: `1 / pi`.
#[inline]
pub fn concentric_disk_pdf() -> f32 {
    FRAC_1_PI
}

/// The regular polygon's vertex `k` of `blades`, on the unit circle, rotated by `rotation`
/// radians from +x.
#[inline]
fn polygon_vertex(k: u32, blades: u32, rotation: f32) -> Vec2 {
    let angle = rotation + TAU * (k % blades) as f32 / blades as f32;
    Vec2::new(angle.cos(), angle.sin())
}

/// The rotation in radians, with a non-finite rotation read as zero.
#[inline]
fn sanitised_rotation(rotation_degrees: f32) -> f32 {
    if rotation_degrees.is_finite() {
        (rotation_degrees % 360.0).to_radians()
    } else {
        0.0
    }
}

/// Uniform sampling of a regular polygon with `blades` vertices inscribed in the unit circle,
/// vertex 0 at `rotation_degrees` from +x, counter-clockwise: the aperture of a lens with
/// straight diaphragm blades.
///
/// `u.x` picks one of the `blades` triangles fanned around the centre and, rescaled, the
/// distance from the centre (`s = sqrt(u')` makes the density grow with `s`, as a triangle's
/// width does); `u.y` places the point along the outer edge. The density is
/// [`polygon_pdf`]. With fewer than three blades the aperture is round:
/// [`square_to_concentric_disk`]. A non-finite rotation is read as zero.
#[inline]
pub fn square_to_polygon(u: Vec2, blades: u32, rotation_degrees: f32) -> Vec2 {
    if blades < 3 {
        return square_to_concentric_disk(u);
    }
    let rotation = sanitised_rotation(rotation_degrees);
    // Pick the triangle and reuse the rest of u.x as a fresh uniform.
    let scaled = clamp_unit(u.x) * blades as f32;
    let k = (scaled as u32).min(blades - 1);
    let u_radial = (scaled - k as f32).clamp(0.0, 1.0);
    // Point on the outer edge, then pull it towards the centre.
    let v0 = polygon_vertex(k, blades, rotation);
    let v1 = polygon_vertex(k + 1, blades, rotation);
    let s = u_radial.sqrt();
    s * v0.lerp(v1, u.y)
}

/// The inverse of [`square_to_polygon`] for a point inside the polygon.
#[inline]
pub fn polygon_to_square(p: Vec2, blades: u32, rotation_degrees: f32) -> Vec2 {
    if blades < 3 {
        return concentric_disk_to_square(p);
    }
    let rotation = sanitised_rotation(rotation_degrees);
    // Which triangle: the angle from vertex 0, counter-clockwise.
    let mut angle = p.y.atan2(p.x) - rotation;
    angle = angle.rem_euclid(TAU);
    let k = ((angle / TAU * blades as f32) as u32).min(blades - 1);
    let v0 = polygon_vertex(k, blades, rotation);
    let v1 = polygon_vertex(k + 1, blades, rotation);
    // Solve p = a v0 + b v1 (Cramer's rule); then s = a + b and t = b / s.
    let det = v0.perp_dot(v1);
    let a = p.perp_dot(v1) / det;
    let b = v0.perp_dot(p) / det;
    let s = a + b;
    let t = if s > 0.0 { b / s } else { 0.5 };
    Vec2::new(
        clamp_unit((k as f32 + s * s) / blades as f32),
        clamp_unit(t),
    )
}

/// The density of [`square_to_polygon`] with respect to area: one over the polygon's area
/// `blades / 2 * sin(2 pi / blades)`; `1 / pi` (the disk) for fewer than three blades.
#[inline]
pub fn polygon_pdf(blades: u32) -> f32 {
    if blades < 3 {
        return FRAC_1_PI;
    }
    let n = blades as f32;
    1.0 / (0.5 * n * (TAU / n).sin())
}

/// Cosine-weighted directions on the hemisphere around +z (Malley's method: a uniform point
/// of the concentric disk lifted onto the hemisphere). Density: [`cosine_hemisphere_pdf`].
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = square_to_concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// The inverse of [`square_to_cosine_hemisphere`] for a direction with `z >= 0`.
#[inline]
pub fn cosine_hemisphere_to_square(w: Vec3) -> Vec2 {
    concentric_disk_to_square(Vec2::new(w.x, w.y))
}

/// The density of [`square_to_cosine_hemisphere`] with respect to solid angle:
/// `cos(theta) / pi`, and zero below the horizon.
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Uniform directions on the unit sphere (`z = 1 - 2 u.x`, azimuth `2 pi u.y`).
/// Density: [`uniform_sphere_pdf`].
#[inline]
pub fn square_to_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = TAU * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The inverse of [`square_to_uniform_sphere`].
#[inline]
pub fn uniform_sphere_to_square(w: Vec3) -> Vec2 {
    let phi = w.y.atan2(w.x).rem_euclid(TAU);
    Vec2::new(clamp_unit(0.5 * (1.0 - w.z)), clamp_unit(phi / TAU))
}

/// The density of [`square_to_uniform_sphere`] with respect to solid angle: `1 / (4 pi)`.
#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    0.25 * FRAC_1_PI
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec2, b: Vec2) -> bool {
        (a - b).abs().max_element() < 1e-5
    }

    #[test]
    fn concentric_disk_hand_cases() {
        // The centre stays; the middle of each edge of the square goes to the circle's axis
        // points: u = (1, 0.5) -> offset (1, 0) -> r = 1, theta = 0 -> (1, 0).
        assert_eq!(square_to_concentric_disk(Vec2::splat(0.5)), Vec2::ZERO);
        assert!(close(
            square_to_concentric_disk(Vec2::new(1.0, 0.5)),
            Vec2::new(1.0, 0.0)
        ));
        // u = (0.5, 1) -> offset (0, 1) -> r = 1, theta = pi/2 -> (0, 1).
        assert!(close(
            square_to_concentric_disk(Vec2::new(0.5, 1.0)),
            Vec2::new(0.0, 1.0)
        ));
        // u = (0, 0.5) -> offset (-1, 0) -> r = -1, theta = 0 -> (-1, 0).
        assert!(close(
            square_to_concentric_disk(Vec2::new(0.0, 0.5)),
            Vec2::new(-1.0, 0.0)
        ));
        // A corner u = (1, 1) -> offset (1, 1) -> r = 1, theta = pi/4 -> (sqrt(.5), sqrt(.5)).
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert!(close(
            square_to_concentric_disk(Vec2::new(1.0, 1.0)),
            Vec2::new(h, h)
        ));
        // Half-way to the right edge: u = (0.75, 0.5) -> offset (0.5, 0) -> (0.5, 0).
        assert!(close(
            square_to_concentric_disk(Vec2::new(0.75, 0.5)),
            Vec2::new(0.5, 0.0)
        ));
    }

    #[test]
    fn polygon_hand_cases() {
        // Square aperture (4 blades, no rotation): vertices (1,0), (0,1), (-1,0), (0,-1);
        // area = 4/2 * sin(pi/2) = 2, pdf = 1/2.
        assert!((polygon_pdf(4) - 0.5).abs() < 1e-6);
        // u.x just below 1/4 with the remainder ~1 picks triangle 0 at s ~ 1; u.y = 0.5 is
        // the middle of the edge (1,0)-(0,1): (0.5, 0.5).
        let p = square_to_polygon(Vec2::new(0.25 - 1e-7, 0.5), 4, 0.0);
        assert!(close(p, Vec2::new(0.5, 0.5)), "{p}");
        // Rotated by 90 degrees, vertex 0 sits at (0, 1): u = (~0, 0) is the centre and
        // u.x ~ 1/4, u.y = 0 that vertex.
        let p = square_to_polygon(Vec2::new(0.25 - 1e-7, 0.0), 4, 90.0);
        assert!(close(p, Vec2::new(0.0, 1.0)), "{p}");
        // The hexagon's area is 6/2 sin(60 deg) = 3 sqrt(3)/2.
        assert!((polygon_pdf(6) - 2.0 / (3.0 * 3f32.sqrt())).abs() < 1e-6);
    }

    #[test]
    fn pdf_hand_cases() {
        assert!((cosine_hemisphere_pdf(1.0) - 1.0 / PI).abs() < 1e-7);
        assert_eq!(cosine_hemisphere_pdf(-0.5), 0.0);
        assert!((uniform_sphere_pdf() * 4.0 * PI - 1.0).abs() < 1e-6);
        // u = (0.5, 0.25): z = 0, phi = pi/2 -> (0, 1, 0).
        let w = square_to_uniform_sphere(Vec2::new(0.5, 0.25));
        assert!((w - Vec3::Y).length() < 1e-6, "{w}");
    }
}
