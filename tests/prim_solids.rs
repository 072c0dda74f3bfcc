//! The closed solids (capped cones and cylinders, axis-aligned and oriented boxes,
//! convex polyhedra) against their independent f64 references on random rays: ordinary,
//! grazing, from inside, parallel to faces, tiny and huge sizes, far from the origin,
//! non-unit directions. Plus: spawned rays never re-hit the surface they leave, `contains`
//! agrees with `spans`, analytic cases, degenerate input, and the presets' geometry.
//!
//! Exemptions, everywhere the same: a hit/miss disagreement is allowed only when the
//! hit point is within `edge_tol` of an edge, rim or apex, or the ray is grazing
//! (`|cos| < 1e-3` between ray and normal on a face, `< 2e-2` on the curved side, where
//! the distance is ill-conditioned like a square root).

use emray::geometry::precise::solids::{self as refs, Crossing};
use emray::geometry::{AaBox, CappedCone, Intersect, OBox, Polyhedron, Primitive, ShapeHit, Spans};
use emray::math::{DRay, DVec3, Ray, Vec3, offset_ray_origin};
use glam::Quat;
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{RngAlgorithm, TestRng, TestRunner};

fn v3() -> impl Strategy<Value = Vec3> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn unit() -> impl Strategy<Value = Vec3> {
    v3().prop_filter("nonzero", |v| v.length() > 0.1)
        .prop_map(|v| v.normalize())
}

fn quat() -> impl Strategy<Value = Quat> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_filter("nonzero", |(x, y, z, w)| {
            x * x + y * y + z * z + w * w > 0.01
        })
        .prop_map(|(x, y, z, w)| Quat::from_xyzw(x, y, z, w).normalize())
}

/// As in tests/intersectors.rs: a scale spanning 12 orders of magnitude and an offset
/// far from the origin; the object stays at least 1e-3 of its offset across.
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

/// Relative distance-error tolerance, as in tests/intersectors.rs: the error of `t` is
/// at most `REL × scale / |cos θ|`.
const REL: f64 = 2e-5;

fn tol(scale: f64, cos: f64) -> f64 {
    REL * scale / cos.abs().max(1e-3)
}

/// Plus the rounding of the coordinates themselves (nothing finer than a few ulps of the
/// largest coordinate is representable in f32), in units of a direction of length
/// `dlen`.
fn tol_at(scale: f64, cos: f64, coord: Vec3, dlen: f64) -> f64 {
    tol(scale, cos)
        + 8.0 * f32::EPSILON as f64 * coord.abs().max_element() as f64 / cos.abs().max(1e-3) / dlen
}

/// Grazing thresholds on `|cos|` between the ray and the normal.
const GRAZING_FLAT: f64 = 1e-3;
const GRAZING_CURVED: f64 = 2e-2;

/// The solid under test.
#[derive(Clone, Debug)]
enum AnySolid {
    Cone(CappedCone),
    Aa(AaBox),
    Ob(OBox),
    Poly(Polyhedron),
}

impl AnySolid {
    fn get(&self) -> &dyn Primitive {
        match self {
            AnySolid::Cone(c) => c,
            AnySolid::Aa(b) => b,
            AnySolid::Ob(b) => b,
            AnySolid::Poly(p) => p,
        }
    }
}

/// The exact description the references work from.
#[derive(Clone, Debug)]
enum Geo {
    Cone {
        base: DVec3,
        axis: DVec3,
        h: f64,
        rb: f64,
        rt: f64,
    },
    Box {
        center: DVec3,
        half: DVec3,
        axes: [DVec3; 3],
    },
    Poly {
        planes: Vec<(DVec3, f64)>,
        center: DVec3,
        size: f64,
    },
}

impl Geo {
    fn of(s: &AnySolid) -> Geo {
        match s {
            AnySolid::Cone(c) => Geo::Cone {
                base: c.base().as_dvec3(),
                axis: c.axis().as_dvec3(),
                h: c.height() as f64,
                rb: c.base_radius() as f64,
                rt: c.top_radius() as f64,
            },
            AnySolid::Aa(b) => {
                let (lo, hi) = (b.min().as_dvec3(), b.max().as_dvec3());
                Geo::Box {
                    center: (lo + hi) * 0.5,
                    half: (hi - lo) * 0.5,
                    axes: [DVec3::X, DVec3::Y, DVec3::Z],
                }
            }
            AnySolid::Ob(b) => Geo::Box {
                center: b.center().as_dvec3(),
                half: b.half_extents().as_dvec3(),
                axes: b.axes().map(|a| a.as_dvec3()),
            },
            AnySolid::Poly(p) => {
                let b = p.bounds();
                Geo::Poly {
                    planes: p.world_planes(),
                    center: b.centroid().as_dvec3(),
                    size: b.extent().max_element() as f64,
                }
            }
        }
    }

    fn crossings(&self, r: &DRay) -> Vec<Crossing> {
        match self {
            Geo::Cone {
                base,
                axis,
                h,
                rb,
                rt,
            } => refs::capped_cone(r, *base, *axis, *h, *rb, *rt),
            Geo::Box { center, half, axes } => refs::oriented_box(r, *center, *half, *axes),
            Geo::Poly { planes, .. } => refs::polyhedron(r, planes),
        }
    }

    fn dist(&self, p: DVec3) -> f64 {
        match self {
            Geo::Cone {
                base,
                axis,
                h,
                rb,
                rt,
            } => refs::capped_cone_distance(p, *base, *axis, *h, *rb, *rt),
            Geo::Box { center, half, axes } => refs::box_distance(p, *center, *half, *axes),
            Geo::Poly { planes, .. } => refs::polyhedron_distance(p, planes),
        }
    }

    fn inside(&self, p: DVec3) -> bool {
        match self {
            Geo::Cone {
                base,
                axis,
                h,
                rb,
                rt,
            } => {
                let q = p - *base;
                let s = q.dot(*axis);
                (0.0..=*h).contains(&s) && (q - *axis * s).length() <= rb + (rt - rb) * s / h
            }
            Geo::Box { center, half, axes } => {
                let r = p - *center;
                (0..3).all(|i| axes[i].dot(r).abs() <= half[i])
            }
            Geo::Poly { planes, .. } => planes.iter().all(|&(n, d)| n.dot(p) <= d),
        }
    }

    /// Whether `p` is within `tol` of the apex of a pointed cone.
    fn near_apex(&self, p: DVec3, tol: f64) -> bool {
        match self {
            Geo::Cone {
                base,
                axis,
                h,
                rb,
                rt,
            } => {
                // Where the cone is thinner than the tolerance.
                let tol = tol * (1.0 + h / (rt - rb).abs());
                (*rb == 0.0 && (p - *base).length() <= tol)
                    || (*rt == 0.0 && (p - (*base + *axis * *h)).length() <= tol)
            }
            _ => false,
        }
    }

    /// Whether `p` is on a knife edge: within `tol` plus a few error bounds `e` (times the
    /// slope) of the rim of a cone so flat that its side meets a cap at a few degrees.
    /// Points there are moved off the rim by a bounded amount, too little for a ray
    /// spawned inwards to be seen inside the cap's slab.
    fn near_knife_edge(&self, p: DVec3, tol: f64, e: f64) -> bool {
        match self {
            Geo::Cone { h, rb, rt, .. } => {
                let k = (rt - rb).abs() / h;
                k > 8.0 && self.near_edge(p, tol + 8.0 * e * (1.0 + k))
            }
            _ => false,
        }
    }

    /// Whether `p` is within `tol` of an edge, a rim or an apex.
    fn near_edge(&self, p: DVec3, tol: f64) -> bool {
        match self {
            Geo::Cone {
                base,
                axis,
                h,
                rb,
                rt,
            } => {
                let q = p - *base;
                let s = q.dot(*axis);
                let rho = (q - *axis * s).length();
                let near = |a: f64, b: f64| ((s - a).powi(2) + (rho - b).powi(2)).sqrt() <= tol;
                near(0.0, *rb) || near(*h, *rt) || self.near_apex(p, tol)
            }
            Geo::Box { center, half, axes } => {
                let r = p - *center;
                (0..3)
                    .filter(|&i| (axes[i].dot(r).abs() - half[i]).abs() <= tol)
                    .count()
                    >= 2
            }
            Geo::Poly { planes, .. } => {
                planes
                    .iter()
                    .filter(|&&(n, d)| (n.dot(p) - d).abs() <= tol)
                    .count()
                    >= 2
            }
        }
    }

