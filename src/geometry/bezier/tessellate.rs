//! Adaptive, crack-free tessellation of bicubic patches into smooth triangles; the
//! scheme is described in the documentation of the parent module.

use super::curve::{canonical, cubic_chord_error_bound, cubic_eval, cubic_split};
use super::patch::BezierPatch;
use crate::geometry::Triangle;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;

/// The largest subdivision level of a patch grid or edge in each direction:
/// `2⁸ = 256` segments. A tolerance that would need more is not met; the mesh then
/// reports its actual bound in [`TriMesh::error_bound`].
pub const MAX_LEVEL: u32 = 8;

/// A triangle mesh with smooth-shading normals, as [`tessellate`] makes it.
///
/// Vertices are not shared between patches: a vertex on a seam appears once per
/// patch, with the same position bit for bit and that patch's normal (so creases keep
/// their two normals). Triangles are counterclockwise in the patch's `(u, v)` plane, so
/// `(p1 − p0) × (p2 − p0)` points the way of the patch normal `∂P/∂u × ∂P/∂v` (up to
/// the error the tolerance allows: only where a triangle spans a fold tighter than
/// the tolerance can a vertex normal be more than 90° from its face).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions: points of the patches, rounded to `f32`.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals from the patch derivatives ([`BezierPatch::normal`]; at a
    /// collapsed edge, the limit from inside the patch).
    pub normals: Vec<Vec3>,
    /// Each vertex's patch parameters `(u, v)`: dyadic, so exact in `f32`.
    pub uvs: Vec<[f32; 2]>,
    /// Vertex indices, three per triangle.
    pub triangles: Vec<[u32; 3]>,
    /// For each triangle, the index of its patch in the input slice (and so of the
    /// patch its vertices' `uvs` refer to).
    pub triangle_patch: Vec<u32>,
    /// An upper bound on the distance between any point of a triangle and the surface
    /// point at the same `(u, v)`, before rounding the vertices to `f32`. At most the
    /// tolerance unless [`MAX_LEVEL`] was reached.
    pub error_bound: f64,
}

impl TriMesh {
    /// Triangle `i` as a [`Triangle`] for intersection.
    pub fn triangle(&self, i: usize) -> Triangle {
        Triangle {
            p: self.triangles[i].map(|k| self.positions[k as usize]),
        }
    }
}

/// Tessellate `patches` into one mesh whose distance from the surface, measured
/// between points at the same patch parameters, is at most `tolerance` (a distance in
/// scene units); see the [module documentation](crate::geometry::bezier) for the scheme. Patches that
/// share a boundary edge with bitwise equal control points (in either order) meet
/// without cracks. Triangles that collapse to a segment because two of their vertices
/// coincide (at an edge collapsed to a point) are left out.
///
/// # Panics
/// If `tolerance` is not a positive finite number.
pub fn tessellate(patches: &[BezierPatch], tolerance: f64) -> TriMesh {
    assert!(
        tolerance > 0.0 && tolerance.is_finite(),
        "tessellation tolerance must be positive and finite, not {tolerance}"
    );
    let mut plans: Vec<Plan> = patches.par_iter().map(|p| plan(p, tolerance)).collect();
    reconcile(patches, &mut plans);
    let parts: Vec<PatchMesh> = patches
        .par_iter()
        .zip(&plans)
        .map(|(p, plan)| build(p, plan))
        .collect();
    let mut mesh = TriMesh::default();
    for (index, part) in parts.into_iter().enumerate() {
        let offset = mesh.positions.len() as u32;
        mesh.positions.extend(part.positions);
        mesh.normals.extend(part.normals);
        mesh.uvs.extend(part.uvs);
        let count = mesh.triangles.len() + part.triangles.len();
        mesh.triangle_patch.resize(count, index as u32);
        mesh.triangles
            .extend(part.triangles.iter().map(|t| t.map(|k| k + offset)));
        mesh.error_bound = mesh.error_bound.max(part.bound);
    }
    mesh
}

/// A patch boundary, in the order bottom (`v = 0`), right (`u = 1`), top (`v = 1`),
/// left (`u = 0`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Bottom = 0,
    Right = 1,
    Top = 2,
    Left = 3,
}

const SIDES: [Side; 4] = [Side::Bottom, Side::Right, Side::Top, Side::Left];

