use super::param::cylindrical;
use super::tessellate::{Tessellation, flip, revolution};
use super::{Intersect, Param, Primitive, Shape, ShapeHit, SurfacePoint, quadratic_roots_f64};
use crate::math::{Aabb, Ray, Vec3, gamma, similarity_scale};
use glam::DAffine3;

/// NFF's open cone or cylinder: the lateral surface between a base disk and an apex
/// disk, with no end caps. With `inside_only` (NFF's negative radii) only hits where the
/// ray leaves the solid count.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Centre of the base end.
    pub base: Vec3,
    /// Radius at the base end, ≥ 0.
    pub base_radius: f32,
    /// Centre of the apex end.
    pub apex: Vec3,
    /// Radius at the apex end, ≥ 0.
    pub apex_radius: f32,
    /// Only the inside is visible.
    pub inside_only: bool,
    /// Unit axis from base to apex (derived).
    axis: Vec3,
    /// Distance from base to apex (derived).
    height: f32,
    /// Radius change per unit of height (derived).
    slope: f32,
}

impl Cone {
    /// A cone from NFF's values. Radii are given signed: negative radii (the other one
    /// negative too, or zero for a pointed cone) make the inside visible. The loader
    /// checks that the signs do not conflict and that `base != apex`.
    pub fn new(base: Vec3, base_radius: f32, apex: Vec3, apex_radius: f32) -> Self {
        let inside_only = base_radius < 0.0 || apex_radius < 0.0;
        let (base_radius, apex_radius) = (base_radius.abs(), apex_radius.abs());
        let h = apex - base;
        let height = h.length();
        Cone {
            base,
            base_radius,
            apex,
            apex_radius,
            inside_only,
            axis: h / height,
            height,
            slope: (apex_radius - base_radius) / height,
        }
    }

    /// Unit axis from base to apex.
    pub fn axis(&self) -> Vec3 {
        self.axis
    }

    /// Distance between the two end centres.
    pub fn height(&self) -> f32 {
        self.height
    }

    /// The ray's quadratic (see [`ConeQuadratic`]) for the ray re-based at
    /// `org + t₀·dir`, the point of the ray nearest the base centre.
    ///
    /// Re-basing keeps the coefficients of the size of the cone instead of the ray's
    /// distance, so a thin cone seen from afar does not lose its discriminant to
    /// cancellation (the analogue of Ray Tracing Gems ch. 7's sphere form).
    ///
    /// It is set up in f64 from the f32 inputs, which are exact there, and along the
    /// unnormalised axis `H = apex − base`, exact too: with `σ = (p − base)·H` and
    /// `r = r_b + Δr·σ/|H|²`, the surface `|p⊥|² = r²` times `|H|⁴` is
    /// `|H|²(|H|²|p|² − σ²) = (r_b|H|² + Δr·σ)²`, with no division and no rounded unit
    /// axis (an f32 unit axis is ~1e-7 rad off the true one). The perpendicular parts
    /// come out of `|H|²|v|² − (v·H)²`, whose cancellation costs a relative 1e-16/θ² for
    /// a direction θ rad off the axis: less than the f32 form lost for any θ above
    /// 1e-9 rad. No square roots and no f32 → f64 → f32 round trips, so it is also
    /// cheaper than the f32 set-up with difference-of-products steps it replaces.
    #[inline]
    fn quadratic(&self, ray: &Ray) -> ConeQuadratic {
        let base = self.base.as_dvec3();
        let h = self.apex.as_dvec3() - base;
        let hh = h.dot(h);
        let rb = f64::from(self.base_radius);
        let dr = f64::from(self.apex_radius) - rb;
        let d = ray.dir.as_dvec3();
        let m = base - ray.org.as_dvec3();
        let dd = d.dot(d);
        let t0 = m.dot(d) / dd;
        // The re-based origin relative to the base centre; `d·f = 0` up to rounding.
        let f = d * t0 - m;
        let fs = f.dot(h);
        let ds = d.dot(h);
        // |H|² times the radius at the re-based origin, and its rate along the ray.
        let r0 = rb * hh + dr * fs;
        let drds = dr * ds;
        ConeQuadratic {
            a: hh * (hh * dd - ds * ds) - drds * drds,
            b: -(hh * fs * ds + drds * r0),
            c: hh * (hh * f.dot(f) - fs * fs) - r0 * r0,
            fs,
            ds,
            hh,
            t0,
        }
    }

