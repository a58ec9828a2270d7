//! Hand-computed rays of a few exact pixels of each model, with the arithmetic written out.
//! All use the identity look-at (eye at the origin, looking down world -z, y up), for which
//! camera (x, y, z) is world (x, y, -z).

use crate::{assert_close2, assert_close3, base_at, identity_look};
use obscura_camera::{
    Camera, CameraSample, EnvironmentCamera, FovAxis, OrthographicCamera, PerspectiveCamera,
    ScreenWindow, ThinLens,
};
use obscura_space::{Point2, Point3};

/// Camera direction (x, y, z) as the world direction of the identity look-at, normalised.
fn world_dir(x: f32, y: f32, z: f32) -> glam::Vec3 {
    glam::Vec3::new(x, y, -z).normalize()
}

fn perspective(res: [u32; 2], fov: f32, axis: FovAxis, lens: ThinLens) -> PerspectiveCamera {
    PerspectiveCamera::new(
        base_at(identity_look(), res, None, 0.01, 100.0),
        fov,
        axis,
        lens,
    )
    .unwrap()
}

fn ray_at(camera: &impl Camera, x: f32, y: f32) -> obscura_space::Ray<obscura_space::World> {
    camera
        .generate_ray(&CameraSample::at(Point2::new(x, y)))
        .unwrap()
        .ray
}

#[test]
fn perspective_2x2_fov_90() {
    // Window [-1, 1]^2 (aspect 1), s = 1 / tan(45) = 1.
    let camera = perspective([2, 2], 90.0, FovAxis::Smaller, ThinLens::PINHOLE);
    let chain = camera.projective();
    // Pixel (0, 0): centre (0.5, 0.5) -> NDC (0.25, 0.25) -> screen (-1 + 0.25 * 2,
    // 1 - 0.25 * 2) = (-0.5, 0.5) -> camera direction normalize(-0.5, 0.5, 1).
    let p = Point3::new(0.5, 0.5, 0.0);
    let ndc = chain.ndc_from_raster().point(p);
    assert_close3(ndc.to_glam(), glam::Vec3::new(0.25, 0.25, 0.0), 1e-7);
    let screen = chain.screen_from_ndc().point(ndc);
    assert_close3(screen.to_glam(), glam::Vec3::new(-0.5, 0.5, 0.0), 1e-7);
    let ray = ray_at(&camera, 0.5, 0.5);
    assert_close3(ray.origin.to_glam(), glam::Vec3::ZERO, 0.0);
    assert_close3(ray.direction.to_glam(), world_dir(-0.5, 0.5, 1.0), 1e-6);
    // |(-0.5, 0.5, 1)| = sqrt(1.5) = 1.2247; z = 1 / 1.2247 = 0.8165, so t_min = 0.01 / 0.8165.
    assert!((ray.t_min - 0.01 * 1.5f32.sqrt()).abs() < 1e-8);
    assert!((ray.t_max - 100.0 * 1.5f32.sqrt()).abs() < 1e-4);
    // Pixel (1, 0): screen (0.5, 0.5); pixel (1, 1): screen (0.5, -0.5).
    assert_close3(
        ray_at(&camera, 1.5, 0.5).direction.to_glam(),
        world_dir(0.5, 0.5, 1.0),
        1e-6,
    );
    assert_close3(
        ray_at(&camera, 1.5, 1.5).direction.to_glam(),
        world_dir(0.5, -0.5, 1.0),
        1e-6,
    );
    // The image centre (1, 1) looks straight ahead; the corner (0, 0) at 45 degrees both ways.
    assert_close3(
        ray_at(&camera, 1.0, 1.0).direction.to_glam(),
        world_dir(0.0, 0.0, 1.0),
        1e-7,
    );
    assert_close3(
        ray_at(&camera, 0.0, 0.0).direction.to_glam(),
        world_dir(-1.0, 1.0, 1.0),
        1e-6,
    );
    // And projection: world (1, 2, -4) is camera (1, 2, 4), screen (0.25, 0.5),
    // NDC ((0.25 + 1) / 2, (1 - 0.5) / 2) = (0.625, 0.25), raster (1.25, 0.5).
    let p = camera.project(Point3::new(1.0, 2.0, -4.0), 0.0).unwrap();
    assert_close2(p.to_glam(), glam::Vec2::new(1.25, 0.5), 1e-6);
}

