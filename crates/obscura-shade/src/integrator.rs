//! The `path` integrator: unidirectional path tracing with next-event estimation and
//! multiple importance sampling.

use crate::error::ShadeError;
use crate::frame::Frame;
use crate::light::{AreaLight, Light};
use crate::material::Material;
use glam::{Vec2, Vec3};
use obscura_accel::{Hit, Placement, Scene, Shape};
use obscura_sample::SampleStream;
use obscura_space::{Ray, Vector3, World};

/// The canonical numbers a path consumes, one shading decision after another. Implemented by
/// [`obscura_sample::SampleStream`]; tests may plug in their own generator.
pub trait SampleDims {
    /// The next number in `[0, 1)`.
    fn next_1d(&mut self) -> f32;
    /// The next pair in `[0, 1)^2`.
    fn next_2d(&mut self) -> Vec2;
    /// Moves past the next number, which nothing would read: the numbers after it must be
    /// the same as after [`SampleDims::next_1d`]. The default draws it and drops it.
    fn skip_1d(&mut self) {
        self.next_1d();
    }
    /// The next number if `read`; otherwise skips it and returns 0.5, for a choice that has
    /// one outcome (the dimensions after are the same either way).
    #[inline]
    fn next_1d_if(&mut self, read: bool) -> f32 {
        if read {
            self.next_1d()
        } else {
            self.skip_1d();
            0.5
        }
    }
}

impl SampleDims for SampleStream<'_> {
    #[inline]
    fn next_1d(&mut self) -> f32 {
        SampleStream::next_1d(self)
    }
    #[inline]
    fn next_2d(&mut self) -> Vec2 {
        SampleStream::next_2d(self)
    }
    #[inline]
    fn skip_1d(&mut self) {
        SampleStream::skip_1d(self)
    }
}

/// Everything the path tracer needs besides the geometry: materials per instance, and lights
/// (the given ones plus one [`AreaLight`] per emitter).
#[derive(Debug, Clone)]
pub struct ShadingScene {
    materials: Vec<Material>,
    instance_material: Vec<u32>,
    lights: Vec<Light>,
    /// For each instance, the index in `lights` of its area light, if it emits.
    instance_light: Vec<Option<u32>>,
    /// Indices in `lights` of the environment lights (seen by rays that escape).
    environment: Vec<u32>,
}

impl ShadingScene {
    /// Validates and assembles the shading side of a scene. `instance_material[i]` is the
    /// index in `materials` of instance `i`'s material (instances as numbered by the
    /// accelerator's `SceneBuilder::add`); `emitters` lists `(instance, shape, placement,
    /// emission)` for every emissive instance, each becoming an area light appended to `lights`.
    pub fn new(
        materials: Vec<Material>,
        instance_material: Vec<u32>,
        lights: Vec<Light>,
        emitters: Vec<(u32, Shape, Placement, Vec3)>,
    ) -> Result<ShadingScene, ShadeError> {
        for m in &materials {
            m.validate()?;
        }
        for (i, &m) in instance_material.iter().enumerate() {
            if m as usize >= materials.len() {
                return Err(ShadeError::BadIndex {
                    what: format!("instance_material[{i}]"),
                    index: m,
                    count: materials.len(),
                });
            }
        }
        let mut lights = lights;
        let mut instance_light = vec![None; instance_material.len()];
        for (instance, shape, placement, emission) in emitters {
            let Some(slot) = instance_light.get_mut(instance as usize) else {
                return Err(ShadeError::BadIndex {
                    what: "emitter instance".to_string(),
                    index: instance,
                    count: instance_material.len(),
                });
            };
            if slot.is_some() {
                return Err(ShadeError::BadIndex {
                    what: "emitter instance (listed twice)".to_string(),
                    index: instance,
                    count: instance_material.len(),
                });
            }
            if emission == Vec3::ZERO {
                continue;
            }
            let light = AreaLight::new(&shape, &placement, emission, instance)?;
            *slot = Some(lights.len() as u32);
            lights.push(Light::Area(light));
        }
        let environment = lights
            .iter()
            .enumerate()
            .filter(|(_, l)| matches!(l, Light::Environment(_)))
            .map(|(i, _)| i as u32)
            .collect();
        Ok(ShadingScene {
            materials,
            instance_material,
            lights,
            instance_light,
            environment,
        })
    }

