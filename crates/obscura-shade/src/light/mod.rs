//! Lights: point, distant, area (any emissive shape) and environment.

use crate::distribution::{Distribution1D, Distribution2D};
use crate::error::{ShadeError, check_non_negative};
use core::f32::consts::{PI, TAU};
use glam::{Mat3, Mat4, Vec2, Vec3};
use obscura_accel::{Placement, Shape};
use obscura_sample::{square_to_uniform_sphere, uniform_sphere_pdf};
use obscura_space::{Object, Transform, World};

/// Linear-RGB luminance (Rec. 709 primaries), the weight for importance sampling.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Cosines and pdfs below this are treated as zero (the sample is dropped, not divided by).
const TINY: f32 = 1e-9;

/// A light sample seen from a reference point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Unit world direction from the reference point towards the light.
    pub wi: Vec3,
    /// Radiance arriving along `wi` (for delta lights: the irradiance on a surface facing them).
    pub radiance: Vec3,
    /// Density in solid angle; 1 for delta lights (see `delta`).
    pub pdf: f32,
    /// The sampled point on the light, for the shadow ray; `None` for lights at infinity.
    pub p_light: Option<Vec3>,
    /// True for point and distant lights: they cannot be hit by BSDF sampling, so no MIS.
    pub delta: bool,
}

/// A light source. Build with the constructors, which validate.
#[derive(Debug, Clone)]
pub enum Light {
    /// An isotropic point light.
    Point {
        /// World position.
        position: Vec3,
        /// Radiant intensity in W/sr per channel: irradiance at distance `r` facing it is `intensity / r^2`.
        intensity: Vec3,
    },
    /// A directional light at infinity.
    Distant {
        /// Unit direction the light travels in.
        direction: Vec3,
        /// Irradiance on a surface facing the light.
        irradiance: Vec3,
    },
    /// An emissive shape.
    Area(AreaLight),
    /// Light arriving from infinitely far in every direction.
    Environment(EnvironmentLight),
}

impl Light {
    /// A point light; errors on non-finite or negative values.
    pub fn point(position: Vec3, intensity: Vec3) -> Result<Light, ShadeError> {
        if !position.is_finite() {
            return Err(ShadeError::NotFinite {
                parameter: "position",
            });
        }
        check_non_negative(intensity, "intensity")?;
        Ok(Light::Point {
            position,
            intensity,
        })
    }

    /// A distant light travelling along `direction` (normalised here; must not be zero).
    pub fn distant(direction: Vec3, irradiance: Vec3) -> Result<Light, ShadeError> {
        if !direction.is_finite() {
            return Err(ShadeError::NotFinite {
                parameter: "direction",
            });
        }
        let direction = direction.try_normalize().ok_or(ShadeError::OutOfRange {
            parameter: "direction",
            expected: "a non-zero vector",
        })?;
        check_non_negative(irradiance, "irradiance")?;
        Ok(Light::Distant {
            direction,
            irradiance,
        })
    }

    /// True for lights that BSDF sampling cannot hit (point, distant).
    pub fn is_delta(&self) -> bool {
        matches!(self, Light::Point { .. } | Light::Distant { .. })
    }

    /// Samples incident light at world point `p_ref` at instant `time` from canonical `u2`.
    /// `None` when this sample carries nothing (e.g. the back of an area light).
    pub fn sample_li(&self, p_ref: Vec3, time: f32, u2: Vec2) -> Option<LightSample> {
        match self {
            Light::Point {
                position,
                intensity,
            } => {
                let to_light = *position - p_ref;
                let d2 = to_light.length_squared();
                if d2 <= TINY {
                    return None;
                }
                Some(LightSample {
                    wi: to_light / d2.sqrt(),
                    radiance: *intensity / d2,
                    pdf: 1.0,
                    p_light: Some(*position),
                    delta: true,
                })
            }
            Light::Distant {
                direction,
                irradiance,
            } => Some(LightSample {
                wi: -*direction,
                radiance: *irradiance,
                pdf: 1.0,
                p_light: None,
                delta: true,
            }),
            Light::Area(area) => area.sample_li(p_ref, time, u2),
            Light::Environment(env) => env.sample_li(u2),
        }
    }
}

/// How an emitter's object space sits in the world: at one pose or moving.
#[derive(Debug, Clone)]
enum Pose {
    Static(Transform<World, Object>),
    Moving(obscura_space::AnimatedTransform<World, Object>),
}

impl Pose {
    fn at(&self, time: f32) -> Transform<World, Object> {
        match self {
            Pose::Static(t) => *t,
            Pose::Moving(a) => a.at(time),
        }
    }
}

