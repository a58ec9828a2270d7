//! Materials, lights and the path-tracing integrator of Obscura: everything that turns a ray's
//! first hit into radiance.
//!
//! What is here:
//! - [`Material`]: Lambertian [`Material::Diffuse`], perfect [`Material::Mirror`], smooth glass
//!   [`Material::Dielectric`] (Fresnel, refraction, total internal reflection) and, as an
//!   extension, [`Material::RoughConductor`] (GGX with visible-normal sampling). Each evaluates
//!   `f`, its sampling `pdf`, and samples a direction ([`BsdfSample`]).
//! - [`Light`]: point, distant, [`AreaLight`] (any emissive shape of obscura-accel; spheres
//!   sampled by their cone of directions, quads and meshes by area) and [`EnvironmentLight`]
//!   (constant, or an equirectangular map importance-sampled by luminance with a
//!   [`Distribution2D`]). Every light gives a [`LightSample`] with a solid-angle pdf that its
//!   `pdf_li` reproduces.
//! - [`PathIntegrator`]: unidirectional path tracing with next-event estimation, multiple
//!   importance sampling ([`power_heuristic`]) and Russian roulette, over an
//!   `obscura_accel::Scene` and a [`ShadingScene`] (materials per instance, lights). It draws
//!   its random numbers from any [`SampleDims`], such as `obscura_sample::SampleStream`.
//!   [`PathIntegrator::li_and_hit_batch`] traces many camera rays' paths together, a vertex
//!   each per round, so that their rays reach the geometry in batches (faster on large
//!   meshes, the same values bit for bit). After [`ShadingScene::aim_at_specular`], diffuse
//!   vertices aim a share of their samples at the nearby glass and mirrors, so that the
//!   caustics those throw are found far more often (still unbiased); after
//!   [`ShadingScene::solve_through_glass`], vertices near a glass ball solve for the paths
//!   through it to their light sample's point on a quad light (manifold next-event
//!   estimation), weighed by MIS against the BSDF samples that find the same paths.
//!
//! What is not here: geometry and ray queries (obscura-accel), cameras, films, scene files and
//! image output (obscura-camera, obscura-render). Nothing here owns a random number generator.
//!
//! The design decision: **BSDFs live in the local shading frame** (normal = +z, `wo` towards
//! the viewer, `wi` towards the light, [`Frame`] converts), and **every density is per unit
//! solid angle**, whether it comes from a BSDF or a light. The integrator therefore combines
//! any BSDF with any light through one MIS formula, and the tests can check each piece against
//! analytic answers (white furnace, inverse square law, form factors) on its own.
//! Two-sidedness: diffuse, mirror and conductor reflect on both sides; the dielectric uses the
//! geometric side to tell inside from outside.
//!
//! ```
//! use glam::Vec3;
//! use obscura_accel::{Placement, SceneBuilder, Shape};
//! use obscura_sample::{Sampler, SamplerKind};
//! use obscura_shade::{Light, Material, PathIntegrator, ShadingScene};
//! use obscura_space::{Point3, Ray, Transform, Vector3};
//!
//! // A white floor (y = 0, facing +y) lit by a point light of intensity 8 at height 2.
//! let floor = Shape::Quad {
//!     origin: Vec3::new(-5.0, 0.0, -5.0),
//!     edge_u: Vec3::new(0.0, 0.0, 10.0),
//!     edge_v: Vec3::new(10.0, 0.0, 0.0),
//! };
//! let mut builder = SceneBuilder::new();
//! let instance = builder.add(floor, Placement::Static(Transform::IDENTITY))?;
//! let geometry = builder.build()?;
//! let shading = ShadingScene::new(
//!     vec![Material::Diffuse { reflectance: Vec3::splat(0.5) }],
//!     vec![0; instance as usize + 1],
//!     vec![Light::point(Vec3::new(0.0, 2.0, 0.0), Vec3::splat(8.0))?],
//!     vec![],
//! )?;
//! // Look straight down at the light's foot: L = rho / pi * I / h^2 = 0.5 / pi * 8 / 4.
//! let sampler = Sampler::new(SamplerKind::Independent, 1, 0)?;
//! let mut dims = sampler.stream([0, 0], 0);
//! let ray = Ray::new(Point3::new(0.0, 1.0, 0.0), Vector3::new(0.0, -1.0, 0.0), 0.0);
//! let radiance = PathIntegrator::new(8).li(&geometry, &shading, &ray, &mut dims);
//! assert!((radiance.x - 1.0 / std::f32::consts::PI).abs() < 1e-5);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

mod error;
mod frame;
mod guide;
mod integrator;
mod lens;
mod light;
mod material;

pub use error::ShadeError;
pub use frame::Frame;
pub use integrator::{
    ESTIMATOR_VERSION, PathIntegrator, SampleDims, ShadingScene, power_heuristic, rr_survival,
};
pub use light::{
    AreaLight, EnvironmentLight, Light, LightSample, direction_to_uv, luminance, uv_to_direction,
};
pub use material::{BsdfSample, MIN_ALPHA, Material, fresnel_dielectric};
pub use obscura_sample::{Distribution1D, Distribution2D};
