//! The wavefront: a batch of eye rays (a tile's samples) traced depth by depth. Each
//! depth is a queue of path states cast together ([`Accel::intersect_coherent`] for
//! the eye rays, [`Accel::intersect_batch`] after); the hits are shaded kind by kind,
//! each at once into its node of the batch's tree; the point lights' shadow rays of the
//! whole depth are cast together as one any-hit batch, and the reflection and
//! refraction rays go to the next depth's queue. When the queues are empty, the tree
//! gives every ray's radiance bottom-up ([`Tree::resolve`]): the same sums, in the same
//! order, as a recursive tracer returns, so the pixels are the same bit for bit.

use super::local::LightQueue;
use super::media::MAX_SKIPS;
use super::path::{Node, PathState, Tree};
use super::record::{Met, RayKind, Recorder, Traced};
use super::shade::{Arrival, Child};
use super::whitted::Tracer;
use crate::accel::{Accel, Hit};
use crate::geometry::Kind;
use crate::math::{Ray, Vec3, offset_ray_origin};
use std::cell::Cell;

/// An eye ray of a batch.
#[derive(Clone, Copy, Debug)]
pub(super) struct Eye {
    /// The ray.
    pub ray: Ray,
    /// The index of its sample-grid position in the batch's positions.
    pub slot: u32,
    /// The identity of its path through the ray tree.
    pub path: u32,
}

/// The depth of the wavefront being shaded: the batch's tree, the next depth's
/// queue, and the point lights' shadow rays waiting to be cast.
pub(super) struct Depth<'p> {
    pub tree: Tree,
    pub next: Vec<PathState>,
    pub lights: LightQueue,
    /// The batch's sample-grid positions, by slot.
    positions: &'p [(u32, u32)],
}

impl Depth<'_> {
    /// Spawn `child` at the hit of `parent` into the next depth's queue; its node.
    #[inline]
    pub fn spawn<R: Recorder>(&mut self, parent: &PathState, child: Child, rec: &mut R) -> u32 {
        let node = self.tree.push();
        let position = self.positions[parent.slot as usize];
        rec.ray(&Traced::child(parent, &child, node, position));
        self.next.push(PathState {
            ray: child.ray,
            node,
            slot: parent.slot,
            depth: parent.depth + 1,
            path: child.path,
            media: child.media,
            weight: parent.weight * child.local_weight,
            skips: 0,
        });
        node
    }
}

/// The buffers of a batch, kept by each thread from one batch to the next so that a
/// tile allocates nothing once the first has grown them.
#[derive(Debug, Default)]
struct Buffers {
    tree: Vec<Node>,
    queue: Vec<PathState>,
    next: Vec<PathState>,
    again: Vec<PathState>,
    rays: Vec<Ray>,
    hits: Vec<Option<Hit>>,
    /// The order the hits are shaded in.
    order: Vec<u32>,
    lights: LightQueue,
}

thread_local! {
    static BUFFERS: Cell<Buffers> = Cell::new(Buffers::default());
}

/// The indices of `hits` grouped by what was hit (the misses first, then kind by
/// kind in [`Kind`] order, each group in cast order) into `order`, so that each
/// kind's surface and shading code runs over a run of hits. The order in which hits
/// are shaded changes no value: each writes its own node.
fn by_kind(hits: &[Option<Hit>], order: &mut Vec<u32>) {
    const GROUPS: usize = Kind::ALL.len() + 1;
    let group = |h: &Option<Hit>| h.map_or(0, |h| (h.geom_id as usize + 1).min(GROUPS - 1));
    let mut start = [0u32; GROUPS + 1];
    for h in hits {
        start[group(h) + 1] += 1;
    }
    for g in 0..GROUPS {
        start[g + 1] += start[g];
    }
    order.clear();
    order.resize(hits.len(), 0);
    for (i, h) in hits.iter().enumerate() {
        let at = &mut start[group(h)];
        order[*at as usize] = i as u32;
        *at += 1;
    }
}

