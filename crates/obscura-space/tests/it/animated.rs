use super::{axis, vec3};
use obscura_space::{AnimatedTransform, Bounds3, Object, Point3, SpaceError, Transform, World};
use proptest::prelude::*;

type Wo = Transform<World, Object>;
type Ww = Transform<World, World>;
type Oo = Transform<Object, Object>;

/// A rigid keyframe (rotation, then translation) with a uniform scale.
fn rigid() -> impl Strategy<Value = Wo> {
    (0.5f32..2.0, -180.0f32..180.0, axis(), vec3(20.0)).prop_map(|(s, deg, ax, t)| {
        Ww::translate(t).unwrap()
            * Wo::rotate(deg, ax).unwrap()
            * Oo::scale(glam::Vec3::splat(s)).unwrap()
    })
}

/// A keyframe with non-uniform scale applied before rotation and translation.
fn trs() -> impl Strategy<Value = Wo> {
    (vec3(1.5), -180.0f32..180.0, axis(), vec3(20.0)).prop_map(|(s, deg, ax, t)| {
        let s = s.abs() + glam::Vec3::splat(0.5);
        Ww::translate(t).unwrap() * Wo::rotate(deg, ax).unwrap() * Oo::scale(s).unwrap()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn keyframes_are_hit_exactly(a in trs(), b in trs(), t0 in -1.0f32..1.0, len in 0.01f32..2.0) {
        let t1 = t0 + len;
        let anim = AnimatedTransform::new(a, t0, b, t1).unwrap();
        prop_assert_eq!(anim.at(t0), a);
        prop_assert_eq!(anim.at(t1), b);
        prop_assert_eq!(anim.at(t0 - 1.0), a);
        prop_assert_eq!(anim.at(t1 + 1.0), b);
    }

    /// The forward-only `matrix_at` is `at(time).matrix()` bit for bit, at keyframes, between
    /// them and outside, and the interpolated inverse inverts (scaled keyframes included).
    #[test]
    fn matrix_at_is_the_matrix_of_at(a in trs(), b in trs(), c in trs(), t in -0.5f32..2.5) {
        let anim = AnimatedTransform::from_keyframes(vec![(0.0, a), (1.0, b), (2.0, c)]).unwrap();
        for time in [t, 0.0, 1.0, 2.0] {
            prop_assert_eq!(anim.matrix_at(time), anim.at(time).matrix());
        }
        let m = anim.at(t);
        let residual = m.matrix() * m.inverse_matrix() - glam::Mat4::IDENTITY;
        prop_assert!(residual.to_cols_array().iter().all(|r| r.abs() < 1e-4), "{residual:?}");
    }

    /// A turn about one axis from angle `a0` to `a1` (less than half a turn apart, so slerp
    /// takes this way round) is the rotation by `a0 + u (a1 - a0)` at fraction `u`: the
    /// slerp's cached angle and 1 / sin(angle) against the closed form.
    #[test]
    fn slerp_turns_at_constant_speed(a0 in -180f32..180.0, turn in -179f32..179.0, u in 0f32..1.0) {
        let axis = glam::Vec3::new(0.3, -0.5, 0.8);
        let start = Wo::rotate(a0, axis).unwrap();
        let end = Wo::rotate(a0 + turn, axis).unwrap();
        let anim = AnimatedTransform::new(start, 0.0, end, 1.0).unwrap();
        let want = Wo::rotate(a0 + u * turn, axis).unwrap().matrix();
        let got = anim.at(u).matrix();
        prop_assert!((got - want).to_cols_array().iter().all(|d| d.abs() < 2e-5), "{got:?} != {want:?}");
    }

    #[test]
    fn rigid_keyframes_give_rigid_motion(a in rigid(), b in rigid(), u in 0.0f32..1.0) {
        let anim = AnimatedTransform::new(a, 0.0, b, 1.0).unwrap();
        let linear = glam::Mat3::from_mat4(anim.at(u).matrix());
        // Columns orthogonal and of one length: M^T M = s^2 I (no shear, uniform scale).
        let gram = linear.transpose() * linear;
        let s2 = gram.x_axis.x;
        for (i, col) in gram.to_cols_array_2d().iter().enumerate() {
            for (j, g) in col.iter().enumerate() {
                let want = if i == j { s2 } else { 0.0 };
                prop_assert!((g - want).abs() < 1e-4 * s2.max(1.0), "gram {gram:?}");
            }
        }
        // And the stored inverse inverts.
        let t = anim.at(u);
        let residual = t.matrix() * t.inverse_matrix() - glam::Mat4::IDENTITY;
        prop_assert!(residual.to_cols_array().iter().all(|r| r.abs() < 1e-4));
    }

    #[test]
    fn translation_is_interpolated_linearly(a in vec3(10.0), b in vec3(10.0), u in 0.0f32..1.0) {
        let anim = AnimatedTransform::new(Wo::translate(a).unwrap(), 0.0, Wo::translate(b).unwrap(), 1.0).unwrap();
        let p = anim.point(Point3::new(0.0, 0.0, 0.0), u).to_glam();
        prop_assert!((p - a.lerp(b, u)).length() < 1e-4 * (1.0 + a.length() + b.length()));
    }

    #[test]
    fn motion_bounds_contain_every_instant_and_are_tight(
        a in trs(), b in trs(), lo in vec3(3.0), size in vec3(3.0),
    ) {
        let anim = AnimatedTransform::new(a, 0.0, b, 1.0).unwrap();
        let bounds = Bounds3::<Object>::new(Point3::from_glam(lo), Point3::from_glam(lo + size.abs() + glam::Vec3::splat(0.01)));
        let moving = anim.motion_bounds(bounds);
        // Dense sampling: every corner at 2001 instants lies inside...
        let mut sampled = Bounds3::<World>::EMPTY;
        for i in 0..=2000 {
            let t = anim.at(i as f32 / 2000.0);
            for c in bounds.corners() {
                let p = t * c;
                prop_assert!(moving.contains(p), "{moving:?} misses {p:?} at {}", i as f32 / 2000.0);
                sampled = sampled.union_point(p);
            }
        }
        // ...and the box is no more than 1% of its size (plus rounding) larger than the
        // sampled extent on any side.
        let slack_lo = (sampled.min - moving.min).to_glam();
        let slack_hi = (moving.max - sampled.max).to_glam();
        let allowed = 0.01 * sampled.diagonal().length() + 1e-3;
        prop_assert!(slack_lo.max_element() <= allowed && slack_hi.max_element() <= allowed,
            "slack {slack_lo:?} {slack_hi:?} allowed {allowed}");
    }
}

#[test]
fn half_turn_motion_bounds_include_the_swept_arc() {
    // A unit cube at x in [2, 3] rotating 180 degrees about +y sweeps through z = +-3 at the
    // quarter turn, far outside both keyframes' boxes (z in [-0.5, 0.5] and, mirrored, the same).
    let a = Wo::translate(glam::Vec3::ZERO).unwrap();
    let b = Wo::rotate(179.0, glam::Vec3::Y).unwrap();
    let anim = AnimatedTransform::new(a, 0.0, b, 1.0).unwrap();
    let cube = Bounds3::<Object>::new(Point3::new(2.0, -0.5, -0.5), Point3::new(3.0, 0.5, 0.5));
    let moving = anim.motion_bounds(cube);
    // Rotating +x towards -z (right-hand rule about +y), the far corner reaches radius
    // sqrt(3^2 + 0.5^2) = 3.041 at some instant, so the box must reach z <= -3.04.
    assert!(moving.min.z <= -3.04, "{moving:?}");
    assert!(moving.min.z >= -3.1, "{moving:?}");
}

#[test]
fn mirrored_keyframes_interpolate_when_both_are_mirrored() {
    let m = Wo::scale(glam::Vec3::new(-1.0, 1.0, 1.0)).unwrap();
    let a = m;
    let b = Ww::rotate(90.0, glam::Vec3::Y).unwrap() * m;
    let anim = AnimatedTransform::new(a, 0.0, b, 1.0).unwrap();
    assert!(anim.at(0.5).swaps_handedness());
    // One mirrored, one not: an error, not a collapse through a singular matrix.
    assert!(matches!(
        AnimatedTransform::new(a, 0.0, Wo::IDENTITY, 1.0),
        Err(SpaceError::BadKeyframes(_))
    ));
}

#[test]
fn bad_keyframe_times_are_errors() {
    let a = Wo::translate(glam::Vec3::X).unwrap();
    assert!(AnimatedTransform::new(a, 1.0, Wo::IDENTITY, 0.0).is_err());
    assert!(AnimatedTransform::new(a, f32::NAN, Wo::IDENTITY, 1.0).is_err());
    assert!(AnimatedTransform::<World, Object>::from_keyframes(vec![]).is_err());
    // Equal times with equal transforms: simply fixed.
    assert!(
        !AnimatedTransform::new(a, 0.0, a, 0.0)
            .unwrap()
            .is_animated()
    );
}
