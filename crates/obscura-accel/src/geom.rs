//! Ray-primitive intersection and floating-point error bounds, on plain glam values.
//!
//! Everything here works in one space (whichever the caller's ray is in) and knows nothing of
//! instances; the scene carries rays and hits between spaces.

use glam::{Mat4, Vec3, Vec3A};

/// pbrt's `gamma(n) = n * eps / (1 - n * eps)`, with `eps` half an ulp of 1: a bound on the
/// relative error of `n` chained roundings.
#[inline]
pub(crate) const fn gamma(n: i32) -> f32 {
    let eps = f32::EPSILON * 0.5;
    (n as f32 * eps) / (1.0 - n as f32 * eps)
}

/// A hit on a triangle: ray parameter and the barycentrics of vertices 1 and 2.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TriangleHit {
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// Moeller-Trumbore ray-triangle intersection, two-sided, for `t` in `[t_min, t_max]`: the
/// scalar reference for the four-wide test the BVH uses (`wide`), kept for the tests.
#[cfg(test)]
pub(crate) fn intersect_triangle(
    origin: Vec3A,
    direction: Vec3A,
    t_min: f32,
    t_max: f32,
    [p0, p1, p2]: &[Vec3A; 3],
) -> Option<TriangleHit> {
    // Solve origin + t d = p0 + b1 e1 + b2 e2 by Cramer's rule on the scalar triple products.
    let e1 = *p1 - *p0;
    let e2 = *p2 - *p0;
    let pvec = direction.cross(e2);
    let det = e1.dot(pvec);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv_det = 1.0 / det;
    let tvec = origin - *p0;
    let b1 = tvec.dot(pvec) * inv_det;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let qvec = tvec.cross(e1);
    let b2 = direction.dot(qvec) * inv_det;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(qvec) * inv_det;
    (t >= t_min && t <= t_max).then_some(TriangleHit { t, b1, b2 })
}

/// The closest root of `|origin + t d - center|^2 = r^2` with `t` in `[t_min, t_max]`.
///
/// Computed in f64 with the numerically stable discriminant `a (r^2 - |f|^2)`, where `f` is the
/// vector from the centre to the point of the line closest to it (pbrt-v4's form), so grazing
/// and distant rays keep their precision.
pub(crate) fn intersect_sphere(
    origin: Vec3,
    direction: Vec3,
    t_min: f32,
    t_max: f32,
    center: Vec3,
    radius: f32,
) -> Option<f32> {
    let oc = (origin - center).as_dvec3();
    let d = direction.as_dvec3();
    let r = f64::from(radius);
    let a = d.length_squared();
    if a == 0.0 {
        return None;
    }
    let b_half = oc.dot(d);
    let f = oc - d * (b_half / a);
    let disc = r * r - f.length_squared();
    if disc < 0.0 {
        return None;
    }
    let c = oc.length_squared() - r * r;
    let root = (a * disc).sqrt();
    // q = -(b + sign(b) sqrt(disc)) avoids cancellation; the roots are q / a and c / q.
    let q = -(b_half + root.copysign(b_half));
    let (mut t0, mut t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    if t0 > t1 {
        core::mem::swap(&mut t0, &mut t1);
    }
    for t in [t0, t1] {
        let t = t as f32;
        if t >= t_min && t <= t_max {
            return Some(t);
        }
    }
    None
}

/// A hit on a parallelogram: ray parameter and the coordinates `(s, t)` along its edges.
#[derive(Clone, Copy, Debug)]
pub(crate) struct QuadHit {
    pub t: f32,
    pub s: f32,
    pub v: f32,
}

/// The parallelogram `origin + s * edge_u + v * edge_v`, `s, v` in `[0, 1]`, with what every
/// ray's test reads of it computed once: its plane's normal `edge_u x edge_v` and the two
/// vectors whose dot products with a point's offset `w` from `origin` in the plane give `s`
/// and `v`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Parallelogram {
    /// The corner at `s = v = 0`.
    pub origin: Vec3,
    /// The edge along which `s` runs.
    pub edge_u: Vec3,
    /// The edge along which `v` runs.
    pub edge_v: Vec3,
    /// `edge_u x edge_v` (not normalised), or its reverse ([`Parallelogram::mirrored`]).
    pub n: Vec3,
    /// `(edge_v x n) / |n|^2`: `s = w . to_s`.
    pub to_s: Vec3,
    /// `(n x edge_u) / |n|^2`: `v = w . to_v`.
    pub to_v: Vec3,
}

