//! Any bytes as a checkpoint file (`obscura render --checkpoint`): a partial or an error, never a
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
        if let Ok(c) = obscura_render::Checkpoint::from_bytes(bytes, Path::new("fuzz.ckpt")) {
            assert_eq!(c.to_bytes(), bytes, "a checkpoint that parses writes back unchanged");
        }
    }
});
