//! A brute-force reference, written independently of the crate: every primitive of every
//! instance, in f64, each instance placed with its transform at the ray's time.
//!
//! Floating-point answers differ near edges and at equal distances, so the reference gives two
//! sets: hits that are *robust* (inside the primitive by a margin and inside the ray's range
//! by a margin) and hits that are merely *possible* (within the margin of it). A correct
//! accelerator must report a possible hit no farther than the nearest robust one, and must
//! report nothing only when nothing is robustly hit.

use glam::{DMat4, Vec2, Vec3};
use obscura_accel::{Hit, Placement, Scene, SceneBuilder, Shape, TriangleMesh};
use obscura_space::{Object, Ray, Transform, World};
use std::sync::Arc;

/// Relative margin inside a primitive (barycentric, edge parameter, discriminant).
const MARGIN: f64 = 1e-4;

/// A scene kept alongside its description, so the reference can walk it.
pub struct TestScene {
    pub scene: Scene,
    pub instances: Vec<(Shape, Placement)>,
}

impl TestScene {
    pub fn build(instances: Vec<(Shape, Placement)>) -> TestScene {
        let mut builder = SceneBuilder::new();
        for (i, (shape, placement)) in instances.iter().enumerate() {
            let id = builder.add(shape.clone(), placement.clone()).unwrap();
            assert_eq!(id as usize, i);
        }
        TestScene {
            scene: builder.build().unwrap(),
            instances,
        }
    }
}

/// One candidate hit of the reference: the ray parameter and how far inside it is.
#[derive(Clone, Copy, Debug)]
pub struct Candidate {
    pub t: f64,
    /// How far `t` may be off in f32: relative 1e-4, more for grazing hits: a sphere's `t`
    /// moves by `delta / sqrt(margin)` for a perturbation `delta` of the ray, a triangle's by
    /// `delta / |cos|` of the angle between the ray and its normal.
    pub t_tol: f64,
    pub margin: f64,
    pub instance: u32,
    pub primitive: u32,
}

fn world_from_object_at(placement: &Placement, time: f32) -> Transform<World, Object> {
    match placement {
        Placement::Static(t) => *t,
        Placement::Moving(a) => a.at(time),
    }
}

/// Every ray-surface crossing of every primitive (inside or not), with its margin.
pub fn candidates(scene: &TestScene, ray: &Ray<World>) -> Vec<Candidate> {
    let o = ray.origin.to_glam().as_dvec3();
    let d = ray.direction.to_glam().as_dvec3();
    let mut out = Vec::new();
    for (instance, (shape, placement)) in scene.instances.iter().enumerate() {
        let instance = instance as u32;
        let m: DMat4 = world_from_object_at(placement, ray.time)
            .matrix()
            .as_dmat4();
        let m_inv = m.inverse();
        let place = |p: Vec3| m.transform_point3(p.as_dvec3());
        match shape {
            Shape::Mesh(mesh) => {
                for (i, tri) in mesh.triangles().iter().enumerate() {
                    let [p0, p1, p2] = tri.map(|v| place(mesh.positions()[v as usize]));
                    // Solve o + t d = p0 + b1 e1 + b2 e2 by Cramer's rule.
                    let (e1, e2) = (p1 - p0, p2 - p0);
                    let det = -d.dot(e1.cross(e2));
                    if det == 0.0 {
                        continue;
                    }
                    let w = o - p0;
                    let t = w.dot(e1.cross(e2)) / det;
                    let b1 = -d.dot(w.cross(e2)) / det;
                    let b2 = -d.dot(e1.cross(w)) / det;
                    let margin = b1.min(b2).min(1.0 - b1 - b2);
                    // A ray grazing the triangle's plane moves its `t` by `delta / |cos|` for a
                    // perturbation `delta` of the ray or the vertices (f32 rounding, or an
                    // instance's f32 transform): up to 100 times the tolerance at |cos| = 1e-4.
                    let cos = det.abs() / (d.length() * e1.cross(e2).length());
                    let conditioning = (0.01 / cos.max(1e-12)).clamp(1.0, 100.0);
                    out.push(Candidate {
                        t,
                        t_tol: t_tolerance(t) * conditioning,
                        margin,
                        instance,
                        primitive: i as u32,
                    });
                }
            }
            Shape::Sphere { center, radius } => {
                let (oo, dd) = (m_inv.transform_point3(o), m_inv.transform_vector3(d));
                let c = center.as_dvec3();
                let r = f64::from(*radius);
                let oc = oo - c;
                let a = dd.length_squared();
                let b = oc.dot(dd);
                let f = oc - dd * (b / a);
                let disc = r * r - f.length_squared();
                // Signed: positive when the line passes inside the sphere.
                let margin = disc / (r * r);
                let root = (a * disc.max(0.0)).sqrt();
                for t in [(-b - root) / a, (-b + root) / a] {
                    let conditioning = (0.1 / margin.max(1e-12).sqrt()).max(1.0);
                    out.push(Candidate {
                        t,
                        t_tol: t_tolerance(t) * conditioning,
                        margin,
                        instance,
                        primitive: 0,
                    });
                }
            }
            Shape::Quad {
                origin,
                edge_u,
                edge_v,
            } => {
                let p0 = place(*origin);
                let eu = m.transform_vector3(edge_u.as_dvec3());
                let ev = m.transform_vector3(edge_v.as_dvec3());
                let n = eu.cross(ev);
                let denom = n.dot(d);
                if denom == 0.0 {
                    continue;
                }
                let t = n.dot(p0 - o) / denom;
                let w = o + d * t - p0;
                let s = n.dot(w.cross(ev)) / n.length_squared();
                let v = n.dot(eu.cross(w)) / n.length_squared();
                let margin = s.min(1.0 - s).min(v).min(1.0 - v);
                out.push(Candidate {
                    t,
                    t_tol: t_tolerance(t),
                    margin,
                    instance,
                    primitive: 0,
                });
            }
        }
    }
    out
}

