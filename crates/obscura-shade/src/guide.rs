//! Aiming at casters: a diffuse vertex sends a share of its BSDF samples into the cones that
//! nearby smooth specular objects (glass, mirrors) subtend, so that light they focus onto it
//! (a caustic) is found far more often than by cosine sampling alone.
//!
//! A caustic on a diffuse surface, the path diffuse - glass - glass - light, can only be
//! found by sampling the BSDF: a light sample's shadow ray is stopped by the glass. Cosine
//! sampling meets a small glass sphere rarely, and when it does the path carries the focused
//! light's whole value, so the caustic is where such scenes keep their error (fireflies).
//!
//! At a diffuse vertex `p` where the camera ray or the first bounce lands ([`AIMED_DEPTH`]),
//! caster `k` (a bounding sphere) gets the weight `w_k = f_k min(1, sin^2(theta_k) / NEAR)`,
//! `theta_k` the half-angle of its cone seen from `p` (zero when `p` is inside it or the cone
//! lies wholly below the horizon), `f_k` its focus: 1 for glass, [`HALF_FOCUS`] for a mirror
//! and for a glass ball that the vertices near it solve through for every light
//! ([`crate::lens`]). The direction is drawn from the mixture
//!
//! `p_mix = (1 - a) p_bsdf + a sum_k (w_k / W) q_k`, with `W = sum_k w_k`, `a = SHARE min(1, W)`
//!
//! where `q_k` is the uniform density over cone `k`, and the sample is weighted by `p_mix`:
//! the one-sample balance heuristic over the strategies (Veach 1997, section 9.2.4), so the
//! estimate stays unbiased. The light sample's MIS weight and an emitter's weight when a
//! path meets it use the same `p_mix`, so next-event estimation and the BSDF samples stay a
//! partition of unity. A ball lens focuses within about its own radius and a convex mirror
//! spreads what it reflects, so a caster's light is concentrated only near it: the weight
//! falls with the square of the distance past twice the radius (`NEAR = 1/4`), and a vertex
//! far from every caster samples its BSDF alone (docs/performance.md, "Aiming at casters").
//! For the same reason a mirror takes half a glass ball's share; so does a glass ball whose
//! focused light the vertices near it already solve for, where what aiming adds is the light
//! it throws further away and along longer chains (docs/performance.md, "Half a share").

use crate::frame::Frame;
use crate::light::solid_angle::{cone_pdf, cone_sin2, one_minus_cos, world_sphere};
use crate::material::Material;
use core::f32::consts::TAU;
use glam::{Vec2, Vec3};
use obscura_accel::{Placement, Shape};
use obscura_sample::ONE_MINUS_EPSILON;
use obscura_space::{AnimatedTransform, Bounds3, Object, Point3, Transform, World};

/// The largest share of a diffuse vertex's BSDF samples aimed at casters.
pub(crate) const SHARE: f32 = 0.5;

/// The focus of a mirror, and of a glass ball solved through for every light: half a glass
/// ball's.
pub(crate) const HALF_FOCUS: f32 = 0.5;

/// `sin^2` of a cone's half-angle from which a caster gets its full weight: within twice its
/// radius of its centre.
const NEAR: f32 = 0.25;

/// Vertices at path depths below this aim: where the camera ray and the first bounce land.
/// A caustic seen after more diffuse bounces is blurred and dimmed by them, and aiming from
/// every depth cost the Cornell-style box more time than it saved error.
pub(crate) const AIMED_DEPTH: u32 = 2;

/// The most casters a scene keeps (the largest bounding spheres), so a vertex's cost stays
/// bounded in a scene with many specular objects.
pub(crate) const MAX_CASTERS: usize = 8;

/// A caster's bounding sphere in world space, and what weighs it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Caster {
    center: Vec3,
    radius: f32,
    /// The instance it bounds.
    instance: u32,
    /// Its material's focus: 1 for glass, [`HALF_FOCUS`] for a mirror.
    focus: f32,
    /// The focus its weight takes: `focus`, or [`HALF_FOCUS`] for a glass ball that is
    /// solved through ([`Casters::mark_solved`]).
    weight_focus: f32,
}

