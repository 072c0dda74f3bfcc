use super::param::{MIN_SIN, turn};
use super::tessellate::{Lookup, Tessellation, cells, flip, inscribed_depth, oriented};
use super::{
    Intersect, Param, Primitive, Shape, ShapeHit, Span, Spans, SurfacePoint, diff_of_products,
    quadratic_roots,
};
use crate::math::{Aabb, Ray, Vec3, gamma, similarity_scale};
use glam::DAffine3;
use glam::Vec2;
use std::f32::consts::{PI, TAU};

/// A sphere. With `inside_only` (NFF's negative radius) only hits where the ray leaves
/// the sphere count, so the inside is visible and the outside is not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius, positive.
    pub radius: f32,
    /// Only the inside is visible.
    pub inside_only: bool,
}

impl Sphere {
    /// A sphere from NFF's signed radius.
    pub fn new(center: Vec3, signed_radius: f32) -> Self {
        Sphere {
            center,
            radius: signed_radius.abs(),
            inside_only: signed_radius < 0.0,
        }
    }

    /// The (entry, exit) roots of the ray's quadratic, or `None` on a miss
    /// (Haines et al., Ray Tracing Gems ch. 7: the discriminant from the distance between
    /// the centre and the line, which does not cancel).
    #[inline]
    pub(crate) fn roots(&self, ray: &Ray) -> Option<(f32, f32)> {
        let f = ray.org - self.center;
        if self.clearly_missed_by(f, ray.dir, ray.dir.dot(ray.dir)) {
            return None;
        }
        self.exact_roots(ray)
    }

    /// [`Sphere::roots`] without the quick rejection.
    #[inline(always)]
    fn exact_roots(&self, ray: &Ray) -> Option<(f32, f32)> {
        let f = ray.org - self.center;
        let a = ray.dir.dot(ray.dir);
        let b = f.dot(ray.dir);
        let c = f.dot(f) - self.radius * self.radius;
        // Perpendicular vector from the centre to the line.
        let l = f - ray.dir * (b / a);
        let ll = l.length();
        let disc = a * diff_of_products(self.radius, self.radius, ll, ll);
        if disc < 0.0 || !disc.is_finite() {
            return None;
        }
        // a > 0, so the entry root is the smaller one.
        Some(quadratic_roots(a, b, c, disc))
    }
}

/// The margin of [`Sphere::clearly_missed_by`], relative to the squared distance from
/// the ray's origin to the centre: 2⁻¹⁶, sixteen times the rounding error of both ways
/// of computing the line's distance (about 15 f32 epsilons).
const MISS_MARGIN: f32 = 1.0 / 65536.0;

impl Sphere {
    /// Whether the line through the ray (origin `f` from the centre, direction `d`,
    /// `a = d·d`) passes so far from the centre that the exact test of
    /// [`Sphere::roots`] finds it misses too, with no square root or division: the
    /// squared distance `|f × d|² / a` exceeds `r²` by more than [`MISS_MARGIN`]` × |f|²`.
    ///
    /// Why the exact test agrees: its perpendicular `l = f − d (f·d)/a` is off by at most
    /// about 4ε|f| (the subtraction of the projection, at most |f| long), so its `|l|²`
    /// by at most about 9ε|f|²; `|f × d|²` here is off by at most about 6ε|f|²a. A
    /// distance over `r² + 2⁻¹⁶|f|²` here is therefore over `r² + (2⁻¹⁶ − 15ε)|f|²`
    /// there, and the exact discriminant `r² − |l|²` is negative. A non-finite value
    /// compares false and leaves the decision to the exact test. Most rays that reach
    /// a sphere's box miss the sphere; they stop here.
    #[inline(always)]
    fn clearly_missed_by(&self, f: Vec3, d: Vec3, a: f32) -> bool {
        let perp = f.cross(d);
        let r2 = self.radius * self.radius;
        perp.dot(perp) > a * (r2 + MISS_MARGIN * f.dot(f))
    }
}

impl Intersect for Sphere {
    /// Bounds, widened by a few ulps.
    fn bounds(&self) -> Aabb {
        let r = Vec3::splat(self.radius * (1.0 + gamma(2)));
        let slack = self.center.abs() * gamma(2);
        Aabb {
            min: self.center - r - slack,
            max: self.center + r + slack,
        }
    }

