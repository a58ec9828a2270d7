//! The path tracer against analytic answers: white furnace, inverse square, area light form
//! factor through MIS, mirror geometry, moving shadows, convergence rate, MIS weights.

use crate::{Rng, mean_and_error};
use core::f32::consts::{FRAC_1_PI, PI};
use glam::{Mat4, Vec2, Vec3};
use obscura_accel::{Placement, Scene, SceneBuilder, Shape};
use obscura_shade::{
    EnvironmentLight, Light, Material, PathIntegrator, SampleDims, ShadingScene, power_heuristic,
};
use obscura_space::{AnimatedTransform, Object, Point3, Ray, Transform, Vector3, World};
use proptest::prelude::*;

fn fixed() -> Placement {
    Placement::Static(Transform::IDENTITY)
}

fn ray(origin: Vec3, direction: Vec3, time: f32) -> Ray<World> {
    Ray::new(
        Point3::from_glam(origin),
        Vector3::from_glam(direction.normalize()),
        time,
    )
}

/// One shape per instance: (shape, placement, material, emission).
fn build(
    items: Vec<(Shape, Placement, Material, Vec3)>,
    lights: Vec<Light>,
) -> (Scene, ShadingScene) {
    build_aiming(items, lights, false)
}

/// [`build`], and with `aim` the diffuse vertices aim at the specular objects
/// ([`ShadingScene::aim_at_specular`]) and solve for the light through glass balls
/// ([`ShadingScene::solve_through_glass`]), as the renderer's scenes do.
fn build_aiming(
    items: Vec<(Shape, Placement, Material, Vec3)>,
    lights: Vec<Light>,
    aim: bool,
) -> (Scene, ShadingScene) {
    build_with(items, lights, aim, aim)
}

/// [`build`], with `aim` aiming at the specular objects and `solve` solving through the
/// glass balls.
fn build_with(
    items: Vec<(Shape, Placement, Material, Vec3)>,
    lights: Vec<Light>,
    aim: bool,
    solve: bool,
) -> (Scene, ShadingScene) {
    let mut builder = SceneBuilder::new();
    let mut placed = Vec::new();
    let mut materials = Vec::new();
    let mut instance_material = Vec::new();
    let mut emitters = Vec::new();
    for (shape, placement, material, emission) in items {
        let instance = builder.add(shape.clone(), placement.clone()).unwrap();
        instance_material.push(materials.len() as u32);
        materials.push(material);
        if emission != Vec3::ZERO {
            emitters.push((instance, shape.clone(), placement.clone(), emission));
        }
        placed.push((instance, shape, placement));
    }
    let mut shading = ShadingScene::new(materials, instance_material, lights, emitters).unwrap();
    if aim {
        shading.aim_at_specular(placed.iter().map(|(i, s, p)| (*i, s, p)));
    }
    if solve {
        shading.solve_through_glass(placed.iter().map(|(i, s, p)| (*i, s, p)));
    }
    (builder.build().unwrap(), shading)
}

/// The red channel of `n` paths along `r`, each checked finite and non-negative.
fn path_values(
    integrator: &PathIntegrator,
    scene: &(Scene, ShadingScene),
    r: &Ray<World>,
    n: usize,
    seed: u64,
) -> Vec<f64> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            let l = integrator.li(&scene.0, &scene.1, r, &mut rng);
            assert!(l.is_finite() && l.min_element() >= 0.0, "{l}");
            l.x as f64
        })
        .collect()
}

fn estimate(
    integrator: &PathIntegrator,
    scene: &(Scene, ShadingScene),
    r: &Ray<World>,
    n: usize,
    seed: u64,
) -> (f64, f64) {
    mean_and_error(&path_values(integrator, scene, r, n, seed))
}

fn white() -> Material {
    Material::Diffuse {
        reflectance: Vec3::ONE,
    }
}

fn furnace(items: Vec<(Shape, Placement, Material, Vec3)>, label: &str) {
    furnace_aiming(items, label, false);
}

fn furnace_aiming(items: Vec<(Shape, Placement, Material, Vec3)>, label: &str, aim: bool) {
    // Radiance 1 everywhere is the solution of the rendering equation when every surface is
    // lossless and the environment is uniform 1, so every pixel must average to 1. Bound: the
    // mean of N = 2000 paths lies within 4.5 standard errors (estimated from the paths
    // themselves) of 1, for each of 12 directions; that fails by chance with probability
    // about 12 * 7e-6.
    let scene = build_aiming(
        items,
        vec![Light::Environment(
            EnvironmentLight::constant(Vec3::ONE).unwrap(),
        )],
        aim,
    );
    let integrator = PathIntegrator::new(100);
    let mut rng = Rng::new(77);
    for k in 0..12 {
        let origin = rng.direction() * 6.0;
        let target = rng.direction() * 0.5;
        let r = ray(origin, target - origin, 0.0);
        let (m, e) = estimate(&integrator, &scene, &r, 2000, k);
        assert!(
            (m - 1.0).abs() <= 4.5 * e + 1e-4,
            "{label}: direction {k}: {m} +- {e}"
        );
    }
}

#[test]
fn white_furnace_diffuse_sphere() {
    furnace(
        vec![(
            Shape::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            },
            fixed(),
            white(),
            Vec3::ZERO,
        )],
        "diffuse sphere",
    );
}