impl Caster {
    /// A caster of focus 1 (glass, not solved through) for instance 0.
    fn sphere(center: Vec3, radius: f32) -> Caster {
        Caster {
            center,
            radius,
            instance: 0,
            focus: 1.0,
            weight_focus: 1.0,
        }
    }
}

/// The cone a caster subtends from a point outside it.
#[derive(Debug, Clone, Copy)]
struct Cone {
    /// The unit direction to the caster's centre.
    axis: Vec3,
    /// `1 - cos_max`, computed from `sin^2` without cancellation for small cones.
    one_minus_cos_max: f32,
}

impl Cone {
    /// A direction uniform over the cone ([`cone_sin2`] for the angle from the axis).
    #[inline]
    fn sample(&self, u: Vec2) -> Vec3 {
        let sin2 = cone_sin2(u.x, self.one_minus_cos_max);
        let cos_theta = (1.0 - sin2).max(0.0).sqrt();
        let sin_theta = sin2.max(0.0).sqrt();
        let (sin_phi, cos_phi) = (TAU * u.y).sin_cos();
        Frame::from_normal(self.axis).from_local(Vec3::new(
            sin_theta * cos_phi,
            sin_theta * sin_phi,
            cos_theta,
        ))
    }
}

/// A caster as a vertex sees it: enough to weigh it and to test a direction against its cone
/// without a square root; the cone itself is made only for a sample drawn from it and for a
/// density it contributes to.
#[derive(Debug, Clone, Copy, Default)]
struct Slot {
    /// From the vertex to the caster's centre.
    to_center: Vec3,
    /// `|to_center|^2`.
    d2: f32,
    /// The caster's radius squared.
    r2: f32,
    /// `focus min(1, sin^2 / NEAR)`; zero for a caster the vertex does not aim at.
    weight: f32,
}

impl Slot {
    /// The cone of directions towards the caster.
    #[inline]
    fn cone(&self) -> Cone {
        Cone {
            axis: self.to_center / self.d2.sqrt(),
            one_minus_cos_max: one_minus_cos(self.r2 / self.d2),
        }
    }

    /// Whether the unit direction `w` lies in the cone: `w . axis >= cos_max`, squared
    /// (`cos_max^2 d^2 = d^2 - r^2`).
    #[inline]
    fn contains(&self, w: Vec3) -> bool {
        let t = w.dot(self.to_center);
        t > 0.0 && t * t >= self.d2 - self.r2
    }

    /// The uniform density over the cone.
    #[inline]
    fn pdf(&self) -> f32 {
        cone_pdf(self.r2 / self.d2)
    }
}

/// The casters of a scene: the bounding spheres of its instances whose material is smooth
/// specular, at most [`MAX_CASTERS`] of them.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Casters {
    list: Vec<Caster>,
}

impl Casters {
    /// The casters among `instances` (`(material, shape, placement)`): every instance whose
    /// material is all delta lobes ([`Material::is_specular`]), the largest [`MAX_CASTERS`]
    /// by radius when there are more (ties by order). A moving instance is bounded over its
    /// whole motion ([`AnimatedTransform::motion_bounds`]): a vertex cannot know where along
    /// it a later ray will meet the object, and any sphere keeps the estimate unbiased.
    pub(crate) fn new<'a>(
        instances: impl IntoIterator<Item = (u32, &'a Material, &'a Shape, &'a Placement)>,
    ) -> Casters {
        let mut list: Vec<Caster> = instances
            .into_iter()
            .filter(|(_, m, _, _)| m.is_specular())
            .filter_map(|(instance, material, shape, placement)| {
                let sphere = match placement {
                    Placement::Static(t) => bounding_sphere(shape, t),
                    Placement::Moving(a) => swept_sphere(shape, a),
                }?;
                let focus = match material {
                    Material::Dielectric { .. } => 1.0,
                    _ => HALF_FOCUS,
                };
                Some(Caster {
                    instance,
                    focus,
                    weight_focus: focus,
                    ..sphere
                })
            })
            .collect();
        if list.len() > MAX_CASTERS {
            list.sort_by(|a, b| b.radius.total_cmp(&a.radius));
            list.truncate(MAX_CASTERS);
        }
        Casters { list }
    }

