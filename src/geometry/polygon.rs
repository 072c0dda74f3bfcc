//! Triangulation of planar, possibly concave, simple polygons in 3-D (NFF `p`/`pp`).
//!
//! The polygon's plane normal comes from Newell's method (robust for any vertex order
//! and for concave or slightly non-planar input), the vertices are projected onto the
//! coordinate plane most perpendicular to it, and the projected polygon is cut by ear
//! clipping in double precision. Every output triangle keeps the polygon's winding:
//! its `(p1 − p0) × (p2 − p0)`, computed in `f32` as the intersectors do, points the
//! same way as the Newell normal. Zero-area ears (collinear or spike vertices) are
//! removed without emitting a triangle.
//!
//! Ear clipping never emits a triangle outside a simple polygon. For input that is not
//! simple (self-intersecting), or when rounding hides every ear, the clipper falls back
//! to cutting a convex corner so that it always terminates.

use crate::math::{DVec3, Vec3};

/// Why a polygon has no triangulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PolygonError {
    /// Fewer than three distinct vertices after removing consecutive duplicates (and a
    /// closing vertex equal to the first).
    #[error("polygon has {distinct} distinct vertices (at least 3 needed)")]
    TooFewVertices {
        /// Number of distinct vertices found.
        distinct: usize,
    },
    /// All vertices are collinear (or the polygon's area is otherwise zero): there is no
    /// plane and nothing to see.
    #[error("polygon has zero area")]
    ZeroArea,
}

/// Relative size under which a projected triangle counts as collinear: `|cross|` below
/// this times the product of its edge lengths. Far below `f32` resolution, so only
/// vertices that are collinear to within `f64` rounding are removed.
const COLLINEAR_REL: f64 = 1e-12;

/// Reusable ear clipper: keeps its scratch buffers between polygons, so a loader can
/// triangulate thousands of polygons without allocating for each.
#[derive(Debug, Default)]
pub struct Triangulator {
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

/// Triangulate one polygon; see [`Triangulator::triangulate`].
pub fn triangulate(points: &[Vec3]) -> Result<Vec<[usize; 3]>, PolygonError> {
    let mut out = Vec::new();
    Triangulator::default().triangulate(points, &mut out)?;
    Ok(out)
}

/// The Newell normal of a polygon (twice its vector area), not normalised, computed in
/// `f64` relative to the first vertex. Zero for fewer than three points.
pub fn newell_normal(points: &[Vec3]) -> DVec3 {
    let Some(first) = points.first() else {
        return DVec3::ZERO;
    };
    let o = first.as_dvec3();
    let mut n = DVec3::ZERO;
    let mut prev = DVec3::ZERO;
    for p in &points[1..] {
        let q = p.as_dvec3() - o;
        n += prev.cross(q);
        prev = q;
    }
    n
}

impl Triangulator {
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f32::consts::TAU;

    /// Everything a correct triangulation of a simple polygon satisfies: indices in
    /// range, area preserved, no reversed triangle, every centroid inside.
    fn check(points: &[Vec3], tris: &[[usize; 3]]) {
        let n = newell_normal(points);
        let area = 0.5 * n.length();
        let unit = n.normalize();
        let mut sum = 0.0;
        for t in tris {
            assert!(t.iter().all(|&i| i < points.len()), "{t:?} out of range");
            let [a, b, c] = t.map(|i| points[i].as_dvec3());
            let ng = (b - a).cross(c - a);
            assert!(ng.dot(unit) > 0.0, "triangle {t:?} reversed or flat");
            sum += 0.5 * ng.length();
            let centroid = (a + b + c) / 3.0;
            assert!(
                inside(points, unit, centroid),
                "centroid of {t:?} outside the polygon"
            );
        }
        assert!(
            ((sum - area) / area).abs() < 1e-5,
            "area {sum} vs polygon {area}"
        );
    }

