//! Ray-cast form factors: the mean over sample points `x` on the shooting element of
//! the exact (unoccluded) form factor from the differential area at `x` to the
//! receiving element (Lambert's contour integral over the polygon, clipped to the
//! half-space in front of `x`), times the fraction of visibility rays between the two
//! elements that no surface blocks (`Accel::occluded`, either backend).
//!
//! `F_ij ≈ V_ij (1/k) Σ_x F(dA_x → A_j)`: shooting from `i` with this estimate
//! distributes exactly the energy that leaves `i` in a closed enclosure (the
//! point-to-polygon form factors of a closed polyhedron sum to one at every point).

use super::mesh::{Element, Mesh, centroid_pattern};
use crate::accel::Accel;
use crate::math::{Ray, Vec3, next_float_down, offset_ray_origin};

/// The exact form factor from a differential area at `x` with unit normal `n` to the
/// planar polygon `poly` (either winding), ignoring occlusion; the part of the
/// polygon behind the plane of `x` is clipped away.
pub fn point_to_polygon(x: Vec3, n: Vec3, poly: &[Vec3]) -> f32 {
    let mut clipped: smallvec::SmallVec<[Vec3; 8]> = smallvec::SmallVec::new();
    let k = poly.len();
    for a in 0..k {
        let p = poly[a];
        let q = poly[(a + 1) % k];
        let dp = n.dot(p - x);
        let dq = n.dot(q - x);
        if dp > 0.0 {
            clipped.push(p);
        }
        if (dp > 0.0) != (dq > 0.0) && dp != dq {
            let t = dp / (dp - dq);
            clipped.push(p + (q - p) * t);
        }
    }
    if clipped.len() < 3 {
        return 0.0;
    }
    let m = clipped.len();
    let mut sum = 0.0f64;
    for a in 0..m {
        let r0 = (clipped[a] - x).as_dvec3();
        let r1 = (clipped[(a + 1) % m] - x).as_dvec3();
        let c = r0.cross(r1);
        let cl = c.length();
        if cl == 0.0 {
            continue;
        }
        let angle = cl.atan2(r0.dot(r1));
        sum += angle * n.as_dvec3().dot(c) / cl;
    }
    (sum.abs() / (2.0 * std::f64::consts::PI)) as f32
}

/// How form factors are sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct Sampling {
    /// Barycentric sample points on the shooting element.
    pub shooter: Vec<(f32, f32)>,
    /// Barycentric ends of the visibility rays, the same on both elements: ray `a`
    /// joins point `a` of one element to point `k − 1 − a` of the other, so the rays
    /// between `i` and `j` are those between `j` and `i` (reciprocal visibility).
    pub visibility: Vec<(f32, f32)>,
}

impl Sampling {
    /// `4^shooter_level` points on the shooter and `4^visibility_level` visibility
    /// rays per pair of elements, at the centroids of the elements' regular
    /// subdivisions (the same pattern whatever the backend).
    pub fn new(shooter_level: u32, visibility_level: u32) -> Self {
        Sampling {
            shooter: centroid_pattern(shooter_level),
            visibility: centroid_pattern(visibility_level),
        }
    }
}

/// Whether nothing blocks the segment between `x` on `a` and `y` on `b`.
#[inline]
pub fn visible<A: Accel>(accel: &A, a: &Element, x: Vec3, b: &Element, y: Vec3) -> bool {
    let d = y - x;
    let org = offset_ray_origin(x, a.err, a.n, d);
    let target = offset_ray_origin(y, b.err, b.n, -d);
    let mut ray = Ray::new(org, target - org);
    ray.tmax = next_float_down(1.0);
    !accel.occluded(&ray)
}

/// The form factor from element `i` to element `j` (fraction of the energy leaving
/// the front of `i` that arrives at the front of `j`).
pub fn element_form_factor<A: Accel>(
    mesh: &Mesh,
    accel: &A,
    s: &Sampling,
    i: usize,
    j: usize,
) -> f32 {
    if i == j {
        return 0.0;
    }
    let (ei, ej) = (&mesh.elements[i], &mesh.elements[j]);
    // Quick rejections: the receiver wholly behind the shooter, or facing away.
    let behind = ej.p.iter().all(|&p| ei.n.dot(p - ei.p[0]) <= 0.0);
    let away = ei.p.iter().all(|&p| ej.n.dot(p - ej.p[0]) <= 0.0);
    if behind || away {
        return 0.0;
    }
    let mut sum = 0.0;
    for &(u, v) in &s.shooter {
        let x = ei.point(u, v);
        if ej.n.dot(x - ej.p[0]) <= 0.0 {
            continue;
        }
        sum += point_to_polygon(x, ei.n, &ej.p);
    }
    if sum <= 0.0 {
        return 0.0;
    }
    let k = s.visibility.len();
    let seen = (0..k)
        .filter(|&a| {
            let (u, v) = s.visibility[a];
            let (ru, rv) = s.visibility[k - 1 - a];
            visible(accel, ei, ei.point(u, v), ej, ej.point(ru, rv))
        })
        .count();
    sum / s.shooter.len() as f32 * (seen as f32 / k as f32)
}