    /// Radius of curvature of the surface at `p` (infinite on flat faces): the normal
    /// there turns by about `δ / radius` over a position error `δ`.
    fn curvature_radius(&self, p: DVec3) -> f64 {
        match self {
            Geo::Cone {
                base,
                axis,
                h,
                rb,
                rt,
            } => {
                let s = (p - *base).dot(*axis).clamp(0.0, *h);
                let k = (rt - rb) / h;
                (rb + k * s) * (1.0 + k * k).sqrt()
            }
            _ => f64::INFINITY,
        }
    }

    fn center(&self) -> DVec3 {
        match self {
            Geo::Cone { base, axis, h, .. } => *base + *axis * (0.5 * h),
            Geo::Box { center, .. } | Geo::Poly { center, .. } => *center,
        }
    }

    fn size(&self) -> f64 {
        match self {
            Geo::Cone { h, rb, rt, .. } => h + rb.max(*rt),
            Geo::Box { half, .. } => half.max_element() * 2.0,
            Geo::Poly { size, .. } => *size,
        }
    }

    fn grazing(&self) -> f64 {
        match self {
            Geo::Cone { .. } => GRAZING_CURVED,
            _ => GRAZING_FLAT,
        }
    }
}

/// One random solid with one random ray.
#[derive(Clone, Debug)]
struct Case {
    solid: AnySolid,
    geo: Geo,
    ray: Ray,
    /// Offset of the placement (coordinates' magnitude).
    off: Vec3,
}

impl Case {
    fn new(solid: AnySolid, org: Vec3, dir: Vec3, off: Vec3) -> Case {
        let geo = Geo::of(&solid);
        Case {
            solid,
            geo,
            ray: Ray::new(org, dir),
            off,
        }
    }

    /// Size of the configuration in length units (origin distance plus object size).
    fn extent(&self) -> f64 {
        (self.ray.org.as_dvec3() - self.geo.center()).length() + self.geo.size()
    }

    /// Tolerance of "near an edge": a relative 1e-4 of the object plus the positional
    /// uncertainty of the configuration.
    fn edge_tol(&self) -> f64 {
        1e-4 * self.geo.size()
            + 10.0 * REL * self.extent()
            + 16.0 * f32::EPSILON as f64 * self.off.abs().max_element() as f64
    }
}

/// Which way the ray goes: aimed at `target` with a length in `0.01..100`, or (one time
/// in eight) in a random direction; sometimes with one or two components zeroed, so
/// that it is parallel to slabs.
fn direction() -> impl Strategy<Value = (f32, u8, Vec3, u8)> {
    (0.01f32..100.0, 0u8..8, unit(), 0u8..12)
}

fn make_dir(org: Vec3, target: Vec3, (len, mode, random, zero): (f32, u8, Vec3, u8)) -> Vec3 {
    let mut d = if mode == 0 {
        random
    } else {
        (target - org).normalize_or(Vec3::X)
    };
    match zero {
        0 => d.x = 0.0,
        1 => d.y = 0.0,
        2 => {
            d.x = 0.0;
            d.z = 0.0;
        }
        _ => {}
    }
    if d == Vec3::ZERO {
        d = Vec3::Z;
    }
    d * len
}

fn cone_case() -> impl Strategy<Value = Case> {
    (
        placement(),
        (
            v3(),
            unit(),
            0.2f32..2.0,
            0.05f32..1.0,
            0.0f32..1.0,
            0u8..4,
            // Ordinary, coin-like (flat) and needle-like proportions.
            prop_oneof![6 => Just((1.0f32, 1.0f32)), 1 => Just((3e-3, 1.0)), 1 => Just((1.0, 3e-3))],
        ),
        (any::<bool>(), v3(), 0.05f32..0.95, 0.0f32..0.95, unit()),
        (0u8..3, 0.0f32..1.0, unit(), 0.9f32..1.1),
        direction(),
    )
        .prop_filter_map(
            "flat or thin beyond the resolution of its offset",
            |((scale, off), (b, axis, h, r1, r2, kind, (hf, rf)), orig, aim, dir)| {
                let (h, r1, r2) = (h * hf, r1 * rf, r2 * rf);
                if h.min(r1) * scale < off.abs().max_element() * 1e-3 {
                    return None;
                }
                let (rb, rt) = match kind {
                    0 => (r1, r2),
                    1 => (r1, r1),
                    2 => (r1, 0.0),
                    _ => (0.0, r1),
                };
                let base = off + b * scale;
                let c = CappedCone::new(base, axis, h * scale, rb * scale, rt * scale)
                    .expect("valid cone");
                let w = c.axis();
                let radius = |s: f32| (rb + (rt - rb) * s) * scale;
                let perp = |v: Vec3| (v - w * v.dot(w)).normalize_or(w.any_orthonormal_vector());
                let (inside, o, s_in, f_in, around_in) = orig;
                let org = if inside {
                    base + w * (s_in * h * scale) + perp(around_in) * (f_in * radius(s_in))
                } else {
                    off + o * (5.0 * scale)
                };
                let (part, s_t, around, factor) = aim;
                let target = match part {
                    // Side (or just off it), base cap, top cap.
                    0 => base + w * (s_t * h * scale) + perp(around) * (radius(s_t) * factor),
                    1 => base + perp(around) * (radius(0.0) * factor * s_t.sqrt()),
                    _ => {
                        base + w * (h * scale) + perp(around) * (radius(1.0) * factor * s_t.sqrt())
                    }
                };
                Some(Case::new(AnySolid::Cone(c), org, make_dir(org, target, dir), off))
            },
        )
}

/// Random point: in the box's frame, on a face (or just off it) or anywhere.
fn box_target(half: Vec3, face: u8, v: Vec3, factor: f32) -> Vec3 {
    let mut l = v * half * factor;
    if face < 6 {
        let i = (face / 2) as usize;
        l[i] = if face % 2 == 0 { half[i] } else { -half[i] };
    }
    l
}

fn aabox_case() -> impl Strategy<Value = Case> {
    (
        placement(),
        (v3(), (0.05f32..1.0, 0.05f32..1.0, 0.05f32..1.0)),
        (any::<bool>(), v3()),
        (0u8..7, v3(), 0.9f32..1.1),
        direction(),
    )
        .prop_map(
            |((scale, off), (c, (hx, hy, hz)), (inside, o), (face, v, factor), dir)| {
                let center = off + c * scale;
                let half = Vec3::new(hx, hy, hz) * scale;
                let b = AaBox::new(center - half, center + half).expect("valid box");
                let org = if inside {
                    center + o * half * 0.9
                } else {
                    off + o * (4.0 * scale)
                };
                let target = center + box_target(half, face, v, factor);
                Case::new(AnySolid::Aa(b), org, make_dir(org, target, dir), off)
            },
        )
}

fn obox_case() -> impl Strategy<Value = Case> {
    (
        placement(),
        (v3(), (0.05f32..1.0, 0.05f32..1.0, 0.05f32..1.0), quat()),
        (any::<bool>(), v3()),
        (0u8..7, v3(), 0.9f32..1.1),
        direction(),
    )
        .prop_map(
            |((scale, off), (c, (hx, hy, hz), q), (inside, o), (face, v, factor), dir)| {
                let center = off + c * scale;
                let half = Vec3::new(hx, hy, hz) * scale;
                let b = OBox::new(center, half, q).expect("valid box");
                let rot = |l: Vec3| {
                    let a = b.axes();
                    a[0] * l.x + a[1] * l.y + a[2] * l.z
                };
                let org = if inside {
                    center + rot(o * half * 0.9)
                } else {
                    off + o * (4.0 * scale)
                };
                let target = center + rot(box_target(half, face, v, factor));
                Case::new(AnySolid::Ob(b), org, make_dir(org, target, dir), off)
            },
        )
}