    /// The nearest hit in `(ray.tmin, ray.tmax)`.
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let (t0, t1) = self.roots(ray)?;
        let t = if !self.inside_only && t0 > ray.tmin && t0 < ray.tmax {
            t0
        } else if t1 > ray.tmin && t1 < ray.tmax {
            t1
        } else {
            return None;
        };
        let ng = ray.at(t) - self.center;
        Some(ShapeHit {
            t,
            u: 0.0,
            v: 0.0,
            ng,
        })
    }

    /// Whether a hit lies in `(ray.tmin, ray.tmax)`.
    // Always inlined: the shadow-ray callbacks and leaf loops call it once per
    // candidate, and a call there costs more than the test's set-up.
    #[inline(always)]
    fn occluded(&self, ray: &Ray) -> bool {
        match self.roots(ray) {
            Some((t0, t1)) => {
                (!self.inside_only && t0 > ray.tmin && t0 < ray.tmax)
                    || (t1 > ray.tmin && t1 < ray.tmax)
            }
            None => false,
        }
    }

    /// The hit point reprojected onto the sphere, with its error bound (pbrt §6.8.5).
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        let mut local = ray.at(hit.t) - self.center;
        let len = local.length();
        if len > 0.0 {
            local *= self.radius / len;
        }
        let p = self.center + local;
        let err = (local.abs() * gamma(5) + p.abs() * gamma(1)) * 2.0;
        let ng = if len > 0.0 {
            local / self.radius
        } else {
            -ray.dir.normalize()
        };
        SurfacePoint { p, err, ng }
    }
}

impl Primitive for Sphere {
    /// A sphere is a solid unless only its inside is visible.
    fn is_solid(&self) -> bool {
        !self.inside_only
    }

    fn spans(&self, ray: &Ray, out: &mut Spans) {
        if let Some((t0, t1)) = self.roots(ray) {
            if t0 <= t1 {
                out.push(Span {
                    t_in: t0,
                    n_in: ray.at(t0) - self.center,
                    t_out: t1,
                    n_out: ray.at(t1) - self.center,
                });
            }
        }
    }

    fn contains(&self, p: Vec3) -> bool {
        (p - self.center).length_squared() <= self.radius * self.radius
    }

    /// The spherical parameterisation at `p` (see [`Param`]).
    fn param(&self, p: Vec3, _ng: Vec3) -> Param {
        let q = ((p - self.center) / self.radius).clamp(Vec3::splat(-1.0), Vec3::splat(1.0));
        let phi = q.x.atan2(q.z);
        let u = turn(q.x, q.z);
        let theta = q.y.clamp(-1.0, 1.0).acos();
        let (sin_t, cos_t) = theta.sin_cos();
        let (sin_p, cos_p) = phi.sin_cos();
        let r = self.radius;
        let dpdu = Vec3::new(cos_p, 0.0, -sin_p) * (TAU * r * sin_t.max(MIN_SIN));
        // v = 1 − θ/π, so ∂p/∂v = −π ∂p/∂θ.
        let dpdv = Vec3::new(cos_t * sin_p, -sin_t, cos_t * cos_p) * (-PI * r);
        Param {
            uv: Vec2::new(u, 1.0 - theta / PI),
            dpdu,
            dpdv,
        }
    }

    /// Under a similarity: the centre moved, the radius scaled.
    fn bake(&self, m: &DAffine3) -> Option<Shape> {
        let k = similarity_scale(m)?;
        let r = (self.radius as f64 * k) as f32;
        Some(
            Sphere {
                center: m.transform_point3(self.center.as_dvec3()).as_vec3(),
                radius: r,
                inside_only: self.inside_only,
            }
            .into(),
        )
    }

