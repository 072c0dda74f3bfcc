//! The triangles of a chunk of faces moved after the model's, in parallel: the lists
//! of [`Geometry`] that triangles fill, numbered on as [`Geometry::append`] numbers
//! them (normals, texture coordinates and quads by index, origins by triangle). The
//! chunk's geometry is left empty with its lists' memory, to convert another chunk
//! into.

use super::append::{append_list, append_mapped};
use crate::scene::Geometry;

/// Move the triangles of `next` after those of `g`, with their normals, texture
/// coordinates, quads and origins; `next` holds triangles only (as a chunk of faces
/// does) and is left empty.
pub(super) fn append_triangles(g: &mut Geometry, next: &mut Geometry) {
    debug_assert_eq!(next.prim_count(), next.triangles.len());
    let mark = g.mark();
    g.sources.append(&next.sources, &|kind| mark.count(kind));
    next.sources = Default::default();
    let first = g.triangles.len();
    let (normals, uvs, quads) = (g.vertex_normals.len(), g.vertex_uvs.len(), g.quads.len());
    append_list(&mut g.triangles.items, &mut next.triangles.items);
    append_list(&mut g.triangles.material, &mut next.triangles.material);
    append_indices(
        &mut g.triangle_normals,
        &mut next.triangle_normals,
        first,
        normals,
    );
    append_list(&mut g.vertex_normals, &mut next.vertex_normals);
    append_indices(&mut g.triangle_uvs, &mut next.triangle_uvs, first, uvs);
    append_list(&mut g.vertex_uvs, &mut next.vertex_uvs);
    append_indices(
        &mut g.triangle_quads,
        &mut next.triangle_quads,
        first,
        quads,
    );
    append_list(&mut g.quads, &mut next.quads);
}

/// Move `next`, a per-triangle list of indices into a list that had `base` items
/// (`u32::MAX` for none), after `list`, which is per triangle for the first `first`
/// triangles but may be shorter (the rest have none).
fn append_indices(list: &mut Vec<u32>, next: &mut Vec<u32>, first: usize, base: usize) {
    if next.is_empty() {
        return;
    }
    list.resize(first, u32::MAX);
    let base = base as u32;
    let rebase = move |k: u32| {
        if k == u32::MAX {
            k
        } else {
            k.wrapping_add(base)
        }
    };
    append_mapped(list, next, rebase);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Kind, QuadUv, Triangle};
    use crate::math::Vec3;
    use glam::Vec2;
    use std::sync::Arc;

    /// Triangles on lines `lines`: each flat or smooth, with texture coordinates or
    /// not, and the first two halves of a textured quad.
    fn some(lines: std::ops::Range<u32>, file: &Arc<str>) -> Geometry {
        let mut g = Geometry::default();
        for (k, line) in lines.enumerate() {
            let x = line as f32;
            let tri = Triangle {
                p: [Vec3::new(x, 0.0, 0.0), Vec3::Y, Vec3::Z],
            };
            if k % 2 == 0 {
                g.add_smooth_triangle(tri, [Vec3::splat(x); 3], k as u32);
            } else {
                g.add_triangle(tri, k as u32);
            }
            if k % 3 == 0 {
                g.set_triangle_uvs(k, [Vec2::splat(x); 3]);
            }
            g.sources.add(Kind::Triangle, k, 1, file, line);
        }
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let quad = QuadUv::new(p, [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y]).unwrap();
        let q = g.add_quad(quad);
        g.set_triangle_quad(0, q);
        g.set_triangle_quad(1, q);
        g
    }

    #[test]
    fn triangles_move_as_geometry_appends_them() {
        let file: Arc<str> = Arc::from("model.obj");
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        for (a, b) in [(0..5, 5..10), (1..3, 3..9000), (0..9000, 9000..9002)] {
            let mut expected = some(a.clone(), &file);
            expected.append(some(b.clone(), &file), |m| m);
            let mut got = some(a, &file);
            let mut next = some(b, &file);
            pool.install(|| append_triangles(&mut got, &mut next));
            assert_eq!(got, expected);
            assert!(got.sources.same_origins(&expected.sources));
            assert_eq!(next, Geometry::default());
            assert!(next.triangles.items.capacity() > 0);
        }
    }
}
