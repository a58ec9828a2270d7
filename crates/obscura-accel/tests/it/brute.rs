//! The BVH against the brute-force reference over random scenes and random rays.

use crate::reference::{
    Rng, TestScene, check_ray, random_placement, random_ray, random_shape, triangle_soup,
};
use obscura_accel::{Hit, Placement, SceneBuilder, Shape, TriangleMesh, load_obj};
use obscura_space::Transform;
use obscura_space::glam::Vec2;
use proptest::prelude::*;
use std::fmt::Write as _;
use std::sync::Arc;

/// Writes `mesh` as an OBJ file split over two objects and a group, with normals when it has
/// them, and returns its path.
fn write_obj(mesh: &TriangleMesh, name: &str) -> std::path::PathBuf {
    let mut text = String::from("# written by the brute-force test\no first\n");
    for p in mesh.positions() {
        writeln!(text, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    if let Some(normals) = mesh.normals() {
        for n in normals {
            writeln!(text, "vn {} {} {}", n.x, n.y, n.z).unwrap();
        }
    }
    let half = mesh.triangle_count() / 2;
    for (i, tri) in mesh.triangles().iter().enumerate() {
        if i == half {
            text.push_str("o second\ng part\n");
        }
        let [a, b, c] = tri.map(|v| v + 1);
        if mesh.normals().is_some() {
            writeln!(text, "f {a}//{a} {b}//{b} {c}//{c}").unwrap();
        } else {
            writeln!(text, "f {a} {b} {c}").unwrap();
        }
    }
    let path = std::env::temp_dir().join(format!(
        "obscura-accel-brute-{}-{name}.obj",
        std::process::id()
    ));
    std::fs::write(&path, text).unwrap();
    path
}

fn random_scene(seed: u64, moving_chance: f32) -> TestScene {
    let mut rng = Rng(seed);
    let soup = Arc::new(triangle_soup(&mut rng, 60, 1.0));
    // Up to 16 instances: the top level is one SIMD box node for up to eight items (static
    // meshes count as one) and obvhs's tree beyond, so both are exercised.
    let count = 1 + rng.index(16);
    let mut instances = (0..count)
        .map(|_| {
            let shape = random_shape(&mut rng, &soup);
            (shape, random_placement(&mut rng, moving_chance))
        })
        .collect::<Vec<_>>();
    if rng.u() < 0.5 {
        // An OBJ file generated here, loaded back, and placed like any mesh.
        let from_file = triangle_soup(&mut rng, 40, 0.8);
        let path = write_obj(&from_file, &format!("{seed}"));
        let loaded = load_obj(&path).unwrap();
        std::fs::remove_file(&path).ok();
        assert_eq!(loaded.triangle_count(), from_file.triangle_count());
        instances.push((
            Shape::Mesh(Arc::new(loaded)),
            random_placement(&mut rng, moving_chance),
        ));
    }
    TestScene::build(instances)
}

fn check_scene(seed: u64, moving_chance: f32, rays: usize) -> Result<(), TestCaseError> {
    let scene = random_scene(seed, moving_chance);
    let mut rng = Rng(seed ^ 0xABCD_EF01);
    // The rays are aimed at the middle of the scene, so most of them hit something (a scene
    // of one small sphere may be missed by all; a_large_soup_matches_brute_force counts hits).
    for _ in 0..rays {
        let ray = random_ray(&mut rng);
        check_ray(&scene, &ray).map_err(TestCaseError::fail)?;
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn static_scenes_match_brute_force(seed in any::<u64>()) {
        check_scene(seed, 0.0, 400)?;
    }

    #[test]
    fn moving_scenes_match_brute_force_at_the_ray_time(seed in any::<u64>()) {
        check_scene(seed, 0.6, 400)?;
    }

    /// Two to sixteen spheres and quads and no mesh: the top level (one set of boxes up to
    /// eight, two up to sixteen) visits the boxes a ray enters in index order, not nearest
    /// first, and must still find the closest hit.
    #[test]
    fn a_few_spheres_and_quads_match_brute_force(seed in any::<u64>(), moving in any::<bool>()) {
        let mut rng = Rng(seed);
        let soup = Arc::new(triangle_soup(&mut rng, 4, 1.0));
        let count = 2 + rng.index(15);
        let instances = (0..count)
            .map(|_| {
                let shape = loop {
                    let shape = random_shape(&mut rng, &soup);
                    if !matches!(shape, Shape::Mesh(_)) {
                        break shape;
                    }
                };
                (shape, random_placement(&mut rng, if moving { 0.5 } else { 0.0 }))
            })
            .collect::<Vec<_>>();
        let scene = TestScene::build(instances);
        for _ in 0..400 {
            let ray = random_ray(&mut rng);
            check_ray(&scene, &ray).map_err(TestCaseError::fail)?;
        }
    }

    /// A scene built without surface coordinates answers every query as the same scene with
    /// them, except that each hit's `uv` is zero.
    #[test]
    fn a_scene_without_uv_hits_the_same_with_zero_uv(seed in any::<u64>()) {
        let test = random_scene(seed, 0.3);
        let mut builder = SceneBuilder::new().with_uv(false);
        for (shape, placement) in &test.instances {
            builder.add(shape.clone(), placement.clone()).unwrap();
        }
        let without = builder.build().unwrap();
        let mut rng = Rng(seed ^ 0x0f0f);
        for _ in 0..200 {
            let ray = random_ray(&mut rng);
            let with = test.scene.intersect(&ray);
            prop_assert_eq!(without.intersect(&ray), with.map(|h| Hit { uv: Vec2::ZERO, ..h }));
            prop_assert_eq!(without.occluded(&ray), test.scene.occluded(&ray));
        }
    }

    /// `Scene::moves` (which lets a renderer skip drawing ray times) says yes exactly when an
    /// instance is placed moving; when it says no, a ray's time changes none of its hits.
    #[test]
    fn a_scene_moves_exactly_when_an_instance_does(seed in any::<u64>()) {
        let test = random_scene(seed, 0.2);
        let moving = test.instances.iter().any(|(_, p)| matches!(p, Placement::Moving(_)));
        prop_assert_eq!(test.scene.moves(), moving);
        if !moving {
            let mut rng = Rng(seed ^ 0x5EED);
            for _ in 0..50 {
                let mut ray = random_ray(&mut rng);
                ray.time = 0.0;
                let early = test.scene.intersect(&ray);
                ray.time = 0.7;
                let late = test.scene.intersect(&ray).map(|h| Hit { time: 0.0, ..h });
                prop_assert_eq!(early, late);
            }
        }
    }
}

#[test]
fn a_large_soup_matches_brute_force() {
    // Enough triangles for a deep BVH; all static and flattened, plus one moving copy.
    let mut rng = Rng(7);
    let soup = Arc::new(triangle_soup(&mut rng, 3000, 0.5));
    let scene = TestScene::build(vec![
        (
            Shape::Mesh(soup.clone()),
            Placement::Static(Transform::IDENTITY),
        ),
        (Shape::Mesh(soup), random_placement(&mut Rng(99), 1.0)),
    ]);
    let mut hits = 0;
    for _ in 0..2000 {
        let ray = random_ray(&mut rng);
        hits += usize::from(scene.scene.intersect(&ray).is_some());
        check_ray(&scene, &ray).unwrap();
    }
    assert!(hits > 500, "only {hits} of 2000 rays hit");
}
