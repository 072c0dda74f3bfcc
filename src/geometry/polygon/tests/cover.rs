//! An exact check that triangles tile a simple polygon of the plane z = 0 whose
//! coordinates are dyadic (see `shapes`): every point of the polygon in exactly one
//! triangle and no point outside it in any.
//!
//! In integers (the coordinates times 2²⁴), it checks that every triangle turns the
//! polygon's way and that the triangles' edges, added up as directed segments, give
//! the polygon's boundary: interior edges cancel in pairs, and the edges along the
//! boundary cover each boundary edge once, forwards (an edge may span a straight run of
//! boundary vertices). Then at any point off the edges the triangles containing it
//! number the boundary's winding number about it: 1 inside, 0 outside.

use crate::math::Vec3;

/// The scale that makes the test shapes' coordinates integers.
const SHIFT: i32 = 24;

/// Assert that `tris` (indices into `points`) tile the polygon `points` exactly.
pub fn assert_tiles(points: &[Vec3], tris: &[[usize; 3]]) {
    let q = lattice(points);
    let n = q.len();
    let area2: i128 = (0..n).map(|i| cross(q[i], q[(i + 1) % n])).sum();
    assert_ne!(area2, 0, "the polygon has no area");
    let sign = area2.signum();
    for t in tris {
        assert!(t.iter().all(|&i| i < n), "{t:?} out of range");
        let turn = orient(q[t[0]], q[t[1]], q[t[2]]);
        assert_eq!(turn.signum(), sign, "triangle {t:?} is flat or reversed");
    }
    let runs = Runs::new(&q);
    let mut cover = vec![0i32; n];
    let mut interior: Vec<(usize, usize, i32)> = Vec::new();
    for t in tris {
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            if runs.forward(u, v) {
                let mut i = u;
                while i != v {
                    cover[i] += 1;
                    i = (i + 1) % n;
                }
            } else {
                assert!(
                    !runs.forward(v, u),
                    "edge {u}→{v} runs back along the boundary"
                );
                interior.push((u.min(v), u.max(v), if u < v { 1 } else { -1 }));
            }
        }
    }
    if let Some(i) = cover.iter().position(|&c| c != 1) {
        panic!("boundary edge {i} covered {} times", cover[i]);
    }
    interior.sort_unstable();
    for group in interior.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)) {
        let net: i32 = group.iter().map(|e| e.2).sum();
        assert_eq!(net, 0, "edge {}–{} is not shared", group[0].0, group[0].1);
    }
}

/// The coordinates times 2^SHIFT, which must be integers.
fn lattice(points: &[Vec3]) -> Vec<[i64; 2]> {
    let scale = 2f64.powi(SHIFT);
    let int = |v: f32| {
        let s = v as f64 * scale;
        assert!(
            s.fract() == 0.0 && s.abs() < 2f64.powi(50),
            "{v} is off the grid"
        );
        s as i64
    };
    points
        .iter()
        .map(|p| {
            assert_eq!(p.z, 0.0, "the polygon is not in the plane z = 0");
            [int(p.x), int(p.y)]
        })
        .collect()
}

fn cross(a: [i64; 2], b: [i64; 2]) -> i128 {
    a[0] as i128 * b[1] as i128 - a[1] as i128 * b[0] as i128
}

fn orient(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i128 {
    cross([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]])
}

/// The polygon's straight runs: a vertex continues its run when it lies on the line
/// through its neighbours, between them.
struct Runs {
    n: usize,
    /// For each vertex, the run its outgoing edge belongs to.
    run: Vec<usize>,
    /// For each run, its last vertex.
    end: Vec<usize>,
}

impl Runs {
    fn new(q: &[[i64; 2]]) -> Self {
        let n = q.len();
        let straight = |i: usize| {
            let (a, b, c) = (q[(i + n - 1) % n], q[i], q[(i + 1) % n]);
            let dot = (b[0] - a[0]) as i128 * (c[0] - b[0]) as i128
                + (b[1] - a[1]) as i128 * (c[1] - b[1]) as i128;
            orient(a, b, c) == 0 && dot > 0
        };
        let first = (0..n)
            .find(|&i| !straight(i))
            .expect("a polygon has a corner");
        let mut run = vec![0; n];
        let mut end = Vec::new();
        for k in 0..n {
            let i = (first + k) % n;
            if k > 0 && !straight(i) {
                end.push(i);
            }
            run[i] = end.len();
        }
        end.push(first);
        Runs { n, run, end }
    }

    /// Whether going forwards from `u` reaches `v` within `u`'s run.
    fn forward(&self, u: usize, v: usize) -> bool {
        let r = self.run[u];
        (v != u && self.run[v] == r && self.after(u, v)) || v == self.end[r]
    }

    /// Whether `v` comes after `u` in `u`'s run (both in it).
    fn after(&self, u: usize, v: usize) -> bool {
        let r = self.run[u];
        let start = (self.end[r] + self.n - self.len(r)) % self.n;
        (u + self.n - start) % self.n < (v + self.n - start) % self.n
    }

    /// Edges in run `r`.
    fn len(&self, r: usize) -> usize {
        let prev_end = if r == 0 {
            self.end[self.end.len() - 1]
        } else {
            self.end[r - 1]
        };
        (self.end[r] + self.n - prev_end) % self.n
    }
}
