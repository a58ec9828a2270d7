//! Any bytes through the scene parser and the scene builder: `Ok` or `Err`, never a panic, a
//! hang or an abort. Run with `cargo +nightly fuzz run scene_parser fuzz/seeds/scenes`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    // load_description refuses non-UTF-8 files before parsing; the parser sees text only.
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = Path::new("/nonexistent/fuzz/scene.toml");
    if let Ok(description) = obscura_render::parse_description(file, text) {
        // Building never allocates the film, so big resolutions stay cheap here.
        let _ = obscura_render::RenderScene::build(description);
    }
});
