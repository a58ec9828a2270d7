//! The projective chain and the pinhole models: round trips, projection of generated rays,
//! parallel and converging rays, clipping at the boundaries, precision with extreme clip planes.

use crate::{assert_close2, assert_close3, base_at, identity_look, projective_strategy, raster_in};
use obscura_camera::{
    AnyCamera, Camera, CameraSample, FovAxis, OrthographicCamera, PerspectiveCamera,
    ProjectiveCamera, ScreenWindow, ThinLens,
};
use obscura_space::{Point2, Point3, Raster, Vector3};
use proptest::prelude::*;

/// The projective chain of a projective camera.
pub fn chain(camera: &AnyCamera) -> &ProjectiveCamera {
    match camera {
        AnyCamera::Perspective(c) => c.projective(),
        AnyCamera::Orthographic(c) => c.projective(),
        _ => panic!("not a projective camera"),
    }
}

/// Raster pixels per radian of direction error (perspective) or per world unit of position
/// error (orthographic) at the ray's film point. With the default window every axis has
/// min(res) / 2 pixels per screen unit; screen position is `s tan(angle)`, whose derivative
/// `s (1 + tan^2)` grows towards grazing rays. (This only sizes the tolerance.)
fn raster_per_unit(camera: &AnyCamera, ray: &obscura_space::Ray<obscura_space::World>) -> f32 {
    let [w, h] = camera.film().resolution().map(|r| r as f32);
    let per_screen = w.min(h) / 2.0;
    match camera {
        AnyCamera::Perspective(c) => {
            let s = c.projective().screen_from_camera().matrix().x_axis.x;
            let d = camera
                .world_from_camera()
                .at(0.0)
                .inverse()
                .vector(ray.direction);
            let tan2 = (d.x * d.x + d.y * d.y) / (d.z * d.z);
            per_screen * s * (1.0 + tan2)
        }
        _ => per_screen,
    }
}