impl Parallelogram {
    /// The parallelogram at `origin` spanned by `edge_u` and `edge_v`.
    pub(crate) fn new(origin: Vec3, edge_u: Vec3, edge_v: Vec3) -> Parallelogram {
        let n = edge_u.cross(edge_v);
        let nn = n.length_squared();
        Parallelogram {
            origin,
            edge_u,
            edge_v,
            n,
            to_s: edge_v.cross(n) / nn,
            to_v: n.cross(edge_u) / nn,
        }
    }

    /// The same parallelogram with its normal reversed, for one carried to world space by a
    /// mirroring placement: the world edges' cross product then points against the inverse
    /// transpose of the object normal, which the hit record's normal must follow. Its hits
    /// are the same to the bit (`t` is a ratio of two dot products with `n`, both negated
    /// exactly; `s` and `v` do not read `n`).
    pub(crate) fn mirrored(self) -> Parallelogram {
        Parallelogram { n: -self.n, ..self }
    }

    /// The ray's hit with `t` in `[t_min, t_max]`, if any.
    #[inline]
    pub(crate) fn intersect(
        &self,
        ray_origin: Vec3,
        direction: Vec3,
        t_min: f32,
        t_max: f32,
    ) -> Option<QuadHit> {
        let Parallelogram {
            origin,
            n,
            to_s,
            to_v,
            ..
        } = *self;
        let denom = n.dot(direction);
        if denom == 0.0 || !denom.is_finite() {
            return None;
        }
        let t = n.dot(origin - ray_origin) / denom;
        if !(t >= t_min && t <= t_max) {
            return None;
        }
        // w = s eu + v ev in the plane. w x ev = s n, so s = n . (w x ev) / |n|^2, and by the
        // triple product's cyclic symmetry that is w . (ev x n) / |n|^2; likewise for v.
        let w = ray_origin + direction * t - origin;
        let s = w.dot(to_s);
        let v = w.dot(to_v);
        ((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&v)).then_some(QuadHit { t, s, v })
    }
}

/// The absolute values of an affine matrix's linear part and translation: what the error
/// bounds of points mapped through it are made of. Computed once per static placement.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AbsAffine {
    linear: glam::Mat3,
    translation: Vec3,
}

impl AbsAffine {
    /// The absolute values of `m`'s linear part and translation.
    pub(crate) fn of(m: &Mat4) -> AbsAffine {
        AbsAffine {
            linear: glam::Mat3::from_mat4(*m).abs(),
            translation: m.w_axis.truncate().abs(),
        }
    }

    /// The absolute values of `m_inv m - I`, computed in f64 from the f32 matrices (exactly
    /// representable there) and rounded up once: how far `m_inv` is from inverting `m`. Both
    /// are affine, so only the linear part and the translation are multiplied out.
    pub(crate) fn inverse_residual(m: &Mat4, m_inv: &Mat4) -> AbsAffine {
        let linear = |a: &Mat4| glam::Mat3::from_mat4(*a).as_dmat3();
        let (n, n_t) = (linear(m_inv), m_inv.w_axis.truncate().as_dvec3());
        let r = n * linear(m) - glam::DMat3::IDENTITY;
        let r_t = n * m.w_axis.truncate().as_dvec3() + n_t;
        let up = |v: glam::DVec3| (v.abs() * (1.0 + f64::from(f32::EPSILON))).as_vec3();
        AbsAffine {
            linear: glam::Mat3::from_cols(up(r.x_axis), up(r.y_axis), up(r.z_axis)),
            translation: up(r_t),
        }
    }
}

/// Maps a point with an absolute error bound through the affine matrix `m` (whose absolute
/// values are `abs`), growing the bound by the roundings of the matrix product (pbrt-v4's
/// `Transform::operator()(Point3fi)`).
pub(crate) fn transform_point_with_error(
    m: &Mat4,
    abs: &AbsAffine,
    p: Vec3,
    p_error: Vec3,
) -> (Vec3, Vec3) {
    let p_out = m.transform_point3(p);
    let rounding = gamma(3) * (abs.linear * p.abs() + abs.translation);
    let carried = (1.0 + gamma(3)) * (abs.linear * p_error);
    (p_out, rounding + carried)
}

