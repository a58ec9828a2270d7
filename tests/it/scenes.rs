//! The shipped scenes, rendered small, checked against geometry worked out by hand, and the
//! renderer's determinism across thread counts and cancellation.

use super::{aov, render_image, shipped};
use glam::Vec3;
use obscura_camera::Camera;
use obscura_render::{
    Film, FilterSettings, Image, IntegratorKind, RenderOptions, RenderOutcome, RenderScene,
    SceneDescription, TILE_WINDOW, render, tiles,
};
use obscura_space::{Point3, World};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Every shipped scene loads, builds and renders a tiny image with finite pixels.
#[test]
fn every_shipped_scene_renders() {
    let dir = super::root().join("scenes");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        count += 1;
        let d = obscura_render::load_description(&path).unwrap_or_else(|e| panic!("{e}"));
        let image = render_image(aov(d, IntegratorKind::Path, [24, 16], 2), 2);
        assert!(
            image.pixels.iter().all(|p| p.iter().all(|c| c.is_finite())),
            "{}",
            path.display()
        );
        assert!(
            image.pixels.iter().any(|p| p[0] + p[1] + p[2] > 0.0),
            "{} is black",
            path.display()
        );
    }
    assert!(
        count >= 5,
        "expected the five spheres scenes, found {count}"
    );
}

/// The pixel holding a world point's projection at time 0.
fn pixel_of(scene: &RenderScene, p: [f32; 3]) -> (u32, u32) {
    let r = scene
        .camera
        .project(Point3::<World>::new(p[0], p[1], p[2]), 0.0)
        .expect("visible");
    (r.x.floor() as u32, r.y.floor() as u32)
}

#[test]
fn depth_at_a_sphere_centre_is_the_analytic_distance() {
    // Box filter, so the centre pixel averages only its own samples.
    let mut d = aov(
        shipped("spheres-perspective.toml"),
        IntegratorKind::Depth,
        [160, 120],
        4,
    );
    d.film.filter = FilterSettings::Box { radius: 0.5 };
    let scene = RenderScene::build(d.clone()).unwrap();
    let eye = d.camera.start.eye.to_glam();
    let view = (d.camera.start.target.to_glam() - eye).normalize();
    for (center, radius) in [
        ([0.0, 0.7, 0.0], 0.7),
        ([-1.6, 0.7, -1.5], 0.7),
        ([1.6, 0.7, 1.5], 0.7),
    ] {
        let (x, y) = pixel_of(&scene, center);
        let image = render_image(d.clone(), 2);
        // The ray towards the centre meets the sphere |c - eye| - r from the eye; its camera z
        // is that distance times the cosine between the ray and the view direction.
        let to_center = Vec3::from(center) - eye;
        let expected = (to_center.length() - radius) * to_center.normalize().dot(view);
        let got = image.pixel(x, y)[0];
        // A pixel spans 40/120 degrees here: across it the sphere's surface moves by well under
        // 0.2% of the distance.
        assert!(
            (got - expected).abs() < 2e-3 * expected,
            "sphere at {center:?}: depth {got}, expected {expected}"
        );
        assert_eq!(
            image.pixel(x, y)[3],
            1.0,
            "the centre pixel is fully covered"
        );
    }
}

/// The floor's albedo in the spheres scenes.
const FLOOR: Vec3 = Vec3::splat(0.7);

/// How much of a pixel a sphere of albedo `a` covers, against the floor, from the albedo AOV.
fn fraction_of(image: &Image, x: u32, y: u32, a: [f32; 3]) -> f32 {
    let p = image.pixel(x, y);
    let d = Vec3::from(a) - FLOOR;
    (Vec3::new(p[0], p[1], p[2]) - FLOOR).dot(d) / d.length_squared()
}

/// The green sphere's share of a pixel (its albedo is (0.2, 0.7, 0.25)); the blue one's, (0.2,
/// 0.3, 0.8), by the same red channel: 0.2 on both spheres against 0.7 on the floor.
fn sphere_fraction(image: &Image, x: u32, y: u32) -> f32 {
    (0.7 - image.pixel(x, y)[0]) / 0.5
}

/// Pixels in the blurred band of a silhouette: walking from `x` (inside the sphere) in
/// direction `step`, the number of pixels whose sphere fraction is strictly between 10% and 90%.
fn edge_width(image: &Image, x: u32, y: u32, step: i32) -> u32 {
    let mut x = x as i32;
    let mut width = 0;
    while x >= 0 && (x as u32) < image.width {
        let f = sphere_fraction(image, x as u32, y);
        if f < 0.1 {
            break;
        }
        if f < 0.9 {
            width += 1;
        }
        x += step;
    }
    width
}

