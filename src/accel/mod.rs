//! Acceleration structures behind one trait: Intel Embree (feature `embree`) and the
//! pure-Rust BVH. Both report hits in the same terms (geometry id = [`Kind`], primitive
//! index within the kind), so the renderer cannot tell them apart.

pub mod bvh;
#[cfg(feature = "embree")]
pub mod embree;

use crate::geometry::Kind;
use crate::math::{Ray, Vec3};

/// The nearest hit along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter.
    pub t: f32,
    /// Geometry id: a [`Kind`] discriminant.
    pub geom_id: u32,
    /// Index of the primitive within its kind.
    pub prim_id: u32,
    /// First surface parameter (triangles: barycentric weight of vertex 1).
    pub u: f32,
    /// Second surface parameter (triangles: barycentric weight of vertex 2).
    pub v: f32,
    /// Geometric normal, not normalised; for triangles `(p1 − p0) × (p2 − p0)`. In the
    /// object space of the instance for instanced hits.
    pub ng: Vec3,
    /// Index of the instance hit ([`crate::scene::Scene::instances`]), or
    /// [`NO_INSTANCE`] for top-level primitives.
    pub inst_id: u32,
}

/// [`Hit::inst_id`] of a top-level primitive.
pub const NO_INSTANCE: u32 = u32::MAX;

impl Hit {
    /// The primitive kind hit.
    pub fn kind(&self) -> Kind {
        Kind::from_id(self.geom_id).expect("invalid geometry id")
    }
}

/// What a backend reports about itself.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AccelStats {
    /// Backend name (`embree` or `bvh`).
    pub backend: &'static str,
    /// Primitives in the structure.
    pub prims: usize,
    /// Nodes (BVH only; 0 when the backend does not say).
    pub nodes: usize,
    /// Bytes used by the structure (approximate for Embree: 0 when unknown).
    pub bytes: usize,
    /// Free-form details (Embree version, ISA, ...).
    pub detail: String,
    /// The primitive kinds the structure holds, with their counts (the scene's own and
    /// each instanced object's once), in [`Kind`] order. Only these are ever dispatched
    /// to: Embree holds one geometry per kind present, the BVH's leaves only the
    /// primitives present.
    pub kinds: Vec<(Kind, usize)>,
}

/// Add `n` primitives of `kind` to a [`AccelStats::kinds`] list (nothing when `n` is 0).
pub(crate) fn add_kind(kinds: &mut Vec<(Kind, usize)>, kind: Kind, n: usize) {
    if n == 0 {
        return;
    }
    match kinds.binary_search_by_key(&kind, |&(k, _)| k) {
        Ok(i) => kinds[i].1 += n,
        Err(i) => kinds.insert(i, (kind, n)),
    }
}

/// `sphere×12, cone×3` for [`AccelStats::kinds`] (`none` when empty).
pub fn kinds_summary(kinds: &[(Kind, usize)]) -> String {
    if kinds.is_empty() {
        return "none".into();
    }
    let parts: Vec<String> = kinds
        .iter()
        .map(|(k, n)| format!("{}×{n}", k.name()))
        .collect();
    parts.join(", ")
}

/// A ray-query structure built over a [`Scene`].
pub trait Accel: Sync {
    /// The nearest hit with `t` in `(ray.tmin, ray.tmax)`.
    fn intersect(&self, ray: &Ray) -> Option<Hit>;
    /// Whether anything lies in `(ray.tmin, ray.tmax)` (any-hit, for shadow rays).
    fn occluded(&self, ray: &Ray) -> bool;
    /// The nearest hits of a batch of coherent rays (`hits[i]` for `rays[i]`; the
    /// slices have the same length), each as [`Accel::intersect`] would find it.
    /// `width` asks for packets of that many rays (4, 8 or 16) where the backend has
    /// them (Embree); the default, and width 0, cast the rays one at a time.
    fn intersect_coherent(&self, rays: &[Ray], hits: &mut [Option<Hit>], width: usize) {
        let _ = width;
        for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
            *hit = self.intersect(ray);
        }
    }
    /// Statistics about the built structure.
    fn stats(&self) -> AccelStats;
}

/// Which backend to build.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Backend {
    /// Intel Embree.
    Embree,
    /// The pure-Rust BVH.
    Bvh,
}

impl Backend {
    /// The name used on the command line and in statistics.
    pub fn name(self) -> &'static str {
        match self {
            Backend::Embree => "embree",
            Backend::Bvh => "bvh",
        }
    }

    /// The default: Embree when compiled in, else the BVH.
    pub fn default_available() -> Backend {
        if cfg!(feature = "embree") {
            Backend::Embree
        } else {
            Backend::Bvh
        }
    }
}

/// Embree's build quality (`RTC_BUILD_QUALITY_*`): a faster build against a faster
/// hierarchy. The BVH backend ignores it.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum EmbreeQuality {
    /// `RTC_BUILD_QUALITY_LOW`: a Morton-code build, fastest to build.
    Low,
    /// `RTC_BUILD_QUALITY_MEDIUM`: binned SAH, Embree's default.
    #[default]
    Medium,
    /// `RTC_BUILD_QUALITY_HIGH`: SAH with spatial splits of triangles.
    High,
}

impl EmbreeQuality {
    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            EmbreeQuality::Low => "low",
            EmbreeQuality::Medium => "medium",
            EmbreeQuality::High => "high",
        }
    }
}

/// Errors from building a backend.
#[derive(Debug, thiserror::Error)]
pub enum AccelError {
    /// The Embree backend failed.
    #[cfg(feature = "embree")]
    #[error(transparent)]
    Embree(#[from] embree::EmbreeError),
    /// The requested backend is not compiled in.
    #[error(
        "backend `{0}` is not available in this build (it was built without the `embree` feature)"
    )]
    Unavailable(&'static str),
}
