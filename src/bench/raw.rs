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
    /// `true` for [`Accel::occluded`], `false` for [`Accel::intersect`].
    pub occluded: bool,
    /// Set on the first query of a batch of `len` nearest-hit queries the renderer cast
    /// together through [`Accel::intersect_coherent`] (the batch's other queries follow
    /// it; the backend casts them in its own packet width); `None` for everything else.
    pub batch: Option<Batch>,
}

/// A batch of coherent rays (see [`Query::batch`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Batch {
    /// Queries in the batch, this one included.
    pub len: u32,
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
        let batch = Batch {
            len: u32::try_from(rays.len()).unwrap_or(u32::MAX),
        };
        self.push(rays.iter().enumerate().map(|(i, ray)| Query {
            ray: *ray,
            occluded: false,
            batch: (i == 0).then_some(batch),
        }));
        self.inner.intersect_coherent(rays, hits);
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
            let (mut rays, mut found) = (Vec::new(), Vec::new());
            let mut n = 0u64;
            let mut k = 0;
            while k < chunk.len() {
                let q = &chunk[k];
                if let Some(b) = q.batch {
                    let len = (b.len as usize).clamp(1, chunk.len() - k);
                    rays.clear();
                    rays.extend(chunk[k..k + len].iter().map(|q| q.ray));
                    found.clear();
                    found.resize(len, None);
                    accel.intersect_coherent(&rays, &mut found);
                    n += found.iter().filter(|h| h.is_some()).count() as u64;
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
        // The eye rays went in batches, one per tile, which raw casting replays as batches.
        let batches: Vec<Batch> = queries.iter().filter_map(|q| q.batch).collect();
        assert_eq!(batches.len(), 1, "13x13 corner rays: one 16x16 tile");
        assert_eq!(batches[0], Batch { len: 169 });
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
