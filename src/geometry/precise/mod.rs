//! Straightforward double-precision intersectors: the independent references the f32
//! intersectors are tested against. Clarity over speed; not used for rendering.

pub mod solids;

use crate::math::{DRay, DVec3};

pub mod quadric;
pub mod torus;

/// Nearest root `> tmin` of `a t² + 2 b t + c = 0` among those passing `accept`,
/// solved directly in f64.
fn solve(a: f64, b: f64, c: f64, tmin: f64, mut accept: impl FnMut(f64) -> bool) -> Option<f64> {
    let mut roots = Vec::with_capacity(2);
    if a.abs() < 1e-300 {
        if b != 0.0 {
            roots.push(-c / (2.0 * b));
        }
    } else {
        let disc = b * b - a * c;
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        roots.push((-b - s) / a);
        roots.push((-b + s) / a);
        roots.sort_by(f64::total_cmp);
    }
    roots.into_iter().find(|&t| t > tmin && accept(t))
}

/// Sphere: nearest `t > tmin`; `inside_only` keeps only exits.
pub fn sphere(ray: &DRay, center: DVec3, radius: f64, inside_only: bool, tmin: f64) -> Option<f64> {
    let f = ray.org - center;
    let a = ray.dir.dot(ray.dir);
    let b = f.dot(ray.dir);
    let c = f.dot(f) - radius * radius;
    solve(a, b, c, tmin, |t| {
        !inside_only || (ray.org + ray.dir * t - center).dot(ray.dir) > 0.0
    })
}

/// The line `ray` against the infinite cone through the disk at `base` (radius `rb`)
/// with unit axis `w` and radius growing by `k` per unit along it: the quadratic
/// `a t² + 2 b t + c` whose roots are the lateral crossings, with the pieces it is made
/// of (axial and perpendicular parts of the origin offset and the direction, and the
/// cone's radius at the origin's axial position).
pub(crate) struct ConeLine {
    pub(crate) fs: f64,
    pub(crate) ds: f64,
    pub(crate) fp: DVec3,
    pub(crate) dp: DVec3,
    pub(crate) r0: f64,
    pub(crate) a: f64,
    pub(crate) b: f64,
    pub(crate) c: f64,
}

impl ConeLine {
    pub(crate) fn new(ray: &DRay, base: DVec3, w: DVec3, rb: f64, k: f64) -> ConeLine {
        let f = ray.org - base;
        let fs = f.dot(w);
        let ds = ray.dir.dot(w);
        let fp = f - w * fs;
        let dp = ray.dir - w * ds;
        let r0 = rb + k * fs;
        ConeLine {
            fs,
            ds,
            fp,
            dp,
            r0,
            a: dp.dot(dp) - k * k * ds * ds,
            b: dp.dot(fp) - k * ds * r0,
            c: fp.dot(fp) - r0 * r0,
        }
    }
}

/// Open cone/cylinder between `base` (radius `rb`) and `apex` (radius `ra`).
pub fn cone(
    ray: &DRay,
    base: DVec3,
    rb: f64,
    apex: DVec3,
    ra: f64,
    inside_only: bool,
    tmin: f64,
) -> Option<f64> {
    let h = (apex - base).length();
    let w = (apex - base) / h;
    let k = (ra - rb) / h;
    let ConeLine {
        fs, ds, a, b, c, ..
    } = ConeLine::new(ray, base, w, rb, k);
    solve(a, b, c, tmin, |t| {
        let s = fs + t * ds;
        if !(0.0..=h).contains(&s) {
            return false;
        }
        if inside_only {
            let p = ray.org + ray.dir * t;
            let q = p - base - w * s;
            let n = q - w * (k * (rb + k * s));
            return n.dot(ray.dir) > 0.0;
        }
        true
    })
}

/// Triangle (Möller–Trumbore, two-sided): `(t, u, v)` with `p = (1−u−v)p0 + u p1 + v p2`.
pub fn triangle(ray: &DRay, p: [DVec3; 3], tmin: f64) -> Option<(f64, f64, f64)> {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let pv = ray.dir.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = ray.org - p[0];
    let u = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = tv.cross(e1);
    let v = ray.dir.dot(qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(qv) * inv;
    (t > tmin).then_some((t, u, v))
}