/// A preset, a prism, or the intersection of random half-spaces around a centre.
fn polyhedron(kind: u8, center: Vec3, r: f32, normals: &[Vec3], ds: &[f32]) -> Option<Polyhedron> {
    match kind {
        0..=5 => Some(Polyhedron::preset(Polyhedron::PRESETS[kind as usize], center, r).unwrap()),
        6..=8 => Some(Polyhedron::prism(center, 3 + kind as u32 * 2, r, r * 1.3).unwrap()),
        _ => {
            let planes = normals
                .iter()
                .zip(ds)
                .map(|(&n, &d)| (n, n.dot(center) + d * r))
                .collect();
            Polyhedron::new(planes).ok()
        }
    }
}

fn poly_case() -> impl Strategy<Value = Case> {
    (
        placement(),
        (
            v3(),
            0.2f32..1.0,
            0u8..12,
            proptest::collection::vec(unit(), 12),
            proptest::collection::vec(0.5f32..1.0, 12),
        ),
        (any::<bool>(), v3()),
        (unit(), 0.95f64..1.05),
        direction(),
    )
        .prop_filter_map(
            "unbounded random polyhedron",
            |((scale, off), (c, r, kind, normals, ds), (inside, o), (u, factor), dir)| {
                let center = off + c * scale;
                let p = polyhedron(kind, center, r * scale, &normals, &ds)?;
                let org = if inside {
                    center + o * (0.15 * r * scale)
                } else {
                    off + o * (4.0 * scale)
                };
                // A point on the surface: where the ray from the centre along u leaves.
                let planes = p.world_planes();
                let exit = refs::polyhedron(
                    &DRay {
                        org: center.as_dvec3(),
                        dir: u.as_dvec3(),
                    },
                    &planes,
                );
                let t = refs::first(&exit, 0.0)?.t;
                let target = (center.as_dvec3() + u.as_dvec3() * (t * factor)).as_vec3();
                Some(Case::new(
                    AnySolid::Poly(p),
                    org,
                    make_dir(org, target, dir),
                    off,
                ))
            },
        )
}

/// Worst errors seen, each relative to what the tests allow or to the scene's scale.
#[derive(Clone, Copy, Debug, Default)]
struct Worst {
    /// |t − t_ref| · |cos| / extent (the constant `REL` of the tolerance formula), for
    /// placements at the origin (elsewhere the coordinates' rounding dominates).
    t_rel: f64,
    /// |t − t_ref| over the tolerance the tests allow.
    t_frac: f64,
    /// Distance of the surface point to the true surface over its allowed `Σ|n_k| err_k`.
    surf: f64,
    /// Largest `err` component over (largest coordinate + object size).
    err_rel: f64,
    /// 1 − cos of the angle between the hit's normal and the reference's (off edges).
    normal: f64,
    cases: usize,
    hits: usize,
}

/// The checks on one case; `Err` says what failed.
fn check(case: &Case, worst: &mut Worst) -> Result<(), String> {
    let s = case.solid.get();
    let ray = case.ray;
    let dr = DRay::from(&ray);
    let dlen = dr.dir.length();
    let dhat = dr.dir / dlen;
    let cr = case.geo.crossings(&dr);
    let want = refs::first(&cr, 0.0);
    let got = s.intersect(&ray);
    let scale_d = case.extent() / dlen;
    let etol = case.edge_tol();
    let grazing = case.geo.grazing();
    worst.cases += 1;

    if s.occluded(&ray) != got.is_some() {
        return Err(format!("occluded disagrees with intersect {got:?}"));
    }
    let mut spans = Spans::new();
    s.spans(&ray, &mut spans);
    if spans.len() > 1 {
        return Err(format!("a convex solid gave {} spans", spans.len()));
    }
    // intersect reports the first end of the span in (tmin, tmax), exactly.
    let from_span = spans.first().and_then(|sp| {
        [(sp.t_in, sp.n_in), (sp.t_out, sp.n_out)]
            .into_iter()
            .find(|(t, _)| *t > ray.tmin && *t < ray.tmax)
    });
    if from_span.map(|f| f.0) != got.map(|g| g.t) {
        return Err(format!(
            "intersect {got:?} is not the span's end {from_span:?}"
        ));
    }

    match (got, want) {
        (Some(g), Some(w)) => {
            worst.hits += 1;
            check_hit(case, &g, &w, worst)?;
        }
        (None, None) => {}
        (g, w) => {
            let t = g.map(|g| g.t as f64).or(w.map(|w| w.t)).unwrap();
            let p = dr.org + dr.dir * t;
            let n = g
                .map(|g| g.ng.as_dvec3().normalize())
                .or(w.map(|w| w.n))
                .unwrap();
            let edge = case.geo.near_edge(p, etol);
            let graze = n.dot(dhat).abs() < grazing;
            if !(edge || graze) {
                return Err(format!("disagree: f32 {g:?} f64 {w:?} at {p}"));
            }
        }
    }

    // The span against the reference's first and last crossings.
    match (spans.first(), refs::span(&cr)) {
        (Some(sp), Some((a, b))) => {
            for (t, n, c) in [(sp.t_in, sp.n_in, a), (sp.t_out, sp.n_out, b)] {
                let nh = n.as_dvec3().normalize();
                if !nh.is_finite() {
                    return Err(format!("span normal {n}"));
                }
                let cos = nh.dot(dhat).abs().min(c.n.dot(dhat).abs());
                let p = dr.org + dr.dir * c.t;
                if cos < grazing || case.geo.near_edge(p, etol) {
                    continue;
                }
                if (t as f64 - c.t).abs() > tol_at(scale_d, cos, case.off, dlen) {
                    return Err(format!("span end {t} vs {} (cos {cos})", c.t));
                }
            }
            // Outward normals: against the ray at the entry, along it at the exit (but a
            // line touching an edge or an apex may take any normal there).
            let (cin, cout) = (
                sp.n_in.as_dvec3().normalize().dot(dhat),
                sp.n_out.as_dvec3().normalize().dot(dhat),
            );
            let touch = ((sp.t_out - sp.t_in) as f64) * dlen < etol
                || case.geo.near_edge(dr.org + dr.dir * sp.t_in as f64, etol)
                || case.geo.near_edge(dr.org + dr.dir * sp.t_out as f64, etol);
            if !touch && (cin > grazing || cout < -grazing) {
                return Err(format!("span normals not outward: {cin} {cout}"));
            }
        }
        (None, None) => {}
        (g, w) => {
            let t = g.map(|g| g.t_in as f64).or(w.map(|w| w.0.t)).unwrap();
            let p = dr.org + dr.dir * t;
            let near = case.geo.near_edge(p, etol) || case.geo.dist(p) <= etol;
            let graze = w.is_some_and(|w| {
                w.0.n.dot(dhat).abs() < grazing || (w.1.t - w.0.t).abs() * dlen < etol
            });
            let thin = g.is_some_and(|g| ((g.t_out - g.t_in) as f64) * dlen < etol);
            if !(near || graze || thin) {
                return Err(format!("span disagrees: f32 {g:?} f64 {w:?}"));
            }
        }
    }
    Ok(())
}

