//! Top-down binned SAH construction (Wald 2007): centroids binned along each axis, the
//! split with the lowest surface-area cost taken, a leaf made when no split beats
//! intersecting everything.
//!
//! The costs count what a leaf visit does: triangles are tested four at a time (see
//! `leaf`), so `t` triangles cost `⌈t/4⌉` tests, and every other primitive one test.
//!
//! The build runs on the caller's rayon pool and gives the same tree whatever its
//! thread count, node for node and primitive for primitive, the tree the sequential
//! builder gave (`reference`, which the tests compare it with): long ranges are
//! summarised and binned in chunks of a fixed size, merged in chunk order, and the two
//! subtrees of a large node are built beside each other, each into its own nodes,
//! spliced afterwards in the order a sequential build lays them out. Partitions stay
//! sequential: the in-place swap partition's order is what the tree's leaves keep.
//!
//! - `bins`: a range's bounds and its bins, chunked over threads, and the SAH sweep;
//! - `tree`: the nodes of subtrees built apart and their splice into one array;
//! - `reference` (tests): the sequential builder.

mod bins;
#[cfg(test)]
mod reference;
mod tree;

use super::{MAX_DEPTH, Node};
use crate::math::Aabb;
use bins::{Binning, Bins, Summary};
use rayon::prelude::*;
use tree::{Slot, Tree};

/// Bins per axis.
pub const BINS: usize = 16;
/// Largest leaf the builder makes while a split still helps.
pub const MAX_LEAF: usize = 8;
/// Below this depth, median splits take over from SAH so that pathological
/// distributions (SAH peeling one primitive at a time) still give a shallow tree:
/// 40 + log2(n / MAX_LEAF) < [`MAX_DEPTH`] for any n < 2^24.
const SAH_DEPTH: usize = 40;
/// Cost of a binary node step relative to one primitive test (a sphere, a cone, a
/// pack of four triangles): a 4-wide node test, which stands for about two binary
/// levels, costs about half as many instructions as one primitive test, so a binary
/// step about a quarter (measured with callgrind on the SPD scenes, 2026-11-26:
/// 0.15 to 0.35 give the same counts within 1%, 1.0 cost 3–7% more).
const TRAVERSAL_COST: f32 = 0.25;

/// Primitives of a range, by how a leaf tests them: the unit of the SAH costs.
#[derive(Clone, Copy, Debug, Default)]
struct Count {
    /// Triangles, tested four at a time.
    tris: u32,
    /// Other primitives, tested one at a time.
    others: u32,
}

impl Count {
    fn of(triangle: bool) -> Count {
        if triangle {
            Count { tris: 1, others: 0 }
        } else {
            Count { tris: 0, others: 1 }
        }
    }

    fn add(self, o: Count) -> Count {
        Count {
            tris: self.tris + o.tris,
            others: self.others + o.others,
        }
    }

    fn is_empty(self) -> bool {
        self.tris + self.others == 0
    }

    /// Primitive tests a leaf of these costs.
    fn tests(self) -> f32 {
        (self.tris.div_ceil(4) + self.others) as f32
    }
}

/// How the build shares its work between threads. The tree does not depend on it but
/// through `chunk` (the order in which chunks' boxes are merged, which only a box
/// bound of `-0.0` against `0.0` could tell apart), and never on the thread count.
#[derive(Clone, Copy, Debug)]
struct Grain {
    /// Ranges at least this long are summarised and binned in parallel chunks.
    par_range: usize,
    /// Primitives per chunk.
    chunk: usize,
    /// Nodes over at least this many primitives build their two subtrees beside each
    /// other.
    par_subtree: usize,
}

impl Grain {
    /// A chunk's binning takes some 100 µs; a subtree task builds about 100 nodes.
    const DEFAULT: Grain = Grain {
        par_range: 64 * 1024,
        chunk: 16 * 1024,
        par_subtree: 1024,
    };
}

/// What the recursion reads: the primitives' bounds, kinds and centroids.
struct Builder<'a> {
    bounds: &'a [Aabb],
    /// Whether each primitive is a triangle.
    triangle: &'a [bool],
    centroids: Vec<glam::Vec3>,
    grain: Grain,
}

/// Build nodes over primitive `bounds` (`triangle[i]` when primitive `i` is a
/// triangle); returns the nodes and the primitive order the leaves refer to.
pub fn build(bounds: &[Aabb], triangle: &[bool]) -> (Vec<Node>, Vec<u32>) {
    build_with(bounds, triangle, Grain::DEFAULT)
}

fn build_with(bounds: &[Aabb], triangle: &[bool], grain: Grain) -> (Vec<Node>, Vec<u32>) {
    let b = Builder {
        bounds,
        triangle,
        centroids: bounds.par_iter().map(Aabb::centroid).collect(),
        grain,
    };
    let mut order: Vec<u32> = (0..bounds.len() as u32).collect();
    let mut tree = Tree::default();
    if !bounds.is_empty() {
        b.subtree(&mut order, 0, 0, &mut tree);
    }
    (tree.flatten(), order)
}

