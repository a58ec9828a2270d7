//! Thin lenses: focus, the pinhole limit, the aperture, projection through the lens centre.

use crate::{assert_close2, assert_close3, projective_strategy, raster_in};
use obscura_camera::{AnyCamera, Camera, CameraSample, ThinLens};
use obscura_space::Point3;
use proptest::prelude::*;

/// The same camera model and parameters with another lens.
fn with_lens(camera: &AnyCamera, lens: ThinLens) -> AnyCamera {
    match camera {
        AnyCamera::Perspective(c) => obscura_camera::PerspectiveCamera::new(
            c.projective().base().clone(),
            c.fov_degrees(),
            c.fov_axis(),
            lens,
        )
        .unwrap()
        .into(),
        AnyCamera::Orthographic(c) => {
            obscura_camera::OrthographicCamera::new(c.projective().base().clone(), lens)
                .unwrap()
                .into()
        }
        _ => unreachable!(),
    }
}

fn lens_of(camera: &AnyCamera) -> ThinLens {
    match camera {
        AnyCamera::Perspective(c) => c.lens().clone(),
        AnyCamera::Orthographic(c) => c.lens().clone(),
        _ => unreachable!(),
    }
}

proptest! {
    #![proptest_config(crate::cases(256))]

    /// Every lens sample of one film point meets the pinhole ray of that point on the plane of
    /// focus (camera z = focal distance), and projects back to the film point there.
    #[test]
    fn lens_samples_meet_on_the_focal_plane(
        camera in projective_strategy(true),
        fx in 0.1f32..0.9, fy in 0.1f32..0.9,
        lens_samples in proptest::collection::vec((0f32..1.0, 0f32..1.0), 4),
        blades in prop_oneof![Just(0u32), 3u32..9],
    ) {
        let lens = lens_of(&camera).with_blades(blades, 10.0).unwrap();
        let camera = with_lens(&camera, lens.clone());
        let p_film = raster_in(camera.film().resolution(), fx, fy);
        let camera_from_world = camera.world_from_camera().at(0.0).inverse();
        let pinhole = with_lens(&camera, ThinLens::PINHOLE);
        let r0 = camera_from_world.ray(pinhole.generate_ray(&CameraSample::at(p_film)).unwrap().ray);
        let focus = lens.focal_distance;
        let at_focus = |r: obscura_space::Ray<obscura_space::Camera>| {
            r.at((focus - r.origin.z) / r.direction.z)
        };
        let p_focus = at_focus(r0);
        // Rounding of points ~17 + |p_focus| from the world origin, through two rigid maps.
        // And the intersection with z = focus amplifies direction rounding by 1 / d.z.
        let tol = 4e-4 + 4e-7 * p_focus.to_vector().length() / r0.direction.z;
        for (u, v) in lens_samples {
            let sample = CameraSample { p_film, p_lens: glam::Vec2::new(u, v), time: 0.0 };
            let ray = camera.generate_ray(&sample).unwrap().ray;
            prop_assert!((ray.direction.length() - 1.0).abs() < 1e-5);
            let r = camera_from_world.ray(ray);
            // The lens point is on z = 0, within the aperture around the pinhole origin. Up to
            // rounding relative to the points' sizes (orthographic origins lie up to ~2000 off
            // axis, where one f32 step is 1.2e-4): 1e-6 = 16.8u per unit, the budget of
            // `perspective_converge_orthographic_parallel` plus ~1u for adding the lens offset.
            let allowance = 1e-6 * (1.0 + ray.origin.to_vector().length() + r.origin.to_vector().length());
            prop_assert!(r.origin.z.abs() <= allowance, "lens point z {} allowance {allowance}", r.origin.z);
            let offset = glam::Vec2::new(r.origin.x - r0.origin.x, r.origin.y - r0.origin.y);
            prop_assert!(offset.length() <= lens.radius * (1.0 + 1e-4) + 1e-4);
            assert_close3(at_focus(r).to_glam(), p_focus.to_glam(), tol);
        }
        // The world point in focus projects (pinhole through the lens centre) to the film point,
        // when the plane of focus lies inside the clip range (else it is invisible: None).
        let p_world = camera.world_from_camera().at(0.0).point(p_focus);
        let base = match &camera {
            AnyCamera::Perspective(c) => c.projective().base(),
            AnyCamera::Orthographic(c) => c.projective().base(),
            _ => unreachable!(),
        };
        // (Within 0.1% of a clip plane rounding decides; those cases are not checked.)
        let inside = focus > base.near * 1.001 && focus < base.far * 0.999;
        let outside = focus < base.near * 0.999 || focus > base.far * 1.001;
        let back = camera.project(p_world, 0.0);
        if inside || outside {
            prop_assert_eq!(back.is_some(), inside);
        }
        if let Some(back) = back {
            let [w, h] = camera.film().resolution().map(|r| r as f32);
            assert_close2(back.to_glam(), p_film.to_glam(), 1e-3 * w.max(h));
        }
    }

    /// The lens centre sample gives the pinhole ray, and as the radius goes to zero every
    /// lens sample does.
    #[test]
    fn zero_radius_is_the_pinhole(camera in projective_strategy(true), fx in 0f32..1.0, fy in 0f32..1.0, u in 0f32..1.0, v in 0f32..1.0) {
        let p_film = raster_in(camera.film().resolution(), fx, fy);
        let pinhole = with_lens(&camera, ThinLens::PINHOLE).generate_ray(&CameraSample::at(p_film)).unwrap().ray;
        let centre = camera.generate_ray(&CameraSample::at(p_film)).unwrap().ray;
        assert_close3(centre.origin.to_glam(), pinhole.origin.to_glam(), 1e-5);
        assert_close3(centre.direction.to_glam(), pinhole.direction.to_glam(), 1e-5);
        let focus = lens_of(&camera).focal_distance;
        let tiny = with_lens(&camera, ThinLens::new(1e-7, focus).unwrap());
        let sample = CameraSample { p_film, p_lens: glam::Vec2::new(u, v), time: 0.0 };
        let r = tiny.generate_ray(&sample).unwrap().ray;
        assert_close3(r.origin.to_glam(), pinhole.origin.to_glam(), 1e-5);
        assert_close3(r.direction.to_glam(), pinhole.direction.to_glam(), 1e-5);
        // A real lens does move the ray (so the comparison above can fail).
        let wide = with_lens(&camera, ThinLens::new(0.5, focus).unwrap());
        let corner = CameraSample { p_film, p_lens: glam::Vec2::new(0.95, 0.95), time: 0.0 };
        let r = wide.generate_ray(&corner).unwrap().ray;
        prop_assert!(r.origin.distance(pinhole.origin) > 0.3);
    }
}

