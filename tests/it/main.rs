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
