//! The f32 intersectors against their f64 references on random rays: ordinary,
//! grazing, from inside, tiny and huge sizes, far from the origin. Plus the robustness
//! of spawned rays: a ray leaving a surface never re-hits it.

use emray::geometry::{Cone, Intersect, Sphere, Triangle, precise};
use emray::math::{DRay, DVec3, Ray, Vec3, offset_ray_origin};
use proptest::prelude::*;

fn v3() -> impl Strategy<Value = Vec3> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn unit() -> impl Strategy<Value = Vec3> {
    v3().prop_filter("nonzero", |v| v.length() > 0.1)
        .prop_map(|v| v.normalize())
}

/// A scale spanning 12 orders of magnitude and an offset far from the origin; the
/// object stays at least 8000 f32 ulps of its offset across (much smaller ones are not
/// representable in f32 at all).
fn placement() -> impl Strategy<Value = (f32, Vec3)> {
    (
        -6i32..=6,
        v3(),
        prop_oneof![Just(0.0f32), Just(1e3), Just(1e5)],
    )
        .prop_map(|(e, off, far)| (10f32.powi(e), off * far))
        .prop_filter("object too small for its offset", |(s, off)| {
            *s >= off.abs().max_element() * 1e-3
        })
}

/// Relative distance-error tolerance of the f32 intersectors: the error of `t` is at
/// most `REL × scale / |cos θ|`, with `scale` the size of the configuration (distance
/// of the ray origin plus object size) and `θ` the angle between the ray and the normal.
const REL: f64 = 2e-5;

fn tol(scale: f64, cos: f64) -> f64 {
    REL * scale / cos.abs().max(1e-3)
}

