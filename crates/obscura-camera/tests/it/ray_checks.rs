//! Checks shared by the tests of the fisheye, cylindrical, octahedral, cube-face and ODS
//! cameras: rays read back in camera space, and differentials against neighbouring rays and
//! against a finite-difference derivative.

use obscura_camera::{Camera, CameraSample};
use obscura_space::{Point2, Raster};

/// The camera-space origin and unit direction of the ray at `p` (through the pose's inverse),
/// or None when no ray leaves from `p`.
pub fn camera_ray(camera: &impl Camera, p: Point2<Raster>) -> Option<(glam::Vec3, glam::Vec3)> {
    let ray = camera.generate_ray(&CameraSample::at(p))?.ray;
    let camera_from_world = camera.world_from_camera().at(0.0).inverse();
    Some((
        camera_from_world.point(ray.origin).to_glam(),
        camera_from_world
            .vector(ray.direction)
            .to_glam()
            .normalize(),
    ))
}

/// The differential at `p` holds the main ray and, where rays leave from them, the rays one
/// pixel right and one pixel down.
#[track_caller]
pub fn check_neighbours(camera: &impl Camera, p: Point2<Raster>) {
    let sample = CameraSample::at(p);
    let Some(main) = camera.generate_ray(&sample) else {
        assert!(camera.generate_ray_differential(&sample).is_none());
        return;
    };
    let diff = camera.generate_ray_differential(&sample).unwrap();
    assert_eq!(diff.ray, main.ray);
    let right = camera.generate_ray(&CameraSample::at(Point2::new(p.x + 1.0, p.y)));
    let down = camera.generate_ray(&CameraSample::at(Point2::new(p.x, p.y + 1.0)));
    if let Some(right) = right {
        crate::assert_close3(
            diff.rx_direction.to_glam(),
            right.ray.direction.to_glam(),
            1e-6,
        );
        crate::assert_close3(diff.rx_origin.to_glam(), right.ray.origin.to_glam(), 1e-6);
    }
    if let Some(down) = down {
        crate::assert_close3(
            diff.ry_direction.to_glam(),
            down.ray.direction.to_glam(),
            1e-6,
        );
        crate::assert_close3(diff.ry_origin.to_glam(), down.ray.origin.to_glam(), 1e-6);
    }
}

/// The differential's one-pixel steps of the direction, `rx - d` and `ry - d`, against the
/// derivatives of the model's direction `dir(x, y)` by central differences (step 0.05 pixel,
/// large enough for f32 raster positions of a few hundred pixels), where the map is smooth: they differ by the second-order term, at most about half
/// the squared angle per pixel, bounded here by `0.1 |J| + 1e-5` (1e-5 covering f32 rounding
/// of the rays). `p` must be at least a pixel away from any crease or rim of the map.
#[track_caller]
pub fn check_derivative(
    camera: &impl Camera,
    p: Point2<Raster>,
    dir: impl Fn(f64, f64) -> glam::DVec3,
) {
    let diff = camera
        .generate_ray_differential(&CameraSample::at(p))
        .unwrap();
    let camera_from_world = camera.world_from_camera().at(0.0).inverse();
    let to_camera = |v: obscura_space::Vector3<obscura_space::World>| {
        camera_from_world.vector(v).to_glam().normalize()
    };
    let d = to_camera(diff.ray.direction);
    let (x, y) = (f64::from(p.x), f64::from(p.y));
    let h = 0.05;
    for (step, derivative) in [
        (
            to_camera(diff.rx_direction) - d,
            (dir(x + h, y) - dir(x - h, y)) / (2.0 * h),
        ),
        (
            to_camera(diff.ry_direction) - d,
            (dir(x, y + h) - dir(x, y - h)) / (2.0 * h),
        ),
    ] {
        let derivative = derivative.as_vec3();
        let tol = 0.1 * derivative.length() + 1e-5;
        assert!(
            (step - derivative).length() <= tol,
            "step {step:?} vs derivative {derivative:?} at {p:?}"
        );
    }
}
