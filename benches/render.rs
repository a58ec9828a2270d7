//! End-to-end render time of the shipped scenes: parse, build and render at each scene's own
//! resolution with 4 samples per pixel, on one and two threads.
//!
//! `cargo bench --bench render -- --quick`. Throughput is camera samples (pixels x spp) per
//! second; the side-by-side comparison with Mitsuba 3 is `bench/compare.py`.

// criterion_group! generates an undocumented function.
#![allow(missing_docs)]

use camera_obscura::render::{RenderOptions, RenderScene, load_description, render};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::path::Path;

const SCENES: [&str; 5] = [
    "spheres-perspective",
    "spheres-orthographic",
    "spheres-thin-lens",
    "spheres-motion-blur",
    "spheres-environment",
];
const SPP: u32 = 4;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    for name in SCENES {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(format!("{name}.toml"));
        let mut description = load_description(&path).expect("shipped scenes parse");
        description.sampler.spp = SPP;
        let [w, h] = description.film.resolution;
        group.throughput(Throughput::Elements(u64::from(w * h * SPP)));
        for threads in [1usize, 2] {
            group.bench_function(BenchmarkId::new(name, format!("{threads}t")), |b| {
                b.iter(|| {
                    let scene =
                        RenderScene::build(description.clone()).expect("shipped scenes build");
                    render(
                        &scene,
                        RenderOptions {
                            threads: Some(threads),
                            ..RenderOptions::default()
                        },
                    )
                    .expect("a thread pool")
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
