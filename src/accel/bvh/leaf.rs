//! The primitives of the leaves, stored in leaf order so that a leaf visit reads them
//! in sequence with no indirection: each leaf's triangles packed four to a
//! [`Triangle4`] (their vertices copied, tested four at a time), then its other
//! primitives (analytic shapes by value, instances by index).

use super::build::MAX_LEAF;
use crate::geometry::{Shape, Triangle, Triangle4};
use crate::math::Aabb;
use rayon::prelude::*;
use smallvec::SmallVec;
use std::ops::Range;

/// Leaves stored by one task (their primitives are copied once more when the tasks'
/// parts are joined).
const LEAVES_PER_TASK: usize = 4096;

/// A primitive of a level as the builder sees it, before it is stored in a leaf.
#[derive(Clone, Debug)]
pub(super) enum Prim {
    /// Triangle `index` of the level's triangle list.
    Triangle(Triangle, u32),
    /// An analytic shape, primitive `u32` of its kind's list.
    Shape(Shape, u32),
    /// An index into the level's instances.
    Instance(u32),
}

/// A non-triangle primitive as a leaf stores it.
#[derive(Clone, Debug)]
pub(super) enum Other {
    /// An analytic shape with its primitive id (its geometry id is its [`Kind`]).
    Shape(Shape, u32),
    /// An index into the level's instances.
    Instance(u32),
}

/// One leaf: its triangle packs and its other primitives, as ranges of [`LeafData`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Leaf {
    packs: (u32, u32),
    others: (u32, u32),
}

impl Leaf {
    /// The leaf's range of [`LeafData::packs`].
    #[inline]
    pub fn packs(&self) -> Range<usize> {
        self.packs.0 as usize..self.packs.1 as usize
    }

    /// The leaf's range of [`LeafData::others`].
    #[inline]
    pub fn others(&self) -> Range<usize> {
        self.others.0 as usize..self.others.1 as usize
    }
}

/// Every leaf's primitives, in leaf order.
#[derive(Clone, Debug, Default)]
pub(super) struct LeafData {
    pub leaves: Vec<Leaf>,
    pub packs: Vec<Triangle4>,
    /// The triangle index of each lane of each pack (a padding lane repeats the last).
    pub pack_ids: Vec<[u32; 4]>,
    pub others: Vec<Other>,
}

impl LeafData {
    /// Store the leaves `ranges` of `order` (each a `(first, count)` run of it, in leaf
    /// order), `order` indexing `prims`. A leaf keeps its primitives' order: triangles
    /// first, four to a pack, then the others. Runs of leaves are stored on the
    /// caller's rayon pool and joined in order.
    pub fn new(ranges: &[(u32, u32)], order: &[usize], prims: &[Prim]) -> LeafData {
        let parts: Vec<LeafData> = ranges
            .par_chunks(LEAVES_PER_TASK)
            .map(|run| {
                let mut part = LeafData::default();
                for &(first, count) in run {
                    let items = order[first as usize..(first + count) as usize]
                        .iter()
                        .map(|&i| &prims[i]);
                    part.push_leaf(items);
                }
                part
            })
            .collect();
        let mut data = LeafData {
            leaves: Vec::with_capacity(ranges.len()),
            packs: Vec::with_capacity(parts.iter().map(|p| p.packs.len()).sum()),
            pack_ids: Vec::with_capacity(parts.iter().map(|p| p.pack_ids.len()).sum()),
            others: Vec::with_capacity(parts.iter().map(|p| p.others.len()).sum()),
        };
        for part in parts {
            data.append(part);
        }
        data
    }

    /// Append the leaves of `part`.
    fn append(&mut self, part: LeafData) {
        let (packs, others) = (self.packs.len() as u32, self.others.len() as u32);
        self.leaves.extend(part.leaves.iter().map(|l| Leaf {
            packs: (l.packs.0 + packs, l.packs.1 + packs),
            others: (l.others.0 + others, l.others.1 + others),
        }));
        self.packs.extend(part.packs);
        self.pack_ids.extend(part.pack_ids);
        self.others.extend(part.others);
    }

    fn push_leaf<'a>(&mut self, items: impl Iterator<Item = &'a Prim>) {
        let (pack_start, other_start) = (self.packs.len(), self.others.len());
        let mut tris: SmallVec<[(Triangle, u32); MAX_LEAF]> = SmallVec::new();
        for item in items {
            match item {
                Prim::Triangle(t, i) => tris.push((*t, *i)),
                Prim::Shape(s, i) => self.others.push(Other::Shape(s.clone(), *i)),
                Prim::Instance(i) => self.others.push(Other::Instance(*i)),
            }
        }
        for chunk in tris.chunks(4) {
            let t: SmallVec<[Triangle; 4]> = chunk.iter().map(|c| c.0).collect();
            self.packs.push(Triangle4::new(&t));
            self.pack_ids
                .push(std::array::from_fn(|i| chunk[i.min(chunk.len() - 1)].1));
        }
        self.leaves.push(Leaf {
            packs: (pack_start as u32, self.packs.len() as u32),
            others: (other_start as u32, self.others.len() as u32),
        });
    }

    /// Bytes of the leaf table and the primitives it holds (heap and inline).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        self.leaves.len() * size_of::<Leaf>()
            + self.packs.len() * (size_of::<Triangle4>() + size_of::<[u32; 4]>())
            + self.others.len() * size_of::<Other>()
    }

    /// Bounds of leaf `leaf`'s primitives, with `instance_bounds` for instances (tests).
    #[cfg(test)]
    pub fn leaf_prim_bounds(&self, leaf: usize, instance_bounds: &[Aabb]) -> Vec<Aabb> {
        use crate::geometry::Intersect;
        let l = self.leaves[leaf];
        let mut out: Vec<Aabb> = Vec::new();
        for p in l.packs() {
            for lane in 0..4 {
                out.push(self.packs[p].triangle(lane).bounds());
            }
        }
        for o in &self.others[l.others()] {
            out.push(match o {
                Other::Shape(s, _) => s.bounds(),
                Other::Instance(i) => instance_bounds[*i as usize],
            });
        }
        out
    }
}

impl Prim {
    /// Bounds, with `instance_bounds` for instances.
    pub fn bounds(&self, instance_bounds: &[Aabb]) -> Aabb {
        use crate::geometry::Intersect;
        match self {
            Prim::Triangle(t, _) => t.bounds(),
            Prim::Shape(s, _) => s.bounds(),
            Prim::Instance(i) => instance_bounds[*i as usize],
        }
    }
}