/// A hit both found: distance, normal, surface point and its error bound.
fn check_hit(case: &Case, g: &ShapeHit, w: &Crossing, worst: &mut Worst) -> Result<(), String> {
    let s = case.solid.get();
    let dr = DRay::from(&case.ray);
    let dlen = dr.dir.length();
    let dhat = dr.dir / dlen;
    let ng = g.ng.as_dvec3();
    if !ng.is_finite() || ng == DVec3::ZERO || !g.t.is_finite() {
        return Err(format!("bad hit {g:?}"));
    }
    if !(0.0..=1.0).contains(&g.u) || !(0.0..=1.0).contains(&g.v) {
        return Err(format!("u, v out of [0, 1]: {g:?}"));
    }
    let ngh = ng.normalize();
    let p_ref = dr.org + dr.dir * w.t;
    let cos = ngh.dot(dhat).abs().min(w.n.dot(dhat).abs());
    let edge = case.geo.near_edge(p_ref, case.edge_tol());
    let graze = cos < case.geo.grazing();
    let extent = case.extent();
    let scale_d = extent / dlen;
    if !graze {
        let terr = (g.t as f64 - w.t).abs();
        if terr > tol_at(scale_d, cos, case.off, dlen) {
            return Err(format!("t {} vs {} (cos {cos}, scale {scale_d})", g.t, w.t));
        }
        worst.t_frac = worst
            .t_frac
            .max(terr / tol_at(scale_d, cos, case.off, dlen));
        if case.off == Vec3::ZERO {
            worst.t_rel = worst.t_rel.max(terr * dlen * cos.max(1e-3) / extent);
        }
        // Entering or leaving, as the reference says (which has no normal at an apex).
        let apex = case.geo.near_apex(p_ref, case.edge_tol());
        if !apex && (ngh.dot(dhat) < 0.0) != (w.n.dot(dhat) < 0.0) {
            return Err(format!("normal {ng} on the wrong side (reference {})", w.n));
        }
    }
    // Normals at points an error apart differ by the surface's turn over that error.
    let turn = (case.edge_tol() / case.geo.curvature_radius(p_ref)).powi(2);
    if !edge && !graze {
        let dev = 1.0 - ngh.dot(w.n);
        worst.normal = worst.normal.max(dev - turn);
        if dev > 1e-4 + turn {
            return Err(format!("normal {ngh} vs {} (1 − cos = {dev})", w.n));
        }
    }

    let sp = s.surface(&case.ray, g);
    if !sp.p.is_finite() || !sp.err.is_finite() || !sp.err.cmpge(Vec3::ZERO).all() {
        return Err(format!("bad surface point {sp:?}"));
    }
    if (sp.ng.length() - 1.0).abs() > 1e-5 {
        return Err(format!("surface normal {} not unit", sp.ng));
    }
    if sp.ng.as_dvec3().dot(ngh) < 0.99 - turn && !edge {
        return Err(format!("surface normal {} vs hit normal {ngh}", sp.ng));
    }
    let p = sp.p.as_dvec3();
    let d = case.geo.dist(p);
    // The error box holds a point of the surface: within Σ|n_k| err_k of it where the
    // surface is smooth; at an apex (no tangent plane), within the box's half-diagonal.
    let allowed = if case.geo.near_apex(p, case.edge_tol()) {
        sp.err.length() as f64
    } else {
        sp.ng.abs().dot(sp.err) as f64
    };
    let magnitude = sp.p.abs().max_element() as f64 + case.geo.size();
    if d > allowed + 1e-13 * magnitude {
        return Err(format!(
            "surface point {} is {d} off the surface, err {} allows {allowed}",
            sp.p, sp.err
        ));
    }
    if allowed > 0.0 {
        worst.surf = worst.surf.max(d / allowed);
    }
    let err_rel = sp.err.max_element() as f64 / magnitude;
    worst.err_rel = worst.err_rel.max(err_rel);
    if err_rel > 1e-5 {
        return Err(format!("err {} absurd for magnitude {magnitude}", sp.err));
    }
    // The refined point is the hit, not another point of the surface.
    if !graze {
        let gap = (p - p_ref).length();
        // Plus the shift off a rim (at most 64 error bounds along the surface).
        let allowed = tol_at(scale_d, cos, case.off, dlen) * dlen
            + 1e-5 * magnitude
            + 80.0 * sp.err.max_element() as f64;
        if gap > allowed {
            return Err(format!(
                "surface point {} is {gap} from the hit {p_ref}",
                sp.p
            ));
        }
    }
    Ok(())
}

/// A ray spawned from a hit: towards the outside it meets nothing (the solid is convex,
/// so it lies behind the tangent plane); towards the inside it leaves the solid again
/// (an exit, at `t > 0`), and never re-enters at `t ≈ 0`.
fn check_spawn(case: &Case, w: Vec3) -> Result<(), String> {
    let s = case.solid.get();
    let Some(hit) = s.intersect(&case.ray) else {
        return Ok(());
    };
    let sp = s.surface(&case.ray, &hit);
    let n = sp.ng;
    if w.dot(n).abs() < 1e-3 {
        return Ok(());
    }
    let out = if w.dot(n) > 0.0 { w } else { -w };
    let po = offset_ray_origin(sp.p, sp.err, n, out);
    if let Some(again) = s.intersect(&Ray::new(po, out)) {
        return Err(format!(
            "outgoing ray from {} (err {}) re-hit at t = {} ng {}",
            sp.p, sp.err, again.t, again.ng
        ));
    }
    let inw = -out;
    let pi = offset_ray_origin(sp.p, sp.err, n, inw);
    // At the apex of a pointed cone most of the inward hemisphere is outside the solid.
    let apex = case.geo.near_apex(sp.p.as_dvec3(), case.edge_tol())
        || case.geo.near_knife_edge(
            sp.p.as_dvec3(),
            case.edge_tol(),
            sp.err.max_element() as f64,
        );
    match s.intersect(&Ray::new(pi, inw)) {
        _ if apex => Ok(()),
        None => Err(format!("inward ray from {} missed the solid", sp.p)),
        Some(h) if h.ng.normalize().dot(inw) < -1e-3 => Err(format!(
            "inward ray from {} (err {}) entered again at t = {} ng {}",
            sp.p, sp.err, h.t, h.ng
        )),
        Some(_) => Ok(()),
    }
}

/// Points along the case's line: `contains` agrees with the span and with the
/// reference's inside test, away from the surface.
fn check_contains(case: &Case, us: &[f32]) -> Result<(), String> {
    let s = case.solid.get();
    let mut spans = Spans::new();
    s.spans(&case.ray, &mut spans);
    let dlen = case.ray.dir.length() as f64;
    let (a, b) = match spans.first() {
        Some(sp) => (sp.t_in, sp.t_out),
        None => (0.0, (2.0 * case.extent() / dlen) as f32),
    };
    for &u in us {
        let t = a + (b - a) * u;
        let p = case.ray.at(t);
        let pd = p.as_dvec3();
        let near = (pd - case.geo.center()).length() + case.geo.size();
        if case.geo.dist(pd) <= 1e-4 * case.geo.size() + 10.0 * REL * near {
            continue;
        }
        let want = case.geo.inside(pd);
        let in_span = spans
            .first()
            .is_some_and(|sp| t >= sp.t_in && t <= sp.t_out);
        if s.contains(p) != want || in_span != want {
            return Err(format!(
                "at t = {t} ({p}): contains {}, in span {in_span}, reference {want}",
                s.contains(p)
            ));
        }
    }
    Ok(())
}

fn run(case: &Case) -> Result<(), TestCaseError> {
    check(case, &mut Worst::default()).map_err(TestCaseError::fail)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1500))]

    #[test]
    fn capped_cone_matches_f64(case in cone_case()) { run(&case)?; }

    #[test]
    fn aabox_matches_f64(case in aabox_case()) { run(&case)?; }

    #[test]
    fn obox_matches_f64(case in obox_case()) { run(&case)?; }

    #[test]
    fn polyhedron_matches_f64(case in poly_case()) { run(&case)?; }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn spawned_rays_do_not_self_intersect(
        case in prop_oneof![cone_case(), aabox_case(), obox_case(), poly_case()], w in unit(),
    ) {
        check_spawn(&case, w).map_err(TestCaseError::fail)?;
    }

    #[test]
    fn contains_agrees_with_spans(
        case in prop_oneof![cone_case(), aabox_case(), obox_case(), poly_case()],
        us in proptest::collection::vec(-0.5f32..1.5, 12),
    ) {
        check_contains(&case, &us).map_err(TestCaseError::fail)?;
    }
}

