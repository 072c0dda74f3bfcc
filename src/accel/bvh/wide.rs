//! The 4-wide form the hierarchy is traversed in (see `traverse`): the binary SAH tree
//! collapsed so that each node holds up to four children, their boxes stored axis by
//! axis (`[f32; 4]` per plane) so that one node's four slab tests are a few vector
//! instructions.

use super::Node;
use crate::math::Aabb;
use rayon::prelude::*;
use smallvec::SmallVec;

/// Marks a child reference as a leaf (the rest is an index into the leaf table).
pub(super) const LEAF: u32 = 1 << 31;
/// An unused child slot; its box is empty, so no ray reaches it.
const EMPTY: u32 = u32::MAX;

/// One node: four children's boxes and references; 128 bytes, two cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node4 {
    /// The six planes of the four boxes, `[side * 3 + axis][slot]`: side 0 holds the
    /// lower corners, side 1 the upper ones (one flat index, so that a traversal picks
    /// the plane a ray enters through with one index it computes once per ray).
    pub planes: [[f32; 4]; 6],
    /// Interior child: its node index. Leaf: [`LEAF`] | index into the leaf table.
    /// Unused: `u32::MAX`.
    pub child: [u32; 4],
    /// Bit `i` set when slot `i` holds a child. The slab test's hit mask is limited to
    /// it, so an unused slot is never followed whatever the ray (a NaN in the slab
    /// test keeps the interval, which would otherwise reach the empty boxes too).
    pub used: u32,
}

impl Node4 {
    const UNUSED: Node4 = Node4 {
        planes: [
            [f32::INFINITY; 4],
            [f32::INFINITY; 4],
            [f32::INFINITY; 4],
            [f32::NEG_INFINITY; 4],
            [f32::NEG_INFINITY; 4],
            [f32::NEG_INFINITY; 4],
        ],
        child: [EMPTY; 4],
        used: 0,
    };

    /// Box of slot `i` (empty for an unused slot).
    #[cfg(test)]
    pub fn slot_bounds(&self, i: usize) -> Aabb {
        let p = &self.planes;
        Aabb {
            min: glam::Vec3::new(p[0][i], p[1][i], p[2][i]),
            max: glam::Vec3::new(p[3][i], p[4][i], p[5][i]),
        }
    }

    fn set_slot(&mut self, i: usize, bounds: &Aabb, child: u32) {
        for a in 0..3 {
            self.planes[a][i] = bounds.min[a];
            self.planes[3 + a][i] = bounds.max[a];
        }
        self.child[i] = child;
        self.used |= 1 << i;
    }
}

/// Binary subtrees of at least this many nodes are collapsed on a task of their own.
const PAR_NODES: usize = 4096;

/// Collapse binary `nodes` into 4-wide ones: each node's children are replaced by
/// grandchildren, the interior child with the largest surface area first, until there
/// are four. Returns the nodes (root first) and the leaf table (`(first primitive,
/// count)`); no nodes for an empty tree.
///
/// Large subtrees are collapsed on the caller's rayon pool beside each other and
/// spliced in the order a sequential collapse gives, so the result does not depend on
/// the thread count.
pub(super) fn collapse(nodes: &[Node]) -> (Vec<Node4>, Vec<(u32, u32)>) {
    collapse_with(nodes, PAR_NODES)
}

/// [`collapse`] with subtrees of `par_nodes` binary nodes or more collapsed apart.
fn collapse_with(nodes: &[Node], par_nodes: usize) -> (Vec<Node4>, Vec<(u32, u32)>) {
    if nodes.is_empty() {
        return (Vec::new(), Vec::new());
    }
    Part::of(nodes, (0, nodes.len()), par_nodes).flatten()
}

/// A binary subtree: its root's index and the end of its nodes (a node's first child
/// follows it, its second starts at its `offset`, the subtree runs up to the end).
type Sub = (usize, usize);

