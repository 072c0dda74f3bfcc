//! The infinite plane `n·x = d` and its half-space `n·x ≤ d`.
//!
//! Computed in f64 (the ray's f32 coordinates are exact there), so `n·o − d` does not
//! cancel for origins near a plane far from the world origin; only `t`, the normal and
//! the surface point are rounded to f32.

use super::quadric::{check_finite, gamma64, rounding_err, unit_axis};
use super::{Intersect, Param, Primitive, Shape, ShapeError, ShapeHit, Span, Spans, SurfacePoint};
use crate::math::{Aabb, DVec3, Ray, Vec3};
use glam::DAffine3;

/// An infinite plane `n·x = d` (unit `n`); as a solid, the half-space `n·x ≤ d`, so the
/// outward normal is `n`. Its bounds are [`Aabb::INFINITE`]; `u` and `v` of hits are 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal, f64.
    n: DVec3,
    /// Offset along `n`: the plane is `n·x = d`.
    d: f64,
    /// Unit normal rounded to f32.
    n32: Vec3,
}

impl Plane {
    /// The plane `normal·x = offset` (any non-zero length of `normal`; both are divided
    /// by it in f64).
    pub fn new(normal: Vec3, offset: f32) -> Result<Self, ShapeError> {
        let len = normal.as_dvec3().length();
        let n = unit_axis("plane normal", normal)?;
        if !offset.is_finite() {
            return Err(ShapeError::PlaneOffset(offset));
        }
        Ok(Self::from_unit(n, offset as f64 / len))
    }

    /// The plane through `point` perpendicular to `normal` (any non-zero length),
    /// with `normal` pointing out of the half-space.
    pub fn from_point_normal(point: Vec3, normal: Vec3) -> Result<Self, ShapeError> {
        check_finite("plane point", point)?;
        let n = unit_axis("plane normal", normal)?;
        Ok(Self::from_unit(n, n.dot(point.as_dvec3())))
    }

    fn from_unit(n: DVec3, d: f64) -> Self {
        Plane {
            n,
            d,
            n32: n.as_vec3(),
        }
    }

    /// Unit outward normal.
    pub fn normal(&self) -> Vec3 {
        self.n32
    }

    /// Signed distance of the plane from the world origin along [`Plane::normal`].
    pub fn offset(&self) -> f64 {
        self.d
    }

    /// Signed distance of `p` from the plane (positive outside), in f64.
    pub fn distance(&self, p: DVec3) -> f64 {
        self.n.dot(p) - self.d
    }

    /// Ray parameter of the crossing and `n·dir`, for finite rays that are not parallel.
    #[inline]
    fn crossing(&self, ray: &Ray) -> Option<(f64, f64)> {
        if !(ray.org.is_finite() && ray.dir.is_finite()) {
            return None;
        }
        let den = self.n.dot(ray.dir.as_dvec3());
        if den == 0.0 {
            return None;
        }
        Some((-self.distance(ray.org.as_dvec3()) / den, den))
    }
}

impl Intersect for Plane {
    fn bounds(&self) -> Aabb {
        Aabb::INFINITE
    }

    /// The hit in `(ray.tmin, ray.tmax)`, if any; `ng` is the unit normal.
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let (t, _) = self.crossing(ray)?;
        let t = t as f32;
        (t > ray.tmin && t < ray.tmax).then_some(ShapeHit {
            t,
            u: 0.0,
            v: 0.0,
            ng: self.n32,
        })
    }

    /// The hit point projected onto the plane in f64, rounded to f32, with the bound of
    /// that rounding (plus the f64 projection's own error).
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        let mut p = ray.org.as_dvec3() + ray.dir.as_dvec3() * hit.t as f64;
        if !p.is_finite() {
            p = ray.org.as_dvec3();
        }
        for _ in 0..2 {
            p -= self.n * self.distance(p);
        }
        let delta = gamma64(8) * (p.abs().dot(self.n.abs()) + self.d.abs() + p.abs().max_element());
        let p32 = p.as_vec3();
        SurfacePoint {
            p: p32,
            err: rounding_err(p32, delta),
            ng: self.n32,
        }
    }
}

