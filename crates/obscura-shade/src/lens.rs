//! Light through a glass ball, solved for: the caustic a diffuse vertex receives from a light
//! sample through a smooth glass sphere, found by solving for the one path that refracts into
//! the ball and out of it towards the sampled point (manifold next-event estimation, Hanika,
//! Droske and Fascione 2015, for the chain refract-in, refract-out of a sphere).
//!
//! A light sample cannot reach such a vertex (its shadow ray is stopped by the glass), so the
//! path tracer finds the caustic only when a BSDF sample happens to pass through the ball and
//! leave it towards the light. Near a ball that is most of the variance of a Cornell box with
//! a glass sphere (docs/performance.md, "What the box's error is"). Here the vertex takes the
//! light sample's point `y` and finds every chain `x -> p1 -> p2 -> y` by refraction at `p1`
//! and `p2`, so the caustic is estimated from every vertex near the ball.
//!
//! **The plane.** Refraction keeps the ray, the normal and the refracted ray in one plane,
//! and a sphere's normals pass through its centre `c`: a chain from `x` to `y` lies in the
//! plane through `x`, `c` and `y`. In that plane, in units of the radius, with `c` at the
//! origin, `x = (d, 0)` and `y = (y1, rho)`, `rho > 0`, the ray leaving `x` is fixed by its
//! impact parameter `b` in `[-1, 1]` (its distance from `c`, signed): it meets the ball at
//! incidence `sin(theta_i) = |b|`, refracts to `sin(theta_t) = |b| / eta`, crosses a chord of
//! length `2 cos(theta_t)` and leaves with the same angles. A chain is a root of
//! `g(b) = (y - p2) x u3`, the signed distance of `y` from the exit line (exit point `p2`,
//! unit direction `u3`), with `y` ahead on the line. The roots are bracketed on [`SCAN`]
//! equal steps of `b` and refined by the Illinois method.
//!
//! **The density.** The chains from `x` form a surface of revolution about the axis from `x`
//! through `c`. A direction at angle `alpha` from the axis (`b = d sin(alpha)`) turned by
//! `d_alpha` in the plane moves the exit line at `y` by `|dg/d_alpha| d_alpha`, in the plane and
//! across the exit ray; turned by `d_phi` about the axis it moves `y` by `rho d_phi` out of the
//! plane. The solid angle at `x` is `|sin(alpha)| d_alpha d_phi`, so
//!
//! `d_omega / dA_perp = |b| / (R^2 d^2 cos(alpha) |dg/db| rho)`
//!
//! per unit area across the exit ray at `y` (`dg/d_alpha = dg/db d cos(alpha)`); times the
//! cosine at the light it is per unit of the light's area. Without refraction (`eta = 1`) it
//! is `1 / |y - x|^2`, the inverse square law (a test checks it).
//!
//! **Two ways to one path.** A path `x -> ball -> ball -> light` with both events
//! refractions is found by the solve (density `p(y) / (d_omega / dA)` for its direction at
//! `x`, with `p(y)` the light sample's density per unit area) and by the vertex's BSDF sample
//! followed by two refractions (density `p_bsdf T`). The path tracer weighs the two by the
//! power heuristic, from the vertex's side and from the light's, so each path counts once.
//! Near a fold of the chains (where the lens's own caustic meets the light) `d_omega / dA`
//! grows without bound and the solve's weight goes to zero: the BSDF samples take those
//! paths, and the solve has no fireflies. Two roots within one scan step lie next to such a
//! fold and are missed together, so the BSDF side weighs a path against the solve only where
//! the scan's step around its root changes sign ([`Lenses::density_along`]); such paths are
//! the BSDF samples' alone. Three roots in one step (at the cusp of the lens's caustic) still
//! count as found, though the scan refines to one of them: what the solve would have added
//! for the other two is lost there.