/// Plus the rounding of the coordinates themselves: nothing finer than a few ulps of
/// the largest coordinate is representable in f32.
fn tol_at(scale: f64, cos: f64, coord: Vec3) -> f64 {
    tol(scale, cos)
        + 8.0 * f32::EPSILON as f64 * coord.abs().max_element() as f64 / cos.abs().max(1e-3)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn sphere_matches_f64(
        (scale, off) in placement(),
        c in v3(), r in 0.05f32..1.0, o in v3(), aim in v3(), dirlen in 0.01f32..100.0,
        inside in any::<bool>(), neg in any::<bool>(),
    ) {
        let center = off + c * scale;
        let radius = r * scale;
        let org = if inside { center + o * (0.5 * radius) } else { off + o * (4.0 * scale) };
        let target = center + aim * radius;
        let dir = (target - org).normalize_or(Vec3::X) * dirlen;
        let s = Sphere::new(center, if neg { -radius } else { radius });
        let ray = Ray::new(org, dir);
        let got = s.intersect(&ray);
        let dr = DRay::from(&ray);
        let want = precise::sphere(&dr, center.as_dvec3(), radius as f64, neg, 0.0);
        // Conditioning: squared distance from the centre to the line, relative to r².
        let f = dr.org - center.as_dvec3();
        let l = f - dr.dir * (f.dot(dr.dir) / dr.dir.dot(dr.dir));
        let margin = 1.0 - l.length_squared() / (radius as f64).powi(2);
        let scale_d = (f.length() + radius as f64) / dr.dir.length();
        match (got, want) {
            (Some(g), Some(w)) => {
                if margin > 1e-3 {
                    prop_assert!((g.t as f64 - w).abs() <= tol_at(scale_d, 1.0, off) + 1e-6 * w.abs(),
                        "t {} vs {} (scale {})", g.t, w, scale_d);
                }
            }
            (None, None) => {}
            (g, w) => {
                // Only tangent rays and hits at t≈0 (origin on the surface) may differ.
                let near_zero = w.is_some_and(|w| w < 1e-4 * scale_d)
                    || g.is_some_and(|g| (g.t as f64) < 1e-4 * scale_d);
                prop_assert!(margin.abs() < 1e-3 || near_zero,
                    "disagree: f32 {g:?} f64 {w:?} margin {margin}");
            }
        }
    }

    #[test]
    fn cone_matches_f64(
        (scale, off) in placement(),
        b in v3(), axis in unit(), h in 0.2f32..2.0, rb in 0.0f32..1.0, ra in 0.0f32..1.0,
        o in v3(), aim in 0.0f32..1.0, around in unit(), neg in any::<bool>(),
    ) {
        prop_assume!(rb + ra > 0.05);
        let base = off + b * scale;
        let apex = base + axis * (h * scale);
        let c = if neg {
            Cone::new(base, -rb * scale, apex, -ra * scale)
        } else {
            Cone::new(base, rb * scale, apex, ra * scale)
        };
        let org = off + o * (5.0 * scale);
        // Aim at a point on (or near) the surface.
        let s_t = aim;
        let r_t = (rb + (ra - rb) * s_t) * scale;
        let perp = (around - axis * around.dot(axis)).normalize_or(axis.any_orthonormal_vector());
        let target = base + axis * (s_t * h * scale) + perp * r_t;
        let dir = (target - org).normalize_or(Vec3::Y);
        let ray = Ray::new(org, dir);
        let got = c.intersect(&ray);
        let dr = DRay::from(&ray);
        let want = precise::cone(&dr, base.as_dvec3(), (rb * scale) as f64, apex.as_dvec3(),
            (ra * scale) as f64, neg, 0.0);
        let scale_d = ((dr.org - base.as_dvec3()).length() + (h * scale) as f64 + (rb.max(ra) * scale) as f64)
            / dr.dir.length();
        match (got, want) {
            (Some(g), Some(w)) => {
                // Compare where the reference point is well inside the lateral surface
                // and the hit is not grazing.
                let p = dr.org + dr.dir * w;
                let n = (c.intersect(&ray).unwrap().ng).as_dvec3().normalize();
                let cosang = n.dot(dr.dir.normalize()).abs();
                let s_hit = (p - base.as_dvec3()).dot(axis.as_dvec3()) / (h * scale) as f64;
                let r_hit = rb as f64 + (ra - rb) as f64 * s_hit;
                let tip = r_hit < 1e-2 * rb.max(ra) as f64;
                if cosang > 0.05 && !tip && (g.t as f64 - w).abs() > tol_at(scale_d, cosang, off) {
                    // Maybe the two solvers picked different roots near an end rim.
                    let s = (p - base.as_dvec3()).dot(axis.as_dvec3());
                    let hh = (h * scale) as f64;
                    prop_assert!(s < 1e-3 * hh || s > hh * (1.0 - 1e-3),
                        "t {} vs {} scale {} cos {}", g.t, w, scale_d, cosang);
                }
            }
            (None, None) => {}
            (g, w) => {
                // Allowed only for grazing hits or hits at an end rim.
                let t = g.map(|g| g.t as f64).or(w).unwrap();
                let p = dr.org + dr.dir * t;
                let s = (p - base.as_dvec3()).dot(axis.as_dvec3()) / (h * scale) as f64;
                let rim = s.abs() < 1e-3 || (s - 1.0).abs() < 1e-3;
                let q = p - base.as_dvec3() - axis.as_dvec3() * (s * (h * scale) as f64);
                let rr = ((rb + (ra - rb) * s as f32) * scale) as f64;
                let radial = (q.length() - rr).abs() / rr.max(1e-30);
                // True normal of the cone: radial part minus slope times the axis.
                let k = ((ra - rb) / h) as f64;
                let ng = (q - axis.as_dvec3() * (k * rr)).normalize_or_zero();
                let grazing = ng.dot(dr.dir.normalize()).abs() < 0.05;
                let tip = rr < 1e-2 * (rb.max(ra) * scale) as f64;
                prop_assert!(rim || grazing || tip || radial > 1e-2 || t < 1e-4 * scale_d,
                    "disagree: f32 {g:?} f64 {w:?} s {s}");
            }
        }
    }

    #[test]
    fn triangle_matches_f64(
        (scale, off) in placement(),
        a in v3(), b in v3(), c in v3(), o in v3(), w in (0.0f32..1.0, 0.0f32..1.0),
    ) {
        let p = [off + a * scale, off + b * scale, off + c * scale];
        let tri = Triangle { p };
        prop_assume!(tri.area() > 1e-3 * scale * scale);
        let (mut u, mut v) = w;
        if u + v > 1.0 { u = 1.0 - u; v = 1.0 - v; }
        // Aim slightly outside the triangle sometimes (u, v can go to -0.05).
        let u = u * 1.1 - 0.05;
        let v = v * 1.1 - 0.05;
        let target = p[0] * (1.0 - u - v) + p[1] * u + p[2] * v;
        let org = off + o * (3.0 * scale) + tri.normal().normalize() * scale;
        let ray = Ray::new(org, (target - org).normalize_or(Vec3::Z));
        let got = tri.intersect(&ray);
        let dr = DRay::from(&ray);
        let want = precise::triangle(&dr, p.map(|q| q.as_dvec3()), 0.0);
        let scale_d = scale as f64 * 5.0;
        match (got, want) {
            (Some(g), Some((wt, wu, wv))) => {
                let cos = tri.normal().as_dvec3().normalize().dot(dr.dir.normalize());
                prop_assert!((g.t as f64 - wt).abs() <= tol_at(scale_d, cos, off), "t {} vs {}", g.t, wt);
                // The barycentrics name the same point, to the same tolerance as t.
                let at = |u: f64, v: f64| {
                    let q = p.map(|q| q.as_dvec3());
                    q[0] * (1.0 - u - v) + q[1] * u + q[2] * v
                };
                let gap = (at(g.u as f64, g.v as f64) - at(wu, wv)).length();
                prop_assert!(gap <= tol_at(scale_d, cos, off), "barycentrics off by {gap}");
            }
            (None, None) => {}
            (g, w) => {
                let edge = u.abs().min(v.abs()).min((1.0 - u - v).abs()) < 1e-4;
                let behind = w.is_some_and(|w| w.0 < 1e-5 * scale_d);
                let cos = tri.normal().as_dvec3().normalize().dot(dr.dir.normalize());
                let grazing = cos.abs() < 1e-2;
                prop_assert!(edge || behind || grazing, "disagree: f32 {g:?} f64 {w:?} (u {u}, v {v})");
            }
        }
    }

    /// A ray spawned from a sphere hit with the robust offset never re-hits the sphere
    /// when it leaves outwards, and when it goes inwards finds the far side, not itself.
    #[test]
    fn spawned_rays_do_not_self_intersect_spheres(
        (scale, off) in placement(), c in v3(), o in unit(), out in unit(),
    ) {
        let center = off + c * scale;
        let s = Sphere::new(center, 0.7 * scale);
        let org = center + o * (3.0 * scale);
        let ray = Ray::new(org, center - org);
        let hit = s.intersect(&ray).expect("aimed at the centre");
        let sp = s.surface(&ray, &hit);
        let n = sp.ng;
        // Outward direction in the hemisphere of n.
        let wout = if out.dot(n) > 0.0 { out } else { -out };
        let po = offset_ray_origin(sp.p, sp.err, n, wout);
        prop_assert!(s.intersect(&Ray::new(po, wout)).is_none(), "outgoing ray re-hit the sphere");
        let win = -wout;
        let pi = offset_ray_origin(sp.p, sp.err, n, win);
        let far = s.intersect(&Ray::new(pi, win));
        prop_assert!(far.is_some(), "inward ray missed the sphere");
        let t = far.unwrap().t;
        // The far side is at a chord length 2r·cos(angle) ≥ a tiny fraction of r.
        let chord = 2.0 * 0.7 * scale * (-win.dot(n));
        prop_assert!(t > 0.5 * chord || chord < 1e-3 * scale, "t {t} vs chord {chord}");
    }
}

