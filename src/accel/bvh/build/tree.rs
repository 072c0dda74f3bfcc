//! The binary nodes of a subtree under construction. A subtree built on another
//! thread has nodes of its own, which its parent's tree takes whole (`append`); one
//! pass at the end (`flatten`) lays every node out in the order a sequential build
//! pushes them (a node, its first subtree, its second), renumbering the second
//! children, so that each node is copied once however deep the parallel splits go.

use crate::accel::bvh::Node;

/// A subtree's nodes in build order: its own, with the subtrees it took in between.
/// An interior node's `offset` is its second child's index in this tree (counting the
/// nodes of the subtrees taken before it); a leaf's is a primitive index.
#[derive(Debug, Default)]
pub(super) struct Tree {
    nodes: Vec<Node>,
    /// Subtrees taken whole, each with the number of `nodes` pushed before it.
    subs: Vec<(usize, Tree)>,
    /// Nodes in all, the subtrees' included.
    len: usize,
}

/// Where [`Tree::push`] put a node, for [`Tree::set`].
#[derive(Clone, Copy, Debug)]
pub(super) struct Slot(usize);

impl Tree {
    /// Nodes in the tree, the subtrees' included: the index of the next node.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Append a node.
    pub fn push(&mut self, node: Node) -> Slot {
        self.nodes.push(node);
        self.len += 1;
        Slot(self.nodes.len() - 1)
    }

    /// Replace the node pushed at `slot`.
    pub fn set(&mut self, slot: Slot, node: Node) {
        self.nodes[slot.0] = node;
    }

    /// Append all of `sub`'s nodes; returns the index of its root.
    pub fn append(&mut self, sub: Tree) -> usize {
        let root = self.len;
        self.len += sub.len;
        self.subs.push((self.nodes.len(), sub));
        root
    }

    /// The nodes in one array, each second child's index an index into it.
    pub fn flatten(self) -> Vec<Node> {
        if self.subs.is_empty() {
            return self.nodes;
        }
        let mut out = Vec::with_capacity(self.len);
        self.flatten_into(&mut out);
        out
    }

    fn flatten_into(self, out: &mut Vec<Node>) {
        let base = out.len() as u32;
        let mut subs = self.subs.into_iter().peekable();
        for (i, node) in self.nodes.into_iter().enumerate() {
            while let Some((_, sub)) = subs.next_if(|(at, _)| *at == i) {
                sub.flatten_into(out);
            }
            out.push(node.shifted(base));
        }
        for (_, sub) in subs {
            sub.flatten_into(out);
        }
    }
}

impl Node {
    /// The node with its second child's index moved by `base` (a leaf unchanged).
    fn shifted(mut self, base: u32) -> Node {
        if self.count == 0 {
            self.offset += base;
        }
        self
    }
}