/// The measured worst errors over many random cases (run with `--ignored --nocapture`).
#[test]
#[ignore]
fn worst_errors() {
    let n: usize = std::env::var("SOLIDS_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000);
    let kinds: [(&str, BoxedStrategy<Case>); 4] = [
        ("capped cone", cone_case().boxed()),
        ("axis-aligned box", aabox_case().boxed()),
        ("oriented box", obox_case().boxed()),
        ("polyhedron", poly_case().boxed()),
    ];
    let config = ProptestConfig {
        max_local_rejects: u32::MAX,
        ..ProptestConfig::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    for (name, strategy) in kinds {
        let mut worst = Worst::default();
        let (mut failures, mut spawn_failures) = (0, 0);
        for _ in 0..n {
            let case = strategy.new_tree(&mut runner).unwrap().current();
            if let Err(e) = check(&case, &mut worst) {
                failures += 1;
                if failures <= 3 {
                    eprintln!("{name}: {e}\n  {case:?}");
                }
            }
            let w = Vec3::new(0.3, -0.8, 0.52).normalize();
            if let Err(e) = check_spawn(&case, w) {
                spawn_failures += 1;
                if spawn_failures <= 3 {
                    eprintln!("{name} spawn: {e}\n  {case:?}");
                }
            }
        }
        eprintln!("{name}: {failures} + {spawn_failures} (spawn) failures; {worst:?}");
    }
}

// ---------------------------------------------------------------------------------
// Analytic cases.

fn approx(a: f32, b: f64, tol: f64) -> bool {
    (a as f64 - b).abs() <= tol * b.abs().max(1.0)
}

fn first_span(s: &dyn Primitive, ray: &Ray) -> Option<(f32, Vec3, f32, Vec3)> {
    let mut out = Spans::new();
    s.spans(ray, &mut out);
    out.first().map(|s| (s.t_in, s.n_in, s.t_out, s.n_out))
}

fn unit_cylinder() -> CappedCone {
    // Radius 1 along z from 0 to 2.
    CappedCone::cylinder(Vec3::ZERO, Vec3::new(0.0, 0.0, 3.0), 2.0, 1.0).unwrap()
}

#[test]
fn cylinder_axis_ray_hits_the_caps() {
    let c = unit_cylinder();
    for len in [1.0f32, 0.25, 40.0] {
        // From above, straight down the axis: the top cap at z = 2.
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -len));
        let h = c.intersect(&ray).expect("axis ray hits the top cap");
        assert!(approx(h.t, 3.0 / len as f64, 1e-6), "t {}", h.t);
        assert_eq!(h.ng.normalize(), Vec3::Z);
        let (t_in, n_in, t_out, n_out) = first_span(&c, &ray).unwrap();
        assert!(approx(t_in, 3.0 / len as f64, 1e-6) && approx(t_out, 5.0 / len as f64, 1e-6));
        assert_eq!((n_in.normalize(), n_out.normalize()), (Vec3::Z, -Vec3::Z));
        // Parallel to the axis, off it: the same caps.
        let off = Ray::new(Vec3::new(0.5, -0.3, 5.0), Vec3::new(0.0, 0.0, -len));
        assert!(approx(c.intersect(&off).unwrap().t, 3.0 / len as f64, 1e-6));
        // Parallel to the axis outside the radius: nothing.
        let out = Ray::new(Vec3::new(1.01, 0.0, 5.0), Vec3::new(0.0, 0.0, -len));
        assert!(c.intersect(&out).is_none());
        assert!(first_span(&c, &out).is_none());
    }
    // From inside along the axis: the exit cap.
    let inside = Ray::new(Vec3::new(0.0, 0.0, 0.5), Vec3::Z);
    let h = c.intersect(&inside).unwrap();
    assert!(approx(h.t, 1.5, 1e-6));
    assert!(h.ng.dot(Vec3::Z) > 0.0, "outward normal at the exit");
    let down = Ray::new(Vec3::new(0.2, 0.1, 0.5), Vec3::new(0.0, 0.0, -2.0));
    let h = c.intersect(&down).unwrap();
    assert!(approx(h.t, 0.25, 1e-6) && h.ng.dot(Vec3::Z) < 0.0);
    // Nearly along the axis (a tiny, not zero): still the caps.
    let tilt = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(1e-7, 0.0, -1.0));
    assert!(approx(c.intersect(&tilt).unwrap().t, 3.0, 1e-6));
}

#[test]
fn cylinder_spans_equal_the_analytic_interval() {
    // Radius 2, height 3, along a tilted axis, away from the origin.
    let base = Vec3::new(1.0, -2.0, 0.5);
    let axis = Vec3::new(1.0, 2.0, 2.0) / 3.0;
    let (r, h) = (2.0f64, 3.0f64);
    let c = CappedCone::cylinder(base, axis * 7.0, h as f32, r as f32).unwrap();
    let w = c.axis().as_dvec3();
    let b = base.as_dvec3();
    let mut n = 0;
    for i in 0..40 {
        for j in 0..40 {
            let th = i as f64 * 0.157;
            let ph = j as f64 * 0.0785 + 0.01;
            let dir = DVec3::new(ph.sin() * th.cos(), ph.sin() * th.sin(), ph.cos());
            let org = b + DVec3::new(
                0.3 * (i as f64 % 5.0) - 0.6,
                0.2 * (j as f64 % 7.0) - 0.6,
                1.0,
            ) - dir * 6.0;
            let ray = Ray::new(org.as_vec3(), (dir * 1.7).as_vec3());
            let dr = DRay::from(&ray);
            // The infinite cylinder's interval ∩ the slab, analytically.
            let f = dr.org - b;
            let (fs, ds) = (f.dot(w), dr.dir.dot(w));
            let (fp, dp) = (f - w * fs, dr.dir - w * ds);
            let (a, bb, cc) = (dp.dot(dp), dp.dot(fp), fp.dot(fp) - r * r);
            let disc = bb * bb - a * cc;
            let want = if disc < 0.0 {
                None
            } else {
                let (c0, c1) = ((-bb - disc.sqrt()) / a, (-bb + disc.sqrt()) / a);
                let (s0, s1) = ((0.0 - fs) / ds, (h - fs) / ds);
                let (s0, s1) = (s0.min(s1), s0.max(s1));
                let (t0, t1) = (c0.max(s0), c1.min(s1));
                (t0 < t1).then_some((t0, t1))
            };
            let got = first_span(&c, &ray);
            match (got, want) {
                (Some((t0, _, t1, _)), Some((w0, w1))) => {
                    assert!(
                        approx(t0, w0, 1e-5) && approx(t1, w1, 1e-5),
                        "{t0} {t1} vs {w0} {w1}"
                    );
                    n += 1;
                }
                (None, None) => {}
                // Only lines touching the solid within rounding.
                (g, w) => {
                    let len = g
                        .map(|g| (g.2 - g.0) as f64)
                        .or(w.map(|w| w.1 - w.0))
                        .unwrap();
                    assert!(len * 1.7 < 1e-4, "{g:?} vs {w:?}");
                }
            }
        }
    }
    assert!(n > 200, "only {n} lines hit");
}

#[test]
fn rays_through_the_rim_never_slip_between_cap_and_side() {
    for c in [
        unit_cylinder(),
        CappedCone::new(Vec3::ZERO, Vec3::Z, 2.0, 1.0, 0.4).unwrap(),
        CappedCone::new(
            Vec3::new(3.0, 1.0, -2.0),
            Vec3::new(1.0, 1.0, 0.0),
            1.0,
            0.3,
            1.5,
        )
        .unwrap(),
    ] {
        let w = c.axis();
        let f = emray::math::Frame::from_z(w);
        let mut misses = 0;
        for i in 0..2000 {
            let th = i as f32 * 0.0314159;
            let radial = f.x * th.cos() + f.y * th.sin();
            for (center, r, up) in [
                (c.base(), c.base_radius(), -1.0),
                (c.top(), c.top_radius(), 1.0),
            ] {
                let rim = center + radial * r;
                // Into the solid through the rim, from outside both the cap and the side:
                // against both outward normals.
                let k = (c.top_radius() - c.base_radius()) / c.height();
                let side = (radial - w * k).normalize();
                let cap = w * up;
                let into = -(side + cap * (0.6 + (i % 7) as f32 * 0.15));
                if into.dot(side) >= 0.0 || into.dot(cap) >= 0.0 {
                    continue;
                }
                let ray = Ray::new(rim - into * 3.0, into);
                match c.intersect(&ray) {
                    Some(h) => assert!((h.t - 3.0).abs() < 1e-4, "rim hit at t = {}", h.t),
                    None => misses += 1,
                }
            }
        }
        assert_eq!(misses, 0, "rays slipped through the rim of {c:?}");
    }
}

