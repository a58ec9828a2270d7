//! Issue 21's photographic controls: apertures (polygon, image, anamorphic), shutter curves,
//! rolling shutters and the tilted plane of focus. Expected values come from formulas written
//! here, never from the code under test.

use crate::{base_at, cases, identity_look};
use glam::{Vec2, Vec3};
use obscura_camera::{
    Aperture, ApertureImage, Camera, CameraSample, FovAxis, OrthographicCamera, PerspectiveCamera,
    RollingDirection, RollingShutter, ShutterTiming, ThinLens,
};
use obscura_sample::PiecewiseShutterCurve;
use obscura_space::{Point2, Raster};
use proptest::prelude::*;
use std::sync::Arc;

/// A small deterministic uniform generator (xorshift64*), so the statistics are repeatable.
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40;
        bits as f32 / (1u64 << 24) as f32
    }
    fn next2(&mut self) -> Vec2 {
        Vec2::new(self.next(), self.next())
    }
}

/// Pearson's chi-square statistic, asserted below a bound five standard deviations above its
/// mean (`k - 1` degrees of freedom, variance `2 (k - 1)`); cells expecting nothing must get
/// nothing.
fn assert_chi_square(observed: &[f64], expected: &[f64], what: &str) {
    let mut stat = 0.0;
    let mut k = 0;
    for (&o, &e) in observed.iter().zip(expected) {
        if e == 0.0 {
            assert_eq!(o, 0.0, "{what}: a sample landed where the density is 0");
            continue;
        }
        stat += (o - e) * (o - e) / e;
        k += 1;
    }
    let dof = (k - 1) as f64;
    let bound = dof + 5.0 * (2.0 * dof).sqrt();
    assert!(stat < bound, "{what}: chi-square {stat} over {dof} dof");
}

/// True when `p` lies in the regular polygon with `n` vertices on the unit circle, vertex 0 at
/// `rotation` degrees: on the inner side of every edge (written independently of the crate).
fn in_polygon(p: Vec2, n: u32, rotation: f32) -> bool {
    let vertex = |k: u32| {
        let a = rotation.to_radians() + std::f32::consts::TAU * k as f32 / n as f32;
        Vec2::new(a.cos(), a.sin())
    };
    (0..n).all(|k| {
        let (a, b) = (vertex(k), vertex((k + 1) % n));
        (b - a).perp_dot(p - a) >= 0.0
    })
}

#[test]
fn polygon_samples_are_uniform_over_the_polygon() {
    let (blades, rotation) = (5, 20.0);
    let aperture = Aperture::polygon(blades, rotation).unwrap();
    // Cells of a 10 x 10 grid over [-1, 1]^2; expected shares from the covered area, found by
    // a fine sub-grid point test.
    let cells = 10;
    let sub = 40;
    let mut area = vec![0.0f64; cells * cells];
    for i in 0..cells * sub {
        for j in 0..cells * sub {
            let p = Vec2::new(
                -1.0 + 2.0 * (i as f32 + 0.5) / (cells * sub) as f32,
                -1.0 + 2.0 * (j as f32 + 0.5) / (cells * sub) as f32,
            );
            if in_polygon(p, blades, rotation) {
                area[(j / sub) * cells + i / sub] += 1.0;
            }
        }
    }
    let total_area: f64 = area.iter().sum();
    let n = 200_000;
    let mut counts = vec![0.0f64; cells * cells];
    let mut rng = Uniform(7);
    for _ in 0..n {
        let p = aperture.sample(rng.next2());
        assert!(
            in_polygon(p * (1.0 - 1e-5), blades, rotation),
            "{p} outside"
        );
        let i = (((p.x + 1.0) * 0.5 * cells as f32) as usize).min(cells - 1);
        let j = (((p.y + 1.0) * 0.5 * cells as f32) as usize).min(cells - 1);
        counts[j * cells + i] += 1.0;
    }
    // Cells the polygon's edge crosses get a sub-grid estimate of their area, good to a
    // fraction of a percent; merge the counts of cells with tiny areas to keep them honest.
    let expected: Vec<f64> = area.iter().map(|a| a / total_area * n as f64).collect();
    let (obs, exp): (Vec<f64>, Vec<f64>) = counts
        .iter()
        .zip(&expected)
        .filter(|(_, e)| **e > 50.0)
        .map(|(o, e)| (*o, *e))
        .unzip();
    assert_chi_square(&obs, &exp, "polygon");
}

