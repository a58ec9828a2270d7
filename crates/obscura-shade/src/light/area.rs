//! The area light: any emissive shape of obscura-accel, at its instance's placement.

use super::solid_angle::{
    area_to_solid_angle, cone_pdf, cone_sin2, normal_matrix, one_minus_cos, orientation_sign,
    world_sphere,
};
use super::{LightSample, TINY};
use crate::error::{ShadeError, check_non_negative};
use core::f32::consts::{PI, TAU};
use glam::{Mat3, Vec2, Vec3};
use obscura_accel::{Placement, Shape, TriangleMesh};
use obscura_sample::Distribution1D;
use obscura_sample::square_to_uniform_sphere;
use obscura_space::{Object, Transform, World};

/// An emissive shape: emits `emission` (radiance) on the side its geometric normal faces.
///
/// Sampling: spheres by the solid angle of the cone they subtend (when their placement is a
/// similarity; an ellipsoid falls back to area sampling with the exact area Jacobian), quads
/// by area, meshes by choosing a triangle by object-space area, then a uniform point on it in
/// world space. Pdfs are converted to solid angle. A moving emitter is evaluated at the
/// reference point's time.
#[derive(Debug, Clone)]
pub struct AreaLight {
    instance: u32,
    emission: Vec3,
    shape: Shape,
    /// For a mesh: its triangles chosen in proportion to their object-space areas.
    by_area: Option<Distribution1D>,
    /// Boxed: transforms are large, and [`Light`](super::Light)'s variants should stay close
    /// in size.
    placement: Box<Placement>,
    /// A quad or sphere that does not move, placed in world space once for all its samples
    /// (every light sample would otherwise carry it there again: a quad's corner, edges and
    /// area, a sphere's centre and radius after checking that its placement is a similarity).
    fixed: Option<Box<Placed>>,
}

/// An emitter that does not move, placed in world space when the light is made.
#[derive(Debug, Clone)]
enum Placed {
    Quad(WorldQuad),
    /// A sphere placed by a similarity, sampled by the cone it subtends.
    Sphere {
        center: Vec3,
        radius: f32,
    },
}

/// A quad in world space: what sampling it by area and its density need.
#[derive(Debug, Clone)]
struct WorldQuad {
    origin: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    /// The unit normal on the emitting side.
    n: Vec3,
    /// One over the area; `None` for a quad too small to sample.
    pdf_area: Option<f32>,
}

impl WorldQuad {
    /// The quad placed by `world_from_object`: kept by a light that does not move, made at
    /// each sample by one that does.
    fn new(
        world_from_object: &Transform<World, Object>,
        origin: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
    ) -> WorldQuad {
        let m = world_from_object.matrix();
        let orientation = orientation_sign(&m);
        let eu = m.transform_vector3(edge_u);
        let ev = m.transform_vector3(edge_v);
        let cross = eu.cross(ev);
        let area = cross.length();
        WorldQuad {
            origin: m.transform_point3(origin),
            edge_u: eu,
            edge_v: ev,
            n: orientation * cross / area,
            pdf_area: (area > TINY).then(|| 1.0 / area),
        }
    }

    /// The point at `u2` in edge coordinates.
    fn sample(&self, u2: Vec2) -> Option<SurfacePoint> {
        Some(SurfacePoint {
            p: self.origin + u2.x * self.edge_u + u2.y * self.edge_v,
            n: self.n,
            pdf_area: self.pdf_area?,
        })
    }
}

/// A point sampled on an emitter's surface, with its unit outward normal and area density.
struct SurfacePoint {
    p: Vec3,
    n: Vec3,
    pdf_area: f32,
}

