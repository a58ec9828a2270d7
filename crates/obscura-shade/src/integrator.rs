//! The `path` integrator: unidirectional path tracing with next-event estimation and
//! multiple importance sampling.

use crate::error::ShadeError;
use crate::frame::Frame;
use crate::guide::{self, Aim, Casters};
use crate::lens::{Chain, Lenses};
use crate::light::{AreaLight, Light};
use crate::material::{BsdfSample, Material};
use glam::{Vec2, Vec3};
use obscura_accel::{Hit, Placement, SHADOW_EPSILON, Scene, Shape};
use obscura_sample::{ONE_MINUS_EPSILON, SampleStream, SearchStart};
use obscura_space::{Point3, Ray, Vector3, World};

/// The canonical numbers a path consumes, one shading decision after another. Implemented by
/// [`obscura_sample::SampleStream`]; tests may plug in their own generator.
pub trait SampleDims {
    /// The next number in `[0, 1)`.
    fn next_1d(&mut self) -> f32;
    /// The next pair in `[0, 1)^2`.
    fn next_2d(&mut self) -> Vec2;
    /// The number [`SampleDims::next_1d`] would return, without moving past it; `None` if the
    /// generator cannot look ahead (nothing then is prepared ahead of time).
    fn peek_1d(&mut self) -> Option<f32> {
        None
    }
    /// The pair [`SampleDims::next_2d`] would return after `skip` calls of
    /// [`SampleDims::skip_1d`], without moving past anything; `None` if the generator cannot
    /// look ahead.
    fn peek_2d(&mut self, skip: u32) -> Option<Vec2> {
        let _ = skip;
        None
    }
    /// Moves past the next number, which nothing would read: the numbers after it must be
    /// the same as after [`SampleDims::next_1d`]. The default draws it and drops it.
    fn skip_1d(&mut self) {
        self.next_1d();
    }
    /// Moves past the next pair (one the caller peeked): the numbers after it must be the
    /// same as after [`SampleDims::next_2d`]. The default draws it and drops it.
    fn skip_2d(&mut self) {
        self.next_2d();
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
    #[inline]
    fn skip_2d(&mut self) {
        SampleStream::skip_2d(self)
    }
    #[inline]
    fn peek_1d(&mut self) -> Option<f32> {
        Some(SampleStream::peek_1d(self))
    }
    #[inline]
    fn peek_2d(&mut self, skip: u32) -> Option<Vec2> {
        Some(SampleStream::peek_2d(self, skip))
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
    /// The smooth specular objects diffuse vertices aim a share of their samples at.
    casters: Casters,
    /// The glass balls diffuse vertices solve light paths through.
    lenses: Lenses,
    /// Whether any vertex solves through them: there are balls and a light they solve for.
    solves: bool,
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
            casters: Casters::default(),
            lenses: Lenses::default(),
            solves: false,
        })
    }

    /// Makes diffuse vertices aim up to half of their BSDF samples at the smooth specular objects
    /// among `instances` (`(instance, shape, placement)`, instances numbered as for
    /// [`ShadingScene::new`]): those whose material is all delta lobes (glass, mirrors), each
    /// by the cone its bounding sphere subtends (a moving one's sphere holds it over its whole
    /// motion), a mirror with half a glass ball's weight, as a glass ball that
    /// [`ShadingScene::solve_through_glass`] solves through for every light. Caustics, light
    /// focused by such an object onto a diffuse surface, are then found far more often; the
    /// estimate stays unbiased (the samples are weighted by the mixture's density). Instances
    /// with an unknown number are ignored. Without this call no sample is aimed.
    pub fn aim_at_specular<'a>(
        &mut self,
        instances: impl IntoIterator<Item = (u32, &'a Shape, &'a Placement)>,
    ) {
        let casters =
            Casters::new(instances.into_iter().filter_map(|(i, shape, placement)| {
                Some((i, self.material(i)?, shape, placement))
            }));
        self.casters = casters;
        self.mark_solved_casters();
    }

    /// Gives the casters that are glass balls solved through for every light (each light a
    /// static quad) half a share ([`crate::guide`]): near them the solve finds the light they
    /// focus. With any other light they keep their full share.
    fn mark_solved_casters(&mut self) {
        let every_light = self
            .lights
            .iter()
            .all(|l| matches!(l, Light::Area(a) if a.is_fixed_quad()));
        let solved = self.solves && every_light;
        let lenses = &self.lenses;
        self.casters
            .mark_solved(|instance| solved && lenses.index_of(instance).is_some());
    }

    /// Makes the vertices near a static ball of smooth glass among `instances` (`(instance,
    /// shape, placement)`, numbered as for [`ShadingScene::new`]) solve for the light that
    /// reaches them through it: a vertex that samples a point on a static quad light also
    /// finds every path that refracts into the ball and out of it to that point, and adds its
    /// light (manifold next-event estimation for the one chain of a sphere, weighed by MIS
    /// against the vertex's BSDF samples that find the same paths). The caustic a ball throws on
    /// the surfaces near it is found from every vertex there, not only by the rare BSDF
    /// sample that leaves the ball towards the light. Balls: spheres placed by a similarity,
    /// index above 1, at most four (the largest); vertices within two radii of a centre.
    /// Without this call nothing is solved for.
    pub fn solve_through_glass<'a>(
        &mut self,
        instances: impl IntoIterator<Item = (u32, &'a Shape, &'a Placement)>,
    ) {
        let lenses =
            Lenses::new(instances.into_iter().filter_map(|(i, shape, placement)| {
                Some((i, self.material(i)?, shape, placement))
            }));
        let quad_light = self
            .lights
            .iter()
            .any(|l| matches!(l, Light::Area(a) if a.is_fixed_quad()));
        self.solves = lenses.len() > 0 && quad_light;
        self.lenses = lenses;
        self.mark_solved_casters();
    }

    /// How many glass balls vertices solve light paths through
    /// ([`ShadingScene::solve_through_glass`]).
    pub fn lens_count(&self) -> usize {
        self.lenses.len()
    }

    /// How many objects diffuse vertices aim samples at ([`ShadingScene::aim_at_specular`]).
    pub fn caster_count(&self) -> usize {
        self.casters.len()
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

    /// Whether one of the lights is an environment map: a light sample or an escaped path
    /// then reads its large table at a random place.
    pub fn has_environment_map(&self) -> bool {
        self.environment
            .iter()
            .any(|&i| matches!(&self.lights[i as usize], Light::Environment(env) if env.is_map()))
    }

    /// Whether a vertex on `material` samples a light (next-event estimation): never on a
    /// specular material, whose BSDF no light sample can meet, nor without lights.
    fn samples_light_on(&self, material: &Material) -> bool {
        !material.is_specular() && !self.lights.is_empty()
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
/// `1 / eta^2` radiance scaling undone, clamped to `[0.05, 1]`. In a scene whose shading
/// side has casters ([`ShadingScene::aim_at_specular`]), a diffuse vertex where the camera ray
/// or the first bounce lands draws its BSDF sample from a mixture of the cosine lobe and the
/// cones of the glass and mirrors near it; roulette sees such a sample's throughput as the
/// BSDF's own density would have weighted it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PathIntegrator {
    /// The largest number of bounces.
    pub max_depth: u32,
}

/// Which values the path tracer gives for the same scene and random numbers: raised whenever
/// its estimator changes (1 before diffuse vertices aimed at casters, 2 once they did, 3 since
/// Russian roulette sees an aimed sample's throughput without the aim's weight, 4 since moving
/// glass and mirrors are aimed at too, 5 since vertices near glass balls solve for the light
/// through them, 6 since mirrors and solved glass balls take half a share of the aimed
/// samples, 7 since a BSDF sample through a ball is weighed against the solve only where the
/// solve finds its chain). Films made by
/// a build with another estimator are unbiased but not this build's image, so the renderer's
/// scene fingerprint includes this number, as it includes the samplers'
/// `obscura_sample::SEQUENCE_VERSION`.
pub const ESTIMATOR_VERSION: u32 = 7;

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

    /// [`li_and_hit`](PathIntegrator::li_and_hit) for many camera rays at once: `rays[i]`'s
    /// path draws its numbers from `dims[i]` and its value is the `i`-th returned, exactly
    /// (bit for bit) what `li_and_hit` gives for it. The paths advance together, one vertex
    /// each per round, so each round's rays go through the geometry as one batch
    /// ([`Scene::intersect_batch`], [`Scene::occluded_batch`]), which on a large mesh overlaps
    /// their cache misses. With an environment map, each round first asks the cache for the
    /// map's cells its vertices will read (the escaped paths' lookups, the light samples'
    /// first loads, from numbers peeked ahead), so that those misses overlap too. Each path's
    /// arithmetic is the one-path loop's, in the same order.
    ///
    /// A scene with neither a large mesh nor an environment map has nothing to overlap: its
    /// paths are traced one at a time, which costs fewer instructions.
    pub fn li_and_hit_batch<D: SampleDims>(
        &self,
        geometry: &Scene,
        shading: &ShadingScene,
        rays: &[Ray<World>],
        dims: &mut [D],
    ) -> Vec<(Vec3, bool)> {
        if !geometry.batches() && !shading.has_environment_map() {
            return rays
                .iter()
                .zip(dims)
                .map(|(ray, dims)| self.trace(geometry, shading, ray, dims))
                .collect();
        }
        let mut out = vec![(Vec3::ZERO, false); rays.len().min(dims.len())];
        // Sized for every ray (a filtered iterator would grow it by doubling).
        let mut live: Vec<(usize, PathState)> = Vec::with_capacity(out.len());
        live.extend(
            rays.iter()
                .take(dims.len())
                .enumerate()
                .filter_map(|(slot, ray)| Some((slot, PathState::new(ray)?))),
        );
        // Every per-round list holds at most one entry per path: sized once, so that no
        // round reallocates.
        let mut next_rays = Vec::with_capacity(live.len());
        let mut pending: Vec<(usize, Shadow)> = Vec::with_capacity(live.len());
        let mut shadow_rays = Vec::with_capacity(live.len());
        let mut going_on = Vec::with_capacity(live.len());
        let mut searches = Vec::with_capacity(live.len());
        let mut ahead = Vec::with_capacity(live.len());
        while !live.is_empty() {
            next_rays.clear();
            next_rays.extend(live.iter().map(|(_, path)| path.ray));
            let hits = geometry.intersect_batch(&next_rays);
            if shading.has_environment_map() {
                // Ask for the map's cells in two steps: the lines each vertex reads first, in
                // this sweep; then the cells a light sample's search compares, found from its
                // guide entry a few vertices ahead of it in the loop below.
                // What the sweep found on the way (an escaped path's map coordinates, a light
                // sample's peeked numbers) is kept for the vertex, which need not find it again.
                searches.clear();
                ahead.clear();
                for ((slot, path), hit) in live.iter().zip(&hits) {
                    ahead.push(match hit {
                        None => {
                            searches.push(None);
                            Ahead {
                                sky_uv: prefetch_escaped(shading, path),
                                light_numbers: None,
                            }
                        }
                        Some(hit) => {
                            let found =
                                self.prefetch_light_sample(shading, path, hit, &mut dims[*slot]);
                            searches.push(found.map(|(start, _)| start));
                            Ahead {
                                sky_uv: None,
                                light_numbers: found.map(|(_, numbers)| numbers),
                            }
                        }
                    });
                }
                for search in searches.iter().take(SEARCH_AHEAD).flatten() {
                    prefetch_searched(search);
                }
            }
            going_on.clear();
            for (k, ((slot, path), hit)) in live.iter_mut().zip(hits).enumerate() {
                if let Some(Some(search)) = searches.get(k + SEARCH_AHEAD) {
                    prefetch_searched(search);
                }
                let found = ahead.get(k).copied().unwrap_or_default();
                let (shadow, more) =
                    self.vertex(geometry, shading, path, hit, found, &mut dims[*slot]);
                if let Some(shadow) = shadow {
                    pending.push((k, shadow));
                }
                going_on.push(more);
            }
            shadow_rays.clear();
            shadow_rays.extend(pending.iter().map(|(_, shadow)| shadow.ray));
            let blocked = geometry.occluded_batch(&shadow_rays);
            for ((k, shadow), blocked) in pending.drain(..).zip(blocked) {
                live[k].1.add_light(shadow, blocked);
            }
            let mut k = 0;
            live.retain(|(slot, path)| {
                let more = going_on[k];
                k += 1;
                if !more {
                    out[*slot] = (path.radiance, path.camera_ray_hit);
                }
                more
            });
        }
        out
    }

    #[inline(always)]
    fn trace(
        &self,
        geometry: &Scene,
        shading: &ShadingScene,
        camera_ray: &Ray<World>,
        dims: &mut impl SampleDims,
    ) -> (Vec3, bool) {
        let Some(mut path) = PathState::new(camera_ray) else {
            return (Vec3::ZERO, false);
        };
        loop {
            let hit = geometry.intersect(&path.ray);
            let (shadow, more) =
                self.vertex(geometry, shading, &mut path, hit, Ahead::default(), dims);
            if let Some(shadow) = shadow {
                let blocked = geometry.occluded(&shadow.ray);
                path.add_light(shadow, blocked);
            }
            if !more {
                return (path.radiance, path.camera_ray_hit);
            }
        }
    }

    /// One vertex of `path`, where its ray met `hit` (or escaped): emission, the light
    /// sample, and the next ray by sampling the BSDF. The light sample's shadow ray is left
    /// to the caller ([`PathState::add_light`] once it is answered). False when the path ends.
    /// `ahead`: what a round's prefetch sweep found for this vertex, if it ran.
    #[inline(always)]
    fn vertex(
        &self,
        geometry: &Scene,
        shading: &ShadingScene,
        path: &mut PathState,
        hit: Option<Hit>,
        ahead: Ahead,
        dims: &mut impl SampleDims,
    ) -> (Option<Shadow>, bool) {
        let light_select = shading.light_select_pdf();
        let d_world = path.ray.direction.to_glam();
        // Escaped rays see the environment.
        let Some(hit) = hit else {
            for &i in &shading.environment {
                let Light::Environment(env) = &shading.lights[i as usize] else {
                    continue;
                };
                let (le, weight) = if path.specular_bounce {
                    (env.radiance_at(d_world, ahead.sky_uv), 1.0)
                } else {
                    let (le, pdf) = env.radiance_and_pdf_at(d_world, ahead.sky_uv);
                    (le, power_heuristic(path.prev_pdf, light_select * pdf))
                };
                path.radiance += path.beta * le * weight;
            }
            return (None, false);
        };
        path.camera_ray_hit |= path.depth == 0;
        let wo_world = -d_world;
        let n_geometric = hit.n_geometric.to_glam();

        // Emission of the surface hit, weighted against light sampling's chance of it.
        if let Some(area) = shading.area_light(hit.instance) {
            let le = area.emitted(n_geometric, wo_world);
            if le != Vec3::ZERO {
                let weight = if let Through::Left(k) = path.through {
                    // The end of a chain through a glass ball from a vertex that solved for
                    // such chains: weighed against the solve's chance of it.
                    path.via
                        .weight(shading, area, k, hit.p.to_glam(), n_geometric.dot(wo_world))
                } else if path.specular_bounce {
                    1.0
                } else {
                    let pdf_light = light_select
                        * area.pdf_li(
                            path.prev_p,
                            hit.p.to_glam(),
                            n_geometric,
                            hit.primitive,
                            hit.time,
                        );
                    power_heuristic(path.prev_pdf, pdf_light)
                };
                path.radiance += path.beta * le * weight;
            }
        }
        if path.depth >= self.max_depth {
            return (None, false);
        }
        let Some(material) = shading.material(hit.instance) else {
            return (None, false);
        };

        // The shading frame: two-sided materials face the viewer; glass keeps its side.
        let frame = shading_frame(&hit, material, wo_world);
        let wo = frame.to_local(wo_world);
        if wo.z == 0.0 {
            return (None, false);
        }

        // A diffuse vertex of a path's first bounces, in a scene with casters, aims part of
        // its samples at them.
        let n_side = if wo.z < 0.0 { -frame.n } else { frame.n };
        let aim = (path.depth < guide::AIMED_DEPTH && aims(shading, material))
            .then(|| shading.casters.at(hit.p.to_glam(), n_side));
        // The glass balls this vertex solves light paths through, if any: only where the
        // chain's two refractions and the light fit within the depth limit, as a BSDF sample's
        // would.
        let near = if shading.solves
            && path.depth + 3 <= self.max_depth
            && shading.samples_light_on(material)
        {
            shading.lenses.near(hit.p.to_glam(), n_side)
        } else {
            0
        };

        // Next-event estimation: one light, chosen uniformly.
        let mut shadow = None;
        if shading.samples_light_on(material) {
            // With one light there is nothing to choose: the number is skipped, not drawn.
            // Numbers the sweep peeked are moved past, not computed again (with one light its
            // choice is any number: every number picks light 0).
            let numbers = match ahead.light_numbers {
                Some(numbers) => {
                    dims.skip_1d();
                    dims.skip_2d();
                    numbers
                }
                None => LightNumbers {
                    choice: dims.next_1d_if(shading.lights.len() > 1),
                    pair: dims.next_2d(),
                    map_row: None,
                },
            };
            let seen = Seen {
                hit: &hit,
                material,
                frame: &frame,
                wo,
                aim: aim.as_ref(),
            };
            match self.sample_light(shading, seen, numbers) {
                Some((value, ray)) => {
                    shadow = Some(Shadow {
                        beta: path.beta,
                        value,
                        ray,
                    });
                }
                None => path.radiance += path.beta * Vec3::ZERO,
            }
            if near != 0 {
                path.radiance += path.beta * through_glass(geometry, shading, seen, near, numbers);
            }
        }

        // Continue the path by sampling the BSDF.
        // Only a material with a choice of lobes reads `u` (see Material::reads_lobe_choice).
        let u = dims.next_1d_if(material.reads_lobe_choice());
        let u2 = dims.next_2d();
        let sampled = match &aim {
            Some(aim) => sample_aimed(aim, material, &frame, wo, u2),
            None => material.sample(wo, u, u2).map(|bs| (bs, 1.0)),
        };
        let Some((bs, aim_scale)) = sampled else {
            return (shadow, false);
        };
        if bs.pdf < MIN_PDF || bs.f == Vec3::ZERO {
            return (shadow, false);
        }
        let throughput = bs.f * bs.wi.z.abs() / bs.pdf;
        if !throughput.is_finite() {
            return (shadow, false);
        }
        path.beta *= throughput;
        path.through = if near != 0 {
            path.via = Via {
                x: hit.p.to_glam(),
                wi: frame.from_local(bs.wi),
                pdf: bs.pdf,
            };
            Through::From(near)
        } else if shading.solves && material.is_specular() {
            path.through
                .after(shading.lenses.index_of(hit.instance), bs.eta)
        } else {
            Through::Nothing
        };
        path.specular_bounce = bs.specular;
        path.prev_pdf = bs.pdf;
        path.prev_p = hit.p.to_glam();
        let Some(wi_world) = frame.from_local(bs.wi).try_normalize() else {
            return (shadow, false);
        };
        path.ray = spawn_ray(&hit, wi_world);
        path.depth += 1;

        // Roulette sees the throughput without a refraction's 1 / eta^2 and without an aimed
        // vertex's weight `p_own / p_mix`: a sample aimed at glass carries a small weight because
        // it was drawn often, not because little light comes that way, and ending such paths
        // by their small weight would undo the aiming for every caustic met past the start.
        path.rr_scale *= bs.eta * bs.eta * aim_scale;
        // Russian roulette once the path is a few bounces long.
        if path.depth >= Self::RR_START_DEPTH {
            let survive = rr_survival(path.beta, path.rr_scale);
            if dims.next_1d() >= survive {
                return (shadow, false);
            }
            path.beta /= survive;
        }
        (shadow, true)
    }

    /// Asks the cache for the guide entry of the light sample the path's coming vertex at
    /// `hit` will search the environment map with (when the vertex will sample a light and
    /// the peeked numbers pick the map), and returns the search's start and the numbers it
    /// peeked (the light's choice is 0 with one light, which any number picks), with the map
    /// row they pick. Draws no number and changes no result.
    #[inline]
    fn prefetch_light_sample<'s>(
        &self,
        shading: &'s ShadingScene,
        path: &PathState,
        hit: &Hit,
        dims: &mut impl SampleDims,
    ) -> Option<(SearchStart<'s>, LightNumbers)> {
        // The vertex goes on to shading (and perhaps a light sample) only below the depth limit.
        let samples_light = path.depth < self.max_depth
            && shading
                .material(hit.instance)
                .is_some_and(|m| shading.samples_light_on(m));
        if !samples_light {
            return None;
        }
        // Its numbers: the light's choice (drawn only among several), then the pair.
        let count = shading.lights.len();
        let u_light = if count > 1 { dims.peek_1d()? } else { 0.0 };
        let Some(Light::Environment(env)) = shading.lights.get(light_index(u_light, count)) else {
            return None;
        };
        let u2 = dims.peek_2d(1)?;
        let start = env.sample_start(u2)?;
        obscura_accel::prefetch(start.guide_cell(), 0);
        let numbers = LightNumbers {
            choice: u_light,
            pair: u2,
            map_row: Some(start.row()),
        };
        Some((start, numbers))
    }

    /// One light sample at `hit`, MIS-weighted against BSDF sampling: its value if nothing
    /// blocks it, and the shadow ray that decides that; `None` for a sample worth nothing.
    #[inline(always)]
    fn sample_light(
        &self,
        shading: &ShadingScene,
        seen: Seen,
        numbers: LightNumbers,
    ) -> Option<(Vec3, Ray<World>)> {
        let hit = seen.hit;
        let count = shading.lights.len();
        let index = light_index(numbers.choice, count);
        let light_select = 1.0 / count as f32;
        let p = hit.p.to_glam();
        let ls = match &shading.lights[index] {
            Light::Environment(env) => env.sample_li_in_row(numbers.pair, numbers.map_row),
            light => light.sample_li(p, hit.time, numbers.pair),
        }?;
        if ls.radiance == Vec3::ZERO || (!ls.delta && ls.pdf < MIN_PDF) {
            return None;
        }
        let (f, wi) = seen.f_cos(ls.wi);
        if f == Vec3::ZERO {
            return None;
        }
        // Shadow ray at the path's own time, so moving occluders cast moving shadows.
        let shadow = match ls.p_light {
            Some(p_light) => spawn_ray_to(hit, p_light),
            None => spawn_ray(hit, ls.wi),
        };
        let value = if ls.delta {
            f * ls.radiance / light_select
        } else {
            let pdf_light = light_select * ls.pdf;
            let weight = power_heuristic(pdf_light, seen.pdf(ls.wi, wi));
            f * ls.radiance * weight / pdf_light
        };
        Some((value, shadow))
    }
}

