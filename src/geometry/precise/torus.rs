//! Torus reference: dense sampling of the implicit function along the line, then
//! bisection. No quartic at all.
//!
//! `g(p) = (√(x² + y²) − R)² + z² − r²` in the torus's frame (`z` along the axis), which
//! is negative exactly inside the solid (self-intersecting tori included). The line is
//! sampled across the bounding sphere; every sign change between samples is bisected to
//! f64 resolution, and every local minimum of the samples that is still positive is
//! searched (golden section) for a dip below zero, so near-tangent pairs of roots
//! closer than the sampling step are found too.

use crate::math::{DRay, DVec3};

/// Number of samples across the bounding sphere.
const SAMPLES: usize = 4096;

/// `g` at world point `p` for the torus `(center, unit axis, major, minor)`.
pub fn torus_value(center: DVec3, axis: DVec3, major: f64, minor: f64, p: DVec3) -> f64 {
    let v = p - center;
    let z = v.dot(axis);
    let rho = (v - axis * z).length();
    (rho - major).powi(2) + z * z - minor * minor
}

/// The outward normal direction `∇g / 2` at `p` (zero on the axis).
pub fn torus_gradient(center: DVec3, axis: DVec3, major: f64, p: DVec3) -> DVec3 {
    let v = p - center;
    let z = v.dot(axis);
    let radial = v - axis * z;
    let rho = radial.length();
    if rho == 0.0 {
        return axis * z;
    }
    radial * ((rho - major) / rho) + axis * z
}

/// Every crossing of the whole line with the surface, sorted (entries and exits
/// alternate, starting with an entry).
pub fn torus_crossings(ray: &DRay, center: DVec3, axis: DVec3, major: f64, minor: f64) -> Vec<f64> {
    let g = |t: f64| torus_value(center, axis, major, minor, ray.org + ray.dir * t);
    // The stretch of the line inside a larger bounding sphere (larger by far more than
    // the f64 error of this direct quadratic for origins far away).
    let big = (major + minor) * 1.01;
    let f = ray.org - center;
    let a = ray.dir.dot(ray.dir);
    let b = f.dot(ray.dir);
    let c = f.dot(f) - big * big;
    let disc = b * b - a * c;
    if a == 0.0 || disc <= 0.0 {
        return Vec::new();
    }
    let (t0, t1) = ((-b - disc.sqrt()) / a, (-b + disc.sqrt()) / a);
    let step = (t1 - t0) / SAMPLES as f64;
    let ts: Vec<f64> = (0..=SAMPLES).map(|k| t0 + step * k as f64).collect();
    let gs: Vec<f64> = ts.iter().map(|&t| g(t)).collect();
    let mut roots = Vec::new();
    for k in 0..SAMPLES {
        if (gs[k] > 0.0) != (gs[k + 1] > 0.0) {
            roots.push(bisect(&g, ts[k], ts[k + 1]));
        }
        if k > 0 && gs[k] > 0.0 && gs[k] <= gs[k - 1] && gs[k] <= gs[k + 1] {
            let m = golden_min(&g, ts[k - 1], ts[k + 1]);
            if g(m) <= 0.0 {
                // Two roots around the dip: [t_{k−1}, m] and [m, t_{k+1}] each change sign.
                roots.push(bisect(&g, ts[k - 1], m));
                roots.push(bisect(&g, m, ts[k + 1]));
            }
        }
    }
    roots.sort_by(f64::total_cmp);
    roots
}

/// The root of `g` in `[a, b]` (signs differ at the ends), by bisection to f64 resolution.
fn bisect(g: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let pos_a = g(a) > 0.0;
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        if (g(m) > 0.0) == pos_a {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// The minimum of a unimodal `g` on `[a, b]` by golden-section search.
fn golden_min(g: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let phi = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - phi * (b - a);
    let mut d = a + phi * (b - a);
    let (mut gc, mut gd) = (g(c), g(d));
    for _ in 0..120 {
        if gc <= 0.0 {
            return c;
        }
        if gd <= 0.0 {
            return d;
        }
        if gc < gd {
            b = d;
            d = c;
            gd = gc;
            c = b - phi * (b - a);
            gc = g(c);
        } else {
            a = c;
            c = d;
            gc = gd;
            d = a + phi * (b - a);
            gd = g(d);
        }
        if b - a <= 4.0 * f64::EPSILON * a.abs().max(b.abs()) {
            break;
        }
    }
    if gc < gd { c } else { d }
}

/// The nearest crossing `t > tmin`.
pub fn torus(
    ray: &DRay,
    center: DVec3,
    axis: DVec3,
    major: f64,
    minor: f64,
    tmin: f64,
) -> Option<f64> {
    torus_crossings(ray, center, axis, major, minor)
        .into_iter()
        .find(|&t| t > tmin)
}

/// The stretches `(t_in, t_out)` of the whole line inside the solid.
pub fn torus_spans(
    ray: &DRay,
    center: DVec3,
    axis: DVec3,
    major: f64,
    minor: f64,
) -> Vec<(f64, f64)> {
    torus_crossings(ray, center, axis, major, minor)
        .chunks_exact(2)
        .map(|p| (p[0], p[1]))
        .collect()
}
