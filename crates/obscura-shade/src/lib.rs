//! WIP
#![deny(missing_docs)]
mod distribution;
mod error;
mod frame;
mod integrator;
mod light;
mod material;
pub use distribution::{Distribution1D, Distribution2D};
pub use error::ShadeError;
pub use frame::Frame;
pub use integrator::{PathIntegrator, SampleDims, ShadingScene, power_heuristic};
pub use light::{
    AreaLight, EnvironmentLight, Light, LightSample, direction_to_uv, luminance, uv_to_direction,
};
pub use material::{BsdfSample, MIN_ALPHA, Material, fresnel_dielectric};
