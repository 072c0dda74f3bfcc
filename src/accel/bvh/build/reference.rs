//! The sequential builder the parallel one replaced, kept as the reference it must
//! reproduce node for node and primitive for primitive.

use super::{BINS, Count, MAX_LEAF, SAH_DEPTH, TRAVERSAL_COST};
use crate::accel::bvh::{MAX_DEPTH, Node};
use crate::math::Aabb;

struct Builder<'a> {
    bounds: &'a [Aabb],
    /// Whether each primitive is a triangle.
    triangle: &'a [bool],
    centroids: Vec<glam::Vec3>,
    order: Vec<u32>,
    nodes: Vec<Node>,
}

/// Build nodes over primitive `bounds` (`triangle[i]` when primitive `i` is a
/// triangle); returns the nodes and the primitive order the leaves refer to.
pub fn build(bounds: &[Aabb], triangle: &[bool]) -> (Vec<Node>, Vec<u32>) {
    let mut b = Builder {
        bounds,
        triangle,
        centroids: bounds.iter().map(|b| b.centroid()).collect(),
        order: (0..bounds.len() as u32).collect(),
        nodes: Vec::with_capacity(2 * bounds.len().max(1)),
    };
    if !bounds.is_empty() {
        b.node(0, bounds.len(), 0);
    }
    (b.nodes, b.order)
}

impl Builder<'_> {
    fn range_bounds(&self, start: usize, end: usize) -> (Aabb, Aabb) {
        let mut bb = Aabb::EMPTY;
        let mut cb = Aabb::EMPTY;
        for &i in &self.order[start..end] {
            bb = bb.union(&self.bounds[i as usize]);
            cb = cb.grow(self.centroids[i as usize]);
        }
        (bb, cb)
    }

    fn leaf(&mut self, at: usize, bounds: Aabb, start: usize, end: usize) {
        self.nodes[at] = Node {
            bounds,
            offset: start as u32,
            count: (end - start) as u16,
            axis: 0,
        };
    }

    /// Build the subtree over `order[start..end]`; returns its node index.
    fn node(&mut self, start: usize, end: usize, depth: usize) -> usize {
        let at = self.nodes.len();
        self.nodes.push(Node {
            bounds: Aabb::EMPTY,
            offset: 0,
            count: 0,
            axis: 0,
        });
        let (bounds, cbounds) = self.range_bounds(start, end);
        let n = end - start;
        let ext = cbounds.extent();
        if n == 1 || ext.max_element() <= 0.0 || depth >= SAH_DEPTH {
            return self.split_or_leaf_forced(at, bounds, start, end, depth);
        }
        // Evaluate BINS-1 candidate planes on each axis.
        let mut best = (f32::INFINITY, 0usize, 0usize);
        for axis in 0..3 {
            if ext[axis] <= 0.0 {
                continue;
            }
            let mut counts = [Count::default(); BINS];
            let mut boxes = [Aabb::EMPTY; BINS];
            let k = BINS as f32 * (1.0 - 1e-6) / ext[axis];
            for &i in &self.order[start..end] {
                let c = self.centroids[i as usize][axis];
                let b = (((c - cbounds.min[axis]) * k) as usize).min(BINS - 1);
                counts[b] = counts[b].add(Count::of(self.triangle[i as usize]));
                boxes[b] = boxes[b].union(&self.bounds[i as usize]);
            }
            let mut right_area = [0.0f32; BINS];
            let mut right_count = [Count::default(); BINS];
            let (mut acc, mut cnt) = (Aabb::EMPTY, Count::default());
            for b in (1..BINS).rev() {
                acc = acc.union(&boxes[b]);
                cnt = cnt.add(counts[b]);
                right_area[b] = acc.surface_area();
                right_count[b] = cnt;
            }
            let (mut acc, mut cnt) = (Aabb::EMPTY, Count::default());
            for b in 0..BINS - 1 {
                acc = acc.union(&boxes[b]);
                cnt = cnt.add(counts[b]);
                if cnt.is_empty() || right_count[b + 1].is_empty() {
                    continue;
                }
                let cost = acc.surface_area() * cnt.tests()
                    + right_area[b + 1] * right_count[b + 1].tests();
                if cost < best.0 {
                    best = (cost, axis, b + 1);
                }
            }
        }
        let area = bounds.surface_area().max(f32::MIN_POSITIVE);
        let split_cost = TRAVERSAL_COST + best.0 / area;
        let leaf_cost = self.order[start..end]
            .iter()
            .fold(Count::default(), |c, &i| {
                c.add(Count::of(self.triangle[i as usize]))
            })
            .tests();
        if best.0.is_infinite() || (n <= MAX_LEAF && split_cost >= leaf_cost) {
            return self.split_or_leaf_forced(at, bounds, start, end, depth);
        }
        let (axis, split_bin) = (best.1, best.2);
        let k = BINS as f32 * (1.0 - 1e-6) / ext[axis];
        let min = cbounds.min[axis];
        let centroids = &self.centroids;
        let mid = start
            + partition(&mut self.order[start..end], |&i| {
                let b = (((centroids[i as usize][axis] - min) * k) as usize).min(BINS - 1);
                b < split_bin
            });
        self.interior(at, bounds, axis, start, mid, end, depth)
    }

    /// A leaf when it fits, else a median split along the longest axis (for ranges whose
    /// centroids coincide or that are deeper than [`SAH_DEPTH`]).
    fn split_or_leaf_forced(
        &mut self,
        at: usize,
        bounds: Aabb,
        start: usize,
        end: usize,
        depth: usize,
    ) -> usize {
        let n = end - start;
        if n <= MAX_LEAF || (depth + 2 >= MAX_DEPTH && n <= u16::MAX as usize) {
            self.leaf(at, bounds, start, end);
            return at;
        }
        let mid = (start + end) / 2;
        let axis = bounds.longest_axis();
        let centroids = &self.centroids;
        self.order[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
        });
        self.interior(at, bounds, axis, start, mid, end, depth)
    }

    #[allow(clippy::too_many_arguments)]
    fn interior(
        &mut self,
        at: usize,
        bounds: Aabb,
        axis: usize,
        start: usize,
        mid: usize,
        end: usize,
        depth: usize,
    ) -> usize {
        self.node(start, mid, depth + 1);
        let right = self.node(mid, end, depth + 1);
        self.nodes[at] = Node {
            bounds,
            offset: right as u32,
            count: 0,
            axis: axis as u16,
        };
        at
    }
}

/// In-place partition; returns the number of elements for which `pred` holds (they
/// come first).
fn partition<T>(v: &mut [T], pred: impl Fn(&T) -> bool) -> usize {
    let mut i = 0;
    for j in 0..v.len() {
        if pred(&v[j]) {
            v.swap(i, j);
            i += 1;
        }
    }
    i
}