use crate::light::solid_angle::{orientation_sign, world_sphere};
use crate::material::{Material, fresnel_dielectric};
use glam::{DVec2, DVec3, Vec3};
use obscura_accel::{Placement, Shape};

/// The most glass balls a scene keeps for the solve (the largest), so a vertex's cost stays
/// bounded.
pub(crate) const MAX_LENSES: usize = 4;

/// Steps of the impact parameter on which the roots are bracketed. Two roots within one step
/// lie next to a fold, where the solve's MIS weight is small (module docs).
const SCAN: usize = 8;

/// The refinement stops when a step moves the root by less than this (in radii): the
/// density's central differences (a step of 1e-6) need no more.
const ROOT_TOLERANCE: f64 = 1e-10;

/// `(radius / distance)^2` from which a ball is solved through: within two radii of its
/// centre. A ball lens of glass focuses light from afar at 1.5 radii from its centre, and
/// further out the caustic is spread and dim enough for the BSDF's samples (and aiming).
const REACH_SIN2: f32 = 1.0 / 4.0;

/// A static glass ball in world space.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Ball {
    instance: u32,
    center: DVec3,
    radius: f64,
    /// Index of refraction inside over outside, above 1.
    ior: f64,
}

/// The glass balls of a scene that diffuse vertices solve light paths through.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Lenses {
    list: Vec<Ball>,
}

/// One light path `x -> p1 -> p2 -> y` through a ball, in world space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Chain {
    /// The unit direction from `x` to `p1`.
    pub(crate) wi: Vec3,
    /// Where the path enters the ball, and the outward normal there.
    pub(crate) p1: Vec3,
    pub(crate) n1: Vec3,
    /// Where it leaves, and the outward normal there.
    pub(crate) p2: Vec3,
    pub(crate) n2: Vec3,
    /// The unit direction from `p2` towards `y`.
    pub(crate) exit: Vec3,
    /// The two refractions' Fresnel transmittance, `(1 - F)^2`.
    pub(crate) transmittance: f32,
    /// `d_omega / dA_perp`: solid angle at `x` per unit area across the exit ray at `y`.
    pub(crate) solid_angle_per_area: f32,
    /// How far off the sphere a segment of the chain ends, so that the ball does not stop
    /// it: a ten-thousandth of the radius, more far from the origin (f32's spacing there).
    pub(crate) margin: f32,
}

impl Lenses {
    /// The balls among `instances` (`(instance, material, shape, placement)`): static spheres
    /// of smooth glass with an index above 1, placed by a similarity that keeps orientation;
    /// the largest [`MAX_LENSES`] when there are more.
    pub(crate) fn new<'a>(
        instances: impl IntoIterator<Item = (u32, &'a Material, &'a Shape, &'a Placement)>,
    ) -> Lenses {
        let mut list: Vec<Ball> = instances
            .into_iter()
            .filter_map(|(instance, material, shape, placement)| {
                let Material::Dielectric { ior } = *material else {
                    return None;
                };
                let (Shape::Sphere { center, radius }, Placement::Static(t)) = (shape, placement)
                else {
                    return None;
                };
                if ior <= 1.0 || orientation_sign(&t.matrix()) < 0.0 {
                    return None;
                }
                let (c, r) = world_sphere(t, *center, *radius)?;
                (c.is_finite() && r.is_finite() && r > 0.0).then(|| Ball {
                    instance,
                    center: c.as_dvec3(),
                    radius: r as f64,
                    ior: ior as f64,
                })
            })
            .collect();
        if list.len() > MAX_LENSES {
            list.sort_by(|a, b| b.radius.total_cmp(&a.radius));
            list.truncate(MAX_LENSES);
        }
        Lenses { list }
    }

    /// How many balls there are.
    pub(crate) fn len(&self) -> usize {
        self.list.len()
    }

    /// The ball that is instance `instance`, if any.
    #[inline]
    pub(crate) fn index_of(&self, instance: u32) -> Option<usize> {
        self.list.iter().position(|b| b.instance == instance)
    }

