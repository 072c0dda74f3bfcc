use super::param::cylindrical;
use super::{
    Intersect, Param, Primitive, ShapeHit, Spans, SurfacePoint, diff_of_products, quadratic_roots,
};
use crate::math::{Aabb, Ray, Vec3, gamma};

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

    /// Bounds of the two end disks, widened by a few ulps.
    pub fn bounds(&self) -> Aabb {
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

    /// Coefficients (a, half b, c) of the quadratic `|q⊥(t)|² = (r_b + k·s(t))²` for the
    /// ray re-based at `org + t₀·dir`, the point of the ray nearest the cone's middle, and
    /// the axial coordinate's value there and rate; returns `t₀` last.
    ///
    /// Re-basing keeps the coefficients of the size of the cone instead of the ray's
    /// distance, so a thin cone seen from afar does not lose its discriminant to
    /// cancellation (the analogue of Ray Tracing Gems ch. 7's sphere form).
    #[inline]
    fn quadratic(&self, ray: &Ray) -> (f32, f32, f32, f32, f32, f32) {
        let w = self.axis;
        let k = self.slope;
        let mid = self.base + w * (0.5 * self.height);
        let dd = ray.dir.dot(ray.dir);
        let t0 = (mid - ray.org).dot(ray.dir) / dd;
        let org = ray.org + ray.dir * t0;
        let f = org - self.base;
        let fs = f.dot(w);
        let ds = ray.dir.dot(w);
        let fp = f - w * fs;
        let dp = ray.dir - w * ds;
        let r0 = self.base_radius + k * fs;
        let kds = k * ds;
        let dpl = dp.length();
        let a = diff_of_products(dpl, dpl, kds, kds);
        let b = dp.dot(fp) - kds * r0;
        let fpl = fp.length();
        let c = diff_of_products(fpl, fpl, r0, r0);
        (a, b, c, fs, ds, t0)
    }

    /// Outward normal (unnormalised) at point `p` whose axial coordinate is `s`.
    #[inline]
    fn normal_at(&self, p: Vec3, s: f32) -> Vec3 {
        let q = p - self.base - self.axis * s;
        let r = self.base_radius + self.slope * s;
        // Gradient of |q⊥|² − r(s)²: 2 q⊥ − 2 k r(s) w.
        q - self.axis * (self.slope * r)
    }

    /// First accepted root: inside the ray interval and within the two ends; for an
    /// inside-only cone only the exit root (the ray leaving the solid) counts.
    #[inline]
    fn first(&self, ray: &Ray) -> Option<(f32, f32)> {
        let (a, b, c, fs, ds, t0) = self.quadratic(ray);
        let disc = diff_of_products(b, b, a, c);
        if disc < 0.0 || !disc.is_finite() {
            return None;
        }
        let (entry, exit) = quadratic_roots(a, b, c, disc);
        let (entry, exit) = (entry + t0, exit + t0);
        let fs = fs - t0 * ds;
        let candidates = if self.inside_only {
            [exit, f32::NAN]
        } else if entry <= exit {
            [entry, exit]
        } else {
            [exit, entry]
        };
        for t in candidates {
            if !(t > ray.tmin && t < ray.tmax) {
                continue;
            }
            let s = fs + t * ds;
            if (0.0..=self.height).contains(&s) {
                return Some((t, s));
            }
        }
        None
    }

    /// The nearest hit in `(ray.tmin, ray.tmax)`. `u` is the axial fraction from base
    /// (0) to apex (1).
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let (t, s) = self.first(ray)?;
        Some(ShapeHit {
            t,
            u: s / self.height,
            v: 0.0,
            ng: self.normal_at(ray.at(t), s),
        })
    }

    /// Whether a hit lies in `(ray.tmin, ray.tmax)`.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.first(ray).is_some()
    }

    /// The hit point refined by one re-intersection from `o + t·d` (the remaining root
    /// is tiny, so its relative error no longer matters), with an error bound that
    /// scales with the cone's coordinates.
    pub fn surface(&self, ray: &Ray, t: f32) -> SurfacePoint {
        let p0 = ray.at(t);
        let local = Ray {
            org: p0,
            dir: ray.dir,
            tmin: f32::NEG_INFINITY,
            tmax: f32::INFINITY,
        };
        let mut p = p0;
        let (a, b, c, _, _, t0) = self.quadratic(&local);
        let disc = diff_of_products(b, b, a, c);
        if disc >= 0.0 && disc.is_finite() {
            let (r0, r1) = quadratic_roots(a, b, c, disc);
            let (r0, r1) = (r0 + t0, r1 + t0);
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

impl Intersect for Cone {
    fn bounds(&self) -> Aabb {
        Cone::bounds(self)
    }
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        Cone::intersect(self, ray)
    }
    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        Cone::occluded(self, ray)
    }
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        Cone::surface(self, ray, hit.t)
    }
}

impl Cone {
    /// Whether both ends have the same radius: an open cylinder.
    pub fn is_cylinder(&self) -> bool {
        self.base_radius == self.apex_radius
    }

    /// The cylindrical parameterisation at `p`.
    pub fn param(&self, p: Vec3) -> Param {
        let slope = (self.apex_radius - self.base_radius) / self.height();
        cylindrical(p, self.base, self.axis(), self.height(), slope)
    }
}

/// An open surface: not a CSG operand, no inside.
impl Primitive for Cone {
    fn is_solid(&self) -> bool {
        false
    }
    fn spans(&self, _ray: &Ray, _out: &mut Spans) {}
    fn contains(&self, _p: Vec3) -> bool {
        false
    }
    fn param(&self, p: Vec3, _ng: Vec3) -> Param {
        Cone::param(self, p)
    }
}
