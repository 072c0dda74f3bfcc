//! The 4-wide form the hierarchy is traversed in: the binary SAH tree collapsed so that
//! each node holds up to four children, their boxes stored axis by axis (`[f32; 4]` per
//! plane) so that one node's four slab tests are plain loops over fixed arrays that the
//! compiler turns into vector instructions.

use super::leaf::Leaf;
use super::{Node, STACK};
use crate::math::{Aabb, Ray};
use glam::Vec4;

/// Marks a child reference as a leaf (the rest is an index into the leaf table).
pub(super) const LEAF: u32 = 1 << 31;
/// An unused child slot; its box is empty, so no ray reaches it.
const EMPTY: u32 = u32::MAX;
/// Far distances are widened by this factor so that rounding never drops a box a ray
/// touches (the same bound as [`Aabb::hit`]).
const FAR_SCALE: f32 = 1.0 + 2.0 * crate::math::gamma(3);
/// Traversal stack depth for any tree: a node pushes at most three children and the
/// collapsed tree is no deeper than the binary one, whose depth the builder keeps below
/// [`STACK`].
pub(super) const STACK4: usize = 3 * STACK;
/// A smaller stack, enough for most trees and cheaper to set up per ray.
pub(super) const STACK_SMALL: usize = 40;

/// One node: four children's boxes (`bounds[0]` the lower corners, `bounds[1]` the upper
/// ones, each `[axis][slot]`) and references; 128 bytes, two cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node4 {
    pub bounds: [[[f32; 4]; 3]; 2],
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
        bounds: [[[f32::INFINITY; 4]; 3], [[f32::NEG_INFINITY; 4]; 3]],
        child: [EMPTY; 4],
        used: 0,
    };

    /// Box of slot `i` (empty for an unused slot).
    #[cfg(test)]
    pub fn slot_bounds(&self, i: usize) -> Aabb {
        let b = &self.bounds;
        Aabb {
            min: glam::Vec3::new(b[0][0][i], b[0][1][i], b[0][2][i]),
            max: glam::Vec3::new(b[1][0][i], b[1][1][i], b[1][2][i]),
        }
    }

    fn set_slot(&mut self, i: usize, bounds: &Aabb, child: u32) {
        for a in 0..3 {
            self.bounds[0][a][i] = bounds.min[a];
            self.bounds[1][a][i] = bounds.max[a];
        }
        self.child[i] = child;
        self.used |= 1 << i;
    }
}

/// Collapse binary `nodes` into 4-wide ones: each node's children are replaced by
/// grandchildren, the interior child with the largest surface area first, until there
/// are four. Returns the nodes (root first) and the leaf table (`(first primitive,
/// count)`) and the traversal stack depth the tree needs (see [`traverse`]); no nodes
/// for an empty tree.
pub(super) fn collapse(nodes: &[Node]) -> (Vec<Node4>, Vec<(u32, u32)>, usize) {
    let mut out = Vec::new();
    let mut leaves = Vec::new();
    let mut need = 0;
    if !nodes.is_empty() {
        out.push(Node4::UNUSED);
        need = fill(nodes, 0, 0, &mut out, &mut leaves);
    }
    (out, leaves, need)
}

/// Fill `out[at]` with the (up to four) descendants that replace binary node `bin`;
/// returns the stack depth a traversal from there needs: a node pushes all but one of
/// the children a ray reaches, so it is the largest sum, over paths down, of each
/// node's children but one.
fn fill(
    nodes: &[Node],
    bin: usize,
    at: usize,
    out: &mut Vec<Node4>,
    leaves: &mut Vec<(u32, u32)>,
) -> usize {
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
    let mut below = 0;
    for (slot, &k) in kids.iter().enumerate() {
        let n = &nodes[k];
        let child = if n.count > 0 {
            leaves.push((n.offset, n.count as u32));
            LEAF | (leaves.len() - 1) as u32
        } else {
            out.push(Node4::UNUSED);
            let i = out.len() - 1;
            below = below.max(fill(nodes, k, i, out, leaves));
            i as u32
        };
        out[at].set_slot(slot, &n.bounds, child);
    }
    kids.len() - 1 + below
}

/// What a leaf visit tells the traversal.
pub(super) enum Visit {
    /// Go on, looking for hits nearer than this.
    Continue(f32),
    /// Stop: the answer is known.
    Stop,
}

/// Walk `nodes` with a stack of `DEPTH` entries (at least the tree's
/// [`stack_need`]); `leaf` is called for every leaf the ray reaches, with the current far
/// end of the interval.
/// With `ORDERED`, the children a node's box tests hit are visited nearest entry first,
/// the others pushed with their entry distance and dropped when they come off the stack
/// if a hit nearer than that was found meanwhile. Without it (any-hit queries, where
/// the first hit ends the walk) they are visited in slot order.
#[inline(always)]
pub(super) fn traverse<const ORDERED: bool, const DEPTH: usize>(
    nodes: &[Node4],
    leaves: &[Leaf],
    ray: &Ray,
    mut leaf: impl FnMut(&Leaf, f32) -> Visit,
) {
    if nodes.is_empty() {
        return;
    }
    let inv = ray.dir.recip();
    // The plane a ray enters a slab through: the lower one for positive directions.
    let near = [
        (inv.x < 0.0) as usize,
        (inv.y < 0.0) as usize,
        (inv.z < 0.0) as usize,
    ];
    let org = [0, 1, 2].map(|a| Vec4::splat(ray.org[a]));
    let inv = [0, 1, 2].map(|a| Vec4::splat(inv[a]));
    let far_scale = Vec4::splat(FAR_SCALE);
    let mut tmax = ray.tmax;
    let mut stack = [(0u32, 0f32); DEPTH];
    let mut sp = 0usize;
    let mut cur = 0u32;
    loop {
        if cur & LEAF == 0 {
            let node = &nodes[cur as usize];
            let mut tn = Vec4::splat(ray.tmin);
            let mut tf = Vec4::splat(tmax);
            for a in 0..3 {
                let lo = Vec4::from_array(node.bounds[near[a]][a]);
                let hi = Vec4::from_array(node.bounds[1 - near[a]][a]);
                // `max`/`min` keep their argument when the distance is NaN (a ray in a
                // slab's plane with a zero direction component), leaving the interval
                // as it was (x86; on other targets such a ray may miss the box).
                tn = ((lo - org[a]) * inv[a]).max(tn);
                tf = ((hi - org[a]) * inv[a] * far_scale).min(tf);
            }
            let mut mask = tn.cmple(tf).bitmask() & node.used;
            if mask != 0 {
                let mut hits = [(0u32, 0f32); 4];
                let mut k = 0;
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    hits[k] = (node.child[i], tn[i]);
                    k += 1;
                }
                if ORDERED {
                    // Insertion sort, nearest first.
                    for i in 1..k {
                        let mut j = i;
                        while j > 0 && hits[j].1 < hits[j - 1].1 {
                            hits.swap(j, j - 1);
                            j -= 1;
                        }
                    }
                }
                for &h in hits[1..k].iter().rev() {
                    stack[sp] = h;
                    sp += 1;
                }
                cur = hits[0].0;
                continue;
            }
        } else {
            match leaf(&leaves[(cur & !LEAF) as usize], tmax) {
                Visit::Continue(t) => tmax = t,
                Visit::Stop => return,
            }
        }
        // Next: the nearest pushed child that may still hold a nearer hit.
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            let (next, tentry) = stack[sp];
            if !ORDERED || tentry <= tmax {
                cur = next;
                break;
            }
        }
    }
}
