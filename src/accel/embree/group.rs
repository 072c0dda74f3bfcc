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
//! within classes of size, ties by index, and cut into runs of at most `g`
//! ([`cut_runs`]). A run ends early where the curve jumps: where adding the next
//! primitive would make the run's box larger in area than [`SPREAD`] times its members'
//! boxes together (a ray that reaches the group's box tests every member, so a box
//! much larger than its members' makes rays test primitives they pass far from). The
//! order and the cuts are computed in parallel on the current rayon pool.

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

/// How much larger a group's box may be, in surface area, than its members' boxes
/// together. Primitives that touch or nearly touch always group (four equal spheres in
/// a row make a box of 0.75 times their boxes' area); the sparse SPD sphereflake,
/// whose neighbours of one size lie a few radii apart, groups 3.0 spheres per Embree
/// primitive at 6 (balls size 7, groups of at most 4). Measured there, 512² `--spd`,
/// 2 threads, against one sphere per primitive (render 270 ms, peak 736 MB) and runs
/// of exactly 4 (816 ms, 421 MB): 3 → 352 ms and 599 MB, 4 → 378 ms and 558 MB,
/// 6 → 395–430 ms and 481–533 MB, 8 → 459 ms and 470 MB, 12 → 489 ms and 487 MB.
pub(super) const SPREAD: f32 = 6.0;

/// Entries of the order cut on their own threads (a cut is forced between two).
const CUT_CHUNK: usize = 1 << 16;

/// Cut `items` (in Morton order) into runs of at most `max` neighbours (see the module
/// documentation): the index where each run starts, then `items.len()`.
pub(super) fn cut_runs<P: Analytic>(items: &[P], max: usize) -> Box<[u32]> {
    let max = max.max(1);
    let chunks: Vec<Vec<u32>> = items
        .par_chunks(CUT_CHUNK)
        .enumerate()
        .map(|(k, chunk)| {
            let base = k * CUT_CHUNK;
            let starts = runs_of(chunk.len(), |i| chunk.get(i).map(|p| p.bounds()), max);
            starts.into_iter().map(|i| index_u32(base + i)).collect()
        })
        .collect();
    let mut starts: Vec<u32> = chunks.into_iter().flatten().collect();
    starts.push(index_u32(items.len()));
    starts.into_boxed_slice()
}

/// Where each run of at most `max` starts among `n` boxes (`bounds(i)`, `None` for
/// an unknown item, which gets a run of its own), cut greedily in order.
fn runs_of(n: usize, bounds: impl Fn(usize) -> Option<Aabb>, max: usize) -> Vec<usize> {
    let mut starts = Vec::with_capacity(n / max + 1);
    let mut run: Option<(Aabb, f32, u8, usize)> = None;
    for i in 0..n {
        let next = bounds(i);
        let joined = match (&run, &next) {
            (Some((union, areas, class, len)), Some(b))
                if *len < max && size_class(b) == *class =>
            {
                let union = union.union(b);
                let areas = areas + b.surface_area();
                (union.surface_area() <= SPREAD * areas).then_some((union, areas, *class, len + 1))
            }
            _ => None,
        };
        run = match (joined, next) {
            (Some(grown), _) => Some(grown),
            (None, b) => {
                starts.push(i);
                b.map(|b| (b, b.surface_area(), size_class(&b), 1))
            }
        };
    }
    starts
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

    /// Starts of the runs of `spheres` (in the order given), at most `max` each.
    fn runs(spheres: &[Sphere], max: usize) -> Vec<u32> {
        cut_runs(spheres, max).to_vec()
    }

    #[test]
    fn touching_primitives_group_up_to_the_limit() {
        let row: Vec<Sphere> = (0..10)
            .map(|i| Sphere::new(Vec3::new(2.0 * i as f32, 0.0, 0.0), 1.0))
            .collect();
        assert_eq!(runs(&row, 4), [0, 4, 8, 10]);
        assert_eq!(runs(&row, 1), (0..=10).collect::<Vec<u32>>());
        assert_eq!(runs(&row[..3], 8), [0, 3]);
        assert_eq!(runs(&[], 4), [0]);
    }

    #[test]
    fn a_run_ends_where_the_curve_jumps_or_the_size_changes() {
        let at = |x: f32, r: f32| Sphere::new(Vec3::new(x, 0.0, 0.0), r);
        // Two pairs of touching spheres 100 radii apart: two runs, not one.
        let pairs = [at(0.0, 1.0), at(2.0, 1.0), at(100.0, 1.0), at(102.0, 1.0)];
        assert_eq!(runs(&pairs, 4), [0, 2, 4]);
        // A small sphere beside large ones starts a run of its own size.
        let sizes = [at(0.0, 1.0), at(2.0, 1.0), at(3.1, 0.1), at(3.3, 0.1)];
        assert_eq!(runs(&sizes, 4), [0, 2, 4]);
        // Three radii apart, centre to centre, still a group; a hundred, not.
        assert_eq!(runs(&[at(0.0, 1.0), at(3.0, 1.0)], 4), [0, 2]);
        assert_eq!(runs(&[at(0.0, 1.0), at(100.0, 1.0)], 4), [0, 1, 2]);
    }

    #[test]
    fn runs_cover_every_item_in_order_across_the_threads_chunks() {
        let n = CUT_CHUNK * 2 + 3;
        let spheres: Vec<Sphere> = (0..n)
            .map(|i| Sphere::new(Vec3::new(2.0 * i as f32, 0.0, 0.0), 1.0))
            .collect();
        let starts = runs(&spheres, 3);
        assert_eq!(starts.first(), Some(&0));
        assert_eq!(starts.last(), Some(&(n as u32)));
        assert!(starts.windows(2).all(|w| w[0] < w[1] && w[1] - w[0] <= 3));
        // Each chunk of the threads starts a run.
        assert!(starts.contains(&(CUT_CHUNK as u32)));
        assert!(starts.contains(&(2 * CUT_CHUNK as u32)));
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
