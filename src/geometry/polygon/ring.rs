//! The polygon's distinct vertices projected into its plane, as a ring that ear clipping
//! shrinks: 2-D coordinates, the circular doubly linked list of the vertices still in
//! it, and the two orientation tests every decision is made with.
//!
//! [`Ring::corner`], which decides convex, reflex and flat, is error-bounded: it calls a
//! corner flat unless its cross product exceeds a bound relative to the edges' lengths
//! that is far above the rounding error of the `f64` arithmetic, so a corner it calls
//! convex or reflex is so in the projection. The point-in-triangle test of the ear test
//! uses the plain signed area [`orient`], whose sign is exact whenever the coordinate
//! differences are (vertices of `f32` coordinates of similar magnitude).

/// Relative size under which a projected triangle counts as collinear: `|cross|` below
/// this times the product of its edge lengths. Far below `f32` resolution, so only
/// vertices that are collinear to within `f64` rounding are removed. (The polygon's
/// Newell normal counts as zero below the same fraction of its squared size.)
pub(super) const COLLINEAR_REL: f64 = 1e-12;

/// The projected vertices and the links of those still in the polygon.
#[derive(Debug, Default)]
pub(super) struct Ring {
    /// Projected 2-D coordinates (relative to the first vertex), per distinct vertex.
    pub xy: Vec<[f64; 2]>,
    /// Circular doubly linked list over the remaining vertices.
    pub prev: Vec<usize>,
    pub next: Vec<usize>,
    /// Whether each vertex is still in the list.
    pub alive: Vec<bool>,
    /// `1` or `-1`: the sign that makes the polygon's winding counterclockwise.
    pub sign: f64,
}

impl Ring {
    /// Link all of `xy` in order, every vertex alive, with the winding sign `sign`.
    pub fn link(&mut self, sign: f64) {
        let n = self.xy.len();
        self.sign = sign;
        self.prev.clear();
        self.next.clear();
        self.alive.clear();
        self.prev.extend((0..n).map(|i| (i + n - 1) % n));
        self.next.extend((0..n).map(|i| (i + 1) % n));
        self.alive.resize(n, true);
    }

    /// Orientation of corner `b` (between `a` and `c`) with the polygon's winding made
    /// counterclockwise: > 0 convex, < 0 reflex, 0 collinear (to `f64` rounding).
    #[inline]
    pub fn corner(&self, a: usize, b: usize, c: usize) -> f64 {
        let (pa, pb, pc) = (self.xy[a], self.xy[b], self.xy[c]);
        let e1 = [pb[0] - pa[0], pb[1] - pa[1]];
        let e2 = [pc[0] - pa[0], pc[1] - pa[1]];
        let cross = self.sign * (e1[0] * e2[1] - e1[1] * e2[0]);
        let l2 = (e1[0] * e1[0] + e1[1] * e1[1]) * (e2[0] * e2[0] + e2[1] * e2[1]);
        if cross * cross <= COLLINEAR_REL * COLLINEAR_REL * l2 {
            0.0
        } else {
            cross
        }
    }

    /// Whether the remaining vertex `p` can keep a corner from being an ear: it is
    /// reflex or flat between its current neighbours.
    #[inline]
    pub fn blocks(&self, p: usize) -> bool {
        self.corner(self.prev[p], p, self.next[p]) <= 0.0
    }

    /// Whether `p`, a remaining vertex other than the corner `a b c`'s own, lies inside
    /// or on that triangle, as the ear test sees it. A vertex at the same position as
    /// `a`, `b` or `c` (a polygon touching itself there) does not count.
    #[inline]
    pub fn in_triangle(&self, a: usize, b: usize, c: usize, p: usize) -> bool {
        let (pa, pb, pc, pp) = (self.xy[a], self.xy[b], self.xy[c], self.xy[p]);
        let s = self.sign;
        pp != pa
            && pp != pb
            && pp != pc
            && orient(s, pa, pb, pp) >= 0.0
            && orient(s, pb, pc, pp) >= 0.0
            && orient(s, pc, pa, pp) >= 0.0
    }

    /// Remove vertex `i` from the list.
    #[inline]
    pub fn unlink(&mut self, i: usize) {
        let (a, c) = (self.prev[i], self.next[i]);
        self.next[a] = c;
        self.prev[c] = a;
        self.alive[i] = false;
    }
}

/// Signed doubled area of `a b p` with the winding made counterclockwise.
#[inline]
fn orient(sign: f64, a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    sign * ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]))
}