/// Whether a vertex on `material` aims part of its samples at casters: a diffuse one, in a
/// scene with casters.
#[inline(always)]
fn aims(shading: &ShadingScene, material: &Material) -> bool {
    matches!(material, Material::Diffuse { .. }) && !shading.casters.is_empty()
}

/// A direction from the mixture of the BSDF's sampling and the casters' cones (the first
/// [`Aim::share`] of `u2.x`'s range aims at a caster, the rest samples the BSDF, each with
/// the number rescaled to `[0, 1)`), with the mixture's density as its `pdf`, and the factor
/// `p_mix / p_own` by which that density exceeds the BSDF's own (1 where the BSDF gives the
/// direction no density), which Russian roulette undoes.
#[inline]
fn sample_aimed(
    aim: &Aim,
    material: &Material,
    frame: &Frame,
    wo: Vec3,
    u2: Vec2,
) -> Option<(BsdfSample, f32)> {
    let share = aim.share();
    let rescale = |x: f32, lo: f32, width: f32| ((x - lo) / width).clamp(0.0, ONE_MINUS_EPSILON);
    let aimed = if u2.x < share {
        aim.sample(Vec2::new(rescale(u2.x, 0.0, share), u2.y))
    } else {
        None
    };
    let (bs, w, drawn) = match aimed {
        Some((w, k)) => {
            let wi = frame.to_local(w);
            let bs = BsdfSample {
                wi,
                f: material.eval(wo, wi),
                pdf: material.pdf(wo, wi),
                specular: false,
                eta: 1.0,
            };
            (bs, w, Some(k))
        }
        None => {
            let u = Vec2::new(rescale(u2.x, share, 1.0 - share), u2.y);
            let bs = material.sample(wo, 0.0, u)?;
            (bs, frame.from_local(bs.wi), None)
        }
    };
    let pdf = aim.mixture_pdf(w, bs.pdf, drawn);
    let scale = if bs.pdf > 0.0 { pdf / bs.pdf } else { 1.0 };
    Some((BsdfSample { pdf, ..bs }, scale))
}

