//! Which sample dimensions a camera reads. When `uses_lens_sample` or `uses_time_sample` says
//! no, renderers skip drawing that dimension, so the ray must not depend on it; when it says
//! yes, the ray must.

use crate::{look_strategy, models};
use obscura_camera::{
    Camera, CameraBase, CameraSample, FilmGeometry, Shutter, ThinLens, look_at_pose,
};
use obscura_space::Point2;
use proptest::prelude::*;

proptest! {
    #![proptest_config(crate::cases(128))]

    #[test]
    fn a_dimension_the_camera_does_not_use_does_not_change_its_ray(
        start in look_strategy(), end in look_strategy(), moving in any::<bool>(),
        open in -2f32..2.0, length in prop_oneof![Just(0.0f32), 0.01f32..3.0],
        radius in prop_oneof![Just(0.0f32), 0.01f32..0.5], blades in prop_oneof![Just(0u32), 3u32..8],
        fx in 0f32..1.0, fy in 0f32..1.0,
        lens_a in (0f32..1.0, 0f32..1.0), lens_b in (0f32..1.0, 0f32..1.0),
        time_a in 0f32..1.0, time_b in 0f32..1.0,
    ) {
        let shutter = Shutter::new(open, open + length).unwrap();
        let film = FilmGeometry::new([40, 30], None, None).unwrap();
        let pose = look_at_pose(start, moving.then_some(end), shutter).unwrap();
        let lens = ThinLens::new(radius.max(1e-3), 2.0).unwrap().with_blades(blades, 10.0).unwrap();
        let lens = if radius == 0.0 { ThinLens::PINHOLE } else { lens };
        let p_film = Point2::new(fx * 40.0, fy * 30.0);
        let sample = |(u, v): (f32, f32), time: f32| CameraSample {
            p_film,
            p_lens: glam::Vec2::new(u, v),
            time,
        };
        for camera in models(CameraBase::new(pose.clone(), shutter, film), lens) {
            let ray = |s: CameraSample| camera.generate_ray(&s).unwrap().ray;
            if !camera.uses_lens_sample() {
                prop_assert_eq!(ray(sample(lens_a, time_a)), ray(sample(lens_b, time_a)));
            } else {
                // Opposite corners of the aperture give rays from different points.
                let (near, far) = (ray(sample((0.05, 0.05), time_a)), ray(sample((0.95, 0.95), time_a)));
                prop_assert_ne!(near.origin, far.origin);
            }
            if !camera.uses_time_sample() {
                prop_assert_eq!(ray(sample(lens_a, time_a)), ray(sample(lens_a, time_b)));
            } else {
                let (early, late) = (ray(sample(lens_a, 0.0)), ray(sample(lens_a, 0.5)));
                prop_assert!(early.time < late.time, "{} !< {}", early.time, late.time);
            }
        }
    }
}

/// The scene format's defaults: a pinhole with the unit shutter reads the time and not the
/// lens; an instantaneous shutter reads neither.
#[test]
fn a_pinhole_reads_the_time_only_while_the_shutter_is_open() {
    let film = FilmGeometry::new([8, 8], None, None).unwrap();
    let look = crate::identity_look();
    for (shutter, uses_time) in [
        (Shutter::UNIT, true),
        (Shutter::new(1.0, 1.0).unwrap(), false),
    ] {
        let base = CameraBase::new(look_at_pose(look, None, shutter).unwrap(), shutter, film);
        for camera in models(base, ThinLens::PINHOLE) {
            assert!(!camera.uses_lens_sample());
            assert_eq!(camera.uses_time_sample(), uses_time);
        }
    }
    let base = CameraBase::new(
        look_at_pose(look, None, Shutter::UNIT).unwrap(),
        Shutter::UNIT,
        film,
    );
    let [perspective, orthographic, environment] = models(base, ThinLens::new(0.1, 2.0).unwrap());
    assert!(perspective.uses_lens_sample() && orthographic.uses_lens_sample());
    assert!(!environment.uses_lens_sample());
}
