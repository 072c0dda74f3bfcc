//! Ear clipping: the walk round the ring that cuts ears, drops flat vertices and, when
//! no ear is found (a polygon that is not simple, or rounding that hides every ear),
//! cuts the sharpest convex corner so that it always terminates.
//!
//! After each cut the walk moves on past the ear's far neighbour: spreading the cuts
//! round the polygon avoids long fans of slivers, and on a convex polygon yields
//! triangles that halve in number and double in size from one round to the next, which
//! a bounding volume hierarchy separates well. Each ear test scans every remaining
//! vertex, so the whole costs `O(n²)`.

use super::ring::Ring;

/// Cut the linked ring into triangles (indices into the ring), appended to `tris`.
pub(super) fn clip_ears(ring: &mut Ring, tris: &mut Vec<[usize; 3]>) {
    let mut remaining = ring.xy.len();
    let mut i = 0;
    let mut stall = 0;
    while remaining > 3 {
        let (a, c) = (ring.prev[i], ring.next[i]);
        let turn = ring.corner(a, i, c);
        if turn == 0.0 {
            // Collinear or a spike: no area to cover, drop the vertex.
            ring.unlink(i);
            remaining -= 1;
            stall = 0;
            i = a;
            continue;
        }
        if turn > 0.0 && is_ear(ring, a, i, c) {
            tris.push([a, i, c]);
            ring.unlink(i);
            remaining -= 1;
            stall = 0;
            // Skipping a vertex spreads the cuts and avoids long fans of slivers.
            i = ring.next[c];
            continue;
        }
        i = ring.next[i];
        stall += 1;
        if stall > remaining {
            // No ear: the polygon is not simple, or rounding hides every ear.
            let Some(j) = sharpest_convex(ring, i, remaining) else {
                // Nothing convex is left: what remains has no positive area.
                return;
            };
            tris.push([ring.prev[j], j, ring.next[j]]);
            i = ring.next[j];
            ring.unlink(j);
            remaining -= 1;
            stall = 0;
        }
    }
    let (a, c) = (ring.prev[i], ring.next[i]);
    if ring.corner(a, i, c) > 0.0 {
        tris.push([a, i, c]);
    }
}

/// Whether the convex corner `a b c` is an ear: no remaining reflex (or flat) vertex
/// lies inside or on the triangle.
fn is_ear(ring: &Ring, a: usize, b: usize, c: usize) -> bool {
    let mut p = ring.next[c];
    while p != a {
        if ring.in_triangle(a, b, c, p) && ring.blocks(p) {
            return false;
        }
        p = ring.next[p];
    }
    true
}

/// The remaining vertex with the most convex corner, the first of equals going round
/// from `i`; none if no corner is convex.
fn sharpest_convex(ring: &Ring, i: usize, remaining: usize) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    let mut j = i;
    for _ in 0..remaining {
        let t = ring.corner(ring.prev[j], j, ring.next[j]);
        if t > 0.0 && best.is_none_or(|(_, bt)| t > bt) {
            best = Some((j, t));
        }
        j = ring.next[j];
    }
    best.map(|(j, _)| j)
}
