//! The 4-wide form the hierarchy is traversed in (see `traverse`): the binary SAH tree
//! collapsed so that each node holds up to four children, their boxes stored axis by
//! axis (`[f32; 4]` per plane) so that one node's four slab tests are a few vector
//! instructions.

use super::Node;
use crate::math::Aabb;

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

/// Collapse binary `nodes` into 4-wide ones: each node's children are replaced by
/// grandchildren, the interior child with the largest surface area first, until there
/// are four. Returns the nodes (root first) and the leaf table (`(first primitive,
/// count)`); no nodes for an empty tree.
pub(super) fn collapse(nodes: &[Node]) -> (Vec<Node4>, Vec<(u32, u32)>) {
    let mut out = Vec::new();
    let mut leaves = Vec::new();
    if !nodes.is_empty() {
        out.push(Node4::UNUSED);
        fill(nodes, 0, 0, &mut out, &mut leaves);
    }
    (out, leaves)
}

/// Fill `out[at]` with the (up to four) descendants that replace binary node `bin`.
fn fill(nodes: &[Node], bin: usize, at: usize, out: &mut Vec<Node4>, leaves: &mut Vec<(u32, u32)>) {
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