#[test]
fn tangent_rays_to_the_side() {
    let c = unit_cylinder();
    // Exactly tangent at x = 1: a touch at t = 5 or nothing, never NaN.
    let ray = Ray::new(Vec3::new(1.0, -5.0, 1.0), Vec3::Y);
    if let Some(h) = c.intersect(&ray) {
        assert!(
            (h.t - 5.0).abs() < 1e-2 && h.ng.x > 0.0 && h.ng.is_finite(),
            "{h:?}"
        );
    }
    // Just inside: through; just outside: nothing.
    let inner = Ray::new(Vec3::new(0.999, -5.0, 1.0), Vec3::Y);
    let (t0, n0, t1, n1) = first_span(&c, &inner).expect("chord");
    let half = (1.0f64 - 0.999 * 0.999).sqrt();
    assert!(approx(t0, 5.0 - half, 1e-5) && approx(t1, 5.0 + half, 1e-5));
    assert!(n0.y < 0.0 && n1.y > 0.0);
    assert!(
        c.intersect(&Ray::new(Vec3::new(1.001, -5.0, 1.0), Vec3::Y))
            .is_none()
    );
    // A cone's side, tangent along a generator (a = 0: the linear case).
    let k = CappedCone::new(Vec3::ZERO, Vec3::Z, 1.0, 1.0, 0.0).unwrap();
    let along = Ray::new(Vec3::new(1.5, 0.0, -0.5), Vec3::new(-1.0, 0.0, 1.0));
    if let Some(h) = k.intersect(&along) {
        assert!(h.t.is_finite() && h.ng.is_finite() && h.ng != Vec3::ZERO);
    }
    // Parallel to a generator, inside: enters through the base, leaves through the side.
    let inside = Ray::new(Vec3::new(0.5, 0.0, -1.0), Vec3::new(-1.0, 0.0, 1.0));
    let (t0, n0, t1, n1) = first_span(&k, &inside).expect("parallel to a generator");
    assert!(approx(t0, 1.0, 1e-6) && n0.z < 0.0, "{t0} {n0}");
    // Leaves where x + z = 1 along x = 0.5 − s, z = −1 + s: never (parallel), so at the
    // apex side: the line x = −0.5 − z... meets the side at the mirrored generator.
    assert!(
        t1 > t0 && n1.dot(Vec3::new(-1.0, 0.0, 1.0)) > 0.0,
        "{t1} {n1}"
    );
}

#[test]
fn ultra_flat_cone_tells_side_from_base_by_the_point() {
    // Slope 1e5: the side's normal is within 1e-5 of the axis, as the cap's is.
    let c = CappedCone::new(Vec3::ZERO, Vec3::Z, 1e-5, 1.0, 0.0).unwrap();
    let params = |s: &CappedCone| {
        (
            s.base().as_dvec3(),
            s.axis().as_dvec3(),
            s.height() as f64,
            s.base_radius() as f64,
            s.top_radius() as f64,
        )
    };
    let (b, w, h, rb, rt) = params(&c);
    for (org, dir, up) in [
        (Vec3::new(0.5, 0.1, 1.0), -Vec3::Z, true),
        (Vec3::new(-0.3, 0.4, -1.0), Vec3::Z * 3.0, false),
        (Vec3::new(0.9, 0.0, 0.5), Vec3::new(-0.2, 0.1, -1.0), true),
    ] {
        let ray = Ray::new(org, dir);
        let hit = c.intersect(&ray).expect("the coin is hit");
        let sp = c.surface(&ray, &hit);
        let d = refs::capped_cone_distance(sp.p.as_dvec3(), b, w, h, rb, rt);
        assert!(d <= sp.ng.abs().dot(sp.err) as f64, "{sp:?} is {d} off");
        assert_eq!(sp.ng.z > 0.0, up, "{sp:?}");
        assert!((sp.p - ray.at(hit.t)).length() < 1e-5, "{sp:?}");
    }
}

#[test]
fn rays_from_inside_hit_the_exit() {
    let solids: Vec<(Box<dyn Primitive>, Vec3)> = vec![
        (Box::new(unit_cylinder()), Vec3::new(0.2, 0.1, 1.0)),
        (
            Box::new(CappedCone::new(Vec3::ZERO, Vec3::Z, 2.0, 1.0, 0.0).unwrap()),
            Vec3::new(0.1, 0.0, 0.5),
        ),
        (
            Box::new(AaBox::new(Vec3::splat(-1.0), Vec3::new(1.0, 2.0, 3.0)).unwrap()),
            Vec3::ZERO,
        ),
        (
            Box::new(
                OBox::new(
                    Vec3::ONE,
                    Vec3::new(1.0, 2.0, 0.5),
                    Quat::from_rotation_y(0.7),
                )
                .unwrap(),
            ),
            Vec3::ONE,
        ),
        (
            Box::new(Polyhedron::preset("icosahedron", Vec3::ONE, 2.0).unwrap()),
            Vec3::ONE,
        ),
        (
            Box::new(Polyhedron::preset("tetrahedron", Vec3::ZERO, 1.0).unwrap()),
            Vec3::ZERO,
        ),
    ];
    for (s, inside) in &solids {
        assert!(s.contains(*inside));
        for i in 0..200 {
            let a = i as f32 * 0.7;
            let b = i as f32 * 0.31;
            let d =
                Vec3::new(a.cos() * b.sin(), a.sin() * b.sin(), b.cos()) * (0.5 + i as f32 * 0.01);
            let ray = Ray::new(*inside, d);
            let h = s.intersect(&ray).expect("a ray from inside leaves");
            assert!(
                h.t > 0.0 && h.ng.dot(d) > 0.0,
                "exit with outward normal: {h:?}"
            );
            assert!(!s.contains(ray.at(h.t * 1.01)) && s.contains(ray.at(h.t * 0.99)));
        }
    }
}

#[test]
fn oriented_box_with_identity_rotation_is_the_axis_aligned_box() {
    let (c, h) = (Vec3::new(1.5, -2.25, 0.75), Vec3::new(0.5, 1.25, 2.0));
    let ob = OBox::new(c, h, Quat::IDENTITY).unwrap();
    let aa = AaBox::new(c - h, c + h).unwrap();
    assert!(ob.bounds().contains(aa.min()) && ob.bounds().contains(aa.max()));
    let mut hits = 0;
    for i in 0..5000 {
        let f = i as f32;
        let org = Vec3::new((f * 0.37).sin(), (f * 0.91).cos(), (f * 0.13).sin()) * 6.0;
        let target = c + Vec3::new((f * 1.7).sin(), (f * 2.3).cos(), (f * 0.7).cos()) * h * 1.1;
        let ray = Ray::new(org, (target - org) * 0.7);
        match (ob.intersect(&ray), aa.intersect(&ray)) {
            (Some(a), Some(b)) => {
                assert!((a.t - b.t).abs() <= 1e-6 * b.t.max(1.0), "{a:?} {b:?}");
                assert_eq!(a.ng, b.ng);
                assert!((a.u - b.u).abs() < 1e-5 && (a.v - b.v).abs() < 1e-5);
                hits += 1;
            }
            (None, None) => {}
            (a, b) => panic!("identity OBox {a:?} vs AaBox {b:?}"),
        }
    }
    assert!(hits > 1000);
}