    /// The balls a vertex at `p` whose samples leave on the side of the unit normal `n` solves
    /// through, one bit each: those within reach whose sphere is not wholly below the horizon.
    #[inline]
    pub(crate) fn near(&self, p: Vec3, n: Vec3) -> u8 {
        let mut mask = 0;
        for (k, ball) in self.list.iter().enumerate() {
            // In f32, like the vertex: a test of reach, not of the chain.
            let to_center = ball.center.as_vec3() - p;
            let d2 = to_center.length_squared();
            let r = ball.radius as f32;
            let r2 = r * r;
            let outside = d2 > r2 * (1.0 + 1e-4) && d2.is_finite();
            if outside && r2 >= REACH_SIN2 * d2 && to_center.dot(n) > -r {
                mask |= 1 << k;
            }
        }
        mask
    }

    /// Calls `found` with every chain from `x` through ball `k` to `y`.
    pub(crate) fn chains(&self, k: usize, x: Vec3, y: Vec3, mut found: impl FnMut(&Chain)) {
        let Some((ball, plane, e1, e2)) = self.plane(k, x, y) else {
            return;
        };
        let r = ball.radius;
        plane.roots(|b| {
            let Some(path) = plane.path(b) else {
                return;
            };
            if (plane.y - path.p2).dot(path.u3) <= 0.0 {
                return;
            }
            let Some(solid_angle_per_area) = plane.density(b, r) else {
                return;
            };
            let world = |v: DVec2| e1 * v.x + e2 * v.y;
            let chain = Chain {
                wi: world(path.u).as_vec3(),
                p1: (ball.center + r * world(path.p1)).as_vec3(),
                n1: world(path.p1).as_vec3(),
                p2: (ball.center + r * world(path.p2)).as_vec3(),
                n2: world(path.p2).as_vec3(),
                exit: world(path.u3).as_vec3(),
                transmittance: transmittance(path.cos_i, ball.ior),
                solid_angle_per_area,
                margin: (1e-4 * r + 1e-6 * ball.center.abs().max_element()) as f32,
            };
            if chain.transmittance > 0.0 {
                found(&chain);
            }
        });
    }

    /// For a path that left `x` along the unit direction `wi`, passed through ball `k` and
    /// reached `y`: the `(d_omega / dA_perp, transmittance)` that [`Lenses::chains`] gives
    /// the chain it finds for it, for weighing the two ways of finding it against each other;
    /// `None` when the solve would not find that chain (its scan misses the root), so that
    /// the path's weight is then 1 and every path counts once.
    pub(crate) fn density_along(&self, k: usize, x: Vec3, wi: Vec3, y: Vec3) -> Option<(f32, f32)> {
        let (ball, plane, e1, e2) = self.plane(k, x, y)?;
        let wi = wi.as_dvec3();
        // The direction must head towards the centre; its impact parameter follows from
        // `u = (-cos(alpha), sin(alpha))`, `b = d sin(alpha)`.
        if wi.dot(e1) >= 0.0 {
            return None;
        }
        let b = (plane.d * wi.dot(e2)).clamp(-1.0, 1.0);
        if !plane.finds(b) {
            return None;
        }
        let path = plane.path(b)?;
        Some((
            plane.density(b, ball.radius)?,
            transmittance(path.cos_i, ball.ior),
        ))
    }

