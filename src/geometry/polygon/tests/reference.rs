//! The ear clipper as it was before its ear test was indexed: every ear test scans
//! the whole remaining polygon, `O(n²)`. Kept, unchanged but for its name, as the
//! oracle the tests compare [`super::super::Triangulator`] with: the two must give the
//! same triangles for every input.

use super::super::PolygonError;
use crate::math::{DVec3, Vec3};

/// Relative size under which a projected triangle counts as collinear: `|cross|` below
/// this times the product of its edge lengths. Far below `f32` resolution, so only
/// vertices that are collinear to within `f64` rounding are removed.
const COLLINEAR_REL: f64 = 1e-12;

/// The quadratic ear clipper, with its scratch buffers.
#[derive(Debug, Default)]
pub struct Reference {
    /// Indices into the input of the distinct vertices.
    idx: Vec<usize>,
    /// Projected 2-D coordinates (relative to the first vertex), per distinct vertex.
    xy: Vec<[f64; 2]>,
    /// Circular doubly linked list over the remaining distinct vertices.
    prev: Vec<usize>,
    next: Vec<usize>,
    /// Triangles over distinct-vertex indices.
    tris: Vec<[usize; 3]>,
}

impl Reference {
    /// A triangulator with empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Triangulate the polygon `points` (in order, closed implicitly) into `out`
    /// (cleared first) as triples of indices into `points`.
    ///
    /// Consecutive duplicate vertices, and a last vertex equal to the first, are
    /// ignored. Triangles and convex quadrilaterals take a fast path; anything else
    /// goes through ear clipping, `O(n²)` for `n` vertices. Triangles too thin to have a
    /// nonzero normal in `f32` are left out.
    ///
    /// # Errors
    /// [`PolygonError::TooFewVertices`] with fewer than 3 distinct vertices,
    /// [`PolygonError::ZeroArea`] when the polygon (or every triangle of it) has no area.
    pub fn triangulate(
        &mut self,
        points: &[Vec3],
        out: &mut Vec<[usize; 3]>,
    ) -> Result<(), PolygonError> {
        out.clear();
        self.idx.clear();
        for (i, p) in points.iter().enumerate() {
            if self.idx.last().is_none_or(|&l| points[l] != *p) {
                self.idx.push(i);
            }
        }
        while self.idx.len() > 1 && points[self.idx[0]] == points[*self.idx.last().unwrap()] {
            self.idx.pop();
        }
        let n = self.idx.len();
        if n < 3 {
            return Err(PolygonError::TooFewVertices { distinct: n });
        }

        // Newell normal and scale, relative to the first distinct vertex.
        let o = points[self.idx[0]].as_dvec3();
        let mut normal = DVec3::ZERO;
        let mut scale2 = 0.0f64;
        let mut prev = DVec3::ZERO;
        for &i in &self.idx[1..] {
            let q = points[i].as_dvec3() - o;
            normal += prev.cross(q);
            scale2 = scale2.max(q.length_squared());
            prev = q;
        }
        let len = normal.length();
        // Also rejects NaN (non-finite input).
        if len.is_nan() || len <= COLLINEAR_REL * scale2 {
            return Err(PolygonError::ZeroArea);
        }
        let unit = (normal / len).as_vec3();

        // Project onto the plane of the two axes other than the dominant one, in cyclic
        // order, so that the projected signed area has the sign of `normal[k]`.
        let k = normal.abs().max_position();
        let (u, v) = ((k + 1) % 3, (k + 2) % 3);
        let sign = if normal[k] < 0.0 { -1.0 } else { 1.0 };
        self.xy.clear();
        for &i in &self.idx {
            let q = points[i].as_dvec3() - o;
            self.xy.push([q[u], q[v]]);
        }

        // Local (distinct-vertex) triangles first, then mapped to input indices.
        self.tris.clear();
        if n == 3 {
            self.tris.push([0, 1, 2]);
        } else if n == 4 && (0..4).all(|i| self.corner(sign, (i + 3) % 4, i, (i + 1) % 4) > 0.0) {
            // Convex quadrilateral: cut along the shorter diagonal.
            if dist2(self.xy[0], self.xy[2]) <= dist2(self.xy[1], self.xy[3]) {
                self.tris.extend([[0, 1, 2], [0, 2, 3]]);
            } else {
                self.tris.extend([[1, 2, 3], [1, 3, 0]]);
            }
        } else {
            self.clip_ears(sign);
        }
        for t in &self.tris {
            let [a, b, c] = t.map(|i| self.idx[i]);
            // The triangle as the intersectors will see it: drop it if its f32 normal
            // vanishes or (a sub-ulp sliver) turns against the polygon's.
            let ng = (points[b] - points[a]).cross(points[c] - points[a]);
            if ng.dot(unit) > 0.0 {
                out.push([a, b, c]);
            }
        }
        if out.is_empty() {
            return Err(PolygonError::ZeroArea);
        }
        Ok(())
    }

