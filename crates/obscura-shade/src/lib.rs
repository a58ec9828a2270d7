//! obscura-shade: under construction.
