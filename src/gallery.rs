//! The illustrated guide's pictures, made from the scenes in `docs/gallery/` by one command:
//! `cargo run --release --example gallery -- [--quick] [OUT_DIR]` (default `docs/gallery`).
//!
//! Each figure is a scene file (embedded here, and written into `OUT_DIR` beside its picture)
//! rendered once or several times with parameters varied, the panels laid side by side into one
//! opaque PNG of the same name. [`generate`] does it all; [`FIGURES`] names what it makes.

use obscura_camera::{
    Aperture, CubeFace, FisheyeProjection, LensPrescription, OpenCvIntrinsics, Shutter,
    ShutterTiming,
};
use obscura_render::{
    DepthOfField, Image, ImageInfo, RenderError, RenderOptions, RenderScene, SceneDescription,
    compose_stereo, depth_of_field, motion_blur, parse_description, render, screen_buffers,
    write_image,
};
use std::path::{Path, PathBuf};

/// How big and how clean the pictures are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quality {
    /// The committed pictures: panels of about 240x180 at up to 256 samples per pixel.
    Full,
    /// Tiny panels and few samples, for tests: every picture is made, in seconds.
    Quick,
}

impl Quality {
    /// A panel's resolution for a scene written at `full` resolution.
    fn resolution(self, full: [u32; 2]) -> [u32; 2] {
        match self {
            Quality::Full => full,
            Quality::Quick => full.map(|v| (v / 8).max(4)),
        }
    }
    /// Samples per pixel for a scene asking for `full`.
    fn spp(self, full: u32) -> u32 {
        match self {
            Quality::Full => full,
            Quality::Quick => (full / 64).clamp(1, 4),
        }
    }
}

/// One figure: a scene file and the picture made from it.
#[derive(Debug, Clone, Copy)]
pub struct Figure {
    /// The file stem: the scene is `NAME.toml`, the picture `NAME.png`.
    pub name: &'static str,
    /// The scene file's text.
    scene: &'static str,
}

macro_rules! figure {
    ($name:literal) => {
        Figure {
            name: $name,
            scene: include_str!(concat!("../docs/gallery/", $name, ".toml")),
        }
    };
}

/// Every figure the gallery makes, in order.
pub const FIGURES: [Figure; 26] = [
    figure!("projection-perspective"),
    figure!("projection-orthographic"),
    figure!("dof-lens-radius"),
    figure!("dof-focal-distance"),
    figure!("undersampling"),
    figure!("motion-object"),
    figure!("motion-camera"),
    figure!("motion-shadow-reflection"),
    figure!("panorama"),
    figure!("postprocess-dof"),
    figure!("postprocess-motion"),
    figure!("fisheye-projections"),
    figure!("opencv-distortion"),
    figure!("opencv-fisheye"),
    figure!("panorama-octahedral"),
    figure!("panorama-cylindrical"),
    figure!("cube-map"),
    figure!("stereo-anaglyph"),
    figure!("ods"),
    figure!("lens-shift"),
    figure!("realistic-lenses"),
    figure!("aperture-bokeh"),
    figure!("realistic-apertures"),
    figure!("rolling-shutter"),
    figure!("tilt-shift"),
    figure!("realistic-tilt"),
];

/// The `realistic-lenses` row: each lens file (written into `lenses/` beside the scene), its
/// text, and the distance (metres) of the camera from the sphere's plane, 10 mm per millimetre
/// of focal length so that the sphere keeps its size on the film.
pub const LENS_PANELS: [(&str, &str, f32); 3] = [
    (
        "wide-angle-22mm.dat",
        include_str!("../scenes/lenses/wide-angle-22mm.dat"),
        0.22,
    ),
    (
        "double-gauss-50mm.dat",
        include_str!("../scenes/lenses/double-gauss-50mm.dat"),
        0.5,
    ),
    (
        "telephoto-250mm.dat",
        include_str!("../scenes/lenses/telephoto-250mm.dat"),
        2.5,
    ),
];

/// The aperture image the `aperture-bokeh` figure reads, written beside its scene.
pub const APERTURE_IMAGE: &str = "aperture-star.png";