#[test]
fn perspective_4x2_fov_axes() {
    // Window [-2, 2] x [-1, 1]. Pixel (3, 1): centre (3.5, 1.5) -> NDC (0.875, 0.75) ->
    // screen (-2 + 0.875 * 4, 1 - 0.75 * 2) = (1.5, -0.5).
    // fov 90 along the smaller (y) half-extent 1: s = 1 / tan 45 = 1 -> direction (1.5, -0.5, 1).
    let c = perspective([4, 2], 90.0, FovAxis::Smaller, ThinLens::PINHOLE);
    assert_close3(
        ray_at(&c, 3.5, 1.5).direction.to_glam(),
        world_dir(1.5, -0.5, 1.0),
        1e-6,
    );
    // Along x (half-extent 2): s = 2 -> camera (1.5 / 2, -0.5 / 2, 1) = (0.75, -0.25, 1).
    let c = perspective([4, 2], 90.0, FovAxis::X, ThinLens::PINHOLE);
    assert_close3(
        ray_at(&c, 3.5, 1.5).direction.to_glam(),
        world_dir(0.75, -0.25, 1.0),
        1e-6,
    );
    let c = perspective([4, 2], 90.0, FovAxis::Larger, ThinLens::PINHOLE);
    assert_close3(
        ray_at(&c, 3.5, 1.5).direction.to_glam(),
        world_dir(0.75, -0.25, 1.0),
        1e-6,
    );
    // Along the diagonal (half-diagonal sqrt(5)): s = sqrt 5; the corner (4, 0) at screen
    // (2, 1) looks at (2, 1, 1) / sqrt 5 * ... = (2 / sqrt 5, 1 / sqrt 5, 1): 45 degrees off axis.
    let c = perspective([4, 2], 90.0, FovAxis::Diagonal, ThinLens::PINHOLE);
    let d = ray_at(&c, 4.0, 0.0).direction.to_glam();
    assert!(
        (d.dot(-glam::Vec3::Z) - 0.5f32.sqrt()).abs() < 1e-6,
        "{d:?}"
    );
    // fov 60 along y on 2 x 2: s = 1 / tan 30 = sqrt 3; pixel (0, 0) at screen (-0.5, 0.5)
    // looks at (-0.5 / sqrt 3, 0.5 / sqrt 3, 1).
    let c = perspective([2, 2], 60.0, FovAxis::Y, ThinLens::PINHOLE);
    let r3 = 3f32.sqrt();
    assert_close3(
        ray_at(&c, 0.5, 0.5).direction.to_glam(),
        world_dir(-0.5 / r3, 0.5 / r3, 1.0),
        1e-6,
    );
}

#[test]
fn perspective_thin_lens_pixel() {
    // 2 x 2, fov 90, radius 1, focus at z = 2. Lens sample (0.75, 0.5): concentric map offset
    // (2 * 0.75 - 1, 2 * 0.5 - 1) = (0.5, 0): r = 0.5, angle 0 -> lens point (0.5, 0, 0).
    // Pixel (0, 0): pinhole direction (-0.5, 0.5, 1) reaches z = 2 at (-1, 1, 2).
    // Ray: from (0.5, 0, 0) towards (-1, 1, 2): direction (-1.5, 1, 2) / sqrt(7.25).
    let camera = perspective(
        [2, 2],
        90.0,
        FovAxis::Smaller,
        ThinLens::new(1.0, 2.0).unwrap(),
    );
    let sample = CameraSample {
        p_film: Point2::new(0.5, 0.5),
        p_lens: glam::Vec2::new(0.75, 0.5),
        time: 0.0,
    };
    let ray = camera.generate_ray(&sample).unwrap().ray;
    assert_close3(ray.origin.to_glam(), glam::Vec3::new(0.5, 0.0, 0.0), 1e-7);
    assert_close3(ray.direction.to_glam(), world_dir(-1.5, 1.0, 2.0), 1e-6);
    // t where camera z = 0.01: 0.01 / (2 / sqrt 7.25).
    assert!((ray.t_min - 0.01 * 7.25f32.sqrt() / 2.0).abs() < 1e-7);
}

