//! Camera motion: a moving camera equals its keyframes at shutter open and close, and ray
//! times follow the shutter.

use crate::{assert_close2, assert_close3, look_strategy};
use obscura_camera::{
    AnyCamera, Camera, CameraBase, CameraSample, FilmGeometry, FovAxis, LookAt, PerspectiveCamera,
    Shutter, ThinLens, look_at_pose,
};
use obscura_space::{Point2, Point3};
use proptest::prelude::*;

/// The three models over one base, the projective ones with a thin lens.
fn models(base: CameraBase) -> [AnyCamera; 3] {
    crate::models(base, ThinLens::new(0.1, 3.0).unwrap())
}

proptest! {
    #![proptest_config(crate::cases(128))]

    #[test]
    fn moving_camera_matches_its_keyframes(
        start in look_strategy(), end in look_strategy(),
        open in -5f32..5.0, length in 0.1f32..3.0,
        fx in 0f32..1.0, fy in 0f32..1.0, u in 0f32..1.0, v in 0f32..1.0,
    ) {
        let shutter = Shutter::new(open, open + length).unwrap();
        let film = FilmGeometry::new([32, 24], None, None).unwrap();
        let moving = CameraBase::new(look_at_pose(start, Some(end), shutter).unwrap(), shutter, film);
        let fixed_start = CameraBase::new(look_at_pose(start, None, shutter).unwrap(), shutter, film);
        let fixed_end = CameraBase::new(look_at_pose(end, None, shutter).unwrap(), shutter, film);
        let p_film = Point2::new(fx * 32.0, fy * 24.0);
        for ((m, a), z) in models(moving).iter().zip(models(fixed_start)).zip(models(fixed_end)) {
            // Shutter open: u = 0 maps to `open` exactly, where the pose is the first keyframe.
            let s0 = CameraSample { p_film, p_lens: glam::Vec2::new(u, v), time: 0.0 };
            let rm = m.generate_ray(&s0).unwrap().ray;
            let ra = a.generate_ray(&s0).unwrap().ray;
            prop_assert_eq!(rm.time, shutter.open);
            prop_assert_eq!(rm, ra);
            // Shutter close: u = 1 maps to `close` (up to rounding of open + 1 * length).
            let s1 = CameraSample { time: 1.0, ..s0 };
            let rm = m.generate_ray(&s1).unwrap().ray;
            let rz = z.generate_ray(&s1).unwrap().ray;
            prop_assert!((rm.time - shutter.close).abs() <= 1e-6 * (1.0 + shutter.close.abs()));
            assert_close3(rm.origin.to_glam(), rz.origin.to_glam(), 1e-3);
            assert_close3(rm.direction.to_glam(), rz.direction.to_glam(), 1e-3);
            // Projection at the keyframe times agrees too.
            let p_world = Point3::new(0.3, -0.2, 0.5);
            if let (Some(pm), Some(pz)) = (m.project(p_world, shutter.close), z.project(p_world, shutter.close)) {
                assert_close2(pm.to_glam(), pz.to_glam(), 1e-2);
            }
            prop_assert_eq!(m.project(p_world, shutter.open), a.project(p_world, shutter.open));
        }
    }
}

/// A camera sliding along world +x: halfway through the shutter its eye is halfway along, and
/// ray times follow `open + u (close - open)`.
#[test]
fn halfway_through_the_shutter() {
    let shutter = Shutter::new(2.0, 4.0).unwrap();
    let up = obscura_space::Vector3::new(0.0, 1.0, 0.0);
    let start = LookAt::new(Point3::new(0.0, 0.0, 0.0), Point3::new(0.0, 0.0, -1.0), up);
    let end = LookAt::new(Point3::new(2.0, 0.0, 0.0), Point3::new(2.0, 0.0, -1.0), up);
    let base = CameraBase::new(
        look_at_pose(start, Some(end), shutter).unwrap(),
        shutter,
        FilmGeometry::new([8, 8], None, None).unwrap(),
    );
    let camera = PerspectiveCamera::new(base, 90.0, FovAxis::Smaller, ThinLens::PINHOLE).unwrap();
    for (u, time, eye_x) in [
        (0.0, 2.0, 0.0),
        (0.25, 2.5, 0.5),
        (0.5, 3.0, 1.0),
        (0.75, 3.5, 1.5),
    ] {
        let sample = CameraSample {
            time: u,
            ..CameraSample::at(Point2::new(4.0, 4.0))
        };
        let ray = camera.generate_ray(&sample).unwrap().ray;
        assert_eq!(ray.time, time);
        assert_close3(ray.origin.to_glam(), glam::Vec3::new(eye_x, 0.0, 0.0), 1e-5);
        // Pure translation: the image centre still looks down -z.
        assert_close3(ray.direction.to_glam(), -glam::Vec3::Z, 1e-5);
        // A point straight ahead of that eye projects to the image centre at that time.
        let p = camera.project(Point3::new(eye_x, 0.0, -3.0), time).unwrap();
        assert_close2(p.to_glam(), glam::Vec2::new(4.0, 4.0), 1e-4);
    }
}
