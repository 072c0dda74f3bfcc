//! OBJ loader (through a file, as the loader reads MTL files beside it): any bytes give
//! a scene or a `LoadError`, never a panic; and the model or error is the same when
//! the file is parsed in stretches of a few bytes, and when its faces are converted
//! to triangles in chunks of two faces.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

fn path() -> &'static PathBuf {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("emray-fuzz-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temporary folder");
        dir.join("fuzz.obj")
    })
}

fuzz_target!(|data: &[u8]| {
    let p = path();
    std::fs::write(p, data).expect("write the input");
    let _ = emray::load::obj::load(p);
    let whole = emray::load::obj::load_geometry(p);
    let cut = emray::load::obj::load_geometry_in_stretches(p, 7);
    // Debug forms: NaN texture coordinates compare equal.
    assert_eq!(format!("{whole:?}"), format!("{cut:?}"));
    let chunks = emray::load::obj::load_geometry_in_chunks(p, usize::MAX, 2);
    assert_eq!(format!("{whole:?}"), format!("{chunks:?}"));
    // The triangles' origins do not show in the Debug forms.
    if let (Ok(a), Ok(b)) = (&whole, &chunks) {
        assert!(a.geometry.sources.same_origins(&b.geometry.sources));
    }
});
