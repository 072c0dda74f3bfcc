//! Ear clipping: the walk round the ring that cuts ears, drops flat vertices and, when
//! no ear is found (a polygon that is not simple, or rounding that hides every ear),
//! cuts the sharpest convex corner so that it always terminates.
//!
//! After each cut the walk moves on past the ear's far neighbour: spreading the cuts
//! round the polygon avoids long fans of slivers, and on a convex polygon yields
//! triangles that halve in number and double in size from one round to the next, which
//! a bounding volume hierarchy separates well. The ear test is [`Blockers::block_ear`];
//! everything else a step does costs a constant, so a convex polygon, whose ear tests
//! cost a constant too, is cut in linear time.

use super::blockers::Blockers;
use super::ring::Ring;

/// Cut the linked ring into triangles (indices into the ring), appended to `tris`.
/// Every step of the walk adds one to `steps`.
pub(super) fn clip_ears(
    ring: &mut Ring,
    blockers: &mut Blockers,
    tris: &mut Vec<[usize; 3]>,
    steps: &mut u64,
) {
    let mut remaining = ring.xy.len();
    let mut i = 0;
    let mut stall = 0;
    while remaining > 3 {
        *steps += 1;
        let (a, c) = (ring.prev[i], ring.next[i]);
        let turn = ring.corner(a, i, c);
        if turn == 0.0 {
            // Collinear or a spike: no area to cover, drop the vertex.
            remove(ring, blockers, i);
            remaining -= 1;
            stall = 0;
            i = a;
            continue;
        }
        if turn > 0.0 && blockers.block_ear(ring, a, i, c).is_none() {
            tris.push([a, i, c]);
            remove(ring, blockers, i);
            remaining -= 1;
            stall = 0;
            i = ring.next[c];
            continue;
        }
        i = ring.next[i];
        stall += 1;
        if stall > remaining {
            // No ear: the polygon is not simple, or rounding hides every ear.
            let Some(j) = sharpest_convex(ring, i, remaining, steps) else {
                // Nothing convex is left: what remains has no positive area.
                return;
            };
            tris.push([ring.prev[j], j, ring.next[j]]);
            i = ring.next[j];
            remove(ring, blockers, j);
            remaining -= 1;
            stall = 0;
        }
    }
    let (a, c) = (ring.prev[i], ring.next[i]);
    if ring.corner(a, i, c) > 0.0 {
        tris.push([a, i, c]);
    }
}

/// Take vertex `i` out of the ring and tell the index, whose view of its two
/// neighbours' corners changes.
fn remove(ring: &mut Ring, blockers: &mut Blockers, i: usize) {
    let (a, c) = (ring.prev[i], ring.next[i]);
    ring.unlink(i);
    blockers.removed(i);
    blockers.changed(ring, a);
    blockers.changed(ring, c);
}

/// The remaining vertex with the most convex corner, the first of equals going round
/// from `i`; none if no corner is convex.
fn sharpest_convex(ring: &Ring, i: usize, remaining: usize, steps: &mut u64) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    let mut j = i;
    for _ in 0..remaining {
        let t = ring.corner(ring.prev[j], j, ring.next[j]);
        if t > 0.0 && best.is_none_or(|(_, bt)| t > bt) {
            best = Some((j, t));
        }
        j = ring.next[j];
    }
    *steps += remaining as u64;
    best.map(|(j, _)| j)
}