#[test]
fn white_furnace_interreflecting_spheres_and_glass() {
    // Two touching white spheres reflect light between them (long paths, Russian roulette),
    // and a glass sphere refracts it through (1/eta^2 in, eta^2 out): still radiance 1.
    furnace(
        vec![
            (
                Shape::Sphere {
                    center: Vec3::new(-1.0, 0.0, 0.0),
                    radius: 1.0,
                },
                fixed(),
                white(),
                Vec3::ZERO,
            ),
            (
                Shape::Sphere {
                    center: Vec3::new(1.0, 0.0, 0.0),
                    radius: 1.0,
                },
                fixed(),
                white(),
                Vec3::ZERO,
            ),
            (
                Shape::Sphere {
                    center: Vec3::new(0.0, 1.8, 0.0),
                    radius: 0.7,
                },
                fixed(),
                Material::Dielectric { ior: 1.5 },
                Vec3::ZERO,
            ),
        ],
        "spheres",
    );
}

fn floor(material: Material) -> (Shape, Placement, Material, Vec3) {
    floor_of(10.0, material)
}

/// A square of side `2 half` at y = 0 around the origin, facing +y: for `half` 10,
/// cross((0, 0, 20), (20, 0, 0)) = (0, 400, 0).
fn floor_of(half: f32, material: Material) -> (Shape, Placement, Material, Vec3) {
    (
        Shape::Quad {
            origin: Vec3::new(-half, 0.0, -half),
            edge_u: Vec3::new(0.0, 0.0, 2.0 * half),
            edge_v: Vec3::new(2.0 * half, 0.0, 0.0),
        },
        fixed(),
        material,
        Vec3::ZERO,
    )
}

#[test]
fn point_light_inverse_square_is_exact() {
    // rho = 0.5, I = 10, h = 2: L = rho / pi * I / h^2 = 0.5 / pi * 2.5 = 0.397887.
    let rho = 0.5;
    let scene = build(
        vec![floor(Material::Diffuse {
            reflectance: Vec3::splat(rho),
        })],
        vec![Light::point(Vec3::new(0.3, 2.0, -0.4), Vec3::splat(10.0)).unwrap()],
    );
    let expected = rho * FRAC_1_PI * 10.0 / 4.0;
    // The camera ray looks straight down at the foot of the light (from below the light).
    let r = ray(Vec3::new(0.3, 1.0, -0.4), Vec3::NEG_Y, 0.0);
    for max_depth in [1, 5] {
        let mut rng = Rng::new(1);
        for _ in 0..20 {
            let l = PathIntegrator::new(max_depth).li(&scene.0, &scene.1, &r, &mut rng);
            assert!(
                (l.x - expected).abs() <= 1e-5 * expected,
                "{} vs {expected}",
                l.x
            );
        }
    }
    // Off the foot, at horizontal distance 2: r^2 = 8, cos = 2 / sqrt(8): L = rho/pi I cos / r^2.
    let r = ray(Vec3::new(2.3, 1.0, -0.4), Vec3::NEG_Y, 0.0);
    let l = PathIntegrator::new(1).li(&scene.0, &scene.1, &r, &mut Rng::new(2));
    let expected = rho * FRAC_1_PI * 10.0 * (2.0 / 8f32.sqrt()) / 8.0;
    assert!((l.x - expected).abs() <= 1e-5 * expected);
    // max_depth 0 sees no light at all (only emitters).
    assert_eq!(
        PathIntegrator::new(0).li(&scene.0, &scene.1, &r, &mut Rng::new(3)),
        Vec3::ZERO
    );
}

#[test]
fn distant_light_irradiance() {
    // Irradiance 3 along a direction 60 degrees from the normal: E cos = 1.5, L = rho/pi 1.5.
    let d = Vec3::new((60f32).to_radians().sin(), -(60f32).to_radians().cos(), 0.0);
    let scene = build(
        vec![floor(Material::Diffuse {
            reflectance: Vec3::splat(0.8),
        })],
        vec![Light::distant(d, Vec3::splat(3.0)).unwrap()],
    );
    let l = PathIntegrator::new(3).li(
        &scene.0,
        &scene.1,
        &ray(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.1, -1.0, 0.0), 0.0),
        &mut Rng::new(4),
    );
    assert!((l.x - 0.8 * FRAC_1_PI * 1.5).abs() < 1e-5, "{}", l.x);
}

/// A floor of albedo rho under a 2 x 3 quad light of radiance 4 at height 1.5 with a corner
/// straight above the origin: the radiance leaving the origin, with max_depth 1, is
/// rho / pi * E where E is the rectangle's form factor formula.
fn area_light_scene() -> ((Scene, ShadingScene), f64) {
    let light_quad = Shape::Quad {
        origin: Vec3::new(0.0, 1.5, 0.0),
        edge_u: Vec3::new(2.0, 0.0, 0.0),
        edge_v: Vec3::new(0.0, 0.0, 3.0),
    };
    let scene = build(
        vec![
            floor(Material::Diffuse {
                reflectance: Vec3::splat(0.5),
            }),
            (
                light_quad,
                fixed(),
                Material::Diffuse {
                    reflectance: Vec3::ZERO,
                },
                Vec3::splat(4.0),
            ),
        ],
        vec![],
    );
    // E = L/2 [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))], X = 2/1.5, Y = 3/1.5.
    let (x, y) = (2.0f64 / 1.5, 3.0f64 / 1.5);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    let e = 0.5 * 4.0 * (x / sx * (y / sx).atan() + y / sy * (x / sy).atan());
    (scene, 0.5 / PI as f64 * e)
}

