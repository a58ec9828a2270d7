//! Any bytes as a render partial (`obscura render --slice`): a partial or an error, never a
//! panic, a hang or an abort; one that parses must write back to the same bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(p) = obscura_render::Partial::from_bytes(data, Path::new("fuzz.part")) {
        assert_eq!(p.to_bytes(), data, "a partial that parses writes back unchanged");
    }
});