/// What a round's prefetch sweep found for a path's coming vertex, which the vertex then
/// need not find again.
#[derive(Clone, Copy, Debug, Default)]
struct Ahead {
    /// An escaped ray's map coordinates ([`prefetch_escaped`]).
    sky_uv: Option<Vec2>,
    /// The light sample's numbers, peeked, and the map row they pick.
    light_numbers: Option<LightNumbers>,
}

/// A light sample's numbers, and what the prefetch sweep found with them.
#[derive(Clone, Copy, Debug)]
struct LightNumbers {
    /// The light's choice (with one light any number, as every number picks it).
    choice: f32,
    /// The pair the light samples with.
    pair: Vec2,
    /// The environment map's row the pair picks, when the sweep found it for the chosen
    /// light (`EnvironmentLight::sample_li_in_row`).
    map_row: Option<usize>,
}

/// How many vertices ahead of its own the batched loop asks for a light sample's searched
/// cells: late enough that the search's guide entry has come, early enough that the cells
/// come before the vertex.
const SEARCH_AHEAD: usize = 8;

/// Asks the cache for the cells a light sample's search compares: the first and either side.
#[inline]
fn prefetch_searched(search: &SearchStart<'_>) {
    for cell in search.searched_cells() {
        obscura_accel::prefetch(cell, 0);
    }
}

