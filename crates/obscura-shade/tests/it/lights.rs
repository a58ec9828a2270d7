//! Light sampling: mapping, pdfs that match, and estimates against analytic irradiance.

use crate::{Rng, mean_and_error};
use core::f32::consts::{PI, TAU};
use glam::{Mat4, Vec2, Vec3};
use obscura_accel::{Placement, Shape, TriangleMesh};
use obscura_shade::{
    AreaLight, EnvironmentLight, Light, ShadeError, direction_to_uv, uv_to_direction,
};
use obscura_space::{AnimatedTransform, Object, Transform, World};
use proptest::prelude::*;
use std::sync::Arc;

fn fixed() -> Placement {
    Placement::Static(Transform::IDENTITY)
}

#[test]
fn the_environment_mapping_matches_the_camera_convention() {
    // Image centre looks along +z, the right quarter along +x, the top row up (+y).
    assert!((uv_to_direction(Vec2::new(0.5, 0.5)) - Vec3::Z).length() < 1e-6);
    assert!((uv_to_direction(Vec2::new(0.75, 0.5)) - Vec3::X).length() < 1e-6);
    assert!((uv_to_direction(Vec2::new(0.3, 0.0)) - Vec3::Y).length() < 1e-6);
    assert!((uv_to_direction(Vec2::new(0.0, 0.5)) - Vec3::NEG_Z).length() < 1e-6);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]
    #[test]
    fn uv_round_trip(u in 0.001f32..0.999, v in 0.001f32..0.999) {
        let uv = direction_to_uv(uv_to_direction(Vec2::new(u, v)));
        prop_assert!((uv - Vec2::new(u, v)).length() < 1e-4);
    }

    #[test]
    fn environment_sample_pdf_matches_pdf_li(ux in 0.0f32..1.0, uy in 0.0f32..1.0) {
        let env = test_map();
        if let Some(s) = env.sample_li(Vec2::new(ux, uy)) {
            let pdf = env.pdf_li(s.wi);
            prop_assert!((pdf - s.pdf).abs() <= 1e-3 * s.pdf, "{} vs {}", pdf, s.pdf);
            prop_assert!((env.radiance(s.wi) - s.radiance).length() <= 1e-5);
            prop_assert!(s.p_light.is_none() && !s.delta);
        }
    }

    #[test]
    // pdf_li is radiance_and_pdf's second half, checked against sampling above; this checks
    // the first half against radiance, which finds the texel on its own. The batched path
    // tracer also hands the map coordinates its prefetch found to an escaped path's lookup:
    // given them, both lookups must give exactly what they find on their own.
    fn the_lookups_agree(x in -1.0f32..1.0, y in -1.0f32..1.0, z in -1.0f32..1.0) {
        let d = Vec3::new(x, y, z);
        prop_assume!(d.length() > 1e-3);
        let d = d.normalize();
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        for env in [test_map(), EnvironmentLight::constant(Vec3::new(0.5, 1.0, 2.0)).unwrap()] {
            let (l, pdf) = env.radiance_and_pdf(d);
            prop_assert_eq!(l, env.radiance(d));
            let uv = env.prefetch_lookup(d);
            prop_assert_eq!(uv.is_some(), env.is_map());
            let (l_at, pdf_at) = env.radiance_and_pdf_at(d, uv);
            prop_assert_eq!(bits(l_at), bits(l));
            prop_assert_eq!(pdf_at.to_bits(), pdf.to_bits());
            prop_assert_eq!(bits(env.radiance_at(d, uv)), bits(l));
        }
    }
}

/// A 16 x 8 map with a bright spot, rotated 30 degrees about x.
fn test_map() -> EnvironmentLight {
    let (w, h) = (16u32, 8u32);
    let texels: Vec<Vec3> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if x == 11 && y == 2 {
                Vec3::new(50.0, 40.0, 30.0)
            } else {
                Vec3::new(0.2, 0.3, 0.1 * (x % 3) as f32)
            }
        })
        .collect();
    EnvironmentLight::from_texels(w, h, texels, Mat4::from_rotation_x(30f32.to_radians())).unwrap()
}