    /// Orientation of corner `b` (between `a` and `c`) with the polygon's winding made
    /// counterclockwise: > 0 convex, < 0 reflex, 0 collinear (to `f64` rounding).
    #[inline]
    fn corner(&self, sign: f64, a: usize, b: usize, c: usize) -> f64 {
        let (pa, pb, pc) = (self.xy[a], self.xy[b], self.xy[c]);
        let e1 = [pb[0] - pa[0], pb[1] - pa[1]];
        let e2 = [pc[0] - pa[0], pc[1] - pa[1]];
        let cross = sign * (e1[0] * e2[1] - e1[1] * e2[0]);
        let l2 = (e1[0] * e1[0] + e1[1] * e1[1]) * (e2[0] * e2[0] + e2[1] * e2[1]);
        if cross * cross <= COLLINEAR_REL * COLLINEAR_REL * l2 {
            0.0
        } else {
            cross
        }
    }

    /// Ear clipping over the linked list of remaining vertices, into `self.tris`.
    fn clip_ears(&mut self, sign: f64) {
        let n = self.xy.len();
        self.prev.clear();
        self.next.clear();
        self.prev.extend((0..n).map(|i| (i + n - 1) % n));
        self.next.extend((0..n).map(|i| (i + 1) % n));
        let mut remaining = n;
        let mut i = 0;
        let mut stall = 0;
        while remaining > 3 {
            let (a, c) = (self.prev[i], self.next[i]);
            let turn = self.corner(sign, a, i, c);
            if turn == 0.0 {
                // Collinear or a spike: no area to cover, drop the vertex.
                self.unlink(i);
                remaining -= 1;
                stall = 0;
                i = a;
                continue;
            }
            if turn > 0.0 && self.is_ear(sign, a, i, c) {
                self.tris.push([a, i, c]);
                self.unlink(i);
                remaining -= 1;
                stall = 0;
                // Skipping a vertex spreads the cuts and avoids long fans of slivers.
                i = self.next[c];
                continue;
            }
            i = self.next[i];
            stall += 1;
            if stall > remaining {
                // No ear: the polygon is not simple, or rounding hides every ear. Cut
                // the sharpest convex corner to make progress.
                let mut best = None;
                let mut j = i;
                for _ in 0..remaining {
                    let t = self.corner(sign, self.prev[j], j, self.next[j]);
                    if t > 0.0 && best.is_none_or(|(_, bt)| t > bt) {
                        best = Some((j, t));
                    }
                    j = self.next[j];
                }
                let Some((j, _)) = best else {
                    // Nothing convex is left: what remains has no positive area.
                    return;
                };
                self.tris.push([self.prev[j], j, self.next[j]]);
                i = self.next[j];
                self.unlink(j);
                remaining -= 1;
                stall = 0;
            }
        }
        let (a, c) = (self.prev[i], self.next[i]);
        if self.corner(sign, a, i, c) > 0.0 {
            self.tris.push([a, i, c]);
        }
    }

    /// Whether the convex corner `a b c` is an ear: no remaining reflex (or flat)
    /// vertex lies inside or on the triangle. Vertices at the same position as `a`, `b`
    /// or `c` (a polygon touching itself there) do not block it.
    fn is_ear(&self, sign: f64, a: usize, b: usize, c: usize) -> bool {
        let (pa, pb, pc) = (self.xy[a], self.xy[b], self.xy[c]);
        let mut p = self.next[c];
        while p != a {
            let pp = self.xy[p];
            if pp != pa
                && pp != pb
                && pp != pc
                && orient(sign, pa, pb, pp) >= 0.0
                && orient(sign, pb, pc, pp) >= 0.0
                && orient(sign, pc, pa, pp) >= 0.0
                && self.corner(sign, self.prev[p], p, self.next[p]) <= 0.0
            {
                return false;
            }
            p = self.next[p];
        }
        true
    }

    /// Remove vertex `i` from the linked list.
    #[inline]
    fn unlink(&mut self, i: usize) {
        let (a, c) = (self.prev[i], self.next[i]);
        self.next[a] = c;
        self.prev[c] = a;
    }
}

/// Signed doubled area of `a b p` with the winding made counterclockwise.
#[inline]
fn orient(sign: f64, a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    sign * ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]))
}

#[inline]
fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}