    /// Gives the casters for which `solved(instance)` holds (glass balls that the vertices
    /// near them solve through for every light) [`HALF_FOCUS`], and the others their
    /// material's focus.
    pub(crate) fn mark_solved(&mut self, solved: impl Fn(u32) -> bool) {
        for caster in &mut self.list {
            caster.weight_focus = if solved(caster.instance) {
                HALF_FOCUS
            } else {
                caster.focus
            };
        }
    }

    /// How many casters there are.
    pub(crate) fn len(&self) -> usize {
        self.list.len()
    }

    /// Whether there is any caster: without one, every vertex samples its BSDF alone.
    #[inline]
    pub(crate) fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The casters' weights at `p`, for a vertex whose samples leave on the side of the unit
    /// normal `n`: zero from inside a caster's bounding sphere and for a cone wholly below
    /// the horizon (the angle from `n` to its axis beyond 90 degrees plus its half-angle,
    /// that is `(c - p) . n < -r`).
    #[inline]
    pub(crate) fn at(&self, p: Vec3, n: Vec3) -> Aim {
        let mut aim = Aim {
            slots: [Slot::default(); MAX_CASTERS],
            count: self.list.len(),
            total: 0.0,
        };
        for (slot, c) in aim.slots.iter_mut().zip(&self.list) {
            let to_center = c.center - p;
            let d2 = to_center.length_squared();
            let r2 = c.radius * c.radius;
            let outside = d2 > r2 * (1.0 + 1e-4) && d2.is_finite();
            if !outside || to_center.dot(n) < -c.radius {
                continue;
            }
            let weight = (r2 / (NEAR * d2)).min(1.0) * c.weight_focus;
            *slot = Slot {
                to_center,
                d2,
                r2,
                weight,
            };
            aim.total += weight;
        }
        aim
    }
}

/// The casters as one vertex sees them (slot `k` for caster `k`), and their weights' sum.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Aim {
    slots: [Slot; MAX_CASTERS],
    /// How many slots are the scene's casters.
    count: usize,
    total: f32,
}

impl Aim {
    /// The probability with which the vertex aims at a caster: `SHARE min(1, W)`.
    #[inline]
    pub(crate) fn share(&self) -> f32 {
        SHARE * self.total.min(1.0)
    }

    /// A direction uniform over the cone of the caster that `u.x` picks (each by its weight;
    /// `u.x` is then rescaled to `[0, 1)` within the pick), with the caster's index; `None`
    /// when the vertex aims at none.
    #[inline]
    pub(crate) fn sample(&self, u: Vec2) -> Option<(Vec3, usize)> {
        let mut target = u.x * self.total;
        let mut last = None;
        for (k, slot) in self.slots[..self.count].iter().enumerate() {
            if slot.weight <= 0.0 {
                continue;
            }
            last = Some((k, slot));
            if target < slot.weight {
                break;
            }
            target -= slot.weight;
        }
        // Rounding may leave `target` just past the last weight: the last caster takes it.
        let (k, slot) = last?;
        let x = (target / slot.weight).clamp(0.0, ONE_MINUS_EPSILON);
        Some((slot.cone().sample(Vec2::new(x, u.y)), k))
    }

    /// The mixture's density for the world direction `w`, given the BSDF's own density
    /// `pdf_bsdf` for it. `drawn`: the caster whose cone `w` was drawn from, if it was, which
    /// counts as containing it whatever the rounding of the test says.
    #[inline]
    pub(crate) fn mixture_pdf(&self, w: Vec3, pdf_bsdf: f32, drawn: Option<usize>) -> f32 {
        if self.total <= 0.0 {
            return pdf_bsdf;
        }
        let mut aimed = 0.0;
        for (k, slot) in self.slots[..self.count].iter().enumerate() {
            if slot.weight > 0.0 && (drawn == Some(k) || slot.contains(w)) {
                aimed += slot.weight * slot.pdf();
            }
        }
        let share = self.share();
        (1.0 - share) * pdf_bsdf + share * aimed / self.total
    }
}

