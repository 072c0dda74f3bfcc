//! Oriented boxes ([`OBox`]), closed solids: the ray is taken into the box's own frame
//! (a rotation, so `t` is unchanged) and meets `[−h, h]` by the slab test of
//! [`aabox`](super::aabox).

use super::aabox::{EDGE_MARGIN, End, clamp_inside, face_uv, pick, slab};
use super::param::box_param;
use super::tessellate::{Tessellation, boxed};
use super::{Intersect, Param, Primitive, Shape, ShapeError, ShapeHit, Span, Spans, SurfacePoint};
use crate::math::{Aabb, Ray, Vec3, gamma, similarity_scale};
use glam::{DAffine3, DMat3, DQuat, Mat3, Quat};
use std::sync::Arc;

/// An oriented box: centre, half extents along its own three axes, and the rotation
/// taking the world axes to the box's (its axes are the columns of
/// `Mat3::from_quat(rotation)`). A closed solid.
///
/// The rotation is a unit quaternion, normalised by the constructor; [`OBox::from_axes`]
/// builds it from three orthonormal axes instead. `u`, `v` of a hit are face-local
/// coordinates in `[0, 1]` as for [`AaBox`](super::AaBox), in the box's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OBox {
    center: Vec3,
    half: Vec3,
    /// The unit quaternion as `[x, y, z, w]`: a plain array keeps the type at 40 bytes
    /// (a `Quat` is 16-byte aligned).
    rotation: [f32; 4],
}

impl OBox {
    /// The box with centre `center`, half extents `half_extents` (all positive) along the
    /// box's axes, and orientation `rotation` (any nonzero length; normalised).
    ///
    /// # Errors
    /// When a number is not finite, a half extent is not positive, or the quaternion is
    /// zero.
    pub fn new(center: Vec3, half_extents: Vec3, rotation: Quat) -> Result<Self, ShapeError> {
        if !center.is_finite() {
            return Err(ShapeError::parameter_not_finite(
                "oriented box",
                "centre",
                center,
            ));
        }
        if !half_extents.is_finite() || !half_extents.cmpgt(Vec3::ZERO).all() {
            return Err(ShapeError::parameter_not_positive(
                "oriented box",
                "half extents",
                half_extents,
            ));
        }
        if !rotation.is_finite() {
            return Err(ShapeError::parameter_not_finite(
                "oriented box",
                "rotation",
                rotation,
            ));
        }
        let q = rotation.as_dquat();
        let len = q.length();
        if !(len.is_finite() && len > 0.0) {
            return Err(ShapeError::ZeroRotation(rotation));
        }
        let rotation = (q / len).as_quat();
        let b = OBox {
            center,
            half: half_extents,
            rotation: rotation.to_array(),
        };
        if !b.bounds().is_finite() {
            return Err(ShapeError::OBoxOverflow {
                center,
                half_extents,
            });
        }
        Ok(b)
    }

    /// The box whose axes are the three orthonormal vectors `axes` (to within 1e-4: they
    /// are re-orthonormalised), with half extent `half_extents[i]` along `axes[i]`. A
    /// left-handed triple describes the same box: its third axis is flipped.
    ///
    /// # Errors
    /// As [`OBox::new`], and when the axes are not orthonormal.
    pub fn from_axes(
        center: Vec3,
        half_extents: Vec3,
        axes: [Vec3; 3],
    ) -> Result<Self, ShapeError> {
        let a = axes.map(|v| v.as_dvec3());
        if !a.iter().all(|v| v.is_finite()) {
            return Err(ShapeError::AxesNotFinite(axes));
        }
        let ortho = (0..3)
            .all(|i| (a[i].length() - 1.0).abs() < 1e-4 && a[i].dot(a[(i + 1) % 3]).abs() < 1e-4);
        if !ortho {
            return Err(ShapeError::AxesNotOrthonormal(axes));
        }
        // Gram–Schmidt in f64, then a right-handed third axis.
        let x = a[0].normalize();
        let y = (a[1] - x * x.dot(a[1])).normalize();
        let z = x.cross(y);
        let q = DQuat::from_mat3(&DMat3::from_cols(x, y, z));
        OBox::new(center, half_extents, q.as_quat())
    }

    /// Centre.
    pub fn center(&self) -> Vec3 {
        self.center
    }

    /// Half extents along the box's axes.
    pub fn half_extents(&self) -> Vec3 {
        self.half
    }

    /// The unit rotation quaternion.
    pub fn rotation(&self) -> Quat {
        Quat::from_array(self.rotation)
    }

    /// The box's axes (the columns of the rotation matrix the intersector uses).
    pub fn axes(&self) -> [Vec3; 3] {
        let m = self.matrix();
        [m.x_axis, m.y_axis, m.z_axis]
    }

    /// The rotation matrix (columns: the box's axes in world space).
    #[inline]
    fn matrix(&self) -> Mat3 {
        Mat3::from_quat(Quat::from_array(self.rotation))
    }