impl AreaLight {
    /// An area light for instance `instance` of the geometry, with the accelerator's shape and
    /// placement. Errors on a non-finite or negative emission.
    pub fn new(
        shape: &Shape,
        placement: &Placement,
        emission: Vec3,
        instance: u32,
    ) -> Result<AreaLight, ShadeError> {
        check_non_negative(emission, "emission")?;
        let by_area = match shape {
            Shape::Sphere { center, radius } => {
                if !center.is_finite() || !radius.is_finite() {
                    return Err(ShadeError::NotFinite {
                        parameter: "emissive sphere",
                    });
                }
                if *radius <= 0.0 {
                    return Err(ShadeError::OutOfRange {
                        parameter: "emissive sphere radius",
                        expected: "greater than 0",
                    });
                }
                None
            }
            Shape::Quad {
                origin,
                edge_u,
                edge_v,
            } => {
                if !(origin.is_finite() && edge_u.is_finite() && edge_v.is_finite()) {
                    return Err(ShadeError::NotFinite {
                        parameter: "emissive quad",
                    });
                }
                if edge_u.cross(*edge_v).length_squared() <= 0.0 {
                    return Err(ShadeError::OutOfRange {
                        parameter: "emissive quad edges",
                        expected: "non-parallel and non-zero (the quad needs an area)",
                    });
                }
                None
            }
            Shape::Mesh(mesh) => {
                // A `TriangleMesh` holds only indices in range (checked when it was made).
                let areas: Vec<f32> = (0..mesh.triangle_count())
                    .filter_map(|i| corners(mesh, i))
                    .map(|[a, b, c]| 0.5 * (b - a).cross(c - a).length())
                    .collect();
                Some(Distribution1D::new(&areas))
            }
        };
        let fixed = match placement {
            Placement::Static(world_from_object) => place(shape, world_from_object),
            Placement::Moving(_) => None,
        };
        Ok(AreaLight {
            instance,
            emission,
            shape: shape.clone(),
            by_area,
            placement: Box::new(placement.clone()),
            fixed: fixed.map(Box::new),
        })
    }

    /// The geometry instance this light belongs to.
    pub fn instance(&self) -> u32 {
        self.instance
    }

    /// The emitted radiance.
    pub fn emission(&self) -> Vec3 {
        self.emission
    }

    /// Radiance leaving a point with geometric normal `n_geometric` towards `w` (world, unit):
    /// the emission on the front side, zero behind.
    pub fn emitted(&self, n_geometric: Vec3, w: Vec3) -> Vec3 {
        if n_geometric.dot(w) > 0.0 {
            self.emission
        } else {
            Vec3::ZERO
        }
    }

    /// Whether this light is a static quad, whose samples are points by area whatever the
    /// reference point: the light that vertices solve paths through glass balls to.
    #[inline]
    pub(crate) fn is_fixed_quad(&self) -> bool {
        matches!(self.fixed.as_deref(), Some(Placed::Quad(_)))
    }

    /// For a static quad, the point [`AreaLight::sample_li`] picks with `u2`: the point, the
    /// unit normal on the emitting side and the density per unit area.
    #[inline]
    pub(crate) fn fixed_quad_point(&self, u2: Vec2) -> Option<(Vec3, Vec3, f32)> {
        match self.fixed.as_deref() {
            Some(Placed::Quad(quad)) => quad.sample(u2).map(|s| (s.p, s.n, s.pdf_area)),
            _ => None,
        }
    }

    /// For a static quad, its density per unit area (one over its area).
    #[inline]
    pub(crate) fn fixed_quad_pdf(&self) -> Option<f32> {
        match self.fixed.as_deref() {
            Some(Placed::Quad(quad)) => quad.pdf_area,
            _ => None,
        }
    }

    /// Samples a direction from `p_ref` towards this light at `time`.
    pub fn sample_li(&self, p_ref: Vec3, time: f32, u2: Vec2) -> Option<LightSample> {
        // Quads, ellipsoids and meshes: a point by area, converted to solid angle; spheres
        // that stay spheres: the cone they subtend.
        let made;
        let placed = match self.fixed.as_deref() {
            Some(placed) => placed,
            None => {
                let world_from_object = self.placement.at(time);
                made = place(&self.shape, &world_from_object);
                match &made {
                    Some(placed) => placed,
                    None => {
                        return self.seen_from(p_ref, self.sample_area(&world_from_object, u2)?);
                    }
                }
            }
        };
        let s = match *placed {
            Placed::Quad(ref quad) => quad.sample(u2)?,
            Placed::Sphere { center, radius } => {
                return self.sample_cone(p_ref, center, radius, u2);
            }
        };
        self.seen_from(p_ref, s)
    }

