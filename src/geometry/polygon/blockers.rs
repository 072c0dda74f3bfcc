//! The ear test, answered from an index of the vertices that can fail it.
//!
//! A convex corner is an ear unless a remaining reflex or flat vertex (a *blocker*) lies
//! inside or on its triangle: convex vertices never do in a simple polygon, and the
//! clipper has always let only blockers count. So only blockers are indexed, in a
//! [`Tree`], and an ear test looks at the blockers near its triangle. A polygon with no
//! blocker at all (a convex one) has an empty index and every ear test costs nothing.
//!
//! A vertex's corner changes only when a neighbour leaves the ring, so the clipper
//! reports every removal and this index re-checks the two neighbours then: a vertex
//! that starts to block goes into a short list beside the tree. The tree is rebuilt
//! from the vertices that still block once that list, or the number of indexed vertices
//! removed since, grows past half the tree: each rebuild is paid for by as many
//! removals or additions, so rebuilding adds `O(n log n)` work in all.
//!
//! The answer is the one a scan of every remaining vertex gives: the same vertices are
//! tested with the same arithmetic, the tree only skips those that cannot be inside.

use super::ring::Ring;
use super::tree::Tree;

/// Extra entries, or removals, tolerated before a rebuild of a small tree.
const SLACK: usize = 32;

/// The blockers of a ring, indexed.
#[derive(Debug, Default)]
pub(super) struct Blockers {
    tree: Tree,
    /// Vertices that started to block after the tree was built.
    extra: Vec<usize>,
    /// Whether each vertex is in the tree or in `extra`.
    indexed: Vec<bool>,
    /// Indexed vertices that left the ring since the tree was built.
    removed: usize,
    /// Scratch for rebuilds.
    scratch: Vec<usize>,
    /// Nodes and vertices looked at, and vertices indexed, since [`Blockers::build`].
    pub work: u64,
}

impl Blockers {
    /// Index the blockers among the vertices of a freshly linked ring.
    pub fn build(&mut self, ring: &Ring) {
        let n = ring.xy.len();
        self.work = n as u64;
        self.extra.clear();
        self.removed = 0;
        self.indexed.clear();
        self.indexed.resize(n, false);
        self.scratch.clear();
        self.scratch
            .extend((0..n).filter(|&p| ring.alive[p] && ring.blocks(p)));
        for &p in &self.scratch {
            self.indexed[p] = true;
        }
        self.tree.build(&ring.xy, &self.scratch);
    }

    /// Vertex `p` left the ring.
    pub fn removed(&mut self, p: usize) {
        if self.indexed[p] {
            self.removed += 1;
        }
    }

    /// The neighbours of the remaining vertex `p` changed: index it if it now blocks.
    pub fn changed(&mut self, ring: &Ring, p: usize) {
        if !self.indexed[p] && ring.blocks(p) {
            self.indexed[p] = true;
            self.extra.push(p);
        }
    }

    /// A blocker that keeps the convex corner `a b c` (`b` between `a` and `c`) from
    /// being an ear, if there is one: a remaining vertex other than these three, reflex
    /// or flat, inside or on the triangle.
    pub fn block_ear(&mut self, ring: &Ring, a: usize, b: usize, c: usize) -> Option<usize> {
        if self.extra.len() > SLACK + self.tree.items().len() / 2
            || self.removed > SLACK + self.tree.items().len() / 2
        {
            self.rebuild(ring);
        }
        let blocks = |p: usize| {
            ring.alive[p]
                && p != a
                && p != b
                && p != c
                && ring.in_triangle(a, b, c, p)
                && ring.blocks(p)
        };
        self.work += self.extra.len() as u64;
        if let Some(&p) = self.extra.iter().find(|&&p| blocks(p)) {
            return Some(p);
        }
        let t = [ring.xy[a], ring.xy[b], ring.xy[c]];
        self.tree.find(t, ring.sign, &mut self.work, blocks)
    }

    /// Rebuild the tree from the indexed vertices that still block; the others leave
    /// the index (any that blocks again is added by [`Blockers::changed`]).
    fn rebuild(&mut self, ring: &Ring) {
        self.scratch.clear();
        self.scratch.extend_from_slice(self.tree.items());
        self.scratch.append(&mut self.extra);
        self.work += self.scratch.len() as u64;
        let indexed = &mut self.indexed;
        self.scratch.retain(|&p| {
            let keep = ring.alive[p] && ring.blocks(p);
            indexed[p] = keep;
            keep
        });
        self.tree.build(&ring.xy, &self.scratch);
        self.removed = 0;
    }
}
