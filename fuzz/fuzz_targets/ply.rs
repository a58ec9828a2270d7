//! Any bytes through the PLY reader: a mesh or an error, never a panic, a hang or an abort.
//! Run with `cargo +nightly fuzz run ply fuzz/corpus/ply`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = obscura_import::parse_ply(data, Path::new("fuzz.ply"));
});
