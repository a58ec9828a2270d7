//! pbrt-v4's environment images: Clarberg's equal-area octahedral mapping of the sphere onto
//! a square (z the pole, the upper hemisphere the inner diamond), resampled into the
//! equirectangular map Obscura's environment light reads.

use glam::DVec3;
use obscura_render::Image;

/// pbrt's `EqualAreaSphereToSquare`, with an exact arctangent where pbrt uses a polynomial
/// (they agree to about 1e-6): a unit direction to (u, v) in [0, 1]^2.
pub(crate) fn sphere_to_square(d: DVec3) -> [f64; 2] {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let (a, b) = (x.max(y), x.min(y));
    let b = if a == 0.0 { 0.0 } else { b / a };
    let mut phi = b.atan() * std::f64::consts::FRAC_2_PI;
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    let (u, v) = (u.copysign(d.x), v.copysign(d.y));
    [0.5 * (u + 1.0), 0.5 * (v + 1.0)]
}

/// pbrt's `EqualAreaSquareToSphere`: the inverse of [`sphere_to_square`].
#[cfg(test)]
pub(crate) fn square_to_sphere(p: [f64; 2]) -> DVec3 {
    let (u, v) = (2.0 * p[0] - 1.0, 2.0 * p[1] - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    let signed_distance = 1.0 - (up + vp);
    let r = 1.0 - signed_distance.abs();
    let phi = (if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 }) * std::f64::consts::FRAC_PI_4;
    let z = (1.0 - r * r).copysign(signed_distance);
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    DVec3::new(phi.cos().copysign(u) * s, phi.sin().copysign(v) * s, z)
}

/// The tallest equirectangular map made from an equal-area image.
const MAX_HEIGHT: u32 = 4096;

/// The equirectangular map (twice as wide as high, Obscura's mapping: row 0 looks along +y,
/// the centre column along +z) of a square equal-area image, bilinearly sampled as pbrt
/// does, row 0 of the image being v = 0.
pub(crate) fn equirect_from_equal_area(square: &Image) -> Image {
    let n = square.width;
    // Twice as wide as high, at most 8192 x 4096 texels (512 MiB of floats at most).
    let h = n.min(MAX_HEIGHT);
    let w = 2 * h;
    let texel = |x: i64, y: i64| {
        let clamp = |i: i64| i.clamp(0, i64::from(n) - 1) as u32;
        square.pixel(clamp(x), clamp(y))
    };
    let mut pixels = Vec::with_capacity((w * h) as usize);
    for j in 0..h {
        let theta = std::f64::consts::PI * (f64::from(j) + 0.5) / f64::from(h);
        for i in 0..w {
            let phi = std::f64::consts::TAU * ((f64::from(i) + 0.5) / f64::from(w) - 0.5);
            let d = DVec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                theta.sin() * phi.cos(),
            );
            let [u, v] = sphere_to_square(d);
            // pbrt's Bilerp: texel centres at (i + 0.5) / n.
            let (x, y) = (u * f64::from(n) - 0.5, v * f64::from(n) - 0.5);
            let (x0, y0) = (x.floor(), y.floor());
            let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
            let (x0, y0) = (x0 as i64, y0 as i64);
            let mut c = [0.0f32; 4];
            for (dx, dy, wgt) in [
                (0, 0, (1.0 - fx) * (1.0 - fy)),
                (1, 0, fx * (1.0 - fy)),
                (0, 1, (1.0 - fx) * fy),
                (1, 1, fx * fy),
            ] {
                let t = texel(x0 + dx, y0 + dy);
                for k in 0..3 {
                    c[k] += wgt * t[k];
                }
            }
            c[3] = 1.0;
            pixels.push(c);
        }
    }
    Image {
        width: w,
        height: h,
        pixels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn poles_and_axes_land_where_pbrt_puts_them() {
        // +z is the square's centre, -z its corners; +x the middle of the right edge of the
        // inner diamond.
        let close =
            |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12;
        assert!(close(sphere_to_square(DVec3::Z), [0.5, 0.5]));
        assert!(close(sphere_to_square(DVec3::X), [1.0, 0.5]));
        assert!(close(sphere_to_square(DVec3::Y), [0.5, 1.0]));
        let c = sphere_to_square(-DVec3::Z);
        assert!(
            close(c, [1.0, 1.0])
                || close(c, [0.0, 0.0])
                || close(c, [1.0, 0.0])
                || close(c, [0.0, 1.0])
        );
    }

    proptest! {
        #[test]
        fn square_to_sphere_inverts_sphere_to_square(u in 0.0f64..1.0, v in 0.0f64..1.0) {
            let d = square_to_sphere([u, v]);
            prop_assert!((d.length() - 1.0).abs() < 1e-9);
            let back = sphere_to_square(d);
            // Away from the seams, where both sides name one direction.
            prop_assert!((back[0] - u).abs() < 1e-7 && (back[1] - v).abs() < 1e-7, "{u} {v} -> {back:?}");
        }
    }
}