/// The smallest distance [`offset_ray_origin`] moves a point off its surface.
const MIN_OFFSET: f32 = 1e-20;

/// Moves `p` off a surface with normal `n` by its error bound `p_error`, to the side `w`
/// points to, then one ulp further away, so a ray from the result cannot re-hit the surface
/// it starts on (pbrt-v4's `OffsetRayOrigin`).
pub(crate) fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    // At least 1e-20: a surface with exact coordinates (a quad in the plane z = 0) has a zero
    // error bound, and an origin left exactly on it would meet it again at t = -0 = 0.
    let d = n.abs().dot(p_error).max(MIN_OFFSET);
    // Then one float further along the normal turned to w's side, so that rounding in the
    // addition cannot pull the origin back; this also moves an origin whose error bound is
    // exactly zero (a plane through 0) off the plane.
    crate::simd::offset_point(Vec3A::from(p), Vec3A::from(n), d, w.dot(n)).into()
}

/// The extra error of a hit found in object space, mapped back to world space. Takes the
/// absolute values of both matrices ([`AbsAffine`]) and of the stored inverse's residual
/// ([`AbsAffine::inverse_residual`]). Two things put the object-space point off the world
/// ray:
/// - the ray's origin was carried there with `object_from_world` (rounded), so the surface
///   point is uncertain by that rounding. Without it, spawned rays far from the origin re-hit
///   moving surfaces;
/// - the stored inverse `N` is not the exact inverse of `M = world_from_object` (each factor of
///   a composed transform was inverted and rounded on its own). The ray met the surface where
///   `N x = p_object`, at `x = N^-1 p_object`, but the hit reports `M p_object`. With
///   `R = N M - I`, `N^-1 - M = -M R (I + R)^-1`, so the two differ by at most
///   `|M| |R| (|p_object|, 1)` to first order (`|R|` is a few ulps). Without it, rays spawned
///   into a scaled sphere met its surface again next to where they left it.
pub(crate) fn object_space_error(
    abs_world_from_object: &AbsAffine,
    abs_object_from_world: &AbsAffine,
    abs_residual: &AbsAffine,
    p_world: Vec3,
    p_object: Vec3,
) -> Vec3 {
    let carried = gamma(4)
        * (abs_object_from_world.linear * p_world.abs() + abs_object_from_world.translation);
    let mismatch = abs_residual.linear * p_object.abs() + abs_residual.translation;
    (1.0 + gamma(3)) * (abs_world_from_object.linear * (carried + mismatch))
}

