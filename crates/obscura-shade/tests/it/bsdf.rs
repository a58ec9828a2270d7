//! BSDF properties: energy conservation, reciprocity, sampled vs evaluated pdfs and values,
//! and a histogram check of the sampling routines against their pdfs.

use crate::{Rng, mean_and_error};
use core::f32::consts::{FRAC_1_PI, PI, TAU};
use glam::{Vec2, Vec3};
use obscura_shade::{Material, fresnel_dielectric};
use proptest::prelude::*;

fn rough(f0: f32, roughness: f32) -> Material {
    Material::RoughConductor {
        reflectance: Vec3::splat(f0),
        roughness,
    }
}

fn dir(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// Directional albedo of `m` for `wo`, estimated two independent ways: by the material's own
/// sampling (mean of f cos / pdf) and by uniform sphere sampling of `eval` (which does not
/// depend on `sample` at all). Returns (mean, standard error) of each.
fn albedos(m: &Material, wo: Vec3, n: usize, rng: &mut Rng) -> ((f64, f64), (f64, f64)) {
    let mut by_sampling = Vec::with_capacity(n);
    let mut by_uniform = Vec::with_capacity(n);
    for _ in 0..n {
        let u = rng.uniform();
        let u2 = Vec2::new(rng.uniform(), rng.uniform());
        let w = match m.sample(wo, u, u2) {
            Some(s) => (s.f.x * s.wi.z.abs() / s.pdf) as f64,
            None => 0.0,
        };
        by_sampling.push(w);
        let wi = rng.direction();
        by_uniform.push((m.eval(wo, wi).x * wi.z.abs() * 4.0 * PI) as f64);
    }
    (mean_and_error(&by_sampling), mean_and_error(&by_uniform))
}

#[test]
fn energy_is_conserved_for_every_non_delta_bsdf() {
    // Albedo <= 1 within 4 standard errors, for random viewing directions on both sides; and
    // the two independent estimators agree within 5 combined standard errors (which checks
    // that `sample` draws from the density that `pdf` reports and `eval` is what it weights).
    let mut rng = Rng::new(1);
    let materials = [
        Material::Diffuse {
            reflectance: Vec3::ONE,
        },
        rough(1.0, 0.2),
        rough(1.0, 0.5),
        rough(1.0, 1.0),
        rough(0.3, 0.7),
    ];
    for m in &materials {
        for k in 0..6 {
            let mut wo = rng.direction();
            if k == 5 {
                wo = dir(1.5, 0.3); // grazing
            }
            let ((a, ea), (b, eb)) = albedos(m, wo, 20_000, &mut rng);
            assert!(
                a <= 1.0 + 4.0 * ea,
                "{m:?} wo {wo}: albedo by sampling {a} +- {ea}"
            );
            assert!(
                b <= 1.0 + 4.0 * eb,
                "{m:?} wo {wo}: albedo by uniform {b} +- {eb}"
            );
            let combined = (ea * ea + eb * eb).sqrt();
            assert!(
                (a - b).abs() <= 5.0 * combined + 1e-3,
                "{m:?} wo {wo}: {a} vs {b} (+- {combined})"
            );
        }
    }
}

#[test]
fn lambert_albedo_is_its_reflectance_exactly() {
    // f cos / pdf = (rho / pi) cos / (cos / pi) = rho for every sample.
    let m = Material::Diffuse {
        reflectance: Vec3::new(0.2, 0.5, 0.9),
    };
    let mut rng = Rng::new(2);
    for _ in 0..1000 {
        let wo = rng.direction();
        let s = m
            .sample(wo, rng.uniform(), Vec2::new(rng.uniform(), rng.uniform()))
            .unwrap();
        let w = s.f * s.wi.z.abs() / s.pdf;
        assert!(
            (w - Vec3::new(0.2, 0.5, 0.9)).abs().max_element() < 1e-4,
            "{w}"
        );
        assert!(s.wi.z * wo.z > 0.0, "reflects on the viewer's side");
    }
}

#[test]
fn delta_bsdfs_conserve_energy() {
    let mut rng = Rng::new(3);
    let mirror = Material::Mirror {
        reflectance: Vec3::splat(0.9),
    };
    for _ in 0..500 {
        let wo = rng.direction();
        let s = mirror.sample(wo, rng.uniform(), Vec2::ZERO).unwrap();
        // Perfect reflection: same z, opposite tangent components.
        assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
        assert!(((s.f * s.wi.z.abs() / s.pdf).x - 0.9).abs() < 1e-5);
        assert_eq!(mirror.eval(wo, s.wi), Vec3::ZERO);
        assert_eq!(mirror.pdf(wo, s.wi), 0.0);
    }
    // Glass: the lobe probabilities R and T = 1 - R sum to one, and each sample's weight times
    // eta_t^2 / eta_i^2 (the radiance scaling undone) is 1: no energy is created or lost.
    for ior in [1.33f32, 1.5, 2.4, 0.8] {
        let glass = Material::Dielectric { ior };
        for _ in 0..500 {
            let wo = rng.direction();
            let fresnel = fresnel_dielectric(wo.z, ior);
            for u in [
                0.5 * fresnel,
                (fresnel + 0.5 * (1.0 - fresnel)).min(0.99999),
            ] {
                let Some(s) = glass.sample(wo, u, Vec2::ZERO) else {
                    panic!("glass must always scatter: ior {ior}, wo {wo}, u {u}");
                };
                let w = (s.f * s.wi.z.abs() / s.pdf).x;
                let reflected = s.wi.z * wo.z > 0.0;
                if reflected {
                    assert!((w - 1.0).abs() < 1e-4 && (s.pdf - fresnel).abs() < 1e-6);
                } else {
                    let eta = if wo.z > 0.0 { ior } else { 1.0 / ior };
                    assert!((w * eta * eta - 1.0).abs() < 1e-3, "ior {ior} wo {wo}: {w}");
                    assert!((s.pdf - (1.0 - fresnel)).abs() < 1e-6);
                    // Snell's law: eta_i sin_i = eta_t sin_t, i.e. sin_t = sin_i / eta.
                    let sin_i = (1.0 - wo.z * wo.z).max(0.0).sqrt();
                    let sin_t = (1.0 - s.wi.z * s.wi.z).max(0.0).sqrt();
                    assert!(
                        (sin_t - sin_i / eta).abs() < 1e-3,
                        "Snell: {sin_t} vs {}",
                        sin_i / eta
                    );
                }
            }
        }
    }
}

#[test]
fn total_internal_reflection_inside_glass() {
    // Inside glass of ior 1.5 the critical angle is asin(1 / 1.5) = 41.8 degrees; at 60 degrees
    // every sample reflects, whatever u.
    let glass = Material::Dielectric { ior: 1.5 };
    let wo = -dir(60f32.to_radians(), 0.4); // below the surface: inside
    for u in [0.0, 0.3, 0.999] {
        let s = glass.sample(wo, u, Vec2::ZERO).unwrap();
        assert!(s.wi.z < 0.0, "stays inside");
        assert!((s.pdf - 1.0).abs() < 1e-6);
    }
    // At 30 degrees inside (below critical) some light leaves: u close to 1 refracts out.
    let wo = -dir(30f32.to_radians(), 0.4);
    let s = glass.sample(wo, 0.999, Vec2::ZERO).unwrap();
    assert!(s.wi.z > 0.0);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn reciprocity(
        t1 in 0.0f32..1.57, p1 in 0.0f32..TAU, t2 in 0.0f32..1.57, p2 in 0.0f32..TAU,
        roughness in 0.05f32..1.0, below in any::<bool>(),
    ) {
        let (mut a, mut b) = (dir(t1, p1), dir(t2, p2));
        if below {
            a = -a;
            b = -b;
        }
        for m in [Material::Diffuse { reflectance: Vec3::new(0.3, 0.6, 0.9) }, rough(0.4, roughness)] {
            let (fab, fba) = (m.eval(a, b), m.eval(b, a));
            prop_assert!((fab - fba).abs().max_element() <= 1e-4 * fab.max_element().max(1.0),
                "{:?}: {} vs {}", m, fab, fba);
        }
    }

    #[test]
    fn sampled_pdf_and_value_match_evaluation(
        theta in 0.01f32..1.56, phi in 0.0f32..TAU, below in any::<bool>(),
        roughness in 0.05f32..1.0, u in 0.0f32..1.0, ux in 0.0f32..1.0, uy in 0.0f32..1.0,
    ) {
        let wo = if below { -dir(theta, phi) } else { dir(theta, phi) };
        for m in [Material::Diffuse { reflectance: Vec3::splat(0.7) }, rough(0.9, roughness)] {
            if let Some(s) = m.sample(wo, u, Vec2::new(ux, uy)) {
                prop_assert!(!s.specular);
                prop_assert!((s.wi.length() - 1.0).abs() < 1e-4);
                let pdf = m.pdf(wo, s.wi);
                prop_assert!((pdf - s.pdf).abs() <= 1e-3 * pdf.max(1e-3), "{:?}: {} vs {}", m, pdf, s.pdf);
                let f = m.eval(wo, s.wi);
                prop_assert!((f - s.f).abs().max_element() <= 1e-3 * f.max_element().max(1e-3));
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// The path tracer skips drawing `u` for a material that says it does not read it, so
    /// such a material must sample the same for every `u`; glass, which reads it, reflects
    /// for a small `u` and refracts for a large one at normal incidence (4% reflectance).
    #[test]
    fn only_a_material_that_reads_its_lobe_choice_depends_on_it(
        theta in 0.01f32..1.56, phi in 0.0f32..TAU, below in any::<bool>(),
        roughness in 0.0f32..1.0, u_a in 0.0f32..1.0, u_b in 0.0f32..1.0,
        ux in 0.0f32..1.0, uy in 0.0f32..1.0, ior in 1.1f32..2.0,
    ) {
        let wo = if below { -dir(theta, phi) } else { dir(theta, phi) };
        let u2 = Vec2::new(ux, uy);
        let materials = [
            Material::Diffuse { reflectance: Vec3::splat(0.7) },
            Material::Mirror { reflectance: Vec3::splat(0.9) },
            rough(0.9, roughness),
            Material::Dielectric { ior },
        ];
        for m in materials {
            if m.reads_lobe_choice() {
                let up = Vec3::Z;
                let reflect = m.sample(up, 0.001, u2).unwrap();
                let refract = m.sample(up, 0.999, u2).unwrap();
                prop_assert!(reflect.wi.z > 0.0 && refract.wi.z < 0.0, "{:?}", m);
            } else {
                let (a, b) = (m.sample(wo, u_a, u2), m.sample(wo, u_b, u2));
                prop_assert_eq!(a.map(|s| (s.wi, s.f, s.pdf)), b.map(|s| (s.wi, s.f, s.pdf)), "{:?}", m);
            }
        }
    }
}

/// Counts samples in (cos theta, phi) cells of the hemisphere of `wo` and compares with the
/// counts the pdf predicts (the pdf integrated over each cell with a 6 x 6 midpoint rule).
fn histogram_check(m: &Material, wo: Vec3, seed: u64) {
    const NZ: usize = 8;
    const NP: usize = 16;
    const N: usize = 200_000;
    let mut rng = Rng::new(seed);
    let mut observed = [[0usize; NP]; NZ];
    for _ in 0..N {
        let Some(s) = m.sample(wo, rng.uniform(), Vec2::new(rng.uniform(), rng.uniform())) else {
            continue;
        };
        let z = s.wi.z * wo.z.signum();
        if z <= 0.0 {
            continue;
        }
        let iz = ((z * NZ as f32) as usize).min(NZ - 1);
        let p = s.wi.y.atan2(s.wi.x).rem_euclid(TAU);
        let ip = ((p / TAU * NP as f32) as usize).min(NP - 1);
        observed[iz][ip] += 1;
    }
    for (iz, row) in observed.iter().enumerate() {
        for (ip, &count) in row.iter().enumerate() {
            // Cells are equal-area in (z, phi): solid angle = dz dphi.
            let mut integral = 0.0;
            for a in 0..6 {
                for b in 0..6 {
                    let z = (iz as f32 + (a as f32 + 0.5) / 6.0) / NZ as f32;
                    let p = (ip as f32 + (b as f32 + 0.5) / 6.0) / NP as f32 * TAU;
                    let r = (1.0 - z * z).sqrt();
                    let wi = Vec3::new(r * p.cos(), r * p.sin(), z * wo.z.signum());
                    integral += m.pdf(wo, wi) * (1.0 / NZ as f32) * (TAU / NP as f32) / 36.0;
                }
            }
            let expected = integral as f64 * N as f64;
            let obs = count as f64;
            // Poisson noise (5 sigma) plus 5% for the quadrature of a peaked pdf.
            let tolerance = 5.0 * expected.sqrt() + 0.05 * expected + 5.0;
            assert!(
                (obs - expected).abs() <= tolerance,
                "{m:?} cell ({iz}, {ip}): observed {obs}, expected {expected:.1}"
            );
        }
    }
}

#[test]
fn sampling_follows_the_reported_pdf() {
    histogram_check(
        &Material::Diffuse {
            reflectance: Vec3::ONE,
        },
        dir(0.7, 0.2),
        10,
    );
    histogram_check(&rough(1.0, 0.7), dir(0.5, 1.0), 11);
    histogram_check(&rough(1.0, 0.9), -dir(1.2, 2.0), 12);
}

#[test]
fn hand_computed_values() {
    // Lambert: f = rho / pi regardless of directions (same side), zero across.
    let m = Material::Diffuse {
        reflectance: Vec3::splat(0.5),
    };
    assert!((m.eval(Vec3::Z, dir(0.3, 1.0)).x - 0.5 * FRAC_1_PI).abs() < 1e-7);
    assert_eq!(m.eval(Vec3::Z, -Vec3::Z), Vec3::ZERO);
    // GGX at normal incidence and exitance (h = z): D = 1 / (pi a^2), Lambda = 0 so G = 1,
    // F = F0 (Schlick at cos 1), and f = D G F / (4 * 1 * 1) = F0 / (4 pi a^2).
    // roughness 0.5 -> a = 0.25: f = 0.8 / (4 pi 0.0625) = 1.01859.
    let g = rough(0.8, 0.5);
    let f = g.eval(Vec3::Z, Vec3::Z).x;
    assert!((f - 0.8 / (4.0 * PI * 0.0625)).abs() < 1e-4, "{f}");
    // Its pdf there: G1 = 1, wo.h = 1: D / 4 = 1 / (4 pi a^2) = 1.27324.
    assert!((g.pdf(Vec3::Z, Vec3::Z) - 1.0 / (4.0 * PI * 0.0625)).abs() < 1e-4);
}
