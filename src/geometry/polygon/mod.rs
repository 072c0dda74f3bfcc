//! Triangulation of planar, possibly concave, simple polygons in 3-D (NFF `p`/`pp`, OBJ
//! faces, the scene format's polygons and meshes).
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
//!
//! Cutting a polygon of `n` vertices costs `O(n)` when it is convex and, for a concave
//! one, `O(n log n)` for polygons as they come (a worst case remains quadratic: a walk
//! that finds no ear for long, on input that is not simple, or a vertex that many
//! blockers in turn keep from being an ear). The parts: `ring` (the
//! projected vertices, their links and the orientation tests), `convex` (the
//! convexity check, and the straight vertices a convex polygon loses before it is cut),
//! `clip` (the walk that cuts ears), `shortcut` (its jumps past vertices where it
//! has nothing to do, with the `witness`es that show a convex vertex is not an ear),
//! `blockers` (the ear test, from an index of the reflex and flat vertices, the only
//! ones that can fail it) and `tree` (that index's spatial structure).
//!
//! The triangles are exactly those of the plain quadratic ear clipper this replaced, so
//! that scenes render as they did (the tests compare the two), but for a convex polygon
//! with vertices exactly on its edges: those vertices add no area and are left out, where
//! the old clipper dropped them one at a time and fanned long slivers out of one vertex.

mod blockers;
mod clip;
mod convex;
mod ring;
mod shortcut;
#[cfg(test)]
mod tests;
mod tree;
mod witness;

use crate::math::{DVec3, Vec3};
use blockers::Blockers;
use ring::{COLLINEAR_REL, Ring};
use shortcut::Shortcut;

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

/// Reusable ear clipper: keeps its scratch buffers between polygons, so a loader can
/// triangulate thousands of polygons without allocating for each.
#[derive(Debug, Default)]
pub struct Triangulator {
    /// Indices into the input of the distinct vertices.
    idx: Vec<usize>,
    /// The distinct vertices, projected and linked.
    ring: Ring,
    /// The index of the ring's reflex and flat vertices.
    blockers: Blockers,
    /// The walk's jumps past vertices where it has nothing to do.
    shortcut: Shortcut,
    /// Triangles over distinct-vertex indices.
    tris: Vec<[usize; 3]>,
    /// Corners tested and steps of the walk in the last triangulation.
    steps: u64,
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
    /// goes through ear clipping: `O(n)` for a convex polygon of `n` vertices, and for
    /// a concave one `O(n log n)` for polygons as they come (see the module
    /// documentation).
    /// Triangles too thin to have a nonzero normal in `f32` are left out.
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
        self.distinct(points);
        let n = self.idx.len();
        if n < 3 {
            return Err(PolygonError::TooFewVertices { distinct: n });
        }
        let normal = self.project(points)?;
        self.cut();
        let unit = normal.as_vec3();
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

    /// The indices of the distinct vertices into `idx`: consecutive duplicates and
    /// copies of the first vertex at the end left out.
    fn distinct(&mut self, points: &[Vec3]) {
        self.idx.clear();
        for (i, p) in points.iter().enumerate() {
            if self.idx.last().is_none_or(|&l| points[l] != *p) {
                self.idx.push(i);
            }
        }
        while let [first, .., last] = self.idx[..] {
            if points[first] != points[last] {
                break;
            }
            self.idx.pop();
        }
    }

    /// Project the distinct vertices into the ring and link it; the unit Newell normal.
    fn project(&mut self, points: &[Vec3]) -> Result<DVec3, PolygonError> {
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

        // Project onto the plane of the two axes other than the dominant one, in cyclic
        // order, so that the projected signed area has the sign of `normal[k]`.
        let k = normal.abs().max_position();
        let (u, v) = ((k + 1) % 3, (k + 2) % 3);
        let sign = if normal[k] < 0.0 { -1.0 } else { 1.0 };
        self.ring.xy.clear();
        for &i in &self.idx {
            let q = points[i].as_dvec3() - o;
            self.ring.xy.push([q[u], q[v]]);
        }
        self.ring.link(sign);
        Ok(normal / len)
    }

    /// Cut the ring into triangles over distinct-vertex indices, into `tris`.
    fn cut(&mut self) {
        self.tris.clear();
        self.steps = 0;
        let n = self.ring.xy.len();
        let r = &self.ring;
        if n == 3 {
            self.tris.push([0, 1, 2]);
        } else if n == 4 && (0..4).all(|i| r.corner((i + 3) % 4, i, (i + 1) % 4) > 0.0) {
            // Convex quadrilateral: cut along the shorter diagonal.
            if dist2(r.xy[0], r.xy[2]) <= dist2(r.xy[1], r.xy[3]) {
                self.tris.extend([[0, 1, 2], [0, 2, 3]]);
            } else {
                self.tris.extend([[1, 2, 3], [1, 3, 0]]);
            }
        } else {
            self.clip();
        }
    }

    /// Ear clipping into `tris`, after a convex ring has lost its straight vertices.
    fn clip(&mut self) {
        let n = self.ring.xy.len();
        // The convexity check, and the straight vertices' removal, each look at every
        // corner.
        self.steps += n as u64;
        let (start, remaining) = if convex::is_convex(&self.ring) {
            self.steps += n as u64;
            convex::drop_straight(&mut self.ring)
        } else {
            (0, n)
        };
        self.blockers.build(&self.ring);
        self.shortcut.reset(n);
        let clipper = clip::Clipper {
            ring: &mut self.ring,
            blockers: &mut self.blockers,
            shortcut: &mut self.shortcut,
            tris: &mut self.tris,
            steps: &mut self.steps,
        };
        clipper.run(clip::Walk { start, remaining });
    }

    /// What the last triangulation cost: corners tested, steps of the walk, corners,
    /// nodes and vertices the ear tests and their index looked at, and the shortcut's
    /// set operations (each counted as the logarithm of the vertex count).
    #[cfg(test)]
    fn work(&self) -> u64 {
        let log = (self.ring.xy.len().max(2) as u64).ilog2() as u64;
        self.steps + self.blockers.work + self.shortcut.work * log
    }
}

#[inline]
fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}
