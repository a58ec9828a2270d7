//! The crate's one error type.

/// Why a transform could not be built. Each message stands alone.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpaceError {
    /// A matrix entry or parameter was NaN or infinite.
    #[error("{what}: a value is NaN or infinite")]
    NonFinite {
        /// What was being built, e.g. `"translation"`.
        what: &'static str,
    },
    /// The matrix has no inverse (determinant zero or too small to invert in f32).
    #[error("{what}: the matrix is singular (it has no inverse)")]
    Singular {
        /// What was being built.
        what: &'static str,
    },
    /// A rotation axis of zero length.
    #[error("rotation: the axis has zero length")]
    ZeroAxis,
    /// The look-at frame is undefined; the string says why.
    #[error("look-at: {0}")]
    DegenerateLookAt(&'static str),
    /// Animated-transform keyframes that cannot be interpolated; the string says why.
    #[error("animated transform: {0}")]
    BadKeyframes(&'static str),
}
