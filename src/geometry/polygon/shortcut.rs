//! The walk's shortcut past the vertices where it has nothing to do.
//!
//! At a reflex vertex, or a convex one that is not an ear, the clipper does nothing but
//! step on and count the step (a full round of steps with no cut sends it to its
//! fallback). On a long reflex chain whose only ears are at its ends (a comb's sagging
//! bar, a crescent's inner arc), or along a corridor whose convex wall is blocked by
//! the other (a spiral), it would walk the whole ring and test every convex vertex
//! again for every cut. Instead, the vertices it must look at (*open*: convex or flat
//! corners, but for the convex ones whose [`Witnesses`] still hold) and those still in
//! the ring are kept as two sets of positions in polygon order (the ring never
//! reorders its vertices), each in a Fenwick tree, so the next open vertex and the
//! number of steps to it, or the vertex a given number of steps on, are found in
//! `O(log n)`.
//!
//! A vertex's corner changes only when a neighbour leaves the ring, and a witness
//! stops holding only then or when its blocker leaves the ring or stops blocking, so
//! the clipper reports every removal and the vertices concerned are looked at again.
//! The sets are kept from the walk's first closed vertex on: a convex polygon never
//! needs them.

use super::ring::Ring;
use super::witness::Witnesses;

/// A set of positions `0..n`, as a Fenwick tree of counts.
#[derive(Debug, Default)]
struct Positions {
    /// `tree[k − 1]` counts the members in `(k − lowbit(k), k]`, 1-based.
    tree: Vec<u32>,
    member: Vec<bool>,
    total: usize,
}

impl Positions {
    /// The set of the positions `0..n` for which `f` holds.
    fn build(&mut self, n: usize, f: impl Fn(usize) -> bool) {
        self.member.clear();
        self.member.extend((0..n).map(f));
        self.total = self.member.iter().filter(|&&m| m).count();
        self.tree.clear();
        self.tree.extend(self.member.iter().map(|&m| u32::from(m)));
        for k in 1..=n {
            let parent = k + (k & k.wrapping_neg());
            if parent <= n {
                self.tree[parent - 1] += self.tree[k - 1];
            }
        }
    }

    /// Put `i` in the set or take it out.
    fn set(&mut self, i: usize, member: bool) {
        if self.member[i] == member {
            return;
        }
        self.member[i] = member;
        let n = self.tree.len();
        let mut k = i + 1;
        while k <= n {
            if member {
                self.tree[k - 1] += 1;
            } else {
                self.tree[k - 1] -= 1;
            }
            k += k & k.wrapping_neg();
        }
        if member {
            self.total += 1;
        } else {
            self.total -= 1;
        }
    }

    /// Members before position `i`.
    fn before(&self, i: usize) -> usize {
        let mut k = i;
        let mut count = 0;
        while k > 0 {
            count += self.tree[k - 1] as usize;
            k &= k - 1;
        }
        count
    }

    /// The member with `k` members before it (`k < total`).
    fn nth(&self, k: usize) -> usize {
        let n = self.tree.len();
        let mut pos = 0;
        let mut left = k;
        let mut step = if n == 0 { 0 } else { 1 << n.ilog2() };
        while step > 0 {
            let next = pos + step;
            if next <= n && (self.tree[next - 1] as usize) <= left {
                pos = next;
                left -= self.tree[next - 1] as usize;
            }
            step >>= 1;
        }
        pos
    }
}

/// The open vertices and the vertices still in the ring, for jumps along the ring.
#[derive(Debug, Default)]
pub(super) struct Shortcut {
    alive: Positions,
    open: Positions,
    witnesses: Witnesses,
    /// Scratch: vertices whose witness stopped holding.
    released: Vec<usize>,
    /// Whether the sets are kept.
    built: bool,
    /// Set operations made, each `O(log n)`.
    pub work: u64,
}

impl Shortcut {
    /// Forget any ring, for one of `n` vertices: no witness, and nothing kept until
    /// [`Shortcut::build`].
    pub fn reset(&mut self, n: usize) {
        self.built = false;
        self.work = 0;
        self.witnesses.reset(n);
    }

    /// Whether the sets are kept.
    pub fn is_built(&self) -> bool {
        self.built
    }

    /// Whether the walk must look at the remaining vertex `v`.
    pub fn is_open(&self, ring: &Ring, v: usize) -> bool {
        open(ring, &self.witnesses, v)
    }

    /// Keep the sets from now on, for the ring as it is.
    pub fn build(&mut self, ring: &Ring) {
        let n = ring.xy.len();
        self.alive.build(n, |v| ring.alive[v]);
        let witnesses = &self.witnesses;
        self.open
            .build(n, |v| ring.alive[v] && open(ring, witnesses, v));
        self.built = true;
        self.work += n as u64;
    }

    /// The ear test of the remaining vertex `v` found `blocker` in its triangle.
    pub fn blocked(&mut self, ring: &Ring, v: usize, blocker: usize) {
        self.witnesses
            .record(v, blocker, ring.prev[v], ring.next[v]);
        if self.built {
            self.open.set(v, false);
            self.work += 1;
        }
    }

    /// Vertex `v` left the ring.
    pub fn removed(&mut self, ring: &Ring, v: usize) {
        if self.built {
            self.alive.set(v, false);
            self.open.set(v, false);
            self.work += 2;
        }
        self.release(ring, v);
    }

    /// The neighbours of the remaining vertex `v` changed.
    pub fn changed(&mut self, ring: &Ring, v: usize) {
        if self.built {
            let open = self.is_open(ring, v);
            self.open.set(v, open);
            self.work += 1;
        }
        if !ring.blocks(v) {
            self.release(ring, v);
        }
    }

    /// `p` left the ring or does not block: look again at the vertices it blocked.
    fn release(&mut self, ring: &Ring, p: usize) {
        let mut released = std::mem::take(&mut self.released);
        self.witnesses.release(p, &mut released);
        self.work += released.len() as u64;
        if self.built {
            for &v in &released {
                if ring.alive[v] {
                    let open = self.is_open(ring, v);
                    self.open.set(v, open);
                }
            }
        }
        released.clear();
        self.released = released;
    }

    /// From the remaining vertex `i`, the first open vertex at or after it going round
    /// and the number of (closed) vertices before it; `None` when none is open.
    pub fn next_open(&mut self, i: usize) -> Option<(usize, usize)> {
        self.work += 4;
        if self.open.total == 0 {
            return None;
        }
        let ahead = self.open.before(i);
        let j = self
            .open
            .nth(if ahead < self.open.total { ahead } else { 0 });
        Some((j, self.steps(i, j)))
    }

    /// The vertex `k` steps on from the remaining vertex `i`.
    pub fn step(&mut self, i: usize, k: usize) -> usize {
        self.work += 2;
        let at = (self.alive.before(i) + k) % self.alive.total;
        self.alive.nth(at)
    }

    /// Steps from the remaining vertex `i` round to the remaining vertex `j`.
    fn steps(&self, i: usize, j: usize) -> usize {
        let (bi, bj) = (self.alive.before(i), self.alive.before(j));
        if j >= i {
            bj - bi
        } else {
            self.alive.total - bi + bj
        }
    }
}

/// Whether the walk must look at the remaining vertex `v`: its corner is flat, or
/// convex and not known to be blocked.
fn open(ring: &Ring, witnesses: &Witnesses, v: usize) -> bool {
    ring.corner(ring.prev[v], v, ring.next[v]) >= 0.0 && !witnesses.holds(ring, v)
}