    /// Even-odd point-in-polygon test in the plane of `normal`, using a 2-D basis of
    /// the plane (independent of the triangulator's projection).
    fn inside(points: &[Vec3], normal: DVec3, p: DVec3) -> bool {
        let e1 = normal.any_orthonormal_vector();
        let e2 = normal.cross(e1);
        let to2 = |q: DVec3| (q.dot(e1), q.dot(e2));
        let (px, py) = to2(p);
        let mut inside = false;
        for i in 0..points.len() {
            let (ax, ay) = to2(points[i].as_dvec3());
            let (bx, by) = to2(points[(i + 1) % points.len()].as_dvec3());
            if (ay > py) != (by > py) {
                let x = ax + (py - ay) / (by - ay) * (bx - ax);
                if px < x {
                    inside = !inside;
                }
            }
        }
        inside
    }

    fn regular(n: usize, r: f32) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let a = TAU * i as f32 / n as f32;
                Vec3::new(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect()
    }

    /// A gear outline like the SPD's: `teeth` teeth, 4 vertices per tooth, the tooth
    /// tips wider in angle than their roots gaps.
    fn gear(teeth: usize, inner: f32, outer: f32) -> Vec<Vec3> {
        let mut v = Vec::new();
        for t in 0..teeth {
            let a0 = TAU * t as f32 / teeth as f32;
            let step = TAU / teeth as f32;
            for (da, r) in [(0.0, inner), (0.2, outer), (0.5, outer), (0.7, inner)] {
                let a = a0 + da * step;
                v.push(Vec3::new(r * a.cos(), r * a.sin(), 1.0));
            }
        }
        v
    }

    /// Rotate and translate a polygon into an arbitrary plane.
    fn transform(points: &[Vec3]) -> Vec<Vec3> {
        let q = glam::Quat::from_euler(glam::EulerRot::XYZ, 0.7, -1.1, 2.3);
        points
            .iter()
            .map(|&p| q * p + Vec3::new(3.0, -7.0, 11.0))
            .collect()
    }

    #[test]
    fn triangle_and_fast_paths() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert_eq!(triangulate(&t).unwrap(), vec![[0, 1, 2]]);
        let quad = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let tris = triangulate(&quad).unwrap();
        assert_eq!(tris.len(), 2);
        check(&quad, &tris);
    }

    #[test]
    fn convex_ngons() {
        for n in [5, 6, 12, 64, 144] {
            let p = regular(n, 2.0);
            let tris = triangulate(&p).unwrap();
            assert_eq!(tris.len(), n - 2, "n = {n}");
            check(&p, &tris);
        }
    }

