//! NFF loader: any bytes give a scene or a `LoadError`, never a panic or a hang.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(scene) = emray::load::nff::parse_str(text, Path::new("fuzz.nff")) {
            // Settings derived from the scene (resolution, depth, the camera) must
            // resolve or be refused, never panic.
            let _ = emray::job::RenderOptions::default().resolve(&scene);
            let _ = scene.prim_count_with_instances();
        }
    }
});