#[test]
fn inside_only_sphere_hides_its_outside() {
    let s = Sphere::new(Vec3::ZERO, -1.0);
    let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
    let h = s.intersect(&ray).unwrap();
    assert!((h.t - 6.0).abs() < 1e-6, "only the far side: t = {}", h.t);
    let inside = Ray::new(Vec3::ZERO, Vec3::X);
    assert!((s.intersect(&inside).unwrap().t - 1.0).abs() < 1e-6);
}

#[test]
fn ray_from_inside_hits_once() {
    let s = Sphere::new(Vec3::new(1.0, 2.0, 3.0), 2.0);
    let ray = Ray::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 3.0, 4.0));
    let h = s.intersect(&ray).unwrap();
    assert!((h.t - 0.4).abs() < 1e-6);
    assert!(h.ng.dot(ray.dir) > 0.0, "outward normal at the exit");
}

#[test]
fn cylinder_and_cone_analytic() {
    // Cylinder of radius 1 along z from 0 to 2, seen along -x from x = 5.
    let c = Cone::new(Vec3::ZERO, 1.0, Vec3::new(0.0, 0.0, 2.0), 1.0);
    let r = Ray::new(Vec3::new(5.0, 0.0, 1.0), -Vec3::X);
    assert!((c.intersect(&r).unwrap().t - 4.0).abs() < 1e-6);
    // Above the top: open, no cap.
    assert!(
        c.intersect(&Ray::new(Vec3::new(5.0, 0.0, 2.5), -Vec3::X))
            .is_none()
    );
    // Straight down the axis: no caps, so no hit.
    assert!(
        c.intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z))
            .is_none()
    );
    // Cone radius 1 at z=0 to 0 at z=1: at height 0.5 the radius is 0.5.
    let k = Cone::new(Vec3::ZERO, 1.0, Vec3::Z, 0.0);
    let h = k
        .intersect(&Ray::new(Vec3::new(5.0, 0.0, 0.5), -Vec3::X))
        .unwrap();
    assert!((h.t - 4.5).abs() < 1e-6);
    // Ray parallel to the cone's side (a → 0: the quadratic degenerates to linear).
    let side = Vec3::new(-1.0, 0.0, 1.0).normalize();
    let org = Vec3::new(2.0, 0.0, -1.0) + Vec3::new(0.1, 0.0, 0.1);
    let got = k.intersect(&Ray::new(org, side));
    let want = precise::cone(
        &DRay {
            org: org.as_dvec3(),
            dir: side.as_dvec3(),
        },
        DVec3::ZERO,
        1.0,
        DVec3::Z,
        0.0,
        false,
        0.0,
    );
    assert_eq!(got.is_some(), want.is_some());
    if let (Some(g), Some(w)) = (got, want) {
        assert!((g.t as f64 - w).abs() < 1e-5, "{} vs {}", g.t, w);
    }
}