/// The `tilt-shift` and `realistic-tilt` rows: the focal plane's tilt about camera x in each
/// panel (the camera looks down at 32.47 degrees, so 57.53 lays the plane in the ground).
pub const TILT_PANELS: [f32; 3] = [0.0, 57.53, -57.53];

/// The `fisheye-projections` row: each projection and its field of view in degrees (the
/// orthographic fisheye cannot reach 90 degrees off its axis).
pub const FISHEYE_PANELS: [(FisheyeProjection, f32); 4] = [
    (FisheyeProjection::Equidistant, 185.0),
    (FisheyeProjection::Equisolid, 185.0),
    (FisheyeProjection::Stereographic, 185.0),
    (FisheyeProjection::Orthographic, 178.0),
];

/// The lens radii of the `dof-lens-radius` row.
pub const LENS_RADII: [f32; 4] = [0.0, 0.1, 0.2, 0.4];
/// The focal distances of the `dof-focal-distance` row: the camera-space depths of the five
/// spheres' centres in that scene.
pub const FOCAL_DISTANCES: [f32; 5] = [3.07, 5.06, 7.05, 9.03, 11.02];
/// The samples per pixel of the `undersampling` row.
pub const UNDERSAMPLING_SPP: [u32; 5] = [1, 4, 16, 64, 256];

/// What a figure's panels were, for the caller to print.
#[derive(Debug, Clone)]
pub struct Made {
    /// The picture written.
    pub png: PathBuf,
    /// Its size in pixels.
    pub size: [u32; 2],
    /// For the comparison figures: the 4x3 grid cells (column, row, of the difference panel) with
    /// the largest mean difference, largest first, with that mean.
    pub hot_cells: Vec<(u32, u32, f32)>,
}

/// Makes every figure into `out_dir` (created if needed): `NAME.toml` and `NAME.png` for each of
/// [`FIGURES`]. `on_figure` is told of each picture as it is written.
pub fn generate(
    out_dir: &Path,
    quality: Quality,
    on_figure: impl FnMut(&Made),
) -> Result<Vec<Made>, RenderError> {
    generate_only(out_dir, quality, &[], on_figure)
}

/// [`generate`] for the figures named in `only` (all of them when it is empty).
pub fn generate_only(
    out_dir: &Path,
    quality: Quality,
    only: &[&str],
    mut on_figure: impl FnMut(&Made),
) -> Result<Vec<Made>, RenderError> {
    std::fs::create_dir_all(out_dir).map_err(|source| RenderError::Io {
        file: out_dir.to_path_buf(),
        action: "cannot create the folder",
        source,
    })?;
    write_aperture_star(&out_dir.join(APERTURE_IMAGE))?;
    let mut made = Vec::new();
    for figure in FIGURES {
        if !only.is_empty() && !only.contains(&figure.name) {
            continue;
        }
        let m = make_figure(out_dir, figure, quality)?;
        on_figure(&m);
        made.push(m);
    }
    Ok(made)
}

