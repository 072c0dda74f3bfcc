//! The `teapot` database: Newell's teapot on a checkerboard (SPD `teapot.c`).
//!
//! The teapot is the 32 bicubic Bézier patches of Newell's 1975 data (rim, body,
//! handle, spout, lid and bottom), each tessellated into `size × size` quadrilaterals
//! of parameter space, each split into two triangles and written as a `pp` patch
//! whose vertex normals come from the cross product of the surface's partial
//! derivatives. The lid and bottom patches have a whole control row collapsed onto
//! the axis (a cusp): a triangle with two vertices on the cusp is degenerate and is
//! not written, and a single cusp vertex gets the normal `(0, 0, ±1)`. The floor is a
//! `size × size` checkerboard of `p` squares in two materials, white ones first.
//!
//! Counts: `64·size² − 8·size` triangles (8 cusp patches lose one triangle per
//! parameter column) and `size²` squares.
//!
//! Every quantity is computed as the SPD program does: the patch geometry matrix
//! `M·G·Mᵀ` per coordinate, power vectors `[s³, s², s, 1]` and their derivatives,
//! row-vector × matrix products summed left to right, then a 4-element dot product,
//! so that the printed rounding noise (e.g. normals `1.4538e-15 -1.67359e-15 1`)
//! comes out the same.

use super::{NffSink, phong_power};
use crate::geometry::bezier::newell::{PATCHES, VERTS};
use glam::DVec3;

/// The SPD program's default size factor.
pub const DEFAULT_SIZE: u32 = 12;

type Mat4 = [[f64; 4]; 4];

/// The cubic Bézier basis in power form (symmetric, so it is its own transpose).
const BEZIER_BASIS: Mat4 = [
    [-1.0, 3.0, -3.0, 1.0],
    [3.0, -6.0, 3.0, 0.0],
    [-3.0, 3.0, 0.0, 0.0],
    [1.0, 0.0, 0.0, 0.0],
];

const TEAPOT_COLOR: DVec3 = DVec3::new(1.0, 0.5, 0.1);
const LIGHT_SQUARES: DVec3 = DVec3::new(1.0, 1.0, 1.0);
const DARK_SQUARES: DVec3 = DVec3::new(0.5, 0.5, 0.5);

/// Write the database at size factor `size` (the number of subdivisions of each patch
/// parameter and of each side of the floor).
pub fn generate(size: u32, w: &mut impl NffSink) {
    w.background(DVec3::new(0.078, 0.361, 0.753));
    w.viewpoint(
        DVec3::new(4.86, 7.2, 5.4),
        DVec3::ZERO,
        DVec3::new(0.0, 0.0, 1.0),
        45.0,
        1.0,
        (512, 512),
    );
    w.light(DVec3::new(-3.1, 9.8, 12.1));
    w.light(DVec3::new(11.3, 5.1, 8.8));
    checkerboard(size, w);
    teapot(size, w);
}

/// A material the way the SPD library writes it for NFF: colour, Kd, Ks, Shine (from
/// the highlight angle), no transmission.
fn material(w: &mut impl NffSink, color: DVec3, kd: f64, ks: f64, angle_deg: f64) {
    w.fill(color, kd, ks, phong_power(angle_deg), 0.0, 0.0);
}

/// The floor: a `size × size` checkerboard on `z = 0` spanning `[-4, 4]²`, the squares
/// with odd `i + j` first (white), then the even ones (grey).
fn checkerboard(size: u32, w: &mut impl NffSink) {
    for (color, parity) in [(LIGHT_SQUARES, 1), (DARK_SQUARES, 0)] {
        material(w, color, 0.5, 0.5, 30.0);
        for i in 0..size {
            for j in 0..size {
                if (i + j) % 2 == parity {
                    w.polygon(&square(i, j, size));
                }
            }
        }
    }
}

