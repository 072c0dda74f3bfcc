//! Double-precision references for the closed solids, built face by face: every piece
//! of the surface (cone side, cap disk, box face, polyhedron face) is intersected on its
//! own and a crossing counts when its point lies within that piece's boundary. This is
//! independent of the f32 intersectors, which clip intervals (lateral ∩ slab, slabs,
//! Haines' half-spaces) and never test a point against a face.

use super::ConeLine;
use crate::math::{DRay, DVec3};

/// Where the line `org + t·dir` crosses a solid's surface, with the outward unit normal
/// of the piece it crosses there. A line through an edge or rim crosses both pieces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    /// Ray parameter.
    pub t: f64,
    /// Outward unit normal.
    pub n: DVec3,
}

/// Relative slack for "the point lies within the face": points on an edge count for
/// both faces despite the rounding of double precision.
const EDGE_SLACK: f64 = 1e-12;

fn sorted(mut c: Vec<Crossing>) -> Vec<Crossing> {
    c.retain(|c| c.t.is_finite());
    c.sort_by(|a, b| a.t.total_cmp(&b.t));
    c
}

/// The nearest crossing with `t > tmin`.
pub fn first(crossings: &[Crossing], tmin: f64) -> Option<Crossing> {
    crossings.iter().copied().find(|c| c.t > tmin)
}

/// The stretch of the whole line inside a convex solid: its first and last crossings.
pub fn span(crossings: &[Crossing]) -> Option<(Crossing, Crossing)> {
    Some((*crossings.first()?, *crossings.last()?))
}

/// Real roots of `a t² + 2 b t + c = 0` in f64 given the discriminant `b² − a c`, by the
/// textbook stable formula (one root when the equation is linear).
fn roots(a: f64, b: f64, c: f64, disc: f64) -> Vec<f64> {
    if disc < 0.0 {
        return vec![];
    }
    let q = -(b + disc.sqrt().copysign(b));
    let mut out = Vec::new();
    if a != 0.0 {
        out.push(q / a);
    }
    if q != 0.0 {
        out.push(c / q);
    }
    out
}

/// Closed cone, truncated cone or cylinder: base disk at `base` (radius `rb`), top disk at
/// `base + h·axis` (radius `rt`), lateral surface between their rims. `axis` any length.
/// Every crossing of the line, sorted.
pub fn capped_cone(
    ray: &DRay,
    base: DVec3,
    axis: DVec3,
    h: f64,
    rb: f64,
    rt: f64,
) -> Vec<Crossing> {
    let w = axis.normalize();
    let k = (rt - rb) / h;
    let ConeLine {
        fs,
        ds,
        fp,
        dp,
        r0,
        a,
        b,
        c,
    } = ConeLine::new(ray, base, w, rb, k);
    // b² − a c by Lagrange's identity, which does not cancel for lines near an apex.
    let disc = (dp * r0 - fp * (k * ds)).length_squared() - dp.cross(fp).length_squared();
    let mut out = Vec::new();
    for t in roots(a, b, c, disc) {
        let s = fs + t * ds;
        let r = rb + k * s;
        if (0.0..=h).contains(&s) && r >= 0.0 {
            let q = ray.org + ray.dir * t - base - w * s;
            let n = (q - w * (k * r)).normalize_or_zero();
            if n != DVec3::ZERO {
                out.push(Crossing { t, n });
            }
        }
    }
    // A pointed end is a single point: a line through it (to within 1e-7 of the size,
    // below f32 resolution) crosses the surface there, whatever the lateral roots'
    // rounding says.
    let size = h + rb.max(rt);
    for (s, r, n) in [(0.0, rb, -w), (h, rt, w)] {
        if r == 0.0 {
            let apex = base + w * s;
            let t = (apex - ray.org).dot(ray.dir) / ray.dir.dot(ray.dir);
            if (ray.org + ray.dir * t - apex).length() <= 1e-7 * size {
                out.push(Crossing { t, n });
            }
        }
    }
    if ds != 0.0 {
        for (s, r, n) in [(0.0, rb, -w), (h, rt, w)] {
            if r <= 0.0 {
                continue;
            }
            let t = (s - fs) / ds;
            let q = ray.org + ray.dir * t - base - w * s;
            let q = q - w * q.dot(w);
            if q.length() <= r * (1.0 + EDGE_SLACK) {
                out.push(Crossing { t, n });
            }
        }
    }
    sorted(out)
}

