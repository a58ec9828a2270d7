//! Any bytes through the OBJ loader: a mesh or an error, never a panic, a hang or an abort.
//! Run with `cargo +nightly fuzz run obj fuzz/seeds/obj`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = obscura_accel::parse_obj(data, Path::new("fuzz.obj"));
});