impl<A: Accel> Tracer<'_, A> {
    /// The radiance of each of `eyes` into `values` (for the sample-grid positions
    /// `positions`, indexed by their slots), the eye rays cast as packets when
    /// `coherent`.
    pub(super) fn trace_batch<R: Recorder>(
        &self,
        eyes: &[Eye],
        positions: &[(u32, u32)],
        coherent: bool,
        rec: &mut R,
        values: &mut Vec<Vec3>,
    ) {
        rec.batch();
        // Taken, not borrowed: a batch started inside this one would get its own.
        let mut b = BUFFERS.with(Cell::take);
        b.tree.clear();
        let mut depth = Depth {
            tree: Tree {
                nodes: std::mem::take(&mut b.tree),
            },
            next: std::mem::take(&mut b.next),
            lights: std::mem::take(&mut b.lights),
            positions,
        };
        let mut queue = std::mem::take(&mut b.queue);
        queue.clear();
        queue.extend(eyes.iter().map(|e| self.eye(e, &mut depth, rec)));
        let mut coherent = coherent;
        while !queue.is_empty() {
            self.cast_depth(&mut queue, coherent, &mut depth, &mut b, rec);
            coherent = false;
            self.finish_lights(&mut depth.lights, &mut depth.tree, rec);
            std::mem::swap(&mut queue, &mut depth.next);
        }
        depth.tree.resolve(rec, values);
        values.truncate(eyes.len());
        b.tree = depth.tree.nodes;
        b.next = depth.next;
        b.lights = depth.lights;
        b.queue = queue;
        BUFFERS.with(|cell| cell.set(b));
    }

    /// The path state of eye ray `e`, as node `tree.len()`.
    fn eye<R: Recorder>(&self, e: &Eye, depth: &mut Depth, rec: &mut R) -> PathState {
        let node = depth.tree.push();
        rec.counts().eye += 1;
        rec.ray(&Traced {
            node,
            parent: None,
            position: depth.positions[e.slot as usize],
            kind: RayKind::Eye,
            depth: 1,
            ray: &e.ray,
            local_weight: Vec3::ONE,
            weight: Vec3::ONE,
            discarded: false,
        });
        PathState {
            ray: e.ray,
            node,
            slot: e.slot,
            depth: 1,
            path: e.path,
            media: super::media::Media::AIR,
            weight: Vec3::ONE,
            skips: 0,
        }
    }

    /// Cast the rays of one depth (`round`, emptied) and shade their hits; the rays
    /// that pass through a surface that is not optically there are cast again, until
    /// none is left.
    fn cast_depth<R: Recorder>(
        &self,
        round: &mut Vec<PathState>,
        coherent: bool,
        depth: &mut Depth,
        b: &mut Buffers,
        rec: &mut R,
    ) {
        let mut coherent = coherent;
        while !round.is_empty() {
            self.cast(round, coherent, b, rec);
            b.again.clear();
            by_kind(&b.hits, &mut b.order);
            for &i in &b.order {
                let i = i as usize;
                self.arrive(&round[i], b.hits[i], depth, &mut b.again, rec);
            }
            std::mem::swap(round, &mut b.again);
            coherent = false;
        }
    }

    /// The nearest hits of `round`'s rays into `b.hits`.
    fn cast<R: Recorder>(&self, round: &[PathState], coherent: bool, b: &mut Buffers, rec: &mut R) {
        b.rays.clear();
        b.rays.extend(round.iter().map(|s| s.ray));
        b.hits.clear();
        b.hits.resize(round.len(), None);
        let nodes: Vec<u32> = if R::ACTIVE {
            round.iter().map(|s| s.node).collect()
        } else {
            Vec::new()
        };
        rec.cast(true, &nodes);
        if coherent {
            self.accel.intersect_coherent(&b.rays, &mut b.hits);
        } else {
            self.accel.intersect_batch(&b.rays, &mut b.hits);
        }
        rec.cast(false, &nodes);
    }

    /// Ray `s` met `first`: the background, a surface it goes on through (queued
    /// `again`), or a surface it is shaded at.
    fn arrive<R: Recorder>(
        &self,
        s: &PathState,
        first: Option<Hit>,
        depth: &mut Depth,
        again: &mut Vec<PathState>,
        rec: &mut R,
    ) {
        let scene = self.scene;
        let Some(hit) = first else {
            let sky = scene.escape(s.ray.dir);
            rec.miss(s.node, sky);
            let node = depth.tree.node(s.node);
            node.local = sky;
            node.missed = true;
            return;
        };
        let surf = scene.surface_of(&hit, &s.ray, self.accel.exact_triangle_hits());
        let m = &scene.materials[surf.material as usize];
        let d = s.ray.dir.normalize();
        let entering = surf.point.ng.dot(d) < 0.0;
        let met = Met {
            hit: &hit,
            surf: &surf,
            entering,
            media: &s.media,
        };
        // Surfaces of lower-priority media inside a higher-priority one are skipped
        // (nested dielectrics): the ray goes on through them, at most MAX_SKIPS times.
        if m.t > 0.0
            && s.skips < MAX_SKIPS
            && s.media.is_false_boundary(scene, surf.material, entering)
        {
            rec.pass_through(s.node, &met);
            let (media, ng) = if entering {
                (s.media.enter(surf.material), -surf.point.ng)
            } else {
                (s.media.leave(surf.material), surf.point.ng)
            };
            let ray = Ray::new(
                offset_ray_origin(surf.point.p, surf.point.err, ng, d),
                s.ray.dir,
            );
            again.push(PathState {
                ray,
                media,
                skips: s.skips + 1,
                ..*s
            });
            return;
        }
        rec.hit(s.node, &met);
        if s.depth == 1 {
            rec.counts().eye_hit += 1;
        }
        let gi = self.gi.and_then(|g| g.radiosity_at(&hit, surf.point.p, d));
        let at = Arrival {
            state: s,
            surf: &surf,
            d,
            entering,
            gi,
        };
        self.shade(&at, depth, rec);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(kind: Kind) -> Option<Hit> {
        Some(Hit {
            t: 1.0,
            geom_id: kind as u32,
            prim_id: 0,
            u: 0.0,
            v: 0.0,
            ng: Vec3::Z,
            inst_id: crate::accel::NO_INSTANCE,
        })
    }

    #[test]
    fn hits_are_shaded_misses_first_then_kind_by_kind_in_cast_order() {
        let (s, t) = (hit(Kind::Sphere), hit(Kind::Triangle));
        let hits = [s, None, t, s, t, None, s];
        let mut order = Vec::new();
        by_kind(&hits, &mut order);
        assert_eq!(order, [1, 5, 2, 4, 0, 3, 6]);
        by_kind(&[], &mut order);
        assert!(order.is_empty());
    }
}