/// The shape of an emitter in its object space.
#[derive(Debug, Clone)]
enum EmitterShape {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    Quad {
        origin: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
    },
    /// Triangles with a distribution proportional to their object-space areas.
    Triangles {
        triangles: Vec<[Vec3; 3]>,
        by_area: Distribution1D,
    },
}

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
    shape: EmitterShape,
    /// Boxed: transforms are large, and [`Light`]'s variants should stay close in size.
    pose: Box<Pose>,
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
        let shape = match shape {
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
                EmitterShape::Sphere {
                    center: *center,
                    radius: *radius,
                }
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
                EmitterShape::Quad {
                    origin: *origin,
                    edge_u: *edge_u,
                    edge_v: *edge_v,
                }
            }
            Shape::Mesh(mesh) => {
                let positions = mesh.positions();
                let mut triangles = Vec::with_capacity(mesh.triangles().len());
                for (i, tri) in mesh.triangles().iter().enumerate() {
                    let mut corners = [Vec3::ZERO; 3];
                    for (c, &index) in corners.iter_mut().zip(tri) {
                        *c =
                            *positions
                                .get(index as usize)
                                .ok_or_else(|| ShadeError::BadIndex {
                                    what: format!("mesh triangle {i} vertex index"),
                                    index,
                                    count: positions.len(),
                                })?;
                    }
                    triangles.push(corners);
                }
                let areas: Vec<f32> = triangles
                    .iter()
                    .map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length())
                    .collect();
                EmitterShape::Triangles {
                    triangles,
                    by_area: Distribution1D::new(&areas),
                }
            }
        };
        let pose = Box::new(match placement {
            Placement::Static(t) => Pose::Static(*t),
            Placement::Moving(a) => Pose::Moving(a.clone()),
        });
        Ok(AreaLight {
            instance,
            emission,
            shape,
            pose,
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

    /// Samples a direction from `p_ref` towards this light at `time`.
    pub fn sample_li(&self, p_ref: Vec3, time: f32, u2: Vec2) -> Option<LightSample> {
        let world_from_object = self.pose.at(time);
        // Spheres that stay spheres: sample the cone they subtend.
        if let EmitterShape::Sphere { center, radius } = self.shape
            && let Some((c_world, r_world)) = world_sphere(&world_from_object, center, radius)
        {
            return self.sample_cone(p_ref, c_world, r_world, u2);
        }
        // Everything else: a point by area, converted to solid angle.
        let s = self.sample_area(&world_from_object, u2)?;
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
        let world_from_object = self.pose.at(time);
        if let EmitterShape::Sphere { center, radius } = self.shape
            && let Some((c_world, r_world)) = world_sphere(&world_from_object, center, radius)
        {
            let d2 = (c_world - p_ref).length_squared();
            let r2 = r_world * r_world;
            if d2 > r2 {
                return cone_pdf(r2 / d2);
            }
            // Inside the sphere: sampled by area (and nothing is emitted inwards).
            return area_to_solid_angle(1.0 / (4.0 * PI * r2), p_ref, p_light, n_light);
        }
        let pdf_area = self.pdf_area(&world_from_object, p_light, primitive);
        area_to_solid_angle(pdf_area, p_ref, p_light, n_light)
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
        let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
        let one_minus_cos_max = sin2_max / (1.0 + cos_max);
        let sin2_theta = u2.x * one_minus_cos_max * (2.0 - u2.x * one_minus_cos_max);
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

    /// A point uniform by world area on shapes other than cone-sampled spheres.
    fn sample_area(
        &self,
        world_from_object: &Transform<World, Object>,
        u2: Vec2,
    ) -> Option<SurfacePoint> {
        let m = world_from_object.matrix();
        let normal_matrix = normal_matrix(world_from_object);
        let orientation = orientation_sign(&m);
        match &self.shape {
            EmitterShape::Sphere { center, radius } => {
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
            EmitterShape::Quad {
                origin,
                edge_u,
                edge_v,
            } => {
                let o = m.transform_point3(*origin);
                let eu = m.transform_vector3(*edge_u);
                let ev = m.transform_vector3(*edge_v);
                let cross = eu.cross(ev);
                let area = cross.length();
                if area <= TINY {
                    return None;
                }
                Some(SurfacePoint {
                    p: o + u2.x * eu + u2.y * ev,
                    n: orientation * cross / area,
                    pdf_area: 1.0 / area,
                })
            }
            EmitterShape::Triangles { triangles, by_area } => {
                let (i, p_triangle, u_remapped) = by_area.sample_discrete(u2.x);
                let [a, b, c] = triangles[i].map(|v| m.transform_point3(v));
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
            EmitterShape::Sphere { center, radius } => {
                let p_object = world_from_object.inverse_matrix().transform_point3(p_light);
                let Some(n_object) = (p_object - *center).try_normalize() else {
                    return 0.0;
                };
                let n_mapped = normal_matrix(world_from_object) * n_object;
                let jacobian = Mat3::from_mat4(m).determinant().abs() * n_mapped.length();
                1.0 / (4.0 * PI * radius * radius * jacobian)
            }
            EmitterShape::Quad { edge_u, edge_v, .. } => {
                let area = m
                    .transform_vector3(*edge_u)
                    .cross(m.transform_vector3(*edge_v))
                    .length();
                if area <= TINY { 0.0 } else { 1.0 / area }
            }
            EmitterShape::Triangles { triangles, by_area } => {
                let Some(tri) = triangles.get(primitive as usize) else {
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

/// The density of uniform cone sampling, `1 / (2 pi (1 - cos_max))`, from `sin^2` of the
/// half-angle, computed without cancellation for small cones.
fn cone_pdf(sin2_max: f32) -> f32 {
    let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
    let one_minus_cos_max = sin2_max / (1.0 + cos_max);
    1.0 / (TAU * one_minus_cos_max)
}

/// Converts an area density at `p_light` (normal `n_light`) to solid angle seen from `p_ref`.
fn area_to_solid_angle(pdf_area: f32, p_ref: Vec3, p_light: Vec3, n_light: Vec3) -> f32 {
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
fn world_sphere(
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
fn normal_matrix(world_from_object: &Transform<World, Object>) -> Mat3 {
    Mat3::from_mat4(world_from_object.inverse_matrix()).transpose()
}

/// `+1` for orientation-preserving maps, `-1` for mirroring ones: `(Ma) x (Mb) = det(M) M^-T (a x b)`,
/// so cross products of mapped edges point against the (inverse-transpose) normal when `det < 0`.
fn orientation_sign(m: &Mat4) -> f32 {
    if Mat3::from_mat4(*m).determinant() < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// Light from every direction at infinity: a constant radiance or an equirectangular map.
#[derive(Debug, Clone)]
pub struct EnvironmentLight {
    kind: EnvironmentKind,
}

#[derive(Debug, Clone)]
enum EnvironmentKind {
    Constant(Vec3),
    Map(Box<EnvironmentMap>),
}

#[derive(Debug, Clone)]
struct EnvironmentMap {
    width: u32,
    height: u32,
    texels: Vec<Vec3>,
    distribution: Distribution2D,
    world_from_light: Mat3,
    light_from_world: Mat3,
}

impl EnvironmentLight {
    /// A uniform environment of the given radiance.
    pub fn constant(radiance: Vec3) -> Result<EnvironmentLight, ShadeError> {
        check_non_negative(radiance, "radiance")?;
        Ok(EnvironmentLight {
            kind: EnvironmentKind::Constant(radiance),
        })
    }

    /// An equirectangular map of `width x height` linear-RGB texels, row 0 at the top
    /// (`+y` of the light's frame), with the light's frame placed in the world by the rotation
    /// `world_from_light` (its translation is ignored; its linear part must be orthonormal).
    pub fn from_texels(
        width: u32,
        height: u32,
        texels: Vec<Vec3>,
        world_from_light: Mat4,
    ) -> Result<EnvironmentLight, ShadeError> {
        if width == 0 || height == 0 {
            return Err(ShadeError::OutOfRange {
                parameter: "environment map size",
                expected: "at least 1 x 1",
            });
        }
        let expected = u64::from(width) * u64::from(height);
        if texels.len() as u64 != expected {
            return Err(ShadeError::TexelCount {
                expected,
                actual: texels.len(),
            });
        }
        for t in &texels {
            check_non_negative(*t, "environment map texel")?;
        }
        if !world_from_light.is_finite() {
            return Err(ShadeError::NotFinite {
                parameter: "environment transform",
            });
        }
        let rotation = Mat3::from_mat4(world_from_light);
        let gram = rotation.transpose() * rotation;
        if !gram.abs_diff_eq(Mat3::IDENTITY, 1e-3) {
            return Err(ShadeError::OutOfRange {
                parameter: "environment transform",
                expected: "a rotation (orthonormal linear part)",
            });
        }
        // Weights: luminance times sin(theta) at the row's centre (rows near the poles cover
        // less solid angle).
        let (w, h) = (width as usize, height as usize);
        let mut weights = Vec::with_capacity(w * h);
        for y in 0..h {
            let sin_theta = (PI * (y as f32 + 0.5) / h as f32).sin();
            for x in 0..w {
                weights.push(luminance(texels[y * w + x]) * sin_theta);
            }
        }
        let distribution = Distribution2D::new(&weights, w, h);
        Ok(EnvironmentLight {
            kind: EnvironmentKind::Map(Box::new(EnvironmentMap {
                width,
                height,
                texels,
                distribution,
                world_from_light: rotation,
                light_from_world: rotation.transpose(),
            })),
        })
    }

    /// The radiance arriving from world direction `d_world` (unit), i.e. seen looking along it.
    pub fn radiance(&self, d_world: Vec3) -> Vec3 {
        match &self.kind {
            EnvironmentKind::Constant(l) => *l,
            EnvironmentKind::Map(map) => {
                let uv = direction_to_uv(map.light_from_world * d_world);
                map.texel(uv)
            }
        }
    }

    /// Samples a direction (by luminance for maps, uniformly for a constant).
    pub fn sample_li(&self, u2: Vec2) -> Option<LightSample> {
        match &self.kind {
            EnvironmentKind::Constant(l) => Some(LightSample {
                wi: square_to_uniform_sphere(u2),
                radiance: *l,
                pdf: uniform_sphere_pdf(),
                p_light: None,
                delta: false,
            }),
            EnvironmentKind::Map(map) => {
                let (uv, pdf_uv) = map.distribution.sample(u2);
                let sin_theta = (PI * uv.y).sin();
                if pdf_uv <= 0.0 || sin_theta <= TINY {
                    return None;
                }
                let d_light = uv_to_direction(uv);
                Some(LightSample {
                    wi: (map.world_from_light * d_light).normalize(),
                    radiance: map.texel(uv),
                    pdf: pdf_uv / (2.0 * PI * PI * sin_theta),
                    p_light: None,
                    delta: false,
                })
            }
        }
    }

    /// The solid-angle density with which [`EnvironmentLight::sample_li`] returns `d_world`.
    pub fn pdf_li(&self, d_world: Vec3) -> f32 {
        match &self.kind {
            EnvironmentKind::Constant(_) => uniform_sphere_pdf(),
            EnvironmentKind::Map(map) => {
                let d_light = map.light_from_world * d_world;
                let uv = direction_to_uv(d_light);
                // sin(theta) from the direction itself: well conditioned at the poles, where
                // going through acos would lose most digits.
                let sin_theta = Vec2::new(d_light.x, d_light.z).length() / d_light.length();
                if sin_theta <= TINY {
                    return 0.0;
                }
                map.distribution.pdf(uv) / (2.0 * PI * PI * sin_theta)
            }
        }
    }
}

impl EnvironmentMap {
    /// The texel holding map coordinates `uv` in `[0, 1]^2` (nearest, no filtering: the
    /// radiance is piecewise constant exactly like the sampling density).
    fn texel(&self, uv: Vec2) -> Vec3 {
        let x = ((uv.x * self.width as f32) as u32).min(self.width - 1);
        let y = ((uv.y * self.height as f32) as u32).min(self.height - 1);
        self.texels[(y * self.width + x) as usize]
    }
}

/// Map coordinates of a unit direction in the light's frame: `u = phi / 2pi + 1/2` with
/// `phi = atan2(x, z)` from +z towards +x, `v = theta / pi` with `theta` from +y (the
/// environment camera's mapping).
pub fn direction_to_uv(d_light: Vec3) -> Vec2 {
    // atan2 rather than acos(y): accurate near the poles too.
    let theta = Vec2::new(d_light.x, d_light.z).length().atan2(d_light.y);
    let phi = d_light.x.atan2(d_light.z);
    let u = (phi / TAU + 0.5).clamp(0.0, 1.0);
    let v = (theta / PI).clamp(0.0, 1.0);
    Vec2::new(u, v)
}

/// The inverse of [`direction_to_uv`]: `d = (sin theta sin phi, cos theta, sin theta cos phi)`
/// with `theta = pi v`, `phi = 2 pi (u - 1/2)`.
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let theta = PI * uv.y;
    let phi = TAU * (uv.x - 0.5);
    let (sin_theta, cos_theta) = theta.sin_cos();
    let (sin_phi, cos_phi) = phi.sin_cos();
    Vec3::new(sin_theta * sin_phi, cos_theta, sin_theta * cos_phi)
}
