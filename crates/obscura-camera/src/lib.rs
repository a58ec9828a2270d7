//! obscura-camera: under construction.
