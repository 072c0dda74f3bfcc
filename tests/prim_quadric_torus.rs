//! Quadrics, planes and tori against their independent f64 references
//! (`precise::quadric`: the homogeneous form solved directly; `precise::torus`: dense
//! sampling of the implicit function and bisection), on random placements across twelve
//! orders of magnitude, plus analytic cases and the robustness of spawned rays.
//!
//! Tolerances (all stated here, measured worst cases in `worst_errors`):
//! * hit `t`: `T_ULPS` f32 ulps of `t` plus `T_REL × scale / |cos θ|` (`scale` the size
//!   of the configuration in units of `t`, `θ` the angle between ray and normal): the f32
//!   intersectors compute in f64 and round `t` once, so only the f64 conditioning of
//!   the two formulations remains;
//! * hit/miss and span-count disagreements only for rays within `GRAZE` of tangency
//!   (`|cos θ|` at the surface point nearest the crossing) or crossings in a pair closer
//!   than `CHORD × size` (a near-tangent chord), crossings within `EDGE × size` of a clip
//!   box face, or at `|t| ≤ NEAR0 × scale` (origin on the surface);
//! * normals: `NORMAL_ANGLE` radians where `|∇F|` is not near a singular point (plus,
//!   for quadrics, the turn of the normal over the reference's own f64 uncertainty);
//! * `surface()`: the true surface point lies within `err`, and `err` is at most
//!   `ERR_ULPS` ulps of the point's largest coordinate.

use emray::geometry::precise::{quadric as rq, torus as rt};
use emray::geometry::{Intersect, Plane, Primitive, Quadric, ShapeHit, Spans, Sphere, Torus};
use emray::math::{Aabb, DRay, DVec3, Ray, Vec3, offset_ray_origin};
use proptest::prelude::*;

const T_ULPS: f64 = 1.0;
const T_REL: f64 = 1e-9;
const GRAZE: f64 = 1e-4;
const CHORD: f64 = 2e-3;
const EDGE: f64 = 1e-7;
const NEAR0: f64 = 1e-9;
const NORMAL_ANGLE: f64 = 1e-6;
const ERR_ULPS: f32 = 4.0;

/// `n` cases, times `$PRIM_STRESS` when set (e.g. `PRIM_STRESS=100` for a long run).
fn cases(n: u32) -> ProptestConfig {
    let k = std::env::var("PRIM_STRESS")
        .ok()
        .and_then(|v| v.parse::<u32>().ok())
        .unwrap_or(1);
    ProptestConfig {
        max_local_rejects: 65536 * k.max(1),
        ..ProptestConfig::with_cases(n * k.max(1))
    }
}

fn v3() -> impl Strategy<Value = Vec3> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn unit() -> impl Strategy<Value = Vec3> {
    v3().prop_filter("nonzero", |v| v.length() > 0.1)
        .prop_map(|v| v.normalize())
}

/// As in tests/intersectors.rs: a scale spanning 12 orders of magnitude and an offset
/// far from the origin, the object at least 1e-3 of its offset across.
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

/// One f32 ulp of `t`.
fn ulp(t: f64) -> f64 {
    (t.abs() as f32 * f32::EPSILON) as f64
}

/// The `t` tolerance at `t` for a configuration of size `scale` (in units of `t`).
fn t_tol(t: f64, scale: f64, cos: f64) -> f64 {
    T_ULPS * ulp(t) + T_REL * (scale + t.abs()) / cos.abs().max(1e-6)
}

/// Angle between two directions, in radians.
fn angle(a: DVec3, b: DVec3) -> f64 {
    let (a, b) = (a.normalize(), b.normalize());
    (a - b).length().atan2((a + b).length()) * 2.0
}

/// An orthonormal frame from two random vectors (Gram–Schmidt in f64).
fn frame(a: Vec3, b: Vec3) -> [DVec3; 3] {
    let u = a.as_dvec3().normalize();
    let v = (b.as_dvec3() - u * u.dot(b.as_dvec3())).normalize_or(u.any_orthonormal_vector());
    [u, v, u.cross(v)]
}

/// A random quadric, written out as world coefficients by the test itself.
#[derive(Clone, Debug)]
struct QCase {
    kind: usize,
    coeffs: [f64; 10],
    center: DVec3,
    size: f64,
    clip: Option<Aabb>,
}

const KINDS: [&str; 7] = [
    "ellipsoid",
    "cylinder",
    "cone",
    "paraboloid",
    "hyperboloid (1 sheet)",
    "hyperboloid (2 sheets)",
    "saddle",
];

/// `Σ λ_k (u_k·y)² + 2μ (u_2·y) + κ` with `y = (p − c)/s`, expanded in f64.
fn quadric_case(
    kind: usize,
    s: f32,
    c: Vec3,
    rot: [DVec3; 3],
    radii: Vec3,
    clip: Option<Vec3>,
) -> QCase {
    let r = radii.as_dvec3();
    let i2 = DVec3::ONE / (r * r);
    let (lam, mu, kappa) = match kind {
        0 => ([i2.x, i2.y, i2.z], 0.0, -1.0),
        1 => ([i2.x, i2.y, 0.0], 0.0, -1.0),
        2 => ([i2.x, i2.y, -i2.z], 0.0, 0.0),
        3 => ([i2.x, i2.y, 0.0], -0.5, 0.0),
        4 => ([i2.x, i2.y, -i2.z], 0.0, -1.0),
        5 => ([i2.x, i2.y, -i2.z], 0.0, 1.0),
        _ => ([i2.x, -i2.y, 0.0], -0.5, 0.0),
    };
    let s64 = s as f64;
    let c64 = c.as_dvec3();
    let mut m = [[0.0f64; 3]; 3];
    for k in 0..3 {
        for a in 0..3 {
            for b in 0..3 {
                m[a][b] += lam[k] / (s64 * s64) * rot[k][a] * rot[k][b];
            }
        }
    }
    let mc = DVec3::new(
        m[0][0] * c64.x + m[0][1] * c64.y + m[0][2] * c64.z,
        m[1][0] * c64.x + m[1][1] * c64.y + m[1][2] * c64.z,
        m[2][0] * c64.x + m[2][1] * c64.y + m[2][2] * c64.z,
    );
    let l = rot[2] * (mu / s64) - mc;
    let j = c64.dot(mc) - 2.0 * (mu / s64) * rot[2].dot(c64) + kappa;
    QCase {
        kind,
        coeffs: [
            m[0][0], m[1][1], m[2][2], m[0][1], m[0][2], m[1][2], l.x, l.y, l.z, j,
        ],
        center: c64,
        size: s64,
        clip: clip.map(|h| Aabb {
            min: c - h * s,
            max: c + h * s,
        }),
    }
}

fn clip64(clip: Option<Aabb>) -> Option<(DVec3, DVec3)> {
    clip.map(|b| (b.min.as_dvec3(), b.max.as_dvec3()))
}

/// The same line with its origin moved (in f64) to the point nearest `c`, and the
/// parameter of that point: the straightforward reference solve then does not lose
/// `F(o)` to cancellation for origins millions of sizes away. (A change of
/// parametrisation done here, by the test, not by the reference.)
fn rebased(dr: &DRay, c: DVec3) -> (DRay, f64) {
    let t = (c - dr.org).dot(dr.dir) / dr.dir.length_squared();
    (
        DRay {
            org: dr.org + dr.dir * t,
            dir: dr.dir,
        },
        t,
    )
}

/// The reference's nearest hit `t > 0`.
fn ref_hit(qc: &QCase, dr: &DRay) -> Option<f64> {
    let (near, t0) = rebased(dr, qc.center);
    rq::quadric(&near, &qc.coeffs, clip64(qc.clip), -t0).map(|t| t + t0)
}

/// The reference's roots along the whole line.
fn ref_roots(qc: &QCase, dr: &DRay) -> Vec<f64> {
    let (near, t0) = rebased(dr, qc.center);
    rq::quadric_roots(&near, &qc.coeffs)
        .into_iter()
        .map(|t| t + t0)
        .collect()
}

/// The reference's spans.
fn ref_spans(qc: &QCase, dr: &DRay) -> Vec<(f64, f64)> {
    let (near, t0) = rebased(dr, qc.center);
    rq::quadric_spans(&near, &qc.coeffs, clip64(qc.clip))
        .into_iter()
        .map(|(a, b)| (a + t0, b + t0))
        .collect()
}

/// Distance of `p` from the nearest face of the box (0 when there is no box).
fn edge_distance(clip: Option<Aabb>, p: DVec3) -> f64 {
    match clip {
        Some(b) => {
            let lo = (p - b.min.as_dvec3()).abs();
            let hi = (b.max.as_dvec3() - p).abs();
            lo.min(hi).min_element()
        }
        None => f64::INFINITY,
    }
}