    /// All lights, area lights last.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// The material of an instance (`None` for an unknown instance).
    pub fn material(&self, instance: u32) -> Option<&Material> {
        let m = *self.instance_material.get(instance as usize)?;
        self.materials.get(m as usize)
    }

    /// The area light of an instance, if it emits.
    pub fn area_light(&self, instance: u32) -> Option<&AreaLight> {
        let index = (*self.instance_light.get(instance as usize)?)?;
        match self.lights.get(index as usize) {
            Some(Light::Area(a)) => Some(a),
            _ => None,
        }
    }

    /// Radiance of the environment lights seen along world direction `d_world` (what a
    /// camera ray that misses everything sees).
    pub fn environment_radiance(&self, d_world: Vec3) -> Vec3 {
        self.environment
            .iter()
            .map(|&i| match &self.lights[i as usize] {
                Light::Environment(env) => env.radiance(d_world),
                _ => Vec3::ZERO,
            })
            .sum()
    }

    /// The probability with which next-event estimation picks any one light (uniform choice).
    pub fn light_select_pdf(&self) -> f32 {
        if self.lights.is_empty() {
            0.0
        } else {
            1.0 / self.lights.len() as f32
        }
    }
}

/// The power heuristic with exponent 2 for a sample drawn from density `pdf_a` with `pdf_b`
/// as the competing strategy: `pdf_a^2 / (pdf_a^2 + pdf_b^2)`. The weights of the two
/// strategies for the same sample sum to one.
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    if pdf_a.is_infinite() {
        return 1.0;
    }
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    let sum = a + b;
    if sum <= 0.0 || !sum.is_finite() {
        // Both zero (no strategy) or overflow: fall back to comparing the densities directly.
        return if pdf_a >= pdf_b && pdf_a > 0.0 {
            1.0
        } else {
            0.0
        };
    }
    a / sum
}

/// Unidirectional path tracing with next-event estimation and MIS (power heuristic).
///
/// `max_depth` is the largest number of scattering events on a path: 0 shows emitters and the
/// environment only, 1 direct lighting, and so on. Russian roulette starts after
/// [`PathIntegrator::RR_START_DEPTH`] bounces, with survival probability
/// [`rr_survival`]: the largest channel of the path throughput with the refractions'
/// `1 / eta^2` radiance scaling undone, clamped to `[0.05, 1]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PathIntegrator {
    /// The largest number of bounces.
    pub max_depth: u32,
}

/// Densities below this are treated as zero (the path ends instead of dividing by them).
const MIN_PDF: f32 = 1e-12;

impl PathIntegrator {
    /// The bounce count from which Russian roulette may end paths. Five, as Mitsuba 3's
    /// default: on the four comparison scenes of `bench/equal_error.py` it gave a lower error
    /// per unit of time than 3, 4 or 6 (docs/performance.md).
    pub const RR_START_DEPTH: u32 = 5;

    /// An integrator with the given maximum number of bounces.
    pub fn new(max_depth: u32) -> PathIntegrator {
        PathIntegrator { max_depth }
    }

    /// Radiance arriving along `ray` (world space, its own time), with further sample
    /// dimensions drawn from `dims`. Never NaN or infinite: a value that overflowed is
    /// replaced by zero (see [`PathIntegrator::li_and_hit`] for the raw value).
    pub fn li(
        &self,
        geometry: &Scene,
        shading: &ShadingScene,
        ray: &Ray<World>,
        dims: &mut impl SampleDims,
    ) -> Vec3 {
        let l = self.trace(geometry, shading, ray, dims).0;
        if l.is_finite() { l } else { Vec3::ZERO }
    }

    /// Radiance along `ray` as [`PathIntegrator::li`] computes it, and whether `ray` itself hit
    /// geometry (the film's coverage), at the cost of one path.
    ///
    /// Unlike `li`, the radiance is returned raw: it may be NaN or infinite when the scene's
    /// numbers overflow (e.g. an emission near `f32::MAX`). The renderer counts such samples
    /// and drops them, which it could not do if they were silently replaced by zero.
    pub fn li_and_hit(
        &self,
        geometry: &Scene,
        shading: &ShadingScene,
        ray: &Ray<World>,
        dims: &mut impl SampleDims,
    ) -> (Vec3, bool) {
        self.trace(geometry, shading, ray, dims)
    }

