//! TOML scene-format loader: any bytes give a scene or a `LoadError`, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = emray::load::toml::parse_str(text, Path::new("fuzz.toml"));
    }
});