/// `|cos θ|` between the ray and the quadric's normal near `t`; 0 at singular points.
fn q_cos(qc: &QCase, ray: &DRay, t: f64) -> f64 {
    // At the surface point nearest the line's point: for a line that just misses (a
    // crossing found only by rounding) that is the tangent point, where cos θ ≈ 0.
    let mut p = ray.org + ray.dir * t;
    for _ in 0..4 {
        let g = rq::quadric_gradient(&qc.coeffs, p);
        let step = g * (rq::quadric_value(&qc.coeffs, p) / g.length_squared());
        if step.is_finite() {
            p -= step;
        }
    }
    let g = rq::quadric_gradient(&qc.coeffs, p);
    let c = g.normalize_or_zero().dot(ray.dir.normalize()).abs();
    if c.is_finite() { c } else { 0.0 }
}

/// The finite ends of spans.
fn span_ends(spans: &Spans) -> Vec<f64> {
    spans
        .iter()
        .flat_map(|s| [s.t_in as f64, s.t_out as f64])
        .filter(|t| t.is_finite())
        .collect()
}

/// Whether the crossing at `t` has a partner within `CHORD × size` along the line in
/// one of the lists: a near-tangent pair (a chord that short means `|cos θ| ≲ CHORD/2`
/// in units of the curvature radius), which rounding may find or not.
fn short_chord(lists: &[Vec<f64>], t: f64, dir_len: f64, size: f64) -> bool {
    lists.iter().any(|l| {
        l.iter()
            .filter(|&&u| (u - t).abs() * dir_len <= CHORD * size)
            .count()
            >= 2
    })
}

/// Whether a crossing at `t` may legitimately be found by one side only.
fn q_exempt(qc: &QCase, ray: &DRay, t: f64, scale: f64) -> bool {
    if !t.is_finite() {
        return true;
    }
    let p = ray.org + ray.dir * t;
    q_cos(qc, ray, t) < GRAZE
        || edge_distance(qc.clip, p) < EDGE * qc.size
        || t.abs() <= NEAR0 * scale
        || near_singular(qc, p)
}

/// The reference's own uncertainty at a crossing `p`, as a distance along the ray: its
/// world coefficients evaluated in f64 lose `ε·Σ|terms|` to cancellation far from the
/// origin, which moves the crossing by that over `|∇F|·cos θ`.
fn q_ref_shift(qc: &QCase, p: DVec3, cos: f64) -> f64 {
    let c = qc.coeffs.map(f64::abs);
    let a = p.abs();
    let f_abs = c[0] * a.x * a.x
        + c[1] * a.y * a.y
        + c[2] * a.z * a.z
        + 2.0 * (c[3] * a.x * a.y + c[4] * a.x * a.z + c[5] * a.y * a.z)
        + 2.0 * (c[6] * a.x + c[7] * a.y + c[8] * a.z)
        + c[9];
    let g = rq::quadric_gradient(&qc.coeffs, p).length();
    16.0 * f64::EPSILON * f_abs / (g * cos.max(1e-3))
}

/// The normal tolerance at a reference crossing `p`: `NORMAL_ANGLE` plus how far the
/// normal turns over the reference's own uncertainty there.
fn q_normal_tol(qc: &QCase, p: DVec3, cos: f64) -> f64 {
    let c = qc.coeffs.map(f64::abs);
    let m_norm =
        (c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + 2.0 * (c[3] * c[3] + c[4] * c[4] + c[5] * c[5]))
            .sqrt();
    let g = rq::quadric_gradient(&qc.coeffs, p).length();
    NORMAL_ANGLE + 2.0 * m_norm / g * q_ref_shift(qc, p, cos)
}

/// Near a singular point (a cone's apex) the gradient vanishes and the normal is
/// ill-defined.
fn near_singular(qc: &QCase, p: DVec3) -> bool {
    qc.kind == 2 && (p - qc.center).length() < 1e-3 * qc.size
}

/// The distance from `p` to the quadric, to first order (`|F| / |∇F|`).
fn q_distance(qc: &QCase, p: DVec3) -> f64 {
    rq::quadric_value(&qc.coeffs, p).abs() / rq::quadric_gradient(&qc.coeffs, p).length()
}

/// Checks `surface()` for a hit: the true surface point within `err` along the normal,
/// `err` at most a few ulps, the point on the ray (up to the rounding of `t`), the normal
/// unit and that of the surface at the point. Returns
/// the worst (distance / allowed, err in ulps).
fn check_surface(
    shape: &dyn Intersect,
    ray: &Ray,
    hit: &ShapeHit,
    distance: impl Fn(DVec3) -> f64,
    normal_at: impl Fn(DVec3) -> DVec3,
    size: f64,
) -> Result<(f64, f64), TestCaseError> {
    let sp = shape.surface(ray, hit);
    prop_assert!(sp.p.is_finite() && sp.err.is_finite() && sp.ng.is_finite());
    prop_assert!(
        (sp.ng.length() - 1.0).abs() < 1e-5,
        "normal not unit: {}",
        sp.ng
    );
    let p = sp.p.as_dvec3();
    let n = sp.ng.as_dvec3();
    // The projection of the error box on the normal: what offset_ray_origin moves by.
    let allowed = n.abs().dot(sp.err.as_dvec3());
    let dist = distance(p);
    prop_assert!(
        dist <= allowed,
        "surface point {dist} off the surface, err {} allows {allowed}",
        sp.err
    );
    let big = sp.p.abs().max_element().max(f32::MIN_POSITIVE);
    let ulps = (sp.err.max_element() / (big * f32::EPSILON)) as f64;
    prop_assert!(
        sp.err.max_element() <= ERR_ULPS * big * f32::EPSILON + 1e-9 * size as f32,
        "err {} is {ulps} ulps of {big}",
        sp.err
    );
    let on_ray = ray.org.as_dvec3() + ray.dir.as_dvec3() * hit.t as f64;
    let gap = (on_ray - p).length();
    // The ray's own crossing, up to the rounding of t along the ray and of the point.
    let t_slack = 4.0 * ulp(hit.t as f64) * ray.dir.length() as f64;
    prop_assert!(
        gap <= t_slack + 8.0 * ulp(on_ray.abs().max_element()) + 1e-9 * size,
        "surface point {gap} away from the ray's point"
    );
    // The normal of the surface at the returned point (not at the ray's point: t is
    // rounded to f32), up to how much it turns within the point's own error box.
    let true_normal = normal_at(p);
    if true_normal.length() > 0.0 {
        let e = sp.err.as_dvec3();
        let turn = (0..8)
            .map(|k| {
                let corner = DVec3::new(
                    if k & 1 == 0 { -e.x } else { e.x },
                    if k & 2 == 0 { -e.y } else { e.y },
                    if k & 4 == 0 { -e.z } else { e.z },
                );
                angle(true_normal, normal_at(p + corner))
            })
            .fold(0.0, f64::max);
        prop_assert!(
            angle(n, true_normal) < NORMAL_ANGLE + 2.0 * turn,
            "surface normal {n} vs {true_normal} (turns by {turn} within err)"
        );
    }
    Ok((dist / allowed.max(f64::MIN_POSITIVE), ulps))
}

/// Spawned rays from a surface point: one leaving outwards and one inwards along
/// directions at least `min_cos` from the tangent plane; neither may hit the surface
/// again within `1e-5 × size`, and the spawned origin must be on the side it leaves to
/// (`side(p) > 0` outside).
fn check_spawn(
    shape: &dyn Intersect,
    ray: &Ray,
    hit: &ShapeHit,
    w: Vec3,
    side: impl Fn(DVec3) -> f64,
    size: f64,
) -> Result<(), TestCaseError> {
    let sp = shape.surface(ray, hit);
    let n = sp.ng;
    if w.dot(n).abs() < 0.05 {
        return Ok(());
    }
    for dir in [w, -w] {
        let po = offset_ray_origin(sp.p, sp.err, n, dir);
        let out = dir.dot(n) > 0.0;
        let f = side(po.as_dvec3());
        prop_assert!(
            if out { f > 0.0 } else { f < 0.0 },
            "spawned origin on the wrong side (out {out}, F {f})"
        );
        if let Some(again) = shape.intersect(&Ray::new(po, dir)) {
            prop_assert!(
                again.t as f64 > 1e-5 * size,
                "self-hit at t = {} (size {size}, out {out})",
                again.t
            );
        }
    }
    Ok(())
}

/// `contains` at the points `ts` of the line agrees with the spans, except within
/// `1e-3 × size` of the surface (by `distance`) or within the f32 rounding of the span
/// ends.
fn check_contains(
    solid: &dyn Primitive,
    ray: &DRay,
    spans: &Spans,
    ts: impl Iterator<Item = f64>,
    distance: impl Fn(DVec3) -> f64,
    size: f64,
) -> Result<(), TestCaseError> {
    for t in ts {
        let p = ray.org + ray.dir * t;
        let end_err = 4.0 * ulp(t) * ray.dir.length();
        if !p.is_finite() || distance(p) <= 1e-3 * size + end_err {
            continue;
        }
        let in_spans = spans
            .iter()
            .any(|s| (s.t_in as f64) <= t && t <= s.t_out as f64);
        prop_assert_eq!(
            solid.contains(p.as_vec3()),
            in_spans,
            "contains vs spans at t = {}",
            t
        );
    }
    Ok(())
}

