use super::{assert_close, axis, transform, vec3};
use obscura_space::{
    Bounds3, Camera, Normal3, Object, Point3, Ray, SpaceError, Transform, Vector3, World,
};
use proptest::prelude::*;

/// The magnitude the tolerance scales with: the point, and the translation it went through.
fn magnitude(t: &Transform<World, Object>, p: glam::Vec3) -> f32 {
    1.0 + p.length()
        + t.matrix().w_axis.truncate().length()
        + t.inverse_matrix().w_axis.truncate().length()
}

proptest! {
    #[test]
    fn point_round_trip(t in transform::<World, Object>(), p in vec3(100.0)) {
        let p_object = Point3::<Object>::from_glam(p);
        let back = t.inverse() * (t * p_object);
        assert_close(back.to_glam(), p, magnitude(&t, p));
    }

    #[test]
    fn vector_and_normal_round_trip(t in transform::<World, Object>(), v in vec3(10.0)) {
        let back = t.inverse() * (t * Vector3::<Object>::from_glam(v));
        assert_close(back.to_glam(), v, 1.0 + v.length());
        let back = t.inverse() * (t * Normal3::<Object>::from_glam(v));
        assert_close(back.to_glam(), v, 1.0 + v.length());
    }

    #[test]
    fn composition_matches_sequential_application(
        a in transform::<World, Camera>(),
        b in transform::<Camera, Object>(),
        p in vec3(10.0),
    ) {
        let p_object = Point3::<Object>::from_glam(p);
        let composed: Transform<World, Object> = a * b;
        let one_by_one = a * (b * p_object);
        let scale = one_by_one.to_glam().length() + a.matrix().w_axis.truncate().length() * 4.0 + 10.0;
        assert_close((composed * p_object).to_glam(), one_by_one.to_glam(), scale);
        // The stored inverse of the composition is the composition of the inverses.
        let back = composed.inverse() * one_by_one;
        assert_close(back.to_glam(), p, scale * 16.0);
    }

    #[test]
    fn normals_stay_perpendicular_to_tangents(t in transform::<World, Object>(), n in axis(), w in axis()) {
        // A tangent: the part of w perpendicular to n.
        let n = n.normalize();
        let tangent = w - n * w.dot(n);
        prop_assume!(tangent.length() > 0.1);
        let n_world = t * Normal3::<Object>::from_glam(n);
        let t_world = t * Vector3::<Object>::from_glam(tangent);
        let cos = n_world.normalize().dot(t_world.normalize());
        prop_assert!(cos.abs() < 1e-4, "cos = {cos}");
    }

    #[test]
    fn bounds_hold_mapped_points(t in transform::<World, Object>(), a in vec3(10.0), b in vec3(10.0), f in vec3(1.0)) {
        let b_object = Bounds3::<Object>::new(Point3::from_glam(a), Point3::from_glam(b));
        let inside = a + (b - a) * (f * 0.5 + 0.5);
        let p_world = t * Point3::<Object>::from_glam(inside);
        let b_world = (t * b_object).expand(1e-4 * magnitude(&t, inside));
        prop_assert!(b_world.contains(p_world), "{b_world:?} misses {p_world:?}");
    }

    #[test]
    fn rays_keep_their_parameter(t in transform::<World, Object>(), o in vec3(10.0), d in axis(), s in 0.0f32..10.0) {
        let r = Ray::<Object>::new(Point3::from_glam(o), Vector3::from_glam(d), 0.25).with_range(0.5, 7.0);
        let r_world = t * r;
        prop_assert_eq!((r_world.time, r_world.t_min, r_world.t_max), (0.25, 0.5, 7.0));
        assert_close(r_world.at(s).to_glam(), (t * r.at(s)).to_glam(), magnitude(&t, r.at(s).to_glam()));
    }

    #[test]
    fn look_at_puts_target_on_plus_z_and_up_in_the_yz_half_plane(
        eye in vec3(50.0), to_target in axis(), up in axis(), dist in 0.1f32..100.0,
    ) {
        let dir = to_target.normalize();
        prop_assume!(dir.cross(up.normalize()).length() > 1e-3);
        let target = eye + dir * dist;
        let world_from_camera = Transform::<World, Camera>::look_at(
            Point3::from_glam(eye), Point3::from_glam(target), Vector3::from_glam(up)).unwrap();
        let camera_from_world = world_from_camera.inverse();
        let t_camera = camera_from_world * Point3::<World>::from_glam(target);
        assert_close(t_camera.to_glam(), glam::Vec3::new(0.0, 0.0, dist), 1.0 + eye.length() + dist);
        let up_camera = camera_from_world * Vector3::<World>::from_glam(up);
        prop_assert!(up_camera.x.abs() < 1e-5 * up.length());
        prop_assert!(up_camera.y >= 0.0);
        prop_assert!(world_from_camera.swaps_handedness());
    }

    #[test]
    fn swaps_handedness_counts_mirrors(deg in -360.0f32..360.0, ax in axis(), s in 0.25f32..4.0) {
        let rot = Transform::<World, Object>::rotate(deg, ax).unwrap();
        prop_assert!(!rot.swaps_handedness());
        let mirror = Transform::<Object, Object>::scale(glam::Vec3::new(-s, s, s)).unwrap();
        prop_assert!((rot * mirror).swaps_handedness());
    }
}

