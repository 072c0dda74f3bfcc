//! Raw casting: the rays a render casts, recorded once and cast again with no shading,
//! so that render time ÷ raw time is the renderer's overhead over pure ray casting.

use crate::accel::{Accel, AccelStats, Hit};
use crate::math::Ray;
use crate::render::{self, RenderSettings};
use crate::scene::Scene;
use rayon::prelude::*;
use std::sync::Mutex;
use std::time::Instant;

/// One recorded query: the ray and whether it was an any-hit (shadow) query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Query {
    /// The ray as the renderer passed it.
    pub ray: Ray,
    /// `true` for [`Accel::occluded`] or [`Accel::occluded_batch`], `false` for the
    /// nearest-hit queries.
    pub occluded: bool,
    /// Set on the first query of a batch of `len` queries the renderer cast together
    /// (the batch's other queries follow it; the backend casts them its own way,
    /// packets or one by one); `None` for a query cast alone.
    pub batch: Option<Batch>,
}

/// A batch of rays cast together (see [`Query::batch`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Batch {
    /// Queries in the batch, this one included.
    pub len: u32,
    /// How the batch was cast.
    pub kind: BatchKind,
}

/// The batch queries of [`Accel`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BatchKind {
    /// [`Accel::intersect_coherent`]: eye rays.
    Coherent,
    /// [`Accel::intersect_batch`]: reflection and refraction rays.
    Nearest,
    /// [`Accel::occluded_batch`]: shadow rays.
    Shadow,
}

/// A backend that records every query passed through it, per worker thread (one
/// buffer per rayon worker, so the order within a thread is the order of tracing).
pub struct Recorder<'a, A: Accel> {
    inner: &'a A,
    buffers: Vec<Mutex<Vec<Query>>>,
}

impl<'a, A: Accel> Recorder<'a, A> {
    /// Record the queries made through `inner` on the current rayon pool.
    pub fn new(inner: &'a A) -> Self {
        let n = rayon::current_num_threads() + 1;
        Recorder {
            inner,
            buffers: (0..n).map(|_| Mutex::new(Vec::new())).collect(),
        }
    }

    fn push(&self, queries: impl IntoIterator<Item = Query>) {
        // Threads outside the pool share the last buffer.
        let k = rayon::current_thread_index()
            .map_or(self.buffers.len() - 1, |i| i.min(self.buffers.len() - 1));
        // A poisoned buffer only means another thread panicked; its data is intact.
        let mut b = self.buffers[k].lock().unwrap_or_else(|e| e.into_inner());
        b.extend(queries);
    }

    /// Record `rays` as one batch of `kind`.
    fn push_batch(&self, rays: &[Ray], kind: BatchKind) {
        let batch = Batch {
            len: u32::try_from(rays.len()).unwrap_or(u32::MAX),
            kind,
        };
        self.push(rays.iter().enumerate().map(|(i, ray)| Query {
            ray: *ray,
            occluded: kind == BatchKind::Shadow,
            batch: (i == 0).then_some(batch),
        }));
    }

    /// The recorded queries, thread by thread.
    pub fn into_queries(self) -> Vec<Query> {
        self.buffers
            .into_iter()
            .flat_map(|m| m.into_inner().unwrap_or_else(|e| e.into_inner()))
            .collect()
    }
}

impl<A: Accel> Accel for Recorder<'_, A> {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.push([Query {
            ray: *ray,
            occluded: false,
            batch: None,
        }]);
        self.inner.intersect(ray)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.push([Query {
            ray: *ray,
            occluded: true,
            batch: None,
        }]);
        self.inner.occluded(ray)
    }

    fn intersect_coherent(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        self.push_batch(rays, BatchKind::Coherent);
        self.inner.intersect_coherent(rays, hits);
    }

    fn intersect_batch(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        self.push_batch(rays, BatchKind::Nearest);
        self.inner.intersect_batch(rays, hits);
    }

    fn occluded_batch(&self, rays: &[Ray], occluded: &mut [bool]) {
        self.push_batch(rays, BatchKind::Shadow);
        self.inner.occluded_batch(rays, occluded);
    }

    fn exact_triangle_hits(&self) -> bool {
        self.inner.exact_triangle_hits()
    }

    fn stats(&self) -> AccelStats {
        self.inner.stats()
    }
}

/// What casting the recorded rays again found.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RawCast {
    /// Queries cast.
    pub queries: u64,
    /// Nearest-hit queries that hit plus shadow queries that were occluded.
    pub hits: u64,
    /// Wall time in milliseconds.
    pub ms: f64,
}

/// Rays per parallel work item: large enough that scheduling costs nothing, small
/// enough to balance two threads.
const CHUNK: usize = 4096;

