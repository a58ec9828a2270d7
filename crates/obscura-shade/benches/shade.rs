//! Hot paths of shading: BSDF sampling, environment-map sampling and one path per iteration.
// criterion_group! generates a public function without documentation.
#![allow(missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Mat4, Vec2, Vec3};
use obscura_accel::{Placement, SceneBuilder, Shape};
use obscura_sample::{Sampler, SamplerKind};
use obscura_shade::{EnvironmentLight, Light, Material, PathIntegrator, ShadingScene};
use obscura_space::{Point3, Ray, Transform, Vector3};
use std::hint::black_box;

fn bsdf(c: &mut Criterion) {
    let wo = Vec3::new(0.3, 0.2, 0.9).normalize();
    let rough = Material::RoughConductor {
        reflectance: Vec3::splat(0.9),
        roughness: 0.4,
    };
    let glass = Material::Dielectric { ior: 1.5 };
    let mut i = 0u32;
    c.bench_function("ggx_sample", |b| {
        b.iter(|| {
            i = i.wrapping_add(1);
            let u = (i % 997) as f32 / 997.0;
            black_box(rough.sample(black_box(wo), u, Vec2::new(u, 1.0 - u)))
        })
    });
    c.bench_function("dielectric_sample", |b| {
        b.iter(|| black_box(glass.sample(black_box(wo), 0.5, Vec2::ZERO)))
    });
}

fn environment(c: &mut Criterion) {
    let (w, h) = (256u32, 128u32);
    let texels: Vec<Vec3> = (0..w * h)
        .map(|i| Vec3::splat(1.0 + (i % 17) as f32))
        .collect();
    let env = EnvironmentLight::from_texels(w, h, texels, Mat4::IDENTITY).unwrap();
    let mut i = 0u32;
    c.bench_function("envmap_sample_li", |b| {
        b.iter(|| {
            i = i.wrapping_add(1);
            let u = (i % 1009) as f32 / 1009.0;
            black_box(env.sample_li(Vec2::new(u, (u * 7.0).fract())))
        })
    });
}

fn path(c: &mut Criterion) {
    let mut builder = SceneBuilder::new();
    let placement = Placement::Static(Transform::IDENTITY);
    let floor = Shape::Quad {
        origin: Vec3::new(-5.0, 0.0, -5.0),
        edge_u: Vec3::new(0.0, 0.0, 10.0),
        edge_v: Vec3::new(10.0, 0.0, 0.0),
    };
    let lamp = Shape::Sphere {
        center: Vec3::new(0.0, 3.0, 0.0),
        radius: 0.5,
    };
    builder.add(floor, placement.clone()).unwrap();
    builder
        .add(
            Shape::Sphere {
                center: Vec3::new(0.0, 1.0, 0.0),
                radius: 1.0,
            },
            placement.clone(),
        )
        .unwrap();
    let lamp_instance = builder.add(lamp.clone(), placement.clone()).unwrap();
    let geometry = builder.build().unwrap();
    let shading = ShadingScene::new(
        vec![
            Material::Diffuse {
                reflectance: Vec3::splat(0.7),
            },
            Material::RoughConductor {
                reflectance: Vec3::splat(0.9),
                roughness: 0.3,
            },
        ],
        vec![0, 1, 0],
        vec![Light::Environment(
            EnvironmentLight::constant(Vec3::splat(0.2)).unwrap(),
        )],
        vec![(lamp_instance, lamp, placement, Vec3::splat(10.0))],
    )
    .unwrap();
    let integrator = PathIntegrator::new(8);
    let sampler = Sampler::new(SamplerKind::Independent, 1 << 20, 0).unwrap();
    let ray = Ray::new(
        Point3::new(0.0, 2.0, 6.0),
        Vector3::new(0.0, -0.3, -1.0).normalize(),
        0.0,
    );
    let mut index = 0u32;
    c.bench_function("path_li", |b| {
        b.iter(|| {
            index = (index + 1) % (1 << 20);
            let mut dims = sampler.stream([0, 0], index);
            black_box(integrator.li(&geometry, &shading, &ray, &mut dims))
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default();
    targets = bsdf, environment, path
}
criterion_main!(benches);
