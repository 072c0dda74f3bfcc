//! Ear clipping: the walk round the ring that cuts ears, drops flat vertices and, when
//! no ear is found (a polygon that is not simple, or rounding that hides every ear),
//! cuts the sharpest convex corner so that it always terminates.
//!
//! After each cut the walk moves on past the ear's far neighbour: spreading the cuts
//! round the polygon avoids long fans of slivers, and on a convex polygon yields
//! triangles that halve in number and double in size from one round to the next, which
//! a bounding volume hierarchy separates well. The ear test is [`Blockers::block_ear`];
//! runs of vertices where the walk only steps on (reflex ones, and convex ones known
//! not to be ears) are jumped by the [`Shortcut`]; everything else a step does costs a
//! constant. A convex polygon, whose ear tests cost a constant too and which has no
//! reflex vertex, is cut in linear time.

use super::blockers::Blockers;
use super::ring::Ring;
use super::shortcut::Shortcut;

/// Where the walk starts and how many vertices the ring has.
pub(super) struct Walk {
    pub start: usize,
    pub remaining: usize,
}

/// The walk's state and what it works with.
pub(super) struct Clipper<'a> {
    pub ring: &'a mut Ring,
    pub blockers: &'a mut Blockers,
    pub shortcut: &'a mut Shortcut,
    /// The triangles (indices into the ring), appended to.
    pub tris: &'a mut Vec<[usize; 3]>,
    /// Incremented at every step of the walk.
    pub steps: &'a mut u64,
}

impl Clipper<'_> {
    /// Cut the linked ring into triangles.
    pub fn run(mut self, walk: Walk) {
        let Walk {
            start: mut i,
            mut remaining,
        } = walk;
        let mut stall = 0;
        while remaining > 3 {
            *self.steps += 1;
            let (a, c) = (self.ring.prev[i], self.ring.next[i]);
            let turn = self.ring.corner(a, i, c);
            if turn == 0.0 {
                // Collinear or a spike: no area to cover, drop the vertex.
                self.remove(i);
                remaining -= 1;
                stall = 0;
                i = a;
                continue;
            }
            if turn > 0.0 {
                match self.blockers.block_ear(self.ring, a, i, c) {
                    None => {
                        self.tris.push([a, i, c]);
                        self.remove(i);
                        remaining -= 1;
                        stall = 0;
                        i = self.ring.next[c];
                        continue;
                    }
                    Some(p) => self.shortcut.blocked(self.ring, i, p),
                }
            }
            // Not an ear: step on, past any closed vertices that follow.
            let (next, steps) = self.pass(self.ring.next[i], remaining - stall);
            i = next;
            stall += steps;
            if stall > remaining {
                // No ear: the polygon is not simple, or rounding hides every ear.
                let Some(j) = self.sharpest_convex(i, remaining) else {
                    // Nothing convex is left: what remains has no positive area.
                    return;
                };
                self.tris.push([self.ring.prev[j], j, self.ring.next[j]]);
                i = self.ring.next[j];
                self.remove(j);
                remaining -= 1;
                stall = 0;
            }
        }
        let (a, c) = (self.ring.prev[i], self.ring.next[i]);
        if self.ring.corner(a, i, c) > 0.0 {
            self.tris.push([a, i, c]);
        }
    }

    /// The walk steps on from a vertex that is not an ear to `i`, then on past closed
    /// vertices (reflex ones, and convex ones known not to be ears), where there is
    /// nothing to do but count the step; `limit` steps are allowed before the stall
    /// sends it to the fallback. Where it stops (the first open vertex, or where it
    /// takes step `limit + 1`) and the steps taken.
    fn pass(&mut self, i: usize, limit: usize) -> (usize, usize) {
        if !self.shortcut.is_built() {
            if limit == 0 || self.shortcut.is_open(self.ring, i) {
                return (i, 1);
            }
            self.shortcut.build(self.ring);
        }
        match self.shortcut.next_open(i) {
            Some((j, closed)) if closed < limit => (j, 1 + closed),
            _ => (self.shortcut.step(i, limit), limit + 1),
        }
    }

    /// Take vertex `i` out of the ring and tell the indexes, whose view of its two
    /// neighbours' corners changes.
    fn remove(&mut self, i: usize) {
        let (a, c) = (self.ring.prev[i], self.ring.next[i]);
        self.ring.unlink(i);
        self.blockers.removed(i);
        self.shortcut.removed(self.ring, i);
        for v in [a, c] {
            self.blockers.changed(self.ring, v);
            self.shortcut.changed(self.ring, v);
        }
    }

    /// The remaining vertex with the most convex corner, the first of equals going round
    /// from `i`; none if no corner is convex.
    fn sharpest_convex(&mut self, i: usize, remaining: usize) -> Option<usize> {
        let ring = &*self.ring;
        let mut best: Option<(usize, f64)> = None;
        let mut j = i;
        for _ in 0..remaining {
            let t = ring.corner(ring.prev[j], j, ring.next[j]);
            if t > 0.0 && best.is_none_or(|(_, bt)| t > bt) {
                best = Some((j, t));
            }
            j = ring.next[j];
        }
        *self.steps += remaining as u64;
        best.map(|(j, _)| j)
    }
}