/// A sphere around `shape` placed by `world_from_object`: exact for a sphere under a
/// similarity, else the sphere through the corners of the world box around its object box.
fn bounding_sphere(shape: &Shape, world_from_object: &Transform<World, Object>) -> Option<Caster> {
    if let Shape::Sphere { center, radius } = shape
        && let Some((c, r)) = world_sphere(world_from_object, *center, *radius)
    {
        return finite(c, r);
    }
    box_sphere(world_from_object.bounds(shape.object_bounds()), 0.0)
}

/// A sphere that holds `shape` over all of its motion. For a sphere placed by similarities at
/// every keyframe: the box its centre sweeps, grown by the largest of the keyframes' radii (a
/// uniform scale is interpolated linearly between keyframes, so the radius never exceeds
/// them). Otherwise the sphere through the corners of the box the shape sweeps.
fn swept_sphere(
    shape: &Shape,
    world_from_object: &AnimatedTransform<World, Object>,
) -> Option<Caster> {
    if let Shape::Sphere { center, radius } = shape {
        let radii: Option<Vec<f32>> = world_from_object
            .keyframes()
            .map(|(_, t)| world_sphere(&t, *center, *radius).map(|(_, r)| r))
            .collect();
        if let Some(largest) = radii.and_then(|r| r.into_iter().reduce(f32::max)) {
            let c = Point3::from_glam(*center);
            return box_sphere(world_from_object.motion_bounds(Bounds3::new(c, c)), largest);
        }
    }
    box_sphere(world_from_object.motion_bounds(shape.object_bounds()), 0.0)
}

/// The sphere through the corners of `b`, its radius grown by `grow`.
fn box_sphere(b: Bounds3<World>, grow: f32) -> Option<Caster> {
    finite(
        b.centroid().to_glam(),
        0.5 * b.diagonal().to_glam().length() + grow,
    )
}

