//! Helpers the integration tests share: which backends this build has, and running
//! the `emray` binary. Each test file that needs them declares `mod common;`; not every
//! file uses every helper.
#![allow(dead_code)]

use emray::accel::Backend;
use std::path::Path;
use std::process::{Command, Output};

/// The backends this build has, the pure-Rust BVH first (Embree with the `embree`
/// feature).
pub fn backends() -> Vec<Backend> {
    let mut all = vec![Backend::Bvh];
    if cfg!(feature = "embree") {
        all.push(Backend::Embree);
    }
    all
}

/// The names `--backend` takes for [`backends`], in the same order.
pub fn backend_names() -> Vec<&'static str> {
    backends().into_iter().map(Backend::name).collect()
}

/// Run the `emray` binary with `args` in the folder `dir` and wait for it.
pub fn emray(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_emray"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run emray")
}

/// What a run printed on its standard error, as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The repository's root (the workspace), where `scenes/` and `docs/` are.
pub fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the command line's package lies in the workspace")
}