#[test]
fn aperture_image_samples_follow_the_image() {
    // A 4 x 3 image (row 0 on top) with a dark cell, a bright cell and a gradient.
    let weights = [
        0.0, 1.0, 2.0, 3.0, //
        4.0, 0.5, 0.0, 1.0, //
        1.0, 1.0, 8.0, 2.0,
    ];
    let (w, h) = (4, 3);
    let aperture = Aperture::image(ApertureImage::new(&weights, w, h).unwrap());
    let total: f32 = weights.iter().sum();
    let n = 100_000;
    let mut counts = vec![0.0f64; w * h];
    let mut rng = Uniform(11);
    for _ in 0..n {
        let p = aperture.sample(rng.next2());
        assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0, "{p}");
        // Aperture x right, y up; image column from x, row from the top.
        let col = (((p.x + 1.0) * 0.5 * w as f32) as usize).min(w - 1);
        let row = (((1.0 - p.y) * 0.5 * h as f32) as usize).min(h - 1);
        counts[row * w + col] += 1.0;
    }
    let expected: Vec<f64> = weights
        .iter()
        .map(|&wt| f64::from(wt / total) * n as f64)
        .collect();
    assert_chi_square(&counts, &expected, "aperture image");
}

#[test]
fn anamorphic_samples_fill_the_squeezed_ellipse() {
    let s = 1.33;
    let aperture = Aperture::CIRCLE.with_anamorphic(s).unwrap();
    let n = 100_000;
    let mut rng = Uniform(3);
    // Uniform over the ellipse x^2 s^2 + y^2 <= 1: the shares inside the concentric ellipses
    // of scale 0.5 and in each quadrant are 1/4 each; the extremes reach 1/s and 1.
    let (mut inner, mut quadrants, mut max) = (0.0f64, [0.0f64; 4], Vec2::ZERO);
    for _ in 0..n {
        let p = aperture.sample(rng.next2());
        let r2 = (p.x * s) * (p.x * s) + p.y * p.y;
        assert!(r2 <= 1.0 + 1e-5, "{p} outside the ellipse");
        if r2 <= 0.25 {
            inner += 1.0;
        }
        quadrants[usize::from(p.x >= 0.0) + 2 * usize::from(p.y >= 0.0)] += 1.0;
        max = max.max(p.abs());
    }
    let quarter = 0.25 * n as f64;
    let mut obs = vec![inner, n as f64 - inner];
    let mut exp = vec![quarter, 3.0 * quarter];
    obs.extend(quadrants);
    exp.extend([quarter; 4]);
    assert_chi_square(&obs[..2], &exp[..2], "ellipse radius");
    assert_chi_square(&obs[2..], &exp[2..], "ellipse quadrants");
    assert!(
        (max.x - 1.0 / s).abs() < 0.01 && (max.y - 1.0).abs() < 0.01,
        "{max}"
    );
}

/// A perspective camera at the identity look-at (camera space = world with z flipped) over a
/// `resolution` film with the given lens and shutter timing.
fn camera(resolution: [u32; 2], lens: ThinLens, timing: ShutterTiming) -> PerspectiveCamera {
    let base = base_at(identity_look(), resolution, None, 0.001, 1e30).with_timing(timing);
    PerspectiveCamera::new(base, 60.0, FovAxis::Smaller, lens).unwrap()
}

#[test]
fn shutter_curve_times_match_the_curve() {
    let points = [[0.0, 0.0], [0.2, 1.0], [0.5, 0.25], [0.9, 1.0], [1.0, 0.0]];
    let curve = PiecewiseShutterCurve::new(&points).unwrap();
    let timing = ShutterTiming {
        curve: Some(Arc::new(curve)),
        rolling: None,
    };
    let cam = camera([4, 4], ThinLens::PINHOLE, timing);
    // The openness, linear between the points, integrated per bin by the midpoint rule on a
    // fine grid.
    let openness = |t: f64| {
        points
            .windows(2)
            .find(|w| (f64::from(w[0][0])..=f64::from(w[1][0])).contains(&t))
            .map_or(0.0, |w| {
                let [t0, o0] = w[0].map(f64::from);
                let [t1, o1] = w[1].map(f64::from);
                o0 + (o1 - o0) * (t - t0) / (t1 - t0)
            })
    };
    let bins = 20;
    let fine = 200;
    let mass: Vec<f64> = (0..bins)
        .map(|b| {
            (0..fine)
                .map(|k| openness((b as f64 + (k as f64 + 0.5) / fine as f64) / bins as f64))
                .sum()
        })
        .collect();
    let total: f64 = mass.iter().sum();
    let n = 100_000;
    // Stratified time samples: the curve must keep equal-weight strata equal-weight.
    let mut counts = vec![0.0f64; bins];
    let mut rng = Uniform(5);
    for i in 0..n {
        let u = (i as f32 + rng.next()) / n as f32;
        let sample = CameraSample {
            time: u.min(0.999_999_9),
            ..CameraSample::at(Point2::new(2.0, 2.0))
        };
        let t = cam.generate_ray(&sample).unwrap().ray.time;
        counts[((t * bins as f32) as usize).min(bins - 1)] += 1.0;
    }
    let expected: Vec<f64> = mass.iter().map(|m| m / total * n as f64).collect();
    assert_chi_square(&counts, &expected, "shutter curve");
}

