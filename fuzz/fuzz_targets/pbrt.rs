//! Any bytes through the pbrt-v4 importer and the renderer's validation of what it produces:
//! `Ok` or `Err`, never a panic, a hang or an abort. Run with
//! `cargo +nightly fuzz run pbrt fuzz/corpus/pbrt scenes`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // A folder that does not exist: Include and plymesh fail cleanly instead of reading files.
    let file = Path::new("/nonexistent/fuzz/scene.pbrt");
    if let Ok(imported) = obscura_import::parse_pbrt(file, text) {
        if let Ok(description) = imported.description() {
            let _ = obscura_render::RenderScene::build(description);
        }
    }
});
