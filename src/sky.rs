//! A procedural sky, generated in code so the environment-map scene needs no downloaded file.
//!
//! `scenes/sky.exr` was made by `cargo run --release --example make_sky -- scenes/sky.exr`, which
//! calls [`procedural_sky`] with [`SKY_WIDTH`] x [`SKY_HEIGHT`]; a root test checks that the
//! shipped file still equals what this function makes.

use glam::Vec3;
use obscura_render::Image;

/// Width of the shipped sky map.
pub const SKY_WIDTH: u32 = 256;
/// Height of the shipped sky map.
pub const SKY_HEIGHT: u32 = 128;

/// The direction towards the sun, in the map's frame (y up): 35 degrees above the horizon,
/// 140 degrees from +z towards +x (ahead and to the right of a camera looking down -z).
pub fn sun_direction() -> Vec3 {
    let (elevation, azimuth) = (35f32.to_radians(), 140f32.to_radians());
    Vec3::new(
        elevation.cos() * azimuth.sin(),
        elevation.sin(),
        elevation.cos() * azimuth.cos(),
    )
}

/// An equirectangular sky of `width` x `height` texels, linear RGB, row 0 at the top, in the
/// environment camera's mapping (texel centre (x + 0.5, y + 0.5) looks along
/// `(sin theta sin phi, cos theta, sin theta cos phi)`, theta = pi y / h, phi = 2 pi (x / w - 0.5)):
/// a blue gradient from the horizon to the zenith, a dim brown ground, and a sun (angular radius
/// 4 degrees, radiance 60) with a soft glow.
pub fn procedural_sky(width: u32, height: u32) -> Image {
    let sun = sun_direction();
    let sun_cos = 4f32.to_radians().cos();
    let mut pixels = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let theta = std::f32::consts::PI * (y as f32 + 0.5) / height as f32;
            let phi = std::f32::consts::TAU * ((x as f32 + 0.5) / width as f32 - 0.5);
            let d = Vec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                theta.sin() * phi.cos(),
            );
            let c = if d.y >= 0.0 {
                // Horizon white-blue to zenith deep blue.
                let t = d.y.sqrt();
                Vec3::new(0.85, 0.9, 1.0).lerp(Vec3::new(0.15, 0.3, 0.8), t) * 1.2
            } else {
                Vec3::new(0.22, 0.18, 0.14) * (1.0 + d.y * 0.5)
            };
            let cos = d.dot(sun);
            let glow = Vec3::new(1.0, 0.8, 0.5) * (8.0 * (cos - 1.0)).exp() * 1.5;
            let disc = if cos >= sun_cos {
                Vec3::new(60.0, 56.0, 50.0)
            } else {
                Vec3::ZERO
            };
            let c = c + glow + disc;
            pixels.push([c.x, c.y, c.z, 1.0]);
        }
    }
    Image {
        width,
        height,
        pixels,
    }
}