/// Checks that spans are sorted, disjoint, finite where the solid is bounded, with
/// outward normals at finite ends (entry normal against the ray, exit along it, up to
/// rounding at grazing ends).
fn check_span_shape(spans: &Spans, dir: Vec3, bounded: bool) -> Result<(), TestCaseError> {
    let mut last = f32::NEG_INFINITY;
    for s in spans {
        prop_assert!(!s.t_in.is_nan() && !s.t_out.is_nan());
        prop_assert!(s.t_in <= s.t_out, "span reversed: {s:?}");
        prop_assert!(s.t_in >= last, "spans overlap or are unsorted: {spans:?}");
        last = s.t_out;
        if bounded {
            prop_assert!(
                s.t_in.is_finite() && s.t_out.is_finite(),
                "infinite span of a bounded solid"
            );
        }
        let d = dir.normalize();
        if s.t_in.is_finite() {
            prop_assert!(s.n_in.is_finite() && s.n_in.length() > 0.5);
            prop_assert!(
                s.n_in.normalize().dot(d) < 1e-3,
                "entry normal not outward: {s:?}"
            );
        }
        if s.t_out.is_finite() {
            prop_assert!(s.n_out.is_finite() && s.n_out.length() > 0.5);
            prop_assert!(
                s.n_out.normalize().dot(d) > -1e-3,
                "exit normal not outward: {s:?}"
            );
        }
    }
    Ok(())
}

/// Compares spans with the reference's: same number and ends within `tol`, except where
/// an end is `exempt` (grazing, clip edge).
fn compare_spans(
    ours: &Spans,
    want: &[(f64, f64)],
    tol: impl Fn(f64) -> f64,
    exempt: impl Fn(f64) -> bool,
) -> Result<f64, TestCaseError> {
    let ends = |a: f64, b: f64| {
        if a.is_infinite() || b.is_infinite() {
            if a == b { 0.0 } else { f64::INFINITY }
        } else {
            (a - b).abs() / tol(b)
        }
    };
    let any_exempt = ours
        .iter()
        .flat_map(|s| [s.t_in as f64, s.t_out as f64])
        .chain(want.iter().flat_map(|w| [w.0, w.1]))
        .any(|t| t.is_finite() && exempt(t));
    if ours.len() != want.len() {
        prop_assert!(any_exempt, "spans differ: {ours:?} vs {want:?}");
        return Ok(0.0);
    }
    let mut worst = 0.0f64;
    for (s, w) in ours.iter().zip(want) {
        for (got, w) in [(s.t_in as f64, w.0), (s.t_out as f64, w.1)] {
            let e = ends(got, w);
            if e > 1.0 {
                prop_assert!(any_exempt, "span end {got} vs {w}: {ours:?} vs {want:?}");
            } else {
                worst = worst.max(e);
            }
        }
    }
    Ok(worst)
}

/// How far back (in object sizes) a ray origin is moved along the ray: mostly near,
/// sometimes very far, where forming `F(o)` directly would cancel.
fn far() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => Just(0.0f32),
        1 => Just(1e2),
        1 => Just(1e4),
        1 => Just(1e6),
    ]
}

/// A random quadric case and ray.
fn quadric_ray() -> impl Strategy<Value = (QCase, Ray)> {
    (
        (placement(), 0usize..7, v3(), unit(), unit()),
        (
            (0.2f32..1.0, 0.2f32..1.0, 0.2f32..1.0),
            proptest::option::of((0.3f32..1.5, 0.3f32..1.5, 0.3f32..1.5)),
        ),
        (v3(), v3(), 0.01f32..100.0, any::<bool>(), far()),
    )
        .prop_map(
            |(((s, off), kind, c, a, b), (radii, clip), (o, aim, dirlen, inside, far))| {
                let center = off + c * s;
                let qc = quadric_case(
                    kind,
                    s,
                    center,
                    frame(a, b),
                    Vec3::from(radii),
                    clip.map(Vec3::from),
                );
                let org = if inside {
                    center + o * (0.5 * s)
                } else {
                    center + o * (4.0 * s)
                };
                let target = center + aim * (1.2 * s);
                let dir = (target - org).normalize_or(Vec3::X);
                let org = org - dir * (far * s);
                (qc, Ray::new(org, dir * dirlen))
            },
        )
}

proptest! {
    #![proptest_config(cases(1500))]

    /// Hits, normals, spans, `surface()` and spawned rays of random quadrics against
    /// the homogeneous-form reference.
    #[test]
    fn quadric_matches_f64((qc, ray) in quadric_ray(), w in unit()) {
        let Ok(q) = Quadric::new(qc.coeffs, qc.clip) else {
            // Only a clip box missing an ellipsoid is refused.
            prop_assert!(qc.kind == 0 && qc.clip.is_some());
            return Ok(());
        };
        let grad = |x: DVec3| rq::quadric_gradient(&qc.coeffs, x);
        let dr = DRay::from(&ray);
        let scale = ((dr.org - qc.center).length() + qc.size) / dr.dir.length();
        let mut spans = Spans::new();
        q.spans(&ray, &mut spans);
        let pairs = [ref_roots(&qc, &dr), span_ends(&spans)];
        let exempt = |t: f64| {
            q_exempt(&qc, &dr, t, scale) || short_chord(&pairs, t, dr.dir.length(), qc.size)
        };
        let got = q.intersect(&ray);
        let want = ref_hit(&qc, &dr);
        prop_assert_eq!(got.is_some(), q.occluded(&ray));
        match (got, want) {
            (Some(g), Some(w)) => {
                let cos = q_cos(&qc, &dr, w);
                let err = (g.t as f64 - w).abs();
                let shift = q_ref_shift(&qc, dr.org + dr.dir * w, cos) / dr.dir.length();
                if err > t_tol(w, scale, cos) + shift {
                    prop_assert!(exempt(w) || exempt(g.t as f64),
                        "{}: t {} vs {w} (cos {cos})", KINDS[qc.kind], g.t);
                } else if !near_singular(&qc, dr.org + dr.dir * w) && cos > GRAZE {
                    let p = dr.org + dr.dir * w;
                    let n = rq::quadric_gradient(&qc.coeffs, p);
                    prop_assert!(angle(g.ng.as_dvec3(), n) < q_normal_tol(&qc, p, cos),
                        "{}: normal {} vs {n}", KINDS[qc.kind], g.ng);
                }
            }
            (None, None) => {}
            (g, w) => {
                let t = g.map(|g| g.t as f64).or(w).unwrap();
                prop_assert!(exempt(t),
                    "{}: disagree f32 {g:?} f64 {w:?} (cos {})", KINDS[qc.kind], q_cos(&qc, &dr, t));
            }
        }

        if let Some(hit) = got {
            let p = dr.org + dr.dir * hit.t as f64;
            if !near_singular(&qc, p) && q_cos(&qc, &dr, hit.t as f64) > GRAZE {
                check_surface(&q, &ray, &hit, |x| q_distance(&qc, x), grad, qc.size)?;
                check_spawn(&q, &ray, &hit, w, |x| rq::quadric_value(&qc.coeffs, x), qc.size)?;
            }
        }

        check_span_shape(&spans, ray.dir, q.is_bounded())?;
        let want = ref_spans(&qc, &dr);
        compare_spans(&spans, &want, |t| t_tol(t, scale, q_cos(&qc, &dr, t)),
            exempt)?;
        // Hits built from span ends (as CSG does: u = v = 0, the span's normal) give good
        // surface points, on the quadric or on a face of the clip box.
        for s in &spans {
            for (t, n) in [(s.t_in, s.n_in), (s.t_out, s.n_out)] {
                if !t.is_finite() || exempt(t as f64) {
                    continue;
                }
                let p = dr.org + dr.dir * t as f64;
                let (dq, db) = (q_distance(&qc, p), edge_distance(qc.clip, p));
                let t_slack = 4.0 * ulp(t as f64) * dr.dir.length();
                prop_assert!(dq.min(db) <= 1e-5 * (qc.size + p.abs().max_element()) + t_slack,
                    "span end {t} on neither the quadric ({dq}) nor the box ({db})");
                // Box ends carry the face's normal, exactly ±x, ±y or ±z (a quadric
                // normal of a randomly rotated quadric essentially never is).
                let on_box = qc.clip.is_some()
                    && n.abs().max_element() == 1.0
                    && n.length_squared() == 1.0;
                let true_n = if on_box { n.as_dvec3() } else { rq::quadric_gradient(&qc.coeffs, p) };
                if true_n.normalize().dot(dr.dir.normalize()).abs() < GRAZE {
                    continue;
                }
                let hit = ShapeHit { t, u: 0.0, v: 0.0, ng: n };
                let dist = |x: DVec3| q_distance(&qc, x).min(edge_distance(qc.clip, x));
                let normal_at = |x: DVec3| if on_box { true_n } else { grad(x) };
                check_surface(&q, &ray, &hit, dist, normal_at, qc.size)?;
            }
        }
        // contains() agrees with the spans away from the surface.
        let ts = (-4i32..=4).map(|k| {
            if spans.is_empty() {
                k as f64 * 0.37 * scale
            } else {
                let s = spans[(k.unsigned_abs() as usize) % spans.len()];
                let (a, b) = ((s.t_in as f64).max(-1e3 * scale), (s.t_out as f64).min(1e3 * scale));
                a + (b - a) * (k as f64 + 4.5) / 9.0
            }
        });
        let dist = |x: DVec3| q_distance(&qc, x).min(edge_distance(qc.clip, x));
        check_contains(&q, &dr, &spans, ts, dist, qc.size)?;
    }

    /// A quadric sphere gives the same hits as `Sphere` (an f32 intersector), to
    /// Sphere's own tolerance.
    #[test]
    fn quadric_sphere_matches_sphere(
        (scale, off) in placement(), c in v3(), r in 0.05f32..1.0, o in v3(), aim in v3(),
        dirlen in 0.01f32..100.0, inside in any::<bool>(),
    ) {
        let center = off + c * scale;
        let radius = r * scale;
        let org = if inside { center + o * (0.5 * radius) } else { off + o * (4.0 * scale) };
        let dir = (center + aim * radius - org).normalize_or(Vec3::X) * dirlen;
        let ray = Ray::new(org, dir);
        let s = Sphere::new(center, radius);
        let q = Quadric::sphere(center, radius).unwrap();
        let dr = DRay::from(&ray);
        let f = dr.org - center.as_dvec3();
        let l = f - dr.dir * (f.dot(dr.dir) / dr.dir.dot(dr.dir));
        let margin = 1.0 - l.length_squared() / (radius as f64).powi(2);
        let scale_d = (f.length() + radius as f64) / dr.dir.length();
        match (q.intersect(&ray), s.intersect(&ray)) {
            (Some(a), Some(b)) => {
                if margin > 1e-3 {
                    // Sphere's tolerance (tests/intersectors.rs): 2e-5 relative plus ulps.
                    let tol = 2e-5 * scale_d + 8.0 * f32::EPSILON as f64 * off.abs().max_element() as f64;
                    prop_assert!((a.t as f64 - b.t as f64).abs() <= tol, "t {} vs {}", a.t, b.t);
                    prop_assert!(angle(a.ng.as_dvec3(), b.ng.as_dvec3()) < 1e-3, "normals {} vs {}", a.ng, b.ng);
                }
            }
            (None, None) => {}
            (a, b) => {
                let near_zero = [a.map(|h| h.t), b.map(|h| h.t)].iter().flatten()
                    .any(|&t| (t as f64) < 1e-4 * scale_d);
                prop_assert!(margin.abs() < 1e-3 || near_zero, "quadric {a:?} vs sphere {b:?}");
            }
        }
    }
}