    /// A sphere on a latitude–longitude grid of cells about `patch` across (at least
    /// 16 × 8).
    fn tessellate(&self, patch: f32) -> Option<Tessellation> {
        let r = self.radius.abs();
        let nu = cells(TAU * r, patch, 16, 256);
        let nv = cells(PI * r, patch, 8, 128);
        // Grid points, the seam and the poles computed once so shared corners are equal.
        let point = |i: u32, j: u32| -> Vec3 {
            if j == 0 {
                return self.center - Vec3::Y * r;
            }
            if j == nv {
                return self.center + Vec3::Y * r;
            }
            let theta = PI * (1.0 - j as f32 / nv as f32);
            let phi = TAU * (i % nu) as f32 / nu as f32;
            let (st, ct) = theta.sin_cos();
            let (sp, cp) = phi.sin_cos();
            self.center + Vec3::new(st * sp, ct, st * cp) * r
        };
        let mut faces = Vec::new();
        let mut depth = Vec::new();
        for j in 0..nv {
            for i in 0..nu {
                let poly = vec![
                    point(i, j),
                    point(i + 1, j),
                    point(i + 1, j + 1),
                    point(i, j + 1),
                ];
                let mid = poly.iter().copied().sum::<Vec3>() / 4.0 - self.center;
                let f = oriented(poly, mid);
                depth.push(inscribed_depth(&f, self.center, r));
                faces.push(f);
            }
        }
        flip(&mut faces, self.inside_only);
        Some(Tessellation {
            faces,
            depth,
            lookup: Lookup::Sphere {
                center: self.center,
                nu,
                nv,
            },
            smooth: true,
            open: false,
        })
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_clear_miss_is_a_miss_of_the_exact_test() {
        // Spheres of radii 10⁻³ to 10³ at up to 10⁴ from the origin, rays from up to
        // 10⁴ in every direction and length, half of them grazing: whenever the quick
        // test rejects, the exact roots are none; and it rejects most misses.
        let mut state = 0x2545_f491_u32;
        let mut next = move || {
            state = crate::math::hash(state);
            crate::math::hash_unit(state)
        };
        let (mut rejected, mut misses) = (0u32, 0u32);
        for k in 0..200_000 {
            let mut v = |scale: f32| Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * scale;
            let (c, o, u, s1, s2) = (v(2e4), v(2e4), v(2.0), v(1.0), v(1.0));
            let radius = 10f32.powf(6.0 * (s1.x + 0.5) - 3.0);
            let s = Sphere::new(c, radius);
            // Every other ray aimed at the sphere's rim (grazing), the others anywhere
            // within three radii of the centre.
            let spread = if k % 2 == 0 { 1.0 + 1e-4 * s1.y } else { 6.0 * s1.y };
            let target = s.center + u.normalize_or_zero() * radius * spread;
            let dir = (target - o) * 10f32.powf(4.0 * (s2.x + 0.5) - 2.0);
            let ray = Ray::new(o, dir);
            let f = ray.org - s.center;
            let quick = s.clearly_missed_by(f, ray.dir, ray.dir.dot(ray.dir));
            let exact = s.exact_roots(&ray);
            assert!(!quick || exact.is_none(), "{s:?} {ray:?}: rejected but {exact:?}");
            // Rejection rate where the eye is within a hundred radii of the sphere
            // (farther off, the margin lets more misses through to the exact test).
            if k % 2 == 1 && f.length() < 100.0 * radius {
                misses += u32::from(exact.is_none());
                rejected += u32::from(quick);
            }
        }
        assert!(misses > 100 && rejected * 10 > misses * 9, "{rejected} of {misses}");
    }

    use super::*;
    use glam::DVec3;

    #[test]
    fn spheres_bake_under_similarities_only() {
        let s = Shape::Sphere(Sphere::new(Vec3::new(1.0, 0.0, 0.0), 2.0));
        let m = DAffine3::from_translation(DVec3::new(0.0, 5.0, 0.0))
            * DAffine3::from_scale(DVec3::splat(3.0))
            * DAffine3::from_axis_angle(DVec3::Z, std::f64::consts::FRAC_PI_2);
        let Some(Shape::Sphere(b)) = s.bake(&m) else {
            panic!("not baked")
        };
        assert!(
            (b.center - Vec3::new(0.0, 8.0, 0.0)).length() < 1e-5,
            "{}",
            b.center
        );
        assert!((b.radius - 6.0).abs() < 1e-5);
        assert!(s.bake(&DAffine3::from_scale(DVec3::new(1.0, 2.0, 3.0))).is_none());
    }
}