fn make_figure(out_dir: &Path, figure: Figure, quality: Quality) -> Result<Made, RenderError> {
    // Write the scene beside its picture (unless it is already there, unchanged).
    let scene_path = out_dir.join(format!("{}.toml", figure.name));
    if std::fs::read_to_string(&scene_path).ok().as_deref() != Some(figure.scene) {
        std::fs::write(&scene_path, figure.scene).map_err(|source| RenderError::Io {
            file: scene_path.clone(),
            action: "cannot write",
            source,
        })?;
    }
    // The realistic figures' lens files go beside them too, where their lens_file finds them.
    if figure.name.starts_with("realistic-") {
        let dir = out_dir.join("lenses");
        let io = |file: PathBuf| {
            move |source| RenderError::Io {
                file,
                action: "cannot write",
                source,
            }
        };
        std::fs::create_dir_all(&dir).map_err(io(dir.clone()))?;
        for (name, text, _) in LENS_PANELS {
            let path = dir.join(name);
            if std::fs::read_to_string(&path).ok().as_deref() != Some(text) {
                std::fs::write(&path, text).map_err(io(path.clone()))?;
            }
        }
    }
    let mut base = parse_description(&scene_path, figure.scene)?;
    let full = base.film.resolution;
    base.film.resolution = quality.resolution(full);
    base.sampler.spp = quality.spp(base.sampler.spp);
    // OpenCV intrinsics are in pixels: a smaller film scales them, about pixel edges (OpenCV's
    // pixel centres are integers, so the image's edge is at -0.5).
    if let Some(k) = &mut base.camera.intrinsics {
        let scale = f64::from(base.film.resolution[0]) / f64::from(full[0]);
        *k = OpenCvIntrinsics {
            fx: k.fx * scale,
            fy: k.fy * scale,
            cx: (k.cx + 0.5) * scale - 0.5,
            cy: (k.cy + 0.5) * scale - 0.5,
        };
    }

    let mut hot_cells = Vec::new();
    let panels: Vec<Image> = match figure.name {
        "dof-lens-radius" => LENS_RADII
            .iter()
            .map(|&r| {
                let mut d = base.clone();
                d.camera.lens.radius = r;
                shoot(d)
            })
            .collect::<Result<_, _>>()?,
        "dof-focal-distance" => FOCAL_DISTANCES
            .iter()
            .map(|&f| {
                let mut d = base.clone();
                d.camera.lens.focal_distance = f;
                shoot(d)
            })
            .collect::<Result<_, _>>()?,
        "undersampling" => UNDERSAMPLING_SPP
            .iter()
            .map(|&spp| {
                let mut d = base.clone();
                d.sampler.spp = match quality {
                    Quality::Full => spp,
                    Quality::Quick => spp.min(4),
                };
                shoot(d)
            })
            .collect::<Result<_, _>>()?,
        "fisheye-projections" => FISHEYE_PANELS
            .iter()
            .map(|&(projection, fov)| {
                let mut d = base.clone();
                d.camera.projection = projection;
                d.camera.fov = fov;
                shoot(d)
            })
            .collect::<Result<_, _>>()?,
        "opencv-distortion" => {
            let mut undistorted = base.clone();
            undistorted.camera.distortion = vec![0.0; 4];
            vec![shoot(base)?, shoot(undistorted)?]
        }
        "cube-map" => CubeFace::ALL
            .iter()
            .map(|&face| {
                let mut d = base.clone();
                d.camera.face = face;
                shoot(d)
            })
            .collect::<Result<_, _>>()?,
        "stereo-anaglyph" => {
            let layout = base.camera.stereo.map(|s| s.layout);
            match (base.stereo_eyes(), layout) {
                (Some([left, right]), Some(layout)) => {
                    let (left, right) = (shoot(left)?, shoot(right)?);
                    vec![compose_stereo(&left, &right, layout).unwrap_or(left)]
                }
                _ => vec![shoot(base)?],
            }
        }
        "lens-shift" => {
            // The tilted camera aims at the shifted window's centre, so both frame the pillar.
            let mut tilted = base.clone();
            let shift = tilted.camera.lens_shift[1];
            tilted.camera.lens_shift = [0.0, 0.0];
            let look = &mut tilted.camera.start;
            let depth = (look.target - look.eye).length();
            let half_height = (0.5 * tilted.camera.fov).to_radians().tan() * full[1] as f32
                / full[0].min(full[1]) as f32;
            look.target.y += depth * 2.0 * half_height * shift;
            vec![shoot(tilted)?, shoot(base)?]
        }
        "realistic-lenses" => LENS_PANELS
            .iter()
            .map(|&(name, text, distance)| {
                let mut d = base.clone();
                if let Some(r) = &mut d.camera.realistic {
                    r.prescription =
                        LensPrescription::parse(text).map_err(|e| RenderError::Scene {
                            file: out_dir.join("lenses").join(name),
                            line: None,
                            key: Some("camera.lens_file".into()),
                            message: e.to_string(),
                        })?;
                    r.lens_file = out_dir.join("lenses").join(name);
                    r.focus_distance = distance;
                }
                d.camera.start.eye.z = distance;
                shoot(d)
            })
            .collect::<Result<_, _>>()?,
        "aperture-bokeh" | "realistic-apertures" => {
            // The panels' apertures are constants, valid by construction. The lens system's
            // stop takes the aperture as the thin lens does.
            let with = |aperture: Aperture| {
                let mut d = base.clone();
                d.camera.lens.aperture = aperture;
                d
            };
            let hexagon = Aperture::polygon(6, 0.0).expect("six blades are valid");
            let oval = Aperture::CIRCLE
                .with_anamorphic(1.8)
                .expect("a squeeze of 1.8 is valid");
            vec![
                shoot(with(Aperture::CIRCLE))?,
                shoot(with(hexagon))?,
                shoot(base.clone())?,
                shoot(with(oval))?,
            ]
        }
        "rolling-shutter" => {
            let mut instant = base.clone();
            instant.camera.shutter = Shutter::new(0.0, 0.0).expect("an instant is a shutter");
            instant.camera.timing = ShutterTiming::default();
            let mut global = base.clone();
            global.camera.timing = ShutterTiming::default();
            vec![shoot(instant)?, shoot(global)?, shoot(base)?]
        }
        "tilt-shift" | "realistic-tilt" => TILT_PANELS
            .iter()
            .map(|&tilt| {
                let mut d = base.clone();
                match d.camera.realistic.as_mut() {
                    Some(r) => r.focal_plane_tilt = [tilt, 0.0],
                    None => d.camera.lens.focal_plane_tilt = [tilt, 0.0],
                }
                shoot(d)
            })
            .collect::<Result<_, _>>()?,
        "postprocess-dof" | "postprocess-motion" => {
            let (distributed, post) = compare(base, figure.name == "postprocess-dof")?;
            let diff = difference(&distributed, &post);
            hot_cells = hottest_cells(&distributed, &post);
            vec![distributed, post, diff]
        }
        _ => vec![shoot(base)?],
    };
    let row = side_by_side(&panels);
    let png = out_dir.join(format!("{}.png", figure.name));
    write_image(
        &png,
        &row,
        &ImageInfo {
            partial: false,
            samples_per_pixel: 0,
        },
    )?;
    Ok(Made {
        png,
        size: [row.width, row.height],
        hot_cells,
    })
}