/// A random torus and ray: origins around it, aimed at a point on (or near) the surface.
fn torus_ray() -> impl Strategy<Value = (Torus, [f64; 2], DVec3, DVec3, Ray)> {
    (
        (placement(), v3(), unit()),
        (0.2f32..1.0, 0.05f32..1.5),
        (
            v3(),
            0.0f32..1.0,
            0.0f32..1.0,
            -0.1f32..0.1,
            0.01f32..100.0,
            far(),
        ),
    )
        .prop_map(
            |(((s, off), c, axis), (rr, ratio), (o, u, v, noise, dirlen, far))| {
                let center = off + c * s;
                let major = rr * s;
                let minor = rr * ratio * s;
                let t = Torus::new(center, axis, major, minor).unwrap();
                let (ex, ey, w) = t.frame();
                let (u, v) = (u * std::f32::consts::TAU, v * std::f32::consts::TAU);
                let ring = ex * u.cos() + ey * u.sin();
                let target = center
                    + ring * (major + minor * (1.0 + noise) * v.cos())
                    + w * (minor * (1.0 + noise) * v.sin());
                let org = center + o * (3.0 * (major + minor));
                let dir = (target - org).normalize_or(Vec3::X);
                let org = org - dir * (far * s);
                let dir = dir * dirlen;
                (
                    t,
                    [major as f64, minor as f64],
                    center.as_dvec3(),
                    // The axis as given, normalised in f64 as the constructor does.
                    axis.as_dvec3().normalize(),
                    Ray::new(org, dir),
                )
            },
        )
}

proptest! {
    #![proptest_config(cases(600))]

    /// Crossings, hits, normals, `surface()`, spawned rays and `contains` of random tori
    /// (self-intersecting spindle tori included) against the sampling reference.
    #[test]
    fn torus_matches_f64((tor, [rr, r], c, axis, ray) in torus_ray(), w in unit()) {
        let dr = DRay::from(&ray);
        let size = rr + r;
        let scale = ((dr.org - c).length() + size) / dr.dir.length();
        let grad = |x: DVec3| rt::torus_gradient(c, axis, rr, x);
        // |cos θ| at the torus point nearest the line's point (see `q_cos`).
        let cos_at = |t: f64| {
            let g = rt::torus_gradient(c, axis, rr, dr.org + dr.dir * t);
            let k = g.normalize_or_zero().dot(dr.dir.normalize()).abs();
            if k.is_finite() { k } else { 0.0 }
        };
        let want = rt::torus_spans(&dr, c, axis, rr, r);
        let mut spans = Spans::new();
        tor.spans(&ray, &mut spans);
        let pairs = [rt::torus_crossings(&dr, c, axis, rr, r), span_ends(&spans)];
        let exempt = |t: f64| {
            cos_at(t) < GRAZE || t.abs() <= NEAR0 * scale || short_chord(&pairs, t, dr.dir.length(), size)
        };
        check_span_shape(&spans, ray.dir, true)?;
        compare_spans(&spans, &want, |t| t_tol(t, scale, cos_at(t)), exempt)?;

        let got = tor.intersect(&ray);
        let want = rt::torus(&dr, c, axis, rr, r, 0.0);
        prop_assert_eq!(got.is_some(), tor.occluded(&ray));
        match (got, want) {
            (Some(g), Some(wt)) => {
                let cos = cos_at(wt);
                if (g.t as f64 - wt).abs() > t_tol(wt, scale, cos) {
                    prop_assert!(exempt(wt) || exempt(g.t as f64), "t {} vs {wt} (cos {cos})", g.t);
                } else if cos > GRAZE {
                    let n = rt::torus_gradient(c, axis, rr, dr.org + dr.dir * wt);
                    prop_assert!(angle(g.ng.as_dvec3(), n) < NORMAL_ANGLE, "normal {} vs {n}", g.ng);
                }
                prop_assert!((0.0..1.0).contains(&g.u) && (0.0..1.0).contains(&g.v));
            }
            (None, None) => {}
            (g, w) => {
                let t = g.map(|g| g.t as f64).or(w).unwrap();
                prop_assert!(exempt(t), "disagree: f32 {g:?} f64 {w:?} (cos {})", cos_at(t));
            }
        }
        let dist = |x: DVec3| {
            let v = x - c;
            let z = v.dot(axis);
            let rho = (v - axis * z).length();
            ((rho - rr).hypot(z) - r).abs()
        };
        if let Some(hit) = got {
            if cos_at(hit.t as f64) > GRAZE {
                check_surface(&tor, &ray, &hit, dist, grad, size)?;
                // Not from a spindle torus's cusp (a singular point in a concave dimple).
                let v = tor.surface(&ray, &hit).p.as_dvec3() - c;
                let near_cusp = r > rr && (v - axis * v.dot(axis)).length() < 1e-3 * size;
                if !near_cusp {
                    check_spawn(&tor, &ray, &hit, w, |x| rt::torus_value(c, axis, rr, r, x), size)?;
                }
            }
        }
        for s in &spans {
            for (t, n) in [(s.t_in, s.n_in), (s.t_out, s.n_out)] {
                if cos_at(t as f64) > GRAZE {
                    let hit = ShapeHit { t, u: 0.0, v: 0.0, ng: n };
                    check_surface(&tor, &ray, &hit, dist, grad, size)?;
                }
            }
        }
        // contains() agrees with the spans away from the surface: points across the
        // torus, around the line's point nearest the centre.
        let mid = (c - dr.org).dot(dr.dir) / dr.dir.length_squared();
        let ts = (0..=16).map(|k| mid + (-1.0 + k as f64 / 8.0) * scale);
        check_contains(&tor, &dr, &spans, ts, dist, size)?;
    }

    /// Planes at any offset and orientation: the hit against `(d − n·o)/(n·dir)` in
    /// f64, the surface point within its error, spawned rays on the right side.
    #[test]
    fn plane_matches_f64(
        (scale, off) in placement(), n in unit(), o in v3(), aim in v3(), w in unit(),
        dirlen in 0.01f32..100.0,
    ) {
        let point = off + aim * scale;
        let plane = Plane::from_point_normal(point, n).unwrap();
        let org = off + o * (4.0 * scale);
        let ray = Ray::new(org, (point - org).normalize_or(Vec3::X) * dirlen);
        let dr = DRay::from(&ray);
        let nd = n.as_dvec3().normalize();
        let side = |x: DVec3| nd.dot(x - point.as_dvec3());
        let want = -side(dr.org) / nd.dot(dr.dir);
        let cos = nd.dot(dr.dir.normalize());
        let scale_d = ((dr.org - point.as_dvec3()).length() + scale as f64) / dr.dir.length();
        match plane.intersect(&ray) {
            Some(hit) => {
                prop_assert!((hit.t as f64 - want).abs() <= t_tol(want, scale_d, cos), "t {} vs {want}", hit.t);
                check_surface(&plane, &ray, &hit, |x| side(x).abs(), |_| nd, scale as f64)?;
                check_spawn(&plane, &ray, &hit, w, side, scale as f64)?;
            }
            None => prop_assert!(want.is_nan() || want <= NEAR0 * scale_d || cos.abs() < 1e-7, "missed at {want}"),
        }
        let mut spans = Spans::new();
        plane.spans(&ray, &mut spans);
        prop_assert_eq!(spans.len(), 1);
        check_span_shape(&spans, ray.dir, false)?;
        prop_assert_eq!(plane.contains(org), side(dr.org) <= 0.0);
    }
}