#[test]
fn each_rolling_shutter_row_samples_exactly_its_window() {
    let (rows, cols) = (6u32, 5u32);
    for direction in [
        RollingDirection::TopToBottom,
        RollingDirection::BottomToTop,
        RollingDirection::LeftToRight,
        RollingDirection::RightToLeft,
    ] {
        let readout = 0.6;
        let timing = ShutterTiming {
            curve: None,
            rolling: Some(RollingShutter { readout, direction }),
        };
        let cam = camera([cols, rows], ThinLens::PINHOLE, timing);
        // Shutter [0, 1]: window of readout index k is [0.6 k / n, 0.6 k / n + 0.4].
        for y in 0..rows {
            for x in 0..cols {
                let (k, n) = match direction {
                    RollingDirection::TopToBottom => (y, rows),
                    RollingDirection::BottomToTop => (rows - 1 - y, rows),
                    RollingDirection::LeftToRight => (x, cols),
                    RollingDirection::RightToLeft => (cols - 1 - x, cols),
                };
                let start = readout * k as f32 / n as f32;
                let end = start + (1.0 - readout);
                let (mut lo, mut hi) = (f32::MAX, f32::MIN);
                for i in 0..64 {
                    let u = Vec2::new((i % 8) as f32 / 8.0 + 0.01, (i / 8) as f32 / 8.0 + 0.01);
                    let sample = CameraSample {
                        p_film: Point2::<Raster>::new(x as f32 + u.x, y as f32 + u.y),
                        p_lens: Vec2::splat(0.5),
                        time: i as f32 / 63.0 * 0.999_999,
                    };
                    let t = cam.generate_ray(&sample).unwrap().ray.time;
                    lo = lo.min(t);
                    hi = hi.max(t);
                }
                assert!(
                    (lo - start).abs() < 1e-6,
                    "{direction:?} ({x}, {y}): {lo} vs {start}"
                );
                assert!(
                    (hi - end).abs() < 1e-5,
                    "{direction:?} ({x}, {y}): {hi} vs {end}"
                );
            }
        }
    }
}

/// Camera-space point of the identity look-at's world point (camera z = -world z).
fn to_camera(p: obscura_space::Point3<obscura_space::World>) -> Vec3 {
    Vec3::new(p.x, p.y, -p.z)
}

proptest! {
    #![proptest_config(cases(64))]

    /// Every aperture sample lies in its outline, squeezed: the polygon (or disk) with x
    /// multiplied back by the squeeze.
    #[test]
    fn aperture_samples_stay_inside_the_squeezed_outline(
        blades in prop_oneof![Just(0u32), 3u32..12],
        rotation in -360f32..360.0,
        squeeze in 1f32..3.0,
        ux in 0f32..1.0, uy in 0f32..1.0,
    ) {
        let aperture = Aperture::polygon(blades, rotation)
            .unwrap()
            .with_anamorphic(squeeze)
            .unwrap();
        let p = aperture.sample(Vec2::new(ux, uy));
        let unsqueezed = Vec2::new(p.x * squeeze, p.y) * (1.0 - 1e-5);
        if blades == 0 {
            prop_assert!(unsqueezed.length() <= 1.0, "{}", p);
        } else {
            prop_assert!(in_polygon(unsqueezed, blades, rotation), "{}", p);
        }
    }

    /// Points on the tilted plane image to a point: every lens sample's ray through a film
    /// point passes through the centre ray's meeting point with the plane. Points off the plane
    /// spread by the thin-lens formula: at depth `z` the ray from lens point `a` is
    /// `|a| |1 - z / z_f|` from the centre ray (`z_f` the focus depth on that ray).
    #[test]
    fn tilted_plane_is_sharp_and_off_plane_blurs_as_predicted(
        tilt_x in -40f32..40.0, tilt_y in -40f32..40.0,
        fx in 0.5f32..63.5, fy in 0.5f32..47.5,
        depth_factor in 0.3f32..3.0,
    ) {
        let lens = ThinLens::new(0.2, 5.0).unwrap().with_tilt([tilt_x, tilt_y]).unwrap();
        let cam = camera([64, 48], lens, ShutterTiming::default());
        let p_film = Point2::<Raster>::new(fx, fy);
        let centre = cam.generate_ray(&CameraSample::at(p_film)).unwrap().ray;
        let d = to_camera_dir(centre.direction);
        // The plane z = 5 + y tan(a) + x tan(b), met by s d: s (d.z - d.y tan a - d.x tan b) = 5.
        let (ta, tb) = (tilt_x.to_radians().tan(), tilt_y.to_radians().tan());
        let denominator = d.z - d.y * ta - d.x * tb;
        prop_assume!(denominator > 0.05);
        let focus = d * (5.0 / denominator);
        lens_rays_meet(&cam, p_film, focus, (Vec3::ZERO, d), depth_factor)?;
    }
}