fn t_tolerance(t: f64) -> f64 {
    1e-4 * t.abs().max(1.0)
}

/// Hits inside by a margin, in the ray's range by a margin.
pub fn robust(ray: &Ray<World>, c: &Candidate) -> bool {
    let tol = c.t_tol;
    c.margin > MARGIN && c.t >= f64::from(ray.t_min) + tol && c.t <= f64::from(ray.t_max) - tol
}

/// Hits within the margin of the primitive and of the ray's range.
pub fn possible(ray: &Ray<World>, c: &Candidate) -> bool {
    let tol = c.t_tol;
    c.margin > -MARGIN && c.t >= f64::from(ray.t_min) - tol && c.t <= f64::from(ray.t_max) + tol
}

/// Checks the scene's closest hit and any-hit answers against the reference; `Err` says how
/// they disagree.
pub fn check_ray(scene: &TestScene, ray: &Ray<World>) -> Result<(), String> {
    let all = candidates(scene, ray);
    let (nearest_robust, nearest_tol) = all
        .iter()
        .filter(|c| robust(ray, c))
        .map(|c| (c.t, c.t_tol))
        .fold((f64::INFINITY, 0.0), |a, b| if b.0 < a.0 { b } else { a });
    let hit = scene.scene.intersect(ray);
    match &hit {
        None => {
            if nearest_robust.is_finite() {
                return Err(format!(
                    "missed, but the reference robustly hits at t = {nearest_robust} ({ray:?})"
                ));
            }
        }
        Some(h) => {
            let t = f64::from(h.t);
            let matches = all.iter().any(|c| {
                c.instance == h.instance
                    && c.primitive == h.primitive
                    && possible(ray, c)
                    && (c.t - t).abs() <= c.t_tol
            });
            if !matches {
                return Err(format!(
                    "hit instance {} primitive {} at t = {t}, which the reference does not allow ({ray:?})",
                    h.instance, h.primitive
                ));
            }
            if t > nearest_robust + nearest_tol {
                return Err(format!(
                    "hit at t = {t}, but the reference has a nearer robust hit at {nearest_robust} ({ray:?})"
                ));
            }
        }
    }
    check_preliminary(scene, ray, hit.as_ref())?;
    let any_possible = all.iter().any(|c| possible(ray, c));
    let occluded = scene.scene.occluded(ray);
    if nearest_robust.is_finite() && !occluded {
        return Err(format!(
            "occluded() is false, but the reference robustly hits ({ray:?})"
        ));
    }
    if occluded && !any_possible {
        return Err(format!(
            "occluded() is true, but the reference has no hit ({ray:?})"
        ));
    }
    if occluded != hit.is_some() && (nearest_robust.is_finite() || !any_possible) {
        return Err(format!(
            "occluded() = {occluded} disagrees with intersect() ({ray:?})"
        ));
    }
    Ok(())
}

/// `intersect_preliminary` finds the hit `intersect` returned, its ids and coordinates agree
/// with the full record, and completing it gives that record exactly.
fn check_preliminary(scene: &TestScene, ray: &Ray<World>, hit: Option<&Hit>) -> Result<(), String> {
    let found = scene.scene.intersect_preliminary(ray);
    let (hit, found) = match (hit, found) {
        (None, None) => return Ok(()),
        (Some(hit), Some(found)) => (hit, found),
        (hit, found) => {
            return Err(format!(
                "intersect() hit: {}, intersect_preliminary() hit: {} ({ray:?})",
                hit.is_some(),
                found.is_some()
            ));
        }
    };
    if (found.t(), found.instance(), found.primitive()) != (hit.t, hit.instance, hit.primitive) {
        return Err(format!(
            "preliminary t {} instance {} primitive {} against the hit's {} {} {} ({ray:?})",
            found.t(),
            found.instance(),
            found.primitive(),
            hit.t,
            hit.instance,
            hit.primitive
        ));
    }
    if found.complete() != *hit {
        return Err(format!(
            "completing the preliminary hit gave another record ({ray:?})"
        ));
    }
    // The coordinates: a quad's are the hit's uv, a triangle's are the barycentrics its
    // vertex uvs are interpolated with (or the uv itself when the mesh has none).
    let b = found.primitive_uv();
    let expected = match &scene.instances[hit.instance as usize].0 {
        Shape::Sphere { .. } => Vec2::ZERO,
        Shape::Quad { .. } => hit.uv,
        Shape::Mesh(mesh) => match mesh.uvs() {
            None => hit.uv,
            Some(uvs) => {
                let [i0, i1, i2] = mesh.triangles()[hit.primitive as usize].map(|i| i as usize);
                let (u0, u1, u2) = (uvs[i0], uvs[i1], uvs[i2]);
                if (u0 * (1.0 - b.x - b.y) + u1 * b.x + u2 * b.y - hit.uv)
                    .abs()
                    .max_element()
                    > 1e-5
                {
                    return Err(format!(
                        "barycentrics {b} do not interpolate the hit's uv {} ({ray:?})",
                        hit.uv
                    ));
                }
                return Ok(());
            }
        },
    };
    if b != expected {
        return Err(format!("primitive_uv {b}, expected {expected} ({ray:?})"));
    }
    Ok(())
}

