//! What converting a run of consecutive faces to triangles gives, and how the results
//! of consecutive runs join: in face order, into what converting them all at once
//! gives (the triangles and their normals, texture coordinates, quads and origins
//! numbered on, the bounds, the counts, the first lines noted, and the first error).

use super::located::whole_file;
use super::triangle_lists::append_triangles;
use crate::load::LoadError;
use crate::math::Aabb;
use crate::scene::{Geometry, LoadStats};
use std::path::Path;

/// Smooth triangles a model may have: their normals are numbered by `u32`.
pub(super) const MAX_SMOOTH: usize = u32::MAX as usize;

/// What stopped a conversion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Stop {
    /// A face names a vertex the file does not define (the index checks rule it out).
    MissingVertex,
    /// More smooth triangles than [`MAX_SMOOTH`].
    TooManySmooth,
}

impl Stop {
    /// The error for the file at `path`.
    pub fn error(self, path: &Path) -> LoadError {
        let message = match self {
            Stop::MissingVertex => "internal error: a face names a vertex the file does not define",
            Stop::TooManySmooth => "too many smooth triangles",
        };
        whole_file(path, message.into())
    }
}

/// The triangles of some consecutive faces, with what was noted on the way.
#[derive(Debug, Default)]
pub(super) struct Converted {
    pub geometry: Geometry,
    pub bounds: Aabb,
    pub stats: LoadStats,
    /// Line of the first degenerate face.
    pub first_degenerate: Option<usize>,
    /// Faces with a zero-length normal, and the line of the first.
    pub zero_normals: usize,
    pub first_zero_normal: Option<usize>,
    /// Some triangle has the default material.
    pub default_used: bool,
    /// Smooth triangles added, and the one refused if [`Stop::TooManySmooth`] stopped
    /// the faces (with the smooth triangles before them, the faces would stop at the
    /// first one past [`MAX_SMOOTH`]).
    pub smooth_tried: usize,
    /// What stopped the faces, if something did: the faces after are not converted.
    pub stop: Option<Stop>,
}

impl Converted {
    /// Join the faces that follow: what converting both in a row gives. Nothing is
    /// joined after a stop. Returns `next`'s geometry emptied, with its lists' memory.
    pub fn append(&mut self, mut next: Converted) -> Geometry {
        let mut spare = std::mem::take(&mut next.geometry);
        if self.stop.is_some() {
            return emptied(spare);
        }
        let before = self.geometry.vertex_normals.len();
        if too_many_smooth(before, next.smooth_tried) {
            self.stop = Some(Stop::TooManySmooth);
            return emptied(spare);
        }
        append_triangles(&mut self.geometry, &mut spare);
        self.bounds = self.bounds.union(&next.bounds);
        self.stats.polygons += next.stats.polygons;
        self.stats.degenerate_dropped += next.stats.degenerate_dropped;
        self.first_degenerate = self.first_degenerate.or(next.first_degenerate);
        self.zero_normals += next.zero_normals;
        self.first_zero_normal = self.first_zero_normal.or(next.first_zero_normal);
        self.default_used |= next.default_used;
        self.smooth_tried = before + next.smooth_tried;
        self.stop = next.stop;
        spare
    }
}

/// `g` without its triangles (a chunk's geometry holds nothing else), with its lists'
/// memory.
fn emptied(mut g: Geometry) -> Geometry {
    g.triangles.items.clear();
    g.triangles.material.clear();
    g.triangle_normals.clear();
    g.vertex_normals.clear();
    g.triangle_uvs.clear();
    g.vertex_uvs.clear();
    g.triangle_quads.clear();
    g.quads.clear();
    g.sources = Default::default();
    g
}

/// Whether trying `tried` smooth triangles after `before` of them goes past
/// [`MAX_SMOOTH`].
pub(super) fn too_many_smooth(before: usize, tried: usize) -> bool {
    before.saturating_add(tried) > MAX_SMOOTH
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Triangle;
    use crate::math::Vec3;

    fn one_triangle(x: f32, line: usize) -> Converted {
        let tri = Triangle {
            p: [Vec3::new(x, 0.0, 0.0), Vec3::Y, Vec3::Z],
        };
        let mut c = Converted::default();
        c.geometry.add_smooth_triangle(tri, [Vec3::Z; 3], 0);
        c.bounds = tri.p.iter().fold(Aabb::EMPTY, |b, p| b.grow(*p));
        c.stats.polygons = 1;
        c.first_degenerate = Some(line);
        c.smooth_tried = 1;
        c
    }

    #[test]
    fn joins_in_order_and_keeps_the_first_lines() {
        let mut a = one_triangle(-1.0, 5);
        let spare = a.append(one_triangle(2.0, 9));
        assert_eq!(spare, Geometry::default());
        assert_eq!(a.geometry.triangles.len(), 2);
        assert_eq!(a.geometry.triangle_normals, [0, 1]);
        assert_eq!(a.geometry.triangles.items[1].p[0].x, 2.0);
        assert_eq!((a.bounds.min.x, a.bounds.max.x), (-1.0, 2.0));
        assert_eq!((a.stats.polygons, a.first_degenerate), (2, Some(5)));
        assert_eq!(a.smooth_tried, 2);
    }

    #[test]
    fn nothing_joins_after_a_stop() {
        let mut a = one_triangle(0.0, 1);
        a.stop = Some(Stop::MissingVertex);
        let spare = a.append(one_triangle(1.0, 2));
        assert_eq!(spare, Geometry::default());
        assert!(spare.triangles.items.capacity() > 0);
        assert_eq!(a.geometry.triangles.len(), 1);
        assert_eq!(a.stop, Some(Stop::MissingVertex));
        let mut b = one_triangle(0.0, 1);
        let mut stopped = one_triangle(1.0, 2);
        stopped.stop = Some(Stop::MissingVertex);
        b.append(stopped);
        assert_eq!(b.stop, Some(Stop::MissingVertex));
    }

    #[test]
    fn smooth_triangles_past_the_limit_stop_where_they_would_in_a_row() {
        assert!(!too_many_smooth(MAX_SMOOTH - 1, 1));
        assert!(too_many_smooth(MAX_SMOOTH - 1, 2));
        assert!(too_many_smooth(1, MAX_SMOOTH));
        assert!(!too_many_smooth(0, MAX_SMOOTH));
        assert!(too_many_smooth(usize::MAX, usize::MAX));
        // The limit comes before a stop that follows the smooth triangles tried.
        let mut a = one_triangle(0.0, 1);
        let mut next = one_triangle(1.0, 2);
        next.smooth_tried = MAX_SMOOTH;
        next.stop = Some(Stop::MissingVertex);
        a.append(next);
        assert_eq!(a.stop, Some(Stop::TooManySmooth));
        assert_eq!(a.geometry.triangles.len(), 1);
    }
}