    #[test]
    fn l_shape() {
        let p: Vec<Vec3> = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)]
            .iter()
            .map(|&(x, y)| Vec3::new(x, y, 0.0))
            .collect();
        let tris = triangulate(&p).unwrap();
        assert_eq!(tris.len(), 4);
        check(&p, &tris);
    }

    #[test]
    fn concave_quad_is_not_fanned_from_its_reflex_vertex_wrongly() {
        // Dart: vertex 3 is reflex. A fan from 0 would emit (0,1,2) and (0,2,3), the
        // latter reversed and outside.
        let p = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.5, 1.0, 0.0),
        ];
        let tris = triangulate(&p).unwrap();
        assert_eq!(tris.len(), 2);
        check(&p, &tris);
    }

    #[test]
    fn gear_and_star() {
        let g = gear(36, 0.8, 1.0); // 144 vertices, like the SPD gears' faces
        assert_eq!(g.len(), 144);
        let tris = triangulate(&g).unwrap();
        assert_eq!(tris.len(), 142);
        check(&g, &tris);

        let star: Vec<Vec3> = (0..200)
            .map(|i| {
                let a = TAU * i as f32 / 200.0;
                let r = if i % 2 == 0 { 1.0 } else { 0.3 };
                Vec3::new(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect();
        let tris = triangulate(&star).unwrap();
        assert_eq!(tris.len(), 198);
        check(&star, &tris);
    }

    /// A comb: a bar with `teeth` teeth. The corners of the bar see the teeth's roots
    /// inside their triangles, so clipping a convex corner blindly goes wrong.
    fn comb(teeth: usize) -> Vec<Vec3> {
        let w = 2.0 * teeth as f32 - 1.0;
        let mut v = vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(w, 0.0, 0.0)];
        for t in (0..teeth).rev() {
            let x = 2.0 * t as f32;
            v.push(Vec3::new(x + 1.0, 3.0, 0.0));
            v.push(Vec3::new(x, 3.0, 0.0));
            if t > 0 {
                v.push(Vec3::new(x, 1.0, 0.0));
                v.push(Vec3::new(x - 1.0, 1.0, 0.0));
            }
        }
        v
    }

    /// A square spiral corridor of width 1 along a centre line with legs 2, 4, 6, …
    /// (4 apart), `turns` times round: walls offset ±½ with mitred corners.
    fn spiral(turns: usize) -> Vec<Vec3> {
        let dirs = [(1.0f32, 0.0f32), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)];
        let legs = 4 * turns;
        let mut centre = vec![(0.0f32, 0.0f32)];
        for k in 0..legs {
            let (dx, dy) = dirs[k % 4];
            let (x, y) = centre[k];
            let len = 2.0 * (k + 1) as f32;
            centre.push((x + dx * len, y + dy * len));
        }
        // Left normal of leg k, and the offset at centre-line vertex i.
        let normal = |k: usize| {
            let (dx, dy) = dirs[k % 4];
            (-dy, dx)
        };
        let offset = |i: usize| {
            let (a, b) = if i == 0 {
                (normal(0), (0.0, 0.0))
            } else if i == legs {
                (normal(legs - 1), (0.0, 0.0))
            } else {
                (normal(i - 1), normal(i))
            };
            (0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1))
        };
        let left = (0..=legs).map(|i| {
            let (o, c) = (offset(i), centre[i]);
            Vec3::new(c.0 + o.0, c.1 + o.1, 0.0)
        });
        let right: Vec<Vec3> = (0..=legs)
            .map(|i| {
                let (o, c) = (offset(i), centre[i]);
                Vec3::new(c.0 - o.0, c.1 - o.1, 0.0)
            })
            .collect();
        left.chain(right.into_iter().rev()).collect()
    }

    #[test]
    fn comb_and_spiral() {
        for teeth in [2, 5, 20] {
            let p = comb(teeth);
            let tris = triangulate(&p).unwrap();
            // Cuts can leave collinear vertices behind, dropped without a triangle.
            assert!(tris.len() <= p.len() - 2);
            check(&p, &tris);
            let p = transform(&p);
            check(&p, &triangulate(&p).unwrap());
        }
        for turns in [1, 3, 6] {
            let p = spiral(turns);
            // A simple corridor: its area is its centre line's length.
            let legs = 4.0 * turns as f64;
            assert!((0.5 * newell_normal(&p).length() - legs * (legs + 1.0)).abs() < 1e-9);
            let tris = triangulate(&p).unwrap();
            check(&p, &tris);
            let mut r = p.clone();
            r.reverse();
            check(&r, &triangulate(&r).unwrap());
        }
    }

    #[test]
    fn arbitrary_plane_and_clockwise() {
        let g = transform(&gear(12, 0.5, 1.0));
        let tris = triangulate(&g).unwrap();
        check(&g, &tris);

        // The same polygon clockwise: the normal flips and every triangle follows.
        let mut rev = g.clone();
        rev.reverse();
        let tris = triangulate(&rev).unwrap();
        check(&rev, &tris);
        let n = newell_normal(&g);
        for t in &tris {
            let [a, b, c] = t.map(|i| rev[i]);
            assert!(((b - a).cross(c - a)).as_dvec3().dot(n) < 0.0);
        }

        // Polygons whose normal is each axis, both ways round.
        let l: Vec<(f32, f32)> = vec![(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)];
        for axis in 0..3 {
            for flip in [false, true] {
                let mut p: Vec<Vec3> = l
                    .iter()
                    .map(|&(x, y)| {
                        let mut v = [0.0; 3];
                        v[(axis + 1) % 3] = x;
                        v[(axis + 2) % 3] = y;
                        v[axis] = 5.0;
                        Vec3::from(v)
                    })
                    .collect();
                if flip {
                    p.reverse();
                }
                let tris = triangulate(&p).unwrap();
                assert_eq!(tris.len(), 4);
                check(&p, &tris);
            }
        }
    }

    #[test]
    fn collinear_vertices_are_dropped() {
        // A square with extra vertices along its edges: still 2 units of area, no
        // zero-area triangles.
        let p: Vec<Vec3> = [
            (0., 0.),
            (1., 0.),
            (2., 0.),
            (2., 1.),
            (2., 2.),
            (1., 2.),
            (0., 2.),
            (0., 1.),
        ]
        .iter()
        .map(|&(x, y)| Vec3::new(x, y, 0.0))
        .collect();
        let tris = triangulate(&p).unwrap();
        check(&p, &tris);
        for t in &tris {
            let [a, b, c] = t.map(|i| p[i]);
            assert!((b - a).cross(c - a).length() > 0.0);
        }
        assert!(tris.len() <= 6);
    }

    #[test]
    fn duplicates_removed() {
        let a = Vec3::ZERO;
        let b = Vec3::X;
        let c = Vec3::new(1.0, 1.0, 0.0);
        let d = Vec3::Y;
        // Repeated vertices and a closing copy of the first.
        let p = [a, a, b, b, b, c, d, d, a];
        let tris = triangulate(&p).unwrap();
        assert_eq!(tris.len(), 2);
        check(&p, &tris);
        // Indices point at the input, never at the dropped copies' positions wrongly.
        for t in &tris {
            let [x, y, z] = t.map(|i| p[i]);
            assert!(x != y && y != z && x != z);
        }
    }

    #[test]
    fn degenerate_inputs() {
        assert_eq!(
            triangulate(&[]),
            Err(PolygonError::TooFewVertices { distinct: 0 })
        );
        assert_eq!(
            triangulate(&[Vec3::ONE, Vec3::ONE, Vec3::ONE]),
            Err(PolygonError::TooFewVertices { distinct: 1 })
        );
        assert_eq!(
            triangulate(&[Vec3::ZERO, Vec3::X, Vec3::X, Vec3::ZERO]),
            Err(PolygonError::TooFewVertices { distinct: 2 })
        );
        // Collinear: zero area.
        assert_eq!(
            triangulate(&[Vec3::ZERO, Vec3::X, Vec3::X * 2.0]),
            Err(PolygonError::ZeroArea)
        );
        assert_eq!(
            triangulate(&[Vec3::ZERO, Vec3::X, Vec3::X * 3.0, Vec3::X * 2.0]),
            Err(PolygonError::ZeroArea)
        );
        // Non-finite input never produces triangles.
        assert_eq!(
            triangulate(&[Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 1.0, 0.0)]),
            Err(PolygonError::ZeroArea)
        );
    }

    #[test]
    fn reuse_of_buffers() {
        let mut tr = Triangulator::new();
        let mut out = Vec::new();
        let big = gear(36, 0.8, 1.0);
        tr.triangulate(&big, &mut out).unwrap();
        assert_eq!(out.len(), 142);
        let small = [Vec3::ZERO, Vec3::X, Vec3::Y];
        tr.triangulate(&small, &mut out).unwrap();
        assert_eq!(out, vec![[0, 1, 2]]);
    }

    #[test]
    fn self_intersecting_input_terminates() {
        // A bowtie-like pentagram: not simple. Only termination and winding are
        // promised.
        let p: Vec<Vec3> = (0..5)
            .map(|i| {
                let a = TAU * (2 * i) as f32 / 5.0;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        if let Ok(tris) = triangulate(&p) {
            let n = newell_normal(&p);
            for t in &tris {
                let [a, b, c] = t.map(|i| p[i]);
                assert!((b - a).cross(c - a).as_dvec3().dot(n) > 0.0);
            }
        }
    }

    proptest! {
        /// Random star-shaped polygons (random radius at increasing angles, so always
        /// simple), in a random plane.
        #[test]
        fn random_star_shaped(
            radii in prop::collection::vec(0.05f32..1.0, 3..80),
            rot in (-3.0f32..3.0, -3.0f32..3.0, -3.0f32..3.0),
            clockwise in any::<bool>(),
        ) {
            let n = radii.len();
            let q = glam::Quat::from_euler(glam::EulerRot::XYZ, rot.0, rot.1, rot.2);
            let mut p: Vec<Vec3> = radii
                .iter()
                .enumerate()
                .map(|(i, &r)| {
                    let a = TAU * i as f32 / n as f32;
                    q * Vec3::new(r * a.cos(), r * a.sin(), 0.0)
                })
                .collect();
            if clockwise {
                p.reverse();
            }
            let tris = triangulate(&p).unwrap();
            prop_assert!(tris.len() <= n - 2);
            check(&p, &tris);
        }
    }
}