/// Square `(i, j)` of the floor, counterclockwise from its low corner.
fn square(i: u32, j: u32, size: u32) -> [DVec3; 4] {
    let n = f64::from(size);
    let coord = |k: u32| 4.0 * (2.0 * f64::from(k) / n - 1.0);
    let corner = |di: u32, dj: u32| DVec3::new(coord(i + di), coord(j + dj), 0.0);
    [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
}

/// Corner `k` of a parameter cell, counterclockwise from `(0, 0)`: `(0,0)`, `(0,1)`,
/// `(1,1)`, `(1,0)` as (`s` step, `t` step).
fn cell_corner(k: usize) -> (u32, u32) {
    (u32::from(k >= 2), u32::from(k == 1 || k == 2))
}

/// The teapot: every patch, every parameter cell, two triangles per cell (corners
/// 0-1-2 and 2-3-0), skipping triangles degenerate at a cusp. Each grid point of a
/// patch is evaluated once, for the cells around it.
fn teapot(size: u32, w: &mut impl NffSink) {
    material(w, TEAPOT_COLOR, 0.75, 0.25, 37.0);
    let n = f64::from(size);
    let side = size as usize + 1;
    let mut grid = Vec::with_capacity(side * side);
    for index in 0..PATCHES.len() {
        let patch = Patch::new(index);
        grid.clear();
        for si in 0..=size {
            for ti in 0..=size {
                let e = patch.eval(f64::from(si) / n, f64::from(ti) / n);
                grid.push((e.point, e.normal()));
            }
        }
        for si in 0..size {
            for ti in 0..size {
                for tri in 0..2 {
                    let mut verts = [DVec3::ZERO; 3];
                    let mut norms = [DVec3::ZERO; 3];
                    for v in 0..3 {
                        let (ds, dt) = cell_corner((v + 2 * tri) % 4);
                        let k = (si + ds) as usize * side + (ti + dt) as usize;
                        (verts[v], norms[v]) = grid[k];
                    }
                    if fix_cusp(&verts, &mut norms) {
                        w.polypatch(&verts, &norms);
                    }
                }
            }
        }
    }
}

/// Whether a point lies on the teapot's axis (a lid or bottom cusp).
fn on_axis(p: DVec3) -> bool {
    p.x.abs() < 0.0001 && p.y.abs() < 0.0001
}

/// A triangle with two or more vertices on the axis is degenerate: `false`. With one,
/// that vertex's (zero) normal becomes straight up at the lid, straight down at the
/// bottom.
fn fix_cusp(verts: &[DVec3; 3], norms: &mut [DVec3; 3]) -> bool {
    let mut on = (0..3).filter(|&i| on_axis(verts[i]));
    match (on.next(), on.next()) {
        (None, _) => true,
        (Some(k), None) => {
            let z = if verts[k].z > 1.5 { 1.0 } else { -1.0 };
            norms[k] = DVec3::new(0.0, 0.0, z);
            true
        }
        (Some(_), Some(_)) => false,
    }
}

/// `a · b` for 4×4 matrices, each entry summed left to right.
fn mat_mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut r = [[0.0; 4]; 4];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] + a[i][3] * b[3][j];
        }
    }
    r
}

fn transpose(m: &Mat4) -> Mat4 {
    let mut r = [[0.0; 4]; 4];
    for (i, row) in m.iter().enumerate() {
        for (j, x) in row.iter().enumerate() {
            r[j][i] = *x;
        }
    }
    r
}

/// Row vector times matrix: `v · m`.
fn row_times(v: &[f64; 4], m: &Mat4) -> [f64; 4] {
    let mut r = [0.0; 4];
    for (j, x) in r.iter_mut().enumerate() {
        *x = v[0] * m[0][j] + v[1] * m[1][j] + v[2] * m[2][j] + v[3] * m[3][j];
    }
    r
}