/// The control polygon of a boundary, in the direction of its increasing parameter.
fn edge_points(p: &BezierPatch, side: Side) -> [DVec3; 4] {
    let p = &p.p;
    match side {
        Side::Bottom => [p[0][0], p[1][0], p[2][0], p[3][0]],
        Side::Top => [p[0][3], p[1][3], p[2][3], p[3][3]],
        Side::Left => p[0],
        Side::Right => p[3],
    }
}

/// The patch parameters of the point at `t` along a boundary.
fn edge_uv(side: Side, t: f64) -> (f64, f64) {
    match side {
        Side::Bottom => (t, 0.0),
        Side::Top => (t, 1.0),
        Side::Left => (0.0, t),
        Side::Right => (1.0, t),
    }
}

/// The subdivision level of an edge: the depth at which every piece of its canonical
/// control polygon has a chord error bound within `limit` (capped at [`MAX_LEVEL`]).
/// The same for the polygon and its reverse.
fn edge_level(points: [DVec3; 4], limit: f64) -> u32 {
    fn level(p: &[DVec3; 4], limit: f64, depth: u32) -> u32 {
        if depth >= MAX_LEVEL || cubic_chord_error_bound(p) <= limit {
            return 0;
        }
        let (l, r) = cubic_split(p, 0.5);
        1 + level(&l, limit, depth + 1).max(level(&r, limit, depth + 1))
    }
    level(&canonical(points).0, limit, 0)
}

/// Vertex `k` of `2ᵉ` along an edge (in the edge's own direction), evaluated on the
/// canonical polygon so that both patches sharing the edge get the same bits.
fn edge_vertex(points: [DVec3; 4], k: u32, level: u32) -> DVec3 {
    let n = 1u32 << level;
    let (c, reversed) = canonical(points);
    let k = if reversed { n - k } else { k };
    cubic_eval(&c, f64::from(k) / f64::from(n))
}

/// Halve `p` in `v` `b` times and in `u` `a` times: the `2ᵃ × 2ᵇ` cell patches, cell
/// `(i, j)` at index `j·2ᵃ + i`.
fn grid(p: &BezierPatch, a: u32, b: u32) -> Vec<BezierPatch> {
    let mut rows = vec![*p];
    for _ in 0..b {
        rows = rows
            .iter()
            .flat_map(|q| {
                let (l, r) = q.split_v(0.5);
                [l, r]
            })
            .collect();
    }
    let mut cells = Vec::with_capacity(rows.len() << a);
    for row in rows {
        let mut line = vec![row];
        for _ in 0..a {
            line = line
                .iter()
                .flat_map(|q| {
                    let (l, r) = q.split_u(0.5);
                    [l, r]
                })
                .collect();
        }
        cells.extend(line);
    }
    cells
}

/// The rectangles of the stitched strip along `side`: the ring of width `2⁻ᵈᵉᵖᵗʰ`
/// next to it, cut into the edge's `2ᵉ` segments.
fn strip(p: &BezierPatch, side: Side, depth: u32, edge_level: u32) -> Vec<BezierPatch> {
    let mut q = *p;
    for _ in 0..depth {
        q = match side {
            Side::Bottom => q.split_v(0.5).0,
            Side::Top => q.split_v(0.5).1,
            Side::Left => q.split_u(0.5).0,
            Side::Right => q.split_u(0.5).1,
        };
    }
    match side {
        Side::Bottom | Side::Top => grid(&q, edge_level, 0),
        Side::Left | Side::Right => grid(&q, 0, edge_level),
    }
}

/// How one patch is cut: grid levels `a` (along `u`) and `b` (along `v`), the edge
/// levels (in [`Side`] order), and the error bound this achieves.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Plan {
    a: u32,
    b: u32,
    edges: [u32; 4],
    bound: f64,
}

/// The worst bound over the rectangles `nets`, and the directions whose refinement
/// would reduce a bound over `tol` (the direction that dominates each failing
/// rectangle's bound: `D_uu` against `D_vv`).
fn worst(nets: &[BezierPatch], tol: f64) -> (f64, bool, bool) {
    let mut r = (0.0f64, false, false);
    for q in nets {
        let bound = q.triangle_error_bound();
        r.0 = r.0.max(bound);
        if bound > tol {
            let (uu, vv, _) = q.second_differences();
            r.1 |= uu >= vv;
            r.2 |= vv >= uu;
        }
    }
    r
}

/// Whether every rectangle of `nets` is within `tol`.
fn all_within(nets: &[BezierPatch], tol: f64) -> bool {
    nets.iter().all(|q| q.triangle_error_bound() <= tol)
}