/// Rays that are not rays: NaN and infinite origins or directions, zero directions.
#[test]
fn non_finite_and_degenerate_rays_never_hit() {
    let shapes: Vec<Box<dyn Primitive>> = vec![
        Box::new(Quadric::sphere(Vec3::ZERO, 1.0).unwrap()),
        Box::new(Quadric::cylinder(Vec3::ZERO, Vec3::Z, 1.0).unwrap()),
        Box::new(
            Quadric::cone(Vec3::ZERO, Vec3::Y, 0.5)
                .unwrap()
                .with_clip(Aabb {
                    min: Vec3::splat(-2.0),
                    max: Vec3::splat(2.0),
                })
                .unwrap(),
        ),
        Box::new(Plane::new(Vec3::Z, 0.5).unwrap()),
        Box::new(Torus::new(Vec3::ZERO, Vec3::Z, 1.0, 0.25).unwrap()),
    ];
    let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
    let mut rays = vec![Ray::new(Vec3::new(0.1, 0.2, 0.3), Vec3::ZERO)];
    for &b in &bad {
        rays.push(Ray::new(Vec3::new(b, 0.0, 0.0), Vec3::X));
        rays.push(Ray::new(Vec3::ZERO, Vec3::new(0.0, b, 1.0)));
    }
    // Empty or NaN intervals on a ray that would hit everything.
    for (tmin, tmax) in [
        (f32::NAN, f32::INFINITY),
        (f32::INFINITY, f32::INFINITY),
        (0.0, f32::NAN),
        (0.0, f32::NEG_INFINITY),
        (3.0, 2.0),
    ] {
        let mut r = Ray::new(Vec3::new(-5.0, 0.6, 0.1), Vec3::X);
        (r.tmin, r.tmax) = (tmin, tmax);
        rays.push(r);
    }
    for s in &shapes {
        for r in &rays {
            let h = s.intersect(r);
            assert!(h.is_none(), "{r:?} hit {h:?}");
            assert!(!s.occluded(r));
            let mut spans = Spans::new();
            s.spans(r, &mut spans);
            assert!(spans.iter().all(|s| !s.t_in.is_nan() && !s.t_out.is_nan()));
            if !(r.org.is_finite() && r.dir.is_finite()) || r.dir == Vec3::ZERO {
                assert!(spans.is_empty(), "{r:?}: {spans:?}");
            }
        }
        // Huge and tiny directions still work.
        for len in [1e-30f32, 1e30] {
            let r = Ray::new(Vec3::new(0.6, 0.0, -10.0), Vec3::Z * len);
            if let Some(h) = s.intersect(&r) {
                assert!(h.t.is_finite() && h.ng.is_finite() && h.ng.length() > 0.5);
                let sp = s.surface(&r, &h);
                assert!(sp.p.is_finite() && sp.err.is_finite());
            }
        }
    }
}

/// A quadric cylinder seen along its axis, across it, and from outside parallel to it.
#[test]
fn cylinder_axis_and_parallel_rays() {
    let cyl = Quadric::cylinder(Vec3::new(1.0, 2.0, 0.0), Vec3::Z, 0.5).unwrap();
    assert!(!cyl.is_bounded());
    assert_eq!(cyl.bounds(), Aabb::INFINITE);
    let mut spans = Spans::new();
    // Along the axis: inside everywhere, never crosses.
    let axis = Ray::new(Vec3::new(1.0, 2.0, -5.0), Vec3::Z);
    assert!(cyl.intersect(&axis).is_none());
    cyl.spans(&axis, &mut spans);
    assert_eq!(spans.len(), 1);
    assert_eq!(
        (spans[0].t_in, spans[0].t_out),
        (f32::NEG_INFINITY, f32::INFINITY)
    );
    assert_eq!(spans[0].n_in, Vec3::ZERO);
    // Parallel outside: nothing.
    spans.clear();
    let outside = Ray::new(Vec3::new(2.0, 2.0, -5.0), -Vec3::Z);
    assert!(cyl.intersect(&outside).is_none());
    cyl.spans(&outside, &mut spans);
    assert!(spans.is_empty());
    // Across: enters at x = 0.5, leaves at x = 1.5, normals ∓x.
    let across = Ray::new(Vec3::new(-3.0, 2.0, 7.0), Vec3::X * 2.0);
    let h = cyl.intersect(&across).unwrap();
    assert!((h.t - 1.75).abs() < 1e-6 && h.ng.dot(Vec3::X) < -0.999);
    cyl.spans(&across, &mut spans);
    assert_eq!(spans.len(), 1);
    assert!((spans[0].t_in - 1.75).abs() < 1e-6 && (spans[0].t_out - 2.25).abs() < 1e-6);
    assert!(spans[0].n_out.dot(Vec3::X) > 0.999);
    // From inside: the exit, normal along the ray.
    let from_in = Ray::new(Vec3::new(1.0, 2.0, 3.0), Vec3::Y);
    let h = cyl.intersect(&from_in).unwrap();
    assert!((h.t - 0.5).abs() < 1e-6 && h.ng.dot(Vec3::Y) > 0.999);
    // Clipped to a box: the solid gets caps, the surface does not.
    let capped = cyl
        .with_clip(Aabb {
            min: Vec3::new(-10.0, -10.0, 0.0),
            max: Vec3::new(10.0, 10.0, 4.0),
        })
        .unwrap();
    assert!(capped.is_bounded());
    let b = capped.bounds();
    assert_eq!((b.min.z, b.max.z), (0.0, 4.0));
    assert!(capped.intersect(&axis).is_none(), "no caps on the surface");
    spans.clear();
    capped.spans(&axis, &mut spans);
    assert_eq!(spans.len(), 1);
    assert_eq!((spans[0].t_in, spans[0].t_out), (5.0, 9.0));
    assert_eq!((spans[0].n_in, spans[0].n_out), (-Vec3::Z, Vec3::Z));
    assert!(capped.contains(Vec3::new(1.0, 2.0, 2.0)));
    assert!(!capped.contains(Vec3::new(1.0, 2.0, 5.0)));
}

/// A negative-definite quadric is the outside of an ellipsoid: unbounded, with two
/// half-line spans through the middle, and normals pointing out of the solid, i.e.
/// towards the ellipsoid's centre.
#[test]
fn complement_of_a_sphere() {
    let q = Quadric::new([-1.0, -1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 4.0], None).unwrap();
    assert!(!q.is_bounded() && q.bounds() == Aabb::INFINITE);
    let ray = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
    let h = q.intersect(&ray).unwrap();
    assert!(
        (h.t - 3.0).abs() < 1e-6 && h.ng.dot(Vec3::X) > 0.999,
        "{h:?}"
    );
    let mut s = Spans::new();
    q.spans(&ray, &mut s);
    assert_eq!(s.len(), 2, "{s:?}");
    assert_eq!((s[0].t_in, s[1].t_out), (f32::NEG_INFINITY, f32::INFINITY));
    assert!((s[0].t_out - 3.0).abs() < 1e-6 && (s[1].t_in - 7.0).abs() < 1e-6);
    assert!(s[0].n_out.dot(Vec3::X) > 0.999 && s[1].n_in.dot(Vec3::X) < -0.999);
    assert!(q.contains(Vec3::new(3.0, 0.0, 0.0)) && !q.contains(Vec3::ZERO));
}