impl Builder<'_> {
    /// Build the subtree over `order`, which is `first..` of the whole order, into
    /// `tree`.
    fn subtree(&self, order: &mut [u32], first: usize, depth: usize, tree: &mut Tree) {
        let at = tree.push(Node::PENDING);
        let s = self.summary(order);
        let n = order.len();
        let split = if n == 1 || s.cbounds.extent().max_element() <= 0.0 || depth >= SAH_DEPTH {
            None
        } else {
            self.sah_split(order, &s)
        };
        match split {
            Some((binning, axis, split_bin)) => {
                let centroids = &self.centroids;
                let mid = partition(order, |&i| {
                    binning.bin(centroids[i as usize], axis) < split_bin
                });
                self.interior(at, s.bounds, axis, (order, mid, first), depth, tree);
            }
            None => self.split_or_leaf_forced(at, s.bounds, order, first, depth, tree),
        }
    }

    /// The bounds of `order`'s primitives and of their centroids.
    fn summary(&self, order: &[u32]) -> Summary {
        self.chunked(
            order,
            || Summary::EMPTY,
            |s, part| s.add(part, self.bounds, &self.centroids),
            Summary::merge,
        )
    }

    /// The SAH's best split of `order` (whose summary is `s`): the binning and the
    /// axis and bin it splits at (the bins below it go left), or none when no split
    /// beats a leaf.
    fn sah_split(&self, order: &[u32], s: &Summary) -> Option<(Binning, usize, usize)> {
        let binning = Binning::new(&s.cbounds);
        let bins = self.chunked(
            order,
            || Bins::EMPTY,
            |bins, part| binning.add(bins, part, self.bounds, self.triangle, &self.centroids),
            Bins::merge,
        );
        let (cost, axis, split_bin) = bins.best_split(&binning);
        let area = s.bounds.surface_area().max(f32::MIN_POSITIVE);
        let split_cost = TRAVERSAL_COST + cost / area;
        let no_split =
            cost.is_infinite() || (order.len() <= MAX_LEAF && split_cost >= self.leaf_tests(order));
        (!no_split).then_some((binning, axis, split_bin))
    }

    /// Primitive tests of a leaf holding `order`.
    fn leaf_tests(&self, order: &[u32]) -> f32 {
        order
            .iter()
            .fold(Count::default(), |c, &i| {
                c.add(Count::of(self.triangle[i as usize]))
            })
            .tests()
    }

    /// `add` of `order` to `init()`: in chunks of [`Grain::chunk`] on the pool's
    /// threads, merged in order, when `order` is long, else at once.
    fn chunked<T: Send>(
        &self,
        order: &[u32],
        init: impl Fn() -> T + Sync + Send,
        add: impl Fn(&mut T, &[u32]) + Sync + Send,
        merge: impl Fn(&mut T, &T),
    ) -> T {
        let mut acc = init();
        if order.len() < self.grain.par_range {
            add(&mut acc, order);
            return acc;
        }
        let parts: Vec<T> = (order.par_chunks(self.grain.chunk))
            .map(|part| {
                let mut t = init();
                add(&mut t, part);
                t
            })
            .collect();
        for part in &parts {
            merge(&mut acc, part);
        }
        acc
    }

    /// A leaf when it fits, else a median split along the longest axis (for ranges whose
    /// centroids coincide or that are deeper than [`SAH_DEPTH`]).
    fn split_or_leaf_forced(
        &self,
        at: Slot,
        bounds: Aabb,
        order: &mut [u32],
        first: usize,
        depth: usize,
        tree: &mut Tree,
    ) {
        let n = order.len();
        if n <= MAX_LEAF || (depth + 2 >= MAX_DEPTH && n <= u16::MAX as usize) {
            tree.set(at, Node::leaf(bounds, first, n));
            return;
        }
        let mid = n / 2;
        let axis = bounds.longest_axis();
        let centroids = &self.centroids;
        order.select_nth_unstable_by(mid, |&a, &b| {
            centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
        });
        self.interior(at, bounds, axis, (order, mid, first), depth, tree);
    }

    /// Node `at` split at `axis` into `order[..mid]` and `order[mid..]` (`order` being
    /// `first..` of the whole order): both subtrees, beside each other for a large
    /// node, then the node itself, which the first follows and the second's index it
    /// holds.
    fn interior(
        &self,
        at: Slot,
        bounds: Aabb,
        axis: usize,
        (order, mid, first): (&mut [u32], usize, usize),
        depth: usize,
        tree: &mut Tree,
    ) {
        let parallel = order.len() >= self.grain.par_subtree;
        let (left, right) = order.split_at_mut(mid);
        let right_index = if parallel {
            let ((), sub) = rayon::join(
                || self.subtree(left, first, depth + 1, tree),
                || {
                    let mut sub = Tree::default();
                    self.subtree(right, first + mid, depth + 1, &mut sub);
                    sub
                },
            );
            tree.append(sub)
        } else {
            self.subtree(left, first, depth + 1, tree);
            let index = tree.len();
            self.subtree(right, first + mid, depth + 1, tree);
            index
        };
        tree.set(at, Node::interior(bounds, right_index, axis));
    }
}