/// Writes the `aperture-bokeh` figure's aperture: a white five-pointed star on black, 64 x 64,
/// its edges anti-aliased by 4 x 4 supersampling.
fn write_aperture_star(path: &Path) -> Result<(), RenderError> {
    const SIZE: u32 = 64;
    // A point is inside the star when it is inside the pentagon of its sector's two tips and
    // the notch between them: test against the star's ten edges as a polygon by winding.
    let vertices: Vec<[f32; 2]> = (0..10)
        .map(|k| {
            let radius = if k % 2 == 0 { 0.95 } else { 0.4 };
            let angle = std::f32::consts::FRAC_PI_2 + std::f32::consts::PI * k as f32 / 5.0;
            [radius * angle.cos(), radius * angle.sin()]
        })
        .collect();
    let inside = |x: f32, y: f32| {
        // Even-odd rule over the star's edges.
        let mut inside = false;
        for k in 0..vertices.len() {
            let [x0, y0] = vertices[k];
            let [x1, y1] = vertices[(k + 1) % vertices.len()];
            if (y0 > y) != (y1 > y) && x < x0 + (y - y0) * (x1 - x0) / (y1 - y0) {
                inside = !inside;
            }
        }
        inside
    };
    let mut pixels = Vec::with_capacity((SIZE * SIZE) as usize);
    for row in 0..SIZE {
        for col in 0..SIZE {
            let mut covered = 0.0;
            for sy in 0..4 {
                for sx in 0..4 {
                    // Image x right, image up = +y (row 0 at the top).
                    let x = -1.0 + 2.0 * (col as f32 + (sx as f32 + 0.5) / 4.0) / SIZE as f32;
                    let y = 1.0 - 2.0 * (row as f32 + (sy as f32 + 0.5) / 4.0) / SIZE as f32;
                    if inside(x, y) {
                        covered += 1.0 / 16.0;
                    }
                }
            }
            pixels.push([covered, covered, covered, 1.0]);
        }
    }
    let image = Image {
        width: SIZE,
        height: SIZE,
        pixels,
    };
    write_image(
        path,
        &image,
        &ImageInfo {
            partial: false,
            samples_per_pixel: 0,
        },
    )
}

/// Renders a description with every core and returns its image made opaque: the sky's
/// radiance is already in RGB, so only the coverage in alpha is dropped.
fn shoot(description: SceneDescription) -> Result<Image, RenderError> {
    let scene = RenderScene::build(description)?;
    Ok(opaque(render_scene(&scene)?))
}

