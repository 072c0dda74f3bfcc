//! Why a convex vertex is not an ear: the blocker its ear test found inside its
//! triangle. The answer stands while the vertex keeps its two neighbours and the
//! blocker stays in the ring and keeps blocking (the test is a function of those four
//! vertices' positions), so the walk need not test the vertex again until then.
//!
//! Each blocker keeps the list of vertices it was found to block, so that when it
//! leaves the ring or stops blocking they can all be looked at again.

use super::ring::Ring;

/// No entry.
const NONE: usize = usize::MAX;

/// What an ear test found.
#[derive(Clone, Copy, Debug)]
struct Witness {
    blocker: usize,
    prev: usize,
    next: usize,
}

/// The witnesses of the vertices that are not ears, and who they block.
#[derive(Debug, Default)]
pub(super) struct Witnesses {
    /// Per vertex: the blocker found in its ear triangle, and its neighbours then.
    by: Vec<Option<Witness>>,
    /// Per blocker: the first entry of the list of vertices it was found to block.
    head: Vec<usize>,
    /// A vertex and the next entry of the same list.
    entries: Vec<(usize, usize)>,
}

impl Witnesses {
    /// No witness, for a ring of `n` vertices.
    pub fn reset(&mut self, n: usize) {
        self.by.clear();
        self.by.resize(n, None);
        self.head.clear();
        self.head.resize(n, NONE);
        self.entries.clear();
    }

    /// The ear test of vertex `v`, between `prev` and `next`, found `blocker`.
    pub fn record(&mut self, v: usize, blocker: usize, prev: usize, next: usize) {
        self.by[v] = Some(Witness {
            blocker,
            prev,
            next,
        });
        self.entries.push((v, self.head[blocker]));
        self.head[blocker] = self.entries.len() - 1;
    }

    /// Whether vertex `v`'s witness still holds: `v` is not an ear.
    pub fn holds(&self, ring: &Ring, v: usize) -> bool {
        self.by[v].is_some_and(|w| {
            ring.prev[v] == w.prev
                && ring.next[v] == w.next
                && ring.alive[w.blocker]
                && ring.blocks(w.blocker)
        })
    }

    /// `p` left the ring or stopped blocking: append to `out` the vertices it was the
    /// witness of, whose witnesses no longer hold, and empty its list.
    pub fn release(&mut self, p: usize, out: &mut Vec<usize>) {
        let mut e = std::mem::replace(&mut self.head[p], NONE);
        while e != NONE {
            let (v, next) = self.entries[e];
            if self.by[v].is_some_and(|w| w.blocker == p) {
                self.by[v] = None;
                out.push(v);
            }
            e = next;
        }
    }
}
