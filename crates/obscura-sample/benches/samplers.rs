//! Dimension values per second per sampler: one camera sample (5 dimensions) plus three
//! shading pairs, for every sample of a small tile, through the stream as a renderer would.

#![allow(
    missing_docs,
    reason = "criterion_group! generates an undocumented public function"
)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use obscura_sample::{Sampler, SamplerKind, square_to_concentric_disk};

/// Tile size, samples per pixel, and dimensions read per sample (5 camera + 3 pairs).
const TILE: u32 = 8;
const SPP: u32 = 16;
const DIMS_PER_SAMPLE: u64 = 5 + 6;

fn samplers(c: &mut Criterion) {
    let mut group = c.benchmark_group("dimension values");
    group.throughput(Throughput::Elements(
        u64::from(TILE * TILE * SPP) * DIMS_PER_SAMPLE,
    ));
    for kind in SamplerKind::ALL {
        let sampler = Sampler::new(kind, SPP, 1).expect("valid sampler");
        group.bench_function(kind.name(), |b| {
            b.iter(|| {
                let mut sum = 0.0f32;
                for y in 0..TILE {
                    for x in 0..TILE {
                        for index in 0..SPP {
                            let mut stream = sampler.stream(black_box([x, y]), index);
                            let (film, lens, time) = stream.camera();
                            sum += film.x + lens.y + time;
                            for _ in 0..3 {
                                sum += stream.next_2d().x;
                            }
                        }
                    }
                }
                black_box(sum)
            })
        });
    }
    group.finish();

    let mut warps = c.benchmark_group("warps");
    warps.throughput(Throughput::Elements(1024));
    warps.bench_function("concentric disk", |b| {
        b.iter(|| {
            let mut acc = glam::Vec2::ZERO;
            for k in 0..1024u32 {
                let u = glam::Vec2::new((k % 32) as f32 / 32.0, (k / 32) as f32 / 32.0);
                acc += square_to_concentric_disk(black_box(u));
            }
            black_box(acc)
        })
    });
    warps.finish();
}

criterion_group!(benches, samplers);
criterion_main!(benches);