#[test]
fn rotated_oriented_box_is_the_polyhedron_of_its_planes() {
    let q = Quat::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 0.9);
    let (c, h) = (Vec3::new(10.0, -3.0, 4.0), Vec3::new(0.5, 1.5, 1.0));
    let ob = OBox::new(c, h, q).unwrap();
    let axes = ob.axes();
    let planes = (0..6)
        .map(|k| {
            let n = axes[k / 2] * if k % 2 == 0 { 1.0 } else { -1.0 };
            (n, n.dot(c) + h[k / 2])
        })
        .collect();
    let poly = Polyhedron::new(planes).unwrap();
    assert_eq!(poly.vertices().len(), 8);
    let mut hits = 0;
    for i in 0..5000 {
        let f = i as f32;
        let org = c + Vec3::new((f * 0.37).sin(), (f * 0.91).cos(), (f * 0.13).sin()) * 8.0;
        let target = c + Vec3::new((f * 1.7).sin(), (f * 2.3).cos(), (f * 0.7).cos()) * 1.5;
        let ray = Ray::new(org, (target - org) * 1.3);
        match (ob.intersect(&ray), poly.intersect(&ray)) {
            (Some(a), Some(b)) => {
                assert!((a.t - b.t).abs() <= 1e-5 * b.t.max(1.0), "{a:?} {b:?}");
                assert!(
                    a.ng.normalize().dot(b.ng.normalize()) > 1.0 - 1e-6,
                    "{a:?} {b:?}"
                );
                hits += 1;
            }
            (None, None) => {}
            (a, b) => {
                // Only through an edge, within rounding.
                let t = a.map(|a| a.t).or(b.map(|b| b.t)).unwrap();
                let p = ray.at(t);
                let l = (0..3)
                    .map(|k| axes[k].dot(p - c).abs() - h[k])
                    .filter(|e| e.abs() < 1e-4);
                assert!(l.count() >= 2, "OBox {a:?} vs polyhedron {b:?}");
            }
        }
    }
    assert!(hits > 1000);
}

// ---------------------------------------------------------------------------------
// Presets.

#[test]
fn presets_are_regular_with_the_given_circumradius() {
    let center = Vec3::new(3.0, -1.0, 2.0);
    let r = 2.5f32;
    // (name, faces, vertices, inradius / circumradius)
    let ico = ((5.0 + 2.0 * 5f64.sqrt()) / 15.0).sqrt();
    let table = [
        ("cube", 6, 8, 1.0 / 3f64.sqrt()),
        ("box", 6, 8, 1.0 / 3f64.sqrt()),
        ("tetrahedron", 4, 4, 1.0 / 3.0),
        ("octahedron", 8, 6, 1.0 / 3f64.sqrt()),
        ("dodecahedron", 12, 20, ico),
        ("icosahedron", 20, 12, ico),
    ];
    assert_eq!(Polyhedron::PRESETS.len(), table.len());
    for (name, faces, verts, ratio) in table {
        let p = Polyhedron::preset(name, center, r).unwrap();
        assert_eq!(p.face_count(), faces, "{name}");
        let v = p.vertices();
        assert_eq!(v.len(), verts, "{name}");
        let c = center.as_dvec3();
        for q in &v {
            let d = (*q - c).length();
            assert!(
                (d - r as f64).abs() < 1e-5 * r as f64,
                "{name}: vertex at {d}"
            );
        }
        // Inradius: every face plane at the same distance from the centre.
        for (n, d) in p.world_planes() {
            let inr = (d - n.dot(c)) / n.length();
            assert!(
                (inr / r as f64 - ratio).abs() < 1e-6,
                "{name}: inradius ratio {}",
                inr / r as f64
            );
        }
        assert!(p.contains(center));
        // Its bounds hold every vertex.
        let b = p.bounds();
        assert!(v.iter().all(|q| b.contains(q.as_vec3())));
    }
    assert!(Polyhedron::preset("ICOSAHEDRON", center, r).is_ok());
    let err = Polyhedron::preset("cuboctahedron", center, r)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("cuboctahedron") && err.contains("dodecahedron"),
        "{err}"
    );
}

#[test]
fn dodecahedron_and_icosahedron_are_duals() {
    let d = Polyhedron::preset("dodecahedron", Vec3::ZERO, 1.0).unwrap();
    let i = Polyhedron::preset("icosahedron", Vec3::ZERO, 1.0).unwrap();
    // The icosahedron's vertices point along the dodecahedron's face normals and back.
    for (solid, dual) in [(&d, &i), (&i, &d)] {
        let normals: Vec<DVec3> = solid
            .world_planes()
            .iter()
            .map(|p| p.0.normalize())
            .collect();
        let verts = dual.vertices();
        assert_eq!(normals.len(), verts.len());
        for v in verts {
            let v = v.normalize();
            assert!(
                normals.iter().any(|n| n.dot(v) > 1.0 - 1e-6),
                "vertex {v} is no face normal"
            );
        }
    }
    // Inradius over circumradius: √((5 + 2√5) / 15) for both.
    let want = ((5.0 + 2.0 * 5f64.sqrt()) / 15.0).sqrt();
    for p in [&d, &i] {
        let inr = p
            .world_planes()
            .iter()
            .map(|(n, d)| d / n.length())
            .fold(f64::INFINITY, f64::min);
        let circ = p.vertices().iter().map(|v| v.length()).fold(0.0, f64::max);
        assert!((inr / circ - want).abs() < 1e-6, "{} vs {want}", inr / circ);
    }
}

#[test]
fn prisms() {
    for sides in [3u32, 4, 5, 6, 17, 64] {
        let c = Vec3::new(-1.0, 2.0, 0.5);
        let p = Polyhedron::prism(c, sides, 1.5, 0.75).unwrap();
        assert_eq!(p.face_count(), sides as usize + 2);
        let v = p.vertices();
        assert_eq!(v.len(), 2 * sides as usize, "{sides} sides");
        for q in v {
            let d = q - c.as_dvec3();
            assert!(
                (d.truncate().length() - 1.5).abs() < 1e-5,
                "{sides}: vertex {q}"
            );
            assert!((d.z.abs() - 0.375).abs() < 1e-6);
        }
        // Straight down the axis: the top at z = 0.875.
        let h = p.intersect(&Ray::new(c + Vec3::Z * 3.0, -Vec3::Z)).unwrap();
        assert!((h.t - 2.625).abs() < 1e-5 && h.ng.z > 0.99);
    }
    // The most planes allowed: validation enumerates plane triples, still quick.
    let start = std::time::Instant::now();
    let big = Polyhedron::prism(Vec3::ZERO, 254, 1.0, 1.0).unwrap();
    assert_eq!(big.face_count(), 256);
    eprintln!("254-sided prism built in {:?}", start.elapsed());
    assert!(Polyhedron::prism(Vec3::ZERO, 255, 1.0, 1.0).is_err());
    assert!(Polyhedron::prism(Vec3::ZERO, 2, 1.0, 1.0).is_err());
    assert!(Polyhedron::prism(Vec3::ZERO, 5, 0.0, 1.0).is_err());
    assert!(Polyhedron::prism(Vec3::ZERO, 5, 1.0, f32::NAN).is_err());
}

// ---------------------------------------------------------------------------------
// Degenerate input.

fn all_solids() -> Vec<Box<dyn Primitive>> {
    vec![
        Box::new(unit_cylinder()),
        Box::new(CappedCone::new(Vec3::ZERO, Vec3::Z, 2.0, 0.0, 1.0).unwrap()),
        Box::new(AaBox::new(Vec3::ZERO, Vec3::ONE).unwrap()),
        Box::new(OBox::new(Vec3::ZERO, Vec3::ONE, Quat::from_rotation_z(0.3)).unwrap()),
        Box::new(OBox::new(Vec3::ZERO, Vec3::ONE, Quat::IDENTITY).unwrap()),
        Box::new(Polyhedron::preset("cube", Vec3::splat(0.5), 3f32.sqrt() * 0.5).unwrap()),
        Box::new(Polyhedron::preset("octahedron", Vec3::ZERO, 1.0).unwrap()),
    ]
}