#[test]
fn thin_lens_keeps_the_focused_sphere_sharp_and_blurs_the_near_one() {
    let mut d = aov(
        shipped("spheres-thin-lens.toml"),
        IntegratorKind::Albedo,
        [320, 240],
        32,
    );
    d.film.filter = FilterSettings::Box { radius: 0.5 };
    let scene = RenderScene::build(d.clone()).unwrap();
    let lens = render_image(d.clone(), 2);
    let mut pinhole = d.clone();
    pinhole.camera.lens.radius = 0.0;
    let pinhole = render_image(pinhole, 2);

    // The green sphere (in focus) and its right edge; the blue one (near) and its left edge.
    let (gx, gy) = pixel_of(&scene, [0.0, 0.7, 0.0]);
    let (bx, by) = pixel_of(&scene, [1.6, 0.7, 1.5]);
    let focused = edge_width(&lens, gx, gy, 1);
    let near = edge_width(&lens, bx, by, -1);
    let near_pinhole = edge_width(&pinhole, bx, by, -1);
    // The circle of confusion: a point at camera depth z, with the lens focused at f, spreads
    // over a disc of radius R (1/z - 1/f) on the z = 1 plane. Here z = 4.569 (the blue sphere's
    // centre: (1.6, -0.8, -4.5) . (0, -0.1483, -0.9889)) and 240 rows span 2 tan(20 deg) = 0.728.
    let c = &d.camera;
    let z_blue = 4.569f32;
    let pixels_per_unit = 240.0 / (2.0 * 20f32.to_radians().tan());
    let coc = c.lens.radius * (1.0 / z_blue - 1.0 / c.lens.focal_distance) * pixels_per_unit;
    // A disc-blurred edge climbs from 10% to 90% over about 1.3 coc pixels.
    let band = 1.3 * coc;
    assert!(
        band > 3.0,
        "the shipped lens should blur visibly; band {band}"
    );
    assert!(focused <= 2, "the focused edge is {focused} pixels wide");
    assert!(
        near_pinhole <= 2,
        "without a lens the near edge is {near_pinhole} pixels wide"
    );
    assert!(
        near as f32 >= 0.6 * band,
        "the out-of-focus edge is only {near} pixels wide, expected about {band:.1}"
    );
    assert!(
        near as f32 <= 1.6 * band + 1.0,
        "the out-of-focus edge is {near} pixels wide, expected about {band:.1}"
    );
}

#[test]
fn motion_blur_smears_the_moving_sphere_by_its_screen_motion_only() {
    // A still camera, so only the blue sphere moves (1.2 units towards -x).
    let mut d = aov(
        shipped("spheres-motion-blur.toml"),
        IntegratorKind::Albedo,
        [320, 240],
        32,
    );
    d.film.filter = FilterSettings::Box { radius: 0.5 };
    d.camera.end = None;
    let scene = RenderScene::build(d.clone()).unwrap();
    let moving = render_image(d.clone(), 2);
    let mut still = d.clone();
    still.camera.shutter = obscura_camera::Shutter::new(0.0, 0.0).unwrap();
    let still = render_image(still, 2);

    let open = scene
        .camera
        .project(Point3::new(1.6, 0.7, 1.5), 0.0)
        .unwrap();
    let close = scene
        .camera
        .project(Point3::new(0.4, 0.7, 1.5), 1.0)
        .unwrap();
    let expected = open.x - close.x;
    assert!(
        expected > 20.0,
        "the motion should span many pixels, got {expected}"
    );

    // The blue sphere's share of each pixel on its centre row: unmix the albedo of blue
    // (0.2, 0.3, 0.8), green (0.2, 0.7, 0.25) and floor (0.7, 0.7, 0.7).
    let unmix = glam::Mat3::from_cols(
        Vec3::new(0.2, 0.3, 0.8),
        Vec3::new(0.2, 0.7, 0.25),
        Vec3::splat(0.7),
    )
    .inverse();
    let y = open.y as u32;
    let blue = |image: &Image, x: u32| {
        let p = image.pixel(x, y);
        (unmix * Vec3::new(p[0], p[1], p[2])).x
    };
    let extent = |image: &Image| {
        let xs: Vec<u32> = (0..image.width)
            .filter(|&x| blue(image, x) > 0.02)
            .collect();
        (xs[0], *xs.last().unwrap())
    };
    let (m0, m1) = extent(&moving);
    let (s0, s1) = extent(&still);
    // The right end stays where the sphere starts; the left end moves by the screen motion.
    assert!(m1.abs_diff(s1) <= 1, "right ends {m1} and {s1}");
    let smear = (s0 - m0) as f32;
    assert!(
        (smear - expected).abs() <= 3.0,
        "smeared {smear} pixels, expected {expected:.1}"
    );

    // Static objects are unchanged: the red sphere's side of the image is the same to the bit.
    for yy in 0..moving.height {
        for x in 0..moving.width / 3 {
            assert_eq!(moving.pixel(x, yy), still.pixel(x, yy), "pixel ({x}, {yy})");
        }
    }
}