/// The next representable f32 above `v` (identity for +inf and NaN). The portable steps of
/// [`offset_ray_origin`]; x86-64 takes the same steps on the bits (`crate::simd`).
#[cfg(any(test, not(target_arch = "x86_64")))]
pub(crate) fn next_float_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 || v.is_nan() {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// The next representable f32 below `v`.
#[cfg(any(test, not(target_arch = "x86_64")))]
pub(crate) fn next_float_down(v: f32) -> f32 {
    -next_float_up(-v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::vec3a;

    #[test]
    fn triangle_hit_exact() {
        // The triangle (0,0,0), (1,0,0), (0,1,0) in the plane z = 0; a ray from (0.25, 0.5, 2)
        // straight down (d = (0, 0, -1)) meets it at t = 2 with b1 = x = 0.25, b2 = y = 0.5.
        let tri = [
            vec3a(0.0, 0.0, 0.0),
            vec3a(1.0, 0.0, 0.0),
            vec3a(0.0, 1.0, 0.0),
        ];
        let hit = intersect_triangle(
            vec3a(0.25, 0.5, 2.0),
            vec3a(0.0, 0.0, -1.0),
            0.0,
            10.0,
            &tri,
        )
        .unwrap();
        assert_eq!((hit.t, hit.b1, hit.b2), (2.0, 0.25, 0.5));
        // Outside (x + y = 1.5 > 1) and beyond t_max both miss.
        let miss = intersect_triangle(
            vec3a(0.75, 0.75, 2.0),
            vec3a(0.0, 0.0, -1.0),
            0.0,
            10.0,
            &tri,
        );
        assert!(miss.is_none());
        let short =
            intersect_triangle(vec3a(0.25, 0.5, 2.0), vec3a(0.0, 0.0, -1.0), 0.0, 1.5, &tri);
        assert!(short.is_none());
    }

    #[test]
    fn sphere_hit_exact() {
        // Unit sphere at (0, 0, -5); ray from the origin along -z: |t - 5| = 1, so t = 4 and 6.
        let c = Vec3::new(0.0, 0.0, -5.0);
        let o = Vec3::ZERO;
        let d = Vec3::new(0.0, 0.0, -1.0);
        assert_eq!(
            intersect_sphere(o, d, 0.0, f32::INFINITY, c, 1.0),
            Some(4.0)
        );
        // With t_min past the near root the far root is the answer.
        assert_eq!(
            intersect_sphere(o, d, 4.5, f32::INFINITY, c, 1.0),
            Some(6.0)
        );
        // A direction of length 2 halves t.
        assert_eq!(
            intersect_sphere(o, d * 2.0, 0.0, f32::INFINITY, c, 1.0),
            Some(2.0)
        );
        // Offset by 1.5 sideways the line passes at distance 1.5 > 1: miss.
        let o_side = Vec3::new(1.5, 0.0, 0.0);
        assert_eq!(
            intersect_sphere(o_side, d, 0.0, f32::INFINITY, c, 1.0),
            None
        );
    }

    #[test]
    fn quad_hit_exact() {
        // The quad (0,0,0) + s (2,0,0) + v (0,4,0); the ray from (1, 1, 3) along -z meets z = 0
        // at t = 3, at x = 1 (s = 1/2) and y = 1 (v = 1/4).
        let quad = Parallelogram::new(
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
        );
        let hit = quad
            .intersect(
                Vec3::new(1.0, 1.0, 3.0),
                Vec3::new(0.0, 0.0, -1.0),
                0.0,
                f32::INFINITY,
            )
            .unwrap();
        assert_eq!((hit.t, hit.s, hit.v), (3.0, 0.5, 0.25));
    }

    #[test]
    fn next_float_steps_one_ulp() {
        assert_eq!(next_float_up(1.0), 1.0 + f32::EPSILON);
        assert_eq!(next_float_down(1.0), 1.0 - f32::EPSILON / 2.0);
        assert_eq!(next_float_up(0.0), f32::from_bits(1));
        assert_eq!(next_float_down(0.0), -f32::from_bits(1));
    }

    #[test]
    fn offset_moves_to_the_side_of_w() {
        let p = Vec3::new(0.0, 0.0, 1.0);
        let err = Vec3::splat(1e-3);
        let up = offset_ray_origin(p, err, Vec3::Z, Vec3::Z);
        let down = offset_ray_origin(p, err, Vec3::Z, -Vec3::Z);
        // |n| . err = 1e-3 along z: above and below p by at least that.
        assert!(up.z >= 1.001 && up.x == 0.0);
        assert!(down.z <= 0.999 && down.x == 0.0);
    }

    #[test]
    fn inverse_residual_measures_how_far_an_inverse_misses() {
        // Scaling by 2 and by 0.5 are exact inverses: no residual.
        let m = Mat4::from_scale(Vec3::splat(2.0));
        let exact = AbsAffine::inverse_residual(&m, &Mat4::from_scale(Vec3::splat(0.5)));
        assert_eq!(exact.linear, glam::Mat3::ZERO);
        assert_eq!(exact.translation, Vec3::ZERO);
        // Nudge the inverse's x scale one ulp above 0.5 (2^-24) and its x translation by 2^-20:
        // m_inv m - I is 2 * 2^-24 = 2^-23 at (0, 0) and 2^-20 in the translation, nothing else.
        let mut nudged = Mat4::from_scale(Vec3::splat(0.5));
        nudged.x_axis.x = next_float_up(0.5);
        nudged.w_axis.x = 2f32.powi(-20);
        let r = AbsAffine::inverse_residual(&m, &nudged);
        assert!(r.linear.x_axis.x >= 2f32.powi(-23) && r.linear.x_axis.x < 1.01 * 2f32.powi(-23));
        assert!(r.translation.x >= 2f32.powi(-20) && r.translation.x < 1.01 * 2f32.powi(-20));
        assert_eq!(r.linear.y_axis, Vec3::ZERO);
        assert_eq!((r.translation.y, r.translation.z), (0.0, 0.0));
    }
}
