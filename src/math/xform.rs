//! Affine transforms of rays, points and normals, with the rounding-error bounds that
//! robust ray spawning needs (pbrt, 3rd ed., §3.9).

use super::{Aabb, Ray, SurfacePoint, Vec3, gamma};
use glam::{Affine3A, DAffine3, DMat3, DVec3, Mat3};

/// Why a matrix is not a usable transform.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum XformError {
    /// An entry is NaN or infinite.
    #[error("the transform has a non-finite entry")]
    NonFinite,
    /// The determinant is zero, not finite, or tiny relative to the scale.
    #[error("the transform is singular or nearly so (determinant {determinant:e})")]
    Singular {
        /// The determinant of the linear part.
        determinant: f32,
    },
    /// The inverse overflows single precision.
    #[error("the transform cannot be inverted in single precision")]
    NotInvertible,
}

/// An invertible affine transform with its inverse, from object space to world space.
///
/// Rays go into object space by the inverse *without* renormalising the direction, so
/// a hit's `t` is the same number in both spaces. Normals go out by the inverse
/// transpose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Xform {
    /// Object to world.
    pub to_world: Affine3A,
    /// World to object.
    pub to_object: Affine3A,
}

impl Xform {
    /// The identity.
    pub const IDENTITY: Xform = Xform {
        to_world: Affine3A::IDENTITY,
        to_object: Affine3A::IDENTITY,
    };

    /// `m` (object to world) and its inverse; `Err` when `m` is singular, nearly so
    /// (condition number beyond 1e6) or not finite.
    pub fn new(m: Affine3A) -> Result<Xform, XformError> {
        let l = m.matrix3;
        let cols = [l.x_axis, l.y_axis, l.z_axis];
        if !cols.iter().all(|c| c.is_finite()) || !m.translation.is_finite() {
            return Err(XformError::NonFinite);
        }
        let det = Mat3::from(l).determinant();
        let scale = cols.iter().map(|c| c.length()).fold(0.0f32, f32::max);
        if det == 0.0 || !det.is_finite() || (det.abs() / scale.powi(3)) < 1e-6 {
            return Err(XformError::Singular { determinant: det });
        }
        let inv = m.inverse();
        if !inv.matrix3.x_axis.is_finite()
            || !inv.matrix3.y_axis.is_finite()
            || !inv.matrix3.z_axis.is_finite()
            || !inv.translation.is_finite()
        {
            return Err(XformError::NotInvertible);
        }
        Ok(Xform {
            to_world: m,
            to_object: inv,
        })
    }

    /// The composition `self ∘ inner` (apply `inner` first).
    pub fn then_inner(&self, inner: &Xform) -> Xform {
        Xform {
            to_world: self.to_world * inner.to_world,
            to_object: inner.to_object * self.to_object,
        }
    }

    /// The world ray in object space, `t` preserved.
    #[inline]
    pub fn ray_to_object(&self, ray: &Ray) -> Ray {
        Ray {
            org: self.to_object.transform_point3(ray.org),
            dir: self.to_object.transform_vector3(ray.dir),
            tmin: ray.tmin,
            tmax: ray.tmax,
        }
    }

    /// An object-space normal in world space (inverse transpose), not normalised.
    #[inline]
    pub fn normal_to_world(&self, n: Vec3) -> Vec3 {
        self.to_object.matrix3.transpose() * n
    }

    /// A world-space normal in object space (the transpose of `to_world`).
    #[inline]
    pub fn normal_to_object(&self, n: Vec3) -> Vec3 {
        self.to_world.matrix3.transpose() * n
    }

    /// World bounds of object bounds (the box of the eight transformed corners,
    /// widened by the rounding of the transform).
    pub fn bounds_to_world(&self, b: &Aabb) -> Aabb {
        if b.is_empty() {
            return *b;
        }
        if !b.is_finite() {
            return Aabb::INFINITE;
        }
        let mut out = Aabb::EMPTY;
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            );
            let (p, e) = self.point_to_world(c, Vec3::ZERO);
            out = out.grow(p - e).grow(p + e);
        }
        out
    }

    /// A point with error bound `err` in world space, with the error bound of the
    /// result: the propagated error plus the rounding of the transform itself.
    #[inline]
    pub fn point_to_world(&self, p: Vec3, err: Vec3) -> (Vec3, Vec3) {
        let m = &self.to_world;
        let q = m.transform_point3(p);
        let abs_m = Mat3::from_cols(
            m.matrix3.x_axis.abs().into(),
            m.matrix3.y_axis.abs().into(),
            m.matrix3.z_axis.abs().into(),
        );
        let rounding = (abs_m * p.abs() + Vec3::from(m.translation).abs()) * gamma(3);
        let propagated = abs_m * err * (1.0 + gamma(3));
        (q, rounding + propagated)
    }

    /// An object-space surface point in world space: point and error bound through
    /// `to_world`, unit normal through the inverse transpose.
    pub fn surface_to_world(&self, sp: &SurfacePoint) -> SurfacePoint {
        let (p, err) = self.point_to_world(sp.p, sp.err);
        let ng = self.normal_to_world(sp.ng).normalize_or(sp.ng);
        SurfacePoint { p, err, ng }
    }
}

