//! Acceleration structures behind one trait: Intel Embree (feature `embree`) and the
//! pure-Rust BVH. Both report hits in the same terms (geometry id = [`Kind`], primitive
//! index within the kind), so the renderer cannot tell them apart. Primitives with
//! infinite bounds stay out of both structures: `unbounded` tests them first, for
//! both.

pub mod bvh;
#[cfg(feature = "embree")]
pub mod embree;
pub(crate) mod unbounded;

use crate::geometry::Kind;
use crate::math::Ray;
use crate::scene::Scene;

pub use crate::scene::{Hit, NO_INSTANCE};

/// What a backend reports about itself.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AccelStats {
    /// Backend name (`embree` or `bvh`).
    pub backend: &'static str,
    /// Primitives in the structure.
    pub prims: usize,
    /// Nodes (BVH only; 0 when the backend does not say).
    pub nodes: usize,
    /// Bytes of the structure: its nodes and leaves with the primitive data they hold
    /// (the BVH's own count; for Embree what its memory monitor counted once the scene
    /// was committed, plus the primitive lists its user geometries read). 0 when
    /// unknown.
    pub bytes: usize,
    /// Free-form details (Embree version, ISA, ...).
    pub detail: String,
    /// The primitive kinds the structure holds, with their counts (the scene's own and
    /// each instanced object's once), in [`Kind`] order. Only these are ever dispatched
    /// to: Embree holds one geometry per kind present, the BVH's leaves only the
    /// primitives present.
    pub kinds: Vec<(Kind, usize)>,
}

impl AccelStats {
    /// [`AccelStats::bytes`] per primitive, `None` when either is 0.
    pub fn bytes_per_prim(&self) -> Option<f64> {
        (self.bytes > 0 && self.prims > 0).then(|| self.bytes as f64 / self.prims as f64)
    }
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

/// The names of the kinds of [`AccelStats::kinds`], `spheres, cones` (`none` when
/// empty). The counts are left out: the backend holds each instanced object once, so
/// they are not the number of primitives a ray can meet, which `--stats` gives.
pub fn kinds_summary(kinds: &[(Kind, usize)]) -> String {
    if kinds.is_empty() {
        return "none".into();
    }
    let names: Vec<&str> = kinds.iter().map(|(k, _)| k.name()).collect();
    names.join(", ")
}

/// A ray-query structure built over a [`Scene`].
pub trait Accel: Sync {
    /// Whether the top-level triangle hits this backend reports carry the watertight
    /// test's own `t`, `u`, `v` for the ray as given, bit for bit, so that
    /// [`Scene::surface_of`](crate::scene::Scene::surface_of) need not test the
    /// triangle again to make every backend's hits the same
    /// ([`crate::scene::Geometry::exact_hit`]).
    #[inline(always)]
    fn exact_triangle_hits(&self) -> bool {
        false
    }
    /// The nearest hit with `t` in `(ray.tmin, ray.tmax)`.
    fn intersect(&self, ray: &Ray) -> Option<Hit>;
    /// Whether anything lies in `(ray.tmin, ray.tmax)` (any-hit, for shadow rays).
    fn occluded(&self, ray: &Ray) -> bool;
    /// The nearest hits of a batch of coherent rays (`hits[i]` for `rays[i]`; the
    /// slices have the same length), each as [`Accel::intersect`] would find it. A
    /// backend with ray packets casts them in packets of the width it was built with
    /// ([`BackendOptions::packet_width`]); the default casts them one at a time.
    fn intersect_coherent(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
            *hit = self.intersect(ray);
        }
    }
    /// The nearest hits of a batch of rays in no particular order (`hits[i]` for
    /// `rays[i]`; the slices have the same length), each as [`Accel::intersect`] would
    /// find it. The default casts them one at a time.
    fn intersect_batch(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
            *hit = self.intersect(ray);
        }
    }
    /// Whether anything lies on each of a batch of rays (`occluded[i]` for `rays[i]`;
    /// the slices have the same length), each as [`Accel::occluded`] would say: the
    /// shadow rays of a depth of the wavefront. The default casts them one at a time.
    fn occluded_batch(&self, rays: &[Ray], occluded: &mut [bool]) {
        for (ray, o) in rays.iter().zip(occluded.iter_mut()) {
            *o = self.occluded(ray);
        }
    }
    /// Statistics about the built structure.
    fn stats(&self) -> AccelStats;
}

