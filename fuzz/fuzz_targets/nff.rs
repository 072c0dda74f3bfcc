//! NFF loader: any bytes give a scene or a `LoadError`, never a panic or a hang.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(scene) = emray::load::nff::parse_str(text, Path::new("fuzz.nff")) {
            let settings = emray::render::RenderSettings::for_scene(&scene);
            let _ = emray::job::limits::estimate_bytes(&scene, &settings);
        }
    }
});
