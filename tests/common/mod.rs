//! Helpers the integration tests share: which backends this build has. Each test file
//! that needs them declares `mod common;`.
#![allow(dead_code)]

use emray::accel::Backend;

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