#[test]
fn no_panics_and_no_nan_for_degenerate_rays() {
    let nan = f32::NAN;
    let inf = f32::INFINITY;
    let vals = [
        0.0f32, -0.0, 1.0, -1.0, 0.5, 2.0, 1e-30, -1e30, nan, inf, -inf,
    ];
    let mut rays = Vec::new();
    for &a in &vals {
        for &b in &vals {
            rays.push(Ray::new(Vec3::new(a, 0.5, b), Vec3::new(b, 0.0, a)));
            rays.push(Ray::new(Vec3::new(0.0, a, 1.0), Vec3::new(0.0, b, -1.0)));
            rays.push(Ray::new(Vec3::new(1.0, 1.0, a), Vec3::new(b, b, 1.0)));
            rays.push(Ray {
                org: Vec3::new(0.5, 0.5, 3.0),
                dir: -Vec3::Z,
                tmin: a,
                tmax: b,
            });
        }
    }
    for s in all_solids() {
        for ray in &rays {
            let h = s.intersect(ray);
            if let Some(h) = h {
                assert!(
                    h.t.is_finite() && h.t > ray.tmin && h.t < ray.tmax,
                    "{ray:?}: {h:?}"
                );
                assert!(h.ng.is_finite() && h.ng != Vec3::ZERO, "{ray:?}: {h:?}");
                assert!(!h.u.is_nan() && !h.v.is_nan());
                let sp = s.surface(ray, &h);
                assert!(
                    sp.p.is_finite() && sp.err.is_finite() && sp.ng.is_finite(),
                    "{sp:?}"
                );
            }
            assert_eq!(s.occluded(ray), h.is_some(), "{ray:?}");
            let mut spans = Spans::new();
            s.spans(ray, &mut spans);
            for sp in &spans {
                assert!(!sp.t_in.is_nan() && !sp.t_out.is_nan() && sp.t_in <= sp.t_out);
                assert!(sp.n_in.is_finite() && sp.n_out.is_finite());
                assert!(sp.n_in != Vec3::ZERO && sp.n_out != Vec3::ZERO);
            }
        }
        assert!(!s.contains(Vec3::splat(nan)));
    }
}

#[test]
fn rays_parallel_to_faces_and_origins_on_face_planes() {
    let aa = AaBox::new(Vec3::ZERO, Vec3::ONE).unwrap();
    let ob = OBox::new(Vec3::splat(0.5), Vec3::splat(0.5), Quat::IDENTITY).unwrap();
    let poly = Polyhedron::new(vec![
        (Vec3::X, 1.0),
        (-Vec3::X, 0.0),
        (Vec3::Y, 1.0),
        (-Vec3::Y, 0.0),
        (Vec3::Z, 1.0),
        (-Vec3::Z, 0.0),
    ])
    .unwrap();
    let solids: [&dyn Primitive; 3] = [&aa, &ob, &poly];
    for s in solids {
        // In the plane x = 0 (a face plane), parallel to it: inside the closed slab.
        let r = Ray::new(Vec3::new(0.0, 0.5, -1.0), Vec3::Z);
        let h = s.intersect(&r).map(|h| h.t);
        assert!(h.is_none() || (h.unwrap() - 1.0).abs() < 1e-6, "{h:?}");
        // Parallel, just outside: nothing.
        assert!(
            s.intersect(&Ray::new(Vec3::new(-1e-6, 0.5, -1.0), Vec3::Z))
                .is_none()
        );
        // Parallel, inside: enters through z = 0 at t = 1, leaves through z = 1.
        let r = Ray::new(Vec3::new(0.5, 0.5, -1.0), Vec3::Z * 2.0);
        let h = s.intersect(&r).unwrap();
        assert!((h.t - 0.5).abs() < 1e-6 && h.ng.z < 0.0);
        // Origin on a face, going in: the exit; going out: nothing.
        let r = Ray::new(Vec3::new(0.5, 0.5, 0.0), Vec3::Z);
        let h = s.intersect(&r).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6 && h.ng.z > 0.0);
        assert!(
            s.intersect(&Ray::new(Vec3::new(0.5, 0.5, 0.0), -Vec3::Z))
                .is_none()
        );
        // Along an edge (in two face planes): a hit or none, never NaN.
        let r = Ray::new(Vec3::new(0.0, 0.0, -1.0), Vec3::Z);
        if let Some(h) = s.intersect(&r) {
            assert!(h.t.is_finite() && h.ng.is_finite());
        }
    }
}

#[test]
fn constructors_reject_bad_input() {
    let z = Vec3::ZERO;
    let errs = [
        CappedCone::new(z, Vec3::ZERO, 1.0, 1.0, 1.0).unwrap_err(),
        CappedCone::new(z, Vec3::Z, 0.0, 1.0, 1.0).unwrap_err(),
        CappedCone::new(z, Vec3::Z, -1.0, 1.0, 1.0).unwrap_err(),
        CappedCone::new(z, Vec3::Z, 1.0, -1.0, 1.0).unwrap_err(),
        CappedCone::new(z, Vec3::Z, 1.0, 0.0, 0.0).unwrap_err(),
        CappedCone::new(Vec3::splat(f32::NAN), Vec3::Z, 1.0, 1.0, 1.0).unwrap_err(),
        CappedCone::new(z, Vec3::Z, f32::INFINITY, 1.0, 1.0).unwrap_err(),
        CappedCone::cylinder(z, Vec3::Z, 1.0, 0.0).unwrap_err(),
        AaBox::new(Vec3::ONE, Vec3::ZERO).unwrap_err(),
        AaBox::new(z, Vec3::new(1.0, 0.0, 1.0)).unwrap_err(),
        AaBox::new(z, Vec3::new(1.0, f32::INFINITY, 1.0)).unwrap_err(),
        OBox::new(z, Vec3::new(1.0, 0.0, 1.0), Quat::IDENTITY).unwrap_err(),
        OBox::new(z, Vec3::ONE, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)).unwrap_err(),
        OBox::new(z, Vec3::ONE, Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0)).unwrap_err(),
        OBox::from_axes(z, Vec3::ONE, [Vec3::X, Vec3::X, Vec3::Z]).unwrap_err(),
        Polyhedron::new(vec![(Vec3::X, 1.0), (-Vec3::X, 1.0), (Vec3::Y, 1.0)]).unwrap_err(),
        // Unbounded: no plane faces −z.
        Polyhedron::new(vec![
            (Vec3::X, 1.0),
            (-Vec3::X, 1.0),
            (Vec3::Y, 1.0),
            (-Vec3::Y, 1.0),
            (Vec3::Z, 1.0),
        ])
        .unwrap_err(),
        // Empty: x ≤ −1 and x ≥ 1.
        Polyhedron::new(vec![
            (Vec3::X, -1.0),
            (-Vec3::X, -1.0),
            (Vec3::Y, 1.0),
            (-Vec3::Y, 1.0),
            (Vec3::Z, 1.0),
            (-Vec3::Z, 1.0),
        ])
        .unwrap_err(),
        // Flat: 0 ≤ x ≤ 0.
        Polyhedron::new(vec![
            (Vec3::X, 0.0),
            (-Vec3::X, 0.0),
            (Vec3::Y, 1.0),
            (-Vec3::Y, 1.0),
            (Vec3::Z, 1.0),
            (-Vec3::Z, 1.0),
        ])
        .unwrap_err(),
        Polyhedron::new(vec![(Vec3::ZERO, 1.0); 4]).unwrap_err(),
        Polyhedron::preset("cube", z, 0.0).unwrap_err(),
    ];
    for e in errs {
        assert!(!e.to_string().is_empty());
    }
    // The messages name the solid and the offending value.
    let e = CappedCone::cylinder(z, Vec3::Z, 1.0, -2.0)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("cylinder") && e.contains("-2"), "{e}");
    let e = CappedCone::cylinder(z, Vec3::Z, -3.0, 1.0)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("cylinder") && e.contains("-3"), "{e}");
    let e = CappedCone::new(z, Vec3::Z, 1.0, 1.0, -0.5)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("capped cone") && e.contains("top radius -0.5"),
        "{e}"
    );
    let e = AaBox::new(Vec3::ONE, Vec3::ZERO).unwrap_err().to_string();
    assert!(e.starts_with("box"), "{e}");
    let e = Polyhedron::new(vec![(Vec3::X, 1.0); 3])
        .unwrap_err()
        .to_string();
    assert!(e.contains("3 planes"), "{e}");
    // Axes in any handedness describe the same box.
    let l = OBox::from_axes(z, Vec3::new(1.0, 2.0, 3.0), [Vec3::Y, Vec3::X, Vec3::Z]).unwrap();
    let b = l.bounds();
    assert!(
        (b.max - Vec3::new(2.0, 1.0, 3.0)).abs().max_element() < 1e-5,
        "{b:?}"
    );
}

#[test]
fn shapes_stay_small() {
    assert!(std::mem::size_of::<Polyhedron>() <= 40);
    assert!(std::mem::size_of::<CappedCone>() <= 40);
    assert!(std::mem::size_of::<OBox>() <= 40);
}