    /// Whether the ray's line passes the axis's line farther than the larger radius,
    /// so that it cannot meet the cone: a few f32 operations that spare most of the
    /// exact f64 test to rays that enter a thin oblique cone's box but not the cone
    /// (most of them, for the SPD's jacks and rings).
    ///
    /// The distance between the lines is `|m·c| / |c|`, with `m` from the ray's origin
    /// to the base centre and `c = d × H`. It is computed in f32, so the test only
    /// answers "far" with a margin of 3·10⁻⁴ of the sizes involved, thousands of times
    /// the rounding of these few operations: the rays it refuses are ones the exact
    /// test misses too, and every other ray gets exactly the exact test's answer. A
    /// ray along the axis (`c = 0`), or with a non-finite value, is never refused.
    #[inline(always)]
    fn line_passes_wide(&self, ray: &Ray) -> bool {
        let m = self.base - ray.org;
        let h = self.apex - self.base;
        let c = ray.dir.cross(h);
        let radius = self.base_radius.max(self.apex_radius);
        let sizes = ray.dir.abs().max_element() * h.abs().max_element();
        let margin = 3e-4 * (m.abs().max_element() + radius) * sizes;
        m.dot(c).abs() > radius * c.length() + margin
    }

    /// Outward normal (unnormalised) at point `p` whose axial coordinate is `s`.
    #[inline]
    fn normal_at(&self, p: Vec3, s: f32) -> Vec3 {
        let q = p - self.base - self.axis * s;
        let r = self.base_radius + self.slope * s;
        // Gradient of |q⊥|² − r(s)²: 2 q⊥ − 2 k r(s) w.
        q - self.axis * (self.slope * r)
    }

    /// First accepted root as `(t, u)`, `u` the axial fraction from base (0) to apex
    /// (1): inside the ray interval and within the two ends; for an inside-only cone
    /// only the exit root (the ray leaving the solid) counts.
    #[inline]
    fn first(&self, ray: &Ray) -> Option<(f32, f32)> {
        if self.line_passes_wide(ray) {
            return None;
        }
        self.first_exact(ray)
    }

    /// [`Cone::first`] by the exact test alone.
    #[inline(always)]
    fn first_exact(&self, ray: &Ray) -> Option<(f32, f32)> {
        let q = self.quadratic(ray);
        let (entry, exit) = q.roots()?;
        let candidates = if self.inside_only {
            [exit, f64::NAN]
        } else if entry <= exit {
            [entry, exit]
        } else {
            [exit, entry]
        };
        for root in candidates {
            let t = (q.t0 + root) as f32;
            if !(t > ray.tmin && t < ray.tmax) {
                continue;
            }
            let sigma = q.fs + root * q.ds;
            if (0.0..=q.hh).contains(&sigma) {
                return Some((t, (sigma / q.hh) as f32));
            }
        }
        None
    }
}

impl Intersect for Cone {
    /// Bounds of the two end disks, widened by a few ulps.
    fn bounds(&self) -> Aabb {
        let w = self.axis;
        // Half-extent of a disk of radius r with normal w along axis i: r·√(1 − w_i²).
        let k = (Vec3::ONE - w * w).max(Vec3::ZERO);
        let k = Vec3::new(k.x.sqrt(), k.y.sqrt(), k.z.sqrt());
        let eb = k * self.base_radius;
        let ea = k * self.apex_radius;
        let b = Aabb::from_points(self.base - eb, self.base + eb)
            .union(&Aabb::from_points(self.apex - ea, self.apex + ea));
        let slack = (b.min.abs().max(b.max.abs())
            + Vec3::splat(self.base_radius.max(self.apex_radius)))
            * gamma(4);
        Aabb {
            min: b.min - slack,
            max: b.max + slack,
        }
    }

    /// The nearest hit in `(ray.tmin, ray.tmax)`. `u` is the axial fraction from base
    /// (0) to apex (1).
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let (t, u) = self.first(ray)?;
        Some(ShapeHit {
            t,
            u,
            v: 0.0,
            ng: self.normal_at(ray.at(t), u * self.height),
        })
    }

    /// Whether a hit lies in `(ray.tmin, ray.tmax)`.
    // Always inlined: the shadow-ray callbacks and leaf loops call it once per
    // candidate, and a call there costs more than the test's set-up.
    #[inline(always)]
    fn occluded(&self, ray: &Ray) -> bool {
        self.first(ray).is_some()
    }

    /// The hit point refined by one re-intersection from `o + t·d` (the remaining root
    /// is tiny, so its relative error no longer matters), with an error bound that
    /// scales with the cone's coordinates.
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        let t = hit.t;
        let p0 = ray.at(t);
        let local = Ray {
            org: p0,
            dir: ray.dir,
            tmin: f32::NEG_INFINITY,
            tmax: f32::INFINITY,
        };
        let mut p = p0;
        let q = self.quadratic(&local);
        if let Some((r0, r1)) = q.roots() {
            let (r0, r1) = ((q.t0 + r0) as f32, (q.t0 + r1) as f32);
            let dt = if r0.abs() < r1.abs() { r0 } else { r1 };
            if dt.is_finite() && dt.abs() < t.abs().max(1.0) * 1e-3 {
                p = p0 + ray.dir * dt;
            }
        }
        let s = (p - self.base).dot(self.axis);
        let ng = self.normal_at(p, s).normalize_or(-ray.dir.normalize());
        let scale = p.abs().max_element()
            + self.base.abs().max_element()
            + self.base_radius.max(self.apex_radius)
            + self.height;
        SurfacePoint {
            p,
            err: Vec3::splat(scale * gamma(32)),
            ng,
        }
    }
}