impl Primitive for Plane {
    /// The half-space: unbounded, but usable to cut bounded solids.
    fn is_solid(&self) -> bool {
        true
    }

    /// The half-space's span of the whole line: a half-line, the whole line (parallel,
    /// inside) or nothing (parallel, outside). Infinite ends have a zero normal.
    fn spans(&self, ray: &Ray, out: &mut Spans) {
        if !(ray.org.is_finite() && ray.dir.is_finite()) || ray.dir == Vec3::ZERO {
            return;
        }
        let (t_in, n_in, t_out, n_out) = match self.crossing(ray) {
            Some((t, den)) if den > 0.0 => (f32::NEG_INFINITY, Vec3::ZERO, t as f32, self.n32),
            Some((t, _)) => (t as f32, self.n32, f32::INFINITY, Vec3::ZERO),
            None if self.distance(ray.org.as_dvec3()) <= 0.0 => {
                (f32::NEG_INFINITY, Vec3::ZERO, f32::INFINITY, Vec3::ZERO)
            }
            None => return,
        };
        out.push(Span {
            t_in,
            n_in,
            t_out,
            n_out,
        });
    }

    /// Whether `p` is in the half-space `n·x ≤ d`.
    fn contains(&self, p: Vec3) -> bool {
        self.distance(p.as_dvec3()) <= 0.0
    }

    /// The planar parameterisation about the normal ([`Param::planar`]).
    fn param(&self, p: Vec3, ng: Vec3) -> Param {
        Param::planar(p, ng)
    }

    /// Under any invertible map: a point of the plane moved, the normal by the inverse
    /// transpose.
    fn bake(&self, m: &DAffine3) -> Option<Shape> {
        let n = self.normal().as_dvec3();
        let point = m.transform_point3(n * self.offset());
        let normal = m.matrix3.inverse().transpose() * n;
        Plane::from_point_normal(point.as_vec3(), normal.as_vec3())
            .ok()
            .map(Shape::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_space_spans() {
        let p = Plane::new(Vec3::new(0.0, 0.0, 2.0), 2.0).unwrap();
        assert_eq!(p.offset(), 1.0);
        let mut s = Spans::new();
        p.spans(&Ray::new(Vec3::ZERO, Vec3::Z), &mut s);
        assert_eq!(s[0].t_in, f32::NEG_INFINITY);
        assert_eq!(s[0].t_out, 1.0);
        assert_eq!(s[0].n_out, Vec3::Z);
        s.clear();
        p.spans(&Ray::new(Vec3::ZERO, -Vec3::Z * 4.0), &mut s);
        assert_eq!((s[0].t_in, s[0].t_out), (-0.25, f32::INFINITY));
        s.clear();
        p.spans(&Ray::new(Vec3::ZERO, Vec3::X), &mut s);
        assert_eq!(s.len(), 1);
        assert!(s[0].t_in.is_infinite() && s[0].t_out.is_infinite());
        s.clear();
        p.spans(&Ray::new(Vec3::new(0.0, 0.0, 3.0), Vec3::X), &mut s);
        assert!(s.is_empty());
        assert!(p.intersect(&Ray::new(Vec3::ZERO, Vec3::X)).is_none());
        let nan = Ray::new(Vec3::splat(f32::NAN), Vec3::Z);
        assert!(p.intersect(&nan).is_none());
        p.spans(&nan, &mut s);
        assert!(s.is_empty());
    }

    #[test]
    fn rejects_bad_input() {
        assert!(Plane::new(Vec3::ZERO, 1.0).is_err());
        assert!(Plane::new(Vec3::Z, f32::NAN).is_err());
        assert!(Plane::from_point_normal(Vec3::splat(f32::INFINITY), Vec3::Z).is_err());
    }
}
