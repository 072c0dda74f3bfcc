//! The convexity check, made once per polygon before clipping, and what it buys.
//!
//! A polygon is convex when every corner turns the polygon's way or is *straight* (its
//! vertex exactly on the segment between its neighbours) and the edge directions go
//! round exactly once. The turns are [`Ring::corner`]'s error-bounded test; straightness
//! is decided exactly, by error-free transformations of the `f64` arithmetic (a
//! difference whose rounding error is not zero, or a product too small to carry its
//! error, leaves the vertex uncertified and the polygon not convex); the directions are
//! counted by the half plane of each edge, which is a matter of signs.
//!
//! A convex polygon's straight vertices lie on its edges and add no area, so they are
//! taken out of the ring before clipping. What is left has only convex corners: nothing
//! can block an ear, and the clipper cuts it in linear time. (Left in, they are flat
//! vertices the walk meets one at a time, dropping each and stepping back, which fans
//! long slivers out of one vertex and makes every ear test look along them.)

use super::ring::Ring;

/// Whether the freshly linked ring is convex (see the module documentation).
pub(super) fn is_convex(ring: &Ring) -> bool {
    let n = ring.xy.len();
    let mut rises = 0;
    let mut was_upper = upper(ring, n - 1);
    for i in 0..n {
        let (a, c) = ((i + n - 1) % n, (i + 1) % n);
        let turn = ring.corner(a, i, c);
        if !(turn > 0.0 || turn == 0.0 && straight(ring.xy[a], ring.xy[i], ring.xy[c])) {
            return false;
        }
        let is_upper = upper(ring, i);
        rises += usize::from(is_upper && !was_upper);
        was_upper = is_upper;
    }
    rises == 1
}

/// Take the straight vertices of a convex ring out of it: the vertex the walk starts
/// from (the first corner) and the number of corners.
pub(super) fn drop_straight(ring: &mut Ring) -> (usize, usize) {
    let n = ring.xy.len();
    // Decided on the original neighbours (the ring is freshly linked), then relinked.
    for i in 0..n {
        ring.alive[i] = ring.corner((i + n - 1) % n, i, (i + 1) % n) > 0.0;
    }
    let Some(first) = ring.alive.iter().position(|&a| a) else {
        ring.link(ring.sign);
        return (0, n);
    };
    let mut last = first;
    let mut count = 1;
    for i in first + 1..n {
        if ring.alive[i] {
            ring.next[last] = i;
            ring.prev[i] = last;
            last = i;
            count += 1;
        }
    }
    ring.next[last] = first;
    ring.prev[first] = last;
    (first, count)
}

/// Whether edge `i` (from vertex `i` to the next) points into the upper half plane
/// (angle in `[0, π)`) with the polygon's winding made counterclockwise.
fn upper(ring: &Ring, i: usize) -> bool {
    let (p, q) = (ring.xy[i], ring.xy[(i + 1) % ring.xy.len()]);
    let (dx, dy) = (q[0] - p[0], ring.sign * (q[1] - p[1]));
    dy > 0.0 || dy == 0.0 && dx > 0.0
}

/// Whether `b` lies exactly on the segment from `a` to `c`, strictly between them.
fn straight(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> bool {
    let (Some(ux), Some(uy), Some(vx), Some(vy)) = (
        exact_sub(b[0], a[0]),
        exact_sub(b[1], a[1]),
        exact_sub(c[0], b[0]),
        exact_sub(c[1], b[1]),
    ) else {
        return false;
    };
    same_product(ux, vy, uy, vx) && ux * vx + uy * vy > 0.0
}

/// `x − y` if it is exact in `f64` (Knuth's two-sum error is zero).
fn exact_sub(x: f64, y: f64) -> Option<f64> {
    let s = x - y;
    let yv = x - s;
    let sv = s + yv;
    let err = (x - sv) - (y - yv);
    (err == 0.0).then_some(s)
}

/// Whether `a·b = c·d` exactly: each product as its rounded value and its rounding
/// error (exact by a fused multiply-add, unless the product is so small that the error
/// underflows, which leaves the answer false).
fn same_product(a: f64, b: f64, c: f64, d: f64) -> bool {
    const TINY: f64 = 1e-280;
    let (p, q) = (a * b, c * d);
    let tiny = |x: f64| x != 0.0 && x.abs() < TINY;
    if tiny(p) || tiny(q) {
        return false;
    }
    p == q && a.mul_add(b, -p) == c.mul_add(d, -q)
}
