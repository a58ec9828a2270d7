//! Workspace-wide tests: the shipped scenes rendered small and checked for properties that can
//! fail, the command line's contract (exit status, messages, atomic output), determinism.

mod cli;
mod deploy;
mod gallery;
mod import;
mod opencv;
mod photo;
mod py_fixture;
mod realistic;
mod robust;
mod scenes;
mod slices;
mod soak;
mod views;

use obscura_render::{
    Image, IntegratorKind, RenderOptions, RenderScene, SceneDescription, load_description, render,
};
use std::path::{Path, PathBuf};

/// The repository's root (where `scenes/` lives).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A shipped scene's description.
pub fn shipped(name: &str) -> SceneDescription {
    load_description(&root().join("scenes").join(name)).expect("shipped scenes load")
}

/// Renders a description with `threads` workers and returns the image.
pub fn render_image(description: SceneDescription, threads: usize) -> Image {
    let scene = RenderScene::build(description).expect("scene builds");
    let outcome = render(
        &scene,
        RenderOptions {
            threads: Some(threads),
            ..RenderOptions::default()
        },
    )
    .unwrap();
    assert!(outcome.is_complete(&scene));
    outcome.film.resolve()
}

/// A description changed for a quick AOV render.
pub fn aov(
    mut d: SceneDescription,
    kind: IntegratorKind,
    resolution: [u32; 2],
    spp: u32,
) -> SceneDescription {
    d.integrator.kind = kind;
    d.film.resolution = resolution;
    d.sampler.spp = spp;
    d
}

/// A scratch folder unique to this test process and name, emptied first.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("obscura-it-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The `obscura` binary built for these tests.
pub fn obscura() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_obscura"))
}

/// Writes `text` to `dir/name` and returns the path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The RMS distance by which the camera's rays from `p`'s image pass the world point `p`,
/// over a grid of lens samples.
pub fn miss_rms(camera: &obscura_camera::AnyCamera, p: [f32; 3]) -> f64 {
    use obscura_camera::{Camera, CameraSample};
    let p = obscura_space::Point3::<obscura_space::World>::new(p[0], p[1], p[2]);
    let film = camera.project(p, 0.0).expect("the point projects");
    let target = p.to_glam().as_dvec3();
    let (mut sum, mut count) = (0.0, 0);
    for i in 0..24 {
        for j in 0..24 {
            let sample = CameraSample {
                p_film: film,
                p_lens: glam::Vec2::new((i as f32 + 0.5) / 24.0, (j as f32 + 0.5) / 24.0),
                time: 0.0,
            };
            if let Some(r) = camera.generate_ray(&sample) {
                let o = r.ray.origin.to_glam().as_dvec3();
                let d = r.ray.direction.to_glam().as_dvec3().normalize();
                sum += (target - o).reject_from_normalized(d).length_squared();
                count += 1;
            }
        }
    }
    assert!(count > 100, "{count} rays");
    (sum / f64::from(count)).sqrt()
}
