//! Quadric reference: the homogeneous form solved directly in f64.
//!
//! With `Q` the symmetric 4×4 matrix of the coefficients `[a, b, c, d, e, f, g, h, i, j]`
//! (see [`crate::geometry::Quadric`]), `P = (o, 1)` and `D = (d, 0)`, the line meets
//! `F = 0` where `(DᵀQD) t² + 2 (DᵀQP) t + PᵀQP = 0`. No re-basing, no local origin, no
//! root labelling: the roots are `(−b ± √(b² − ac)) / a`, polished by Newton steps on
//! `F(o + t·d)`, and inside/outside comes from evaluating `F` between them.

use crate::math::{DRay, DVec3};

/// The symmetric matrix `Q`.
fn matrix(c: &[f64; 10]) -> [[f64; 4]; 4] {
    let [a, b, cc, d, e, f, g, h, i, j] = *c;
    [[a, d, e, g], [d, b, f, h], [e, f, cc, i], [g, h, i, j]]
}

/// `xᵀ Q y`.
fn form(c: &[f64; 10], x: [f64; 4], y: [f64; 4]) -> f64 {
    let q = matrix(c);
    let mut s = 0.0;
    for r in 0..4 {
        for k in 0..4 {
            s += x[r] * q[r][k] * y[k];
        }
    }
    s
}

fn point(p: DVec3) -> [f64; 4] {
    [p.x, p.y, p.z, 1.0]
}

fn vector(v: DVec3) -> [f64; 4] {
    [v.x, v.y, v.z, 0.0]
}

/// `F(p) = PᵀQP`.
pub fn quadric_value(c: &[f64; 10], p: DVec3) -> f64 {
    form(c, point(p), point(p))
}

/// `∇F(p)`, the outward normal.
pub fn quadric_gradient(c: &[f64; 10], p: DVec3) -> DVec3 {
    let q = matrix(c);
    let pp = point(p);
    let row = |r: usize| 2.0 * (0..4).map(|k| q[r][k] * pp[k]).sum::<f64>();
    DVec3::new(row(0), row(1), row(2))
}

/// Every real root of `F` along the whole line, sorted.
pub fn quadric_roots(ray: &DRay, c: &[f64; 10]) -> Vec<f64> {
    let (pp, dd) = (point(ray.org), vector(ray.dir));
    let a = form(c, dd, dd);
    let b = form(c, dd, pp);
    let cc = form(c, pp, pp);
    let mut roots = Vec::new();
    if a == 0.0 {
        if b != 0.0 {
            roots.push(-cc / (2.0 * b));
        }
    } else {
        let disc = b * b - a * cc;
        if disc >= 0.0 {
            let s = disc.sqrt();
            roots.push((-b - s) / a);
            roots.push((-b + s) / a);
        }
    }
    // Newton steps on F evaluated at the point o + t·d (small coordinates near the
    // surface, unlike a·t² + 2b·t + c for a far origin) repair the textbook formula's
    // cancellation, keeping a step only when it reduces |F|.
    let at = |t: f64| quadric_value(c, ray.org + ray.dir * t);
    for t in &mut roots {
        for _ in 0..4 {
            let slope = quadric_gradient(c, ray.org + ray.dir * *t).dot(ray.dir);
            let step = at(*t) / slope;
            let next = *t - step;
            if step.is_finite() && at(next).abs() < at(*t).abs() {
                *t = next;
            } else {
                break;
            }
        }
    }
    roots.sort_by(f64::total_cmp);
    roots
}

/// Whether `p` is in the (closed) box `[lo, hi]`.
fn in_box(p: DVec3, clip: Option<(DVec3, DVec3)>) -> bool {
    match clip {
        Some((lo, hi)) => p.cmpge(lo).all() && p.cmple(hi).all(),
        None => true,
    }
}

/// The nearest crossing `t > tmin` whose point is in the clip box `[lo, hi]`.
pub fn quadric(ray: &DRay, c: &[f64; 10], clip: Option<(DVec3, DVec3)>, tmin: f64) -> Option<f64> {
    quadric_roots(ray, c)
        .into_iter()
        .find(|&t| t > tmin && in_box(ray.org + ray.dir * t, clip))
}

/// The stretches `(t_in, t_out)` of the whole line inside `{F ≤ 0} ∩ [lo, hi]`, sorted
/// and merged; infinite where the solid is unbounded along the line.
pub fn quadric_spans(ray: &DRay, c: &[f64; 10], clip: Option<(DVec3, DVec3)>) -> Vec<(f64, f64)> {
    let mut cuts = quadric_roots(ray, c);
    if let Some((lo, hi)) = clip {
        for k in 0..3 {
            if ray.dir[k] != 0.0 {
                cuts.push((lo[k] - ray.org[k]) / ray.dir[k]);
                cuts.push((hi[k] - ray.org[k]) / ray.dir[k]);
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let inside = |t: f64| {
        let p = ray.org + ray.dir * t;
        quadric_value(c, p) <= 0.0 && in_box(p, clip)
    };
    // Pieces between consecutive cuts, each tested at its middle.
    let mut edges = vec![f64::NEG_INFINITY];
    edges.extend(&cuts);
    edges.push(f64::INFINITY);
    let probe = |a: f64, b: f64| match (a.is_finite(), b.is_finite()) {
        (true, true) => 0.5 * (a + b),
        (false, true) => b - 1.0 - b.abs(),
        (true, false) => a + 1.0 + a.abs(),
        (false, false) => 0.0,
    };
    let mut spans: Vec<(f64, f64)> = Vec::new();
    for w in edges.windows(2) {
        if !inside(probe(w[0], w[1])) {
            continue;
        }
        match spans.last_mut() {
            Some(last) if last.1 == w[0] => last.1 = w[1],
            _ => spans.push((w[0], w[1])),
        }
    }
    spans
}