impl Cone {
    /// Whether both ends have the same radius: an open cylinder.
    pub fn is_cylinder(&self) -> bool {
        self.base_radius == self.apex_radius
    }
}

/// An open surface: not a CSG operand, no inside (the defaults).
impl Primitive for Cone {
    /// The cylindrical parameterisation at `p`.
    fn param(&self, p: Vec3, _ng: Vec3) -> Param {
        let slope = (self.apex_radius - self.base_radius) / self.height();
        cylindrical(p, self.base, self.axis(), self.height(), slope)
    }

    /// Under a similarity: the ends moved, the radii scaled.
    fn bake(&self, m: &DAffine3) -> Option<Shape> {
        let k = similarity_scale(m)?;
        let sign = if self.inside_only { -1.0 } else { 1.0 };
        Some(
            Cone::new(
                m.transform_point3(self.base.as_dvec3()).as_vec3(),
                sign * (self.base_radius as f64 * k) as f32,
                m.transform_point3(self.apex.as_dvec3()).as_vec3(),
                sign * (self.apex_radius as f64 * k) as f32,
            )
            .into(),
        )
    }

    /// The lateral surface on an angle × height grid (its outside, or its inside when
    /// only that is visible): an open surface, meshed on its front side.
    fn tessellate(&self, patch: f32) -> Option<Tessellation> {
        let mut t = revolution(
            self.base,
            self.axis(),
            self.height(),
            (self.base_radius.abs(), self.apex_radius.abs()),
            patch,
            false,
        );
        flip(&mut t.faces, self.inside_only);
        Some(t)
    }
}

/// A ray's quadratic against a cone, `a t² + 2 b t + c = 0` in the re-based parameter
/// `t − t0`: `|H|⁴ (|q⊥|² − r²)`, negative inside the solid (see [`Cone::quadratic`]),
/// with `σ = (p − base)·H` at the re-based origin (`fs`) and its rate along the ray
/// (`ds`); the ends are at `σ = 0` and `σ = |H|²` (`hh`).
#[derive(Clone, Copy, Debug)]
struct ConeQuadratic {
    a: f64,
    b: f64,
    c: f64,
    fs: f64,
    ds: f64,
    hh: f64,
    t0: f64,
}

impl ConeQuadratic {
    /// The re-based `(entry, exit)` roots (see [`quadratic_roots_f64`]), or `None` when
    /// the line misses the infinite cone (or the set-up was not finite).
    #[inline]
    fn roots(&self) -> Option<(f64, f64)> {
        let disc = self.b * self.b - self.a * self.c;
        // Also false for a NaN.
        if !(0.0..f64::INFINITY).contains(&disc) {
            return None;
        }
        Some(quadratic_roots_f64(self.a, self.b, self.c, disc))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rng;

    #[test]
    fn the_distance_filter_refuses_only_rays_that_miss() {
        let mut rng = Rng::new(17);
        let (mut refused, mut hits) = (0, 0);
        for scale in [1e-3f32, 1.0, 1e3] {
            for _ in 0..4000 {
                let base = rng.vec3_in(-1.0, 1.0) * scale;
                let apex = base + rng.vec3_in(-1.0, 1.0) * scale;
                let (rb, ra) = (rng.range(0.0, 0.2) * scale, rng.range(0.0, 0.2) * scale);
                let sign = if rng.next_f32() < 0.2 { -1.0 } else { 1.0 };
                let cone = Cone::new(
                    base,
                    sign * rb,
                    apex,
                    if rb == 0.0 { ra } else { sign * ra },
                );
                let org = rng.vec3_in(-3.0, 3.0) * scale;
                // Aim near the cone: its surface, just off it, or along its axis.
                let s = rng.next_f32();
                let on_axis = base + (apex - base) * s;
                let target = on_axis + rng.vec3_in(-0.25, 0.25) * scale;
                let dir = if rng.next_f32() < 0.1 {
                    (apex - base) * rng.range(0.5, 2.0)
                } else {
                    (target - org) * rng.range(0.1, 10.0)
                };
                let ray = Ray::new(org, dir);
                let want = cone.first_exact(&ray);
                hits += usize::from(want.is_some());
                if cone.line_passes_wide(&ray) {
                    refused += 1;
                    assert!(want.is_none(), "refused a hit: {cone:?} {ray:?}");
                }
                assert_eq!(cone.first(&ray), want, "{cone:?} {ray:?}");
            }
        }
        assert!(
            refused > 2000 && hits > 2000,
            "refused {refused}, hits {hits}"
        );
    }
}