/// The orthographic lens point is offset from the film point's own ray origin, not from the
/// camera centre: a film point far off-axis keeps its lens rays near its own origin.
#[test]
fn orthographic_lens_is_centred_on_the_film_point() {
    let base = crate::base_at(crate::identity_look(), [10, 10], None, 0.0, 100.0);
    let lens = ThinLens::new(0.1, 4.0).unwrap();
    let camera = obscura_camera::OrthographicCamera::new(base, lens).unwrap();
    // Pixel (9, 0), centre (9.5, 0.5): window [-1, 1]^2, NDC (0.95, 0.05), x = -1 + 0.95 * 2
    // = 0.9, y = 1 - 0.05 * 2 = 0.9: the film point's ray starts at (0.9, 0.9, 0).
    for u in [0.0, 0.3, 0.7, 0.99] {
        let sample = CameraSample {
            p_film: obscura_space::Point2::new(9.5, 0.5),
            p_lens: glam::Vec2::new(u, 1.0 - u),
            time: 0.0,
        };
        let ray = camera.generate_ray(&sample).unwrap().ray;
        // Identity look: camera (x, y, z) is world (x, y, -z).
        let offset = ray.origin.to_glam() - glam::Vec3::new(0.9, 0.9, 0.0);
        assert!(offset.length() <= 0.1 + 1e-6, "origin {:?}", ray.origin);
        // And it reaches the film point's ray at z = 4 (world z = -4).
        let p = ray.at(4.0 / -ray.direction.z);
        assert_close3(
            p.to_glam(),
            Point3::<obscura_space::World>::new(0.9, 0.9, -4.0).to_glam(),
            1e-5,
        );
    }
}