proptest! {
    #![proptest_config(crate::cases(512))]

    /// raster -> camera -> raster, through `camera_from_raster` and `raster_from_camera`.
    #[test]
    fn raster_camera_raster(camera in projective_strategy(false), fx in 0f32..1.0, fy in 0f32..1.0) {
        let chain = chain(&camera);
        let p_film = raster_in(camera.film().resolution(), fx, fy);
        let p_raster = Point3::<Raster>::new(p_film.x, p_film.y, 0.0);
        let p_camera = chain.camera_from_raster().point(p_raster);
        let back = chain.raster_from_camera().point(p_camera);
        assert_close3(back.to_glam(), p_raster.to_glam(), 2e-3);
        // The film point lies on the near plane (screen z = 0), relative to near.
        let near = chain.base().near;
        prop_assert!((p_camera.z - near).abs() <= 1e-5 * near.max(1e-3), "z {} near {near}", p_camera.z);
    }

    /// raster -> screen -> NDC -> raster, through the separate maps.
    #[test]
    fn raster_screen_ndc_raster(camera in projective_strategy(false), fx in 0f32..1.0, fy in 0f32..1.0) {
        let chain = chain(&camera);
        let [w, h] = camera.film().resolution().map(|r| r as f32);
        let p_film = raster_in(camera.film().resolution(), fx, fy);
        let p_raster = Point3::<Raster>::new(p_film.x, p_film.y, 0.0);
        let p_screen = chain.screen_from_raster().point(p_raster);
        let p_ndc = chain.ndc_from_screen().point(p_screen);
        // NDC is the raster position over the resolution (y down in both).
        assert_close3(p_ndc.to_glam(), glam::Vec3::new(p_film.x / w, p_film.y / h, 0.0), 1e-5);
        let back = chain.raster_from_ndc().point(p_ndc);
        assert_close3(back.to_glam(), p_raster.to_glam(), 2e-3);
        // And the window: screen x runs from x_min at raster 0 to x_max at the width.
        let win = camera.film().screen_window();
        let expect_x = win.x_min + fx * (win.x_max - win.x_min);
        let expect_y = win.y_max - fy * (win.y_max - win.y_min);
        assert_close2(glam::Vec2::new(p_screen.x, p_screen.y), glam::Vec2::new(expect_x, expect_y), 1e-4 * win.x_max.abs().max(win.y_max.abs()));
    }

    /// `project(generate_ray(p).at(d)) == p` for pinhole projective cameras.
    #[test]
    fn project_inverts_generate(camera in projective_strategy(false), fx in 0f32..1.0, fy in 0f32..1.0, frac in 0.02f32..0.98) {
        let p_film = raster_in(camera.film().resolution(), fx, fy);
        let ray = camera.generate_ray(&CameraSample::at(p_film)).unwrap().ray;
        prop_assert!((ray.direction.length() - 1.0).abs() < 1e-5);
        // A distance strictly inside the clip range (at its ends rounding may step outside),
        // and at least 1 so the eye's rounding stays small against it.
        let lower = ray.t_min.max(1.0);
        let upper = ray.t_max.min(100.0 * lower);
        let d = lower + frac * (upper - lower);
        let back = camera.project(ray.at(d), ray.time).unwrap();
        // Rounding of the world point (eye up to ~17 from the origin) turned into pixels.
        let eye = ray.origin.to_vector().length();
        let ortho = matches!(camera, AnyCamera::Orthographic(_));
        let world_err = 1.5e-6 * (eye + d);
        let tol = 2e-3 + raster_per_unit(&camera, &ray) * if ortho { world_err } else { world_err / d };
        assert_close2(back.to_glam(), p_film.to_glam(), tol);
    }

    /// Perspective rays all start at the eye; orthographic rays are parallel and start on the
    /// camera plane z = 0.
    #[test]
    fn perspective_converge_orthographic_parallel(camera in projective_strategy(false), a in (0f32..1.0, 0f32..1.0), b in (0f32..1.0, 0f32..1.0)) {
        let res = camera.film().resolution();
        let ra = camera.generate_ray(&CameraSample::at(raster_in(res, a.0, a.1))).unwrap().ray;
        let rb = camera.generate_ray(&CameraSample::at(raster_in(res, b.0, b.1))).unwrap().ray;
        let pose = camera.world_from_camera().at(0.0);
        let eye = pose.point(Point3::ORIGIN);
        match camera {
            AnyCamera::Perspective(_) => {
                assert_close3(ra.origin.to_glam(), eye.to_glam(), 1e-5);
                assert_close3(rb.origin.to_glam(), eye.to_glam(), 1e-5);
            }
            _ => {
                assert_close3(ra.direction.to_glam(), rb.direction.to_glam(), 1e-6);
                let view = pose.vector(obscura_space::Vector3::new(0.0, 0.0, 1.0));
                assert_close3(ra.direction.to_glam(), view.to_glam(), 1e-6);
                // The origin is on the camera plane z = 0 up to f32 rounding of a point that may
                // lie ~2000 units off axis (the window's half-extent on a 1999 x 1 film), where
                // one f32 step is 1.2e-4: so the allowance is relative to the points' sizes,
                // 1e-6 = 16.8u per unit (u = 2^-24). Budget, with q = (x', y', 0) the camera-space
                // origin and o its world image: the fast path's `R.x x' + R.y y' + eye` rounds
                // by at most 3u (|q| sqrt 2 + |eye|) and |eye| <= |o| + |q|; this test's
                // `camera_from_world` rounds by ~4u (|o| + |eye|); the stored pose and its
                // inverse disagree by ~2u (|o| + |eye|). Total <= 15u (|o| + |q|).
                let camera_from_world = pose.inverse();
                let o_camera = camera_from_world.point(ra.origin);
                let allowance = 1e-6
                    * (1.0 + ra.origin.to_vector().length() + o_camera.to_vector().length());
                prop_assert!(o_camera.z.abs() <= allowance, "origin z {} allowance {allowance}", o_camera.z);
            }
        }
    }

    /// Near and far clipping: the camera z of ray.at(t_min) is near and of ray.at(t_max) far.
    #[test]
    fn clip_range_is_camera_z(camera in projective_strategy(false), fx in 0f32..1.0, fy in 0f32..1.0) {
        check_clip_range(&camera, raster_in(camera.film().resolution(), fx, fy))?;
    }
}