/// The (up to four) descendants that replace binary interior node `bin`: the
/// children of the interior descendant with the largest surface area (the last of
/// equals) take its place, until there are four or only leaves.
fn widest_descendants(nodes: &[Node], bin: Sub) -> SmallVec<[Sub; 4]> {
    let mut kids: SmallVec<[Sub; 4]> = smallvec::smallvec![bin];
    loop {
        let widest = kids
            .iter()
            .enumerate()
            .filter(|&(_, &(k, _))| nodes[k].count == 0)
            .max_by(|a, b| {
                let (sa, sb) = (
                    nodes[a.1.0].bounds.surface_area(),
                    nodes[b.1.0].bounds.surface_area(),
                );
                sa.total_cmp(&sb)
            })
            .map(|(i, _)| i);
        match widest {
            Some(i) if kids.len() < 4 => {
                let (k, end) = kids[i];
                let right = nodes[k].offset as usize;
                kids[i] = (k + 1, right);
                kids.insert(i + 1, (right, end));
            }
            _ => break,
        }
    }
    kids
}

/// The 4-wide nodes and leaves of a subtree in the order a sequential collapse pushes
/// them, with the subtrees collapsed apart in between. A child reference holds an
/// index into this part (counting the nodes and leaves of the parts taken before it).
#[derive(Debug, Default)]
struct Part {
    nodes: Vec<Node4>,
    leaves: Vec<(u32, u32)>,
    /// Parts taken whole, each with the numbers of `nodes` and `leaves` before it.
    subs: Vec<(usize, usize, Part)>,
    /// Nodes and leaves in all, the parts' included.
    len: (usize, usize),
}

impl Part {
    /// The collapse of binary interior subtree `bin`.
    fn of(nodes: &[Node], bin: Sub, par_nodes: usize) -> Part {
        let mut part = Part::default();
        part.fill(nodes, bin, par_nodes);
        part
    }

    /// Push the node that replaces binary interior node `bin`, and all below it.
    fn fill(&mut self, nodes: &[Node], bin: Sub, par_nodes: usize) {
        self.nodes.push(Node4::UNUSED);
        self.len.0 += 1;
        let at = self.nodes.len() - 1;
        let kids = widest_descendants(nodes, bin);
        let large = |&(k, end): &Sub| nodes[k].count == 0 && end - k >= par_nodes;
        let mut apart: SmallVec<[Option<Part>; 4]> = if kids.iter().any(large) {
            kids.par_iter()
                .map(|kid| large(kid).then(|| Part::of(nodes, *kid, par_nodes)))
                .collect::<Vec<_>>()
                .into()
        } else {
            kids.iter().map(|_| None).collect()
        };
        for (slot, &kid) in kids.iter().enumerate() {
            let n = &nodes[kid.0];
            let child = if n.count > 0 {
                self.leaves.push((n.offset, n.count as u32));
                self.len.1 += 1;
                LEAF | (self.len.1 - 1) as u32
            } else if let Some(part) = apart[slot].take() {
                self.append(part) as u32
            } else {
                let i = self.len.0;
                self.fill(nodes, kid, par_nodes);
                i as u32
            };
            self.nodes[at].set_slot(slot, &n.bounds, child);
        }
    }

    /// Take `part` whole; returns the index of its root node.
    fn append(&mut self, part: Part) -> usize {
        let root = self.len.0;
        self.len = (self.len.0 + part.len.0, self.len.1 + part.len.1);
        self.subs.push((self.nodes.len(), self.leaves.len(), part));
        root
    }

    /// The nodes and leaves in one array each, the child references indices into them.
    fn flatten(self) -> (Vec<Node4>, Vec<(u32, u32)>) {
        let mut nodes = Vec::with_capacity(self.len.0);
        let mut leaves = Vec::with_capacity(self.len.1);
        self.flatten_into(&mut nodes, &mut leaves);
        (nodes, leaves)
    }

    fn flatten_into(self, nodes: &mut Vec<Node4>, leaves: &mut Vec<(u32, u32)>) {
        let base = (nodes.len() as u32, leaves.len() as u32);
        let (mut own_nodes, mut own_leaves) = (self.nodes.into_iter(), self.leaves.into_iter());
        let (mut nodes_done, mut leaves_done) = (0, 0);
        for (n, l, part) in self.subs {
            nodes.extend(
                own_nodes
                    .by_ref()
                    .take(n - nodes_done)
                    .map(|x| x.shifted(base)),
            );
            leaves.extend(own_leaves.by_ref().take(l - leaves_done));
            (nodes_done, leaves_done) = (n, l);
            part.flatten_into(nodes, leaves);
        }
        nodes.extend(own_nodes.map(|x| x.shifted(base)));
        leaves.extend(own_leaves);
    }
}