#[test]
fn orthographic_pixels() {
    // 4 x 2 with window [-2, 2] x [-1, 1] world units, near 0, far 10.
    let base = base_at(
        identity_look(),
        [4, 2],
        Some(ScreenWindow::new(-2.0, 2.0, -1.0, 1.0).unwrap()),
        0.0,
        10.0,
    );
    let camera = OrthographicCamera::new(base.clone(), ThinLens::PINHOLE).unwrap();
    // Pixel (0, 0): centre (0.5, 0.5) -> NDC (0.125, 0.25) -> (-2 + 0.125 * 4, 1 - 0.25 * 2)
    // = (-1.5, 0.5): the ray starts at camera (-1.5, 0.5, 0) along +z (world -z), t in [0, 10].
    let ray = ray_at(&camera, 0.5, 0.5);
    assert_close3(ray.origin.to_glam(), glam::Vec3::new(-1.5, 0.5, 0.0), 1e-7);
    assert_close3(ray.direction.to_glam(), -glam::Vec3::Z, 0.0);
    assert_eq!((ray.t_min, ray.t_max), (0.0, 10.0));
    // Pixel (3, 1): centre (3.5, 1.5) -> NDC (0.875, 0.75) -> (1.5, -0.5).
    assert_close3(
        ray_at(&camera, 3.5, 1.5).origin.to_glam(),
        glam::Vec3::new(1.5, -0.5, 0.0),
        1e-7,
    );
    // Projection ignores depth: world (1, 0.25, -7) is camera (1, 0.25, 7) -> NDC
    // ((1 + 2) / 4, (1 - 0.25) / 2) = (0.75, 0.375) -> raster (3, 0.75).
    let p = camera.project(Point3::new(1.0, 0.25, -7.0), 0.0).unwrap();
    assert_close2(p.to_glam(), glam::Vec2::new(3.0, 0.75), 1e-6);

    // Thin lens, radius 1, focus 2, lens sample (0.75, 0.5) -> lens offset (0.5, 0).
    // Pixel (0, 0): origin (-1.5 + 0.5, 0.5, 0) = (-1, 0.5, 0), towards the focus point
    // (-1.5, 0.5, 2): direction (-0.5, 0, 2) / sqrt(4.25).
    let camera = OrthographicCamera::new(base, ThinLens::new(1.0, 2.0).unwrap()).unwrap();
    let sample = CameraSample {
        p_film: Point2::new(0.5, 0.5),
        p_lens: glam::Vec2::new(0.75, 0.5),
        time: 0.0,
    };
    let ray = camera.generate_ray(&sample).unwrap().ray;
    assert_close3(ray.origin.to_glam(), glam::Vec3::new(-1.0, 0.5, 0.0), 1e-7);
    assert_close3(ray.direction.to_glam(), world_dir(-0.5, 0.0, 2.0), 1e-6);
}

#[test]
fn environment_pixels() {
    let camera =
        EnvironmentCamera::new(base_at(identity_look(), [4, 2], None, 0.0, 1.0e30)).unwrap();
    let h = 0.5f32.sqrt();
    // Pixel (2, 1): centre (2.5, 1.5): theta = pi * 1.5 / 2 = 3 pi / 4,
    // phi = 2 pi (2.5 / 4 - 0.5) = pi / 4: d = (sin 3pi/4 sin pi/4, cos 3pi/4, sin 3pi/4 cos pi/4)
    // = (0.5, -0.7071, 0.5) in camera space.
    assert_close3(
        ray_at(&camera, 2.5, 1.5).direction.to_glam(),
        world_dir(0.5, -h, 0.5),
        1e-6,
    );
    // Pixel (0, 0): centre (0.5, 0.5): theta = pi / 4, phi = 2 pi (0.125 - 0.5) = -3 pi / 4:
    // d = (0.7071 * -0.7071, 0.7071, 0.7071 * -0.7071) = (-0.5, 0.7071, -0.5): up, left, behind.
    assert_close3(
        ray_at(&camera, 0.5, 0.5).direction.to_glam(),
        world_dir(-0.5, h, -0.5),
        1e-6,
    );
    // Raster (3, 1): theta = pi / 2, phi = 2 pi (0.75 - 0.5) = pi / 2: straight right (+x).
    assert_close3(
        ray_at(&camera, 3.0, 1.0).direction.to_glam(),
        world_dir(1.0, 0.0, 0.0),
        1e-6,
    );
    // Inverse: world (0, 0, 3) (behind the eye: camera (0, 0, -3)) has theta = pi / 2,
    // phi = atan2(0, -3) = pi -> raster (4 * (1/2 + 1/2), 2 * 1/2) = (4, 1), the seam.
    let p = camera.project(Point3::new(0.0, 0.0, 3.0), 0.0).unwrap();
    assert_close2(p.to_glam(), glam::Vec2::new(4.0, 1.0), 1e-6);
}
