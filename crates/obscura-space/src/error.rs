//! The crate's one error type.

use core::fmt;

/// Why a transform could not be built. Each message stands alone.
#[derive(Debug, Clone, PartialEq)]
pub enum SpaceError {
    /// A matrix entry or parameter was NaN or infinite.
    NonFinite {
        /// What was being built, e.g. `"translation"`.
        what: &'static str,
    },
    /// The matrix has no inverse (determinant zero or too small to invert in f32).
    Singular {
        /// What was being built.
        what: &'static str,
    },
    /// A rotation axis of zero length.
    ZeroAxis,
    /// The look-at frame is undefined; the string says why.
    DegenerateLookAt(&'static str),
    /// Animated-transform keyframes that cannot be interpolated; the string says why.
    BadKeyframes(&'static str),
}

impl fmt::Display for SpaceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SpaceError::NonFinite { what } => write!(f, "{what}: a value is NaN or infinite"),
            SpaceError::Singular { what } => {
                write!(f, "{what}: the matrix is singular (it has no inverse)")
            }
            SpaceError::ZeroAxis => write!(f, "rotation: the axis has zero length"),
            SpaceError::DegenerateLookAt(why) => write!(f, "look-at: {why}"),
            SpaceError::BadKeyframes(why) => write!(f, "animated transform: {why}"),
        }
    }
}

impl std::error::Error for SpaceError {}