/// Asks the cache for the environment map's cell an escaped path's vertex will read, and
/// returns its map coordinates for that vertex (`EnvironmentLight::radiance_and_pdf_at`):
/// only for a scene with one environment light, the one whose coordinates they are.
#[inline]
fn prefetch_escaped(shading: &ShadingScene, path: &PathState) -> Option<Vec2> {
    let mut uv = None;
    for &i in &shading.environment {
        if let Light::Environment(env) = &shading.lights[i as usize] {
            uv = env.prefetch_lookup(path.ray.direction.to_glam());
        }
    }
    uv.filter(|_| shading.environment.len() == 1)
}

/// The light that number `u` in `[0, 1)` picks among `count` (at least one), uniformly.
#[inline(always)]
fn light_index(u: f32, count: usize) -> usize {
    ((u * count as f32) as usize).min(count - 1)
}

/// A path under way: its next ray, throughput and radiance so far, and what MIS needs of the
/// previous scattering.
#[derive(Clone, Copy, Debug)]
struct PathState {
    ray: Ray<World>,
    beta: Vec3,
    radiance: Vec3,
    /// Whether the previous scattering was a delta lobe, its pdf, and where it happened.
    specular_bounce: bool,
    prev_pdf: f32,
    prev_p: Vec3,
    depth: u32,
    /// The product of eta^2 over the refractions so far and of `p_mix / p_own` over the aimed
    /// vertices: beta * rr_scale is the path's throughput without the 1 / eta^2 radiance
    /// scaling and the aims' weights, which Russian roulette must not see.
    rr_scale: f32,
    camera_ray_hit: bool,
    /// Where the path stands on a chain through a glass ball from a vertex that solved
    /// through it, and that vertex.
    through: Through,
    via: Via,
}