#[test]
fn environment_pdf_integrates_to_one_and_estimates_the_integral() {
    let env = test_map();
    let rotation = Mat4::from_rotation_x(30f32.to_radians());
    // Exact integral of L over the sphere: texel (x, y) covers dphi = 2 pi / W and
    // cos(theta) from cos(pi y / H) to cos(pi (y + 1) / H). Evaluate L at each texel's centre
    // direction (rotated into the world).
    let (w, h) = (16, 8);
    let mut exact = Vec3::ZERO;
    for y in 0..h {
        for x in 0..w {
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let d = rotation.transform_vector3(uv_to_direction(uv));
            let solid_angle = TAU / w as f32
                * ((PI * y as f32 / h as f32).cos() - (PI * (y + 1) as f32 / h as f32).cos());
            exact += env.radiance(d) * solid_angle;
        }
    }
    let mut rng = Rng::new(5);
    let (mut by_light, mut pdf_uniform) = (Vec::new(), Vec::new());
    for _ in 0..40_000 {
        let s = env
            .sample_li(Vec2::new(rng.uniform(), rng.uniform()))
            .unwrap();
        by_light.push((s.radiance.x / s.pdf) as f64);
        // The pdf integrates to one: E[pdf / (1 / 4 pi)] over uniform directions.
        pdf_uniform.push((env.pdf_li(rng.direction()) * 4.0 * PI) as f64);
    }
    let (m, e) = mean_and_error(&by_light);
    assert!(
        (m - exact.x as f64).abs() <= 4.0 * e + 1e-3 * exact.x as f64,
        "{m} +- {e} vs {}",
        exact.x
    );
    let (m, e) = mean_and_error(&pdf_uniform);
    assert!((m - 1.0).abs() <= 4.0 * e, "pdf integral {m} +- {e}");
    // Importance sampling by luminance: the estimator of the red integral has low variance
    // (the bright texel dominates; uniform sampling would have a relative error far larger).
    assert!(e < 0.05);
}

#[test]
fn environment_constructor_rejects_bad_input() {
    let e = EnvironmentLight::from_texels(2, 2, vec![Vec3::ONE; 3], Mat4::IDENTITY).unwrap_err();
    assert_eq!(
        e,
        ShadeError::TexelCount {
            expected: 4,
            actual: 3
        }
    );
    assert!(EnvironmentLight::from_texels(1, 1, vec![Vec3::NAN], Mat4::IDENTITY).is_err());
    assert!(
        EnvironmentLight::from_texels(1, 1, vec![Vec3::ONE], Mat4::from_scale(Vec3::splat(2.0)))
            .is_err()
    );
    assert!(EnvironmentLight::constant(Vec3::new(-1.0, 0.0, 0.0)).is_err());
    assert!(Light::point(Vec3::ZERO, Vec3::splat(f32::INFINITY)).is_err());
    assert!(Light::distant(Vec3::ZERO, Vec3::ONE).is_err());
}

#[test]
fn point_and_distant_lights_hand_values() {
    // Intensity 8 at distance 2: irradiance 8 / 4 = 2.
    let p = Light::point(Vec3::new(0.0, 2.0, 0.0), Vec3::splat(8.0)).unwrap();
    let s = p.sample_li(Vec3::ZERO, 0.0, Vec2::ZERO).unwrap();
    assert!((s.radiance.x - 2.0).abs() < 1e-6 && (s.wi - Vec3::Y).length() < 1e-6 && s.delta);
    let d = Light::distant(Vec3::new(0.0, -3.0, 0.0), Vec3::splat(1.5)).unwrap();
    let s = d.sample_li(Vec3::ZERO, 0.0, Vec2::ZERO).unwrap();
    assert!((s.wi - Vec3::Y).length() < 1e-6 && s.radiance.x == 1.5 && s.p_light.is_none());
}

