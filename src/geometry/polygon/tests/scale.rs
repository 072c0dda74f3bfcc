//! Large polygons: the work of a triangulation (corners tested, steps of the walk,
//! nodes and vertices the ear tests look at) grows linearly with the vertex count for
//! convex polygons and as `n log n` for concave ones, and the triangles tile the
//! polygon exactly. Work, not time, is asserted, so the tests hold on any machine and
//! in a debug build.

use super::super::Triangulator;
use super::cover::assert_tiles;
use super::shapes::*;
use crate::math::Vec3;

/// Triangulate `points`: the triangles and the work done.
fn run(points: &[Vec3]) -> (Vec<[usize; 3]>, u64) {
    let mut t = Triangulator::new();
    let mut out = Vec::new();
    t.triangulate(points, &mut out).expect("a triangulation");
    (out, t.work())
}

/// Assert `work` is at most `per_vertex` per vertex of `points`.
fn assert_linear(name: &str, points: &[Vec3], work: u64, per_vertex: u64) {
    let n = points.len() as u64;
    assert!(
        work <= per_vertex * n,
        "{name}: {work} units of work for {n} vertices, more than {per_vertex} each"
    );
}

/// Assert `work` is at most `k · n · log₂ n` for the `n` vertices of `points`.
fn assert_n_log_n(name: &str, points: &[Vec3], work: u64, k: u64) {
    let n = points.len() as u64;
    let log = n.ilog2() as u64;
    assert!(
        work <= k * n * log,
        "{name}: {work} units of work for {n} vertices, more than {k} n log₂ n"
    );
}

#[test]
fn convex_100k_vertices() {
    let p = farey(203);
    assert!(p.len() >= 100_000, "{}", p.len());
    let (tris, work) = run(&p);
    assert_eq!(tris.len(), p.len() - 2);
    assert_tiles(&p, &tris);
    // The convexity check, the index's build (empty) and a step per vertex: nothing
    // can block an ear.
    assert_linear("convex", &p, work, 5);
}

#[test]
fn convex_1m_vertices_with_collinear_runs() {
    // No convex polygon of a million vertices has f32 coordinates and no three vertices
    // in a line (a convex polygon on a grid of 2²⁵ × 2²⁵ points has at most about
    // 600 000 vertices): this one is 25 000 corners with 39 vertices along each edge.
    let corners = farey(101);
    let p = subdivided(&corners, 40);
    assert!(p.len() >= 1_000_000, "{}", p.len());
    let (tris, work) = run(&p);
    assert!(tris.len() >= corners.len() - 2 && tris.len() <= p.len() - 2);
    assert_tiles(&p, &tris);
    assert_linear("convex with collinear vertices", &p, work, 5);
}

#[test]
fn concave_100k_vertices() {
    for (name, p) in [
        ("star", exact_spiky_star(143, 3)),
        ("comb", exact_comb(287, 1 << 20)),
        ("spiral", exact_spiral(200, 250)),
    ] {
        assert!(p.len() >= 100_000, "{name}: {}", p.len());
        let (tris, work) = run(&p);
        assert_eq!(tris.len(), p.len() - 2, "{name}");
        assert_tiles(&p, &tris);
        assert_n_log_n(name, &p, work, 16);
    }
}