impl PathState {
    /// A path starting along `camera_ray`; `None` for a direction that cannot be normalised.
    fn new(camera_ray: &Ray<World>) -> Option<PathState> {
        let mut ray = *camera_ray;
        let dir = ray.direction.to_glam().try_normalize()?;
        ray.direction = Vector3::from_glam(dir);
        Some(PathState {
            ray,
            beta: Vec3::ONE,
            radiance: Vec3::ZERO,
            specular_bounce: true,
            prev_pdf: 0.0,
            prev_p: ray.origin.to_glam(),
            depth: 0,
            rr_scale: 1.0,
            camera_ray_hit: false,
            through: Through::Nothing,
            via: Via::default(),
        })
    }

    /// Adds a light sample's share once its shadow ray is answered: the throughput it was
    /// taken at times its value, or times zero when blocked (the same sum the one-path loop
    /// has always made, NaN and infinity included).
    #[inline(always)]
    fn add_light(&mut self, shadow: Shadow, blocked: bool) {
        let value = if blocked { Vec3::ZERO } else { shadow.value };
        self.radiance += shadow.beta * value;
    }
}

/// A light sample waiting for its shadow ray's answer.
#[derive(Clone, Copy, Debug)]
struct Shadow {
    /// The path's throughput when the sample was taken.
    beta: Vec3,
    /// The sample's value if nothing blocks it.
    value: Vec3,
    ray: Ray<World>,
}