/// The camera z of `ray.at(t_min)` is near and of `ray.at(t_max)` far, for the pinhole ray of
/// `p_film`, up to f32 rounding.
///
/// The allowance: an absolute part for the transformed origin (eye up to ~17 away), and a
/// relative part `1e-6 / d.z = 1e-6 |q|` (`q` the film point on the camera plane z = 1,
/// `d.z = 1 / |q|` for the unit direction). The perspective fast path's error budget (see
/// `PerspectiveMap`): its rounding in `R q` is at most `3 sqrt(3) u |q|` along the view axis
/// (u = 2^-24), the stored pose and the two roundings of `t` and the direction add ~4u, and
/// this test's own `camera_from_world` rounds `d.z` by up to `3u`, i.e. `3u |q|` relative.
/// Total <= `8.2u |q| + 4u <= 12.2u |q| = 7.3e-7 |q|`, inside `1e-6 |q|`.
/// (Orthographic origins lie up to the window's size off axis: the absolute part covers them.)
fn check_clip_range(camera: &AnyCamera, p_film: Point2<Raster>) -> Result<(), TestCaseError> {
    let ray = camera.generate_ray(&CameraSample::at(p_film)).unwrap().ray;
    let chain = chain(camera);
    let (near, far) = (chain.base().near, chain.base().far);
    // In camera space (the pose is rigid, so t is the same distance there).
    let camera_from_world = camera.world_from_camera().at(0.0).inverse();
    let r_camera = camera_from_world.ray(ray);
    let z_near = r_camera.origin.z + r_camera.direction.z * ray.t_min;
    let z_far = r_camera.origin.z + r_camera.direction.z * ray.t_max;
    let rel = 1e-6 / r_camera.direction.z;
    let abs = 1e-6 * (1.0 + ray.origin.to_vector().length() + r_camera.origin.to_vector().length());
    prop_assert!(
        (z_near - near).abs() <= abs + rel * near,
        "near {near} got {z_near} at {p_film:?}"
    );
    prop_assert!(
        (z_far - far).abs() <= abs + rel * far,
        "far {far} got {z_far} at {p_film:?}"
    );
    Ok(())
}

/// The clip range on tall films, where the film point's offset in camera space (up to the
/// window's half-extent, over `s` for perspective) is much longer than the centre rows' film
/// point (~1): the cases the property found (issue 9). Perspective: 4 x 528 film, fov along
/// x, offset up to 132 / s = 74.7. Orthographic: 3 x 969 film, offset up to 323. Sweeps
/// the middle rows in quarter pixels, every column, with the failing cases' poses.
#[test]
fn clip_range_on_a_tall_film() {
    // Camera z along (0.29, 0.52, -0.81), camera x in world xy.
    let perspective_look = obscura_camera::LookAt::new(
        Point3::new(0.0, 0.0, 8.132996),
        Point3::new(0.2917941, 0.51542217, 8.132996 - 0.8057272),
        Vector3::new(0.0, 0.0, -1.0),
    );
    // Camera z along (-0.65, -0.12, -0.75), y along (-0.55, 0.75, 0.36), eye 3.6 from 0.
    let orthographic_look = obscura_camera::LookAt::new(
        Point3::new(-3.4135153, 1.1702431, 0.0),
        Point3::new(-3.4135153 - 0.6539908, 1.1702431 - 0.12455316, -0.74617857),
        Vector3::new(-0.5524943, 0.75241345, 0.35864165),
    );
    for (near, far) in [(0.001f32, 1.0e30f32), (0.1, 1000.0)] {
        let perspective: AnyCamera = PerspectiveCamera::new(
            base_at(perspective_look, [4, 528], None, near, far),
            58.985527,
            FovAxis::X,
            ThinLens::PINHOLE,
        )
        .unwrap()
        .into();
        let orthographic: AnyCamera = OrthographicCamera::new(
            base_at(orthographic_look, [3, 969], None, near, far),
            ThinLens::PINHOLE,
        )
        .unwrap()
        .into();
        for camera in [perspective, orthographic] {
            let [w, h] = camera.film().resolution();
            for j in 0..4 * 40 {
                for i in 0..4 * w {
                    let y = (h / 2 - 20) as f32 + j as f32 * 0.25;
                    let p_film = Point2::new(i as f32 * 0.25, y);
                    check_clip_range(&camera, p_film).unwrap();
                }
            }
        }
    }
}