    /// Ball `k`, the plane through `x`, its centre and `y`, and the plane's axes in world
    /// space: `e1` from the centre towards `x`, `e2` across it towards `y`.
    #[inline]
    fn plane(&self, k: usize, x: Vec3, y: Vec3) -> Option<(Ball, Plane, DVec3, DVec3)> {
        let ball = *self.list.get(k)?;
        let r = ball.radius;
        let to_x = (x.as_dvec3() - ball.center) / r;
        let to_y = (y.as_dvec3() - ball.center) / r;
        let d = to_x.length();
        if d <= 1.0 || !d.is_finite() {
            return None;
        }
        let e1 = to_x / d;
        let y1 = to_y.dot(e1);
        let across = to_y - y1 * e1;
        let rho = across.length();
        // `y` on the axis through `x` and the centre: a set of no area on the light.
        if rho <= 1e-9 * to_y.length().max(1.0) || !rho.is_finite() {
            return None;
        }
        let plane = Plane {
            d,
            y: DVec2::new(y1, rho),
            eta: ball.ior,
        };
        Some((ball, plane, e1, across / rho))
    }
}

/// The Fresnel transmittance of the two refractions at incidence `cos_i`, `(1 - F)^2` (the
/// exit sees the same angles from inside).
fn transmittance(cos_i: f64, ior: f64) -> f32 {
    let f = fresnel_dielectric(cos_i as f32, ior as f32);
    (1.0 - f) * (1.0 - f)
}

/// The plane of the chains from `x` to `y`, in units of the radius about the centre.
#[derive(Debug, Clone, Copy)]
struct Plane {
    /// `x = (d, 0)`, `d > 1`.
    d: f64,
    /// `y = (y1, rho)`, `rho > 0`.
    y: DVec2,
    /// Index inside over outside.
    eta: f64,
}

/// The path through the unit ball of one impact parameter.
#[derive(Debug, Clone, Copy)]
struct PlanePath {
    /// The direction from `x`, the entry point (also its normal), the exit point, the exit
    /// direction, and the cosine of incidence.
    u: DVec2,
    p1: DVec2,
    p2: DVec2,
    u3: DVec2,
    cos_i: f64,
}

impl Plane {
    /// The path of impact parameter `b` in `[-1, 1]`: the ray from `x` at angle `alpha` from
    /// the axis, `sin(alpha) = b / d`, meets the ball at `t = d cos(alpha) - sqrt(1 - b^2)`;
    /// Snell's law in vector form at `p1` (normal `p1`, index ratio `1 / eta`) and at `p2`
    /// (normal `-p2`, ratio `eta`), the chord between them `2 cos(theta_t)` long.
    #[inline]
    fn path(&self, b: f64) -> Option<PlanePath> {
        let path = self.trace(b.clamp(-1.0, 1.0));
        path.u3.is_finite().then_some(path)
    }

    /// [`Plane::path`] for `b` in `[-1, 1]`, unchecked: the scan's and the refinement's
    /// arithmetic (a NaN, which no finite input gives, fails their sign tests).
    #[inline(always)]
    fn trace(&self, b: f64) -> PlanePath {
        let inv_eta = 1.0 / self.eta;
        let sin_alpha = b * (1.0 / self.d);
        let cos_alpha = (1.0 - sin_alpha * sin_alpha).max(0.0).sqrt();
        let u = DVec2::new(-cos_alpha, sin_alpha);
        let cos_i = (1.0 - b * b).max(0.0).sqrt();
        let sin_t = b * inv_eta;
        let cos_t = (1.0 - sin_t * sin_t).max(0.0).sqrt();
        let t1 = self.d * cos_alpha - cos_i;
        let p1 = DVec2::new(self.d, 0.0) + t1 * u;
        let u2 = u * inv_eta + (cos_i * inv_eta - cos_t) * p1;
        let p2 = p1 + 2.0 * cos_t * u2;
        let u3 = self.eta * u2 - (self.eta * cos_t - cos_i) * p2;
        PlanePath {
            u,
            p1,
            p2,
            u3,
            cos_i,
        }
    }

    /// `g(b)`: the signed distance of `y` from the exit line of `b`.
    #[inline(always)]
    fn miss(&self, b: f64) -> f64 {
        let p = self.trace(b);
        p.u3.perp_dot(self.y - p.p2)
    }