#[test]
fn the_environment_camera_sees_each_sphere_in_its_direction() {
    let d = aov(
        shipped("spheres-environment.toml"),
        IntegratorKind::Albedo,
        [128, 64],
        4,
    );
    let image = render_image(d, 2);
    // The eye looks along world -z with world +x to its right. The mapping puts the view
    // direction at x = w/2, camera +x (right) at 3w/4, -x at w/4, behind at the edges; the
    // horizon (theta = 90 degrees) at y = h/2: the spheres' centres are at the eye's height.
    let (w, h) = (image.width, image.height);
    let y = h / 2;
    let cases = [
        (w / 2, [0.2, 0.7, 0.25], "green ahead"),
        (3 * w / 4, [0.8, 0.2, 0.15], "red to the right"),
        (w / 4, [0.8, 0.7, 0.2], "yellow to the left"),
        (0, [0.2, 0.3, 0.8], "blue behind (left edge)"),
        (w - 1, [0.2, 0.3, 0.8], "blue behind (right edge)"),
    ];
    for (x, albedo, what) in cases {
        let p = image.pixel(x, y);
        assert!(
            (Vec3::new(p[0], p[1], p[2]) - Vec3::from(albedo))
                .abs()
                .max_element()
                < 0.02,
            "{what}: pixel ({x}, {y}) has albedo {p:?}"
        );
    }
    // The top row looks up at the sky (nothing hit); the bottom row down at the floor.
    assert!(image.pixels[..w as usize].iter().all(|p| p[3] == 0.0));
    assert!(
        image.pixels[((h - 1) * w) as usize..]
            .iter()
            .all(|p| (p[0] - 0.7).abs() < 1e-4 && p[3] == 1.0)
    );
}

#[test]
fn orthographic_spheres_keep_their_size_with_distance() {
    // Three equal spheres at different depths: through the orthographic camera their
    // silhouettes are equally wide; through the perspective one the nearest is widest.
    let width = |name: &str| {
        let mut d = aov(shipped(name), IntegratorKind::Albedo, [320, 240], 4);
        d.film.filter = FilterSettings::Box { radius: 0.5 };
        let scene = RenderScene::build(d.clone()).unwrap();
        let image = render_image(d, 2);
        // The red sphere (far) and the blue one (near), each counted by its own albedo.
        [
            ([-1.6, 0.7, -1.5], [0.8, 0.2, 0.15]),
            ([1.6, 0.7, 1.5], [0.2, 0.3, 0.8]),
        ]
        .map(|(c, albedo)| {
            let (x, y) = pixel_of(&scene, c);
            (0..image.width)
                .filter(|&xx| xx.abs_diff(x) < 80 && fraction_of(&image, xx, y, albedo) > 0.5)
                .count() as i64
        })
    };
    let [far, near] = width("spheres-orthographic.toml");
    assert!(
        (far - near).abs() <= 2,
        "orthographic widths {far} and {near}"
    );
    let [far, near] = width("spheres-perspective.toml");
    assert!(
        near > far + 10,
        "perspective widths {far} (far) and {near} (near)"
    );
}

#[test]
fn images_are_identical_for_one_and_two_threads() {
    // The motion-blurred spheres, and the Cornell box, whose diffuse vertices aim at its
    // mirror and glass spheres (aimed samples go through the batched and one-path loops).
    for (scene, resolution) in [
        ("spheres-motion-blur.toml", [48, 32]),
        ("cornell-box.toml", [40, 40]),
    ] {
        let d = aov(shipped(scene), IntegratorKind::Path, resolution, 4);
        let one = render_image(d.clone(), 1);
        let two = render_image(d, 2);
        assert!(
            one.pixels
                .iter()
                .zip(&two.pixels)
                .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits)),
            "{scene}"
        );
    }
}

#[test]
fn the_renderer_aims_at_the_cornell_box_mirror_and_glass() {
    // The renderer hands every instance to the shading scene, which keeps the static
    // specular ones as casters for diffuse vertices to aim at: the mirror and the glass
    // sphere here; the spheres-only scenes have none.
    let scene = RenderScene::build(shipped("cornell-box.toml")).unwrap();
    assert_eq!(scene.shading.caster_count(), 2);
    let plain = RenderScene::build(shipped("spheres-perspective.toml")).unwrap();
    assert_eq!(plain.shading.caster_count(), 0);
}

