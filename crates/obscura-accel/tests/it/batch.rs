//! Batch queries against one-ray queries: `intersect_batch`, `intersect_preliminary_batch`
//! and `occluded_batch` must give, ray for ray, exactly what `intersect`,
//! `intersect_preliminary` and `occluded` give (the batch only changes the order in which the
//! rays' steps are taken, never the steps).

use crate::testmesh;
use glam::Vec3;
use obscura_accel::{Placement, Scene, SceneBuilder, Shape, TriangleMesh};
use obscura_space::{AnimatedTransform, Object, Point3, Ray, Transform, Vector3, World};
use proptest::prelude::*;
use std::sync::{Arc, OnceLock};

/// The scenes the batch takes different ways through: a mesh alone (no top level), a mesh
/// with a sphere and a quad (the top level visits the mesh between them), a moving sphere
/// beside it, spheres alone (no flattened triangles: one ray at a time), and a mesh among
/// twenty spheres (obvhs's top-level tree: one ray at a time). The mesh has 81,920
/// triangles, enough for its batches to take turns between rays.
fn scenes() -> &'static [Scene; 5] {
    static SCENES: OnceLock<[Scene; 5]> = OnceLock::new();
    SCENES.get_or_init(|| {
        let mesh: Arc<TriangleMesh> = Arc::new(testmesh::icosphere(6).unwrap());
        let grid: Arc<TriangleMesh> = Arc::new(testmesh::displaced_grid(24).unwrap());
        let still = || Placement::Static(Transform::IDENTITY);
        let shifted = |x: f32| {
            Placement::Static(
                Transform::<World, Object>::translate(Vec3::new(x, 0.0, 0.0)).unwrap(),
            )
        };
        let sphere = |c: Vec3, r: f32| Shape::Sphere {
            center: c,
            radius: r,
        };
        let quad = Shape::Quad {
            origin: Vec3::new(-1.5, -1.0, -0.2),
            edge_u: Vec3::new(3.0, 0.0, 0.0),
            edge_v: Vec3::new(0.0, 2.0, 0.0),
        };
        let build = |shapes: Vec<(Shape, Placement)>| {
            let mut b = SceneBuilder::new();
            for (shape, placement) in shapes {
                b.add(shape, placement).unwrap();
            }
            b.build().unwrap()
        };
        let moving = AnimatedTransform::new(
            Transform::<World, Object>::translate(Vec3::new(-0.5, 0.0, 0.0)).unwrap(),
            0.0,
            Transform::<World, Object>::translate(Vec3::new(0.5, 0.0, 0.0)).unwrap(),
            1.0,
        )
        .unwrap();
        [
            build(vec![(Shape::Mesh(mesh.clone()), still())]),
            build(vec![
                (sphere(Vec3::new(0.3, 0.2, 0.1), 0.5), still()),
                (Shape::Mesh(mesh.clone()), still()),
                (quad.clone(), still()),
                (Shape::Mesh(grid), shifted(0.4)),
            ]),
            build(vec![
                (Shape::Mesh(mesh.clone()), still()),
                (sphere(Vec3::ZERO, 0.4), Placement::Moving(moving)),
            ]),
            build(vec![
                (sphere(Vec3::ZERO, 0.7), still()),
                (sphere(Vec3::new(0.5, 0.5, 0.0), 0.4), still()),
                (quad, still()),
            ]),
            build(
                std::iter::once((Shape::Mesh(mesh), still()))
                    .chain((0..20).map(|k| {
                        let a = k as f32 * 0.9;
                        (
                            sphere(Vec3::new(a.cos(), a.sin(), 0.3 * a.cos()), 0.15),
                            still(),
                        )
                    }))
                    .collect(),
            ),
        ]
    })
}

/// Every batch answer equals the one-ray answer for the same ray.
fn check(scene: &Scene, rays: &[Ray<World>]) -> Result<(), TestCaseError> {
    // Batches take turns where the big mesh is under a top level of few items.
    prop_assert_eq!(scene.batches(), [1, 4, 2].contains(&scene.instance_count()));
    let full = scene.intersect_batch(rays);
    let preliminary = scene.intersect_preliminary_batch(rays);
    let occluded = scene.occluded_batch(rays);
    prop_assert_eq!(
        (full.len(), preliminary.len(), occluded.len()),
        (rays.len(), rays.len(), rays.len())
    );
    for (k, ray) in rays.iter().enumerate() {
        prop_assert_eq!(full[k], scene.intersect(ray), "ray {}: {:?}", k, ray);
        let one = scene.intersect_preliminary(ray);
        let key = |p: &obscura_accel::PreliminaryHit<'_>| {
            (
                p.t().to_bits(),
                p.instance(),
                p.primitive(),
                p.primitive_uv().to_array().map(f32::to_bits),
            )
        };
        prop_assert_eq!(
            preliminary[k].as_ref().map(key),
            one.as_ref().map(key),
            "ray {}",
            k
        );
        prop_assert_eq!(occluded[k], scene.occluded(ray), "ray {}: {:?}", k, ray);
    }
    Ok(())
}

#[test]
fn batches_of_pinhole_and_incoherent_rays_answer_as_one_ray_queries() {
    let mut rays = testmesh::primary_rays();
    rays.truncate(20_000);
    rays.extend(testmesh::random_rays().into_iter().take(20_000));
    // Shadow-ray ranges too: the same rays stopped half way, some before the surface.
    let stopped: Vec<Ray<World>> = rays
        .iter()
        .step_by(7)
        .map(|r| Ray { t_max: 2.5, ..*r })
        .collect();
    rays.extend(stopped);
    for scene in scenes() {
        check(scene, &rays).unwrap();
    }
}

/// A ray towards the unit cube, with the range, time and validity proptest picks.
fn any_ray() -> impl Strategy<Value = Ray<World>> {
    (
        prop::array::uniform3(-3.0f32..3.0),
        prop::array::uniform3(-1.0f32..1.0),
        -0.5f32..0.5,
        prop_oneof![Just(f32::INFINITY), 0.0f32..6.0],
        0.0f32..1.0,
        0u8..12,
    )
        .prop_map(|(o, target, t_min, t_max, time, kind)| {
            let origin = Point3::new(o[0], o[1], o[2]);
            let dir = Point3::new(target[0], target[1], target[2]) - origin;
            let mut ray = Ray::new(origin, dir, time);
            ray.t_max = t_max;
            // Mostly t_min = 0 (the renderer's rays), some negative (the other box test),
            // and some rays that can hit nothing at all.
            match kind {
                0 => ray.t_min = t_min,
                1 => ray.direction = Vector3::new(0.0, 0.0, 0.0),
                2 => ray.origin = Point3::new(f32::NAN, 0.0, 0.0),
                3 => ray.t_min = ray.t_max + 1.0,
                _ => {}
            }
            ray
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn any_batch_answers_as_one_ray_queries(
        rays in prop::collection::vec(any_ray(), 0..200),
        which in 0usize..5,
    ) {
        check(&scenes()[which], &rays)?;
    }
}