#[test]
fn area_light_through_mis_is_unbiased() {
    let (scene, expected) = area_light_scene();
    let r = ray(Vec3::new(-0.5, 1.0, -0.5), Vec3::new(0.5, -1.0, 0.5), 0.0);
    let (m, e) = estimate(&PathIntegrator::new(1), &scene, &r, 20_000, 5);
    assert!((m - expected).abs() <= 4.0 * e, "{m} +- {e} vs {expected}");
    // The emitter seen directly from below shows its radiance; from above (its back) nothing.
    let below = PathIntegrator::new(0).li(
        &scene.0,
        &scene.1,
        &ray(Vec3::new(1.0, 1.0, 1.0), Vec3::Y, 0.0),
        &mut Rng::new(1),
    );
    assert_eq!(below, Vec3::splat(4.0));
    let above = PathIntegrator::new(0).li(
        &scene.0,
        &scene.1,
        &ray(Vec3::new(1.0, 2.0, 1.0), Vec3::NEG_Y, 0.0),
        &mut Rng::new(1),
    );
    assert_eq!(above, Vec3::ZERO);
}

#[test]
fn error_falls_as_one_over_sqrt_spp() {
    // RMS error against the analytic value over 200 independent pixel estimates at 4 and 64
    // samples: 16 times the samples should give a quarter of the error. Accept a ratio in
    // [3, 5.3] (the RMS of 200 estimates is itself uncertain by about 5%).
    let (scene, expected) = area_light_scene();
    let r = ray(Vec3::new(-0.5, 1.0, -0.5), Vec3::new(0.5, -1.0, 0.5), 0.0);
    let integrator = PathIntegrator::new(1);
    let rms = |spp: usize, seed: u64| {
        let mut rng = Rng::new(seed);
        let mut sum = 0.0f64;
        for _ in 0..200 {
            let mean: f64 = (0..spp)
                .map(|_| integrator.li(&scene.0, &scene.1, &r, &mut rng).x as f64)
                .sum::<f64>()
                / spp as f64;
            sum += (mean - expected) * (mean - expected);
        }
        (sum / 200.0).sqrt()
    };
    let (coarse, fine) = (rms(4, 100), rms(64, 200));
    let ratio = coarse / fine;
    assert!(
        (3.0..=5.3).contains(&ratio),
        "rms {coarse} at 4 spp, {fine} at 64 spp: ratio {ratio}"
    );
}

#[test]
fn a_mirror_shows_the_reflected_object_where_geometry_says() {
    // A mirror floor at y = 0 and an emissive sphere (radius 0.5, radiance 2) centred at
    // (2, 1, 0). A ray from (-2, 1, 0) aimed at the floor point (0, 0, 0) reflects to
    // direction (2, 1, 0), which passes through the sphere's centre at t = 1: we see 0.9 * 2.
    // Aimed at (0, 0, 1.0) it reflects along (2, 1, 1), passing the centre at
    // distance sqrt(10/3) = 1.83 > 0.5: black.
    let scene = build(
        vec![
            floor(Material::Mirror {
                reflectance: Vec3::splat(0.9),
            }),
            (
                Shape::Sphere {
                    center: Vec3::new(2.0, 1.0, 0.0),
                    radius: 0.5,
                },
                fixed(),
                white(),
                Vec3::splat(2.0),
            ),
        ],
        vec![],
    );
    let integrator = PathIntegrator::new(4);
    let hit = integrator.li(
        &scene.0,
        &scene.1,
        &ray(Vec3::new(-2.0, 1.0, 0.0), Vec3::new(2.0, -1.0, 0.0), 0.0),
        &mut Rng::new(1),
    );
    assert!((hit - Vec3::splat(1.8)).abs().max_element() < 1e-5, "{hit}");
    let miss = integrator.li(
        &scene.0,
        &scene.1,
        &ray(Vec3::new(-2.0, 1.0, 0.0), Vec3::new(2.0, -1.0, 1.0), 0.0),
        &mut Rng::new(1),
    );
    // Only the floor's reflection of nothing: no environment, and the mirror does not sample lights.
    assert_eq!(miss, Vec3::ZERO);
}

#[test]
fn a_moving_occluder_casts_a_moving_shadow() {
    // A point light at height 4 above the origin; a 1 x 1 occluder quad at height 2 moving
    // along x from x = -3 to x = +1 (its left edge) over time [0, 1]. Its shadow on the floor
    // has twice its size and position (similar triangles, factor 4/2): the shadow covers
    // x in [2 (-3 + 4t), 2 (-2 + 4t)] = [-6 + 8t, -4 + 8t], z in [-1, 1].
    let start = Transform::<World, Object>::translate(Vec3::new(-3.0, 2.0, -0.5)).unwrap();
    let end = Transform::<World, Object>::translate(Vec3::new(1.0, 2.0, -0.5)).unwrap();
    let occluder = (
        Shape::Quad {
            origin: Vec3::ZERO,
            edge_u: Vec3::new(0.0, 0.0, 1.0),
            edge_v: Vec3::new(1.0, 0.0, 0.0),
        },
        Placement::Moving(AnimatedTransform::new(start, 0.0, end, 1.0).unwrap()),
        white(),
        Vec3::ZERO,
    );
    let scene = build(
        vec![floor(white()), occluder],
        vec![Light::point(Vec3::new(0.0, 4.0, 0.0), Vec3::splat(16.0)).unwrap()],
    );
    let integrator = PathIntegrator::new(1);
    let radiance = |x: f32, time: f32| {
        let r = ray(Vec3::new(x, 0.5, 0.0), Vec3::NEG_Y, time);
        integrator.li(&scene.0, &scene.1, &r, &mut Rng::new(1)).x
    };
    // At time t the floor point x is dark exactly when -6 + 8t < x < -4 + 8t.
    for (x, time, dark) in [
        (-5.0, 0.0, true),
        (-5.0, 0.5, false),
        (-1.0, 0.5, true),
        (3.0, 1.0, true),
        (3.0, 0.5, false),
        (-1.0, 0.0, false),
    ] {
        let l = radiance(x, time);
        assert_eq!(l == 0.0, dark, "x {x} time {time}: radiance {l}");
    }
    // Averaged over the shutter, the shadow is blurred: at x = -1 the point is dark for
    // t in (5/8, 3/8 + ...): -6 + 8t < -1 < -4 + 8t  <=>  3/8 < t < 5/8, a quarter of the time.
    let n = 4000;
    let mut rng = Rng::new(9);
    let dark = (0..n)
        .filter(|_| radiance(-1.0, rng.uniform()) == 0.0)
        .count();
    let fraction = dark as f64 / n as f64;
    // Binomial standard deviation sqrt(0.25 * 0.75 / 4000) = 0.0068; allow 4.5 of them.
    assert!((fraction - 0.25).abs() < 0.031, "{fraction}");
}

