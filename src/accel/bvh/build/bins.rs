//! What the SAH reads of a range of primitives: its bounds and its centroids' bounds
//! (`Summary`), and its bins along the three axes at once (`Bins`), both computed over
//! any part of the range and merged, so that the parts of a long range can be done on
//! several threads. Merging is a box union (exact) and an integer sum.

use super::{BINS, Count};
use crate::math::Aabb;
use glam::Vec3;

/// The bounds of a range's primitives and of their centroids.
#[derive(Clone, Copy, Debug)]
pub(super) struct Summary {
    pub bounds: Aabb,
    pub cbounds: Aabb,
}

impl Summary {
    pub const EMPTY: Summary = Summary {
        bounds: Aabb::EMPTY,
        cbounds: Aabb::EMPTY,
    };

    /// Add primitives `order`.
    pub fn add(&mut self, order: &[u32], bounds: &[Aabb], centroids: &[Vec3]) {
        for &i in order {
            self.bounds = self.bounds.union(&bounds[i as usize]);
            self.cbounds = self.cbounds.grow(centroids[i as usize]);
        }
    }

    /// Add the summary of another part of the range.
    pub fn merge(&mut self, o: &Summary) {
        self.bounds = self.bounds.union(&o.bounds);
        self.cbounds = self.cbounds.union(&o.cbounds);
    }
}

/// Which bin a centroid falls in along each axis: [`BINS`] equal slices of the
/// centroids' bounds; an axis along which they do not spread is not binned.
#[derive(Clone, Copy, Debug)]
pub(super) struct Binning {
    min: Vec3,
    /// Bins per unit length, per axis (the bins' span shrunk by a millionth so that
    /// the largest centroid stays in the last bin).
    k: [f32; 3],
    /// Axes along which the centroids spread.
    binned: [bool; 3],
}

impl Binning {
    /// The binning of centroids bounded by `cbounds`.
    pub fn new(cbounds: &Aabb) -> Binning {
        let ext = cbounds.extent();
        Binning {
            min: cbounds.min,
            k: std::array::from_fn(|a| BINS as f32 * (1.0 - 1e-6) / ext[a]),
            binned: std::array::from_fn(|a| ext[a] > 0.0),
        }
    }

    /// The bin of centroid `c` along `axis`.
    #[inline]
    pub fn bin(&self, c: Vec3, axis: usize) -> usize {
        (((c[axis] - self.min[axis]) * self.k[axis]) as usize).min(BINS - 1)
    }

    /// Add primitives `order` to `bins` along every binned axis.
    pub fn add(
        &self,
        bins: &mut Bins,
        order: &[u32],
        bounds: &[Aabb],
        triangle: &[bool],
        centroids: &[Vec3],
    ) {
        for &i in order {
            let (c, b) = (centroids[i as usize], &bounds[i as usize]);
            let count = Count::of(triangle[i as usize]);
            for axis in 0..3 {
                if !self.binned[axis] {
                    continue;
                }
                let k = self.bin(c, axis);
                bins.counts[axis][k] = bins.counts[axis][k].add(count);
                bins.boxes[axis][k] = bins.boxes[axis][k].union(b);
            }
        }
    }
}

/// Primitive counts and bounds per bin, per axis (empty along an axis not binned).
#[derive(Clone, Copy, Debug)]
pub(super) struct Bins {
    counts: [[Count; BINS]; 3],
    boxes: [[Aabb; BINS]; 3],
}

impl Bins {
    pub const EMPTY: Bins = Bins {
        counts: [[Count { tris: 0, others: 0 }; BINS]; 3],
        boxes: [[Aabb::EMPTY; BINS]; 3],
    };

    /// Add the bins of another part of the range.
    pub fn merge(&mut self, o: &Bins) {
        for axis in 0..3 {
            for k in 0..BINS {
                self.counts[axis][k] = self.counts[axis][k].add(o.counts[axis][k]);
                self.boxes[axis][k] = self.boxes[axis][k].union(&o.boxes[axis][k]);
            }
        }
    }

    /// The split with the lowest cost among the `BINS - 1` planes between bins of
    /// each binned axis: `(cost, axis, first bin of the second side)`, the first
    /// lowest in axis then plane order; an infinite cost when no plane leaves
    /// primitives on both sides. The cost is unnormalised: the sides' areas times
    /// their primitive tests.
    ///
    /// Only the planes just after an occupied bin are costed: the planes up to the next
    /// occupied bin split the primitives the same way, at the same cost, and the first
    /// of them is the one a strict `<` keeps. (Empty bins add nothing to a union or a
    /// count, so skipping them changes no cost by a bit.)
    pub fn best_split(&self, binning: &Binning) -> (f32, usize, usize) {
        let mut best = (f32::INFINITY, 0usize, 0usize);
        for axis in (0..3).filter(|&a| binning.binned[a]) {
            let mut occupied = [0usize; BINS];
            let mut len = 0;
            for b in 0..BINS {
                if !self.counts[axis][b].is_empty() {
                    occupied[len] = b;
                    len += 1;
                }
            }
            self.best_plane(axis, &occupied[..len], &mut best);
        }
        best
    }

    /// Lower `best` to the lowest cost along `axis`, the sides being split between
    /// consecutive `occupied` bins.
    fn best_plane(&self, axis: usize, occupied: &[usize], best: &mut (f32, usize, usize)) {
        let (counts, boxes) = (&self.counts[axis], &self.boxes[axis]);
        // The second side's area and count when it starts at occupied[j].
        let mut right = [(0.0f32, Count::default()); BINS];
        let (mut acc, mut cnt) = (Aabb::EMPTY, Count::default());
        for (j, &b) in occupied.iter().enumerate().skip(1).rev() {
            acc = acc.union(&boxes[b]);
            cnt = cnt.add(counts[b]);
            right[j] = (acc.surface_area(), cnt);
        }
        let (mut acc, mut cnt) = (Aabb::EMPTY, Count::default());
        for (j, &b) in occupied
            .iter()
            .enumerate()
            .take(occupied.len().saturating_sub(1))
        {
            acc = acc.union(&boxes[b]);
            cnt = cnt.add(counts[b]);
            let (right_area, right_count) = right[j + 1];
            let cost = acc.surface_area() * cnt.tests() + right_area * right_count.tests();
            if cost < best.0 {
                *best = (cost, axis, b + 1);
            }
        }
    }
}
