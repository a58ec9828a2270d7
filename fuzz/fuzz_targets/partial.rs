//! Any bytes as a render partial (`obscura render --slice`): a partial or an error, never a
//! panic, a hang or an abort; one that parses must write back to the same bytes.
//!
//! Each input is tried as it is and again with its last eight bytes replaced by the FNV-1a
//! checksum of the rest, so that mutations reach the field checks behind the checksum instead
//! of all failing at it.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

#[path = "reseal.rs"]
mod reseal;

fuzz_target!(|data: &[u8]| {
    let sealed = reseal::resealed(data);
    for bytes in std::iter::once(data).chain(sealed.as_deref()) {
        if let Ok(p) = obscura_render::Partial::from_bytes(bytes, Path::new("fuzz.part")) {
            assert_eq!(p.to_bytes(), bytes, "a partial that parses writes back unchanged");
        }
    }
});
