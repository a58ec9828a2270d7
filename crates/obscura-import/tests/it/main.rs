//! The importers against the formats' documented defaults and against equivalent TOML scenes
//! rendered by the same renderer.

mod mitsuba;
mod pbrt;

use obscura_render::{
    Image, IntegratorKind, RenderOptions, RenderScene, SceneDescription, parse_description, render,
};
use std::path::{Path, PathBuf};

/// A scratch folder unique to this test process and name, emptied first.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("obscura-import-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `text` to `dir/name` and returns the path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Renders a description's AOV at 1 spp on one thread.
pub fn render_aov(mut d: SceneDescription, kind: IntegratorKind) -> Image {
    d.integrator.kind = kind;
    d.sampler.spp = 1;
    let scene = RenderScene::build(d).expect("scene builds");
    let outcome = render(
        &scene,
        RenderOptions {
            threads: Some(1),
            ..RenderOptions::default()
        },
    )
    .unwrap();
    outcome.film.resolve()
}

/// The TOML scene at `dir/name`.
pub fn toml_scene(dir: &Path, name: &str, text: &str) -> SceneDescription {
    let path = write(dir, name, text);
    parse_description(&path, text).expect("the reference TOML parses")
}

/// Asserts two images agree pixel by pixel within `tol` (relative to the value's size), and
/// returns how many pixels differ at all.
pub fn assert_images_close(a: &Image, b: &Image, tol: f32) -> usize {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let mut differ = 0;
    for y in 0..a.height {
        for x in 0..a.width {
            let (p, q) = (a.pixel(x, y), b.pixel(x, y));
            if p != q {
                differ += 1;
            }
            for c in 0..4 {
                let scale = p[c].abs().max(q[c].abs()).max(1.0);
                assert!(
                    (p[c] - q[c]).abs() <= tol * scale,
                    "pixel ({x}, {y}) channel {c}: {} vs {}",
                    p[c],
                    q[c]
                );
            }
        }
    }
    differ
}
