//! Spawned rays do not re-hit the surface they leave (no shadow acne), even far from the
//! origin where f32 spacing is coarse.

use crate::reference::{Rng, random_placement, random_ray, random_shape, triangle_soup};
use glam::Vec3;
use obscura_accel::{Placement, SceneBuilder, Shape};
use obscura_space::{Point3, Transform, Vector3, World};
use proptest::prelude::*;
use std::sync::Arc;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn spawned_rays_do_not_rehit_their_own_surface(seed in any::<u64>(), far in prop::bool::ANY) {
        no_self_hits(seed, far)?;
    }
}

/// Cases the proptest found. The first is a thin triangle whose Möller–Trumbore numerator's
/// rounding was more than the hit point's own error bound; the second a ray spawned into a
/// scaled sphere whose stored inverse transform is a few ulps from the matrix's inverse.
#[test]
fn spawned_rays_do_not_rehit_their_own_surface_found_cases() {
    no_self_hits(1449465297462541552, false).unwrap();
    no_self_hits(17815279262193261497, false).unwrap();
}

/// Six random shapes from `seed`, far from the origin if `far`; rays spawned from their hits
/// must not re-hit the surface they leave.
fn no_self_hits(seed: u64, far: bool) -> Result<(), TestCaseError> {
    let mut rng = Rng(seed);
    let soup = Arc::new(triangle_soup(&mut rng, 40, 1.0));
    let mut builder = SceneBuilder::new();
    // Far away (x = 5000) f32 steps are about 5e-4: fixed epsilons fail there.
    let shift = if far {
        Vec3::new(5000.0, -3000.0, 2000.0)
    } else {
        Vec3::ZERO
    };
    let to_far = Transform::<World, World>::translate(shift).unwrap();
    let mut shapes = Vec::new();
    let mut descriptions = Vec::new();
    for _ in 0..6 {
        let shape = random_shape(&mut rng, &soup);
        let placement = match random_placement(&mut rng, 0.4) {
            Placement::Static(t) => Placement::Static(to_far * t),
            Placement::Moving(a) => {
                let keys = a.keyframes().map(|(time, t)| (time, to_far * t)).collect();
                Placement::Moving(obscura_space::AnimatedTransform::from_keyframes(keys).unwrap())
            }
        };
        shapes.push(matches!(shape, Shape::Sphere { .. }));
        descriptions.push(format!("{shape:?} {placement:?}"));
        builder.add(shape, placement).unwrap();
    }
    let scene = builder.build().unwrap();
    let mut checked = 0;
    for _ in 0..300 {
        let mut ray = random_ray(&mut rng);
        ray.origin += Vector3::from_glam(shift);
        let Some(hit) = scene.intersect(&ray) else {
            continue;
        };
        let n = hit.n_geometric.to_glam();
        let is_sphere = shapes[hit.instance as usize];
        for _ in 0..4 {
            let d = rng.unit();
            let spawned = scene.intersect(&hit.spawn_ray(Vector3::from_glam(d)));
            let same =
                spawned.is_some_and(|h| h.instance == hit.instance && h.primitive == hit.primitive);
            if !is_sphere || d.dot(n) > 0.0 {
                // Planar primitives cannot be re-hit at all; neither can a (transformed,
                // still convex) sphere by a ray leaving it outward.
                prop_assert!(
                    !same,
                    "self-hit: {hit:?} -> {spawned:?}, direction {d:?}, shape {}",
                    descriptions[hit.instance as usize]
                );
            } else if let Some(h) = spawned.filter(|_| same) {
                // Into a sphere: the far side, a real chord away, never next to the start. The
                // shapes are ellipsoids with semi-axes in [0.2 * 0.5, 1.5 * 1.5], so their radii
                // of curvature are at least 0.1^2 / 2.25 = 0.0044, and a ball of that radius
                // rolls freely inside them (Blaschke): a chord leaving at `cos = |d . n|` is at
                // least 2 * 0.0044 * cos long. A grazing ray's chord is short; acne is a re-hit
                // within the error bound (about 1e-6) of the start.
                let chord = 0.008 * d.dot(n).abs();
                prop_assert!(
                    h.p.distance(hit.p) > chord.min(1e-3),
                    "acne inside a sphere: {hit:?} -> {h:?}, direction {d:?}, shape {}",
                    descriptions[hit.instance as usize]
                );
            }
            checked += 1;
        }
        // A shadow ray to a point above the surface is not blocked by the surface itself.
        let target = Point3::from_glam(hit.p.to_glam() + n * 0.5);
        let shadow = hit.spawn_ray_to(target);
        let blocker = scene.intersect(&shadow);
        prop_assert!(
            !blocker.is_some_and(|h| h.instance == hit.instance
                && h.primitive == hit.primitive
                && !is_sphere),
            "shadow acne: {hit:?} -> {blocker:?}"
        );
    }
    prop_assert!(checked > 0);
    Ok(())
}

#[test]
fn spawn_ray_to_stops_short_of_its_target() {
    // A quad at z = 0 facing +z and a sphere of radius 1 at (0, 0, 3): from the quad's hit at
    // the origin, a shadow ray to the sphere's bottom point (0, 0, 2) must not report the
    // sphere itself (t stops at 1 - SHADOW_EPSILON), but one to its top (0, 0, 4) is blocked
    // by the sphere's bottom at t = 1/2.
    let mut b = SceneBuilder::new();
    let fixed = || Placement::Static(Transform::IDENTITY);
    b.add(
        Shape::Quad {
            origin: Vec3::new(-1.0, -1.0, 0.0),
            edge_u: Vec3::X * 2.0,
            edge_v: Vec3::Y * 2.0,
        },
        fixed(),
    )
    .unwrap();
    b.add(
        Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 3.0),
            radius: 1.0,
        },
        fixed(),
    )
    .unwrap();
    let scene = b.build().unwrap();
    let down = obscura_space::Ray::new(
        Point3::new(0.0, 0.0, 1.5),
        Vector3::new(0.0, 0.0, -1.0),
        0.0,
    );
    let hit = scene.intersect(&down).unwrap();
    assert_eq!(hit.instance, 0);
    assert!(!scene.occluded(&hit.spawn_ray_to(Point3::new(0.0, 0.0, 2.0))));
    assert!(scene.occluded(&hit.spawn_ray_to(Point3::new(0.0, 0.0, 4.0))));
}