    /// The light sample of the surface point `s`, seen from `p_ref`: its area density turned
    /// into solid angle; `None` when `p_ref` is on it or sees it edge on or from behind.
    fn seen_from(&self, p_ref: Vec3, s: SurfacePoint) -> Option<LightSample> {
        let to_light = s.p - p_ref;
        let d2 = to_light.length_squared();
        if d2 <= TINY {
            return None;
        }
        let wi = to_light / d2.sqrt();
        let cos_light = s.n.dot(-wi);
        if cos_light <= TINY {
            return None;
        }
        let pdf = s.pdf_area * d2 / cos_light;
        if !pdf.is_finite() || pdf <= 0.0 {
            return None;
        }
        Some(LightSample {
            wi,
            radiance: self.emission,
            pdf,
            p_light: Some(s.p),
            delta: false,
        })
    }

    /// The solid-angle density with which [`AreaLight::sample_li`] from `p_ref` picks the point
    /// `p_light` (on this light, geometric normal `n_light`, on triangle `primitive` for meshes)
    /// at `time`.
    pub fn pdf_li(
        &self,
        p_ref: Vec3,
        p_light: Vec3,
        n_light: Vec3,
        primitive: u32,
        time: f32,
    ) -> f32 {
        let made;
        let placed = match self.fixed.as_deref() {
            Some(placed) => placed,
            None => {
                let world_from_object = self.placement.at(time);
                made = place(&self.shape, &world_from_object);
                match &made {
                    Some(placed) => placed,
                    None => {
                        let pdf_area = self.pdf_area(&world_from_object, p_light, primitive);
                        return area_to_solid_angle(pdf_area, p_ref, p_light, n_light);
                    }
                }
            }
        };
        match *placed {
            Placed::Quad(ref quad) => {
                area_to_solid_angle(quad.pdf_area.unwrap_or(0.0), p_ref, p_light, n_light)
            }
            Placed::Sphere { center, radius } => {
                sphere_pdf(center, radius, p_ref, p_light, n_light)
            }
        }
    }

    /// Cone sampling of a world-space sphere (pbrt's method), from outside it.
    fn sample_cone(&self, p_ref: Vec3, c: Vec3, r: f32, u2: Vec2) -> Option<LightSample> {
        let to_center = c - p_ref;
        let dc2 = to_center.length_squared();
        let r2 = r * r;
        if dc2 <= r2 * (1.0 + 1e-5) {
            // Inside (or on) an outward-emitting sphere: it sends nothing here.
            return None;
        }
        let dc = dc2.sqrt();
        let w_c = to_center / dc;
        // Sample cos(theta) uniformly in [cos_max, 1]; small cones via sin^2 to keep precision.
        let sin2_max = r2 / dc2;
        let sin2_theta = cone_sin2(u2.x, one_minus_cos(sin2_max));
        let cos_theta = (1.0 - sin2_theta).max(0.0).sqrt();
        // The point on the sphere seen at that angle: the nearer intersection of the ray.
        let ds = dc * cos_theta - (r2 - dc2 * sin2_theta).max(0.0).sqrt();
        let cos_alpha = ((dc2 + r2 - ds * ds) / (2.0 * dc * r)).clamp(-1.0, 1.0);
        let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
        let phi = TAU * u2.y;
        let frame = crate::frame::Frame::from_normal(-w_c);
        let n_light = frame.from_local(Vec3::new(
            sin_alpha * phi.cos(),
            sin_alpha * phi.sin(),
            cos_alpha,
        ));
        let p_light = c + r * n_light;
        let wi = (p_light - p_ref).try_normalize()?;
        let pdf = cone_pdf(sin2_max);
        if !pdf.is_finite() {
            return None;
        }
        Some(LightSample {
            wi,
            radiance: self.emission,
            pdf,
            p_light: Some(p_light),
            delta: false,
        })
    }