/// project() at the clip boundaries: a point just inside [near, far] projects, just outside
/// does not. With the identity look-at, camera z of world (x, y, -z) is exactly z.
#[test]
fn project_respects_near_and_far() {
    for (near, far) in [(0.1f32, 1000.0f32), (0.001, 1.0e30), (2.0, 3.0)] {
        let perspective: AnyCamera = PerspectiveCamera::new(
            base_at(identity_look(), [8, 6], None, near, far),
            60.0,
            FovAxis::Smaller,
            ThinLens::PINHOLE,
        )
        .unwrap()
        .into();
        let ortho: AnyCamera = OrthographicCamera::new(
            base_at(identity_look(), [8, 6], None, near, far),
            ThinLens::PINHOLE,
        )
        .unwrap()
        .into();
        for camera in [perspective, ortho] {
            let at = |z: f32| camera.project(Point3::new(0.01 * z, 0.0, -z), 0.0);
            assert!(at(near).is_some(), "near {near} itself is visible");
            assert!(at(far).is_some(), "far {far} itself is visible");
            assert!(at(near * 1.001).is_some());
            assert!(at(near * 0.999).is_none(), "in front of near {near}");
            assert!(at(far * 0.999).is_some());
            assert!(at(far * 1.001).is_none(), "beyond far {far}");
            assert!(at(-1.0).is_none(), "behind the camera");
        }
    }
}

/// Precision of the closed-form projection with near = 0.001, far = 1e30 and near = 0.1,
/// far = 1000: screen z is 0 at near and 1 at far, and every pixel centre survives
/// raster -> camera -> raster to within 1e-3 pixel on a 1920 x 1080 film.
#[test]
fn extreme_clip_planes_keep_precision() {
    for (near, far) in [(0.001f32, 1.0e30f32), (0.1, 1000.0)] {
        let camera = PerspectiveCamera::new(
            base_at(identity_look(), [1920, 1080], None, near, far),
            45.0,
            FovAxis::Smaller,
            ThinLens::PINHOLE,
        )
        .unwrap();
        let chain = camera.projective();
        let s_near = chain
            .screen_from_camera()
            .point(Point3::new(0.0, 0.0, near));
        let s_far = chain.screen_from_camera().point(Point3::new(0.0, 0.0, far));
        assert!(s_near.z.abs() < 1e-6, "screen z at near: {}", s_near.z);
        assert!((s_far.z - 1.0).abs() < 1e-5, "screen z at far: {}", s_far.z);
        // The inverse matrix really is the inverse (no numerical inversion of a 1e30 entry).
        let back = chain
            .camera_from_screen()
            .point(Point3::new(0.3, -0.2, 0.0));
        assert!((back.z - near).abs() < 1e-6 * near.max(1.0));
        let mut worst = 0f32;
        for j in (0..1080).step_by(7) {
            for i in (0..1920).step_by(11) {
                let p = Point3::<Raster>::new(i as f32 + 0.5, j as f32 + 0.5, 0.0);
                let q = chain
                    .raster_from_camera()
                    .point(chain.camera_from_raster().point(p));
                worst = worst.max((q.to_glam() - p.to_glam()).abs().max_element());
            }
        }
        assert!(
            worst < 1e-3,
            "near {near}, far {far}: worst round trip error {worst} px"
        );
        // And through the full ray: the image corner's ray projects back.
        let corner = Point2::new(0.5, 0.5);
        let ray = camera.generate_ray(&CameraSample::at(corner)).unwrap().ray;
        let back = camera.project(ray.at(10.0), 0.0).unwrap();
        assert_close2(back.to_glam(), corner.to_glam(), 1e-3);
    }
}

/// Differentials are the rays one pixel right and one pixel down, same lens point and time.
#[test]
fn differentials_are_neighbouring_rays() {
    let lens = ThinLens::new(0.2, 3.0).unwrap();
    for lens in [ThinLens::PINHOLE, lens] {
        let camera = PerspectiveCamera::new(
            base_at(identity_look(), [16, 9], None, 0.01, 100.0),
            50.0,
            FovAxis::Smaller,
            lens,
        )
        .unwrap();
        let sample = CameraSample {
            p_film: Point2::new(3.25, 4.75),
            p_lens: glam::Vec2::new(0.8, 0.1),
            time: 0.3,
        };
        let diff = camera.generate_ray_differential(&sample).unwrap();
        let main = camera.generate_ray(&sample).unwrap().ray;
        assert_eq!(diff.ray, main);
        let right = CameraSample {
            p_film: Point2::new(4.25, 4.75),
            ..sample
        };
        let down = CameraSample {
            p_film: Point2::new(3.25, 5.75),
            ..sample
        };
        let rx = camera.generate_ray(&right).unwrap().ray;
        let ry = camera.generate_ray(&down).unwrap().ray;
        assert_close3(diff.rx_origin.to_glam(), rx.origin.to_glam(), 1e-6);
        assert_close3(diff.rx_direction.to_glam(), rx.direction.to_glam(), 1e-6);
        assert_close3(diff.ry_origin.to_glam(), ry.origin.to_glam(), 1e-6);
        assert_close3(diff.ry_direction.to_glam(), ry.direction.to_glam(), 1e-6);
        // One pixel right turns the ray towards world +x (identity look: camera x = world x),
        // one pixel down towards world -y.
        assert!(diff.rx_direction.x > main.direction.x);
        assert!(diff.ry_direction.y < main.direction.y);
    }
}