/// Every material and light together: `ground` under a glass, a mirror and an emitting
/// sphere, an emitting quad of a smooth conductor, a point light, a distant light and a sky
/// with one very bright texel.
fn every_material_and_light(ground: (Shape, Placement, Material, Vec3)) -> (Scene, ShadingScene) {
    let mut texels = vec![Vec3::splat(0.5); 8 * 4];
    texels[5] = Vec3::splat(1e4);
    let env = EnvironmentLight::from_texels(8, 4, texels, glam::Mat4::IDENTITY).unwrap();
    // As the renderer builds its scenes: aiming at the glass and the mirror, and solving for
    // the light through the glass ball from the quad light.
    build_aiming(
        vec![
            ground,
            (
                Shape::Sphere {
                    center: Vec3::new(0.0, 1.0, 0.0),
                    radius: 1.0,
                },
                fixed(),
                Material::Dielectric { ior: 1.5 },
                Vec3::ZERO,
            ),
            (
                Shape::Sphere {
                    center: Vec3::new(2.5, 1.0, 0.0),
                    radius: 1.0,
                },
                fixed(),
                Material::Mirror {
                    reflectance: Vec3::ONE,
                },
                Vec3::ZERO,
            ),
            (
                Shape::Sphere {
                    center: Vec3::new(-2.5, 1.0, 0.0),
                    radius: 1.0,
                },
                fixed(),
                white(),
                Vec3::splat(3.0),
            ),
            (
                Shape::Quad {
                    origin: Vec3::new(-1.0, 4.0, -1.0),
                    edge_u: Vec3::new(2.0, 0.0, 0.0),
                    edge_v: Vec3::new(0.0, 0.0, 2.0),
                },
                fixed(),
                Material::RoughConductor {
                    reflectance: Vec3::ONE,
                    roughness: 0.0,
                },
                Vec3::splat(5.0),
            ),
        ],
        vec![
            Light::point(Vec3::new(0.0, 3.0, 2.0), Vec3::splat(5.0)).unwrap(),
            Light::distant(Vec3::new(1.0, -1.0, 0.0), Vec3::ONE).unwrap(),
            Light::Environment(env),
        ],
        true,
    )
}

#[test]
fn radiance_is_always_finite() {
    // Every material and light together, rays in every direction, grazing included.
    let scene = every_material_and_light(floor(Material::RoughConductor {
        reflectance: Vec3::splat(0.9),
        roughness: 0.3,
    }));
    let integrator = PathIntegrator::new(12);
    let mut rng = Rng::new(31);
    for _ in 0..3000 {
        let origin = rng.direction() * 5.0 + Vec3::new(0.0, 5.0, 0.0);
        let r = ray(origin, rng.direction(), rng.uniform());
        let l = integrator.li(&scene.0, &scene.1, &r, &mut rng);
        assert!(l.is_finite() && l.min_element() >= 0.0, "{l}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]
    #[test]
    fn mis_weights_sum_to_one(a in 0.0f32..1e6, b in 0.0f32..1e6) {
        prop_assume!(a > 0.0 || b > 0.0);
        let sum = power_heuristic(a, b) + power_heuristic(b, a);
        prop_assert!((sum - 1.0).abs() < 1e-5, "{}", sum);
    }
}

#[test]
fn mis_weight_hand_values() {
    // pdfs 1 and 3: 1 / (1 + 9) = 0.1 and 9 / 10 = 0.9.
    assert!((power_heuristic(1.0, 3.0) - 0.1).abs() < 1e-7);
    assert!((power_heuristic(3.0, 1.0) - 0.9).abs() < 1e-7);
    assert_eq!(power_heuristic(2.0, 0.0), 1.0);
    let _ = Vec2::ZERO;
}

#[test]
fn shading_scene_rejects_bad_input_with_clear_messages() {
    let sphere = || Shape::Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
    };
    let e = ShadingScene::new(vec![white()], vec![0, 1], vec![], vec![]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "instance_material[1] = 1 is out of range (there are 1)"
    );
    let e = ShadingScene::new(
        vec![white()],
        vec![0],
        vec![],
        vec![(4, sphere(), fixed(), Vec3::ONE)],
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "emitter instance = 4 is out of range (there are 1)"
    );
    let twice = vec![
        (0, sphere(), fixed(), Vec3::ONE),
        (0, sphere(), fixed(), Vec3::ONE),
    ];
    assert!(ShadingScene::new(vec![white()], vec![0], vec![], twice).is_err());
    let e = ShadingScene::new(
        vec![Material::Dielectric { ior: f32::NAN }],
        vec![0],
        vec![],
        vec![],
    )
    .unwrap_err();
    assert_eq!(e.to_string(), "ior must be finite (no NaN or infinity)");
    let e = ShadingScene::new(
        vec![white()],
        vec![0],
        vec![],
        vec![(0, sphere(), fixed(), Vec3::new(1.0, -1.0, 0.0))],
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "emission must be at least 0 in every channel"
    );
    let flat = Shape::Quad {
        origin: Vec3::ZERO,
        edge_u: Vec3::X,
        edge_v: Vec3::X * 2.0,
    };
    let e = ShadingScene::new(
        vec![white()],
        vec![0],
        vec![],
        vec![(0, flat, fixed(), Vec3::ONE)],
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "emissive quad edges must be non-parallel and non-zero (the quad needs an area)"
    );
    // A valid scene: the emitter becomes the last light and belongs to its instance.
    let ok = ShadingScene::new(
        vec![white()],
        vec![0, 0],
        vec![Light::point(Vec3::Y, Vec3::ONE).unwrap()],
        vec![(1, sphere(), fixed(), Vec3::ONE)],
    )
    .unwrap();
    assert_eq!(ok.lights().len(), 2);
    assert_eq!(ok.area_light(1).map(|a| a.instance()), Some(1));
    assert!(ok.area_light(0).is_none());
    assert_eq!(ok.light_select_pdf(), 0.5);
}

/// A non-emitting sphere of radius 1 at the origin.
fn unit_sphere(material: Material) -> (Shape, Placement, Material, Vec3) {
    let sphere = Shape::Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
    };
    (sphere, fixed(), material, Vec3::ZERO)
}