/// Axis-aligned box `[lo, hi]`, face by face. Every crossing, sorted.
pub fn aa_box(ray: &DRay, lo: DVec3, hi: DVec3) -> Vec<Crossing> {
    let mut out = Vec::new();
    let slack = (hi - lo).max_element() * EDGE_SLACK;
    for i in 0..3 {
        if ray.dir[i] == 0.0 {
            continue;
        }
        for (plane, sign) in [(lo[i], -1.0), (hi[i], 1.0)] {
            let t = (plane - ray.org[i]) / ray.dir[i];
            let p = ray.org + ray.dir * t;
            let inside = (0..3)
                .filter(|&j| j != i)
                .all(|j| p[j] >= lo[j] - slack && p[j] <= hi[j] + slack);
            if inside {
                let mut n = DVec3::ZERO;
                n[i] = sign;
                out.push(Crossing { t, n });
            }
        }
    }
    sorted(out)
}

/// Oriented box: centre, half extents along `axes` (orthonormal). Every crossing, sorted.
pub fn oriented_box(ray: &DRay, center: DVec3, half: DVec3, axes: [DVec3; 3]) -> Vec<Crossing> {
    let rel = ray.org - center;
    let local = DRay {
        org: DVec3::new(axes[0].dot(rel), axes[1].dot(rel), axes[2].dot(rel)),
        dir: DVec3::new(
            axes[0].dot(ray.dir),
            axes[1].dot(ray.dir),
            axes[2].dot(ray.dir),
        ),
    };
    aa_box(&local, -half, half)
        .into_iter()
        .map(|c| Crossing {
            t: c.t,
            n: (axes[0] * c.n.x + axes[1] * c.n.y + axes[2] * c.n.z).normalize(),
        })
        .collect()
}

/// Convex polyhedron `{x : n·x ≤ d}`: each plane's crossing counts when its point
/// satisfies all the other planes. Every crossing, sorted.
pub fn polyhedron(ray: &DRay, planes: &[(DVec3, f64)]) -> Vec<Crossing> {
    let mut out = Vec::new();
    let scale = planes.iter().fold(0.0f64, |m, p| m.max(p.1.abs()));
    for (i, &(n, d)) in planes.iter().enumerate() {
        let len = n.length();
        let vn = n.dot(ray.dir);
        if vn == 0.0 {
            continue;
        }
        let t = (d - n.dot(ray.org)) / vn;
        let p = ray.org + ray.dir * t;
        let inside = planes.iter().enumerate().all(|(j, &(m, e))| {
            j == i || m.dot(p) <= e + EDGE_SLACK * (scale + m.length() * p.length())
        });
        if inside {
            out.push(Crossing { t, n: n / len });
        }
    }
    sorted(out)
}

/// Distance from `p` to the surface of the capped cone (in the meridian half-plane, to
/// the three segments generating the surface).
pub fn capped_cone_distance(p: DVec3, base: DVec3, axis: DVec3, h: f64, rb: f64, rt: f64) -> f64 {
    let w = axis.normalize();
    let q = p - base;
    let s = q.dot(w);
    let rho = (q - w * s).length();
    let seg = |a: (f64, f64), b: (f64, f64)| {
        let (ex, ey) = (b.0 - a.0, b.1 - a.1);
        let l2 = ex * ex + ey * ey;
        let u = if l2 > 0.0 {
            (((s - a.0) * ex + (rho - a.1) * ey) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        ((s - a.0 - u * ex).powi(2) + (rho - a.1 - u * ey).powi(2)).sqrt()
    };
    seg((0.0, 0.0), (0.0, rb))
        .min(seg((0.0, rb), (h, rt)))
        .min(seg((h, rt), (h, 0.0)))
}

/// Distance from `p` to the surface of the box `[−half, half]` around `center` with
/// orthonormal `axes`.
pub fn box_distance(p: DVec3, center: DVec3, half: DVec3, axes: [DVec3; 3]) -> f64 {
    let r = p - center;
    let y = DVec3::new(axes[0].dot(r), axes[1].dot(r), axes[2].dot(r)).abs();
    if y.cmple(half).all() {
        (half - y).min_element()
    } else {
        (y - half).max(DVec3::ZERO).length()
    }
}

/// Distance from `p` to the surface of the polyhedron `{x : n·x ≤ d}`: exact inside;
/// outside, the largest violation (a lower bound, exact when the foot on that plane is
/// inside the others).
pub fn polyhedron_distance(p: DVec3, planes: &[(DVec3, f64)]) -> f64 {
    let signed = planes
        .iter()
        .map(|&(n, d)| (n.dot(p) - d) / n.length())
        .fold(f64::NEG_INFINITY, f64::max);
    signed.abs()
}