/// The error bound of the layout with grid levels `(a, b)` and edge levels `e`: the
/// worst bound over a set of parameter rectangles that between them hold every
/// triangle.
fn layout_bound(p: &BezierPatch, a: u32, b: u32, e: &[u32; 4]) -> f64 {
    let [bottom, right, top, left] = *e;
    let max = |nets: Vec<BezierPatch>| worst(&nets, f64::INFINITY).0;
    match (a, b) {
        // One strip joining the two u edges: rectangles of the coarser edge's segments.
        (_, 0) => max(grid(p, bottom.min(top), 0)),
        (0, _) => max(grid(p, 0, left.min(right))),
        _ => {
            let mut bound = max(strip(p, Side::Bottom, b, bottom))
                .max(max(strip(p, Side::Top, b, top)))
                .max(max(strip(p, Side::Left, a, left)))
                .max(max(strip(p, Side::Right, a, right)));
            let (nu, nv) = (1usize << a, 1usize << b);
            if nu > 2 && nv > 2 {
                let cells = grid(p, a, b);
                for j in 1..nv - 1 {
                    bound = bound.max(max(cells[j * nu + 1..(j + 1) * nu - 1].to_vec()));
                }
            }
            bound
        }
    }
}

/// What one patch needs on its own: the coarsest grid whose cells are all within
/// `tol`, refined in the direction that dominates the failing cells' bounds, and for
/// each edge the coarsest level (at least what the edge alone needs) whose stitched
/// strip is within `tol` on that grid. The edge levels may still be raised by the
/// neighbours; that only shrinks the rectangles the bound is taken over.
fn plan(p: &BezierPatch, tol: f64) -> Plan {
    let floor = SIDES.map(|s| edge_level(edge_points(p, s), tol));
    let [fb, fr, ft, fl] = floor;
    let (mut a, mut b) = (fb.max(ft), fl.max(fr));
    loop {
        let (bound, grow_a, grow_b) = worst(&grid(p, a, b), tol);
        let grow_a = grow_a && a < MAX_LEVEL;
        let grow_b = grow_b && b < MAX_LEVEL;
        if bound <= tol || !(grow_a || grow_b) {
            break;
        }
        a += u32::from(grow_a);
        b += u32::from(grow_b);
    }
    // The coarsest level in `from..=to` at which `nets(level)` are within `tol`;
    // `to` (where the strip is the grid's own ring of cells) if none is.
    let coarsest = |from: u32, to: u32, nets: &dyn Fn(u32) -> Vec<BezierPatch>| {
        (from..=to)
            .find(|&e| all_within(&nets(e), tol))
            .unwrap_or(to)
            .max(from)
    };
    let edges = match (a, b) {
        (_, 0) => {
            let c = coarsest(0, a, &|e| grid(p, e, 0));
            [fb.max(c), fr, ft.max(c), fl]
        }
        (0, _) => {
            let c = coarsest(0, b, &|e| grid(p, 0, e));
            [fb, fr.max(c), ft, fl.max(c)]
        }
        _ => [
            coarsest(fb, a, &|e| strip(p, Side::Bottom, b, e)),
            coarsest(fr, b, &|e| strip(p, Side::Right, a, e)),
            coarsest(ft, a, &|e| strip(p, Side::Top, b, e)),
            coarsest(fl, b, &|e| strip(p, Side::Left, a, e)),
        ],
    };
    Plan {
        a,
        b,
        edges,
        bound: layout_bound(p, a, b, &edges),
    }
}

/// An edge's identity: the bits of its canonical control polygon, the same for the
/// two patches that share it whichever way round they run along it.
type EdgeKey = [[u64; 3]; 4];

fn edge_key(points: [DVec3; 4]) -> EdgeKey {
    canonical(points).0.map(|q| q.to_array().map(f64::to_bits))
}

/// Make the plans agree along shared edges: each edge gets the finest level any of
/// its patches asked for, and each grid grows to be at least as fine as its edges.
fn reconcile(patches: &[BezierPatch], plans: &mut [Plan]) {
    let mut levels: HashMap<EdgeKey, u32> = HashMap::new();
    for (p, plan) in patches.iter().zip(plans.iter()) {
        for side in SIDES {
            let level = levels.entry(edge_key(edge_points(p, side))).or_default();
            *level = (*level).max(plan.edges[side as usize]);
        }
    }
    for (p, plan) in patches.iter().zip(plans.iter_mut()) {
        let edges = SIDES.map(|side| levels[&edge_key(edge_points(p, side))]);
        if edges != plan.edges {
            let [bottom, right, top, left] = edges;
            plan.a = plan.a.max(bottom).max(top);
            plan.b = plan.b.max(left).max(right);
            plan.edges = edges;
            plan.bound = layout_bound(p, plan.a, plan.b, &edges);
        }
    }
}

