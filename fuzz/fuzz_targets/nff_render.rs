//! NFF loader and the whole pure-Rust pipeline: a scene that loads also builds its BVH
//! and renders a tiny image with no panic, no hang and no NaN pixel.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(scene) = emray::load::nff::parse_str(text, Path::new("fuzz.nff")) else {
        return;
    };
    let mut settings = emray::RenderSettings::for_scene(&scene);
    settings.width = 6;
    settings.height = 5;
    settings.max_depth = settings.max_depth.min(6);
    settings.spp = 1;
    settings.area_samples = settings.area_samples.min(2);
    if let Ok((film, _)) = emray::run::render_scene(
        "fuzz",
        &scene,
        emray::accel::Backend::Bvh,
        &settings,
        0.0,
        None,
    ) {
        for (i, p) in film.pixels.iter().enumerate() {
            assert!(!p.x.is_nan() && !p.y.is_nan() && !p.z.is_nan(), "NaN at pixel {i}: {p:?}");
        }
    }
});
