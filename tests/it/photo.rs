//! Issue 21's photographic controls end to end: the rolling shutter skews a moving bar by the
//! predicted slope; exposure settings scale pixel values as photography says.

use crate::{miss_rms, render_image};
use obscura_render::{Image, parse_description};
use std::path::Path;

fn render_text(text: &str) -> Image {
    let d = parse_description(Path::new("photo.toml"), text).expect("scene parses");
    render_image(d, 2)
}

/// A vertical bar moving right by `speed` world units over the shutter [0, 1], seen by an
/// orthographic camera whose 32 x 32 film spans world x and y in [-1, 1] (16 pixels per unit).
fn moving_bar(camera_extra: &str) -> String {
    format!(
        r#"
[film]
resolution = [32, 32]
filter = "box"
[sampler]
type = "stratified"
spp = 16
[integrator]
type = "albedo"
[camera]
type = "orthographic"
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
screen_window = [-1.0, 1.0, -1.0, 1.0]
shutter = [0.0, 1.0]
{camera_extra}
[materials.white]
type = "diffuse"
reflectance = [1.0, 1.0, 1.0]
[[shapes]]
type = "quad"
origin = [-0.1, -2.0, 0.0]
edge_u = [0.2, 0.0, 0.0]
edge_v = [0.0, 4.0, 0.0]
material = "white"
transform_end = [{{ translate = [1.0, 0.0, 0.0] }}]
"#
    )
}

/// The bar's centre column (pixel units, from the left edge) in each row: the red channel's
/// centroid.
fn centroids(image: &Image) -> Vec<f64> {
    (0..image.height)
        .map(|y| {
            let (mut sum, mut weight) = (0.0f64, 0.0f64);
            for x in 0..image.width {
                let v = f64::from(image.pixel(x, y)[0]);
                sum += v * (f64::from(x) + 0.5);
                weight += v;
            }
            sum / weight
        })
        .collect()
}

/// Least-squares slope of `values` against their index.
fn slope(values: &[f64]) -> f64 {
    let n = values.len() as f64;
    let mean_x = (n - 1.0) / 2.0;
    let mean_y = values.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, v) in values.iter().enumerate() {
        let dx = i as f64 - mean_x;
        sxy += dx * (v - mean_y);
        sxx += dx * dx;
    }
    sxy / sxx
}

#[test]
fn rolling_shutter_slants_a_moving_bar_by_the_predicted_slope() {
    // Global shutter: every row sees the same blurred bar, so no slant.
    let global = centroids(&render_text(&moving_bar("")));
    assert!(
        slope(&global).abs() < 0.01,
        "global slope {}",
        slope(&global)
    );
    // readout = 1 (the whole interval): row k of 32 is exposed at the instant k / 32, when the
    // bar's centre is at world x = k / 32, i.e. column 16 + 16 k / 32: slope 0.5 px per row,
    // with the bar 0.2 * 16 = 3.2 pixels wide in every row, centred at 16 + k / 2.
    for (direction, expected) in [("top_to_bottom", 0.5), ("bottom_to_top", -0.5)] {
        let image = render_text(&moving_bar(&format!(
            "rolling_shutter = {{ readout = 1.0, direction = \"{direction}\" }}"
        )));
        let c = centroids(&image);
        let s = slope(&c);
        assert!((s - expected).abs() < 0.01, "{direction}: slope {s}");
        // The row read first is exposed at shutter open, the bar centred on column 16.
        let first = if expected > 0.0 { c[0] } else { c[31] };
        assert!((first - 16.0).abs() < 0.1, "{direction}: {first}");
    }
    // A partial readout: windows of length 1 - r; centre of row k's window at
    // r k / 32 + (1 - r) / 2, so the slope is 16 r / 32 = r / 2 px per row.
    let c = centroids(&render_text(&moving_bar(
        "rolling_shutter = { readout = 0.5 }",
    )));
    assert!(
        (slope(&c) - 0.25).abs() < 0.01,
        "readout 0.5: {}",
        slope(&c)
    );
}

