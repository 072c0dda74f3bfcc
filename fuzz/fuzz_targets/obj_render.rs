//! OBJ loader (through a file, as the loader reads MTL files beside it) and the whole
//! pipeline: a model that loads also builds its BVH (and Embree's, with the `embree`
//! feature) and renders a tiny image with no panic, no hang and no NaN pixel.
#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

fn path() -> &'static PathBuf {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("emray-fuzz-obj-render-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temporary folder");
        dir.join("fuzz.obj")
    })
}

fuzz_target!(|data: &[u8]| {
    let p = path();
    std::fs::write(p, data).expect("write the input");
    let Ok(scene) = emray::load::obj::load(p) else {
        return;
    };
    common::render_has_no_nan(&scene);
});