fn dot4(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// The power vector `[x³, x², x, 1]` and its derivative `[3x², 2x, 1, 0]`, built by
/// repeated multiplication as the SPD does.
fn powers(x: f64) -> ([f64; 4], [f64; 4]) {
    let mut p = [0.0; 4];
    let mut d = [0.0; 4];
    let mut val = 1.0;
    let mut dval = 1.0;
    for k in (0..4).rev() {
        p[k] = val;
        val *= x;
        if k == 3 {
            d[k] = 0.0;
            dval = 1.0;
        } else {
            d[k] = dval * (3 - k) as f64;
            dval *= x;
        }
    }
    (p, d)
}

/// A point on a patch with its partial derivatives.
#[derive(Clone, Copy, Debug)]
struct Eval {
    point: DVec3,
    /// ∂P/∂s.
    ds: DVec3,
    /// ∂P/∂t.
    dt: DVec3,
}

impl Eval {
    /// The unit normal `∂P/∂t × ∂P/∂s` (zero where the derivatives are parallel or
    /// vanish, as at a cusp).
    fn normal(&self) -> DVec3 {
        let (a, b) = (self.dt, self.ds);
        let n = DVec3::new(
            a.y * b.z - a.z * b.y,
            a.z * b.x - a.x * b.z,
            a.x * b.y - a.y * b.x,
        );
        let len = (n.x * n.x + n.y * n.y + n.z * n.z).sqrt();
        if len > 0.0 {
            DVec3::new(n.x / len, n.y / len, n.z / len)
        } else {
            n
        }
    }
}

/// One Bézier patch in power form: `P_i(s, t) = S · (M G_i Mᵀ) · Tᵀ` for each
/// coordinate `i`, with `S = [s³, s², s, 1]`.
#[derive(Clone, Debug)]
struct Patch {
    mgm: [Mat4; 3],
}

impl Patch {
    fn new(index: usize) -> Patch {
        let basis_t = transpose(&BEZIER_BASIS);
        let mut mgm = [[[0.0; 4]; 4]; 3];
        for (i, m) in mgm.iter_mut().enumerate() {
            let mut g = [[0.0; 4]; 4];
            for (r, row) in g.iter_mut().enumerate() {
                for (c, x) in row.iter_mut().enumerate() {
                    *x = VERTS[PATCHES[index][r][c]][i];
                }
            }
            *m = mat_mul(&mat_mul(&BEZIER_BASIS, &g), &basis_t);
        }
        Patch { mgm }
    }

    fn eval(&self, s: f64, t: f64) -> Eval {
        let (sp, dsp) = powers(s);
        let (tp, dtp) = powers(t);
        let mut point = [0.0; 3];
        let mut ds = [0.0; 3];
        let mut dt = [0.0; 3];
        for i in 0..3 {
            let m = &self.mgm[i];
            let st = row_times(&sp, m);
            point[i] = dot4(&st, &tp);
            ds[i] = dot4(&row_times(&dsp, m), &tp);
            dt[i] = dot4(&st, &dtp);
        }
        Eval {
            point: DVec3::from_array(point),
            ds: DVec3::from_array(ds),
            dt: DVec3::from_array(dt),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spd::NffWriter;
    use std::path::Path;

    fn text(size: u32) -> String {
        let mut w = NffWriter::new();
        generate(size, &mut w);
        w.finish()
    }

    fn count(text: &str, keyword: &str) -> usize {
        text.lines()
            .filter(|l| l.split_whitespace().next() == Some(keyword))
            .count()
    }

    fn control(index: usize, r: usize, c: usize) -> DVec3 {
        DVec3::from_array(VERTS[PATCHES[index][r][c]])
    }

    /// Triangles: 2·size² per patch, less one per parameter column of the first row
    /// of the 8 patches (lid top, bottom) whose `s = 0` edge is a cusp.
    fn expected_triangles(size: usize) -> usize {
        32 * 2 * size * size - 8 * size
    }

    #[test]
    fn counts_follow_the_tessellation() {
        for size in 1..=6 {
            let t = text(size as u32);
            assert_eq!(count(&t, "pp"), expected_triangles(size), "size {size}");
            assert_eq!(count(&t, "p"), size * size, "size {size}");
            assert_eq!(count(&t, "f"), 3);
            assert_eq!(count(&t, "l"), 2);
            // White squares (odd i + j) come first, then grey.
            let first_grey = t.find("f 0.5 0.5 0.5").unwrap();
            assert_eq!(count(&t[..first_grey], "p"), size * size / 2);
        }
        assert_eq!(expected_triangles(DEFAULT_SIZE as usize), 9120);
    }

    #[test]
    fn cusp_triangles_are_dropped_and_cusp_normals_are_vertical() {
        let t = text(3);
        let mut on_axis_vertices = 0;
        for block in t.split("pp 3\n").skip(1) {
            let rows: Vec<Vec<f64>> = block
                .lines()
                .take(3)
                .map(|l| l.split(' ').map(|x| x.parse().unwrap()).collect())
                .collect();
            let on: Vec<&Vec<f64>> = rows
                .iter()
                .filter(|r| r[0].abs() < 1e-4 && r[1].abs() < 1e-4)
                .collect();
            assert!(on.len() <= 1, "degenerate triangle written: {block}");
            for r in on {
                on_axis_vertices += 1;
                let up = if r[2] > 1.5 { 1.0 } else { -1.0 };
                assert_eq!(&r[3..], &[0.0, 0.0, up]);
            }
        }
        // Each cusp patch: one triangle per column touches the cusp; 8 patches.
        assert_eq!(on_axis_vertices, 8 * 3);
    }

    #[test]
    fn output_reproduces_the_spd_text() {
        let t = text(2);
        assert!(t.starts_with(
            "b 0.078 0.361 0.753\nv\nfrom 4.86 7.2 5.4\nat 0 0 0\nup 0 0 1\nangle 45\n\
             hither 1\nresolution 512 512\nl -3.1 9.8 12.1\nl 11.3 5.1 8.8\n\
             f 1 1 1 0.5 0.5 4.81884 0 0\np 4\n-4 0 0\n0 0 0\n0 4 0\n-4 4 0\n"
        ));
        // The first teapot triangle, rounding noise of the normals included.
        assert!(t.contains(
            "f 1 0.5 0.1 0.75 0.25 3.0827 0 0\npp 3\n\
             1.4 0 2.4 -0.902861 -0 -0.429934\n\
             0.994 -0.994 2.4 -0.637936 0.637936 -0.431366\n\
             0.996219 -0.996219 2.49844 1.4538e-15 -1.67359e-15 1\n"
        ));
    }

    /// Point `u` along edge `e` of a patch: 0 is `s = 0`, 1 is `s = 1`, 2 is `t = 0`,
    /// 3 is `t = 1`.
    fn edge_point(p: &Patch, e: usize, u: f64) -> DVec3 {
        match e {
            0 => p.eval(0.0, u).point,
            1 => p.eval(1.0, u).point,
            2 => p.eval(u, 0.0).point,
            _ => p.eval(u, 1.0).point,
        }
    }

    #[test]
    fn neighbouring_patches_meet_along_their_edges() {
        const S0: usize = 0;
        const S1: usize = 1;
        const T0: usize = 2;
        const T1: usize = 3;
        // (patch, edge, patch, edge, reversed)
        let mut shared = Vec::new();
        // Rings of four patches around the axis: rim, upper and lower body, lid knob,
        // lid, bottom; each one's t = 1 edge is the next one's t = 0 edge.
        for first in [0, 4, 8, 20, 24, 28] {
            for k in 0..4 {
                shared.push((first + k, T1, first + (k + 1) % 4, T0, false));
            }
        }
        // Stacked rings: rim over upper body over lower body, knob over lid.
        for k in (0..8).chain(20..24) {
            shared.push((k, S1, k + 4, S0, false));
        }
        // The lower body's bottom edge is the bottom's outer edge, run backwards.
        for k in 0..4 {
            shared.push((8 + k, S1, 31 - k, S1, true));
        }
        // Handle and spout: two halves (mirror images in y) of two sections each.
        for first in [12, 16] {
            shared.push((first, T1, first + 1, T0, false));
            shared.push((first, T0, first + 1, T1, false));
            shared.push((first + 2, T1, first + 3, T0, false));
            shared.push((first + 2, T0, first + 3, T1, false));
            shared.push((first, S1, first + 2, S0, false));
            shared.push((first + 1, S1, first + 3, S0, false));
        }
        assert_eq!(shared.len(), 52);
        for (a, ea, b, eb, reversed) in shared {
            let (pa, pb) = (Patch::new(a), Patch::new(b));
            for k in 0..=16 {
                let u = f64::from(k) / 16.0;
                let v = if reversed { 1.0 - u } else { u };
                let (p, q) = (edge_point(&pa, ea, u), edge_point(&pb, eb, v));
                assert!(
                    (p - q).length() < 1e-6,
                    "patch {a} edge {ea} vs patch {b} edge {eb} at {u}: {p} vs {q}"
                );
            }
        }
        // The comparison is not vacuous: the rim's bottom edge is not the lid's edge.
        let (rim, lid) = (Patch::new(0), Patch::new(24));
        assert!((edge_point(&rim, S1, 0.5) - edge_point(&lid, S1, 0.5)).length() > 0.1);
        // The lid's and bottom's s = 0 edges are collapsed onto the axis.
        for index in (20..24).chain(28..32) {
            let p = Patch::new(index);
            for k in 0..=8 {
                let q = edge_point(&p, S0, f64::from(k) / 8.0);
                assert!(q.x.abs() < 1e-12 && q.y.abs() < 1e-12, "patch {index}: {q}");
            }
        }
    }

    #[test]
    fn bezier_patches_interpolate_their_corners() {
        for index in 0..PATCHES.len() {
            let p = Patch::new(index);
            for (s, t, r, c) in [
                (0.0, 0.0, 0, 0),
                (0.0, 1.0, 0, 3),
                (1.0, 0.0, 3, 0),
                (1.0, 1.0, 3, 3),
            ] {
                let got = p.eval(s, t).point;
                let want = control(index, r, c);
                assert!(
                    (got - want).length() < 1e-12,
                    "patch {index} ({s}, {t}): {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn derivatives_and_normals_are_consistent() {
        let h = 1e-6;
        for index in 0..PATCHES.len() {
            let p = Patch::new(index);
            for (s, t) in [(0.3, 0.6), (0.5, 0.5), (0.8, 0.25)] {
                let e = p.eval(s, t);
                // Partial derivatives against central differences.
                let ds = (p.eval(s + h, t).point - p.eval(s - h, t).point) / (2.0 * h);
                let dt = (p.eval(s, t + h).point - p.eval(s, t - h).point) / (2.0 * h);
                assert!(
                    (e.ds - ds).length() < 1e-6,
                    "patch {index} ∂s: {} vs {ds}",
                    e.ds
                );
                assert!(
                    (e.dt - dt).length() < 1e-6,
                    "patch {index} ∂t: {} vs {dt}",
                    e.dt
                );
                // The normal is the unit cross product ∂t × ∂s.
                let n = e.normal();
                assert!(
                    (n.length() - 1.0).abs() < 1e-12,
                    "patch {index}: |n| = {}",
                    n.length()
                );
                let want = e.dt.cross(e.ds).normalize();
                assert!((n - want).length() < 1e-12, "patch {index}: {n} vs {want}");
            }
        }
        // The body's normals point away from the axis.
        for index in 4..12 {
            let e = Patch::new(index).eval(0.5, 0.5);
            let radial = DVec3::new(e.point.x, e.point.y, 0.0);
            assert!(e.normal().dot(radial) > 0.0, "patch {index}");
        }
    }

    #[test]
    fn power_vectors_and_their_derivatives() {
        let (p, d) = powers(0.5);
        assert_eq!(p, [0.125, 0.25, 0.5, 1.0]);
        assert_eq!(d, [0.75, 1.0, 1.0, 0.0]);
    }

    #[test]
    fn shine_is_the_half_power_exponent() {
        for angle in [30.0, 37.0] {
            let n = phong_power(angle);
            let c = (angle * std::f64::consts::PI / 180.0).cos();
            assert!((c.powf(n) - 0.5).abs() < 1e-12);
        }
    }

    #[test]
    fn generated_text_parses() {
        for size in [1u32, 2, 3] {
            let n = size as usize;
            let scene = crate::load::nff::parse_str(&text(size), Path::new("x")).unwrap();
            let tris = expected_triangles(n);
            assert_eq!(scene.load_stats.polygons, tris + n * n);
            // At size 1 the spout tip's four corner triangles are flat (its corners all
            // lie on one line), as in the SPD output; the loader drops them.
            let flat = if size == 1 { 4 } else { 0 };
            assert_eq!(scene.load_stats.degenerate_dropped, flat, "size {size}");
            // Each square is two triangles; every patch triangle has vertex normals.
            assert_eq!(scene.geometry.triangles.len(), tris - flat + 2 * n * n);
            assert_eq!(scene.geometry.vertex_normals.len(), tris - flat);
            assert_eq!(scene.lights.len(), 2);
        }
    }
}