fn render_scene(scene: &RenderScene) -> Result<Image, RenderError> {
    let outcome = render(scene, RenderOptions::default()).map_err(|e| RenderError::Setting {
        name: "threads",
        message: format!("cannot start the render's worker threads: {e}"),
    })?;
    Ok(outcome.film.resolve())
}

fn opaque(mut image: Image) -> Image {
    for p in &mut image.pixels {
        p[3] = 1.0;
    }
    image
}

/// The same scene rendered Cook-style (distributed over lens or shutter) and by post-processing
/// a pinhole image at shutter open with its depth or velocity buffer.
fn compare(base: SceneDescription, defocus: bool) -> Result<(Image, Image), RenderError> {
    let scene = RenderScene::build(base.clone())?;
    let distributed = opaque(render_scene(&scene)?);
    let buffers = screen_buffers(&scene);
    // The pinhole image: no lens, and an instant shutter at the scene's shutter open.
    let mut pinhole = base;
    pinhole.camera.lens.radius = 0.0;
    pinhole.camera.shutter.close = pinhole.camera.shutter.open;
    let sharp = render_scene(&RenderScene::build(pinhole)?)?;
    let post = if defocus {
        let params = DepthOfField::for_camera(&scene.camera)?;
        depth_of_field(&sharp, &buffers.depth, &params)?
    } else {
        motion_blur(&sharp, &buffers.velocity)?
    };
    Ok((distributed, opaque(post)))
}

/// `|a - b|` summed over RGB (display-clamped first), times 4, in false colour: black, red,
/// yellow, white as the difference grows.
pub fn difference(a: &Image, b: &Image) -> Image {
    let pixels = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| {
            let d: f32 = (0..3)
                .map(|k| (p[k].clamp(0.0, 1.0) - q[k].clamp(0.0, 1.0)).abs())
                .sum::<f32>()
                * 4.0
                / 3.0;
            [
                d.clamp(0.0, 1.0),
                (d - 1.0).clamp(0.0, 1.0),
                (d - 2.0).clamp(0.0, 1.0),
                1.0,
            ]
        })
        .collect();
    Image {
        width: a.width,
        height: a.height,
        pixels,
    }
}

/// The cells of a 4x3 grid over the image ordered by mean `|a - b|` (RGB mean), largest first.
fn hottest_cells(a: &Image, b: &Image) -> Vec<(u32, u32, f32)> {
    let (cols, rows) = (4u32, 3u32);
    let mut cells = Vec::new();
    for cy in 0..rows {
        for cx in 0..cols {
            let (x0, x1) = (cx * a.width / cols, (cx + 1) * a.width / cols);
            let (y0, y1) = (cy * a.height / rows, (cy + 1) * a.height / rows);
            let mut sum = 0.0;
            let mut n = 0.0;
            for y in y0..y1 {
                for x in x0..x1 {
                    let (p, q) = (a.pixel(x, y), b.pixel(x, y));
                    sum += (0..3).map(|k| (p[k] - q[k]).abs()).sum::<f32>() / 3.0;
                    n += 1.0;
                }
            }
            cells.push((cx, cy, if n > 0.0 { sum / n } else { 0.0 }));
        }
    }
    cells.sort_by(|p, q| q.2.total_cmp(&p.2));
    cells
}

/// Panels of equal height laid left to right with a 4-pixel white gap between them.
pub fn side_by_side(panels: &[Image]) -> Image {
    const GAP: u32 = 4;
    let height = panels.iter().map(|p| p.height).max().unwrap_or(1);
    let width =
        panels.iter().map(|p| p.width).sum::<u32>() + GAP * (panels.len() as u32).saturating_sub(1);
    let mut pixels = vec![[1.0; 4]; (width * height) as usize];
    let mut x0 = 0;
    for panel in panels {
        for y in 0..panel.height {
            for x in 0..panel.width {
                pixels[(y * width + x0 + x) as usize] = panel.pixel(x, y);
            }
        }
        x0 += panel.width + GAP;
    }
    Image {
        width: width.max(1),
        height,
        pixels,
    }
}
