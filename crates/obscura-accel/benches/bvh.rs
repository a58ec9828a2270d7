//! BVH build time and ray throughput on generated meshes of about 100k and 1M triangles (a
//! geodesic icosphere and a displaced grid), one thread.
//!
//! `cargo bench -p obscura-accel -- --quick`. Throughput is reported in rays (elements) per
//! second: coherent primary rays from a pinhole grid, incoherent rays between random points,
//! each as a closest-hit query and as a shadow (any-hit) query, one ray at a time and in
//! batches of 4096 (`Scene::intersect_preliminary_batch`, `occluded_batch`; their turns
//! between rays pay on the 1M-triangle meshes). `bench/compare.py` traces the
//! same kinds of rays through Embree for the ratios in docs/performance.md.

// criterion_group! generates an undocumented function.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use obscura_accel::{Placement, Scene, SceneBuilder, Shape};
use obscura_space::Transform;
use std::hint::black_box;
use std::sync::Arc;

// Generated meshes and ray sets, shared with the tests (not part of obscura-accel's API).
#[path = "../tests/it/testmesh.rs"]
mod testmesh;

/// Icospheres of 20 * 4^6 = 81,920 and 20 * 4^8 = 1,310,720 triangles, and displaced grids of
/// 2 * 224^2 = 100,352 and 2 * 724^2 = 1,048,352 triangles.
const MESHES: [(&str, u32); 4] = [
    ("icosphere", 6),
    ("icosphere", 8),
    ("grid", 224),
    ("grid", 724),
];

fn scene_of(mesh: &Arc<obscura_accel::TriangleMesh>) -> Scene {
    let mut builder = SceneBuilder::new();
    builder
        .add(
            Shape::Mesh(mesh.clone()),
            Placement::Static(Transform::IDENTITY),
        )
        .unwrap();
    builder.build().unwrap()
}

fn bench(c: &mut Criterion) {
    let primary = testmesh::primary_rays();
    let random = testmesh::random_rays();
    for (kind, n) in MESHES {
        let mesh = Arc::new(match kind {
            "icosphere" => testmesh::icosphere(n).unwrap(),
            _ => testmesh::displaced_grid(n).unwrap(),
        });
        let tris = mesh.triangle_count();

        let mut build = c.benchmark_group("build");
        build.sample_size(10);
        build.throughput(Throughput::Elements(tris as u64));
        build.bench_function(BenchmarkId::new(kind, tris), |b| {
            b.iter(|| black_box(scene_of(&mesh)))
        });
        build.finish();

        let scene = scene_of(&mesh);
        let mut trace = c.benchmark_group(format!("trace_{kind}_{tris}_tris"));
        trace.sample_size(10);
        for (name, rays) in [
            ("primary_coherent", &primary),
            ("random_incoherent", &random),
        ] {
            trace.throughput(Throughput::Elements(rays.len() as u64));
            trace.bench_function(format!("{name}_closest"), |b| {
                b.iter(|| rays.iter().filter(|r| scene.intersect(r).is_some()).count())
            });
            trace.bench_function(format!("{name}_closest_preliminary"), |b| {
                b.iter(|| {
                    rays.iter()
                        .filter(|r| scene.intersect_preliminary(r).is_some())
                        .count()
                })
            });
            trace.bench_function(format!("{name}_shadow_anyhit"), |b| {
                b.iter(|| rays.iter().filter(|r| scene.occluded(r)).count())
            });
            // The batch queries, over the same rays in batches of 4096.
            trace.bench_function(format!("{name}_closest_preliminary_batch"), |b| {
                b.iter(|| {
                    rays.chunks(4096)
                        .map(|rs| {
                            let hits = scene.intersect_preliminary_batch(rs);
                            hits.iter().filter(|h| h.is_some()).count()
                        })
                        .sum::<usize>()
                })
            });
            trace.bench_function(format!("{name}_shadow_anyhit_batch"), |b| {
                b.iter(|| {
                    rays.chunks(4096)
                        .map(|rs| scene.occluded_batch(rs).iter().filter(|&&o| o).count())
                        .sum::<usize>()
                })
            });
        }
        trace.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
