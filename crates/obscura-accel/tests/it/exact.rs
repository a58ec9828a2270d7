//! Hand-computed cases: each expected value is worked out in the comment beside it.

use glam::{Vec2, Vec3};
use obscura_accel::{Placement, Scene, SceneBuilder, Shape, TriangleMesh};
use obscura_space::{AnimatedTransform, Object, Point3, Ray, Transform, Vector3, World};
use std::sync::Arc;

const EPS: f32 = 1e-5;

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() <= EPS
}

fn ray(o: [f32; 3], d: [f32; 3], time: f32) -> Ray<World> {
    Ray::new(
        Point3::new(o[0], o[1], o[2]),
        Vector3::new(d[0], d[1], d[2]),
        time,
    )
}

fn one(shape: Shape, placement: Placement) -> Scene {
    let mut b = SceneBuilder::new();
    assert_eq!(b.add(shape, placement).unwrap(), 0);
    b.build().unwrap()
}

fn unit_triangle(normals: Option<Vec<Vec3>>) -> Arc<TriangleMesh> {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let uvs = vec![Vec2::ZERO, Vec2::X, Vec2::Y];
    Arc::new(TriangleMesh::new(positions, vec![[0, 1, 2]], normals, Some(uvs)).unwrap())
}

#[test]
fn sphere_hit_point_normal_and_uv() {
    // Unit sphere at (0, 0, -5). A ray from (0, 5, -5) down -y meets its top (0, 1, -5) at
    // t = 4. There rel = (0, 1, 0): theta = acos(0) = pi/2 so v = 1/2; phi = atan2(1, 0) = pi/2
    // so u = 1/4. The outward normal is +y.
    let scene = one(
        Shape::Sphere {
            center: Vec3::new(0.0, 0.0, -5.0),
            radius: 1.0,
        },
        Placement::Static(Transform::IDENTITY),
    );
    let hit = scene
        .intersect(&ray([0.0, 5.0, -5.0], [0.0, -1.0, 0.0], 0.0))
        .unwrap();
    assert!((hit.t - 4.0).abs() < EPS);
    assert!(close(hit.p.to_glam(), Vec3::new(0.0, 1.0, -5.0)));
    assert!(close(hit.n_geometric.to_glam(), Vec3::Y));
    assert_eq!(hit.n_shading, hit.n_geometric);
    assert!((hit.uv - Vec2::new(0.25, 0.5)).abs().max_element() < EPS);
    assert_eq!((hit.instance, hit.primitive), (0, 0));
    // The error bound is small but not zero.
    let err = hit.p_error.to_glam();
    assert!(err.max_element() > 0.0 && err.max_element() < 1e-5);
}

#[test]
fn ray_range_is_honoured() {
    // From the origin down -z the unit sphere at z = -5 is crossed at t = 4 and t = 6.
    let scene = one(
        Shape::Sphere {
            center: Vec3::new(0.0, 0.0, -5.0),
            radius: 1.0,
        },
        Placement::Static(Transform::IDENTITY),
    );
    let r = ray([0.0; 3], [0.0, 0.0, -1.0], 0.0);
    assert!((scene.intersect(&r).unwrap().t - 4.0).abs() < EPS);
    let past_near = r.with_range(4.5, 10.0);
    assert!((scene.intersect(&past_near).unwrap().t - 6.0).abs() < EPS);
    // The far hit's normal is still outward (-z side is away from the centre at z = -6).
    assert!(close(
        scene.intersect(&past_near).unwrap().n_geometric.to_glam(),
        -Vec3::Z
    ));
    let short = r.with_range(0.0, 3.9);
    assert!(scene.intersect(&short).is_none());
    assert!(!scene.occluded(&short));
    assert!(scene.occluded(&r));
    let between = r.with_range(4.1, 5.9);
    assert!(scene.intersect(&between).is_none() && !scene.occluded(&between));
}