    /// World vector `v` in the box's frame (`Rᵀ v`).
    #[inline]
    fn to_local(m: &Mat3, v: Vec3) -> Vec3 {
        Vec3::new(m.x_axis.dot(v), m.y_axis.dot(v), m.z_axis.dot(v))
    }

    #[inline]
    fn ends(&self, ray: &Ray) -> Option<(Mat3, End, End)> {
        if !ray.org.is_finite() || !ray.dir.is_finite() {
            return None;
        }
        let m = self.matrix();
        let o = Self::to_local(&m, ray.org - self.center);
        let d = Self::to_local(&m, ray.dir);
        let (a, b) = slab(o, d, -self.half, self.half)?;
        Some((m, a, b))
    }
}

impl Intersect for OBox {
    fn bounds(&self) -> Aabb {
        let m = self.matrix();
        // Half extent along world axis k: Σ_i |R_ki| h_i.
        let ext = m.x_axis.abs() * self.half.x
            + m.y_axis.abs() * self.half.y
            + m.z_axis.abs() * self.half.z;
        let ext = ext * (1.0 + gamma(4)) + self.center.abs() * gamma(2);
        Aabb {
            min: self.center - ext,
            max: self.center + ext,
        }
    }

    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let (m, a, b) = self.ends(ray)?;
        let e = pick(ray, (a, b))?;
        let local = Self::to_local(&m, ray.at(e.t) - self.center);
        let (u, v) = face_uv(local, -self.half, self.half, e.axis);
        Some(ShapeHit {
            t: e.t,
            u,
            v,
            ng: m.col(e.axis) * e.sign,
        })
    }

    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        self.ends(ray)
            .and_then(|(_, a, b)| pick(ray, (a, b)))
            .is_some()
    }

    /// In double precision: the hit point taken into the box's frame, snapped onto the
    /// face of `ng` (the box axis closest to it) and clamped into the face away from its
    /// edges, then back to world space. `err` bounds the final rounding and what a
    /// spawned ray's f32 transform into the box's frame can see.
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        let m = self.matrix();
        let md = m.as_dmat3();
        let c = self.center.as_dvec3();
        let nl = Self::to_local(&m, hit.ng);
        let i = nl.abs().max_position();
        let top = nl[i] > 0.0;
        let h = self.half.as_dvec3();
        let mut y = md.transpose() * (ray.at(hit.t).as_dvec3() - c);
        y[i] = if top { h[i] } else { -h[i] };
        let p = (c + md * y).as_vec3();
        // What the intersector's `Rᵀ (o − c)` and the rotation's rounding can hide.
        let e = gamma(8) as f64 * (y.abs().element_sum() + h.element_sum());
        let err = Vec3::splat(e as f32) + p.abs() * gamma(2);
        let margin = EDGE_MARGIN * err.max_element() as f64;
        for j in [(i + 1) % 3, (i + 2) % 3] {
            y[j] = clamp_inside(y[j], -h[j], h[j], margin);
        }
        let p = (c + md * y).as_vec3();
        let sign = if top { 1.0 } else { -1.0 };
        SurfacePoint {
            p,
            err: Vec3::splat(e as f32) + p.abs() * gamma(2),
            ng: (md.col(i) * sign).normalize().as_vec3(),
        }
    }
}

impl Primitive for OBox {
    fn is_solid(&self) -> bool {
        true
    }

    fn spans(&self, ray: &Ray, out: &mut Spans) {
        if let Some((m, a, b)) = self.ends(ray) {
            out.push(Span {
                t_in: a.t,
                n_in: m.col(a.axis) * a.sign,
                t_out: b.t,
                n_out: m.col(b.axis) * b.sign,
            });
        }
    }

    fn contains(&self, p: Vec3) -> bool {
        let y = Self::to_local(&self.matrix(), p - self.center);
        y.abs().cmple(self.half).all()
    }

    fn param(&self, p: Vec3, ng: Vec3) -> Param {
        box_param(p, ng, self.center(), self.half_extents(), self.axes())
    }

    /// Under a similarity: the centre moved, the axes turned, the half extents scaled.
    fn bake(&self, m: &DAffine3) -> Option<Shape> {
        let k = similarity_scale(m)?;
        let axes = self.axes().map(|a| ((m.matrix3 * a.as_dvec3()) / k).as_vec3());
        OBox::from_axes(
            m.transform_point3(self.center().as_dvec3()).as_vec3(),
            (self.half_extents().as_dvec3() * k).as_vec3(),
            axes,
        )
        .ok()
        .map(|b| Arc::new(b).into())
    }

    /// Its six faces, exact.
    fn tessellate(&self, _patch: f32) -> Option<Tessellation> {
        Some(boxed(self.center(), self.half_extents(), self.axes()))
    }
}