/// A non-finite sample gives no ray rather than a NaN ray.
#[test]
fn non_finite_samples_give_no_ray() {
    let camera = PerspectiveCamera::new(
        base_at(identity_look(), [4, 4], None, 0.01, 100.0),
        50.0,
        FovAxis::Smaller,
        ThinLens::PINHOLE,
    )
    .unwrap();
    let mut sample = CameraSample::at(Point2::new(f32::NAN, 1.0));
    assert!(camera.generate_ray(&sample).is_none());
    sample.p_film = Point2::new(1.0, 1.0);
    sample.time = f32::INFINITY;
    assert!(camera.generate_ray_differential(&sample).is_none());
}

/// Every field of the sample is checked, against every kind of non-finite number: the check
/// is one sum of `0 * v` terms, so each term must be able to spoil it on its own.
#[test]
fn each_non_finite_field_alone_gives_no_ray() {
    let camera = PerspectiveCamera::new(
        base_at(identity_look(), [4, 4], None, 0.01, 100.0),
        50.0,
        FovAxis::Smaller,
        ThinLens::new(0.1, 2.0).unwrap(),
    )
    .unwrap();
    let good = CameraSample {
        p_film: Point2::new(1.5, 2.5),
        p_lens: glam::Vec2::new(0.25, 0.75),
        time: 0.5,
    };
    assert!(camera.generate_ray(&good).is_some());
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for field in 0..5 {
            let mut sample = good;
            match field {
                0 => sample.p_film.x = bad,
                1 => sample.p_film.y = bad,
                2 => sample.p_lens.x = bad,
                3 => sample.p_lens.y = bad,
                _ => sample.time = bad,
            }
            assert!(
                camera.generate_ray(&sample).is_none(),
                "{bad} in field {field}"
            );
            assert!(
                camera.generate_ray_differential(&sample).is_none(),
                "{bad} in field {field}"
            );
        }
    }
}

#[test]
fn a_screen_window_is_a_window_onto_the_fovs_screen() {
    // pbrt's screen space: the fov fixes the scale, s = 1 / tan(fov / 2) along the smaller
    // axis of the default window, and a screen window given in the scene picks a part of that
    // screen. By hand, fov 90 on a square film (s = 1, screen x = camera x / z): the window
    // [0, 1] x [0, 1] sees x / z and y / z from 0 to 1, so the top-left raster corner looks
    // along (0, 1, 1), the bottom-right along (1, 0, 1), the centre along (0.5, 0.5, 1). The
    // same window twice as large, [-0.5, 1.5]^2, sees twice the range about the same centre.
    let window = |w: [f32; 4]| ScreenWindow::new(w[0], w[1], w[2], w[3]).unwrap();
    for (w, corner, centre) in [
        ([0.0, 1.0, 0.0, 1.0], [0.0, 1.0], [0.5, 0.5]),
        ([-0.5, 1.5, -0.5, 1.5], [-0.5, 1.5], [0.5, 0.5]),
    ] {
        let base = base_at(identity_look(), [100, 100], Some(window(w)), 0.001, 1e30);
        let camera =
            PerspectiveCamera::new(base, 90.0, FovAxis::Smaller, ThinLens::PINHOLE).unwrap();
        for (raster, slope) in [([0.0, 0.0], corner), ([50.0, 50.0], centre)] {
            let ray = camera
                .generate_ray(&CameraSample {
                    p_film: Point2::<Raster>::new(raster[0], raster[1]),
                    p_lens: glam::Vec2::splat(0.5),
                    time: 0.0,
                })
                .unwrap()
                .ray;
            // identity_look: camera +x = world +x, +y = world +y, +z = world -z.
            let d = ray.direction.to_glam();
            let got = [d.x / -d.z, d.y / -d.z];
            assert!(
                (got[0] - slope[0]).abs() < 1e-5 && (got[1] - slope[1]).abs() < 1e-5,
                "window {w:?}, raster {raster:?}: {got:?} against {slope:?}"
            );
        }
    }
}
