//! Any bytes through the Mitsuba 3 XML importer and the renderer's validation of what it
//! produces: `Ok` or `Err`, never a panic, a hang or an abort. Run with
//! `cargo +nightly fuzz run mitsuba fuzz/corpus/mitsuba scenes`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = Path::new("/nonexistent/fuzz/scene.xml");
    if let Ok(imported) = obscura_import::parse_mitsuba(file, text) {
        if let Ok(description) = imported.description() {
            let _ = obscura_render::RenderScene::build(description);
        }
    }
});
