//! Bézier curves and patches against their definitions, and the tessellation of the
//! Utah teapot against its error bound and for cracks.

use emray::geometry::WatertightRay;
use emray::geometry::bezier::{BezierCurve, BezierPatch, TriMesh, teapot_patches, tessellate};
use emray::math::{DVec3, Ray, Rng, Vec3};
use std::collections::HashMap;
use std::sync::OnceLock;

/// Random control points, curves and patches.
trait RandomBezier {
    /// A point uniform in the cube `[-scale, scale)³`.
    fn point(&mut self, scale: f64) -> DVec3;
    /// A curve of degree `degree` with control points in `[-3, 3)³`.
    fn curve(&mut self, degree: usize) -> BezierCurve;
    /// A bicubic patch with control points in `[-2, 2)³`.
    fn patch(&mut self) -> BezierPatch;
}

impl RandomBezier for Rng {
    fn point(&mut self, scale: f64) -> DVec3 {
        let mut c = || self.range_f64(-scale, scale);
        DVec3::new(c(), c(), c())
    }

    fn curve(&mut self, degree: usize) -> BezierCurve {
        BezierCurve::new((0..=degree).map(|_| self.point(3.0)).collect())
    }

    fn patch(&mut self) -> BezierPatch {
        BezierPatch::new(std::array::from_fn(|_| {
            std::array::from_fn(|_| self.point(2.0))
        }))
    }
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// The curve in Bernstein form, summed directly.
fn bernstein_eval(c: &BezierCurve, t: f64) -> DVec3 {
    let n = c.degree();
    c.points
        .iter()
        .enumerate()
        .map(|(i, p)| *p * binomial(n, i) * t.powi(i as i32) * (1.0 - t).powi((n - i) as i32))
        .sum()
}

/// The patch in Bernstein form, summed directly.
fn bernstein_patch(p: &BezierPatch, u: f64, v: f64) -> DVec3 {
    let b = |i: usize, t: f64| binomial(3, i) * t.powi(i as i32) * (1.0 - t).powi(3 - i as i32);
    let mut s = DVec3::ZERO;
    for i in 0..4 {
        for j in 0..4 {
            s += p.p[i][j] * b(i, u) * b(j, v);
        }
    }
    s
}

const PARAMS: [f64; 9] = [0.0, 0.05, 0.2, 1.0 / 3.0, 0.5, 0.61, 0.8, 0.97, 1.0];

// ---------------------------------------------------------------------------------
// Curves

#[test]
fn de_casteljau_equals_the_bernstein_form() {
    let mut rng = Rng::new(7);
    for degree in 0..=7 {
        for _ in 0..5 {
            let c = rng.curve(degree);
            for t in PARAMS {
                let d = (c.eval(t) - bernstein_eval(&c, t)).length();
                assert!(d <= 1e-12, "degree {degree}, t {t}: {d}");
            }
        }
    }
}

#[test]
fn split_halves_reproduce_the_curve() {
    let mut rng = Rng::new(11);
    for degree in 1..=6 {
        let c = rng.curve(degree);
        for t in [0.25, 0.5, 0.7, 0.93] {
            let (left, right) = c.split(t);
            assert_eq!(left.degree(), degree);
            assert_eq!(right.degree(), degree);
            assert_eq!(left.points[degree], right.points[0], "shared split point");
            for s in PARAMS {
                let l = (left.eval(s) - c.eval(s * t)).length();
                let r = (right.eval(s) - c.eval(t + s * (1.0 - t))).length();
                assert!(
                    l <= 1e-12 && r <= 1e-12,
                    "degree {degree} t {t} s {s}: {l} {r}"
                );
            }
        }
    }
}

#[test]
fn degree_elevation_keeps_the_curve_and_tightens_the_polygon() {
    let mut rng = Rng::new(13);
    for degree in 1..=5 {
        let c = rng.curve(degree);
        let mut e = c.clone();
        // The largest distance from a control point to the (densely sampled) curve:
        // it shrinks as the elevated polygons converge to the curve.
        let samples: Vec<DVec3> = (0..=400).map(|k| c.eval(f64::from(k) / 400.0)).collect();
        let spread = |c: &BezierCurve| {
            c.points
                .iter()
                .map(|p| {
                    samples
                        .iter()
                        .map(|q| (*p - *q).length())
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max)
        };
        let first_spread = spread(&c);
        for step in 1..=12 {
            let next = e.elevate();
            assert_eq!(next.degree(), e.degree() + 1);
            for t in PARAMS {
                let d = (next.eval(t) - c.eval(t)).length();
                assert!(d <= 1e-12, "degree {degree} step {step} t {t}: {d}");
            }
            assert!(next.flatness() <= e.flatness() + 1e-14, "flatness grew");
            assert!(next.chord_error_bound() <= e.chord_error_bound() + 1e-14);
            // Corner cutting: every new control point lies on a leg of the old
            // polygon, so each polygon lies in the previous one's convex hull.
            for (i, q) in next.points.iter().enumerate() {
                let (a, b) = (e.points[i.saturating_sub(1)], e.points[i.min(e.degree())]);
                let s = if a == b {
                    0.0
                } else {
                    (*q - a).dot(b - a) / (b - a).length_squared()
                };
                assert!((0.0..=1.0).contains(&s));
                assert!(
                    (*q - (a + (b - a) * s)).length() <= 1e-12,
                    "point {i} off its leg"
                );
            }
            e = next;
        }
        // The control points have moved towards the curve.
        if degree >= 2 {
            assert!(
                spread(&e) < 0.5 * first_spread,
                "degree {degree}: {} vs {first_spread}",
                spread(&e)
            );
        }
    }
}

#[test]
fn derivative_equals_finite_differences() {
    let mut rng = Rng::new(17);
    let h = 1e-6;
    for degree in 0..=6 {
        let c = rng.curve(degree);
        let d = c.derivative();
        assert_eq!(d.degree(), degree.saturating_sub(1));
        for t in [0.1, 0.3, 0.5, 0.77, 0.9] {
            let fd = (c.eval(t + h) - c.eval(t - h)) / (2.0 * h);
            let err = (d.eval(t) - fd).length();
            assert!(
                err <= 1e-6 * (1.0 + fd.length()),
                "degree {degree} t {t}: {err}"
            );
        }
        // The second derivative too, through the hodograph of the hodograph.
        let dd = d.derivative();
        let t = 0.4;
        let fd = (d.eval(t + h) - d.eval(t - h)) / (2.0 * h);
        assert!((dd.eval(t) - fd).length() <= 1e-5 * (1.0 + fd.length()));
    }
}

#[test]
fn ends_interpolate_and_tangents_follow_the_end_legs() {
    let mut rng = Rng::new(19);
    for degree in 1..=6 {
        let c = rng.curve(degree);
        let p = &c.points;
        assert_eq!(c.eval(0.0), p[0]);
        assert_eq!(c.eval(1.0), p[degree]);
        let d = c.derivative();
        let n = degree as f64;
        let start = (p[1] - p[0]) * n;
        let end = (p[degree] - p[degree - 1]) * n;
        assert!((d.eval(0.0) - start).length() <= 1e-12 * start.length());
        assert!((d.eval(1.0) - end).length() <= 1e-12 * end.length());
        // The tangent points along the first and last legs.
        assert!(d.eval(0.0).normalize().dot((p[1] - p[0]).normalize()) > 1.0 - 1e-12);
        assert!(
            d.eval(1.0)
                .normalize()
                .dot((p[degree] - p[degree - 1]).normalize())
                > 1.0 - 1e-12
        );
    }
}

#[test]
fn flatness_measures_the_polygon_against_the_chord() {
    let c = BezierCurve::new(vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 2.0, 0.0),
        DVec3::new(3.0, -1.0, 0.0),
        DVec3::new(4.0, 0.0, 0.0),
    ]);
    assert_eq!(c.flatness(), 2.0);
    // Beyond the chord's end the distance is to the end point.
    let over = BezierCurve::new(vec![DVec3::ZERO, DVec3::new(5.0, 0.0, 0.0), DVec3::X]);
    assert_eq!(over.flatness(), 4.0);
    // Collinear control points: flat.
    let line = BezierCurve::new((0..5).map(|k| DVec3::splat(f64::from(k * k))).collect());
    assert!(line.flatness() < 1e-14);
    // Symmetric in the point order, bit for bit.
    let mut rng = Rng::new(23);
    for degree in 1..=6 {
        let c = rng.curve(degree);
        assert_eq!(c.flatness().to_bits(), c.reversed().flatness().to_bits());
        if degree == 1 {
            // A segment is its own chord: flat up to the rounding of its end points.
            assert!(c.flatness() < 1e-14, "{}", c.flatness());
        } else {
            // Random inner control points lie off the chord.
            assert!(c.flatness() > 0.0);
        }
        // Every curve point is within the flatness of the chord.
        let (a, b) = (c.points[0], c.points[degree]);
        for t in PARAMS {
            let q = c.eval(t);
            let s = ((q - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            assert!((q - (a + (b - a) * s)).length() <= c.flatness() + 1e-12);
        }
    }
}

#[test]
fn chord_error_bound_bounds_the_parametric_chord_error() {
    let mut rng = Rng::new(29);
    for degree in 2..=6 {
        let c = rng.curve(degree);
        let bound = c.chord_error_bound();
        let (a, b) = (c.points[0], c.points[degree]);
        for k in 0..=200 {
            let t = f64::from(k) / 200.0;
            let err = (c.eval(t) - (a * (1.0 - t) + b * t)).length();
            assert!(
                err <= bound + 1e-12,
                "degree {degree} t {t}: {err} > {bound}"
            );
        }
        // Halving divides it by at least four.
        let (l, r) = c.split(0.5);
        assert!(l.chord_error_bound() <= bound / 4.0 + 1e-12);
        assert!(r.chord_error_bound() <= bound / 4.0 + 1e-12);
    }
    // Exact for a parabola: (t, t², 0) errs by 1/4 at t = 1/2.
    let parabola = BezierCurve::new(vec![
        DVec3::ZERO,
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::ONE.with_z(0.0),
    ]);
    assert!((parabola.chord_error_bound() - 0.25).abs() < 1e-15);
    assert!(((parabola.eval(0.5) - DVec3::new(0.5, 0.5, 0.0)).length() - 0.25).abs() < 1e-15);
}

// ---------------------------------------------------------------------------------
// Patches

#[test]
fn patch_evaluation_matches_the_bernstein_form_and_interpolates_corners() {
    let mut rng = Rng::new(31);
    let mut patches: Vec<BezierPatch> = (0..5).map(|_| rng.patch()).collect();
    patches.extend(teapot_patches());
    for p in &patches {
        assert_eq!(p.eval(0.0, 0.0), p.p[0][0]);
        assert_eq!(p.eval(1.0, 0.0), p.p[3][0]);
        assert_eq!(p.eval(0.0, 1.0), p.p[0][3]);
        assert_eq!(p.eval(1.0, 1.0), p.p[3][3]);
        for u in PARAMS {
            for v in PARAMS {
                assert!((p.eval(u, v) - bernstein_patch(p, u, v)).length() <= 1e-12);
            }
        }
    }
}

#[test]
fn patch_derivatives_equal_finite_differences() {
    let mut rng = Rng::new(37);
    let mut patches: Vec<BezierPatch> = (0..5).map(|_| rng.patch()).collect();
    patches.extend(teapot_patches());
    let h = 1e-6;
    for p in &patches {
        for (u, v) in [(0.1, 0.2), (0.5, 0.5), (0.73, 0.31), (0.9, 0.95)] {
            let fu = (p.eval(u + h, v) - p.eval(u - h, v)) / (2.0 * h);
            let fv = (p.eval(u, v + h) - p.eval(u, v - h)) / (2.0 * h);
            assert!((p.du(u, v) - fu).length() <= 1e-6 * (1.0 + fu.length()));
            assert!((p.dv(u, v) - fv).length() <= 1e-6 * (1.0 + fv.length()));
            // Mixed and higher partials against differences of the lower ones.
            let d = p.partials(u, v);
            let duv = (p.du(u, v + h) - p.du(u, v - h)) / (2.0 * h);
            assert!((d[1][1] - duv).length() <= 1e-5 * (1.0 + duv.length()));
            let duu = (p.du(u + h, v) - p.du(u - h, v)) / (2.0 * h);
            assert!((d[2][0] - duu).length() <= 1e-5 * (1.0 + duu.length()));
        }
    }
}

#[test]
fn split_u_and_split_v_reproduce_the_patch() {
    let mut rng = Rng::new(41);
    for _ in 0..5 {
        let p = rng.patch();
        for t in [0.5, 0.3, 0.85] {
            let (a, b) = p.split_u(t);
            let (c, d) = p.split_v(t);
            for s in PARAMS {
                for w in PARAMS {
                    let errs = [
                        (a.eval(s, w) - p.eval(s * t, w)).length(),
                        (b.eval(s, w) - p.eval(t + s * (1.0 - t), w)).length(),
                        (c.eval(s, w) - p.eval(s, w * t)).length(),
                        (d.eval(s, w) - p.eval(s, t + w * (1.0 - t))).length(),
                    ];
                    for e in errs {
                        assert!(e <= 1e-12, "t {t} ({s}, {w}): {e}");
                    }
                }
            }
            // The halves share their common edge exactly.
            for j in 0..4 {
                assert_eq!(a.p[3][j], b.p[0][j]);
                assert_eq!(c.p[j][3], d.p[j][0]);
            }
        }
    }
}

#[test]
fn teapot_patches_are_the_generators_and_meet_along_their_edges() {
    let t = teapot_patches();
    assert_eq!(t.len(), 32);
    // The first control point of the rim and the bottom's centre.
    assert_eq!(t[0].p[0][0], DVec3::new(1.4, 0.0, 2.4));
    assert_eq!(t[28].p[0][0], DVec3::ZERO);
    // Rings of four around the axis: patch k's u = 1 edge is patch k+1's u = 0 edge,
    // bit for bit; stacked rings share v edges.
    for first in [0, 4, 8, 20, 24, 28] {
        for k in 0..4 {
            let (a, b) = (&t[first + k], &t[first + (k + 1) % 4]);
            assert_eq!(
                a.p[3],
                b.p[0],
                "patches {} {}",
                first + k,
                first + (k + 1) % 4
            );
        }
    }
    for k in (0..8).chain(20..24) {
        for i in 0..4 {
            assert_eq!(t[k].p[i][3], t[k + 4].p[i][0], "patches {k} {}", k + 4);
        }
    }
    // The lower body's v = 1 edge is the bottom's, reversed.
    for k in 0..4 {
        for i in 0..4 {
            assert_eq!(t[8 + k].p[i][3], t[31 - k].p[3 - i][3]);
        }
    }
    // Collapsed edges at the knob and the bottom.
    for k in (20..24).chain(28..32) {
        assert!(t[k].p.iter().all(|c| c[0] == t[k].p[0][0]), "patch {k}");
    }
}

/// Angle in degrees between two unit vectors.
fn angle(a: DVec3, b: DVec3) -> f64 {
    a.dot(b).clamp(-1.0, 1.0).acos().to_degrees()
}

#[test]
fn teapot_normals_are_unit_everywhere_and_continuous() {
    let t = teapot_patches();
    let n = 16;
    for (index, p) in t.iter().enumerate() {
        for iu in 0..=n {
            for iv in 0..=n {
                let (u, v) = (f64::from(iu) / f64::from(n), f64::from(iv) / f64::from(n));
                let nrm = p.normal(u, v);
                assert!(nrm.is_finite(), "patch {index} ({u}, {v})");
                assert!(
                    (nrm.length() - 1.0).abs() < 1e-12,
                    "patch {index} ({u}, {v}): {nrm}"
                );
                // Against the normals a little way inside, in both parameters.
                for (du, dv) in [(1e-3, 1e-3), (1e-3, 0.0), (0.0, 1e-3)] {
                    let (su, sv) = (
                        if u < 0.5 { du } else { -du },
                        if v < 0.5 { dv } else { -dv },
                    );
                    let near = p.normal(u + su, v + sv);
                    let a = angle(nrm, near);
                    assert!(a < 3.0, "patch {index} ({u}, {v}) vs +({su}, {sv}): {a}°");
                }
            }
        }
    }
    // At the collapsed edges: straight up at the knob, straight down at the bottom.
    for u in [0.0, 0.3, 0.5, 1.0] {
        for (k, p) in t.iter().enumerate() {
            let want = match k {
                20..=23 => DVec3::Z,
                28..=31 => -DVec3::Z,
                _ => continue,
            };
            let nrm = p.normal(u, 0.0);
            assert!((nrm - want).length() < 1e-9, "patch {k} at u = {u}: {nrm}");
        }
    }
}

#[test]
fn teapot_normals_point_outwards() {
    for (k, p) in teapot_patches().iter().enumerate() {
        match k {
            // Rim's outer half and the body: away from the axis.
            0..=11 => {
                let (u, v) = (0.5, if k < 4 { 0.9 } else { 0.5 });
                let q = p.eval(u, v);
                let radial = DVec3::new(q.x, q.y, 0.0);
                assert!(p.normal(u, v).dot(radial) > 0.0, "patch {k}");
            }
            20..=27 => assert!(p.normal(0.5, 0.2).z > 0.0, "lid patch {k}"),
            28..=31 => assert!(p.normal(0.5, 0.5).z < 0.0, "bottom patch {k}"),
            _ => {}
        }
    }
}

// ---------------------------------------------------------------------------------
// Tessellation

/// The teapot tessellated at a few tolerances, shared by the tests.
fn teapot_mesh(tolerance: f64) -> &'static TriMesh {
    static MESHES: OnceLock<Vec<(f64, TriMesh)>> = OnceLock::new();
    let meshes = MESHES.get_or_init(|| {
        let patches = teapot_patches();
        TOLERANCES
            .iter()
            .map(|&tol| (tol, tessellate(&patches, tol)))
            .collect()
    });
    &meshes
        .iter()
        .find(|(t, _)| *t == tolerance)
        .expect("cached tolerance")
        .1
}

const TOLERANCES: [f64; 4] = [0.04, 0.02, 0.01, 0.005];

/// The patch of each vertex.
fn vertex_patches(m: &TriMesh) -> Vec<u32> {
    let mut patch = vec![u32::MAX; m.positions.len()];
    for (t, &p) in m.triangles.iter().zip(&m.triangle_patch) {
        for &k in t {
            patch[k as usize] = p;
        }
    }
    patch
}

/// The largest distance between sample points of the triangles and the surface at
/// the same parameters.
fn measured_deviation(m: &TriMesh, patches: &[BezierPatch]) -> f64 {
    const BARY: [[f64; 3]; 7] = [
        [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
        [0.6, 0.2, 0.2],
        [0.2, 0.6, 0.2],
        [0.2, 0.2, 0.6],
    ];
    let mut worst: f64 = 0.0;
    for (t, &p) in m.triangles.iter().zip(&m.triangle_patch) {
        let pos = t.map(|k| m.positions[k as usize].as_dvec3());
        let uv = t.map(|k| m.uvs[k as usize].map(f64::from));
        for w in BARY {
            let x = pos[0] * w[0] + pos[1] * w[1] + pos[2] * w[2];
            let u = uv[0][0] * w[0] + uv[1][0] * w[1] + uv[2][0] * w[2];
            let v = uv[0][1] * w[0] + uv[1][1] * w[1] + uv[2][1] * w[2];
            worst = worst.max((x - patches[p as usize].eval(u, v)).length());
        }
    }
    worst
}

/// Slack for rounding the vertices to f32: a few ulps of the teapot's largest
/// coordinate (3.4).
const F32_SLACK: f64 = 4.0 * 3.5 * f32::EPSILON as f64;

#[test]
fn mesh_vertices_lie_on_their_patches_with_unit_normals() {
    let patches = teapot_patches();
    let m = teapot_mesh(0.01);
    let owner = vertex_patches(m);
    assert_eq!(m.positions.len(), m.normals.len());
    assert_eq!(m.positions.len(), m.uvs.len());
    assert_eq!(m.triangles.len(), m.triangle_patch.len());
    for k in 0..m.positions.len() {
        assert_ne!(owner[k], u32::MAX, "vertex {k} is in no triangle");
        let p = &patches[owner[k] as usize];
        let [u, v] = m.uvs[k].map(f64::from);
        let exact = p.eval(u, v);
        let d = (m.positions[k].as_dvec3() - exact).length();
        assert!(d <= 1e-6 * exact.length().max(1.0), "vertex {k}: {d}");
        let n = m.normals[k];
        assert!((n.length() - 1.0).abs() < 1e-6, "normal {k}: {n}");
        assert!((n.as_dvec3() - p.normal(u, v)).length() < 1e-6);
    }
}

#[test]
fn mesh_deviation_is_within_the_tolerance() {
    let patches = teapot_patches();
    for tol in TOLERANCES {
        let m = teapot_mesh(tol);
        assert!(m.error_bound <= tol, "bound {} over {tol}", m.error_bound);
        let measured = measured_deviation(m, &patches);
        assert!(
            measured <= m.error_bound + F32_SLACK,
            "tol {tol}: {measured} > {}",
            m.error_bound
        );
        // The bound is not wildly pessimistic.
        assert!(measured > 0.1 * tol, "tol {tol}: only {measured}");
    }
}

#[test]
fn halving_the_tolerance_refines_the_mesh() {
    let patches = teapot_patches();
    for pair in TOLERANCES.windows(2) {
        let (coarse, fine) = (teapot_mesh(pair[0]), teapot_mesh(pair[1]));
        assert!(fine.triangles.len() > coarse.triangles.len(), "{pair:?}");
        let (ec, ef) = (
            measured_deviation(coarse, &patches),
            measured_deviation(fine, &patches),
        );
        assert!(ef < ec, "{pair:?}: {ef} !< {ec}");
    }
}

#[test]
fn teapot_triangle_counts_and_deviation() {
    let patches = teapot_patches();
    println!("tolerance  triangles  vertices  bound      measured max deviation");
    let mut last = 0;
    for tol in TOLERANCES {
        let m = teapot_mesh(tol);
        let measured = measured_deviation(m, &patches);
        println!(
            "{tol:<9}  {:>9}  {:>8}  {:.6}  {measured:.6}",
            m.triangles.len(),
            m.positions.len(),
            m.error_bound
        );
        assert!(m.triangles.len() > last);
        last = m.triangles.len();
    }
}

#[test]
fn a_flat_patch_is_two_triangles() {
    // A planar, evenly parametrised patch (bilinear in disguise).
    let origin = DVec3::new(1.0, -2.0, 0.5);
    let (a, b) = (DVec3::new(3.0, 0.0, 1.0), DVec3::new(0.0, 2.0, 0.0));
    let p = BezierPatch::new(std::array::from_fn(|i| {
        std::array::from_fn(|j| origin + a * (i as f64 / 3.0) + b * (j as f64 / 3.0))
    }));
    for tol in [1.0, 1e-3, 1e-9] {
        let m = tessellate(&[p], tol);
        assert_eq!(m.triangles.len(), 2, "tol {tol}");
        assert_eq!(m.positions.len(), 4);
        assert!(m.error_bound < 1e-12, "{}", m.error_bound);
        let normal = a.cross(b).normalize().as_vec3();
        for n in &m.normals {
            assert!((*n - normal).length() < 1e-6);
        }
        for i in 0..2 {
            let face = m.triangle(i).normal().normalize();
            assert!((face - normal).length() < 1e-6, "winding");
        }
    }
}

#[test]
fn triangles_wind_with_the_normals() {
    // Fine enough for the normals to vary little across a triangle: every vertex
    // normal is on the front side.
    for tol in [0.02, 0.01, 0.005] {
        let m = teapot_mesh(tol);
        for i in 0..m.triangles.len() {
            let face = m.triangle(i).normal();
            for &k in &m.triangles[i] {
                let n = m.normals[k as usize];
                assert!(face.dot(n) > 0.0, "tol {tol} triangle {i}: {face} vs {n}");
            }
        }
    }
    // Coarser, a triangle on the spout's tightly curled lip spans normals more than
    // 90° apart; it still faces the way of their mean.
    let m = teapot_mesh(0.04);
    for i in 0..m.triangles.len() {
        let mean: Vec3 = m.triangles[i].iter().map(|&k| m.normals[k as usize]).sum();
        assert!(m.triangle(i).normal().dot(mean) > 0.0, "triangle {i}");
    }
}

#[test]
#[should_panic(expected = "tolerance")]
fn a_zero_tolerance_is_refused() {
    tessellate(&teapot_patches(), 0.0);
}

// ---------------------------------------------------------------------------------
// Crack-freedom

/// The patch sides where the teapot is open: (patch, v) with `v` the open edge.
/// Rim: its mouth; handle and spout: both ends; lid: its rim.
fn open_side(patch: u32, v: f32) -> bool {
    match patch {
        0..=3 | 12 | 13 | 16 | 17 => v == 0.0,
        14 | 15 | 18 | 19 | 24..=27 => v == 1.0,
        _ => false,
    }
}

/// Weld the vertices by their exact bits, count each undirected edge's triangles
/// and each directed edge's, and return the edges that are not as a crack-free,
/// consistently wound mesh needs: used by more than two triangles, used twice in the
/// same direction, or used once away from the known open boundaries.
fn seam_defects(m: &TriMesh) -> Vec<String> {
    let mut weld: HashMap<[u32; 3], u32> = HashMap::new();
    let id: Vec<u32> = m
        .positions
        .iter()
        .map(|p| {
            let n = weld.len() as u32;
            *weld.entry(p.to_array().map(f32::to_bits)).or_insert(n)
        })
        .collect();
    // Directed welded edge → the (unwelded) vertex pairs using it.
    let mut directed: HashMap<(u32, u32), Vec<(u32, u32)>> = HashMap::new();
    for t in &m.triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            directed
                .entry((id[a as usize], id[b as usize]))
                .or_default()
                .push((a, b));
        }
    }
    let owner = vertex_patches(m);
    let mut defects = Vec::new();
    for (&(a, b), uses) in &directed {
        let back = directed.get(&(b, a)).map_or(0, Vec::len);
        let (x, y) = uses[0];
        let describe = || {
            format!(
                "edge {} – {} (patch {} uv {:?} – {:?})",
                m.positions[x as usize],
                m.positions[y as usize],
                owner[x as usize],
                m.uvs[x as usize],
                m.uvs[y as usize]
            )
        };
        if uses.len() > 1 {
            defects.push(format!("{} used {} times one way", describe(), uses.len()));
        } else if back == 0 {
            let on_open = [x, y]
                .iter()
                .all(|&k| open_side(owner[k as usize], m.uvs[k as usize][1]));
            if !on_open {
                defects.push(format!("{} unmatched", describe()));
            }
        }
    }
    defects
}

