//! Area lights for the Whitted renderer: every triangle whose material has an
//! `emission` is a Lambertian emitter (radiance `emission / π` from its front side),
//! sampled with stratified shadow rays for soft shadows.
//!
//! The direct term at a point is `(emission/π) Σ_s V cosθ cosθ' A / (N r²)`: the
//! irradiance from the light divided by π, so that a diffuse surface of reflectance
//! `ρ` shows `ρ ×` it, the same units as the radiosity solution's `B`.

use crate::accel::Accel;
use crate::math::{Ray, Vec3, gamma, hash, hash_unit as unit, next_float_down, offset_ray_origin};
use crate::scene::{INHERIT, Scene};
use std::f32::consts::FRAC_1_PI;

/// One emitting triangle in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaLight {
    /// Corners (counterclockwise seen from the emitting front).
    pub p: [Vec3; 3],
    /// Unit normal of the front.
    pub n: Vec3,
    /// Area.
    pub area: f32,
    /// Emitted radiosity.
    pub emission: Vec3,
    /// Error bound of points on the triangle.
    pub err: Vec3,
}

/// Every emitting triangle of `scene` (top level and instanced).
pub fn collect(scene: &Scene) -> Vec<AreaLight> {
    let mut out = Vec::new();
    let mut push = |p: [Vec3; 3], err: Vec3, material: u32| {
        let e = scene.materials[material as usize].emission;
        if e.max_element() <= 0.0 {
            return;
        }
        let c = (p[1] - p[0]).cross(p[2] - p[0]);
        let len = c.length();
        if !(len > 0.0 && len.is_finite()) {
            return;
        }
        let m = p[0].abs().max(p[1].abs()).max(p[2].abs()).max_element();
        out.push(AreaLight {
            p,
            n: c / len,
            area: 0.5 * len,
            emission: e,
            err: err + Vec3::splat(m * gamma(12)),
        });
    };
    for (k, t) in scene.geometry.triangles.items.iter().enumerate() {
        push(t.p, Vec3::ZERO, scene.geometry.triangles.material[k]);
    }
    for inst in &scene.instances {
        let object = &scene.objects[inst.object as usize];
        for (k, t) in object.triangles.items.iter().enumerate() {
            let mut material = object.triangles.material[k];
            if material == INHERIT {
                material = inst.material;
            }
            let mut err = Vec3::ZERO;
            let p = t.p.map(|q| {
                let (w, e) = inst.xform.point_to_world(q, Vec3::ZERO);
                err = err.max(e);
                w
            });
            push(p, err, material);
        }
    }
    out
}

/// The point lit by area lights: position `p`, its error bound `err`, the unit
/// geometric normal `ng` and shading normal `ns`, both facing the viewer.
#[derive(Clone, Copy, Debug)]
pub struct Receiver {
    /// The point.
    pub p: Vec3,
    /// A bound on the error of `p`.
    pub err: Vec3,
    /// Unit geometric normal facing the viewer.
    pub ng: Vec3,
    /// Unit shading normal facing the viewer.
    pub ns: Vec3,
}

#[cfg(test)]
/// `(irradiance / π)` from `lights` at the point `at`, with `n × n`
/// stratified shadow rays per light, jittered by `seed` (the ray-tree path of the hit,
/// which does not depend on the hit point's rounding, so both backends draw the same
/// jitter). Returns the term and the shadow rays cast.
pub fn direct<A: Accel>(
    accel: &A,
    lights: &[AreaLight],
    at: &Receiver,
    n: u32,
    seed: u32,
) -> (Vec3, u64) {
    direct_recorded(accel, lights, at, n, seed, &mut |_, _, _, _| {})
}

/// [`direct`], each light's share reported to `report(light, rays, visible, value)`:
/// the shadow rays it cast, how many reached it, and its direct term.
pub fn direct_recorded<A: Accel>(
    accel: &A,
    lights: &[AreaLight],
    at: &Receiver,
    n: u32,
    seed: u32,
    report: &mut impl FnMut(usize, u32, u32, Vec3),
) -> (Vec3, u64) {
    let Receiver { p, err, ng, ns } = *at;
    let n = n.max(1);
    let mut sum = Vec3::ZERO;
    let mut rays = 0;
    for (li, l) in lights.iter().enumerate() {
        // The light wholly behind the surface, or facing away from the point.
        if l.p.iter().all(|&q| ns.dot(q - p) <= 0.0) || l.n.dot(p - l.p[0]) <= 0.0 {
            continue;
        }
        let mut acc = 0.0;
        let (first, mut visible) = (rays, 0u32);
        for s in 0..n * n {
            let h = hash(seed ^ hash(li as u32) ^ s.wrapping_mul(0x9e37_79b9));
            let a = ((s % n) as f32 + unit(h)) / n as f32;
            let b = ((s / n) as f32 + unit(hash(h))) / n as f32;
            // Square to triangle, area-preserving (Shirley): √a, b.
            let r = a.sqrt();
            let (u, v) = (r * (1.0 - b), r * b);
            let q = l.p[0] * (1.0 - u - v) + l.p[1] * u + l.p[2] * v;
            let d = q - p;
            let dist2 = d.length_squared();
            let cos_s = ns.dot(d);
            let cos_l = -l.n.dot(d);
            if cos_s <= 0.0 || cos_l <= 0.0 || dist2 <= 0.0 {
                continue;
            }
            rays += 1;
            let org = offset_ray_origin(p, err, ng, d);
            let target = offset_ray_origin(q, l.err, l.n, -d);
            let mut ray = Ray::new(org, target - org);
            ray.tmax = next_float_down(1.0);
            if accel.occluded(&ray) {
                continue;
            }
            visible += 1;
            acc += cos_s * cos_l / (dist2 * dist2);
        }
        let term = l.emission * (FRAC_1_PI * acc * l.area / (n * n) as f32);
        report(li, (rays - first) as u32, visible, term);
        sum += term;
    }
    (sum, rays)
}