impl Node {
    /// The place of a node whose children are still to be built.
    const PENDING: Node = Node {
        bounds: Aabb::EMPTY,
        offset: 0,
        count: 0,
        axis: 0,
    };

    fn leaf(bounds: Aabb, first: usize, count: usize) -> Node {
        Node {
            bounds,
            offset: first as u32,
            count: count as u16,
            axis: 0,
        }
    }

    fn interior(bounds: Aabb, right: usize, axis: usize) -> Node {
        Node {
            bounds,
            offset: right as u32,
            count: 0,
            axis: axis as u16,
        }
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

#[cfg(test)]
mod tests {
    //! The parallel build against the sequential one, and against itself on pools of
    //! other sizes: the same nodes bit for bit and the same primitive order. Small
    //! grains make scenes of a few thousand primitives take every parallel path.
    use super::*;
    use crate::math::{Rng, Vec3};

    /// Grains small enough for test scenes to be chunked and split over threads.
    const FINE: Grain = Grain {
        par_range: 256,
        chunk: 64,
        par_subtree: 32,
    };

    /// A node's fields, its box bit for bit.
    fn bits(n: &Node) -> ([u32; 6], u32, u16, u16) {
        let (a, b) = (n.bounds.min.to_array(), n.bounds.max.to_array());
        let c = [a[0], a[1], a[2], b[0], b[1], b[2]].map(f32::to_bits);
        (c, n.offset, n.count, n.axis)
    }

    fn same(a: &(Vec<Node>, Vec<u32>), b: &(Vec<Node>, Vec<u32>), what: &str) {
        assert_eq!(a.0.len(), b.0.len(), "{what}: node count");
        for (i, (x, y)) in a.0.iter().zip(&b.0).enumerate() {
            assert_eq!(bits(x), bits(y), "{what}: node {i}");
        }
        assert_eq!(a.1, b.1, "{what}: primitive order");
    }

    /// `n` boxes of every shape the builder meets: scattered ones of all sizes, some
    /// coincident (median splits), and a run along one line (unbinned axes); every
    /// third a triangle.
    fn boxes(n: usize, rng: &mut Rng) -> (Vec<Aabb>, Vec<bool>) {
        let bounds = (0..n)
            .map(|i| {
                let c = match i % 5 {
                    0..=2 => rng.vec3_in(-10.0, 10.0),
                    3 => Vec3::ONE,
                    _ => Vec3::X * rng.range(-10.0, 10.0),
                };
                let h = rng.vec3_in(0.0, 1.0);
                Aabb {
                    min: c - h,
                    max: c + h,
                }
            })
            .collect();
        (bounds, (0..n).map(|i| i % 3 == 0).collect())
    }

    #[test]
    fn same_tree_as_the_sequential_builder() {
        let mut rng = Rng::new(11);
        for n in [0, 1, 2, 9, 100, 1000, 5000] {
            let (bounds, triangle) = boxes(n, &mut rng);
            let want = reference::build(&bounds, &triangle);
            same(&build(&bounds, &triangle), &want, &format!("n={n}"));
            same(
                &build_with(&bounds, &triangle, FINE),
                &want,
                &format!("n={n}, fine"),
            );
        }
    }

    #[test]
    fn coincident_primitives_same_tree() {
        // No SAH split separates them: median splits, deep ones into large leaves.
        let bounds = vec![
            Aabb {
                min: Vec3::ZERO,
                max: Vec3::ONE,
            };
            3000
        ];
        let triangle = vec![false; 3000];
        let want = reference::build(&bounds, &triangle);
        same(&build_with(&bounds, &triangle, FINE), &want, "coincident");
    }

    #[test]
    fn same_tree_on_any_thread_count() {
        let (bounds, triangle) = boxes(5000, &mut Rng::new(12));
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a thread pool");
            pool.install(|| build_with(&bounds, &triangle, FINE))
        };
        let one = on(1);
        assert!(one.0.len() > 1000, "{} nodes", one.0.len());
        for threads in [2, 4] {
            same(&on(threads), &one, &format!("{threads} threads"));
        }
    }

    #[test]
    fn spd_scenes_same_tree() {
        let scenes = [
            "balls?size=3",
            "tetra?size=5",
            "gears?size=1",
            "rings?size=3",
            "mount?size=4",
            "teapot?size=4",
            "sombrero?size=1",
        ];
        for spec in scenes {
            let scene = crate::job::load_scene(format!("spd:{spec}")).expect("an SPD scene");
            let prims = crate::accel::bvh::gather(&scene.geometry, 0);
            let (_, bounds, triangle) = crate::accel::bvh::tree_prims(&prims, &[]);
            let want = reference::build(&bounds, &triangle);
            same(&build_with(&bounds, &triangle, FINE), &want, spec);
        }
    }
}