#[test]
fn the_teapot_mesh_has_no_cracks() {
    for tol in TOLERANCES {
        let m = teapot_mesh(tol);
        let defects = seam_defects(m);
        assert!(
            defects.is_empty(),
            "tol {tol}: {} defects, e.g. {:?}",
            defects.len(),
            &defects[..defects.len().min(5)]
        );
        // Not vacuous: the open boundaries are there, and patches meet at seams with
        // different subdivisions (some edge's two patches differ in triangle count).
        let mut per_patch = [0usize; 32];
        for &p in &m.triangle_patch {
            per_patch[p as usize] += 1;
        }
        assert!(per_patch.iter().all(|&n| n > 0));
        assert!((4..8).any(|k| per_patch[k] != per_patch[k + 4]) || per_patch[0] != per_patch[4]);
    }
}

#[test]
fn the_crack_check_catches_a_t_junction() {
    // Split one triangle's edge on a seam between two patches by a vertex on that
    // edge: a T-junction, geometrically closed but not conforming.
    let mut m = teapot_mesh(0.04).clone();
    assert!(seam_defects(&m).is_empty());
    let owner = vertex_patches(&m);
    let (i, (a, b)) = m
        .triangles
        .iter()
        .enumerate()
        .find_map(|(i, t)| {
            // An edge on the rim/body seam: rim patch, v = 1 on both ends.
            let p = m.triangle_patch[i];
            (p < 4)
                .then(|| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
                .and_then(|es| {
                    es.into_iter()
                        .find(|&(a, b)| m.uvs[a as usize][1] == 1.0 && m.uvs[b as usize][1] == 1.0)
                })
                .map(|e| (i, e))
        })
        .expect("a seam edge");
    let c = m.triangles[i]
        .iter()
        .copied()
        .find(|&k| k != a && k != b)
        .unwrap();
    let mid = m.positions.len() as u32;
    let (pa, pb) = (m.positions[a as usize], m.positions[b as usize]);
    m.positions.push((pa + pb) * 0.5);
    m.normals.push(m.normals[a as usize]);
    let (ua, ub) = (m.uvs[a as usize], m.uvs[b as usize]);
    m.uvs.push([(ua[0] + ub[0]) / 2.0, 1.0]);
    m.triangles[i] = [a, mid, c];
    m.triangles.push([mid, b, c]);
    m.triangle_patch.push(owner[a as usize]);
    let defects = seam_defects(&m);
    assert_eq!(defects.len(), 3, "{defects:?}");
}

#[test]
fn patches_refined_differently_share_their_edge_vertices() {
    // A flat square next to a dome: the dome needs a fine grid, the straight shared
    // edge one segment, and the flat square two triangles.
    let flat = BezierPatch::new(std::array::from_fn(|i| {
        std::array::from_fn(|j| DVec3::new(i as f64 / 3.0, j as f64 / 3.0, 0.0))
    }));
    let dome = BezierPatch::new(std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let inner = (1..3).contains(&i) && (1..3).contains(&j);
            DVec3::new(
                1.0 + i as f64 / 3.0,
                j as f64 / 3.0,
                if inner { 0.8 } else { 0.0 },
            )
        })
    }));
    // And on the dome's other side a patch, as consistently oriented, whose v = 0 edge
    // runs down where the dome's u = 1 edge runs up.
    let mirror = BezierPatch::new(std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            DVec3::new(
                2.0 + j as f64 / 3.0,
                (3 - i) as f64 / 3.0,
                0.3 * (j * (3 - j)) as f64,
            )
        })
    }));
    let patches = [flat, dome, mirror];
    // Alone, the flat square is two triangles.
    assert_eq!(tessellate(&patches[..1], 1e-3).triangles.len(), 2);
    let m = tessellate(&patches, 1e-3);
    let count = |p: u32| m.triangle_patch.iter().filter(|&&q| q == p).count();
    assert!(count(1) > 100, "{}", count(1));
    assert!(count(2) > 10, "{}", count(2));
    // Next to the dome it takes the dome's vertices along the shared edge and none
    // inside: a strip of fans, far fewer triangles than the dome.
    assert!(
        count(0) > 2 && 4 * count(0) < count(1),
        "{} {}",
        count(0),
        count(1)
    );
    let owner = vertex_patches(&m);
    for k in (0..m.positions.len()).filter(|&k| owner[k] == 0) {
        let [u, v] = m.uvs[k];
        assert!(
            u == 0.0 || u == 1.0 || v == 0.0 || v == 1.0,
            "inner vertex at {u} {v}"
        );
    }
    // Every edge is shared by two triangles in opposite directions, except the outer
    // boundary of the three-patch strip.
    let mut directed: HashMap<([u32; 3], [u32; 3]), i32> = HashMap::new();
    let key = |k: u32| m.positions[k as usize].to_array().map(f32::to_bits);
    for t in &m.triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *directed.entry((key(a), key(b))).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "edge used {n} times one way");
        if !directed.contains_key(&(b, a)) {
            let (pa, pb) = (f32::from_bits(a[0]), f32::from_bits(b[0]));
            let (qa, qb) = (f32::from_bits(a[1]), f32::from_bits(b[1]));
            let outer = (pa == 0.0 && pb == 0.0)
                || (pa == 3.0 && pb == 3.0)
                || (qa == 0.0 && qb == 0.0)
                || (qa == 1.0 && qb == 1.0);
            assert!(outer, "unmatched inner edge {a:?} – {b:?}");
        }
    }
    // The seams x = 1 and x = 2 are shared: the vertices on them are the same bits in
    // both patches.
    for (x, left, right) in [(1.0f32, 0, 1), (2.0, 1, 2)] {
        let on = |p: u32| {
            let mut v: Vec<[u32; 3]> = (0..m.positions.len())
                .filter(|&k| owner[k] == p && m.positions[k].x == x)
                .map(|k| key(k as u32))
                .collect();
            v.sort();
            v
        };
        assert_eq!(on(left), on(right), "seam x = {x}");
        assert!(on(left).len() >= 2);
    }
}