    /// A point uniform by world area on the shapes [`place`] does not place: ellipsoids and
    /// meshes (a quad is sampled as placed, never here).
    fn sample_area(
        &self,
        world_from_object: &Transform<World, Object>,
        u2: Vec2,
    ) -> Option<SurfacePoint> {
        let m = world_from_object.matrix();
        let normal_matrix = normal_matrix(world_from_object);
        let orientation = orientation_sign(&m);
        match &self.shape {
            Shape::Sphere { center, radius } => {
                // An ellipsoid: uniform on the object sphere, divided by the area Jacobian.
                let n_object = square_to_uniform_sphere(u2);
                let p = m.transform_point3(*center + *radius * n_object);
                let n_mapped = normal_matrix * n_object;
                let jacobian = Mat3::from_mat4(m).determinant().abs() * n_mapped.length();
                let pdf_area = 1.0 / (4.0 * PI * radius * radius * jacobian);
                Some(SurfacePoint {
                    p,
                    n: n_mapped.try_normalize()?,
                    pdf_area,
                })
            }
            Shape::Quad { .. } => None,
            Shape::Mesh(mesh) => {
                let by_area = self.by_area.as_ref()?;
                let (i, p_triangle, u_remapped) = by_area.sample_discrete(u2.x);
                let [a, b, c] = corners(mesh, i)?.map(|v| m.transform_point3(v));
                let cross = (b - a).cross(c - a);
                let area = 0.5 * cross.length();
                if area <= TINY {
                    return None;
                }
                // Uniform barycentrics by the square-root warp.
                let su = u_remapped.sqrt();
                let (b0, b1) = (1.0 - su, u2.y * su);
                Some(SurfacePoint {
                    p: b0 * a + b1 * b + (1.0 - b0 - b1) * c,
                    n: orientation * cross / (2.0 * area),
                    pdf_area: p_triangle / area,
                })
            }
        }
    }

    /// The area density of [`AreaLight::sample_area`] at a world point on this light.
    fn pdf_area(
        &self,
        world_from_object: &Transform<World, Object>,
        p_light: Vec3,
        primitive: u32,
    ) -> f32 {
        let m = world_from_object.matrix();
        match &self.shape {
            Shape::Sphere { center, radius } => {
                let p_object = world_from_object.inverse_matrix().transform_point3(p_light);
                let Some(n_object) = (p_object - *center).try_normalize() else {
                    return 0.0;
                };
                let n_mapped = normal_matrix(world_from_object) * n_object;
                let jacobian = Mat3::from_mat4(m).determinant().abs() * n_mapped.length();
                1.0 / (4.0 * PI * radius * radius * jacobian)
            }
            Shape::Quad { .. } => 0.0,
            Shape::Mesh(mesh) => {
                let (Some(by_area), Some(tri)) = (&self.by_area, corners(mesh, primitive as usize))
                else {
                    return 0.0;
                };
                let [a, b, c] = tri.map(|v| m.transform_point3(v));
                let area = 0.5 * (b - a).cross(c - a).length();
                if area <= TINY {
                    0.0
                } else {
                    by_area.discrete_pdf(primitive as usize) / area
                }
            }
        }
    }
}

/// The emitter `shape` placed in world space by `world_from_object`, for the shapes sampled
/// in world space: a quad (by area) and a sphere the map keeps a sphere, a similarity (by its
/// cone). `None` for an ellipsoid or a mesh, which are sampled through the map
/// ([`AreaLight::sample_area`]). A static light keeps this; a moving one makes it per sample.
fn place(shape: &Shape, world_from_object: &Transform<World, Object>) -> Option<Placed> {
    match shape {
        Shape::Quad {
            origin,
            edge_u,
            edge_v,
        } => Some(Placed::Quad(WorldQuad::new(
            world_from_object,
            *origin,
            *edge_u,
            *edge_v,
        ))),
        Shape::Sphere { center, radius } => world_sphere(world_from_object, *center, *radius)
            .map(|(center, radius)| Placed::Sphere { center, radius }),
        Shape::Mesh(_) => None,
    }
}

/// The solid-angle density of a light sample from `p_ref` at `p_light` (normal `n_light`) on
/// the world-space sphere of centre `c` and radius `r`: the cone's from outside, the area
/// density from inside (where nothing is emitted inwards).
fn sphere_pdf(c: Vec3, r: f32, p_ref: Vec3, p_light: Vec3, n_light: Vec3) -> f32 {
    let d2 = (c - p_ref).length_squared();
    let r2 = r * r;
    if d2 > r2 {
        cone_pdf(r2 / d2)
    } else {
        area_to_solid_angle(1.0 / (4.0 * PI * r2), p_ref, p_light, n_light)
    }
}