#[test]
fn white_furnace_glass_and_mirror_spheres() {
    // Lossless delta BSDFs alone: glass (paths bounce inside, with total internal reflection)
    // and a mirror of reflectance 1 must vanish into a uniform environment too.
    furnace(
        vec![unit_sphere(Material::Dielectric { ior: 1.5 })],
        "glass sphere",
    );
    furnace(
        vec![unit_sphere(Material::Mirror {
            reflectance: Vec3::ONE,
        })],
        "mirror sphere",
    );
}

#[test]
fn roulette_sees_through_the_radiance_scaling_of_glass() {
    // In a uniform environment a lossless glass sphere's paths carry exactly radiance 1 whatever
    // they do: Fresnel's choice is sampled with its own probability, and the 1 / eta^2 of
    // entering cancels the eta^2 of leaving. Russian roulette on beta alone would end paths
    // inside (beta = 1 / 2.25 there) and weight the survivors by 1 / 0.44, so single paths
    // would carry 0 or 2.25; on beta * eta^2 it never fires, and every path is 1 to rounding.
    let scene = build(
        vec![unit_sphere(Material::Dielectric { ior: 1.5 })],
        vec![Light::Environment(
            EnvironmentLight::constant(Vec3::ONE).unwrap(),
        )],
    );
    let integrator = PathIntegrator::new(1000);
    let mut rng = Rng::new(5);
    for k in 0..8u64 {
        let origin = rng.direction() * 4.0;
        let r = ray(origin, rng.direction() * 0.3 - origin, 0.0);
        let mut dims = Rng::new(100 + k);
        for i in 0..500 {
            let l = integrator.li(&scene.0, &scene.1, &r, &mut dims);
            assert!((l.x - 1.0).abs() < 1e-3, "direction {k}, path {i}: {l}");
        }
    }
}

#[test]
fn roulette_survival_hand_values() {
    use obscura_shade::rr_survival;
    // The largest channel of beta * scale, clamped to [0.05, 1].
    assert_eq!(rr_survival(Vec3::new(0.2, 0.4, 0.1), 1.0), 0.4);
    assert!((rr_survival(Vec3::splat(0.4), 2.25) - 0.9).abs() < 1e-6);
    assert_eq!(rr_survival(Vec3::splat(0.5), 2.25), 1.0);
    assert_eq!(rr_survival(Vec3::splat(0.001), 1.0), 0.05);
    assert_eq!(rr_survival(Vec3::splat(f32::NAN), 1.0), 0.05);
    assert_eq!(rr_survival(Vec3::splat(f32::INFINITY), 1.0), 1.0);
    // An aimed sample's throughput 0.31 with its scale p_mix / p_own = 2.6 (the two-ball
    // caustic test's case): roulette sees 0.806, a cosine sample's 0.8 within rounding.
    assert!((rr_survival(Vec3::splat(0.31), 2.6) - 0.806).abs() < 1e-6);
    // A path that carries nothing under a scale that overflowed: 0 x inf is NaN, the floor.
    assert_eq!(rr_survival(Vec3::ZERO, f32::INFINITY), 0.05);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    /// Survival is a probability that roulette can divide by, for any throughput and scale
    /// (refractions' eta^2 and aims' density ratios span many decades), and it is the
    /// largest channel of `beta * scale` wherever that lies in `[0.05, 1]`.
    #[test]
    fn roulette_survival_is_a_probability(
        b in prop::array::uniform3(0.0f32..1e3),
        log_scale in -30.0f32..30.0,
    ) {
        use obscura_shade::rr_survival;
        let beta = Vec3::from(b);
        let scale = 10f32.powf(log_scale);
        let q = rr_survival(beta, scale);
        prop_assert!((0.05..=1.0).contains(&q), "{q}");
        let raw = beta.max_element() * scale;
        if (0.05..=1.0).contains(&raw) {
            prop_assert_eq!(q, raw);
        }
    }
}

