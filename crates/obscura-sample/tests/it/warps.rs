//! Warps: land in their domain, inverses undo them, pdfs integrate to one and match where
//! the samples fall.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3};
use obscura_sample::*;
use proptest::prelude::*;

use crate::assert_close;

/// A canonical point in `[0, 1)^2`.
fn unit_square() -> impl Strategy<Value = Vec2> {
    (0.0f32..1.0, 0.0f32..1.0).prop_map(|(x, y)| Vec2::new(x, y))
}

/// The vertices of the regular polygon, computed here independently of the crate.
fn polygon_vertices(blades: u32, rotation_degrees: f32) -> Vec<Vec2> {
    (0..blades)
        .map(|k| {
            let angle = rotation_degrees.to_radians() + TAU * k as f32 / blades as f32;
            Vec2::new(angle.cos(), angle.sin())
        })
        .collect()
}

/// Whether `p` is inside the convex counter-clockwise polygon (with a little slack).
fn inside_polygon(p: Vec2, vertices: &[Vec2], slack: f32) -> bool {
    (0..vertices.len()).all(|k| {
        let v0 = vertices[k];
        let v1 = vertices[(k + 1) % vertices.len()];
        (v1 - v0).perp_dot(p - v0) >= -slack
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn concentric_disk_lands_in_the_disk_and_inverts(u in unit_square()) {
        let p = square_to_concentric_disk(u);
        prop_assert!(p.length() <= 1.0 + 1e-6, "{p}");
        let back = concentric_disk_to_square(p);
        prop_assert!((back - u).abs().max_element() < 2e-4, "{u} -> {p} -> {back}");
    }

    #[test]
    fn concentric_disk_inverse_lands_in_the_square_and_is_undone(
        r in 0.0f32..1.0, phi in 0.0f32..TAU
    ) {
        let p = r * Vec2::new(phi.cos(), phi.sin());
        let u = concentric_disk_to_square(p);
        prop_assert!(u.cmpge(Vec2::ZERO).all() && u.cmplt(Vec2::ONE).all(), "{u}");
        let back = square_to_concentric_disk(u);
        prop_assert!((back - p).length() < 2e-4, "{p} -> {u} -> {back}");
    }

    #[test]
    fn polygon_lands_in_the_polygon_and_inverts(
        u in unit_square(), blades in 3u32..13, rotation in -720.0f32..720.0
    ) {
        let vertices = polygon_vertices(blades, rotation);
        let p = square_to_polygon(u, blades, rotation);
        prop_assert!(inside_polygon(p, &vertices, 1e-5), "{p} outside {blades}-gon");
        // The inverse gives a u' that maps to the same point...
        let back = polygon_to_square(p, blades, rotation);
        prop_assert!(back.cmpge(Vec2::ZERO).all() && back.cmplt(Vec2::ONE).all());
        prop_assert!((square_to_polygon(back, blades, rotation) - p).length() < 2e-4);
        // ... and is u itself away from the centre (where the edge parameter is undefined)
        // and from the seams between triangles.
        let radial = (u.x * blades as f32).fract();
        if radial > 0.01 && (0.01..0.99).contains(&u.y) {
            prop_assert!((back - u).abs().max_element() < 2e-3, "{u} -> {p} -> {back}");
        }
    }

    #[test]
    fn polygon_with_too_few_blades_is_the_disk(u in unit_square(), blades in 0u32..3) {
        prop_assert_eq!(square_to_polygon(u, blades, 30.0), square_to_concentric_disk(u));
    }

    #[test]
    fn cosine_hemisphere_is_unit_upper_and_inverts(u in unit_square()) {
        let w = square_to_cosine_hemisphere(u);
        prop_assert!((w.length() - 1.0).abs() < 1e-5 && w.z >= 0.0, "{w}");
        let back = cosine_hemisphere_to_square(w);
        prop_assert!((back - u).abs().max_element() < 2e-4, "{u} -> {w} -> {back}");
    }

    #[test]
    fn uniform_sphere_is_unit_and_inverts(u in unit_square()) {
        let w = square_to_uniform_sphere(u);
        prop_assert!((w.length() - 1.0).abs() < 1e-5, "{w}");
        let back = uniform_sphere_to_square(w);
        // Near the poles the azimuth is undefined; check it only away from them, and
        // modulo the seam at azimuth 0 = 1.
        prop_assert!((back.x - u.x).abs() < 2e-4);
        if (0.001..0.999).contains(&u.x) {
            let d = (back.y - u.y).abs();
            prop_assert!(d.min(1.0 - d) < 2e-3, "{u} -> {w} -> {back}");
        }
    }

    #[test]
    fn sin_cos_pi_matches_f64(x in -1.0e6f32..1.0e6) {
        // x is exact in f64 and pi x there is within 1e6 * 2^-52 ~ 2e-10 of the true angle,
        // so f64's sine and cosine are references to far better than f32 precision.
        let (sin, cos) = sin_cos_pi(x);
        let (sin_64, cos_64) = (std::f64::consts::PI * f64::from(x)).sin_cos();
        prop_assert!((f64::from(sin) - sin_64).abs() <= 7.5e-8 + 2e-10, "sin(pi {x}) = {sin}");
        prop_assert!((f64::from(cos) - cos_64).abs() <= 7.5e-8 + 2e-10, "cos(pi {x}) = {cos}");
        prop_assert!((sin * sin + cos * cos - 1.0).abs() <= 2e-7, "{sin}^2 + {cos}^2");
    }

    #[test]
    fn shutter_sample_lands_in_the_interval_and_inverts(u in 0.0f32..1.0, ramp in 0.0f32..=0.5) {
        let curve = ShutterCurve::trapezoid(ramp).unwrap();
        let t = curve.sample(u);
        prop_assert!((0.0..1.0).contains(&t), "{t}");
        prop_assert!((curve.invert(t) - u).abs() < 1e-4, "u {u} -> t {t} -> {}", curve.invert(t));
        prop_assert!(curve.pdf(t) >= 0.0 && curve.pdf(t) <= 1.0 / (1.0 - ramp) + 1e-5);
    }

    #[test]
    fn shutter_invert_is_undone_by_sample(t in 0.0f32..1.0, ramp in 0.0f32..=0.5) {
        let curve = ShutterCurve::trapezoid(ramp).unwrap();
        let u = curve.invert(t);
        prop_assert!((0.0..1.0).contains(&u));
        prop_assert!((curve.sample(u) - t).abs() < 1e-3, "t {t} -> u {u} -> {}", curve.sample(u));
    }
}

/// Integrates `f(theta, phi) sin(theta)` over `theta` in `[0, theta_max]` and `phi` in
/// `[0, 2 pi]` by the midpoint rule.
fn integrate_solid_angle(theta_max: f64, f: impl Fn(f64) -> f64) -> f64 {
    let n = 2000;
    let d_theta = theta_max / n as f64;
    (0..n)
        .map(|i| {
            let theta = (i as f64 + 0.5) * d_theta;
            f(theta) * theta.sin() * d_theta * std::f64::consts::TAU
        })
        .sum()
}

#[test]
fn cosine_hemisphere_pdf_integrates_to_one() {
    // The pdf depends on theta only, so the phi integral is a factor 2 pi.
    let total = integrate_solid_angle(std::f64::consts::PI, |theta| {
        f64::from(cosine_hemisphere_pdf(theta.cos() as f32))
    });
    assert!((total - 1.0).abs() < 1e-3, "{total}");
}

#[test]
fn uniform_sphere_pdf_integrates_to_one() {
    let total = integrate_solid_angle(std::f64::consts::PI, |_| f64::from(uniform_sphere_pdf()));
    assert!((total - 1.0).abs() < 1e-3, "{total}");
}

/// Integrates an area pdf that is constant inside `inside` over `[-1, 1]^2` on a grid.
fn integrate_area(pdf: f32, inside: impl Fn(Vec2) -> bool) -> f64 {
    let n = 1000;
    let cell = 2.0 / n as f64;
    let mut total = 0.0;
    for i in 0..n {
        for j in 0..n {
            let p = Vec2::new(
                -1.0 + (i as f32 + 0.5) * cell as f32,
                -1.0 + (j as f32 + 0.5) * cell as f32,
            );
            if inside(p) {
                total += f64::from(pdf) * cell * cell;
            }
        }
    }
    total
}

#[test]
fn disk_and_polygon_pdfs_integrate_to_one() {
    let disk = integrate_area(concentric_disk_pdf(), |p| p.length() <= 1.0);
    assert!((disk - 1.0).abs() < 2e-3, "disk {disk}");
    for (blades, rotation) in [(3, 0.0), (5, 17.0), (6, 90.0), (9, -40.0)] {
        let vertices = polygon_vertices(blades, rotation);
        let total = integrate_area(polygon_pdf(blades), |p| inside_polygon(p, &vertices, 0.0));
        assert!((total - 1.0).abs() < 3e-3, "{blades} blades: {total}");
    }
}

#[test]
fn shutter_pdfs_integrate_to_one() {
    for curve in [
        ShutterCurve::Box,
        ShutterCurve::Trapezoid { ramp: 0.1 },
        ShutterCurve::Trapezoid { ramp: 0.5 },
    ] {
        let n = 100_000;
        let total: f64 = (0..n)
            .map(|i| f64::from(curve.pdf((i as f32 + 0.5) / n as f32)) / n as f64)
            .sum();
        assert!((total - 1.0).abs() < 1e-4, "{curve:?}: {total}");
    }
}

/// The canonical points of a fine grid over the square.
fn grid_points(n: u32) -> impl Iterator<Item = Vec2> {
    (0..n * n).map(move |k| {
        Vec2::new(
            ((k % n) as f32 + 0.5) / n as f32,
            ((k / n) as f32 + 0.5) / n as f32,
        )
    })
}

#[test]
fn warps_put_samples_where_their_pdfs_say() {
    let n = 256;
    let count = (n * n) as f32;
    // Disk: area of radius 1/2 over area of radius 1 = 1/4.
    let inner = grid_points(n)
        .filter(|&u| square_to_concentric_disk(u).length() < 0.5)
        .count();
    assert_close!(inner as f32 / count, 0.25, 0.01, "disk inner fraction");
    // Hexagon (inradius cos 30 deg > 1/2, so the disk of radius 1/2 is inside it):
    // (pi / 4) / (3 sqrt(3) / 2) = 0.30230.
    let inner = grid_points(n)
        .filter(|&u| square_to_polygon(u, 6, 0.0).length() < 0.5)
        .count();
    assert_close!(
        inner as f32 / count,
        0.30230,
        0.01,
        "hexagon inner fraction"
    );
    // Cosine hemisphere: P(cos theta > 1/2) = sin^2(60 deg) = 3/4.
    let above = grid_points(n)
        .filter(|&u| square_to_cosine_hemisphere(u).z > 0.5)
        .count();
    assert_close!(above as f32 / count, 0.75, 0.01, "cosine hemisphere cap");
    // Uniform sphere: a cap z > 1/2 holds (1 - 1/2) / 2 = 1/4; the octant x, y, z > 0 holds 1/8.
    let cap = grid_points(n)
        .filter(|&u| square_to_uniform_sphere(u).z > 0.5)
        .count();
    assert_close!(cap as f32 / count, 0.25, 0.01, "sphere cap");
    let octant = grid_points(n)
        .filter(|&u| square_to_uniform_sphere(u).cmpgt(Vec3::ZERO).all())
        .count();
    assert_close!(octant as f32 / count, 0.125, 0.01, "sphere octant");
    // Trapezoid with ramp 0.2: the opening ramp holds (0.2 / 2) / 0.8 = 1/8 of the time.
    let curve = ShutterCurve::trapezoid(0.2).unwrap();
    let early = (0..10_000)
        .filter(|&i| curve.sample((i as f32 + 0.5) / 10_000.0) < 0.2)
        .count();
    assert_close!(
        early as f32 / 10_000.0,
        0.125,
        0.002,
        "trapezoid opening share"
    );
}

#[test]
fn warps_of_the_square_corners_stay_finite() {
    let just_below = ONE_MINUS_EPSILON;
    for u in [
        Vec2::ZERO,
        Vec2::splat(just_below),
        Vec2::new(0.0, just_below),
        Vec2::new(just_below, 0.0),
    ] {
        assert!(square_to_concentric_disk(u).is_finite());
        assert!(square_to_polygon(u, 5, 10.0).is_finite());
        assert!(square_to_cosine_hemisphere(u).is_finite());
        assert!(square_to_uniform_sphere(u).is_finite());
    }
    // The pole of the sphere: u.x = 0 -> z = 1.
    assert_close!(square_to_uniform_sphere(Vec2::ZERO).z, 1.0, 1e-6, "pole");
    assert_close!(uniform_sphere_pdf() * 4.0 * PI, 1.0, 1e-6, "sphere pdf");
}
