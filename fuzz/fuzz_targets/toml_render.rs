//! TOML scene loader and the whole pure-Rust pipeline: a scene that loads also builds its BVH
//! and renders a tiny image with no panic, no hang and no NaN pixel.
#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(scene) = emray::load::toml::parse_str(text, Path::new("fuzz.toml")) else {
        return;
    };
    common::render_has_no_nan(&scene);
});