#[test]
fn rays_at_the_body_seams_do_not_slip_through() {
    let m = teapot_mesh(0.02);
    // Closed region: rim, body and bottom (the handle and spout only touch it).
    let closed = |p: u32| !(12..28).contains(&p);
    let owner = vertex_patches(m);
    // Targets: points on mesh edges that lie on seams between two closed patches, and
    // the seam vertices themselves.
    let mut weld: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
    for (k, p) in m.positions.iter().enumerate() {
        weld.entry(p.to_array().map(f32::to_bits))
            .or_default()
            .push(k as u32);
    }
    let on_seam = |k: u32| {
        let same = &weld[&m.positions[k as usize].to_array().map(f32::to_bits)];
        let patches: Vec<u32> = same.iter().map(|&j| owner[j as usize]).collect();
        patches.iter().all(|&p| closed(p)) && patches.iter().any(|&p| p != owner[k as usize])
    };
    let mut targets = Vec::new();
    for t in &m.triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            if a < b && on_seam(a) && on_seam(b) {
                let (pa, pb) = (m.positions[a as usize], m.positions[b as usize]);
                let n = (m.normals[a as usize] + m.normals[b as usize]).normalize();
                for f in [0.0, 0.5, 0.25, 1.0 / 3.0] {
                    targets.push((pa + (pb - pa) * f, n));
                }
            }
        }
    }
    assert!(targets.len() > 500, "{} seam targets", targets.len());
    let tris: Vec<_> = (0..m.triangles.len()).map(|i| m.triangle(i)).collect();
    let mut rng = Rng::new(43);
    let mut missed = Vec::new();
    for (i, &(target, n)) in targets.iter().enumerate().step_by(3) {
        // From outside, along the normal tilted a little, at distance ~4.
        let tilt = rng.vec3_in(-0.5, 0.5);
        let org = target + (n + tilt * 0.8).normalize() * 4.0;
        let ray = Ray::new(org, target - org);
        let wt = WatertightRay::new(&ray);
        let nearest = tris
            .iter()
            .filter_map(|t| t.intersect_wt(&wt))
            .map(|h| h.t)
            .fold(f32::INFINITY, f32::min);
        // The target is at t = 1: the ray must stop there or before (on the way in it
        // may hit the handle or spout first).
        if nearest.is_nan() || nearest > 1.0 + 1e-4 {
            missed.push((i, target, nearest));
        }
    }
    assert!(
        missed.is_empty(),
        "{} rays slipped through, e.g. {:?}",
        missed.len(),
        &missed[..missed.len().min(5)]
    );
}