#[cfg(test)]
/// The analytic form factor between two directly opposed parallel `a × b` rectangles
/// at distance `c` (Howell's catalogue, C-11).
pub fn parallel_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let x = a / c;
    let y = b / c;
    let (x2, y2) = (x * x, y * y);
    let pi = std::f64::consts::PI;
    2.0 / (pi * x * y)
        * ((((1.0 + x2) * (1.0 + y2)) / (1.0 + x2 + y2)).sqrt().ln()
            + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
            + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
            - x * x.atan()
            - y * y.atan())
}

#[cfg(test)]
/// The analytic form factor from an `l × w` rectangle to an `l × h` rectangle
/// perpendicular to it along their common edge of length `l` (Howell's catalogue,
/// C-14).
pub fn perpendicular_rectangles(l: f64, w: f64, h: f64) -> f64 {
    let hh = h / l;
    let ww = w / l;
    let (h2, w2) = (hh * hh, ww * ww);
    let pi = std::f64::consts::PI;
    let a = ((1.0 + w2) * (1.0 + h2)) / (1.0 + w2 + h2);
    let b = (w2 * (1.0 + w2 + h2)) / ((1.0 + w2) * (w2 + h2));
    let c = (h2 * (1.0 + h2 + w2)) / ((1.0 + h2) * (w2 + h2));
    1.0 / (pi * ww)
        * (ww * (1.0 / ww).atan() + hh * (1.0 / hh).atan()
            - (h2 + w2).sqrt() * (1.0 / (h2 + w2).sqrt()).atan()
            + 0.25 * (a.ln() + w2 * b.ln() + h2 * c.ln()))
}

#[cfg(test)]
/// The analytic form factor from a differential area facing a coaxial disk of radius
/// `r` at distance `h`.
pub fn point_to_disk(r: f64, h: f64) -> f64 {
    r * r / (h * h + r * r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_to_square_matches_the_closed_form() {
        // A unit square centred above the point at height 1: F = 0.2395 (from the
        // parallel-rectangle point formula with four quarter squares).
        let sq = [
            Vec3::new(-0.5, -0.5, 1.0),
            Vec3::new(0.5, -0.5, 1.0),
            Vec3::new(0.5, 0.5, 1.0),
            Vec3::new(-0.5, 0.5, 1.0),
        ];
        let f = point_to_polygon(Vec3::ZERO, Vec3::Z, &sq) as f64;
        // Quarter square a × b at height c from a corner: (1/2π)(A/√(1+A²) atan(B/√(1+A²)) + ...).
        let q = |a: f64, b: f64| {
            let (a, b) = (a / 1.0, b / 1.0);
            (a / (1.0 + a * a).sqrt() * (b / (1.0 + a * a).sqrt()).atan()
                + b / (1.0 + b * b).sqrt() * (a / (1.0 + b * b).sqrt()).atan())
                / (2.0 * std::f64::consts::PI)
        };
        let expect = 4.0 * q(0.5, 0.5);
        assert!((f - expect).abs() < 1e-5, "{f} vs {expect}");
        // Behind the point: nothing.
        let below: Vec<Vec3> = sq.iter().map(|p| *p * Vec3::new(1.0, 1.0, -1.0)).collect();
        assert_eq!(point_to_polygon(Vec3::ZERO, Vec3::Z, &below), 0.0);
    }

    #[test]
    fn analytic_formulas_have_their_known_values() {
        // Unit squares one apart: 0.1998; perpendicular unit squares: 0.2000.
        assert!((parallel_rectangles(1.0, 1.0, 1.0) - 0.19982).abs() < 1e-4);
        assert!((perpendicular_rectangles(1.0, 1.0, 1.0) - 0.20004).abs() < 1e-4);
        assert!((point_to_disk(1.0, 1.0) - 0.5).abs() < 1e-12);
    }
}