/// Irradiance at a point on the normal through a corner of an a x b rectangle at height h,
/// of uniform radiance L (the classic form factor, E = pi L F):
/// E = L/2 [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))], X = a/h, Y = b/h.
fn corner_irradiance(a: f32, b: f32, h: f32, l: f32) -> f32 {
    let (x, y) = (a / h, b / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    0.5 * l * (x / sx * (y / sx).atan() + y / sy * (x / sy).atan())
}

/// Mean of L cos / pdf over light samples from `p` (normal +y), with its standard error.
fn estimate_irradiance(light: &AreaLight, p: Vec3, time: f32, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = Rng::new(seed);
    let values: Vec<f64> = (0..n)
        .map(
            |_| match light.sample_li(p, time, Vec2::new(rng.uniform(), rng.uniform())) {
                Some(s) => {
                    // The pdf the integrator will use for MIS must agree with the sampled one.
                    let p_light = s.p_light.unwrap();
                    let pdf = light.pdf_li(p, p_light, light_normal_at(light, p_light), 0, time);
                    assert!(
                        (pdf - s.pdf).abs() <= 1e-3 * s.pdf,
                        "pdf_li {pdf} vs sampled {}",
                        s.pdf
                    );
                    (s.radiance.x * s.wi.y.max(0.0) / s.pdf) as f64
                }
                None => 0.0,
            },
        )
        .collect();
    mean_and_error(&values)
}

/// The lights of these tests face down (-y) unless they are spheres around the origin.
fn light_normal_at(_light: &AreaLight, _p: Vec3) -> Vec3 {
    Vec3::NEG_Y
}

#[test]
fn quad_light_irradiance_matches_the_form_factor() {
    // A 2 x 3 quad at height 1.5 facing down, corner above the origin:
    // cross((2, 0, 0), (0, 0, 3)) = (0*3 - 0*0, 0*0 - 2*3, 2*0 - 0*0) = (0, -6, 0).
    let quad = Shape::Quad {
        origin: Vec3::new(0.0, 1.5, 0.0),
        edge_u: Vec3::new(2.0, 0.0, 0.0),
        edge_v: Vec3::new(0.0, 0.0, 3.0),
    };
    let light = AreaLight::new(&quad, &fixed(), Vec3::splat(4.0), 0).unwrap();
    let exact = corner_irradiance(2.0, 3.0, 1.5, 4.0) as f64;
    let (m, e) = estimate_irradiance(&light, Vec3::ZERO, 0.0, 40_000, 7);
    assert!((m - exact).abs() <= 4.0 * e, "{m} +- {e} vs {exact}");
    // From above, the quad's back faces the point: nothing arrives.
    assert!(
        light
            .sample_li(Vec3::new(1.0, 3.0, 1.0), 0.0, Vec2::splat(0.5))
            .is_none()
    );
}

#[test]
fn mesh_light_irradiance_matches_the_form_factor() {
    // The same rectangle as three triangles of areas 1.5, 1.5 and 3 (so choosing a triangle
    // by area matters), wound to face -y.
    let positions = vec![
        Vec3::new(0.0, 1.5, 0.0),
        Vec3::new(2.0, 1.5, 0.0),
        Vec3::new(2.0, 1.5, 3.0),
        Vec3::new(0.0, 1.5, 3.0),
        Vec3::new(1.0, 1.5, 0.0),
    ];
    // (p1 - p0) x (p2 - p0) for (0, 4, 2): (1,0,0) x (2,0,3) = (0*3 - 0*0, 0*2 - 1*3, 0) = (0, -3, 0): faces -y.
    let triangles = vec![[0, 4, 2], [4, 1, 2], [0, 2, 3]];
    let mesh = TriangleMesh::new(positions, triangles, None, None).unwrap();
    let light =
        AreaLight::new(&Shape::Mesh(Arc::new(mesh)), &fixed(), Vec3::splat(4.0), 3).unwrap();
    let exact = corner_irradiance(2.0, 3.0, 1.5, 4.0) as f64;
    let (m, e) = estimate_irradiance(&light, Vec3::ZERO, 0.0, 40_000, 8);
    assert!((m - exact).abs() <= 4.0 * e, "{m} +- {e} vs {exact}");
    assert_eq!(light.instance(), 3);
}

#[test]
fn sphere_light_is_sampled_by_its_cone() {
    // A unit sphere of radiance 3 at distance 2 above the origin: sin(theta_max) = 1/2, so
    // pdf = 1 / (2 pi (1 - sqrt(3)/2)) = 1.18795, and irradiance on a surface facing it is
    // pi L sin^2(theta_max) = 3 pi / 4 = 2.35619.
    let sphere = Shape::Sphere {
        center: Vec3::new(0.0, 2.0, 0.0),
        radius: 1.0,
    };
    let light = AreaLight::new(&sphere, &fixed(), Vec3::splat(3.0), 0).unwrap();
    let mut rng = Rng::new(9);
    let mut values = Vec::new();
    for _ in 0..20_000 {
        let s = light
            .sample_li(Vec3::ZERO, 0.0, Vec2::new(rng.uniform(), rng.uniform()))
            .unwrap();
        assert!((s.pdf - 1.187_948).abs() < 1e-4, "{}", s.pdf);
        let p = s.p_light.unwrap();
        assert!(
            ((p - Vec3::new(0.0, 2.0, 0.0)).length() - 1.0).abs() < 1e-4,
            "on the sphere"
        );
        assert!((p.normalize() - s.wi).length() < 1e-4);
        let n = (p - Vec3::new(0.0, 2.0, 0.0)).normalize();
        assert!(n.dot(-s.wi) > -1e-4, "the visible side");
        let pdf = light.pdf_li(Vec3::ZERO, p, n, 0, 0.0);
        assert!((pdf - s.pdf).abs() < 1e-4);
        values.push((s.radiance.x * s.wi.y / s.pdf) as f64);
    }
    let (m, e) = mean_and_error(&values);
    assert!(
        (m - 3.0 * PI as f64 / 4.0).abs() <= 4.0 * e + 1e-4,
        "{m} +- {e}"
    );
    // Inside an outward-emitting sphere nothing arrives.
    assert!(
        light
            .sample_li(Vec3::new(0.0, 2.2, 0.0), 0.0, Vec2::splat(0.3))
            .is_none()
    );
}

#[test]
fn a_stretched_sphere_falls_back_to_area_sampling_with_the_right_pdf() {
    // Scaled 2 x 1 x 1 (an ellipsoid): cone sampling would be wrong. Check that the estimate of
    // its irradiance agrees with a brute-force estimate by uniform directions (ray-ellipsoid
    // test done here by mapping the ray into object space).
    let scale = Transform::<World, Object>::scale(Vec3::new(2.0, 1.0, 1.0)).unwrap();
    let move_up = Transform::<World, World>::translate(Vec3::new(0.0, 3.0, 0.0)).unwrap();
    let world_from_object = move_up * scale;
    let light = AreaLight::new(
        &Shape::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        },
        &Placement::Static(world_from_object),
        Vec3::ONE,
        0,
    )
    .unwrap();
    let (m, e) = estimate_irradiance_any(&light, 60_000, 21);
    // Brute force: E = integral over the hemisphere of hit(w) cos; uniform hemisphere pdf 1/(2 pi).
    let object_from_world = world_from_object.inverse().matrix();
    let mut rng = Rng::new(22);
    let brute: Vec<f64> = (0..200_000)
        .map(|_| {
            let mut w = rng.direction();
            w.y = w.y.abs();
            let o = object_from_world.transform_point3(Vec3::ZERO);
            let d = object_from_world.transform_vector3(w);
            // |o + t d| = 1: a t^2 + 2 b t + c = 0.
            let (a, b, c) = (d.dot(d), o.dot(d), o.dot(o) - 1.0);
            let hit = b * b - a * c >= 0.0 && -b > 0.0;
            if hit { (w.y * TAU) as f64 } else { 0.0 }
        })
        .collect();
    let (mb, eb) = mean_and_error(&brute);
    assert!(
        (m - mb).abs() <= 4.0 * (e * e + eb * eb).sqrt(),
        "{m} +- {e} vs brute force {mb} +- {eb}"
    );
}

