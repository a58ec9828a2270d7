//! Densities and maps the area light's sampling shares: cone and area densities in solid
//! angle, spheres under similarity transforms, normals under any transform.

use super::TINY;
use core::f32::consts::TAU;
use glam::{Mat3, Mat4, Vec3};
use obscura_space::{Object, Transform, World};

/// `1 - cos` of a cone's half-angle from its `sin^2`, without cancellation for small cones.
pub(crate) fn one_minus_cos(sin2_max: f32) -> f32 {
    let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
    sin2_max / (1.0 + cos_max)
}

/// The density of uniform cone sampling, `1 / (2 pi (1 - cos_max))`, from `sin^2` of the
/// half-angle, computed without cancellation for small cones.
pub(crate) fn cone_pdf(sin2_max: f32) -> f32 {
    1.0 / (TAU * one_minus_cos(sin2_max))
}

/// `sin^2` of the angle from the axis of a direction uniform over the cone with
/// `1 - cos_max` = `one_minus_cos_max`, for a uniform `u`: `cos` uniform in `[cos_max, 1]`,
/// drawn through `sin^2` so that small cones keep their precision (pbrt-v4's
/// `SampleUniformCone`).
pub(crate) fn cone_sin2(u: f32, one_minus_cos_max: f32) -> f32 {
    u * one_minus_cos_max * (2.0 - u * one_minus_cos_max)
}

/// Converts an area density at `p_light` (normal `n_light`) to solid angle seen from `p_ref`.
pub(super) fn area_to_solid_angle(pdf_area: f32, p_ref: Vec3, p_light: Vec3, n_light: Vec3) -> f32 {
    let to_light = p_light - p_ref;
    let d2 = to_light.length_squared();
    if d2 <= TINY {
        return 0.0;
    }
    let cos_light = n_light.dot(-to_light / d2.sqrt()).abs();
    if cos_light <= TINY {
        return 0.0;
    }
    pdf_area * d2 / cos_light
}

/// The world centre and radius of an object-space sphere when the map is a similarity
/// (rotation, uniform scale, translation); `None` when it would be an ellipsoid.
pub(crate) fn world_sphere(
    world_from_object: &Transform<World, Object>,
    center: Vec3,
    radius: f32,
) -> Option<(Vec3, f32)> {
    let m = world_from_object.matrix();
    let linear = Mat3::from_mat4(m);
    let (x, y, z) = (linear.x_axis, linear.y_axis, linear.z_axis);
    let s = x.length();
    let tol = 1e-4 * s.max(1e-30);
    let similar = (y.length() - s).abs() <= tol
        && (z.length() - s).abs() <= tol
        && x.dot(y).abs() <= tol * s
        && x.dot(z).abs() <= tol * s
        && y.dot(z).abs() <= tol * s;
    similar.then(|| (m.transform_point3(center), radius * s))
}

/// The linear map for normals, `(M^-1)^T`, unnormalised.
pub(super) fn normal_matrix(world_from_object: &Transform<World, Object>) -> Mat3 {
    Mat3::from_mat4(world_from_object.inverse_matrix()).transpose()
}

/// `+1` for orientation-preserving maps, `-1` for mirroring ones: `(Ma) x (Mb) = det(M) M^-T (a x b)`,
/// so cross products of mapped edges point against the (inverse-transpose) normal when `det < 0`.
pub(crate) fn orientation_sign(m: &Mat4) -> f32 {
    if Mat3::from_mat4(*m).determinant() < 0.0 {
        -1.0
    } else {
        1.0
    }
}