/// Two triangles sharing an edge: rays through points on the edge hit at least one.
#[test]
fn shared_edges_are_watertight() {
    let a = Vec3::new(0.0, 0.0, 0.0);
    let b = Vec3::new(1.0, 0.3, 0.1);
    let c = Vec3::new(0.2, 1.0, 0.05);
    let d = Vec3::new(1.3, 1.1, 0.2);
    let t1 = Triangle { p: [a, b, c] };
    let t2 = Triangle { p: [b, d, c] };
    let mut misses = 0;
    // Interior points of the edge (its end points are on the mesh boundary).
    for i in 1..10_000 {
        let s = i as f32 / 10_000.0;
        let target = b + (c - b) * s;
        let org = Vec3::new(0.37, 0.41, 3.0);
        let ray = Ray::new(org, target - org);
        if t1.intersect(&ray).is_none() && t2.intersect(&ray).is_none() {
            misses += 1;
        }
    }
    assert_eq!(misses, 0, "rays slipped through the shared edge");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    /// Rays leaving a cone hit from outside, towards the outside, never re-hit the cone
    /// at t ≈ 0 (a later hit on the far wall of a concave view is legitimate, so only
    /// hits closer than 1e-3 of the cone's size count as self-intersections).
    #[test]
    fn spawned_rays_do_not_self_intersect_cones(
        (scale, off) in placement(), b in v3(), axis in unit(), h in 0.2f32..2.0,
        rb in 0.05f32..1.0, ra in 0.0f32..1.0, o in unit(), w in unit(), aim in 0.05f32..0.95,
    ) {
        let base = off + b * scale;
        let apex = base + axis * (h * scale);
        let c = Cone::new(base, rb * scale, apex, ra * scale);
        let r_t = (rb + (ra - rb) * aim) * scale;
        let perp = (o - axis * o.dot(axis)).normalize_or(axis.any_orthonormal_vector());
        let target = base + axis * (aim * h * scale) + perp * r_t;
        let org = target + perp * (3.0 * scale) + axis * (0.3 * scale);
        let ray = Ray::new(org, target - org);
        let Some(hit) = c.intersect(&ray) else { return Ok(()); };
        let sp = c.surface(&ray, &hit);
        let n = if sp.ng.dot(ray.dir) < 0.0 { sp.ng } else { -sp.ng };
        let wout = if w.dot(n) > 0.0 { w } else { -w };
        let po = offset_ray_origin(sp.p, sp.err, n, wout);
        let size = (h + rb + ra) * scale;
        if let Some(again) = c.intersect(&Ray::new(po, wout)) {
            prop_assert!(again.t > 1e-3 * size, "self-hit at t = {} (size {size})", again.t);
        }
    }

    /// The same for triangles: a ray leaving the surface never re-hits it, whatever
    /// the triangle's size, position and orientation (axis-aligned ones included).
    #[test]
    fn spawned_rays_do_not_self_intersect_triangles(
        (scale, off) in placement(), a in v3(), b in v3(), c in v3(), o in v3(), w in unit(),
        axis_aligned in any::<bool>(), bary in (0.0f32..1.0, 0.0f32..1.0),
    ) {
        let mut p = [off + a * scale, off + b * scale, off + c * scale];
        if axis_aligned {
            for q in &mut p { q.z = off.z; }
        }
        let tri = Triangle { p };
        prop_assume!(tri.area() > 1e-3 * scale * scale);
        let (mut u, mut v) = bary;
        if u + v > 1.0 { u = 1.0 - u; v = 1.0 - v; }
        let target = p[0] * (1.0 - u - v) + p[1] * u + p[2] * v;
        let org = off + o * (3.0 * scale) + tri.normal().normalize() * scale;
        let ray = Ray::new(org, target - org);
        let Some(hit) = tri.intersect(&ray) else { return Ok(()); };
        let sp = tri.surface(hit.u, hit.v);
        for dir in [w, -w] {
            let po = offset_ray_origin(sp.p, sp.err, sp.ng, dir);
            prop_assert!(tri.intersect(&Ray::new(po, dir)).is_none(), "self-hit leaving along {dir}");
        }
    }
}