/// A floor of `n` x `n` quads, two triangles each, rippled so that rays meet it at every angle.
fn rippled_floor(n: u32, material: Material) -> (Shape, Placement, Material, Vec3) {
    let side = n + 1;
    let positions = (0..side * side)
        .map(|k| {
            let (i, j) = ((k % side) as f32 / n as f32, (k / side) as f32 / n as f32);
            let (x, z) = (8.0 * i - 4.0, 8.0 * j - 4.0);
            Vec3::new(x, 0.15 * (3.0 * x).sin() * (2.0 * z).cos(), z)
        })
        .collect();
    let triangles = (0..n * n)
        .flat_map(|k| {
            let v = (k / n) * side + k % n;
            [[v, v + side, v + side + 1], [v, v + side + 1, v + 1]]
        })
        .collect();
    let mesh = obscura_accel::TriangleMesh::new(positions, triangles, None, None).unwrap();
    (
        Shape::Mesh(std::sync::Arc::new(mesh)),
        fixed(),
        material,
        Vec3::ZERO,
    )
}

/// `count` rays from around `(0, 3, 7)` in random directions leaning towards `-z` and `dip`
/// downwards: most meet `every_material_and_light`'s objects, some miss them all.
fn rays_towards_the_scene(count: usize, seed: u64, dip: f32) -> Vec<Ray<World>> {
    let mut rng = Rng::new(seed);
    (0..count)
        .map(|_| {
            let origin = Vec3::new(0.0, 3.0, 7.0) + rng.direction() * 0.5;
            ray(origin, rng.direction() + Vec3::new(0.0, -dip, -1.0), 0.0)
        })
        .collect()
}

/// Traces `rays` together ([`PathIntegrator::li_and_hit_batch`]) and one by one, path `k`
/// drawing from `dims(k)` both times, and asserts that every value is the same bit for bit.
/// Returns the values and the generators each way, as the paths left them.
fn together_equals_alone<D: SampleDims>(
    integrator: &PathIntegrator,
    scene: &(Scene, ShadingScene),
    rays: &[Ray<World>],
    dims: impl Fn(usize) -> D,
) -> (Vec<(Vec3, bool)>, [Vec<D>; 2]) {
    let mut batch: Vec<D> = (0..rays.len()).map(&dims).collect();
    let together = integrator.li_and_hit_batch(&scene.0, &scene.1, rays, &mut batch);
    assert_eq!(together.len(), rays.len());
    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
    let mut alone: Vec<D> = (0..rays.len()).map(&dims).collect();
    for (k, r) in rays.iter().enumerate() {
        let one = integrator.li_and_hit(&scene.0, &scene.1, r, &mut alone[k]);
        assert_eq!(
            (bits(together[k].0), together[k].1),
            (bits(one.0), one.1),
            "ray {k}"
        );
    }
    (together, [batch, alone])
}

#[test]
fn paths_traced_together_equal_paths_traced_one_by_one() {
    // The batch (wavefront) path tracer must give every camera ray the very value the one-path
    // loop gives it, bit for bit: the same numbers drawn in the same order, the same sums. A
    // floor of 80,000 triangles makes the geometry's batches take turns between rays; every
    // material and light exercises every branch of a vertex (escape, emission with MIS,
    // delta and area light samples, occlusion, roulette).
    let scene = every_material_and_light(rippled_floor(
        200,
        Material::RoughConductor {
            reflectance: Vec3::splat(0.9),
            roughness: 0.3,
        },
    ));
    assert!(scene.0.batches(), "the floor is large enough for batches");
    let integrator = PathIntegrator::new(12);
    let rays = rays_towards_the_scene(3000, 7, 0.4);
    let (together, _) =
        together_equals_alone(&integrator, &scene, &rays, |k| Rng::new(1000 + k as u64));
    // Not vacuous: some rays miss everything, most carry light.
    let lit = together.iter().filter(|v| v.0.max_element() > 0.0).count();
    let missed = together.iter().filter(|v| !v.1).count();
    assert!(lit > 2000 && missed > 0, "{lit} lit, {missed} missed");
}

#[test]
fn paths_traced_together_under_an_environment_map_equal_paths_traced_one_by_one() {
    // With an environment map, a scene without a large mesh also takes the batched path, which
    // prefetches the map's cells from numbers it peeks ahead in the sample streams. Peeking
    // must draw nothing and prefetching change nothing: every value is the one-path loop's,
    // bit for bit, with the renderer's own Sobol streams (which can peek).
    let scene = every_material_and_light(floor(Material::Diffuse {
        reflectance: Vec3::splat(0.7),
    }));
    assert!(!scene.0.batches() && scene.1.has_environment_map());
    let sampler = obscura_sample::Sampler::new(obscura_sample::SamplerKind::Sobol, 16, 3).unwrap();
    let integrator = PathIntegrator::new(12);
    let rays = rays_towards_the_scene(2000, 8, 0.2);
    let stream = |k: usize| {
        let mut s = sampler.stream([k as u32 % 40, k as u32 / 40], k as u32 % 16);
        s.camera();
        s
    };
    let (together, [batch, alone]) = together_equals_alone(&integrator, &scene, &rays, stream);
    // Each path's stream stopped where the one-path loop's did.
    for (k, (b, a)) in batch.iter().zip(&alone).enumerate() {
        assert_eq!(b.dimension(), a.dimension(), "ray {k}");
    }
    // Not vacuous: some rays escape to the map, most carry light.
    let lit = together.iter().filter(|v| v.0.max_element() > 0.0).count();
    let missed = together.iter().filter(|v| !v.1).count();
    assert!(lit > 1500 && missed > 0, "{lit} lit, {missed} missed");
}

fn sphere_at(center: Vec3, radius: f32, material: Material) -> (Shape, Placement, Material, Vec3) {
    (
        Shape::Sphere { center, radius },
        fixed(),
        material,
        Vec3::ZERO,
    )
}

