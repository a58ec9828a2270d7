//! Any bytes as a checkpoint file: a checkpoint or an error, never a panic, a hang or an abort;
//! one that parses must write back to the same bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(c) = obscura_render::Checkpoint::from_bytes(data, Path::new("fuzz.ckpt")) {
        assert_eq!(c.to_bytes(), data, "a checkpoint that parses writes back unchanged");
    }
});