/// The uniform scale factor of `m` if its linear part is a rotation (or mirror) times
/// that factor, to a relative 1e-6: a similarity, under which spheres, cones, tori and
/// oriented boxes keep their kind.
pub fn similarity_scale(m: &DAffine3) -> Option<f64> {
    let l = m.matrix3;
    let g = l.transpose() * l;
    let s2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    if !(s2 > 0.0 && s2.is_finite()) {
        return None;
    }
    let dev = g - DMat3::from_diagonal(DVec3::splat(s2));
    let worst = [dev.x_axis, dev.y_axis, dev.z_axis]
        .iter()
        .map(|c| c.abs().max_element())
        .fold(0.0f64, f64::max);
    (worst <= 1e-6 * s2).then(|| s2.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn xf() -> Xform {
        Xform::new(Affine3A::from_scale_rotation_translation(
            Vec3::new(2.0, 0.5, 3.0),
            Quat::from_rotation_y(0.7) * Quat::from_rotation_x(-0.3),
            Vec3::new(10.0, -4.0, 2.5),
        ))
        .unwrap()
    }

    #[test]
    fn rays_keep_their_parameter() {
        let x = xf();
        let ray = Ray::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(-0.3, 0.5, 0.8));
        let local = x.ray_to_object(&ray);
        for t in [0.0f32, 1.0, 7.5] {
            let back = x.to_world.transform_point3(local.at(t));
            assert!((back - ray.at(t)).length() < 1e-4, "t = {t}");
        }
    }

    #[test]
    fn normals_stay_perpendicular_under_non_uniform_scale() {
        let x = xf();
        let n = Vec3::new(0.2, 0.9, -0.4).normalize();
        let tangent = n.cross(Vec3::X);
        let nw = x.normal_to_world(n);
        let tw = x.to_world.transform_vector3(tangent);
        assert!(nw.dot(tw).abs() < 1e-5 * nw.length() * tw.length());
        let back = x.normal_to_object(nw);
        assert!((back.normalize() - n).length() < 1e-5);
    }

    #[test]
    fn point_error_bound_covers_the_exact_result() {
        let x = xf();
        let p = Vec3::new(123.456, -0.001, 77.0);
        let (q, err) = x.point_to_world(p, Vec3::ZERO);
        let m = x.to_world;
        let exact = m.matrix3.x_axis.as_dvec3() * p.x as f64
            + m.matrix3.y_axis.as_dvec3() * p.y as f64
            + m.matrix3.z_axis.as_dvec3() * p.z as f64
            + m.translation.as_dvec3();
        let d = (q.as_dvec3() - exact).abs();
        assert!(d.cmple(err.as_dvec3()).all(), "{d} vs {err}");
        assert!(err.max_element() < 1e-3);
    }

    #[test]
    fn singular_and_non_finite_transforms_are_refused() {
        let singular = Xform::new(Affine3A::from_scale(Vec3::new(1.0, 0.0, 1.0))).unwrap_err();
        assert_eq!(singular, XformError::Singular { determinant: 0.0 });
        assert_eq!(
            singular.to_string(),
            "the transform is singular or nearly so (determinant 0e0)"
        );
        assert!(matches!(
            Xform::new(Affine3A::from_scale(Vec3::new(1.0, 1e-9, 1.0))),
            Err(XformError::Singular { .. })
        ));
        let nan = Xform::new(Affine3A::from_translation(Vec3::new(f32::NAN, 0.0, 0.0)));
        assert_eq!(
            nan.unwrap_err().to_string(),
            "the transform has a non-finite entry"
        );
        assert!(Xform::new(Affine3A::IDENTITY).is_ok());
    }

    #[test]
    fn bounds_contain_transformed_corners() {
        let x = xf();
        let b = Aabb::from_points(Vec3::splat(-1.0), Vec3::splat(1.0));
        let w = x.bounds_to_world(&b);
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            assert!(w.contains(x.to_world.transform_point3(c)));
        }
    }

    #[test]
    fn similarity_detection() {
        let r = DAffine3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        assert_eq!(similarity_scale(&r).map(|s| (s * 1e9).round()), Some(1e9));
        let s = DAffine3::from_translation(DVec3::X) * DAffine3::from_scale(DVec3::splat(-2.5)) * r;
        assert!((similarity_scale(&s).unwrap() - 2.5).abs() < 1e-12);
        let ns = DAffine3::from_scale(DVec3::new(1.0, 2.0, 1.0)) * r;
        assert_eq!(similarity_scale(&ns), None);
        let shear = DAffine3::from_mat3(DMat3::from_cols(
            DVec3::X,
            DVec3::new(0.1, 1.0, 0.0),
            DVec3::Z,
        ));
        assert_eq!(similarity_scale(&shear), None);
    }
}
