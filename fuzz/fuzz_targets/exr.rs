//! Any bytes as an environment map's EXR: texels or an error, never a panic, a hang or an
//! abort; texels that pass go on to the environment light's sampling tables.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.exr");
    if let Ok((w, h, texels)) = obscura_render::environment_map_texels(data, path) {
        // Past a few million texels only the allocator is being tested.
        if u64::from(w) * u64::from(h) <= 1 << 22 {
            let _ = obscura_shade::EnvironmentLight::from_texels(
                w,
                h,
                texels,
                glam::Mat4::IDENTITY,
            );
        }
    }
});