#[test]
fn mirrored_sphere_keeps_outward_normals() {
    // Centre (2, 0, 0) mirrored by x -> -x sits at (-2, 0, 0). A ray from (-5, 0, 0) along +x
    // meets it at x = -3 (t = 2), where outward is -x. In object space that point is
    // (3, 0, 0), object normal +x, and the inverse transpose of diag(-1, 1, 1) maps it to -x.
    let mirror = Transform::<World, Object>::scale(Vec3::new(-1.0, 1.0, 1.0)).unwrap();
    let scene = one(
        Shape::Sphere {
            center: Vec3::new(2.0, 0.0, 0.0),
            radius: 1.0,
        },
        Placement::Static(mirror),
    );
    let hit = scene
        .intersect(&ray([-5.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0))
        .unwrap();
    assert!((hit.t - 2.0).abs() < EPS);
    assert!(close(hit.n_geometric.to_glam(), -Vec3::X));
}

#[test]
fn mirrored_quad_normal_and_uv() {
    // The quad (0,0,0) + s x + t y has normal x cross y = +z; mirrored by z -> -z it faces -z.
    // A ray from (0.5, 0.25, 3) down -z meets it at t = 3 with (s, t) = (0.5, 0.25).
    let mirror = Transform::<World, Object>::scale(Vec3::new(1.0, 1.0, -1.0)).unwrap();
    let scene = one(
        Shape::Quad {
            origin: Vec3::ZERO,
            edge_u: Vec3::X,
            edge_v: Vec3::Y,
        },
        Placement::Static(mirror),
    );
    let hit = scene
        .intersect(&ray([0.5, 0.25, 3.0], [0.0, 0.0, -1.0], 0.0))
        .unwrap();
    assert!((hit.t - 3.0).abs() < EPS);
    assert!(close(hit.n_geometric.to_glam(), -Vec3::Z));
    assert!((hit.uv - Vec2::new(0.5, 0.25)).abs().max_element() < EPS);
    // Outside the parallelogram (s = 1.5): a miss.
    assert!(
        scene
            .intersect(&ray([1.5, 0.25, 3.0], [0.0, 0.0, -1.0], 0.0))
            .is_none()
    );
}

#[test]
fn flattened_triangle_uv_and_shading_normal() {
    // The triangle (0,0,0), (1,0,0), (0,1,0) scaled by 2: (0,0,0), (2,0,0), (0,2,0). A ray from
    // (0.5, 1, 5) down -z meets it at t = 5 with b1 = x / 2 = 0.25, b2 = y / 2 = 0.5, so
    // uv = 0.25 (1, 0) + 0.5 (0, 1) = (0.25, 0.5). Winding normal +z. The vertex normals all
    // say -z, so the shading normal is flipped to the geometric side: +z.
    let mesh = unit_triangle(Some(vec![-Vec3::Z; 3]));
    let scale = Transform::<World, Object>::scale(Vec3::splat(2.0)).unwrap();
    let scene = one(Shape::Mesh(mesh), Placement::Static(scale));
    let hit = scene
        .intersect(&ray([0.5, 1.0, 5.0], [0.0, 0.0, -1.0], 0.0))
        .unwrap();
    assert!((hit.t - 5.0).abs() < EPS);
    assert!(close(hit.p.to_glam(), Vec3::new(0.5, 1.0, 0.0)));
    assert!((hit.uv - Vec2::new(0.25, 0.5)).abs().max_element() < EPS);
    assert!(close(hit.n_geometric.to_glam(), Vec3::Z));
    assert!(close(hit.n_shading.to_glam(), Vec3::Z));
}

#[test]
fn mirrored_triangles_keep_their_winding_normal_static_and_moving() {
    // Mirrored by z -> -z the winding normal +z becomes -z, whether the triangle is flattened
    // (static) or carried at the ray's time (moving between two mirrored keyframes).
    let mirror = Transform::<World, Object>::scale(Vec3::new(1.0, 1.0, -1.0)).unwrap();
    let shifted = Transform::<World, World>::translate(Vec3::new(0.0, 0.0, 1.0)).unwrap() * mirror;
    let moving = AnimatedTransform::new(mirror, 0.0, shifted, 1.0).unwrap();
    for placement in [Placement::Static(mirror), Placement::Moving(moving)] {
        let scene = one(Shape::Mesh(unit_triangle(None)), placement);
        let hit = scene
            .intersect(&ray([0.25, 0.25, 5.0], [0.0, 0.0, -1.0], 0.0))
            .unwrap();
        assert!((hit.t - 5.0).abs() < EPS);
        assert!(close(hit.n_geometric.to_glam(), -Vec3::Z));
        // The vertex uvs are the unit corners, so uv = (b1, b2) = (0.25, 0.25).
        assert!((hit.uv - Vec2::new(0.25, 0.25)).abs().max_element() < EPS);
    }
}

#[test]
fn moving_triangle_is_where_its_keyframes_say() {
    // The unit triangle moves from x = 0 (time 0) to x = 10 (time 1): at time 0.5 it covers
    // x in [5, 6]. A ray from (5.25, 0.5, 5) down -z hits it at time 0.5 (t = 5, b1 = 0.25,
    // b2 = 0.5) and misses at times 0 and 1, where the triangle is elsewhere.
    let start = Transform::<World, Object>::IDENTITY;
    let end = Transform::<World, Object>::translate(Vec3::new(10.0, 0.0, 0.0)).unwrap();
    let scene = one(
        Shape::Mesh(unit_triangle(None)),
        Placement::Moving(AnimatedTransform::new(start, 0.0, end, 1.0).unwrap()),
    );
    let at = |time| ray([5.25, 0.5, 5.0], [0.0, 0.0, -1.0], time);
    let hit = scene.intersect(&at(0.5)).unwrap();
    assert!((hit.t - 5.0).abs() < EPS);
    assert!(close(hit.p.to_glam(), Vec3::new(5.25, 0.5, 0.0)));
    assert!((hit.uv - Vec2::new(0.25, 0.5)).abs().max_element() < EPS);
    assert_eq!(hit.time, 0.5);
    assert!(scene.intersect(&at(0.0)).is_none() && !scene.occluded(&at(0.0)));
    assert!(scene.intersect(&at(1.0)).is_none() && !scene.occluded(&at(1.0)));
    assert!(scene.occluded(&at(0.5)));
    // The scene's bounds hold the triangle at both ends: x from 0 to 11.
    let b = scene.bounds();
    assert!(b.min.x <= 0.0 && b.max.x >= 11.0);
}

#[test]
fn instances_are_numbered_in_call_order_and_bounds_cover_them() {
    let mut b = SceneBuilder::new();
    let sphere = |x: f32| Shape::Sphere {
        center: Vec3::new(x, 0.0, 0.0),
        radius: 0.5,
    };
    for (i, x) in [0.0, 3.0, 6.0].into_iter().enumerate() {
        assert_eq!(
            b.add(sphere(x), Placement::Static(Transform::IDENTITY))
                .unwrap(),
            i as u32
        );
    }
    let scene = b.build().unwrap();
    assert_eq!(scene.instance_count(), 3);
    // A ray along +x from x = 10 backwards meets the sphere at x = 6 first (instance 2, at
    // x = 6.5, t = 3.5).
    let hit = scene
        .intersect(&ray([10.0, 0.0, 0.0], [-1.0, 0.0, 0.0], 0.0))
        .unwrap();
    assert_eq!(hit.instance, 2);
    assert!((hit.t - 3.5).abs() < EPS);
    let bounds = scene.bounds();
    assert!(bounds.min.x <= -0.5 && bounds.max.x >= 6.5);
}

#[test]
fn invalid_input_is_refused_not_panicked_on() {
    let mut b = SceneBuilder::new();
    let fixed = || Placement::Static(Transform::IDENTITY);
    assert!(
        b.add(
            Shape::Sphere {
                center: Vec3::ZERO,
                radius: 0.0
            },
            fixed()
        )
        .is_err()
    );
    assert!(
        b.add(
            Shape::Sphere {
                center: Vec3::NAN,
                radius: 1.0
            },
            fixed()
        )
        .is_err()
    );
    let flat = Shape::Quad {
        origin: Vec3::ZERO,
        edge_u: Vec3::X,
        edge_v: Vec3::X * 2.0,
    };
    let err = b.add(flat, fixed()).unwrap_err();
    assert!(err.to_string().contains("parallel"), "{err}");
    // Nothing was added: the scene is empty and answers every ray with a miss.
    let scene = b.build().unwrap();
    assert_eq!(scene.instance_count(), 0);
    let r = ray([0.0; 3], [0.0, 0.0, 1.0], 0.0);
    assert!(scene.intersect(&r).is_none() && !scene.occluded(&r));

    // Rays that cannot hit anything are misses, not panics.
    let scene = one(
        Shape::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        },
        Placement::Static(Transform::IDENTITY),
    );
    for bad in [
        ray([0.0, 0.0, 5.0], [0.0, 0.0, 0.0], 0.0),
        ray([0.0, 0.0, 5.0], [f32::NAN, 0.0, -1.0], 0.0),
        ray([f32::INFINITY, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0),
        ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0).with_range(3.0, 1.0),
        ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0).with_range(f32::NAN, 10.0),
    ] {
        assert!(scene.intersect(&bad).is_none());
        assert!(!scene.occluded(&bad));
    }
}