/// Tangent rays: exactly tangent gives the tangent point or nothing; a hair inside two
/// close hits; a hair outside none.
#[test]
fn tangent_rays() {
    let q = Quadric::sphere(Vec3::ZERO, 1.0).unwrap();
    let tangent = Ray::new(Vec3::new(-5.0, 1.0, 0.0), Vec3::X);
    if let Some(h) = q.intersect(&tangent) {
        assert!(
            (h.t - 5.0).abs() < 1e-3 && h.ng.dot(Vec3::Y) > 0.999,
            "{h:?}"
        );
    }
    let y_in = 1.0 - 1e-6;
    let inside = Ray::new(Vec3::new(-5.0, y_in, 0.0), Vec3::X);
    let h = q.intersect(&inside).expect("a hair inside hits");
    let half_chord = (1.0 - (y_in as f64).powi(2)).sqrt();
    assert!(((h.t as f64) - (5.0 - half_chord)).abs() < 1e-6, "{h:?}");
    let mut spans = Spans::new();
    q.spans(&inside, &mut spans);
    assert_eq!(spans.len(), 1);
    assert!(((spans[0].t_out - spans[0].t_in) as f64 - 2.0 * half_chord).abs() < 1e-6);
    let outside = Ray::new(Vec3::new(-5.0, 1.0 + 1e-6, 0.0), Vec3::X);
    assert!(q.intersect(&outside).is_none());
    // The torus's outer equator, grazed from outside and a hair inside.
    let t = Torus::new(Vec3::ZERO, Vec3::Z, 2.0, 0.5).unwrap();
    assert!(
        t.intersect(&Ray::new(Vec3::new(-5.0, 2.5 + 1e-5, 0.0), Vec3::X))
            .is_none()
    );
    spans.clear();
    t.spans(
        &Ray::new(Vec3::new(-5.0, 2.5 - 1e-5, 0.0), Vec3::X),
        &mut spans,
    );
    assert_eq!(spans.len(), 1, "{spans:?}");
    assert!((spans[0].t_in - 5.0).abs() < 1e-2 && spans[0].t_in < spans[0].t_out);
    // Grazing the inner equator (ρ = 1.5) from the hole's side: the line dips out of the
    // tube into the hole for a chord of 2√(1.5² − y²); from the tube's side it stays in.
    let y = 1.5f32 - 1e-5;
    spans.clear();
    t.spans(&Ray::new(Vec3::new(-5.0, y, 0.0), Vec3::X), &mut spans);
    assert_eq!(spans.len(), 2, "{spans:?}");
    let gap = (spans[1].t_in - spans[0].t_out) as f64;
    let chord = 2.0 * (1.5f64 * 1.5 - (y as f64).powi(2)).sqrt();
    assert!((gap - chord).abs() < 1e-3 * chord, "{gap} vs {chord}");
    spans.clear();
    t.spans(
        &Ray::new(Vec3::new(-5.0, 1.5 + 1e-5, 0.0), Vec3::X),
        &mut spans,
    );
    assert_eq!(spans.len(), 1, "{spans:?}");
}

/// A ray parallel to a paraboloid's axis: the quadratic's leading coefficient is 0, one
/// hit, and the span runs to infinity.
#[test]
fn ray_parallel_to_paraboloid_axis_hits_once() {
    let p = Quadric::paraboloid(Vec3::new(0.0, 0.0, 1.0), Vec3::Z, 0.25).unwrap();
    assert!(!p.is_bounded());
    // x² + y² = z − 1: at (0.5, 0.3) the surface is at z = 1.34.
    let up = Ray::new(Vec3::new(0.5, 0.3, -10.0), Vec3::Z * 2.0);
    let h = p.intersect(&up).unwrap();
    assert!((h.t - 11.34 / 2.0).abs() < 1e-6, "{h:?}");
    assert!(h.ng.dot(Vec3::Z) < 0.0);
    let mut spans = Spans::new();
    p.spans(&up, &mut spans);
    assert_eq!(spans.len(), 1);
    assert!((spans[0].t_in - 5.67).abs() < 1e-6 && spans[0].t_out == f32::INFINITY);
    // From inside going down: the exit.
    let down = Ray::new(Vec3::new(0.5, 0.3, 5.0), -Vec3::Z);
    let h = p.intersect(&down).unwrap();
    assert!((h.t - 3.66).abs() < 1e-6 && h.ng.dot(Vec3::Z) < 0.0);
    // The same with a far-away origin and a ray almost (not exactly) parallel.
    let far = Ray::new(
        Vec3::new(0.5, 0.3, -1e6),
        Vec3::new(1e-9, 0.0, 1.0).normalize(),
    );
    let h = p.intersect(&far).unwrap();
    let want = rq::quadric(&DRay::from(&far), &p.coefficients(), None, 0.0).unwrap();
    assert!(
        ((h.t as f64) - want).abs() <= 2.0 * ulp(want),
        "{} vs {want}",
        h.t
    );
}

/// Rays from inside a closed quadric hit the exit with the normal along the ray.
#[test]
fn rays_from_inside_hit_the_exit() {
    let e = Quadric::ellipsoid(Vec3::new(1.0, -2.0, 3.0), Vec3::new(1.0, 2.0, 3.0)).unwrap();
    for dir in [Vec3::X, -Vec3::Y * 4.0, Vec3::Z * 0.5] {
        let r = Ray::new(Vec3::new(1.0, -2.0, 3.0), dir);
        let h = e.intersect(&r).unwrap();
        let p = r.at(h.t) - Vec3::new(1.0, -2.0, 3.0);
        let f = (p / Vec3::new(1.0, 2.0, 3.0)).length_squared();
        assert!((f - 1.0).abs() < 1e-6, "{p}");
        assert!(h.ng.dot(dir) > 0.999 * dir.length());
    }
}

/// The bounds of an ellipsoid are its analytic box, within a couple of ulps, for axis
/// aligned and rotated ones.
#[test]
fn ellipsoid_bounds_are_tight() {
    let c = Vec3::new(3.0, -1e4, 0.25);
    let r = Vec3::new(0.5, 7.0, 1e-3);
    let e = Quadric::ellipsoid(c, r).unwrap();
    assert!(e.is_bounded());
    let b = e.bounds();
    let (lo, hi) = (c.as_dvec3() - r.as_dvec3(), c.as_dvec3() + r.as_dvec3());
    for k in 0..3 {
        let ulp = |x: f64| (x.abs() as f32 * f32::EPSILON) as f64;
        assert!((b.min[k] as f64) <= lo[k] && lo[k] - (b.min[k] as f64) <= 2.0 * ulp(lo[k]));
        assert!((b.max[k] as f64) >= hi[k] && (b.max[k] as f64) - hi[k] <= 2.0 * ulp(hi[k]));
    }
    // Rotated: the half-extent along axis k is √(Σ_i (u_i[k]·r_i)²). Near the origin the
    // test's f64 coefficients are exact to ~1e-16, so the box must contain the analytic
    // one and be within a few ulps of it; far away the coefficients themselves carry
    // cancellation (~1e-16 of |c|²), which bounds the comparison.
    let rot = frame(Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.5, 0.2));
    let radii = DVec3::new(2.0, 0.5, 1.0);
    for (c, slack_rel) in [(Vec3::new(0.75, -0.5, 0.25), 0.0), (c, 1e-8)] {
        let qc = quadric_case(0, 1.0, c, rot, radii.as_vec3(), None);
        let q = Quadric::new(qc.coeffs, None).unwrap();
        let b = q.bounds();
        for k in 0..3 {
            let half = (0..3)
                .map(|i| (rot[i][k] * radii[i]).powi(2))
                .sum::<f64>()
                .sqrt();
            let (lo, hi) = (c[k] as f64 - half, c[k] as f64 + half);
            let fuzz = slack_rel * c.abs().max_element() as f64;
            let (bl, bh) = (b.min[k] as f64, b.max[k] as f64);
            assert!(
                bl <= lo + fuzz && lo - bl <= 2.0 * ulp(lo) + fuzz,
                "{k}: {b:?} vs {lo}"
            );
            assert!(
                bh >= hi - fuzz && bh - hi <= 2.0 * ulp(hi) + fuzz,
                "{k}: {b:?} vs {hi}"
            );
        }
    }
    // Unbounded kinds report infinite bounds unless clipped.
    for (kind, name) in KINDS.iter().enumerate().skip(1) {
        let qc = quadric_case(kind, 1.0, Vec3::ZERO, rot, Vec3::ONE, None);
        let q = Quadric::new(qc.coeffs, None).unwrap();
        assert!(!q.is_bounded() && !q.bounds().is_finite(), "{name}");
    }
}