    fn trace(
        &self,
        geometry: &Scene,
        shading: &ShadingScene,
        camera_ray: &Ray<World>,
        dims: &mut impl SampleDims,
    ) -> (Vec3, bool) {
        let mut camera_ray_hit = false;
        let mut radiance = Vec3::ZERO;
        let mut beta = Vec3::ONE;
        let mut ray = *camera_ray;
        let Some(dir) = ray.direction.to_glam().try_normalize() else {
            return (Vec3::ZERO, false);
        };
        ray.direction = Vector3::from_glam(dir);
        // The previous scattering: was it a delta lobe, its pdf, and where it happened.
        let mut specular_bounce = true;
        let mut prev_pdf = 0.0f32;
        let mut prev_p = ray.origin.to_glam();
        let light_select = shading.light_select_pdf();

        let mut depth = 0u32;
        // The product of eta^2 over the refractions so far: beta * eta_scale is the path's
        // throughput without the 1 / eta^2 radiance scaling, which Russian roulette must not see.
        let mut eta_scale = 1.0f32;
        loop {
            let d_world = ray.direction.to_glam();
            // Find the next vertex; escaped rays see the environment.
            let Some(hit) = geometry.intersect(&ray) else {
                for &i in &shading.environment {
                    let Light::Environment(env) = &shading.lights[i as usize] else {
                        continue;
                    };
                    let (le, weight) = if specular_bounce {
                        (env.radiance(d_world), 1.0)
                    } else {
                        let (le, pdf) = env.radiance_and_pdf(d_world);
                        (le, power_heuristic(prev_pdf, light_select * pdf))
                    };
                    radiance += beta * le * weight;
                }
                break;
            };
            camera_ray_hit |= depth == 0;
            let wo_world = -d_world;
            let n_geometric = hit.n_geometric.to_glam();

            // Emission of the surface hit, weighted against light sampling's chance of it.
            if let Some(area) = shading.area_light(hit.instance) {
                let le = area.emitted(n_geometric, wo_world);
                if le != Vec3::ZERO {
                    let weight = if specular_bounce {
                        1.0
                    } else {
                        let pdf_light = light_select
                            * area.pdf_li(
                                prev_p,
                                hit.p.to_glam(),
                                n_geometric,
                                hit.primitive,
                                hit.time,
                            );
                        power_heuristic(prev_pdf, pdf_light)
                    };
                    radiance += beta * le * weight;
                }
            }
            if depth >= self.max_depth {
                break;
            }
            let Some(material) = shading.material(hit.instance) else {
                break;
            };

            // The shading frame: two-sided materials face the viewer; glass keeps its side.
            let frame = shading_frame(&hit, material, wo_world);
            let wo = frame.to_local(wo_world);
            if wo.z == 0.0 {
                break;
            }

            // Next-event estimation: one light, chosen uniformly.
            if !material.is_specular() && !shading.lights.is_empty() {
                // With one light there is nothing to choose: the number is skipped, not drawn.
                let u_light = dims.next_1d_if(shading.lights.len() > 1);
                let u2_light = dims.next_2d();
                radiance += beta
                    * self.sample_light(
                        geometry, shading, &hit, material, &frame, wo, u_light, u2_light,
                    );
            }

            // Continue the path by sampling the BSDF.
            // Only a material with a choice of lobes reads `u` (see Material::reads_lobe_choice).
            let u = dims.next_1d_if(material.reads_lobe_choice());
            let u2 = dims.next_2d();
            let Some(bs) = material.sample(wo, u, u2) else {
                break;
            };
            if bs.pdf < MIN_PDF || bs.f == Vec3::ZERO {
                break;
            }
            let throughput = bs.f * bs.wi.z.abs() / bs.pdf;
            if !throughput.is_finite() {
                break;
            }
            beta *= throughput;
            specular_bounce = bs.specular;
            prev_pdf = bs.pdf;
            prev_p = hit.p.to_glam();
            let Some(wi_world) = frame.from_local(bs.wi).try_normalize() else {
                break;
            };
            ray = spawn_ray(&hit, wi_world);
            depth += 1;

            eta_scale *= bs.eta * bs.eta;
            // Russian roulette once the path is a few bounces long.
            if depth >= Self::RR_START_DEPTH {
                let survive = rr_survival(beta, eta_scale);
                if dims.next_1d() >= survive {
                    break;
                }
                beta /= survive;
            }
        }
        (radiance, camera_ray_hit)
    }

