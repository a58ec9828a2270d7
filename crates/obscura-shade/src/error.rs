//! The one error type of this crate.

/// Why a material, light or shading scene was rejected. Every message names the parameter and
/// stands alone, so the renderer can print it after the scene file's name and key.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShadeError {
    /// A parameter holds NaN or infinity.
    #[error("{parameter} must be finite (no NaN or infinity)")]
    NotFinite {
        /// The parameter's name, e.g. `"reflectance"`.
        parameter: &'static str,
    },
    /// A parameter lies outside its allowed range.
    #[error("{parameter} must be {expected}")]
    OutOfRange {
        /// The parameter's name, e.g. `"ior"`.
        parameter: &'static str,
        /// The allowed range, in words, e.g. `"in [0, 1]"`.
        expected: &'static str,
    },
    /// An environment map's texel count does not match its size.
    #[error("environment map texels: expected width * height = {expected}, got {actual}")]
    TexelCount {
        /// `width * height`.
        expected: u64,
        /// The number of texels given.
        actual: usize,
    },
    /// An index refers to something that does not exist.
    #[error("{what} = {index} is out of range (there are {count})")]
    BadIndex {
        /// What the index is, e.g. `"instance_material[3]"`.
        what: String,
        /// The index given.
        index: u32,
        /// How many there are.
        count: usize,
    },
}

/// Checks that every component of `v` is finite and at least zero.
pub(crate) fn check_non_negative(v: glam::Vec3, parameter: &'static str) -> Result<(), ShadeError> {
    if !v.is_finite() {
        return Err(ShadeError::NotFinite { parameter });
    }
    if v.min_element() < 0.0 {
        return Err(ShadeError::OutOfRange {
            parameter,
            expected: "at least 0 in every channel",
        });
    }
    Ok(())
}

/// Checks that every component of `v` lies in `[0, 1]`.
pub(crate) fn check_unit(v: glam::Vec3, parameter: &'static str) -> Result<(), ShadeError> {
    if !v.is_finite() {
        return Err(ShadeError::NotFinite { parameter });
    }
    if v.min_element() < 0.0 || v.max_element() > 1.0 {
        return Err(ShadeError::OutOfRange {
            parameter,
            expected: "in [0, 1] in every channel",
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_parameter() {
        let e = check_unit(glam::Vec3::new(0.5, 1.5, 0.0), "reflectance").unwrap_err();
        assert_eq!(
            e.to_string(),
            "reflectance must be in [0, 1] in every channel"
        );
        let e = check_non_negative(glam::Vec3::new(f32::NAN, 0.0, 0.0), "intensity").unwrap_err();
        assert_eq!(
            e.to_string(),
            "intensity must be finite (no NaN or infinity)"
        );
    }
}