/// The torus's analytic cases: through the hole along the axis, and across the middle
/// in the equatorial plane.
#[test]
fn torus_axis_and_equator() {
    let c = Vec3::new(10.0, -20.0, 30.0);
    let t = Torus::new(c, Vec3::new(0.0, 0.0, 3.0), 2.0, 0.5).unwrap();
    let b = t.bounds();
    assert!(b.min.abs_diff_eq(c - Vec3::new(2.5, 2.5, 0.5), 1e-5));
    assert!(b.max.abs_diff_eq(c + Vec3::new(2.5, 2.5, 0.5), 1e-5));
    let mut spans = Spans::new();
    let axis = Ray::new(c + Vec3::Z * 5.0, -Vec3::Z);
    assert!(t.intersect(&axis).is_none());
    t.spans(&axis, &mut spans);
    assert!(spans.is_empty());
    // From the centre along x: the line meets the tube at x = ±1.5 and ±2.5.
    let across = Ray::new(c, Vec3::X);
    t.spans(&across, &mut spans);
    assert_eq!(spans.len(), 2, "{spans:?}");
    let want = [(-2.5, -1.5), (1.5, 2.5)];
    for (s, w) in spans.iter().zip(want) {
        assert!(
            (s.t_in - w.0).abs() < 1e-5 && (s.t_out - w.1).abs() < 1e-5,
            "{spans:?}"
        );
        assert!(s.n_in.dot(Vec3::X) < -0.999 && s.n_out.dot(Vec3::X) > 0.999);
    }
    // From outside: four crossings, the first at the outer side.
    let from_out = Ray::new(c - Vec3::X * 5.0, Vec3::X * 0.5);
    let h = t.intersect(&from_out).unwrap();
    assert!((h.t - 5.0).abs() < 1e-5 && h.ng.dot(Vec3::X) < -0.999);
    // Hit at angle u around the axis and v around the tube.
    let (ex, ey, w) = t.frame();
    for (u, v) in [(0.1f32, 0.2f32), (0.6, 0.9), (0.3, 0.55)] {
        let (a, bb) = (u * std::f32::consts::TAU, v * std::f32::consts::TAU);
        let ring = ex * a.cos() + ey * a.sin();
        let normal = ring * bb.cos() + w * bb.sin();
        let p = c + ring * 2.0 + normal * 0.5;
        let h = t.intersect(&Ray::new(p + normal * 0.1, -normal)).unwrap();
        assert!(
            (h.u - u).abs() < 1e-5 && (h.v - v).abs() < 1e-5,
            "{h:?} vs {u} {v}"
        );
        assert!(h.ng.dot(normal) > 0.9999);
    }
}

/// A spindle torus (minor > major): the inner lemon is inside the solid, not a surface.
#[test]
fn spindle_torus_has_no_inner_surface() {
    let t = Torus::new(Vec3::ZERO, Vec3::Z, 1.0, 1.5).unwrap();
    // Along the axis: the solid runs from z = −√(r² − R²) to +√(r² − R²)... through the
    // lemon, which is inside: one span.
    let mut spans = Spans::new();
    t.spans(&Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z), &mut spans);
    let z = (1.5f32 * 1.5 - 1.0).sqrt();
    assert_eq!(spans.len(), 1, "{spans:?}");
    assert!((spans[0].t_in - (5.0 - z)).abs() < 1e-4 && (spans[0].t_out - (5.0 + z)).abs() < 1e-4);
    // Across the middle: one span from −2.5 to 2.5.
    spans.clear();
    t.spans(&Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X), &mut spans);
    assert_eq!(spans.len(), 1, "{spans:?}");
    assert!((spans[0].t_in - 2.5).abs() < 1e-5 && (spans[0].t_out - 7.5).abs() < 1e-5);
    assert!(t.contains(Vec3::ZERO));
}

/// `contains` agrees with the spans on random points of random lines.
#[test]
fn torus_contains_agrees_with_spans() {
    let t = Torus::new(
        Vec3::new(0.3, -0.2, 0.1),
        Vec3::new(1.0, 2.0, -0.5),
        1.2,
        0.4,
    )
    .unwrap();
    let mut rng = emray::math::Rng::new(0x2545_F491_4F6C_DD1D);
    let mut rnd = move || rng.range(-1.0, 1.0);
    let mut checked = 0;
    for _ in 0..2000 {
        let o = Vec3::new(rnd(), rnd(), rnd()) * 3.0;
        let d = Vec3::new(rnd(), rnd(), rnd());
        if d.length() < 0.1 {
            continue;
        }
        let ray = Ray::new(o, d);
        let mut spans = Spans::new();
        t.spans(&ray, &mut spans);
        let tt = rnd() * 4.0;
        let near = spans
            .iter()
            .any(|s| (tt - s.t_in).abs() < 1e-4 || (tt - s.t_out).abs() < 1e-4);
        if near {
            continue;
        }
        let inside = spans.iter().any(|s| s.t_in <= tt && tt <= s.t_out);
        assert_eq!(t.contains(ray.at(tt)), inside, "{ray:?} at {tt}: {spans:?}");
        checked += 1;
    }
    assert!(checked > 1500);
}

/// A small quadric far from the origin, given about its own centre, keeps its precision
/// (its world coefficients alone could not).
#[test]
fn small_quadric_far_away() {
    let c = Vec3::new(1e5, -2e5, 3e5);
    let s = Quadric::sphere(c, 1e-2).unwrap();
    let ray = Ray::new(c - Vec3::new(0.0, 0.0, 1.0), Vec3::Z);
    let h = s.intersect(&ray).unwrap();
    let sp = s.surface(&ray, &h);
    assert!((sp.p.z - (c.z - 1e-2)).abs() <= sp.err.z, "{sp:?}");
    assert!(sp.ng.dot(-Vec3::Z) > 0.9999);
    // From a million units away.
    let far = Ray::new(c - Vec3::new(0.0, 0.0, 1e6), Vec3::Z);
    let h = s.intersect(&far).unwrap();
    assert!((h.t - (1e6 - 1e-2)).abs() <= 0.07, "{}", h.t);
}

/// Each preset is the surface its documentation describes: on a rotated axis, points of
/// the analytic surface have `F ≈ 0`, and points slightly inside (outside) are negative
/// (positive).
#[test]
fn presets_match_their_definitions() {
    let point = Vec3::new(3.0, -2.0, 1.5);
    let axis = Vec3::new(1.0, -2.0, 0.5);
    let w = axis.as_dvec3().normalize();
    let (e1, _) = w.any_orthonormal_pair();
    let p0 = point.as_dvec3();
    // (preset, radius of the surface at height h along the axis, heights to test); the
    // sizes are exact in f32.
    type Radius = Box<dyn Fn(f64) -> f64>;
    let cases: Vec<(&str, Quadric, Radius, Vec<f64>)> = vec![
        (
            "cylinder",
            Quadric::cylinder(point, axis, 0.75).unwrap(),
            Box::new(|_| 0.75),
            vec![-5.0, 0.0, 3.0],
        ),
        (
            "cone",
            Quadric::cone(point, axis, 0.375).unwrap(),
            Box::new(|h: f64| 0.375 * h.abs()),
            vec![-2.0, 0.5, 3.0],
        ),
        (
            "paraboloid",
            Quadric::paraboloid(point, axis, 0.25).unwrap(),
            Box::new(|h: f64| (h).sqrt()),
            vec![0.25, 1.0, 4.0],
        ),
        (
            "hyperboloid (1 sheet)",
            Quadric::hyperboloid_one_sheet(point, axis, 0.5, 2.0).unwrap(),
            Box::new(|h: f64| (0.25 + 4.0 * h * h).sqrt()),
            vec![-1.0, 0.0, 0.3],
        ),
        (
            "hyperboloid (2 sheets)",
            Quadric::hyperboloid_two_sheets(point, axis, 0.5, 2.0).unwrap(),
            Box::new(|h: f64| (4.0 * (h * h - 0.25)).sqrt()),
            vec![-2.0, 0.75, 1.5],
        ),
        (
            "sphere",
            Quadric::sphere(point, 1.5).unwrap(),
            Box::new(|h: f64| (2.25 - h * h).sqrt()),
            vec![-1.0, 0.0, 1.2],
        ),
    ];
    for (name, q, radius, heights) in cases {
        assert!(!q.is_bounded() || name == "sphere", "{name}");
        for h in heights {
            let r = radius(h);
            let at = |k: f64| p0 + w * h + e1 * (r * k);
            let (on, inner, outer) = (q.value(at(1.0)), q.value(at(0.97)), q.value(at(1.03)));
            assert!(
                inner < 0.0 && outer > 0.0,
                "{name} at h = {h}: {inner} {outer}"
            );
            assert!(
                on.abs() < 1e-9 * (inner.abs() + outer.abs()),
                "{name} at h = {h}: F = {on}"
            );
        }
    }
    // The axis-aligned ellipsoid.
    let e = Quadric::ellipsoid(point, Vec3::new(1.0, 2.0, 0.5)).unwrap();
    for (k, r) in [1.0, 2.0, 0.5].into_iter().enumerate() {
        let mut d = DVec3::ZERO;
        d[k] = r;
        assert!(e.value(p0 + d).abs() < 1e-12 && e.value(p0 + d * 0.99) < 0.0);
    }
}