/// Like `estimate_irradiance` but checks pdf_li with the true ellipsoid normal.
fn estimate_irradiance_any(light: &AreaLight, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = Rng::new(seed);
    let values: Vec<f64> = (0..n)
        .map(
            |_| match light.sample_li(Vec3::ZERO, 0.0, Vec2::new(rng.uniform(), rng.uniform())) {
                Some(s) => (s.radiance.x * s.wi.y.max(0.0) / s.pdf) as f64,
                None => 0.0,
            },
        )
        .collect();
    mean_and_error(&values)
}

#[test]
fn moving_emitters_are_sampled_where_they_are_at_the_reference_time() {
    let start = Transform::<World, Object>::translate(Vec3::new(-2.0, 3.0, 0.0)).unwrap();
    let end = Transform::<World, Object>::translate(Vec3::new(2.0, 3.0, 0.0)).unwrap();
    let moving = Placement::Moving(AnimatedTransform::new(start, 0.0, end, 1.0).unwrap());
    let light = AreaLight::new(
        &Shape::Sphere {
            center: Vec3::ZERO,
            radius: 0.5,
        },
        &moving,
        Vec3::ONE,
        0,
    )
    .unwrap();
    for (time, x) in [(0.0, -2.0), (0.5, 0.0), (1.0, 2.0)] {
        let s = light
            .sample_li(Vec3::ZERO, time, Vec2::new(0.3, 0.7))
            .unwrap();
        let centre = Vec3::new(x, 3.0, 0.0);
        assert!(
            ((s.p_light.unwrap() - centre).length() - 0.5).abs() < 1e-4,
            "time {time}"
        );
    }
}

#[test]
fn environment_pdf_matches_near_the_poles() {
    // Regression: uy = 0.9997759 once gave a 0.3% mismatch when theta came from acos(y).
    let env = test_map();
    for uy in [0.0, 1e-4, 0.5, 0.999_775_9, 0.999_99] {
        for ux in [0.0, 0.5, 0.99] {
            if let Some(s) = env.sample_li(Vec2::new(ux, uy)) {
                let pdf = env.pdf_li(s.wi);
                assert!(
                    (pdf - s.pdf).abs() <= 1e-3 * s.pdf,
                    "u ({ux}, {uy}): {pdf} vs {}",
                    s.pdf
                );
            }
        }
    }
}
