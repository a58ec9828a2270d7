//! obscura-render: under construction.
