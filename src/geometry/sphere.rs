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
    #[inline]
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
