//! Groups of neighbouring primitives behind one Embree user primitive.
//!
//! Embree's hierarchy over user geometry costs about 72 bytes per primitive (compact,
//! medium quality), and its build about as much again in references while it runs: at
//! tens of millions of primitives that is most of a render's memory and time to image.
//! A user primitive may stand for several of the scene's, whose callbacks test each in
//! turn with the same exact intersector and the same tie rule, so a group of `g`
//! primitives gives the same hits as its members would one by one while Embree builds
//! over `g` times fewer boxes.
//!
//! The groups must be compact in space, or their boxes would overlap and rays would
//! test primitives far from their path: the primitives are ordered along a Morton curve
//! (the Z-order of their boxes' centres, 21 bits per axis, over the box of all centres),
//! ties by index, and cut into runs of `g`. The order is computed in parallel on the
//! current rayon pool.

use crate::geometry::Analytic;
use crate::math::{Aabb, Vec3};
use rayon::prelude::*;

/// Bits of the Morton code per axis.
const BITS: u32 = 21;

/// The indices of `items` that Embree holds (`ids`, or all of them for `None`) in
/// Morton order of their boxes' centres, ties by index: runs of consecutive entries are
/// then neighbours in space.
pub(super) fn morton_order<P: Analytic>(items: &[P], ids: Option<Box<[u32]>>) -> Box<[u32]> {
    let ids: Vec<u32> = match ids {
        Some(ids) => ids.into_vec(),
        None => (0..items.len()).map(index_u32).collect(),
    };
    let centre = |id: u32| items[id as usize].bounds().centroid();
    let extent = ids
        .par_iter()
        .map(|&id| Aabb::EMPTY.grow(centre(id)))
        .reduce(|| Aabb::EMPTY, |a, b| a.union(&b));
    let grid = Grid::over(&extent);
    // One integer per primitive, its size class, Morton code and index from the high
    // bits down, sorts fastest.
    let mut keyed: Vec<u128> = ids
        .par_iter()
        .map(|&id| {
            let b = items[id as usize].bounds();
            let class = u128::from(size_class(&b));
            class << 96 | u128::from(grid.code(b.centroid())) << 32 | u128::from(id)
        })
        .collect();
    drop(ids);
    keyed.par_sort_unstable();
    keyed.into_par_iter().map(|key| key as u32).collect()
}

/// The binary order of magnitude of a box's largest side (its `f32` exponent), so that
/// a group does not put small primitives in the box of a large one.
fn size_class(b: &Aabb) -> u8 {
    let side = (b.max - b.min).max_element();
    if side.is_finite() && side > 0.0 {
        (side.to_bits() >> 23) as u8
    } else {
        0
    }
}

/// An index of a list Embree holds (whose length `attach_user` has checked against
/// `u32`).
fn index_u32(i: usize) -> u32 {
    u32::try_from(i).unwrap_or(u32::MAX)
}

/// The cells of a `2^BITS`-per-axis grid over a box.
struct Grid {
    min: Vec3,
    /// Cells per unit length, per axis (0 across a flat axis).
    scale: Vec3,
}

impl Grid {
    fn over(extent: &Aabb) -> Grid {
        let cells = ((1u32 << BITS) - 1) as f32;
        let size = extent.max - extent.min;
        let per = |s: f32| {
            if s > 0.0 && s.is_finite() {
                cells / s
            } else {
                0.0
            }
        };
        Grid {
            min: extent.min,
            scale: Vec3::new(per(size.x), per(size.y), per(size.z)),
        }
    }

    /// The Morton code of the cell holding `p` (clamped to the grid; a NaN coordinate
    /// counts as 0).
    fn code(&self, p: Vec3) -> u64 {
        let max = ((1u32 << BITS) - 1) as f32;
        let cell = |v: f32, min: f32, scale: f32| ((v - min) * scale).clamp(0.0, max) as u64;
        spread(cell(p.x, self.min.x, self.scale.x))
            | spread(cell(p.y, self.min.y, self.scale.y)) << 1
            | spread(cell(p.z, self.min.z, self.scale.z)) << 2
    }
}

/// The low 21 bits of `v` moved to every third bit (bit `k` to bit `3k`).
fn spread(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Sphere;

    #[test]
    fn spread_moves_bit_k_to_bit_3k() {
        for k in 0..BITS {
            assert_eq!(spread(1 << k), 1 << (3 * k), "bit {k}");
        }
        assert_eq!(spread(0x1f_ffff), 0x1249_2492_4924_9249);
        assert_eq!(spread(1 << BITS), 0, "bits above 21 are dropped");
    }

    #[test]
    fn the_order_is_a_permutation_with_neighbours_together() {
        // Two clusters of spheres, interleaved in the list: the order puts each
        // cluster's spheres together.
        let items: Vec<Sphere> = (0..64)
            .map(|i| {
                let far = if i % 2 == 0 { 0.0 } else { 100.0 };
                Sphere::new(Vec3::new(far + (i / 2) as f32 * 0.01, 0.0, 0.0), 0.1)
            })
            .collect();
        let order = morton_order(&items, None);
        let mut sorted = order.to_vec();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..64).collect::<Vec<u32>>());
        let side = |id: u32| id % 2;
        let changes = order
            .windows(2)
            .filter(|w| side(w[0]) != side(w[1]))
            .count();
        assert_eq!(changes, 1, "{order:?}");
        // A subset keeps only its ids.
        let some = morton_order(&items, Some(vec![5, 2, 9].into_boxed_slice()));
        assert_eq!(some.len(), 3);
        assert!(some.contains(&5) && some.contains(&2) && some.contains(&9));
    }
}