/// One patch's share of the mesh.
struct PatchMesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<[f32; 2]>,
    triangles: Vec<[u32; 3]>,
    bound: f64,
}

/// Vertices of one patch under construction, one per parameter point.
#[derive(Default)]
struct Vertices {
    index: HashMap<(u64, u64), u32>,
    positions: Vec<Vec3>,
    uvs: Vec<(f64, f64)>,
}

impl Vertices {
    /// The vertex at `(u, v)`, created at `position` if new.
    fn at(&mut self, u: f64, v: f64, position: impl FnOnce() -> DVec3) -> u32 {
        let next = self.positions.len() as u32;
        *self
            .index
            .entry((u.to_bits(), v.to_bits()))
            .or_insert_with(|| {
                // `+ 0.0` turns a −0 into +0, so that equal positions have equal bits.
                self.positions.push((position() + DVec3::ZERO).as_vec3());
                self.uvs.push((u, v));
                next
            })
    }
}

/// Triangulate between a coarse chain of `c + 1` vertices and a fine chain of `f + 1`
/// parameter positions (`c` divides `f`) of which `first..=last` exist: one fan
/// polygon per coarse segment, all its triangles within that segment's span.
fn stitch(coarse: &[u32], fine: &[u32], first: usize, last: usize, out: &mut Vec<[u32; 3]>) {
    let c = coarse.len() - 1;
    let f = fine.len() - 1;
    let r = f / c;
    debug_assert_eq!(r * c, f);
    for k in 0..c {
        let lo = (k * r).max(first);
        let hi = ((k + 1) * r).min(last);
        let m = (k * r + r / 2).clamp(lo, hi);
        for i in lo..m {
            out.push([coarse[k], fine[i], fine[i + 1]]);
        }
        out.push([coarse[k], coarse[k + 1], fine[m]]);
        for i in m..hi {
            out.push([coarse[k + 1], fine[i], fine[i + 1]]);
        }
    }
}

/// Build the triangles of one patch as `plan` says.
fn build(p: &BezierPatch, plan: &Plan) -> PatchMesh {
    let mut verts = Vertices::default();
    let chain = |verts: &mut Vertices, side: Side| -> Vec<u32> {
        let level = plan.edges[side as usize];
        let points = edge_points(p, side);
        let n = 1u32 << level;
        (0..=n)
            .map(|k| {
                let (u, v) = edge_uv(side, f64::from(k) / f64::from(n));
                verts.at(u, v, || edge_vertex(points, k, level))
            })
            .collect()
    };
    let bottom = chain(&mut verts, Side::Bottom);
    let right = chain(&mut verts, Side::Right);
    let top = chain(&mut verts, Side::Top);
    let left = chain(&mut verts, Side::Left);

    let mut tris = Vec::new();
    let strip_between = |x: &[u32], y: &[u32], tris: &mut Vec<[u32; 3]>| {
        let (coarse, fine) = if x.len() <= y.len() { (x, y) } else { (y, x) };
        stitch(coarse, fine, 0, fine.len() - 1, tris);
    };
    match (plan.a, plan.b) {
        (_, 0) => strip_between(&bottom, &top, &mut tris),
        (0, _) => strip_between(&left, &right, &mut tris),
        (a, b) => {
            let (nu, nv) = (1usize << a, 1usize << b);
            // Interior grid vertices; index [j][i], the boundary entries unused.
            let mut g = vec![vec![u32::MAX; nu + 1]; nv + 1];
            for (j, row) in g.iter_mut().enumerate().take(nv).skip(1) {
                for (i, x) in row.iter_mut().enumerate().take(nu).skip(1) {
                    let (u, v) = (i as f64 / nu as f64, j as f64 / nv as f64);
                    *x = verts.at(u, v, || p.eval(u, v));
                }
            }
            let column = |i: usize| -> Vec<u32> { g.iter().map(|row| row[i]).collect() };
            stitch(&bottom, &g[1], 1, nu - 1, &mut tris);
            stitch(&top, &g[nv - 1], 1, nu - 1, &mut tris);
            stitch(&left, &column(1), 1, nv - 1, &mut tris);
            stitch(&right, &column(nu - 1), 1, nv - 1, &mut tris);
            for j in 1..nv - 1 {
                for i in 1..nu - 1 {
                    let (a, b, c, d) = (g[j][i], g[j][i + 1], g[j + 1][i + 1], g[j + 1][i]);
                    let pos = |k: u32| verts.positions[k as usize];
                    if pos(a).distance_squared(pos(c)) <= pos(b).distance_squared(pos(d)) {
                        tris.push([a, b, c]);
                        tris.push([a, c, d]);
                    } else {
                        tris.push([a, b, d]);
                        tris.push([b, c, d]);
                    }
                }
            }
        }
    }
    finish(p, verts, tris, plan.bound)
}