    /// `d_omega / dA_perp` of the chain of impact parameter `b` through a ball of radius `r`
    /// (the module's formula); `None` where it is not finite (a fold, or `b = 0`).
    fn density(&self, b: f64, r: f64) -> Option<f32> {
        let slope = self.slope(b);
        let sin_alpha = b / self.d;
        let cos_alpha = (1.0 - sin_alpha * sin_alpha).max(0.0).sqrt();
        let denominator = r * r * self.d * self.d * cos_alpha * slope.abs() * self.y.y;
        let density = (b.abs() / denominator) as f32;
        (denominator > 0.0 && density.is_finite()).then_some(density)
    }

    /// `dg/db` by central differences (one-sided within a step of the ends).
    fn slope(&self, b: f64) -> f64 {
        const H: f64 = 1e-6;
        let lo = (b - H).max(-1.0);
        let hi = (b + H).min(1.0);
        (self.miss(hi) - self.miss(lo)) / (hi - lo)
    }

    /// Calls `root` with every root of `g` found on [`SCAN`] steps of `[-1, 1]`.
    fn roots(&self, mut root: impl FnMut(f64)) {
        let step = 2.0 / SCAN as f64;
        let mut b0 = -1.0;
        let mut g0 = self.miss(b0);
        for i in 1..=SCAN {
            let b1 = -1.0 + step * i as f64;
            let g1 = self.miss(b1);
            if g0.is_finite() && g1.is_finite() && (g0 < 0.0) != (g1 < 0.0) {
                root(self.refine(b0, g0, b1, g1));
            }
            b0 = b1;
            g0 = g1;
        }
    }

    /// Whether [`Plane::roots`] finds the root of `g` at `b`: whether the ends of the scan's
    /// step around `b` differ in sign. A step with two roots (next to a fold) has ends of one
    /// sign, and the scan finds neither. A step with three (next to the cusp of the lens's
    /// caustic) counts as found, though the scan refines to one of them.
    fn finds(&self, b: f64) -> bool {
        let step = 2.0 / SCAN as f64;
        // The same nodes as the scan's, `-1 + step i`, so the same signs.
        let i = (((b + 1.0) / step).floor() as usize).min(SCAN - 1);
        let (g0, g1) = (
            self.miss(-1.0 + step * i as f64),
            self.miss(-1.0 + step * (i + 1) as f64),
        );
        g0.is_finite() && g1.is_finite() && (g0 < 0.0) != (g1 < 0.0)
    }