/// Which backend to build.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
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

/// Which backend to build, and how: everything about the acceleration structure that a
/// render does not need to know. The BVH ignores the Embree options.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BackendOptions {
    /// The backend.
    pub backend: Backend,
    /// Embree's build quality.
    pub embree_quality: EmbreeQuality,
    /// Embree's `RTC_SCENE_FLAG_ROBUST` on every scene it commits (on by default: no
    /// pinholes between triangles sharing an edge; the BVH is watertight anyway).
    pub embree_robust: bool,
    /// Embree's `RTC_SCENE_FLAG_COMPACT` on every scene it commits; `None` chooses by
    /// the scene's size ([`embree_compact_for`]).
    pub embree_compact: Option<bool>,
    /// Analytic primitives per Embree user primitive, at most (1: one each); a group's
    /// members are neighbours in space and its callbacks test each, so the hits are
    /// the same.
    /// `None` chooses by the scene's size and the render's camera rays
    /// ([`embree_group_for`]).
    pub embree_group: Option<u32>,
    /// The camera rays the render will cast (pixels × samples), when known (0: not
    /// known); the default grouping weighs them against the build ([`embree_group_for`]).
    pub camera_rays: u64,
    /// Coherent rays (a tile's eye rays with one sample per pixel) are cast in packets
    /// of this many (4, 8 or 16: Embree's `rtcIntersect4/8/16`); 0 casts them one by
    /// one. Analytic shapes give the same hits either way; Embree's packet triangle
    /// test may round a ray through a shared edge to the other triangle.
    pub packet_width: u32,
    /// The shadow rays of a depth of the wavefront (ordered light by light) are cast
    /// in packets of this many (4, 8 or 16: Embree's `rtcOccluded4/8/16`); 0 casts them
    /// one by one. Either gives the same answers. `None` chooses by the scene's kinds
    /// ([`shadow_packet_width_for`]).
    pub shadow_packet_width: Option<u32>,
}

/// Eye rays per Embree packet by default.
pub const DEFAULT_PACKET_WIDTH: u32 = 8;
/// Shadow rays per Embree packet when packets pay (see [`shadow_packet_width_for`]).
pub const DEFAULT_SHADOW_PACKET_WIDTH: u32 = 8;

/// The shadow packet width for a scene of `kinds`, when none is asked for: packets of
/// [`DEFAULT_SHADOW_PACKET_WIDTH`] when the scene holds only triangles and spheres, one
/// by one otherwise. Measured (512² `--spd`, 1 thread, interleaved): packets save
/// 7–16% of the render on the triangle scenes (tetra, gears, teapot) and instructions on
/// spheres (balls −6%), but a packet's any-hit traversal serves all its rays in one
/// order and tests cones for rays that an earlier cone would have stopped: rings +19%,
/// jacks no gain.
pub fn shadow_packet_width_for(kinds: &[(Kind, usize)]) -> u32 {
    let packets_pay = kinds
        .iter()
        .all(|&(k, _)| matches!(k, Kind::Triangle | Kind::Sphere));
    if packets_pay {
        DEFAULT_SHADOW_PACKET_WIDTH
    } else {
        0
    }
}

/// Primitives from which Embree builds compact structures by default.
pub const EMBREE_COMPACT_FROM: usize = 1 << 22;

/// Whether Embree builds a scene of `prims` primitives compact when not told: from
/// [`EMBREE_COMPACT_FROM`] on. Measured on balls at 5.4 M spheres (2 threads, six
/// interleaved runs): the peak resident memory is 817 MB instead of 891 MB and the
/// build steadier (2.5–2.7 s, against 2.5–3.7 s); at 0.6 M spheres the build gains
/// 2–6 %. A compact structure costs the render 0–16 % (jacks +16 %, gears +12 %, rings
/// and tetra nothing; 512² `--spd`), which only a scene whose build outweighs its
/// render repays.
pub fn embree_compact_for(prims: usize) -> bool {
    prims >= EMBREE_COMPACT_FROM
}

