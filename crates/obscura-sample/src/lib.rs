//! obscura-sample: under construction.