    /// The root of `g` between `a` and `b`, where it changes sign (the Illinois variant of
    /// the false position method, which converges superlinearly and stays bracketed).
    fn refine(&self, mut a: f64, mut ga: f64, mut b: f64, mut gb: f64) -> f64 {
        let mut side = 0;
        let mut last = f64::NAN;
        for _ in 0..60 {
            if gb == ga {
                break;
            }
            let c = (a * gb - b * ga) / (gb - ga);
            let gc = self.miss(c);
            if gc == 0.0 || !gc.is_finite() || (c - last).abs() < ROOT_TOLERANCE {
                return c;
            }
            last = c;
            if (gc < 0.0) == (gb < 0.0) {
                b = c;
                gb = gc;
                if side == -1 {
                    ga *= 0.5;
                }
                side = -1;
            } else {
                a = c;
                ga = gc;
                if side == 1 {
                    gb *= 0.5;
                }
                side = 1;
            }
        }
        0.5 * (a + b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use obscura_space::Transform;
    use proptest::prelude::*;

    fn lenses(center: Vec3, radius: f32, ior: f32) -> Lenses {
        let material = Material::Dielectric { ior };
        let shape = Shape::Sphere { center, radius };
        let placement = Placement::Static(Transform::IDENTITY);
        Lenses::new([(7, &material, &shape, &placement)])
    }

    fn all_chains(lenses: &Lenses, x: Vec3, y: Vec3) -> Vec<Chain> {
        let mut out = Vec::new();
        lenses.chains(0, x, y, |c| out.push(*c));
        out
    }

    /// Snell's law in 3D at a sphere, written independently of the plane's formulas.
    fn refract(d: Vec3, n: Vec3, ratio: f32) -> Vec3 {
        let c = -d.dot(n);
        let k = 1.0 - ratio * ratio * (1.0 - c * c);
        ratio * d + (ratio * c - k.sqrt()) * n
    }

    /// The unit direction `d` from `x` traced through the ball by [`refract`]: the entry
    /// point and its outward normal, the exit point, and the exit direction (not finite past
    /// total internal reflection); `None` for a ray that misses the ball.
    fn trace_through(
        x: Vec3,
        d: Vec3,
        center: Vec3,
        radius: f32,
        ior: f32,
    ) -> Option<(Vec3, Vec3, Vec3, Vec3)> {
        // Into the sphere: the nearer root of |x + t d - c| = radius.
        let oc = x - center;
        let (b, c) = (oc.dot(d), oc.length_squared() - radius * radius);
        if b * b - c <= 0.0 {
            return None;
        }
        let p1 = x + (-b - (b * b - c).sqrt()) * d;
        let n1 = (p1 - center) / radius;
        let inside = refract(d, n1, 1.0 / ior).normalize();
        let p2 = p1 - 2.0 * (p1 - center).dot(inside) * inside;
        let out = refract(inside, -(p2 - center) / radius, ior).normalize();
        Some((p1, n1, p2, out))
    }

    proptest! {
        #[test]
        fn every_chain_obeys_snells_law_and_ends_at_y(
            center in prop::array::uniform3(-2.0f32..2.0),
            radius in 0.2f32..1.5,
            ior in 1.05f32..2.5,
            x_dir in prop::array::uniform3(-1.0f32..1.0),
            x_far in 1.05f32..3.0,
            y in prop::array::uniform3(-6.0f32..6.0),
        ) {
            // Every chain found from x to y: p1 on the ray from x and on the sphere, Snell's
            // law in 3D (`refract`, not the plane's formulas) carries it to p2 and out along
            // `exit`, which points at y; the density and transmittance are finite.
            let center = Vec3::from(center);
            let Some(x_dir) = Vec3::from(x_dir).try_normalize() else { return Ok(()) };
            let x = center + x_dir * radius * x_far;
            let y = Vec3::from(y);
            prop_assume!((y - center).length() > 1.05 * radius);
            let l = lenses(center, radius, ior);
            for c in all_chains(&l, x, y) {
                let tol = 2e-3;
                prop_assert!((c.p1 - x).normalize().dot(c.wi) > 1.0 - tol, "{:?}", c);
                prop_assert!(((c.p1 - center).length() / radius - 1.0).abs() < tol);
                prop_assert!(((c.p2 - center).length() / radius - 1.0).abs() < tol);
                // Near grazing entry the exit's `1 - eta^2 sin^2` is below f32's rounding of
                // the chain's vectors, so Snell's law in f32 cannot check it, and the density
                // (steep in `b` there) moves with the rounding of `wi`. Such chains carry less
                // than a thousandth of the light (cos_i of 1.7e-3 gave a transmittance of 9e-5).
                let grazing = c.transmittance < 1e-3;
                if !grazing {
                    let inside = refract(c.wi, c.n1, 1.0 / ior);
                    prop_assert!((c.p2 - c.p1).normalize().dot(inside) > 1.0 - tol, "{:?}", c);
                    let out = refract(inside, -c.n2, ior);
                    prop_assert!(out.dot(c.exit) > 1.0 - tol, "{:?}", c);
                }
                prop_assert!((y - c.p2).normalize().dot(c.exit) > 1.0 - tol, "{:?}", c);
                prop_assert!(c.solid_angle_per_area.is_finite() && c.solid_angle_per_area > 0.0);
                prop_assert!((0.0..=1.0).contains(&c.transmittance));
                // The density the path tracer computes for the same path, from its direction.
                let (per_area, t) = l.density_along(0, x, c.wi, y).unwrap();
                if !grazing {
                    prop_assert!((per_area / c.solid_angle_per_area - 1.0).abs() < 1e-2);
                }
                prop_assert!((t - c.transmittance).abs() < 1e-3);
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]
        #[test]
        fn the_paths_weighed_against_the_solve_are_the_chains_it_finds(
            radius in 0.2f32..1.5,
            ior in 1.05f32..2.5,
            x_dir in prop::array::uniform3(-1.0f32..1.0),
            x_far in 1.1f32..2.0,
            across in prop::array::uniform3(-1.0f32..1.0),
            s in -0.95f32..0.95,
            beyond in 0.3f32..4.0,
        ) {
            // A path traced from x through the ball by Snell's law in 3D, to y on its exit
            // ray. The path tracer weighs it against the solve (density_along is Some) if and
            // only if the solve finds its chain: else a path would count less than once (the
            // solve missing two roots next to a fold) or twice.
            let center = Vec3::new(0.3, -0.2, 0.5);
            let Some(x_dir) = Vec3::from(x_dir).try_normalize() else { return Ok(()) };
            let x = center + x_dir * radius * x_far;
            let axis = (center - x).normalize();
            let v = Vec3::from(across);
            let Some(perp) = (v - v.dot(axis) * axis).try_normalize() else { return Ok(()) };
            let sin_alpha = s * radius / (center - x).length();
            let wi = (1.0 - sin_alpha * sin_alpha).sqrt() * axis + sin_alpha * perp;
            let Some((_, _, p2, out)) = trace_through(x, wi, center, radius, ior) else {
                return Ok(());
            };
            prop_assume!(out.is_finite());
            let y = p2 + beyond * radius * out;
            let l = lenses(center, radius, ior);
            // Chains and the path compared by impact parameter in the solve's own plane, which
            // f32's rounding of y turns a little when y is near the axis through x and the
            // centre.
            let Some((_, plane, _, e2)) = l.plane(0, x, y) else { return Ok(()) };
            let b = |w: Vec3| plane.d * w.as_dvec3().dot(e2);
            let near: Vec<Chain> = all_chains(&l, x, y)
                .into_iter()
                .filter(|c| (b(c.wi) - b(wi)).abs() < 1e-3)
                .collect();
            let weighed = l.density_along(0, x, wi, y).is_some();
            prop_assert!(!weighed || !near.is_empty(), "weighed, but the solve finds no such chain");
            if near.len() == 1 && near[0].transmittance > 0.0 {
                prop_assert!(weighed, "the solve finds the chain {:?}, but it is not weighed", near[0]);
            }
        }
    }

    #[test]
    fn a_ball_between_two_points_gives_a_chain() {
        // x below a ball and y above it, on either side of the axis: at least one chain, and
        // its first direction points into the ball.
        let l = lenses(Vec3::new(0.0, 1.0, 0.0), 0.5, 1.5);
        let x = Vec3::new(0.1, 0.0, 0.0);
        let chains = all_chains(&l, x, Vec3::new(-0.3, 3.0, 0.2));
        assert!(!chains.is_empty());
        assert!(chains.iter().all(|c| c.wi.y > 0.0));
    }

    /// A xorshift generator: numbers in `[0, 1)` for the Monte Carlo test.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// Mean and standard error.
    fn mean_and_error(values: &[f64]) -> (f64, f64) {
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
        (mean, (var / n).sqrt())
    }

    #[test]
    fn the_solved_light_equals_what_directions_through_the_ball_find() {
        // The light through a ball of radius 0.5 at height 1 onto a floor point beside its
        // foot, from a 0.6 x 0.6 quad facing down at height 2.8: the integral of
        // T^2 cos(theta_x) over the directions at x that pass through the ball and reach the
        // quad. Estimated twice, independently: (a) as the solve gives it, over points y
        // uniform on the quad, area x sum over chains of T^2 cos_x (d_omega / dA_perp) cos_y;
        // (b) by cosine-sampling directions at x and tracing them through the ball with
        // Snell's law in 3D (`refract` above, not the plane's formulas), pi x mean of T^2
        // over those that reach the quad (about 4% of them). The two agree within 1.5% (the
        // traced estimate's standard error); an error in the roots or the density of a few
        // percent moves (a) away from (b) by more than the 4.5 standard errors allowed.
        let center = Vec3::new(0.0, 1.0, 0.0);
        let l = lenses(center, 0.5, 1.5);
        let x = Vec3::new(0.35, 0.0, 0.1);
        let (corner, side, height) = (Vec3::new(0.0, 2.8, -0.5), 0.6, 2.8);
        let n_light = Vec3::NEG_Y;
        let n = 200_000;
        let traced_n = 2_000_000;
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let solved: Vec<f64> = (0..n)
            .map(|_| {
                let y = corner + Vec3::new(side * rng.next(), 0.0, side * rng.next());
                let mut sum = 0.0;
                l.chains(0, x, y, |c| {
                    let (cos_x, cos_y) = (c.wi.y, n_light.dot(-c.exit));
                    if cos_x > 0.0 && cos_y > 0.0 {
                        sum += (c.transmittance * cos_x * c.solid_angle_per_area * cos_y) as f64;
                    }
                });
                sum * (side * side) as f64
            })
            .collect();
        let traced: Vec<f64> = (0..traced_n)
            .map(|_| {
                let (u1, u2) = (rng.next(), rng.next());
                let (r, phi) = (u1.sqrt(), core::f32::consts::TAU * u2);
                let d = Vec3::new(r * phi.cos(), (1.0 - u1).sqrt(), r * phi.sin());
                let Some((_, n1, p2, out)) = trace_through(x, d, center, 0.5, 1.5) else {
                    return 0.0;
                };
                let f = fresnel_dielectric(d.dot(-n1), 1.5);
                if out.y <= 0.0 {
                    return 0.0;
                }
                let q = p2 + (height - p2.y) / out.y * out;
                let on = (0.0..side).contains(&(q.x - corner.x))
                    && (0.0..side).contains(&(q.z - corner.z));
                if on {
                    core::f64::consts::PI * ((1.0 - f) * (1.0 - f)) as f64
                } else {
                    0.0
                }
            })
            .collect();
        let (a, ea) = mean_and_error(&solved);
        let (b, eb) = mean_and_error(&traced);
        let report = format!("solved {a} +- {ea}, traced {b} +- {eb}");
        assert!(b > 20.0 * eb, "the test should see the caustic: {report}");
        assert!(
            (a - b).abs() <= 4.5 * (ea * ea + eb * eb).sqrt(),
            "{report}"
        );
        // The solve's estimate is far less noisy: that is what it is for.
        assert!(ea < 0.5 * eb, "{report}");
    }

    #[test]
    fn without_refraction_the_density_is_the_inverse_square_law() {
        // An index of 1 (allowed in the plane, not in a scene) bends nothing: the one chain
        // is the straight line, and d_omega / dA_perp = 1 / |y - x|^2.
        let plane = Plane {
            d: 3.0,
            y: DVec2::new(-2.0, 0.5),
            eta: 1.0,
        };
        let mut roots = Vec::new();
        plane.roots(|b| roots.push(b));
        assert_eq!(roots.len(), 1);
        let b = roots[0];
        let slope = plane.slope(b);
        let cos_alpha = (1.0 - (b / 3.0) * (b / 3.0)).sqrt();
        let density = b.abs() / (9.0 * cos_alpha * slope.abs() * 0.5);
        let expected = 1.0 / (DVec2::new(3.0, 0.0) - plane.y).length_squared();
        assert!(
            (density - expected).abs() < 1e-6 * expected,
            "{density} {expected}"
        );
    }
}
