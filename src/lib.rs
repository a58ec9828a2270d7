//! Obscura: camera models for ray tracing.
pub use obscura_space as space;