/// Russian roulette's survival probability for a path of throughput `beta` whose refractions
/// and aimed samples scaled it by `1 / scale`: the largest channel of `beta * scale`, clamped
/// to `[0.05, 1]`. Without the refractions' eta^2 a path inside glass (radiance scaled by
/// 1 / 1.5^2) would be ended 56% more often and its survivors weighted up, the variance of
/// every caustic and every view through glass; pbrt-v4 and Mitsuba 3 roulette on the same
/// product. An aimed sample's `p_mix / p_own` does the same for the aiming at casters. The
/// floor bounds the weight a survivor can gain at 20.
pub fn rr_survival(beta: Vec3, scale: f32) -> f32 {
    let q = beta.max_element() * scale;
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

/// Where a path stands on a chain `x -> ball -> ball -> light` from a vertex `x` that solved
/// for such chains ([`ShadingScene::solve_through_glass`]): the emission at the end of one
/// is weighed against the solve's chance of the same path ([`Via::weight`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Through {
    /// On no such chain.
    Nothing,
    /// Leaving a vertex that solved through the balls of this mask.
    From(u8),
    /// Refracted into ball `k` from such a vertex.
    Inside(u8),
    /// Refracted out of ball `k` again: the next surface, if it is the light, ends the chain.
    Left(u8),
}

