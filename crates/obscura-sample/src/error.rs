//! The crate's one error type.

/// Everything that can go wrong when configuring a sampler, a shutter curve or an aperture.
///
/// Every message stands alone: it names the parameter, the value that was given and what
/// would have been accepted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SampleError {
    /// A sampler needs at least one sample per pixel.
    #[error("samples per pixel must be at least 1, got 0")]
    ZeroSamplesPerPixel,
    /// More samples per pixel than the samplers can stratify exactly in `f32`.
    #[error("samples per pixel must be at most {max}, got {spp}")]
    TooManySamplesPerPixel {
        /// The number that was asked for.
        spp: u32,
        /// The largest supported number.
        max: u32,
    },
    /// A sampler name that is not one of the four of the scene format.
    #[error(
        "unknown sampler type \"{name}\": expected \"independent\", \"stratified\", \"halton\" or \"sobol\""
    )]
    UnknownSampler {
        /// The name that was given.
        name: String,
    },
    /// A trapezoidal shutter ramp outside `[0, 0.5]` or not finite.
    #[error(
        "shutter ramp must be a finite fraction of the interval in [0, 0.5] (time spent opening, and again closing), got {ramp}"
    )]
    InvalidShutterRamp {
        /// The ramp that was given.
        ramp: f32,
    },
    /// A polygonal aperture with fewer than three blades.
    #[error("an aperture polygon needs at least 3 blades, got {blades}")]
    TooFewBlades {
        /// The number of blades that was given.
        blades: u32,
    },
    /// An aperture rotation that is NaN or infinite.
    #[error("aperture rotation must be a finite angle in degrees, got {degrees}")]
    InvalidRotation {
        /// The rotation that was given.
        degrees: f32,
    },
    /// A piecewise-linear shutter curve that is not a valid density over the interval.
    #[error("shutter_curve: {reason}")]
    InvalidShutterCurve {
        /// What is wrong with it, naming the offending point.
        reason: String,
        /// The offending point's index, when one point is at fault.
        point: Option<usize>,
    },
}