/// The coefficients' scale does not matter: the same quadric multiplied by 1e±200
/// gives the same hits (the constructor rescales by a power of two).
#[test]
fn coefficient_scale_does_not_matter() {
    let base = [1.0, 2.0, 0.5, 0.1, -0.2, 0.3, -0.4, 0.2, 0.1, -3.0];
    let q = Quadric::new(base, None).unwrap();
    for k in [1e-200, 1e-30, 3.0, 1e30, 1e200] {
        let scaled = Quadric::new(base.map(|c| c * k), None).unwrap();
        for dir in [
            Vec3::X,
            Vec3::new(0.3, -1.0, 0.2),
            Vec3::new(-1.0, -1.0, 4.0),
        ] {
            let ray = Ray::new(Vec3::new(-4.0, 3.0, -2.0) * 0.5, dir);
            let (a, b) = (q.intersect(&ray), scaled.intersect(&ray));
            assert_eq!(a.map(|h| h.t), b.map(|h| h.t), "scale {k}");
            let mut sa = Spans::new();
            let mut sb = Spans::new();
            q.spans(&ray, &mut sa);
            scaled.spans(&ray, &mut sb);
            assert_eq!(sa, sb, "scale {k}");
        }
    }
}

/// Along the equatorial ray through the centre the torus is crossed four times, one
/// after another as `tmin` advances.
#[test]
fn torus_four_hits_in_order() {
    let t = Torus::new(Vec3::new(1.0, 2.0, 3.0), Vec3::Y, 3.0, 1.0).unwrap();
    let mut ray = Ray::new(Vec3::new(-9.0, 2.0, 3.0), Vec3::X * 2.0);
    let mut got = Vec::new();
    while let Some(h) = t.intersect(&ray) {
        got.push(h.t);
        ray.tmin = h.t;
    }
    let want = [3.0f32, 4.0, 6.0, 7.0];
    assert_eq!(got.len(), 4, "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() < 1e-6, "{got:?}");
    }
}

/// A plane far from the origin: the hit and the surface point keep f32 precision of
/// the coordinates, and the half-space spans flip with the direction.
#[test]
fn plane_far_away() {
    let n = Vec3::new(1.0, 2.0, -2.0);
    let point = Vec3::new(1e6, -2e6, 5e5);
    let plane = Plane::from_point_normal(point, n).unwrap();
    assert_eq!(plane.bounds(), Aabb::INFINITE);
    assert!((plane.normal().length() - 1.0).abs() < 1e-7);
    let ray = Ray::new(point + Vec3::new(3.0, 1.0, 2.0), -n);
    let h = plane.intersect(&ray).unwrap();
    let sp = plane.surface(&ray, &h);
    let nd = n.as_dvec3().normalize();
    let off = nd.dot(sp.p.as_dvec3() - point.as_dvec3()).abs();
    assert!(
        off <= nd.abs().dot(sp.err.as_dvec3()),
        "{off} vs {:?}",
        sp.err
    );
    assert!(sp.err.max_element() <= 2.0 * 2e6 * f32::EPSILON);
    let mut s = Spans::new();
    plane.spans(&ray, &mut s);
    assert_eq!((s[0].t_in, s[0].t_out), (h.t, f32::INFINITY));
    assert!(plane.contains(point - n) && !plane.contains(point + n));
}

/// The worst errors over many random cases, printed (run with `--nocapture`) and held
/// to the stated tolerances: `t` in f32 ulps beyond the reference, normal angle,
/// `surface()` distance relative to what `err` allows, and `err` in ulps.
#[test]
fn worst_errors() {
    let config = ProptestConfig {
        failure_persistence: None,
        ..cases(500)
    };
    #[derive(Default, Debug)]
    struct Worst {
        cases: usize,
        t_ulps: f64,
        t_rel: f64,
        angle: f64,
        dist: f64,
        err_ulps: f64,
    }
    /// One hit and what the reference says about it.
    struct Sample<'a> {
        shape: &'a dyn Intersect,
        ray: Ray,
        hit: ShapeHit,
        /// Reference t, scale of the configuration, reference normal.
        want: f64,
        scale: f64,
        n: DVec3,
        /// Normal tolerance and the reference's own t uncertainty.
        normal_tol: f64,
        ref_t_err: f64,
        size: f64,
    }
    impl Worst {
        fn add(
            &mut self,
            s: Sample,
            distance: impl Fn(DVec3) -> f64,
            normal_at: impl Fn(DVec3) -> DVec3,
        ) -> Result<(), TestCaseError> {
            let cos = s.n.normalize().dot(s.ray.dir.as_dvec3().normalize()).abs();
            let dt = (s.hit.t as f64 - s.want).abs();
            self.cases += 1;
            self.t_ulps = self.t_ulps.max(dt / ulp(s.want).max(f64::MIN_POSITIVE));
            // Beyond one ulp and the reference's own uncertainty.
            let beyond = (dt - ulp(s.want) - s.ref_t_err).max(0.0);
            self.t_rel = self.t_rel.max(beyond * cos / s.scale);
            // Worst normal where the reference itself is well conditioned; all within
            // their tolerance.
            let a = angle(s.hit.ng.as_dvec3(), s.n);
            prop_assert!(
                a <= s.normal_tol,
                "normal off by {a} (tolerance {})",
                s.normal_tol
            );
            if s.normal_tol <= 1.01 * NORMAL_ANGLE {
                self.angle = self.angle.max(a);
            }
            let (d, ulps) = check_surface(s.shape, &s.ray, &s.hit, distance, normal_at, s.size)?;
            self.dist = self.dist.max(d);
            self.err_ulps = self.err_ulps.max(ulps);
            Ok(())
        }
    }
    let worst_q = std::cell::RefCell::new(Worst::default());
    let mut runner = proptest::test_runner::TestRunner::new(config.clone());
    runner
        .run(&quadric_ray(), |(qc, ray)| {
            let Ok(q) = Quadric::new(qc.coeffs, qc.clip) else {
                return Ok(());
            };
            let dr = DRay::from(&ray);
            let scale = ((dr.org - qc.center).length() + qc.size) / dr.dir.length();
            let want = ref_hit(&qc, &dr);
            if let (Some(g), Some(w)) = (q.intersect(&ray), want) {
                if !q_exempt(&qc, &dr, w, scale) {
                    let n = rq::quadric_gradient(&qc.coeffs, dr.org + dr.dir * w);
                    let dist = |x: DVec3| q_distance(&qc, x);
                    let p = dr.org + dr.dir * w;
                    let cos = q_cos(&qc, &dr, w);
                    let sample = Sample {
                        shape: &q,
                        ray,
                        hit: g,
                        want: w,
                        scale,
                        n,
                        normal_tol: q_normal_tol(&qc, p, cos),
                        ref_t_err: q_ref_shift(&qc, p, cos) / dr.dir.length(),
                        size: qc.size,
                    };
                    let grad = |x: DVec3| rq::quadric_gradient(&qc.coeffs, x);
                    worst_q.borrow_mut().add(sample, dist, grad)?;
                }
            }
            Ok(())
        })
        .unwrap();
    let worst_t = std::cell::RefCell::new(Worst::default());
    let mut runner = proptest::test_runner::TestRunner::new(config);
    runner
        .run(&torus_ray(), |(tor, [rr, r], c, axis, ray)| {
            let dr = DRay::from(&ray);
            let scale = ((dr.org - c).length() + rr + r) / dr.dir.length();
            let want = rt::torus(&dr, c, axis, rr, r, 0.0);
            if let (Some(g), Some(w)) = (tor.intersect(&ray), want) {
                let n = rt::torus_gradient(c, axis, rr, dr.org + dr.dir * w);
                if n.normalize().dot(dr.dir.normalize()).abs() > GRAZE {
                    let dist = |x: DVec3| {
                        let v = x - c;
                        let z = v.dot(axis);
                        (((v - axis * z).length() - rr).hypot(z) - r).abs()
                    };
                    let sample = Sample {
                        shape: &tor,
                        ray,
                        hit: g,
                        want: w,
                        scale,
                        n,
                        normal_tol: NORMAL_ANGLE,
                        ref_t_err: 0.0,
                        size: rr + r,
                    };
                    let grad = |x: DVec3| rt::torus_gradient(c, axis, rr, x);
                    worst_t.borrow_mut().add(sample, dist, grad)?;
                }
            }
            Ok(())
        })
        .unwrap();
    for (name, w) in [
        ("quadric", worst_q.into_inner()),
        ("torus", worst_t.into_inner()),
    ] {
        println!(
            "{name} ({} hits): |Δt| ≤ {:.2} ulps, beyond 1 ulp ≤ {:.1e} × scale / |cos|; \
             normal ≤ {:.1e} rad; surface() distance ≤ {:.3} of err along n; err ≤ {:.2} ulps",
            w.cases, w.t_ulps, w.t_rel, w.angle, w.dist, w.err_ulps
        );
        assert!(w.cases > 100);
        assert!(w.t_rel <= T_REL && w.angle <= NORMAL_ANGLE && w.dist <= 1.0);
        assert!(w.err_ulps <= ERR_ULPS as f64);
    }
}