#[test]
fn look_at_of_the_scene_format_example() {
    // eye (0,0,0), target (0,0,-1), up (0,1,0): dir = (0,0,-1); right = dir x up = (1,0,0);
    // true_up = right x dir = (0,1,0). So camera +x is world +x and camera +y is world +y.
    let world_from_camera = Transform::<World, Camera>::look_at(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(0.0, 0.0, -1.0),
        Vector3::new(0.0, 1.0, 0.0),
    )
    .unwrap();
    assert_eq!(
        world_from_camera * Vector3::<Camera>::new(1.0, 0.0, 0.0),
        Vector3::new(1.0, 0.0, 0.0)
    );
    assert_eq!(
        world_from_camera * Vector3::<Camera>::new(0.0, 1.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0)
    );
    assert_eq!(
        world_from_camera * Vector3::<Camera>::new(0.0, 0.0, 1.0),
        Vector3::new(0.0, 0.0, -1.0)
    );
}

#[test]
fn look_at_with_an_offset_eye_and_z_up() {
    // eye (1,2,3) looking along world +x with z up: dir = (1,0,0), right = (1,0,0)x(0,0,1) =
    // (0,-1,0), true_up = (0,-1,0)x(1,0,0) = (0,0,1). Camera point (2,3,4) lands at
    // eye + 2 right + 3 up + 4 dir = (1+4, 2-2, 3+3) = (5, 0, 6).
    let world_from_camera = Transform::<World, Camera>::look_at(
        Point3::new(1.0, 2.0, 3.0),
        Point3::new(9.0, 2.0, 3.0),
        Vector3::new(0.0, 0.0, 5.0),
    )
    .unwrap();
    assert_eq!(
        world_from_camera * Point3::<Camera>::new(2.0, 3.0, 4.0),
        Point3::new(5.0, 0.0, 6.0)
    );
    assert_eq!(
        world_from_camera.inverse() * Point3::<World>::new(5.0, 0.0, 6.0),
        Point3::new(2.0, 3.0, 4.0)
    );
}

#[test]
fn matrices_are_read_row_major_and_points_get_the_homogeneous_divide() {
    // Rows: x' = x + 1, y' = 2y, z' = 1, w' = z. The point (1, 1, 2) goes to (2, 2, 1, 2),
    // which divides to (1, 1, 0.5).
    #[rustfmt::skip]
    let t = Transform::<World, Object>::from_rows([
        1.0, 0.0, 0.0, 1.0,
        0.0, 2.0, 0.0, 0.0,
        0.0, 0.0, 0.0, 1.0,
        0.0, 0.0, 1.0, 0.0,
    ])
    .unwrap();
    assert_eq!(
        t * Point3::<Object>::new(1.0, 1.0, 2.0),
        Point3::new(1.0, 1.0, 0.5)
    );
}

#[test]
fn rotation_follows_the_right_hand_rule() {
    // 90 degrees about +z takes +x to +y.
    let t = Transform::<World, Object>::rotate(90.0, glam::Vec3::Z).unwrap();
    let v = t * Vector3::<Object>::new(1.0, 0.0, 0.0);
    assert_close(v.to_glam(), glam::Vec3::Y, 1.0);
}

#[test]
fn normals_use_the_inverse_transpose() {
    // Squash y by 1/2: the plane x + y = 0 (normal (1,1,0)) becomes x + 2y' = 0, normal (1,2,0).
    let t = Transform::<World, Object>::scale(glam::Vec3::new(1.0, 0.5, 1.0)).unwrap();
    assert_eq!(
        t * Normal3::<Object>::new(1.0, 1.0, 0.0),
        Normal3::new(1.0, 2.0, 0.0)
    );
}

#[test]
fn degenerate_input_is_an_error_not_a_nan() {
    type Wc = Transform<World, Camera>;
    let o = Point3::<World>::new(0.0, 0.0, 0.0);
    let z = Point3::<World>::new(0.0, 0.0, -1.0);
    assert_eq!(
        Wc::look_at(o, z, Vector3::new(0.0, 0.0, 0.0)),
        Err(SpaceError::DegenerateLookAt("up has zero length"))
    );
    assert_eq!(
        Wc::look_at(o, z, Vector3::new(0.0, 0.0, 3.0)),
        Err(SpaceError::DegenerateLookAt(
            "up is parallel to the view direction"
        ))
    );
    assert_eq!(
        Wc::look_at(o, o, Vector3::new(0.0, 1.0, 0.0)),
        Err(SpaceError::DegenerateLookAt(
            "eye and target are the same point"
        ))
    );
    assert!(matches!(
        Wc::look_at(
            Point3::new(f32::NAN, 0.0, 0.0),
            z,
            Vector3::new(0.0, 1.0, 0.0)
        ),
        Err(SpaceError::NonFinite { .. })
    ));
    let mut singular = [0.0f32; 16];
    singular[0] = 1.0;
    singular[5] = 1.0;
    singular[15] = 1.0; // z row all zero
    assert!(matches!(
        Wc::from_rows(singular),
        Err(SpaceError::Singular { .. })
    ));
    assert!(matches!(
        Wc::scale(glam::Vec3::new(1.0, 0.0, 1.0)),
        Err(SpaceError::Singular { .. })
    ));
    assert_eq!(
        Wc::rotate(30.0, glam::Vec3::ZERO),
        Err(SpaceError::ZeroAxis)
    );
    assert!(matches!(
        Wc::translate(glam::Vec3::new(f32::INFINITY, 0.0, 0.0)),
        Err(SpaceError::NonFinite { .. })
    ));
    let mut with_nan = glam::Mat4::IDENTITY;
    with_nan.z_axis.y = f32::NAN;
    assert!(matches!(
        Wc::from_matrix(with_nan),
        Err(SpaceError::NonFinite { .. })
    ));
}