    /// One light sample at `hit`, MIS-weighted against BSDF sampling, unoccluded or zero.
    fn sample_light(
        &self,
        geometry: &Scene,
        shading: &ShadingScene,
        hit: &Hit,
        material: &Material,
        frame: &Frame,
        wo: Vec3,
        u_light: f32,
        u2_light: Vec2,
    ) -> Vec3 {
        let count = shading.lights.len();
        let index = ((u_light * count as f32) as usize).min(count - 1);
        let light_select = 1.0 / count as f32;
        let p = hit.p.to_glam();
        let Some(ls) = shading.lights[index].sample_li(p, hit.time, u2_light) else {
            return Vec3::ZERO;
        };
        if ls.radiance == Vec3::ZERO || (!ls.delta && ls.pdf < MIN_PDF) {
            return Vec3::ZERO;
        }
        let wi = frame.to_local(ls.wi);
        let f = material.eval(wo, wi) * wi.z.abs();
        if f == Vec3::ZERO {
            return Vec3::ZERO;
        }
        // Shadow ray at the path's own time, so moving occluders cast moving shadows.
        let shadow = match ls.p_light {
            Some(p_light) => spawn_ray_to(hit, p_light),
            None => spawn_ray(hit, ls.wi),
        };
        if geometry.occluded(&shadow) {
            return Vec3::ZERO;
        }
        if ls.delta {
            f * ls.radiance / light_select
        } else {
            let pdf_light = light_select * ls.pdf;
            let weight = power_heuristic(pdf_light, material.pdf(wo, wi));
            f * ls.radiance * weight / pdf_light
        }
    }
}

/// Russian roulette's survival probability for a path of throughput `beta` whose refractions
/// multiplied its radiance by `1 / eta_scale`: the largest channel of `beta * eta_scale`,
/// clamped to `[0.05, 1]`. Without `eta_scale` a path inside glass (radiance scaled by
/// 1 / 1.5^2) would be ended 56% more often and its survivors weighted up, the variance of
/// every caustic and every view through glass; pbrt-v4 and Mitsuba 3 roulette on the same
/// product. The floor bounds the weight a survivor can gain at 20.
pub fn rr_survival(beta: Vec3, eta_scale: f32) -> f32 {
    let q = beta.max_element() * eta_scale;
    if q.is_nan() { 0.05 } else { q.clamp(0.05, 1.0) }
}

/// The local frame at a hit: the shading normal, flipped towards the viewer for two-sided
/// materials (together with the geometric normal, so they stay on the same side).
fn shading_frame(hit: &Hit, material: &Material, wo_world: Vec3) -> Frame {
    let n_geometric = hit.n_geometric.to_glam();
    let mut n_shading = hit.n_shading.to_glam();
    if !material.is_oriented() && n_geometric.dot(wo_world) < 0.0 {
        n_shading = -n_shading;
    }
    Frame::from_normal(n_shading.try_normalize().unwrap_or(Vec3::Z))
}

/// A ray leaving `hit` along `direction` at the hit's time (the path's own time).
fn spawn_ray(hit: &Hit, direction: Vec3) -> Ray<World> {
    let mut ray = hit.spawn_ray(Vector3::from_glam(direction));
    ray.time = hit.time;
    ray
}

/// A shadow ray from `hit` to just short of `target`, at the hit's time, so that moving
/// occluders are where they are at that instant.
fn spawn_ray_to(hit: &Hit, target: Vec3) -> Ray<World> {
    let mut ray = hit.spawn_ray_to(obscura_space::Point3::from_glam(target));
    ray.time = hit.time;
    ray
}
