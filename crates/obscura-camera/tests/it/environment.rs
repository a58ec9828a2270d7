//! The environment camera: unit directions covering the sphere, its orientation, the inverse.

use crate::{
    assert_close2, assert_close3, base_at, environment_strategy, identity_look, raster_in,
};
use obscura_camera::{Camera, CameraSample, EnvironmentCamera};
use obscura_space::{Point2, Point3, Vector3};
use proptest::prelude::*;

/// The camera-space direction of a raster point (through the pose's inverse).
fn camera_dir(camera: &EnvironmentCamera, p: Point2<obscura_space::Raster>) -> glam::Vec3 {
    let ray = camera.generate_ray(&CameraSample::at(p)).unwrap().ray;
    camera
        .world_from_camera()
        .at(0.0)
        .inverse()
        .vector(ray.direction)
        .to_glam()
}

proptest! {
    #![proptest_config(crate::cases(512))]

    /// Directions are unit; the top half looks up (+y), the right half right (+x), the middle
    /// columns forward (+z); and the ray runs over [near, far] from the eye.
    #[test]
    fn orientation_and_unit_directions(camera in environment_strategy(), fx in 0f32..1.0, fy in 0f32..1.0) {
        let p = raster_in(camera.film().resolution(), fx, fy);
        let ray = camera.generate_ray(&CameraSample::at(p)).unwrap().ray;
        prop_assert!((ray.direction.length() - 1.0).abs() < 1e-5);
        prop_assert_eq!(ray.t_min, camera.base().near);
        prop_assert_eq!(ray.t_max, camera.base().far);
        let eye = camera.world_from_camera().at(0.0).point(Point3::ORIGIN);
        assert_close3(ray.origin.to_glam(), eye.to_glam(), 1e-5);
        let d = camera_dir(&camera, p);
        // theta = pi * fy: up for fy < 1/2. phi = 2 pi (fx - 1/2): right for fx > 1/2,
        // forward for |phi| < pi/2, i.e. fx in (1/4, 3/4). Margins keep away from the zeros.
        if fy < 0.49 { prop_assert!(d.y > 0.0); }
        if fy > 0.51 { prop_assert!(d.y < 0.0); }
        if fy > 0.01 && fy < 0.99 {
            // (The seam fx = 0 or 1 looks straight back, x = 0.)
            if fx > 0.51 && fx < 0.99 { prop_assert!(d.x > 0.0, "{d:?}"); }
            if fx < 0.49 && fx > 0.01 { prop_assert!(d.x < 0.0, "{d:?}"); }
            if fx > 0.26 && fx < 0.74 { prop_assert!(d.z > 0.0); }
            if !(0.24..=0.76).contains(&fx) { prop_assert!(d.z < 0.0); }
        }
    }

    /// Every direction of the sphere is seen: a random direction projects to a raster point
    /// whose ray looks that way. And project(generate_ray(p).at(t)) == p away from the poles.
    #[test]
    fn covers_the_sphere_and_inverts(camera in environment_strategy(), w in (-1f32..1.0, -1f32..1.0, -1f32..1.0), fx in 0f32..1.0, fy in 0.02f32..0.98, t in 0.5f32..50.0) {
        let w = glam::Vec3::new(w.0, w.1, w.2);
        prop_assume!(w.length() > 0.1);
        let pose = camera.world_from_camera().at(0.0);
        let eye = pose.point(Point3::ORIGIN);
        let d_world = Vector3::from_glam(w.normalize());
        let p = camera.project(eye + d_world * 5.0, 0.0).unwrap();
        let [width, height] = camera.film().resolution().map(|r| r as f32);
        prop_assert!(p.x >= 0.0 && p.x <= width && p.y >= 0.0 && p.y <= height, "{p:?}");
        let ray = camera.generate_ray(&CameraSample::at(p)).unwrap().ray;
        assert_close3(ray.direction.to_glam(), d_world.to_glam(), 1e-4);

        let p = raster_in(camera.film().resolution(), fx, fy);
        let ray = camera.generate_ray(&CameraSample::at(p)).unwrap().ray;
        let back = camera.project(ray.at(t), 0.0).unwrap();
        // x wraps around at the seam (x = 0 and x = width are the same azimuth).
        let dx = (back.x - p.x).abs();
        let dx = dx.min((dx - width).abs());
        // Angular error ~1e-6 rad / 0.5 distance times pixels per radian, larger near the poles.
        let tol = 2e-3 + 4e-6 * width.max(height) / (std::f32::consts::PI * fy).sin() * (1.0 + 20.0 / t);
        prop_assert!(dx <= tol && (back.y - p.y).abs() <= tol, "{back:?} vs {p:?} (tol {tol})");
    }
}

/// The image centre looks along +z (the view direction), the top row up, and the corners of
/// the sphere are all reached by a coarse grid of pixels (all eight octants).
#[test]
fn centre_top_and_octants() {
    let camera =
        EnvironmentCamera::new(base_at(identity_look(), [64, 32], None, 0.0, 1.0e30)).unwrap();
    assert_close3(
        camera_dir(&camera, Point2::new(32.0, 16.0)),
        glam::Vec3::Z,
        1e-6,
    );
    for x in [0.0, 10.0, 33.3, 64.0] {
        assert_close3(
            camera_dir(&camera, Point2::new(x, 0.0)),
            glam::Vec3::Y,
            1e-6,
        );
        assert_close3(
            camera_dir(&camera, Point2::new(x, 32.0)),
            -glam::Vec3::Y,
            1e-6,
        );
    }
    let mut octants = [false; 8];
    for j in 0..32 {
        for i in 0..64 {
            let d = camera_dir(&camera, Point2::new(i as f32 + 0.5, j as f32 + 0.5));
            let k =
                usize::from(d.x > 0.0) | usize::from(d.y > 0.0) << 1 | usize::from(d.z > 0.0) << 2;
            octants[k] = true;
        }
    }
    assert_eq!(octants, [true; 8]);
    // The eye itself and points beyond far have no raster position.
    let near_far =
        EnvironmentCamera::new(base_at(identity_look(), [64, 32], None, 1.0, 10.0)).unwrap();
    assert!(near_far.project(Point3::new(0.0, 0.0, 0.0), 0.0).is_none());
    assert!(
        near_far
            .project(Point3::new(0.0, 0.0, -0.99), 0.0)
            .is_none()
    );
    assert!(
        near_far
            .project(Point3::new(0.0, 0.0, -10.01), 0.0)
            .is_none()
    );
    let p = near_far.project(Point3::new(0.0, 0.0, -5.0), 0.0).unwrap();
    assert_close2(p.to_glam(), glam::Vec2::new(32.0, 16.0), 1e-4);
}