/// Orient the triangles counterclockwise in parameter space, drop those with two
/// coincident vertices, drop unused vertices, and compute the normals.
fn finish(p: &BezierPatch, verts: Vertices, tris: Vec<[u32; 3]>, bound: f64) -> PatchMesh {
    let uv = |k: u32| verts.uvs[k as usize];
    let pos = |k: u32| verts.positions[k as usize];
    let mut kept = Vec::with_capacity(tris.len());
    for [a, b, c] in tris {
        let ((u0, v0), (u1, v1), (u2, v2)) = (uv(a), uv(b), uv(c));
        // Exact: the parameters are dyadic with small denominators.
        let area = (u1 - u0) * (v2 - v0) - (v1 - v0) * (u2 - u0);
        debug_assert!(area != 0.0, "parameter-space triangle is flat");
        let t = if area > 0.0 { [a, b, c] } else { [a, c, b] };
        let [x, y, z] = t.map(pos);
        if x != y && y != z && z != x {
            kept.push(t);
        }
    }
    // Renumber the vertices in use.
    let mut new_index = vec![u32::MAX; verts.positions.len()];
    let mut mesh = PatchMesh {
        positions: Vec::new(),
        normals: Vec::new(),
        uvs: Vec::new(),
        triangles: Vec::with_capacity(kept.len()),
        bound,
    };
    for t in &kept {
        mesh.triangles.push(t.map(|k| {
            let slot = &mut new_index[k as usize];
            if *slot == u32::MAX {
                *slot = mesh.positions.len() as u32;
                let (u, v) = verts.uvs[k as usize];
                mesh.positions.push(verts.positions[k as usize]);
                mesh.uvs.push([u as f32, v as f32]);
                mesh.normals.push(p.normal(u, v).as_vec3());
            }
            *slot
        }));
    }
    // A vertex where the patch has no tangent plane at all gets the mean of its
    // triangles' normals.
    if mesh.normals.contains(&Vec3::ZERO) {
        let mut sum = vec![Vec3::ZERO; mesh.positions.len()];
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
            let n = (b - a).cross(c - a);
            for k in t {
                sum[*k as usize] += n;
            }
        }
        for (n, s) in mesh.normals.iter_mut().zip(sum) {
            if *n == Vec3::ZERO {
                *n = s.normalize_or_zero();
            }
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wavy(amplitude: f64) -> BezierPatch {
        BezierPatch::new(std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let z = amplitude * ((i * 3 + j * 5) % 4) as f64;
                DVec3::new(i as f64, j as f64, z)
            })
        }))
    }

    /// Every layout tiles the parameter square: positive, non-overlapping triangles
    /// whose parameter areas sum to 1, and whose interior edges pair up.
    #[test]
    fn layouts_tile_the_parameter_square() {
        let p = wavy(0.0);
        for a in 0..4 {
            for b in 0..4 {
                for edges in [[0, 0, 0, 0], [a, b, a, b], [a.min(1), b, 0, b.min(2)]] {
                    let plan = Plan {
                        a,
                        b,
                        edges,
                        bound: 0.0,
                    };
                    // With a = 0 the u edges have one segment (the grid is never
                    // coarser than an edge).
                    if edges[0] > a || edges[2] > a || edges[1] > b || edges[3] > b {
                        continue;
                    }
                    let m = build(&p, &plan);
                    let mut area = 0.0;
                    let mut edge_use: HashMap<(u32, u32), i32> = HashMap::new();
                    for t in &m.triangles {
                        let [x, y, z] = t.map(|k| m.uvs[k as usize].map(f64::from));
                        let a2 = (y[0] - x[0]) * (z[1] - x[1]) - (y[1] - x[1]) * (z[0] - x[0]);
                        assert!(a2 > 0.0, "{plan:?}: clockwise triangle");
                        area += a2 / 2.0;
                        for (s, e) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                            // Directed edges: a shared edge is used once each way.
                            *edge_use.entry((s, e)).or_default() += 1;
                            *edge_use.entry((e, s)).or_default() -= 1;
                        }
                    }
                    assert!((area - 1.0).abs() < 1e-12, "{plan:?}: area {area}");
                    // Unmatched directed edges are exactly the boundary segments.
                    let open = edge_use.values().filter(|&&n| n != 0).count() / 2;
                    let boundary: usize = edges.iter().map(|e| 1usize << e).sum();
                    assert_eq!(open, boundary, "{plan:?}");
                    let expected_triangles = if a == 0 || b == 0 {
                        // A strip: one triangle per segment of either chain.
                        if b == 0 {
                            (1usize << edges[0]) + (1 << edges[2])
                        } else {
                            (1usize << edges[1]) + (1 << edges[3])
                        }
                    } else {
                        2 * (1usize << (a + b)) - 2 * ((1 << a) + (1 << b))
                            + edges.iter().map(|e| 1usize << e).sum::<usize>()
                    };
                    assert_eq!(m.triangles.len(), expected_triangles, "{plan:?}");
                }
            }
        }
    }

    #[test]
    fn edge_levels_do_not_depend_on_direction() {
        let p = wavy(0.3);
        for side in SIDES {
            let pts = edge_points(&p, side);
            let mut rev = pts;
            rev.reverse();
            for tol in [1.0, 0.1, 0.01, 1e-4] {
                assert_eq!(edge_level(pts, tol), edge_level(rev, tol));
            }
            for level in 0..5 {
                let n = 1u32 << level;
                for k in 0..=n {
                    assert_eq!(
                        edge_vertex(pts, k, level).to_array().map(f64::to_bits),
                        edge_vertex(rev, n - k, level).to_array().map(f64::to_bits)
                    );
                }
            }
        }
    }

    /// The teapot exercises what the crack tests rely on: edges stitched to a finer
    /// grid, and shared edges between patches whose grids differ along them.
    #[test]
    fn the_teapot_needs_stitching_and_shared_edge_levels() {
        let patches = super::super::teapot_patches();
        let tol = 0.01;
        let mut plans: Vec<Plan> = patches.iter().map(|p| plan(p, tol)).collect();
        let own = plans.clone();
        reconcile(&patches, &mut plans);
        let grid_along = |plan: &Plan, side: Side| match side {
            Side::Bottom | Side::Top => plan.a,
            Side::Left | Side::Right => plan.b,
        };
        let mut stitched = 0;
        let mut raised = 0;
        let mut by_edge: HashMap<EdgeKey, Vec<u32>> = HashMap::new();
        for ((p, plan), before) in patches.iter().zip(&plans).zip(&own) {
            assert!(plan.bound <= tol, "{plan:?}");
            for side in SIDES {
                let e = plan.edges[side as usize];
                assert!(e <= grid_along(plan, side));
                stitched += usize::from(e < grid_along(plan, side));
                raised += usize::from(e > before.edges[side as usize]);
                by_edge
                    .entry(edge_key(edge_points(p, side)))
                    .or_default()
                    .push(grid_along(plan, side));
            }
        }
        assert!(stitched > 10, "{stitched} stitched edges");
        assert!(raised > 0, "no edge raised by its neighbour");
        let differing = by_edge
            .values()
            .filter(|g| g.len() == 2 && g[0] != g[1])
            .count();
        assert!(differing > 0, "no shared edge between different grids");
        // An empty input is an empty mesh.
        assert_eq!(tessellate(&[], tol), TriMesh::default());
    }

    #[test]
    fn plans_meet_the_tolerance_and_refine_with_it() {
        let p = wavy(0.4);
        let mut last = (0, 0);
        for tol in [0.5, 0.1, 0.02, 0.004] {
            let plan = plan(&p, tol);
            assert!(plan.bound <= tol, "{plan:?} for {tol}");
            assert!(plan.a >= last.0 && plan.b >= last.1);
            assert!(plan.a + plan.b > last.0 + last.1, "{plan:?}");
            last = (plan.a, plan.b);
        }
        // The cap stops refinement short of an unreachable tolerance.
        let plan = plan(&p, 1e-12);
        assert_eq!((plan.a, plan.b), (MAX_LEVEL, MAX_LEVEL));
        assert!(plan.bound > 1e-12);
    }
}