/// A deterministic generator for test data (SplitMix64), so failures reproduce from a seed.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn u(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.u()
    }
    pub fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
    pub fn unit(&mut self) -> Vec3 {
        loop {
            let v = self.vec3(-1.0, 1.0);
            let l2 = v.length_squared();
            if l2 > 1e-4 && l2 <= 1.0 {
                return v / l2.sqrt();
            }
        }
    }
    pub fn index(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// A soup of `n` random triangles of size up to `size` around random points in `[-4, 4]^3`,
/// with random per-vertex normals and uvs half the time.
pub fn triangle_soup(rng: &mut Rng, n: usize, size: f32) -> TriangleMesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..n {
        let c = rng.vec3(-4.0, 4.0);
        for _ in 0..3 {
            positions.push(c + rng.vec3(-size, size));
        }
        let v = 3 * i as u32;
        triangles.push([v, v + 1, v + 2]);
    }
    let normals = (rng.u() < 0.5).then(|| positions.iter().map(|_| rng.unit()).collect());
    let uvs = (rng.u() < 0.5).then(|| {
        positions
            .iter()
            .map(|_| Vec2::new(rng.u(), rng.u()))
            .collect()
    });
    TriangleMesh::new(positions, triangles, normals, uvs).unwrap()
}

/// A random static placement: rotation, scale (possibly mirroring), translation.
pub fn random_transform(rng: &mut Rng) -> Transform<World, Object> {
    let axis = rng.unit();
    let angle = rng.range(-180.0, 180.0);
    let mut scale = rng.vec3(0.5, 1.5);
    if rng.u() < 0.25 {
        scale.x = -scale.x;
    }
    let translate = rng.vec3(-2.0, 2.0);
    Transform::translate(translate).unwrap()
        * Transform::<Object, Object>::rotate(angle, axis).unwrap()
        * Transform::<Object, Object>::scale(scale).unwrap()
}

/// A random placement: static, or moving between two random transforms over [0, 1].
pub fn random_placement(rng: &mut Rng, moving_chance: f32) -> Placement {
    let start = random_transform(rng);
    if rng.u() < moving_chance {
        // The end keyframe: the start moved and turned a little (same handedness).
        let turn = Transform::<World, World>::rotate(rng.range(-90.0, 90.0), rng.unit()).unwrap();
        let shift = Transform::<World, World>::translate(rng.vec3(-2.0, 2.0)).unwrap();
        let end = shift * turn * start;
        Placement::Moving(obscura_space::AnimatedTransform::new(start, 0.0, end, 1.0).unwrap())
    } else {
        Placement::Static(start)
    }
}

/// A random shape among spheres, quads and triangle soups (`mesh` supplies soups).
pub fn random_shape(rng: &mut Rng, mesh: &Arc<TriangleMesh>) -> Shape {
    match rng.index(3) {
        0 => Shape::Sphere {
            center: rng.vec3(-3.0, 3.0),
            radius: rng.range(0.2, 1.5),
        },
        1 => Shape::Quad {
            origin: rng.vec3(-3.0, 3.0),
            edge_u: rng.vec3(-2.0, 2.0),
            edge_v: rng.vec3(-2.0, 2.0),
        },
        _ => Shape::Mesh(mesh.clone()),
    }
}

/// A random ray through the scene's region, with a random time and sometimes a short range.
pub fn random_ray(rng: &mut Rng) -> Ray<World> {
    let origin = rng.vec3(-8.0, 8.0);
    // Aim near the middle so that most rays hit something.
    let target = rng.vec3(-3.0, 3.0);
    let direction = (target - origin).normalize() * rng.range(0.5, 2.0);
    let mut ray = Ray::new(
        obscura_space::Point3::from_glam(origin),
        obscura_space::Vector3::from_glam(direction),
        rng.u(),
    );
    if rng.u() < 0.3 {
        let t_min = rng.range(0.0, 4.0);
        ray = ray.with_range(t_min, t_min + rng.range(0.0, 8.0));
    }
    ray
}