/// Analytic primitives per Embree user primitive, at most, when grouping pays.
pub const EMBREE_GROUP_LARGE: u32 = 4;

/// Primitives per camera ray from which grouping pays (see [`embree_group_for`]).
pub const EMBREE_GROUP_PRIMS_PER_RAY: u64 = 4;

/// How many analytic primitives one Embree user primitive stands for at most, when not
/// told, in a scene of `prims` primitives rendered with `camera_rays` camera rays (0:
/// not known): [`EMBREE_GROUP_LARGE`] from [`EMBREE_COMPACT_FROM`] primitives on when
/// there are at least [`EMBREE_GROUP_PRIMS_PER_RAY`] per camera ray, one otherwise.
///
/// Groups trade render time for build time and memory. Measured on balls at 5.4 M
/// spheres, 512² `--spd`, 2 threads, with the machine otherwise idle: groups of at
/// most 4 (3.0 on average there: a group ends where its box would grow much larger
/// than its members') build in 1.4–1.6 s instead of 3.1 s and peak at 0.48–0.53 GB
/// instead of 0.74 GB, and the render takes 0.40–0.43 s instead of 0.27 s: a group's
/// box is larger than its members', so more rays reach it, and each tests its
/// members. The build's saving (about 0.28 µs per primitive) equals the render's loss
/// (about 0.6 µs per camera ray) at about 2 primitives per camera ray; the rule keeps
/// a margin, and leaves scenes whose render is not known (a library's own builds)
/// ungrouped.
pub fn embree_group_for(prims: usize, camera_rays: u64) -> u32 {
    let prims_per_ray = (prims as u64).checked_div(camera_rays).unwrap_or(0);
    if prims >= EMBREE_COMPACT_FROM && prims_per_ray >= EMBREE_GROUP_PRIMS_PER_RAY {
        EMBREE_GROUP_LARGE
    } else {
        1
    }
}

impl BackendOptions {
    /// `backend` with the default options: medium build quality, robust (watertight)
    /// traversal, packets of [`DEFAULT_PACKET_WIDTH`].
    pub fn new(backend: Backend) -> Self {
        BackendOptions {
            backend,
            embree_quality: EmbreeQuality::default(),
            embree_robust: true,
            embree_compact: None,
            embree_group: None,
            camera_rays: 0,
            packet_width: DEFAULT_PACKET_WIDTH,
            shadow_packet_width: None,
        }
    }
}

impl Default for BackendOptions {
    /// The default backend ([`Backend::default_available`]) with the default options.
    fn default() -> Self {
        BackendOptions::new(Backend::default_available())
    }
}

impl From<Backend> for BackendOptions {
    fn from(backend: Backend) -> Self {
        BackendOptions::new(backend)
    }
}

/// Work to do with a built backend, generic over it: [`build`] builds the backend and
/// hands it over, so that everything below is monomorphised per backend.
pub trait WithAccel {
    /// What the work returns.
    type Output;
    /// Do the work with `accel`, built in `build_ms` milliseconds.
    fn run<A: Accel>(self, accel: &A, build_ms: f64) -> Self::Output;
}

/// Build the backend `options` names over `scene` (timed) and run `work` with it: the
/// one place a backend is chosen and built. Embree builds on the process's device for
/// as many threads as the current rayon pool has.
pub fn build<W: WithAccel>(
    scene: &Scene,
    options: &BackendOptions,
    work: W,
) -> Result<W::Output, AccelError> {
    let t0 = std::time::Instant::now();
    let ms = |t: std::time::Instant| t.elapsed().as_secs_f64() * 1e3;
    match options.backend {
        Backend::Bvh => {
            let accel = bvh::Bvh::build(scene);
            let build_ms = ms(t0);
            Ok(work.run(&accel, build_ms))
        }
        #[cfg(feature = "embree")]
        Backend::Embree => {
            let accel = embree::EmbreeAccel::build_with(scene, options)?;
            let build_ms = ms(t0);
            Ok(work.run(&accel, build_ms))
        }
        #[cfg(not(feature = "embree"))]
        Backend::Embree => Err(AccelError::Unavailable("embree")),
    }
}

/// Embree's build quality (`RTC_BUILD_QUALITY_*`): a faster build against a faster
/// hierarchy. The BVH backend ignores it.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
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