#[test]
fn shapes_beyond_the_coordinate_limit_are_refused_not_built() {
    use obscura_accel::{MAX_COORDINATE, Placement, SceneBuilder, Shape};
    use obscura_space::{AnimatedTransform, Object, Transform, World};
    // A radius whose box overflows f32 once doubled (found by the scene-mutation proptest: it
    // made obvhs's CWBVH conversion assert).
    let mut b = SceneBuilder::new();
    let huge = Shape::Sphere {
        center: glam::Vec3::ZERO,
        radius: 3.4e38,
    };
    assert!(b.add(huge, Placement::Static(Transform::IDENTITY)).is_err());
    // Just inside the limit is fine; just outside, including by moving there, is not.
    let inside = Shape::Sphere {
        center: glam::Vec3::ZERO,
        radius: MAX_COORDINATE * 0.5,
    };
    assert!(
        b.add(inside, Placement::Static(Transform::IDENTITY))
            .is_ok()
    );
    let small = Shape::Sphere {
        center: glam::Vec3::ZERO,
        radius: 1.0,
    };
    let far =
        Transform::<World, Object>::translate(glam::Vec3::new(2.0 * MAX_COORDINATE, 0.0, 0.0))
            .unwrap();
    let moving = AnimatedTransform::new(Transform::IDENTITY, 0.0, far, 1.0).unwrap();
    assert!(b.add(small.clone(), Placement::Moving(moving)).is_err());
    assert!(b.add(small, Placement::Static(Transform::IDENTITY)).is_ok());
    assert!(b.build().is_ok());
}