impl Node4 {
    /// The node with its children's references moved by `base`: `(nodes, leaves)`.
    fn shifted(mut self, base: (u32, u32)) -> Node4 {
        for c in self.child.iter_mut().filter(|c| **c != EMPTY) {
            *c = if *c & LEAF != 0 {
                LEAF | ((*c & !LEAF) + base.1)
            } else {
                *c + base.0
            };
        }
        self
    }
}

#[cfg(test)]
mod tests {
    //! The parallel collapse against the sequential one it replaced (`reference`), and
    //! against itself on pools of other sizes.
    use super::*;
    use crate::math::{Rng, Vec3};

    mod reference {
        //! The sequential collapse.
        use super::super::{LEAF, Node, Node4};

        pub fn collapse(nodes: &[Node]) -> (Vec<Node4>, Vec<(u32, u32)>) {
            let mut out = Vec::new();
            let mut leaves = Vec::new();
            if !nodes.is_empty() {
                out.push(Node4::UNUSED);
                fill(nodes, 0, 0, &mut out, &mut leaves);
            }
            (out, leaves)
        }

        /// Fill `out[at]` with the (up to four) descendants that replace binary node `bin`.
        fn fill(
            nodes: &[Node],
            bin: usize,
            at: usize,
            out: &mut Vec<Node4>,
            leaves: &mut Vec<(u32, u32)>,
        ) {
            let mut kids: Vec<usize> = vec![bin];
            loop {
                let widest = kids
                    .iter()
                    .enumerate()
                    .filter(|&(_, &k)| nodes[k].count == 0)
                    .max_by(|a, b| {
                        let (sa, sb) = (
                            nodes[*a.1].bounds.surface_area(),
                            nodes[*b.1].bounds.surface_area(),
                        );
                        sa.total_cmp(&sb)
                    })
                    .map(|(i, _)| i);
                match widest {
                    Some(i) if kids.len() < 4 => {
                        let k = kids[i];
                        kids.splice(i..=i, [k + 1, nodes[k].offset as usize]);
                    }
                    _ => break,
                }
            }
            for (slot, &k) in kids.iter().enumerate() {
                let n = &nodes[k];
                let child = if n.count > 0 {
                    leaves.push((n.offset, n.count as u32));
                    LEAF | (leaves.len() - 1) as u32
                } else {
                    out.push(Node4::UNUSED);
                    let i = out.len() - 1;
                    fill(nodes, k, i, out, leaves);
                    i as u32
                };
                out[at].set_slot(slot, &n.bounds, child);
            }
        }
    }

    /// The binary tree over `n` random boxes.
    fn binary(n: usize) -> Vec<Node> {
        let mut rng = Rng::new(21);
        let bounds: Vec<Aabb> = (0..n)
            .map(|_| {
                let c = rng.vec3_in(-10.0, 10.0);
                let h = Vec3::splat(rng.range(0.01, 1.0));
                Aabb {
                    min: c - h,
                    max: c + h,
                }
            })
            .collect();
        super::super::build::build(&bounds, &vec![false; n]).0
    }

    fn same(a: &(Vec<Node4>, Vec<(u32, u32)>), b: &(Vec<Node4>, Vec<(u32, u32)>)) {
        assert_eq!(a.0.len(), b.0.len(), "node count");
        for (i, (x, y)) in a.0.iter().zip(&b.0).enumerate() {
            let bits = |n: &Node4| (n.planes.map(|p| p.map(f32::to_bits)), n.child, n.used);
            assert_eq!(bits(x), bits(y), "node {i}");
        }
        assert_eq!(a.1, b.1, "leaves");
    }

    #[test]
    fn same_nodes_as_the_sequential_collapse() {
        for n in [0, 1, 9, 3000] {
            let nodes = binary(n);
            let want = reference::collapse(&nodes);
            same(&collapse(&nodes), &want);
            same(&collapse_with(&nodes, 8), &want);
        }
    }

    #[test]
    fn same_nodes_on_any_thread_count() {
        let nodes = binary(3000);
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a thread pool");
            pool.install(|| collapse_with(&nodes, 8))
        };
        let one = on(1);
        assert!(one.0.len() > 100, "{} nodes", one.0.len());
        same(&on(4), &one);
    }
}