/// The object-space corners of triangle `i` of `mesh`; `None` past the last triangle.
fn corners(mesh: &TriangleMesh, i: usize) -> Option<[Vec3; 3]> {
    let positions = mesh.positions();
    mesh.triangles()
        .get(i)
        .map(|tri| tri.map(|v| positions[v as usize]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Quat};
    use proptest::prelude::*;

    /// Scaled by `scale`, turned by the Euler angles `angles` (XYZ) and moved by `shift`.
    fn placement(scale: Vec3, angles: [f32; 3], shift: [f32; 3]) -> Transform<World, Object> {
        let m = Mat4::from_scale_rotation_translation(
            scale,
            Quat::from_euler(glam::EulerRot::XYZ, angles[0], angles[1], angles[2]),
            Vec3::from(shift),
        );
        Transform::from_matrix(m).unwrap()
    }

    proptest! {
        /// A fixed quad's world-space frame, made once, gives each sample and density the bits
        /// of the quad carried to world space at that sample, written out here as the light
        /// computed it before the frame was kept.
        #[test]
        fn a_fixed_quad_samples_as_the_quad_carried_each_time(
            angles in proptest::array::uniform3(-3.0f32..3.0),
            scale in proptest::array::uniform3(prop_oneof![-3.0f32..-0.1, 0.1f32..3.0]),
            shift in proptest::array::uniform3(-5.0f32..5.0),
            u in proptest::array::uniform2(0.0f32..1.0),
        ) {
            let world_from_object = placement(Vec3::from(scale), angles, shift);
            let (origin, edge_u, edge_v) =
                (Vec3::new(-0.4, 0.2, 1.0), Vec3::new(0.8, 0.0, 0.1), Vec3::new(0.0, 0.7, -0.2));
            let shape = Shape::Quad { origin, edge_u, edge_v };
            let light =
                AreaLight::new(&shape, &Placement::Static(world_from_object), Vec3::ONE, 0)
                    .unwrap();
            let Some(Placed::Quad(quad)) = light.fixed.as_deref() else {
                panic!("a static quad light keeps its placed quad");
            };
            let fixed = quad.sample(Vec2::from(u)).unwrap();
            let m = world_from_object.matrix();
            let (eu, ev) = (m.transform_vector3(edge_u), m.transform_vector3(edge_v));
            let cross = eu.cross(ev);
            let area = cross.length();
            let p = m.transform_point3(origin) + u[0] * eu + u[1] * ev;
            let n = orientation_sign(&m) * cross / area;
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            prop_assert_eq!(bits(fixed.p), bits(p));
            prop_assert_eq!(bits(fixed.n), bits(n));
            prop_assert_eq!(fixed.pdf_area.to_bits(), (1.0 / area).to_bits());
            let pdf = light.pdf_li(Vec3::new(0.0, 0.0, -20.0), fixed.p, fixed.n, 0, 0.0);
            let each = area_to_solid_angle(1.0 / area, Vec3::new(0.0, 0.0, -20.0), p, n);
            prop_assert_eq!(pdf.to_bits(), each.to_bits());
        }
    }

    proptest! {
        /// A fixed sphere, placed once, samples and weighs as the sphere placed at the sample:
        /// the centre carried to world space and the radius times the map's scale (written out
        /// here as `world_sphere` computes them), then the cone from `p_ref`, to the bit.
        #[test]
        fn a_fixed_sphere_samples_as_the_sphere_placed_each_time(
            angles in proptest::array::uniform3(-3.0f32..3.0),
            scale in prop_oneof![-3.0f32..-0.1, 0.1f32..3.0],
            shift in proptest::array::uniform3(-5.0f32..5.0),
            p_ref in proptest::array::uniform3(-20.0f32..20.0),
            u in proptest::array::uniform2(0.0f32..1.0),
        ) {
            let world_from_object = placement(Vec3::splat(scale), angles, shift);
            let (center, radius) = (Vec3::new(0.3, -0.2, 0.5), 0.7);
            let shape = Shape::Sphere { center, radius };
            let light =
                AreaLight::new(&shape, &Placement::Static(world_from_object), Vec3::ONE, 0)
                    .unwrap();
            let placed = matches!(light.fixed.as_deref(), Some(Placed::Sphere { .. }));
            prop_assert!(placed, "a static sphere is placed once");
            let m = world_from_object.matrix();
            let c_world = m.transform_point3(center);
            let r_world = radius * Mat3::from_mat4(m).x_axis.length();
            let (p_ref, u) = (Vec3::from(p_ref), Vec2::from(u));
            let kept = light.sample_li(p_ref, 0.0, u);
            let each = light.sample_cone(p_ref, c_world, r_world, u);
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            match (kept, each) {
                (Some(a), Some(b)) => {
                    prop_assert_eq!(bits(a.wi), bits(b.wi));
                    prop_assert_eq!(a.pdf.to_bits(), b.pdf.to_bits());
                    let (pa, pb) = (a.p_light.unwrap(), b.p_light.unwrap());
                    prop_assert_eq!(bits(pa), bits(pb));
                    let n = (pa - c_world) / r_world;
                    prop_assert_eq!(
                        light.pdf_li(p_ref, pa, n, 0, 0.0).to_bits(),
                        sphere_pdf(c_world, r_world, p_ref, pa, n).to_bits()
                    );
                }
                (None, None) => {}
                (a, b) => prop_assert!(false, "kept {:?} against placed {:?}", a.is_some(), b.is_some()),
            }
        }
    }

    /// The sphere's density by hand: from 5 away, a sphere of radius 3 subtends a cone with
    /// `sin^2 = 9 / 25`, `cos = 4 / 5`, solid angle `2 pi (1 - 4/5)`, so a uniform sample's
    /// density is `1 / (0.4 pi)`; from inside, the area density `1 / (4 pi r^2)` turned into
    /// solid angle.
    #[test]
    fn sphere_pdf_by_hand() {
        let pdf = sphere_pdf(
            Vec3::ZERO,
            3.0,
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::Z * 3.0,
            Vec3::Z,
        );
        assert!((pdf - 1.0 / (0.4 * PI)).abs() < 1e-5 * pdf, "{pdf}");
        // From the centre, the point 3 away along +z seen head on: (1 / (36 pi)) * 9 / 1.
        let inside = sphere_pdf(Vec3::ZERO, 3.0, Vec3::ZERO, Vec3::Z * 3.0, Vec3::Z);
        assert!((inside - 1.0 / (4.0 * PI)).abs() < 1e-6, "{inside}");
    }

    #[test]
    fn only_static_quads_and_spheres_are_placed_once() {
        let quad = Shape::Quad {
            origin: Vec3::ZERO,
            edge_u: Vec3::X,
            edge_v: Vec3::Y,
        };
        let fixed = Placement::Static(Transform::identity());
        let light = AreaLight::new(&quad, &fixed, Vec3::ONE, 0).unwrap();
        let Some(Placed::Quad(frame)) = light.fixed.as_deref() else {
            panic!("a static quad is placed once");
        };
        assert_eq!((frame.n, frame.pdf_area), (Vec3::Z, Some(1.0)));
        let sphere = Shape::Sphere {
            center: Vec3::new(1.0, 0.0, 0.0),
            radius: 0.5,
        };
        // Scaled by 2 and moved by (0, 3, 0): centre (2, 3, 0), radius 1.
        let scale_and_move = Transform::from_matrix(Mat4::from_scale_rotation_translation(
            Vec3::splat(2.0),
            Quat::IDENTITY,
            Vec3::new(0.0, 3.0, 0.0),
        ))
        .unwrap();
        let scaled = Placement::Static(scale_and_move);
        let light = AreaLight::new(&sphere, &scaled, Vec3::ONE, 0).unwrap();
        let Some(&Placed::Sphere { center, radius }) = light.fixed.as_deref() else {
            panic!("a static sphere placed by a similarity is placed once");
        };
        assert_eq!((center, radius), (Vec3::new(2.0, 3.0, 0.0), 1.0));
        // Squashed into an ellipsoid: sampled by area at each sample, nothing kept.
        let squashed = Placement::Static(
            Transform::from_matrix(Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0))).unwrap(),
        );
        let light = AreaLight::new(&sphere, &squashed, Vec3::ONE, 0).unwrap();
        assert!(light.fixed.is_none());
        // Moving: placed at each sample's time.
        let moving = Placement::Moving(
            obscura_space::AnimatedTransform::new(Transform::identity(), 0.0, scale_and_move, 1.0)
                .unwrap(),
        );
        let light = AreaLight::new(&sphere, &moving, Vec3::ONE, 0).unwrap();
        assert!(light.fixed.is_none());
    }
}
