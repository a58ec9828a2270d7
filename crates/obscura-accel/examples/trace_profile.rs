//! A deterministic traversal workload for instruction-count profiling (valgrind's callgrind):
//! builds a displaced grid of 2 * 300^2 = 180,000 triangles, then traces the same 65,536
//! coherent primary and 65,536 incoherent random rays as closest-hit (full record, then
//! preliminary: distance and ids only) and as shadow queries,
//! each in its own non-inlined function so `callgrind_annotate --inclusive=yes` gives per-query
//! instruction counts.
//!
//! ```text
//! cargo build --release -p obscura-accel --example trace_profile
//! valgrind --tool=callgrind --callgrind-out-file=cg.out target/release/examples/trace_profile
//! ```
//!
//! For one figure per query, split the profile at each of them with `--dump-after=` for
//! `trace_profile::setup_done`, `trace_profile::closest_*` and `trace_profile::shadow_*`: the
//! `totals:` line of each part is then that query's count (`--cache-sim=yes` adds cache misses).
//!
//! Pass `icosphere` as the first argument for a 20 * 4^7 = 327,680-triangle sphere instead
//! (`grid` for the default), and `fast`, `medium` (the default) or `slow` as the second for the
//! [`BuildQuality`].

use obscura_accel::{BuildQuality, Placement, Scene, SceneBuilder, Shape};
use obscura_space::{Ray, Transform, World};
use std::hint::black_box;
use std::sync::Arc;

// Generated meshes and ray sets, shared with the tests (not part of obscura-accel's API).
#[path = "../tests/it/testmesh.rs"]
mod testmesh;

#[inline(never)]
fn closest_primary(scene: &Scene, rays: &[Ray<World>]) -> f64 {
    closest(scene, rays) + 1.0
}

#[inline(never)]
fn closest_random(scene: &Scene, rays: &[Ray<World>]) -> f64 {
    closest(scene, rays) + 2.0
}

#[inline(never)]
fn preliminary_primary(scene: &Scene, rays: &[Ray<World>]) -> f64 {
    preliminary(scene, rays) + 1.0
}

#[inline(never)]
fn preliminary_random(scene: &Scene, rays: &[Ray<World>]) -> f64 {
    preliminary(scene, rays) + 2.0
}

#[inline(never)]
fn shadow_primary(scene: &Scene, rays: &[Ray<World>]) -> usize {
    rays.iter().filter(|r| scene.occluded(r)).count() + 1
}

#[inline(never)]
fn shadow_random(scene: &Scene, rays: &[Ray<World>]) -> usize {
    rays.iter().filter(|r| scene.occluded(r)).count() + 2
}

/// Marks the end of the set-up, for `--dump-after=trace_profile::setup_done`.
#[inline(never)]
fn setup_done(scene: &Scene) {
    black_box(scene.bounds());
}

/// (Each query function adds its own constant so the linker cannot fold them into one.)
/// Sums t and the primitive ids so the hits cannot be optimised away and runs can be compared.
fn preliminary(scene: &Scene, rays: &[Ray<World>]) -> f64 {
    rays.iter()
        .filter_map(|r| scene.intersect_preliminary(r))
        .map(|h| f64::from(h.t()) + f64::from(h.primitive()))
        .sum()
}

fn closest(scene: &Scene, rays: &[Ray<World>]) -> f64 {
    rays.iter()
        .filter_map(|r| scene.intersect(r))
        .map(|h| f64::from(h.t) + f64::from(h.primitive) + f64::from(h.n_shading.to_glam().x))
        .sum()
}

fn main() {
    let mesh = match std::env::args().nth(1).as_deref() {
        Some("icosphere") => testmesh::icosphere(7),
        _ => testmesh::displaced_grid(300),
    }
    .expect("generated meshes are valid");
    let quality = match std::env::args().nth(2).as_deref() {
        Some("fast") => BuildQuality::Fast,
        Some("slow") => BuildQuality::Slow,
        _ => BuildQuality::Medium,
    };
    let mut builder = SceneBuilder::new().with_quality(quality);
    builder
        .add(
            Shape::Mesh(Arc::new(mesh)),
            Placement::Static(Transform::IDENTITY),
        )
        .expect("a static identity placement is valid");
    let scene = builder.build().expect("one mesh builds");
    let (primary, random) = (testmesh::primary_rays(), testmesh::random_rays());
    setup_done(&scene);
    println!(
        "closest primary {:.3}",
        black_box(closest_primary(&scene, &primary))
    );
    println!(
        "closest random {:.3}",
        black_box(closest_random(&scene, &random))
    );
    println!(
        "preliminary primary {:.3}",
        black_box(preliminary_primary(&scene, &primary))
    );
    println!(
        "preliminary random {:.3}",
        black_box(preliminary_random(&scene, &random))
    );
    println!(
        "shadow primary {}",
        black_box(shadow_primary(&scene, &primary))
    );
    println!(
        "shadow random {}",
        black_box(shadow_random(&scene, &random))
    );
}