impl Through {
    /// The state after a specular vertex on ball `ball` (if it is one) that scattered with
    /// the refraction ratio `eta` (above 1 entering glass, below 1 leaving, 1 reflecting).
    #[inline]
    fn after(self, ball: Option<usize>, eta: f32) -> Through {
        match (self, ball) {
            (Through::From(mask), Some(k)) if mask & (1 << k) != 0 && eta > 1.0 => {
                Through::Inside(k as u8)
            }
            (Through::Inside(j), Some(k)) if j as usize == k && eta < 1.0 => Through::Left(j),
            _ => Through::Nothing,
        }
    }
}

/// A vertex as its light samples see it: the hit, its material in its shading frame, the
/// direction to the viewer in that frame, and the mixture its BSDF sample is drawn from if it
/// aims at casters.
#[derive(Clone, Copy)]
struct Seen<'a> {
    hit: &'a Hit,
    material: &'a Material,
    frame: &'a Frame,
    wo: Vec3,
    aim: Option<&'a Aim>,
}

impl Seen<'_> {
    /// `f |cos|` for light arriving along the world direction `w`, and `w` in the local frame.
    #[inline(always)]
    fn f_cos(&self, w: Vec3) -> (Vec3, Vec3) {
        let wi = self.frame.to_local(w);
        (self.material.eval(self.wo, wi) * wi.z.abs(), wi)
    }

    /// The density with which the vertex's BSDF sample (aimed, if it aims) draws the world
    /// direction `w` (`wi` in the local frame): the weight's other side for a light sample.
    #[inline(always)]
    fn pdf(&self, w: Vec3, wi: Vec3) -> f32 {
        let pdf = self.material.pdf(self.wo, wi);
        match self.aim {
            Some(aim) => aim.mixture_pdf(w, pdf, None),
            None => pdf,
        }
    }
}

/// The vertex a path solved through glass balls from: where it was, the direction its BSDF
/// sample left along, and that sample's density.
#[derive(Clone, Copy, Debug, Default)]
struct Via {
    x: Vec3,
    wi: Vec3,
    pdf: f32,
}

impl Via {
    /// The MIS weight of a BSDF-sampled path that went from this vertex through ball `k` to
    /// the point `y` on `area`, arriving at cosine `cos_y` there: the power heuristic of the sample's
    /// density times the two refractions' chance, `p_bsdf T`, against the solve's density
    /// for the same direction, `p(y) / (d_omega / dA)`. 1 for a light the solve does not
    /// sample or a chain it would not find.
    fn weight(&self, shading: &ShadingScene, area: &AreaLight, k: u8, y: Vec3, cos_y: f32) -> f32 {
        let Some(pdf_area) = area.fixed_quad_pdf() else {
            return 1.0;
        };
        let Some((per_area, transmittance)) =
            shading.lenses.density_along(k as usize, self.x, self.wi, y)
        else {
            return 1.0;
        };
        let p_solve = pdf_area * shading.light_select_pdf() / (per_area * cos_y);
        power_heuristic(self.pdf * transmittance, p_solve)
    }
}