#[test]
fn white_furnace_with_diffuse_vertices_aiming_at_glass_and_a_mirror() {
    // A white sphere between a glass and a mirror sphere close enough to be aimed at with
    // full weight (sin^2 of the half-angle 0.7^2 / 1.1^2 = 0.40 from the white sphere's
    // nearest point): the aimed samples are weighted by the mixture's density and the light
    // samples' MIS weights use it too, so the pixels must still average to 1.
    let items = vec![
        unit_sphere(white()),
        sphere_at(
            Vec3::new(1.8, 0.0, 0.0),
            0.7,
            Material::Dielectric { ior: 1.5 },
        ),
        sphere_at(
            Vec3::new(-1.8, 0.0, 0.0),
            0.7,
            Material::Mirror {
                reflectance: Vec3::ONE,
            },
        ),
    ];
    let scene = build_aiming(items.clone(), vec![], true);
    assert_eq!(scene.1.caster_count(), 2);
    furnace_aiming(items, "white sphere aiming at glass and a mirror", true);
}

/// A diffuse floor (a square of side `2 floor_half`) under glass balls of radius 1 at
/// `heights`, lit only by a bright sphere of radius 2 high above: the balls focus that light
/// onto the floor below them, a caustic that only paths floor - glass - ... - glass - light
/// reach (the light's own samples are blocked by the balls). The balls slide by `travel`
/// along z over the shutter `[0, 1]` (they are static when it is zero). With `aim`, floor
/// vertices aim at the balls.
fn caustic_scene(
    floor_half: f32,
    heights: &[f32],
    travel: f32,
    aim: bool,
) -> (Scene, ShadingScene) {
    let balls = heights.iter().map(|&h| {
        let mut ball = sphere_at(
            Vec3::new(0.0, h, 0.0),
            1.0,
            Material::Dielectric { ior: 1.5 },
        );
        if travel != 0.0 {
            let end = Transform::from_matrix(Mat4::from_translation(Vec3::new(0.0, 0.0, travel)));
            ball.1 = Placement::Moving(
                AnimatedTransform::new(Transform::IDENTITY, 0.0, end.unwrap(), 1.0).unwrap(),
            );
        }
        ball
    });
    build_aiming(
        [floor_of(
            floor_half,
            Material::Diffuse {
                reflectance: Vec3::splat(0.8),
            },
        )]
        .into_iter()
        .chain(balls)
        .chain([(
            Shape::Sphere {
                center: Vec3::new(0.0, 40.0, 0.0),
                radius: 2.0,
            },
            fixed(),
            Material::Diffuse {
                reflectance: Vec3::ZERO,
            },
            Vec3::splat(100.0),
        )])
        .collect(),
        vec![],
        aim,
    )
}

/// The mean and standard error of `n` paths along `r`, and how many carried light.
fn estimate_and_count(
    scene: &(Scene, ShadingScene),
    r: &Ray<World>,
    n: usize,
    seed: u64,
) -> (f64, f64, usize) {
    let values = path_values(&PathIntegrator::new(8), scene, r, n, seed);
    let (m, e) = mean_and_error(&values);
    (m, e, values.iter().filter(|&&v| v > 0.0).count())
}

#[test]
fn aiming_at_glass_finds_its_caustic_more_often_with_the_same_mean() {
    // The floor under a ball at height 2.5, seen from the side below the ball. In its
    // shadow, every path that carries light is a caustic path. By hand: the ball subtends
    // sin^2 = 1 / 2.5^2 = 0.16 of a half-angle, so its weight is 0.16 / 0.25 = 0.64 and a
    // share 0.5 * 0.64 = 0.32 of the samples is aimed, uniformly over a cone of solid angle
    // 2 pi (1 - cos) = 0.525 (density 1.91), against the cosine density 1 / pi = 0.32 near
    // the axis, where the lens sends light on to the source: about 0.68 + 0.32 * 1.91 / 0.32
    // = 2.6 times as many caustic paths. Measured 2.7; the counts (about 800 and 2100 of
    // 40,000) are binomial, so fewer than twice as many would be six standard deviations out.
    // Both estimates are unbiased: they must agree within 4.5 combined standard errors.
    aiming_finds_the_caustic_more_often(10.0, &[2.5], 0.0, 40_000, 3);
}

#[test]
fn a_moving_glass_ball_is_aimed_at_over_its_motion() {
    // The one-ball scene with the ball sliding by 0.2 along z over the shutter; the paths
    // are at time 0, where the ball starts. The vertex aims at the sphere that holds the
    // ball all along its motion: radius 1 + 0.1 about the middle of its path. By hand, as
    // above: sin^2 = 1.21 / 2.5^2 = 0.19, weight 0.77, share 0.39, over a cone of 0.64 sr
    // (density 1.56): about 0.61 + 0.39 * 1.56 / 0.32 = 2.5 times as many caustic paths.
    // Measured 2.8 (2172 against 780 of 40,000); without aiming at moving casters the two
    // estimators are the same (803 against 774).
    aiming_finds_the_caustic_more_often(10.0, &[2.5], 0.2, 40_000, 7);
}

/// Paths from the side onto the floor under the balls of `caustic_scene(floor_half,
/// heights, travel)`, `n` plain and `n` aimed (seeds `seed` and `seed + 1`): the aimed ones
/// must carry light at least twice as often, and both estimates must agree within 4.5
/// combined standard errors.
fn aiming_finds_the_caustic_more_often(
    floor_half: f32,
    heights: &[f32],
    travel: f32,
    n: usize,
    seed: u64,
) {
    let r = ray(Vec3::new(4.0, 0.4, 0.0), Vec3::new(-4.0, -0.4, 0.05), 0.0);
    let (plain, plain_err, plain_lit) = estimate_and_count(
        &caustic_scene(floor_half, heights, travel, false),
        &r,
        n,
        seed,
    );
    let (aimed, aimed_err, aimed_lit) = estimate_and_count(
        &caustic_scene(floor_half, heights, travel, true),
        &r,
        n,
        seed + 1,
    );
    let report = format!(
        "plain {plain} +- {plain_err} ({plain_lit} lit), aimed {aimed} +- {aimed_err} ({aimed_lit} lit)"
    );
    assert!(plain_lit > 300, "{report}");
    assert!(aimed_lit > 2 * plain_lit, "{report}");
    let combined = (plain_err * plain_err + aimed_err * aimed_err).sqrt();
    assert!((plain - aimed).abs() <= 4.5 * combined, "{report}");
}