/// Cast `queries` through `accel` on the current rayon pool, with no shading at all;
/// a recorded batch of coherent rays is cast as one batch again.
pub fn cast<A: Accel>(accel: &A, queries: &[Query]) -> RawCast {
    // Work items of about CHUNK queries, never splitting a batch.
    let mut cuts = vec![0];
    let mut i = 0;
    while i < queries.len() {
        i += queries[i].batch.map_or(1, |b| (b.len as usize).max(1));
        i = i.min(queries.len());
        if i - cuts[cuts.len() - 1] >= CHUNK || i == queries.len() {
            cuts.push(i);
        }
    }
    let start = Instant::now();
    let hits: u64 = cuts
        .par_windows(2)
        .map(|w| {
            let chunk = &queries[w[0]..w[1]];
            let mut batch = BatchBuffers::default();
            let mut n = 0u64;
            let mut k = 0;
            while k < chunk.len() {
                let q = &chunk[k];
                if let Some(b) = q.batch {
                    let len = (b.len as usize).clamp(1, chunk.len() - k);
                    n += batch.cast(accel, b.kind, &chunk[k..k + len]);
                    k += len;
                    continue;
                }
                let hit = if q.occluded {
                    accel.occluded(&q.ray)
                } else {
                    accel.intersect(&q.ray).is_some()
                };
                n += u64::from(hit);
                k += 1;
            }
            n
        })
        .sum();
    RawCast {
        queries: queries.len() as u64,
        hits,
        ms: start.elapsed().as_secs_f64() * 1e3,
    }
}

/// The buffers of a replayed batch.
#[derive(Default)]
struct BatchBuffers {
    rays: Vec<Ray>,
    hits: Vec<Option<Hit>>,
    occluded: Vec<bool>,
}

impl BatchBuffers {
    /// Cast `queries` as one batch of `kind` through `accel`; how many hit (or were
    /// occluded).
    fn cast<A: Accel>(&mut self, accel: &A, kind: BatchKind, queries: &[Query]) -> u64 {
        self.rays.clear();
        self.rays.extend(queries.iter().map(|q| q.ray));
        let n = self.rays.len();
        if kind == BatchKind::Shadow {
            self.occluded.clear();
            self.occluded.resize(n, false);
            accel.occluded_batch(&self.rays, &mut self.occluded);
            return self.occluded.iter().filter(|&&o| o).count() as u64;
        }
        self.hits.clear();
        self.hits.resize(n, None);
        if kind == BatchKind::Coherent {
            accel.intersect_coherent(&self.rays, &mut self.hits);
        } else {
            accel.intersect_batch(&self.rays, &mut self.hits);
        }
        self.hits.iter().filter(|h| h.is_some()).count() as u64
    }
}

/// Render `scene` once through a [`Recorder`] (untimed) and return the queries it made
/// with the render's ray counts.
pub fn record<A: Accel>(
    scene: &Scene,
    accel: &A,
    settings: &RenderSettings,
) -> (Vec<Query>, render::RayCounts) {
    let rec = Recorder::new(accel);
    let (_, stats) = render::render(scene, &rec, settings, None);
    (rec.into_queries(), stats.rays)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raw_casting_replays_exactly_the_rays_of_the_render() {
        // A sphereflake without transmitters: every query is a counted ray.
        let scene = crate::job::load_scene("spd:balls?size=1").unwrap();
        let accel = crate::accel::bvh::Bvh::build(&scene);
        let mut s = RenderSettings::for_scene(&scene);
        s.width = 12;
        s.height = 12;
        s.spd = true;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let (queries, counts) = pool.install(|| record(&scene, &accel, &s));
        assert_eq!(queries.len() as u64, counts.total());
        let shadow = queries.iter().filter(|q| q.occluded).count() as u64;
        assert_eq!(shadow, counts.shadow);
        // The eye rays went in one batch per tile, then the shadow rays of each depth
        // and the reflections of each depth as batches, which raw casting replays as
        // batches.
        let batches: Vec<Batch> = queries.iter().filter_map(|q| q.batch).collect();
        assert_eq!(
            batches[0],
            Batch {
                len: 169,
                kind: BatchKind::Coherent
            },
            "13x13 corner rays: one 16x16 tile"
        );
        let in_batches: u32 = batches.iter().map(|b| b.len).sum();
        assert_eq!(in_batches as usize, queries.len(), "every ray in a batch");
        let kinds = |k: BatchKind| batches.iter().filter(|b| b.kind == k).count();
        assert_eq!(kinds(BatchKind::Coherent), 1);
        assert!(kinds(BatchKind::Shadow) >= 2 && kinds(BatchKind::Nearest) >= 1);
        let cast = pool.install(|| cast(&accel, &queries));
        assert_eq!(cast.queries, counts.total());
        // Eye rays that hit, reflection rays that hit and occluded shadow rays, found again
        // one by one.
        let expected = queries
            .iter()
            .filter(|q| {
                if q.occluded {
                    Accel::occluded(&accel, &q.ray)
                } else {
                    Accel::intersect(&accel, &q.ray).is_some()
                }
            })
            .count() as u64;
        assert_eq!(cast.hits, expected);
        assert!(cast.hits >= counts.eye_hit);
    }
}