/// Renders `d` on `threads` workers; when pass `hold_pass` is complete, the pass callback
/// (which runs while the merge is held) waits until `hold_until(total tiles)` tiles have been
/// rendered, then sets the cancel flag if `cancel_after_hold`. So the other workers run ahead
/// of the merge by a known amount, with no timing involved.
fn render_holding_the_merge(
    d: SceneDescription,
    threads: usize,
    hold_pass: u32,
    hold_until: impl Fn(u64) -> u64 + Sync,
    cancel_after_hold: bool,
) -> RenderOutcome {
    let scene = RenderScene::build(d).unwrap();
    let cancel = AtomicBool::new(false);
    let rendered = AtomicU64::new(0);
    let total = AtomicU64::new(u64::MAX);
    let on_tile = |done: u64, all: u64| {
        total.store(all, Ordering::SeqCst);
        rendered.fetch_max(done, Ordering::SeqCst);
    };
    let on_pass = |passes: u32, _: u32, _: &Film| {
        if passes == hold_pass {
            let target = hold_until(total.load(Ordering::SeqCst));
            while rendered.load(Ordering::SeqCst) < target {
                std::thread::yield_now();
            }
            if cancel_after_hold {
                cancel.store(true, Ordering::SeqCst);
            }
        }
    };
    render(
        &scene,
        RenderOptions {
            threads: Some(threads),
            cancel: Some(&cancel),
            on_pass: Some(&on_pass),
            on_tile: Some(&on_tile),
            ..RenderOptions::default()
        },
    )
    .unwrap()
}

#[test]
fn images_are_identical_for_any_thread_count_when_rendering_runs_far_ahead_of_merging() {
    // 25 x 23 = 575 tiles a pass, three passes. The merge is held after the first pass until
    // the other workers have rendered a whole window of tiles past it, so they must wait for
    // the merge; the Gaussian filter makes neighbouring tiles overlap, so the merge order
    // shows in the bits of the film.
    let d = aov(
        shipped("spheres-perspective.toml"),
        IntegratorKind::Path,
        [400, 360],
        3,
    );
    let per_pass = tiles(RenderScene::build(d.clone()).unwrap().pixel_bounds).len() as u64;
    assert_eq!(per_pass, 575);
    let one = render_image(d.clone(), 1);
    let held = render_holding_the_merge(d, 3, 1, |_| per_pass + TILE_WINDOW as u64, false);
    assert_eq!(held.passes_done, 3);
    let three = held.film.resolve();
    assert_eq!(one.pixels.len(), three.pixels.len());
    assert!(
        one.pixels
            .iter()
            .zip(&three.pixels)
            .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits))
    );
}

#[test]
fn a_cancelled_render_on_several_threads_keeps_exactly_the_passes_before_the_cancel() {
    // Every tile of all five passes is rendered while the merge is held at pass 2; the
    // cancel then comes, so passes 3-5, although rendered, must not reach the film.
    let d = aov(
        shipped("spheres-perspective.toml"),
        IntegratorKind::Path,
        [96, 64],
        5,
    );
    let outcome = render_holding_the_merge(d.clone(), 3, 2, |total| total, true);
    assert_eq!(outcome.passes_done, 2);
    // The same render's first two passes on one thread (samples depend on the spp, so not a
    // 2-spp render).
    let straight = render(
        &RenderScene::build(d).unwrap(),
        RenderOptions {
            threads: Some(1),
            passes: Some(0..2),
            ..RenderOptions::default()
        },
    )
    .unwrap();
    assert_eq!(straight.passes_done, 2);
    assert!(outcome.film == straight.film, "the films differ");
}

#[test]
fn the_shipped_sky_is_what_its_generator_makes() {
    // scenes/sky.exr must be reproducible from the code that documents how it was made.
    let (shipped, _) =
        obscura_render::read_exr(&super::root().join("scenes").join("sky.exr")).unwrap();
    let made = camera_obscura::sky::procedural_sky(
        camera_obscura::sky::SKY_WIDTH,
        camera_obscura::sky::SKY_HEIGHT,
    );
    assert_eq!((shipped.width, shipped.height), (made.width, made.height));
    assert!(
        shipped
            .pixels
            .iter()
            .zip(&made.pixels)
            .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits))
    );
    // The sun is where sun_direction() says: the brightest texel looks along it (within a texel).
    let brightest = (0..made.pixels.len())
        .max_by(|&a, &b| made.pixels[a][0].total_cmp(&made.pixels[b][0]))
        .unwrap();
    let (x, y) = (
        (brightest as u32 % made.width) as f32 + 0.5,
        (brightest as u32 / made.width) as f32 + 0.5,
    );
    let theta = std::f32::consts::PI * y / made.height as f32;
    let phi = std::f32::consts::TAU * (x / made.width as f32 - 0.5);
    let d = Vec3::new(
        theta.sin() * phi.sin(),
        theta.cos(),
        theta.sin() * phi.cos(),
    );
    assert!(
        d.dot(camera_obscura::sky::sun_direction()) > 4f32.to_radians().cos(),
        "{d:?}"
    );
}