/// The light reaching the vertex at `hit` through the glass balls of `near` from the point
/// that the light sample's `numbers` pick on a static quad light: the sum over the chains
/// to it of `f cos T L_e (d_omega / dA) / p(y)`, each chain whose three segments are clear,
/// weighed by MIS against the vertex's BSDF sample (`aim`: the vertex's mixture, if it aims)
/// finding the same chain (zero when the numbers pick another kind of light, whose chains
/// the BSDF samples count).
#[inline(never)]
fn through_glass(
    geometry: &Scene,
    shading: &ShadingScene,
    seen: Seen,
    near: u8,
    numbers: LightNumbers,
) -> Vec3 {
    let hit = seen.hit;
    let count = shading.lights.len();
    let Light::Area(area) = &shading.lights[light_index(numbers.choice, count)] else {
        return Vec3::ZERO;
    };
    let Some((y, n_y, pdf_area)) = area.fixed_quad_point(numbers.pair) else {
        return Vec3::ZERO;
    };
    let p_y = pdf_area / count as f32;
    let x = hit.p.to_glam();
    let mut sum = Vec3::ZERO;
    for k in 0..shading.lenses.len() {
        if near & (1 << k) == 0 {
            continue;
        }
        shading.lenses.chains(k, x, y, |chain| {
            let cos_y = n_y.dot(-chain.exit);
            let le = area.emitted(n_y, -chain.exit);
            let (f, wi) = seen.f_cos(chain.wi);
            if cos_y <= 0.0 || le == Vec3::ZERO || f == Vec3::ZERO {
                return;
            }
            let per_area = chain.solid_angle_per_area * cos_y;
            let pdf_bsdf = seen.pdf(chain.wi, wi);
            let weight = power_heuristic(p_y / per_area, pdf_bsdf * chain.transmittance);
            if weight > 0.0 && !blocked(geometry, hit, chain, y) {
                sum += f * le * (chain.transmittance * per_area / p_y * weight);
            }
        });
    }
    sum
}

/// Whether something stops a chain: between the vertex and the ball, inside the ball, or
/// between the ball and the light. The segments end a ten-thousandth of the radius off the
/// sphere, on their own side of it, so that the ball itself does not stop them.
fn blocked(geometry: &Scene, hit: &Hit, chain: &Chain, y: Vec3) -> bool {
    let margin = chain.margin;
    let to_ball = spawn_ray_to(hit, chain.p1 + margin * chain.n1);
    if geometry.occluded(&to_ball) {
        return true;
    }
    let a = chain.p1 - margin * chain.n1;
    let b = chain.p2 - margin * chain.n2;
    let inside =
        Ray::new(Point3::from_glam(a), Vector3::from_glam(b - a), hit.time).with_range(0.0, 1.0);
    if geometry.occluded(&inside) {
        return true;
    }
    let out = chain.p2 + margin * chain.n2;
    let to_light = Ray::new(
        Point3::from_glam(out),
        Vector3::from_glam(y - out),
        hit.time,
    )
    .with_range(0.0, 1.0 - SHADOW_EPSILON);
    geometry.occluded(&to_light)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::guide::{HALF_FOCUS, SHARE};
    use obscura_space::Transform;

    /// A glass ball at the origin, a mirror ball 20 below it, a 1 x 1 quad light 10 above,
    /// and, with `point`, a point light too; the casters and the lenses made in either order.
    fn two_balls(point: bool, solve_first: bool) -> ShadingScene {
        let materials = vec![
            Material::Diffuse {
                reflectance: Vec3::splat(0.5),
            },
            Material::Dielectric { ior: 1.5 },
            Material::Mirror {
                reflectance: Vec3::ONE,
            },
        ];
        let fixed = Placement::Static(Transform::IDENTITY);
        let quad = Shape::Quad {
            origin: Vec3::new(-0.5, 10.0, -0.5),
            edge_u: Vec3::X,
            edge_v: Vec3::Z,
        };
        let lights = if point {
            vec![Light::Point {
                position: Vec3::new(3.0, 5.0, 0.0),
                intensity: Vec3::ONE,
            }]
        } else {
            vec![]
        };
        let emitters = vec![(2, quad, fixed.clone(), Vec3::ONE)];
        let mut scene = ShadingScene::new(materials, vec![1, 2, 0], lights, emitters).unwrap();
        let ball = |y| Shape::Sphere {
            center: Vec3::new(0.0, y, 0.0),
            radius: 1.0,
        };
        let (glass, mirror) = (ball(0.0), ball(-20.0));
        let instances = [(0, &glass, &fixed), (1, &mirror, &fixed)];
        if solve_first {
            scene.solve_through_glass(instances);
            scene.aim_at_specular(instances);
        } else {
            scene.aim_at_specular(instances);
            scene.solve_through_glass(instances);
        }
        scene
    }

    #[test]
    fn mirrors_and_glass_solved_for_every_light_take_half_a_share() {
        // 1.5 below the glass, facing it (the mirror below the horizon), and 1.5 above the
        // mirror, facing it (the glass below the horizon): each ball alone at full weight.
        let at_glass = |s: &ShadingScene| s.casters.at(Vec3::new(0.0, -1.5, 0.0), Vec3::Y).share();
        let at_mirror =
            |s: &ShadingScene| s.casters.at(Vec3::new(0.0, -18.5, 0.0), -Vec3::Y).share();
        for solve_first in [false, true] {
            let quad_only = two_balls(false, solve_first);
            assert_eq!(quad_only.lens_count(), 1);
            assert_eq!(at_glass(&quad_only), SHARE * HALF_FOCUS);
            assert_eq!(at_mirror(&quad_only), SHARE * HALF_FOCUS);
            // The point light's caustic through the glass is not solved for: full share.
            let with_point = two_balls(true, solve_first);
            assert_eq!(with_point.lens_count(), 1);
            assert_eq!(at_glass(&with_point), SHARE);
            assert_eq!(at_mirror(&with_point), SHARE * HALF_FOCUS);
        }
    }
}
