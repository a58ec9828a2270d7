//! obscura-accel: under construction.