#[test]
fn roulette_past_the_start_keeps_what_aiming_found() {
    // A small floor (0.5 x 0.5, so that nothing but the caustic lights a path) under two
    // glass balls stacked at heights 2.5 and 5: a caustic path is floor - A - A - B - B -
    // light, and its fifth bounce, out of the upper ball, faces Russian roulette
    // (`RR_START_DEPTH`) before the light. A sample aimed up the axis has the throughput
    // 0.8 x cosine density 0.32 / mixture density 0.8 to 1.4 (by hand, as in the one-ball
    // test, with the upper ball's cone inside the lower one's), that is 0.18 to 0.32, because
    // it was drawn often, not because little light comes that way. Roulette on that would
    // end about 70% of the aimed caustic paths and leave about as many lit paths as the plain
    // estimator finds (measured 1.04 times as many); roulette on the throughput without the
    // aim's weight (0.8, a cosine sample's) keeps the aiming's gain (measured 4.0 times as
    // many: 1979 against 499 of 200,000). The counts are binomial; twice the plain count lies
    // over ten standard deviations from both.
    assert_eq!(PathIntegrator::RR_START_DEPTH, 5);
    aiming_finds_the_caustic_more_often(0.25, &[2.5, 5.0], 0.0, 200_000, 5);
}

/// A diffuse floor under a glass ball of radius 1 at height 1.6, lit only by a square quad
/// light of side `side` facing down at height 12 above the ball's foot (the same power for
/// any side): the floor under the ball sees the light only through it. With `solve`, vertices
/// near the ball solve for those paths ([`ShadingScene::solve_through_glass`]); both aim at
/// the ball.
fn quad_caustic_scene(side: f32, solve: bool) -> (Scene, ShadingScene) {
    let items = vec![
        floor_of(
            10.0,
            Material::Diffuse {
                reflectance: Vec3::splat(0.8),
            },
        ),
        sphere_at(
            Vec3::new(0.0, 1.6, 0.0),
            1.0,
            Material::Dielectric { ior: 1.5 },
        ),
        (
            Shape::Quad {
                origin: Vec3::new(-0.5 * side, 12.0, -0.5 * side),
                edge_u: Vec3::new(side, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 0.0, side),
            },
            fixed(),
            Material::Diffuse {
                reflectance: Vec3::ZERO,
            },
            Vec3::splat(640.0 / (side * side)),
        ),
    ];
    build_with(items, vec![], true, solve)
}

/// The floor point under `quad_caustic_scene`'s ball, 0.3 from its foot (1.64 radii from its
/// centre, within the solve's reach of two radii), seen from the side: `n` paths without the
/// solve and `n / 10` with it (seeds `seed`, `seed + 1`). Both estimators are unbiased: the
/// means must agree within 4.5 combined standard errors. Returns both standard errors.
fn solve_keeps_the_mean(side: f32, n: usize, seed: u64) -> (f64, f64) {
    let r = ray(Vec3::new(4.0, 0.4, 0.3), Vec3::new(-4.0, -0.4, 0.0), 0.0);
    let plain = quad_caustic_scene(side, false);
    let solved = quad_caustic_scene(side, true);
    assert_eq!((plain.1.lens_count(), solved.1.lens_count()), (0, 1));
    let (a, ea, lit) = estimate_and_count(&plain, &r, n, seed);
    let (b, eb, _) = estimate_and_count(&solved, &r, n / 10, seed + 1);
    let report = format!("plain {a} +- {ea} ({lit} of {n} lit), solved {b} +- {eb}");
    assert!(a > 30.0 * ea, "the caustic must be there: {report}");
    assert!(
        (a - b).abs() <= 4.5 * (ea * ea + eb * eb).sqrt(),
        "{report}"
    );
    (ea, eb)
}

#[test]
fn solving_through_a_glass_ball_weighs_both_ways_to_a_path() {
    // A 4 x 4 light: seen through the ball from near its focus, the light fills most of the
    // ball's cone, so the solve's density for a chain's direction, p(y) / (d_omega / dA), is
    // about the BSDF's (by hand: (1 / 16) / (1.3 sr / 16) = 0.8 against 0.3 to 0.5, the
    // mixture of cosine and cone times T), and MIS splits the paths between the two. A solve
    // that counted its paths without the weight, or a BSDF side that still counted them
    // whole, would move the mean by a third or more of it: over 30 standard errors here.
    solve_keeps_the_mean(4.0, 100_000, 11);
}

#[test]
fn solving_through_a_glass_ball_keeps_the_caustics_mean_and_cuts_its_noise() {
    // A 1 x 1 light of the same power: a BSDF sample finds it through the ball in about 6%
    // of the paths (each then worth some 20 times the mean), while the solve finds a chain
    // from every light sample. Its paths' standard deviation must be a tenth of the plain
    // one's or less (measured: a thirtieth). The solve traced a tenth as many paths, so its
    // standard error is sqrt(10) times its paths' deviation over sqrt(n).
    let (plain, solved) = solve_keeps_the_mean(1.0, 400_000, 13);
    assert!(solved < 0.1 * plain * 10f64.sqrt(), "{plain} {solved}");
}
