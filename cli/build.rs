//! Build script: when the library was built against an Embree outside the folders the
//! system's loader searches (`EMBREE_DIR` and the like, see the library's `build.rs`),
//! write that folder into the command's run path too, so that `emray` starts without
//! `LD_LIBRARY_PATH`. The library's build script hands the folder over as
//! `DEP_EMBREE_RPATH` (its `links = "embree"` metadata); a link argument of a build
//! script reaches its own package's targets only.

fn main() {
    println!("cargo::rerun-if-env-changed=DEP_EMBREE_RPATH");
    if let Ok(dir) = std::env::var("DEP_EMBREE_RPATH") {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