/// A caster, when its centre and radius are finite and the radius positive.
fn finite(center: Vec3, radius: f32) -> Option<Caster> {
    (center.is_finite() && radius.is_finite() && radius > 0.0)
        .then(|| Caster::sphere(center, radius))
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::PI;
    use glam::Mat4;
    use proptest::prelude::*;

    fn casters(list: &[(Vec3, f32)]) -> Casters {
        Casters {
            list: list
                .iter()
                .map(|&(center, radius)| Caster::sphere(center, radius))
                .collect(),
        }
    }

    fn ball(radius: f32) -> Shape {
        Shape::Sphere {
            center: Vec3::ZERO,
            radius,
        }
    }

    fn at(x: f32, y: f32, z: f32) -> Placement {
        Placement::Static(
            Transform::from_matrix(Mat4::from_translation(Vec3::new(x, y, z))).unwrap(),
        )
    }

    #[test]
    fn specular_instances_cast_and_moving_ones_over_their_motion() {
        let glass = Material::Dielectric { ior: 1.5 };
        let mirror = Material::Mirror {
            reflectance: Vec3::ONE,
        };
        let clay = Material::Diffuse {
            reflectance: Vec3::splat(0.5),
        };
        let rough = Material::RoughConductor {
            reflectance: Vec3::ONE,
            roughness: 0.5,
        };
        let t = |m: Mat4| Transform::from_matrix(m).unwrap();
        let slide = |from: Mat4, to: Mat4| {
            Placement::Moving(AnimatedTransform::new(t(from), 0.0, t(to), 1.0).unwrap())
        };
        let moving = slide(Mat4::IDENTITY, Mat4::from_translation(Vec3::X));
        let (s, fixed) = (ball(1.0), at(0.0, 2.0, 0.0));
        let c = Casters::new([
            (0, &glass, &s, &fixed),
            (1, &mirror, &s, &moving),
            (2, &clay, &s, &fixed),
            (3, &rough, &s, &fixed),
            (4, &clay, &s, &moving),
        ]);
        assert_eq!(c.len(), 2, "{:?}", c.list);
        assert_eq!(c.list[0], Caster::sphere(Vec3::new(0.0, 2.0, 0.0), 1.0));
        // The mirror keeps its instance and takes half a glass ball's focus.
        assert_eq!((c.list[1].instance, c.list[1].focus), (1, HALF_FOCUS));
        // The unit ball slid by 1 along x: its centre sweeps (0, 0, 0) to (1, 0, 0), so the
        // sphere is centred at (0.5, 0, 0) with radius 0.5 + 1.
        let swept = |placement: &Placement| Casters::new([(0, &glass, &s, placement)]).list[0];
        let c = swept(&moving);
        assert!(
            (c.center - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6,
            "{c:?}"
        );
        assert!((c.radius - 1.5).abs() < 1e-6, "{c:?}");
        // Growing from radius 1 to 2 in place: the larger radius.
        let c = swept(&slide(Mat4::IDENTITY, Mat4::from_scale(Vec3::splat(2.0))));
        assert!(
            c.center.length() < 1e-6 && (c.radius - 2.0).abs() < 1e-6,
            "{c:?}"
        );
        // Stretched by 2 along y (not a sphere) and slid by 1 along x: the box it sweeps is
        // [-1, 2] x [-2, 2] x [-1, 1], whose corners lie sqrt(9 + 16 + 4) / 2 from its centre.
        let stretch = Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0));
        let c = swept(&slide(stretch, Mat4::from_translation(Vec3::X) * stretch));
        assert!(
            (c.center - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6,
            "{c:?}"
        );
        assert!((c.radius - 29f32.sqrt() / 2.0).abs() < 1e-5, "{c:?}");
    }

    #[test]
    fn bounding_spheres_by_hand() {
        // A sphere of radius 1 at (1, 2, 3), scaled by 2 and moved by (1, 0, 0): centre
        // (3, 4, 6), radius 2, exactly.
        let t = |m: Mat4| Transform::from_matrix(m).unwrap();
        let m = t(Mat4::from_translation(Vec3::X) * Mat4::from_scale(Vec3::splat(2.0)));
        let s = Shape::Sphere {
            center: Vec3::new(1.0, 2.0, 3.0),
            radius: 1.0,
        };
        assert_eq!(
            bounding_sphere(&s, &m),
            Some(Caster::sphere(Vec3::new(3.0, 4.0, 6.0), 2.0))
        );
        // Stretched by 2 along y it is an ellipsoid: the sphere through its box's corners,
        // [-1, 1] x [-2, 2] x [-1, 1], has radius sqrt(1 + 4 + 1).
        let stretched = bounding_sphere(&ball(1.0), &t(Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0))));
        let c = stretched.unwrap();
        assert_eq!(c.center, Vec3::ZERO);
        assert!((c.radius - 6f32.sqrt()).abs() < 1e-6, "{c:?}");
        // A 2 x 2 quad in the plane y = 0 from the origin: centre (1, 0, 1), radius sqrt(2).
        let quad = Shape::Quad {
            origin: Vec3::ZERO,
            edge_u: Vec3::new(2.0, 0.0, 0.0),
            edge_v: Vec3::new(0.0, 0.0, 2.0),
        };
        let c = bounding_sphere(&quad, &Transform::IDENTITY).unwrap();
        assert_eq!(c.center, Vec3::new(1.0, 0.0, 1.0));
        assert!((c.radius - 2f32.sqrt()).abs() < 1e-6);
        // A mesh's box: the triangle (0,0,0), (4,0,0), (0,2,0) has the box [0,4] x [0,2] x 0.
        let mesh = obscura_accel::TriangleMesh::new(
            vec![
                Vec3::ZERO,
                Vec3::new(4.0, 0.0, 0.0),
                Vec3::new(0.0, 2.0, 0.0),
            ],
            vec![[0, 1, 2]],
            None,
            None,
        )
        .unwrap();
        let c = bounding_sphere(
            &Shape::Mesh(std::sync::Arc::new(mesh)),
            &Transform::IDENTITY,
        )
        .unwrap();
        assert_eq!(c.center, Vec3::new(2.0, 1.0, 0.0));
        assert!((c.radius - 5f32.sqrt()).abs() < 1e-6);
    }

    #[test]
    fn more_casters_than_the_limit_keep_the_largest() {
        let glass = Material::Dielectric { ior: 1.5 };
        let shapes: Vec<Shape> = (0..MAX_CASTERS + 4).map(|k| ball(1.0 + k as f32)).collect();
        let fixed = at(0.0, 0.0, 0.0);
        let c = Casters::new(shapes.iter().map(|s| (0, &glass, s, &fixed)));
        assert_eq!(c.len(), MAX_CASTERS);
        assert!(c.list.iter().all(|c| c.radius >= 5.0), "{:?}", c.list);
    }

    #[test]
    fn weights_and_shares_by_hand() {
        let up = Vec3::Y;
        // From 4 away a sphere of radius 1 has sin^2 = 1/16 of its half-angle: weight
        // (1/16) / NEAR = 1/4, so a quarter of SHARE.
        let far = casters(&[(Vec3::new(0.0, 4.0, 0.0), 1.0)]);
        assert!((far.at(Vec3::ZERO, up).share() - SHARE / 4.0).abs() < 1e-6);
        // From 1.5 away, sin^2 = 4/9 > NEAR: full weight.
        let near = casters(&[(Vec3::new(0.0, 1.5, 0.0), 1.0)]);
        assert_eq!(near.at(Vec3::ZERO, up).share(), SHARE);
        // Two near casters: the share is still SHARE, split between them.
        let two = casters(&[
            (Vec3::new(0.0, 1.5, 0.0), 1.0),
            (Vec3::new(1.5, 0.0, 0.0), 1.0),
        ]);
        assert_eq!(two.at(Vec3::ZERO, up).share(), SHARE);
        // Wholly below the horizon (from the side of -y it is above), and from inside: none.
        let below = casters(&[(Vec3::new(0.0, -4.0, 0.0), 1.0)]);
        assert_eq!(below.at(Vec3::ZERO, up).share(), 0.0);
        assert!((below.at(Vec3::ZERO, -up).share() - SHARE / 4.0).abs() < 1e-6);
        assert_eq!(near.at(Vec3::new(0.0, 1.4, 0.0), up).share(), 0.0);
        assert_eq!(
            near.at(Vec3::new(0.0, 1.4, 0.0), up)
                .sample(Vec2::splat(0.5)),
            None
        );
        // Half below the horizon (the axis in the tangent plane) still counts.
        let side = casters(&[(Vec3::new(4.0, 0.0, 0.0), 1.0)]);
        assert!(side.at(Vec3::ZERO, up).share() > 0.0);
    }

    #[test]
    fn mirrors_and_solved_glass_take_half_a_share() {
        let up = Vec3::Y;
        let glass = Material::Dielectric { ior: 1.5 };
        let mirror = Material::Mirror {
            reflectance: Vec3::ONE,
        };
        let s = ball(1.0);
        let (over, beside) = (at(0.0, 1.5, 0.0), at(1.5, 0.0, 0.0));
        // Full weight from 1.5 away: a mirror alone takes half of SHARE.
        let mut c = Casters::new([(7, &mirror, &s, &over)]);
        assert_eq!(c.at(Vec3::ZERO, up).share(), SHARE * HALF_FOCUS);
        // Glass and a mirror side by side: weights 1 and 1/2, so the share is SHARE and the
        // glass is picked two times in three.
        c = Casters::new([(3, &glass, &s, &over), (7, &mirror, &s, &beside)]);
        let aim = c.at(Vec3::ZERO, up);
        assert_eq!(aim.share(), SHARE);
        assert_eq!(aim.sample(Vec2::new(0.66, 0.5)).map(|(_, k)| k), Some(0));
        assert_eq!(aim.sample(Vec2::new(0.67, 0.5)).map(|(_, k)| k), Some(1));
        // Marked as solved through, the glass drops to half as well: weights 1/2 and 1/2,
        // the share still SHARE, split evenly; alone, half of SHARE.
        c.mark_solved(|instance| instance == 3);
        let alone = Casters {
            list: vec![c.list[0]],
        };
        assert_eq!(alone.at(Vec3::ZERO, up).share(), SHARE * HALF_FOCUS);
        let aim = c.at(Vec3::ZERO, up);
        assert_eq!(aim.share(), SHARE);
        assert_eq!(aim.sample(Vec2::new(0.49, 0.5)).map(|(_, k)| k), Some(0));
        assert_eq!(aim.sample(Vec2::new(0.51, 0.5)).map(|(_, k)| k), Some(1));
        // Marking again with nothing solved gives the glass back its focus; a mirror (never
        // a lens) keeps its half whatever it is marked.
        c.mark_solved(|_| false);
        assert_eq!(c.at(Vec3::ZERO, up).share(), SHARE);
        c.mark_solved(|instance| instance == 7);
        assert_eq!(c.at(Vec3::ZERO, up).share(), SHARE);
    }

    #[test]
    fn picks_follow_the_weights() {
        // Weights 1 (sin^2 = 4/9) and 1/4 (sin^2 = 1/16): picked 4/5 and 1/5 of the time over
        // an even grid of u.x.
        let c = casters(&[
            (Vec3::new(0.0, 1.5, 0.0), 1.0),
            (Vec3::new(4.0, 1.0, 0.0), 1.0),
        ]);
        let aim = c.at(Vec3::new(0.0, 0.0, 0.0), Vec3::Y);
        let n = 10_000;
        let mut picks = [0usize; 2];
        for i in 0..n {
            let (_, k) = aim
                .sample(Vec2::new((i as f32 + 0.5) / n as f32, 0.3))
                .unwrap();
            picks[k] += 1;
        }
        let w2 = (1.0 / 17.0) / NEAR; // sin^2 from sqrt(17) away
        let expected = 1.0 / (1.0 + w2);
        assert!(
            (picks[0] as f32 / n as f32 - expected).abs() < 2e-4,
            "{picks:?}"
        );
    }

    #[test]
    fn the_mixture_density_integrates_to_one() {
        // Over the whole sphere of directions, by the midpoint rule on a 1024 x 2048 grid in
        // (cos theta, phi) (equal-area cells of 4 pi / N). A near cone, a far one, one half
        // below the horizon and the cosine lobe: each part integrates to one, so the mixture
        // does. The cones' edges cut cells, which costs at most about 1e-3 here.
        let c = casters(&[
            (Vec3::new(0.0, 1.5, 0.0), 1.0),
            (Vec3::new(3.0, 2.0, 1.0), 0.7),
            (Vec3::new(-3.0, 0.0, 0.0), 1.0),
        ]);
        let n = Vec3::Y;
        let aim = c.at(Vec3::ZERO, n);
        assert!(aim.share() > 0.0);
        let (rows, cols) = (1024, 2048);
        let mut sum = 0.0f64;
        for i in 0..rows {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / rows as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            for j in 0..cols {
                let phi = 2.0 * PI * (j as f32 + 0.5) / cols as f32;
                // The cosine lobe about n = +y.
                let w = Vec3::new(r * phi.cos(), z, r * phi.sin());
                let p_cos = w.y.max(0.0) / PI;
                sum += aim.mixture_pdf(w, p_cos, None) as f64;
            }
        }
        let integral = sum * 4.0 * PI as f64 / (rows * cols) as f64;
        assert!((integral - 1.0).abs() < 3e-3, "{integral}");
    }

    proptest! {
        #[test]
        fn aimed_directions_lie_in_their_cone_with_a_density_at_least_their_own(
            x in -3.0f32..3.0,
            z in -3.0f32..3.0,
            ux in 0.0f32..1.0,
            uy in 0.0f32..1.0,
        ) {
            let c = casters(&[(Vec3::new(0.0, 2.0, 0.0), 1.0), (Vec3::new(2.0, 0.6, 1.0), 0.5)]);
            let p = Vec3::new(x, 0.0, z);
            let aim = c.at(p, Vec3::Y);
            let Some((w, k)) = aim.sample(Vec2::new(ux, uy)) else {
                return Ok(());
            };
            prop_assert!((w.length() - 1.0).abs() < 1e-5);
            let slot = aim.slots[k];
            let cone = slot.cone();
            prop_assert!(w.dot(cone.axis) >= 1.0 - cone.one_minus_cos_max - 1e-5, "{w} {cone:?}");
            let own = aim.share() * slot.weight / aim.total * slot.pdf();
            let pdf = aim.mixture_pdf(w, w.y.max(0.0) / PI, Some(k));
            prop_assert!(pdf.is_finite() && pdf >= own * (1.0 - 1e-5), "{pdf} < {own}");
        }
    }
}