proptest! {
    #![proptest_config(cases(64))]

    /// The orthographic thin lens tilts its plane of focus too. A film point's centre ray runs
    /// along +z from the film point `(x, y, 0)`, so it meets the plane
    /// `z = 5 + y tan(a) + x tan(b)` at `(x, y, 5 + y tan(a) + x tan(b))`: every lens sample's
    /// ray from that film point passes there, and off the plane spreads by `|a| |1 - z / z_f|`.
    #[test]
    fn an_orthographic_thin_lens_tilts_its_plane_of_focus(
        tilt_x in -40f32..40.0, tilt_y in -40f32..40.0,
        fx in 0.5f32..63.5, fy in 0.5f32..47.5,
        depth_factor in 0.3f32..3.0,
    ) {
        let lens = ThinLens::new(0.2, 5.0).unwrap().with_tilt([tilt_x, tilt_y]).unwrap();
        let base = base_at(identity_look(), [64, 48], None, 0.001, 1e30);
        let cam = OrthographicCamera::new(base, lens).unwrap();
        let p_film = Point2::<Raster>::new(fx, fy);
        let centre = cam.generate_ray(&CameraSample::at(p_film)).unwrap().ray;
        let film = to_camera(centre.origin);
        prop_assert!(film.z.abs() < 1e-6 && to_camera_dir(centre.direction).z > 0.999_999);
        let (ta, tb) = (tilt_x.to_radians().tan(), tilt_y.to_radians().tan());
        let focus = Vec3::new(film.x, film.y, 5.0 + film.y * ta + film.x * tb);
        prop_assume!(focus.z > 0.05);
        lens_rays_meet(&cam, p_film, focus, (film, Vec3::Z), depth_factor)?;
    }
}

/// Every lens sample's ray from `p_film` passes through `focus` (camera space), and off the
/// plane spreads as the thin lens predicts: at depth `z = depth_factor * focus.z` the ray from
/// lens point `o` is `|o - c| |1 - z / focus.z|` from the centre ray's point there, with the
/// centre ray `(c, d)` (origin and direction, camera space) and the lens on the plane z = 0.
fn lens_rays_meet(
    cam: &impl Camera,
    p_film: Point2<Raster>,
    focus: Vec3,
    (c, d): (Vec3, Vec3),
    depth_factor: f32,
) -> Result<(), TestCaseError> {
    for i in 0..16 {
        let u = Vec2::new((i % 4) as f32 / 4.0 + 0.1, (i / 4) as f32 / 4.0 + 0.1);
        let sample = CameraSample {
            p_lens: u,
            ..CameraSample::at(p_film)
        };
        let ray = cam.generate_ray(&sample).unwrap().ray;
        let o = to_camera(ray.origin);
        let dir = to_camera_dir(ray.direction);
        // Distance from the focus point to the ray.
        let miss = (focus - o).cross(dir).length();
        prop_assert!(
            miss < 1e-4 * focus.length().max(1.0),
            "miss {} at {}",
            miss,
            focus
        );
        let z = depth_factor * focus.z;
        let on_ray = o + dir * ((z - o.z) / dir.z);
        let on_centre = c + d * ((z - c.z) / d.z);
        let predicted = (o - c).length() * (1.0 - z / focus.z).abs();
        let spread = (on_ray - on_centre).length();
        prop_assert!(
            (spread - predicted).abs() < 1e-3 * (1.0 + predicted),
            "spread {} predicted {}",
            spread,
            predicted
        );
    }
    Ok(())
}

fn to_camera_dir(v: obscura_space::Vector3<obscura_space::World>) -> Vec3 {
    Vec3::new(v.x, v.y, -v.z)
}

#[test]
fn untilted_lens_rays_are_unchanged_by_the_tilt_path() {
    // A zero tilt is the plain thin lens: the plane z = focal_distance, bit for bit.
    let plain = camera(
        [16, 16],
        ThinLens::new(0.1, 3.0).unwrap(),
        ShutterTiming::default(),
    );
    let zero = camera(
        [16, 16],
        ThinLens::new(0.1, 3.0)
            .unwrap()
            .with_tilt([0.0, 0.0])
            .unwrap(),
        ShutterTiming::default(),
    );
    let sample = CameraSample {
        p_lens: Vec2::new(0.2, 0.9),
        ..CameraSample::at(Point2::new(3.3, 12.1))
    };
    assert_eq!(plain.generate_ray(&sample), zero.generate_ray(&sample));
}