/// A lit diffuse sphere (path integrator) with the given exposure keys.
fn lit(camera_extra: &str) -> Image {
    render_text(&format!(
        r#"
[film]
resolution = [12, 12]
[sampler]
spp = 4
[camera]
eye = [0.0, 0.0, 4.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
{camera_extra}
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
[[lights]]
type = "point"
position = [2.0, 3.0, 4.0]
intensity = [30.0, 30.0, 30.0]
"#
    ))
}

/// Asserts `b = factor * a` pixel by pixel (colour channels) and that the image is not black.
fn assert_scaled(a: &Image, b: &Image, factor: f32, what: &str) {
    let mut lit_pixels = 0;
    for (pa, pb) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            assert!(
                (pb[c] - factor * pa[c]).abs() <= 1e-5 * pb[c].abs().max(1e-6),
                "{what}: {} vs {} * {}",
                pb[c],
                factor,
                pa[c]
            );
        }
        assert_eq!(pa[3], pb[3], "{what}: coverage changed");
        lit_pixels += usize::from(pa[0] > 0.0);
    }
    assert!(lit_pixels > 10, "{what}: the reference is black");
}

#[test]
fn exposure_follows_time_iso_and_f_number() {
    let reference = lit("f_number = 2.0\nshutter_time = 0.5\niso = 100.0");
    let longer = lit("f_number = 2.0\nshutter_time = 1.0\niso = 100.0");
    assert_scaled(&reference, &longer, 2.0, "doubling the shutter time");
    let faster_film = lit("f_number = 2.0\nshutter_time = 0.5\niso = 200.0");
    assert_scaled(&reference, &faster_film, 2.0, "doubling the ISO");
    let stopped_down = lit(&format!(
        "f_number = {}\nshutter_time = 0.5\niso = 100.0",
        2.0 * std::f32::consts::SQRT_2
    ));
    assert_scaled(&reference, &stopped_down, 0.5, "one stop of f_number");
    let compensated =
        lit("f_number = 2.0\nshutter_time = 0.5\niso = 100.0\nexposure_compensation = -1.0");
    assert_scaled(&reference, &compensated, 0.5, "-1 EV");
    // t / N^2 * S / 100 = 0.5 / 4 * 1 = 1/8 of the unscaled radiance.
    let plain = lit("");
    assert_scaled(&plain, &reference, 0.125, "against no exposure keys");
}

#[test]
fn no_exposure_keys_leave_the_image_unchanged_and_unit_keys_scale_by_one() {
    let plain = lit("");
    let unit = lit("f_number = 1.0\nshutter_time = 1.0\niso = 100.0");
    assert_eq!(plain.pixels, unit.pixels);
}

#[test]
fn an_orthographic_thin_lens_reads_focal_plane_tilt() {
    // Camera at world z = 5 looking down -z, so camera z = 5 - world z; focused at 5, the plane
    // of focus tilted 60 degrees about camera x is z = 5 + y tan(60): world z = -y tan(60).
    let scene = |tilt: &str| {
        let text = format!(
            r#"
[film]
resolution = [32, 32]
[camera]
type = "orthographic"
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
screen_window = [-1.0, 1.0, -1.0, 1.0]
lens_radius = 0.2
focal_distance = 5.0
{tilt}
[[lights]]
type = "environment"
radiance = [1.0, 1.0, 1.0]
"#
        );
        let d = parse_description(Path::new("tilt.toml"), &text).expect("scene parses");
        assert!(d.ignored.is_empty(), "{:?}", d.ignored);
        obscura_render::RenderScene::build(d).expect("scene builds")
    };
    let tilted = scene("focal_plane_tilt = [60.0, 0.0]");
    let flat = scene("");
    let t = 60f32.to_radians().tan();
    for p in [[0.0, 0.5, -0.5 * t], [0.3, -0.6, 0.6 * t]] {
        let (on, off) = (miss_rms(&tilted.camera, p), miss_rms(&flat.camera, p));
        assert!(on < 1e-4, "{p:?}: tilted camera misses by {on}");
        assert!(off > 5e-3, "{p:?}: untilted camera misses by {off}");
    }
}
