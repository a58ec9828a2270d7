//! Sample generation for Obscura's cameras and shading: the canonical numbers in `[0, 1)`
//! that become a ray's film position, lens point and time, and then the shading decisions
//! along its path.
//!
//! What is here: [`Sampler`], a small value naming one of four generators
//! ([`SamplerKind`]: independent, stratified, Halton, Sobol), and [`SampleStream`], a
//! cursor over the dimensions of one sample whose first call, [`SampleStream::camera`], gives
//! the camera's film offset, lens sample and time as plain glam values. Warps turn canonical numbers into shapes:
//! [`square_to_concentric_disk`] and [`square_to_polygon`] for the aperture,
//! [`ShutterCurve`], [`PiecewiseShutterCurve`] and [`shutter_time`] for the shutter,
//! [`Distribution2D`] for apertures and environment maps drawn in proportion to an image, [`square_to_cosine_hemisphere`] and
//! [`square_to_uniform_sphere`] for shading, each with its pdf. [`sin_cos_pi`] (and [`sin_cos_pi_vec4`]) is the short
//! sine and cosine the per-sample warps and cameras use instead of libm's. Errors are
//! [`SampleError`].
//!
//! What is not here: cameras, films, filters, random number generators with state. The camera
//! crate draws its sample from a [`SampleStream`]; a camera never owns a sampler.
//!
//! The design decision: **every value is a pure function of (pixel, sample index, dimension,
//! seed)**. There is no generator state to share or to advance in order, so the same seed
//! gives the same image for any thread count or tile order, and a render can be split across
//! machines. Dimensions come in pairs, and each pair (film, lens, time, ...) is scrambled or
//! shuffled independently per pixel, so the lens and time strata a sample gets do not follow
//! its film stratum: otherwise depth of field and motion blur would show structured
//! artefacts instead of noise.
//!
//! ```
//! use obscura_sample::{Sampler, SamplerKind, ShutterCurve, shutter_time, square_to_concentric_disk};
//!
//! let sampler = Sampler::new("sobol".parse::<SamplerKind>()?, 16, 0)?;
//! let pixel = [10, 20];
//! for index in 0..sampler.samples_per_pixel() {
//!     let mut stream = sampler.stream(pixel, index);
//!     let (film, lens, time) = stream.camera();
//!     let p_raster = glam::Vec2::new(pixel[0] as f32, pixel[1] as f32) + film;
//!     let p_lens = 0.05 * square_to_concentric_disk(lens); // lens radius 0.05
//!     let time = shutter_time(ShutterCurve::Box.sample(time), [0.0, 1.0]);
//!     assert!(film.cmpge(glam::Vec2::ZERO).all() && film.cmplt(glam::Vec2::ONE).all());
//!     assert!(p_lens.length() <= 0.05 + 1e-6 && (0.0..1.0).contains(&time));
//!     let _u_bsdf = stream.next_2d(); // dimensions 6-7, for shading
//!     # let _ = p_raster;
//! }
//! // Pure: asking again gives the same number.
//! assert_eq!(sampler.value(pixel, 3, 2), sampler.value(pixel, 3, 2));
//! # Ok::<(), obscura_sample::SampleError>(())
//! ```

#![deny(missing_docs)]

mod distribution;
mod error;
mod hash;
mod sampler;
mod sequences;
mod shutter;
mod trig;
mod warp;

pub use distribution::{Distribution1D, Distribution2D, GridCell, SearchStart};
pub use error::SampleError;
pub use hash::ONE_MINUS_EPSILON;
pub use sampler::{
    MAX_SAMPLES_PER_PIXEL, SEQUENCE_VERSION, SOBOL_DIMENSIONS, SampleStream, Sampler, SamplerKind,
};
pub use shutter::{PiecewiseShutterCurve, ShutterCurve, shutter_time};
pub use trig::{sin_cos_pi, sin_cos_pi_vec4};
pub use warp::{
    concentric_disk_pdf, concentric_disk_to_square, cosine_hemisphere_pdf,
    cosine_hemisphere_to_square, polygon_pdf, polygon_to_square, square_to_concentric_disk,
    square_to_cosine_hemisphere, square_to_polygon, square_to_uniform_sphere, uniform_sphere_pdf,
    uniform_sphere_to_square,
};
