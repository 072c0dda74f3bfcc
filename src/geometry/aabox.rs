//! Axis-aligned boxes ([`AaBox`]), closed solids, and the slab test they share with
//! the oriented boxes of [`obox`](super::obox).
//!
//! The slab test (Kay and Kajiya): the line's entry is the latest of the three
//! slabs' near distances and its exit the earliest of their far distances, and the slab
//! that decides an end gives its normal. A ray parallel to a slab is inside it for every
//! `t` or for none, decided by its origin, so no `0 · ∞` ever forms. The distances are
//! divided, not multiplied by a reciprocal, so each is correctly rounded from the
//! (exact, for a nearby origin) difference of coordinates.

use super::param::box_param;
use super::tessellate::{Tessellation, boxed};
use super::{Intersect, Param, Primitive, Shape, ShapeError, ShapeHit, Span, Spans, SurfacePoint};
use crate::math::{Aabb, Ray, Vec3, gamma};
use glam::DAffine3;

/// One end of a line's stretch through a box: its parameter, the axis whose slab decided
/// it and the sign of the outward normal along that axis.
#[derive(Clone, Copy, Debug)]
pub(super) struct End {
    pub(super) t: f32,
    pub(super) axis: usize,
    pub(super) sign: f32,
}

/// The stretch of the line `org + t·dir`, `t ∈ (−∞, ∞)`, inside the closed box
/// `[lo, hi]`, or `None`. Inputs must be finite.
#[inline]
pub(super) fn slab(org: Vec3, dir: Vec3, lo: Vec3, hi: Vec3) -> Option<(End, End)> {
    let mut t_in = f32::NEG_INFINITY;
    let mut t_out = f32::INFINITY;
    let (mut a_in, mut a_out) = (3, 3);
    let (mut s_in, mut s_out) = (0.0f32, 0.0f32);
    for i in 0..3 {
        let (o, d) = (org[i], dir[i]);
        if d == 0.0 {
            // Parallel: the origin decides for the whole line (the slab is closed).
            if !(o >= lo[i] && o <= hi[i]) {
                return None;
            }
            continue;
        }
        let ta = (lo[i] - o) / d;
        let tb = (hi[i] - o) / d;
        // Moving up the axis the line enters through `lo` (normal −e_i) and leaves
        // through `hi` (+e_i); moving down, the other way round.
        let (near, far, sign) = if d > 0.0 {
            (ta, tb, 1.0)
        } else {
            (tb, ta, -1.0)
        };
        if near > t_in {
            t_in = near;
            a_in = i;
            s_in = -sign;
        }
        if far < t_out {
            t_out = far;
            a_out = i;
            s_out = sign;
        }
    }
    // `a_in == 3` only for a zero direction (or distances overflowing to −∞).
    if a_in < 3 && a_out < 3 && t_in <= t_out {
        Some((
            End {
                t: t_in,
                axis: a_in,
                sign: s_in,
            },
            End {
                t: t_out,
                axis: a_out,
                sign: s_out,
            },
        ))
    } else {
        None
    }
}

/// The end to report for a ray: the entry if it lies in `(tmin, tmax)`, else the exit.
#[inline]
pub(super) fn pick(ray: &Ray, (a, b): (End, End)) -> Option<End> {
    if a.t > ray.tmin && a.t < ray.tmax {
        Some(a)
    } else if b.t > ray.tmin && b.t < ray.tmax {
        Some(b)
    } else {
        None
    }
}

/// `x` moved into `[lo + m, hi − m]`, or the middle of `[lo, hi]` when that is narrower
/// than `2m`. Never panics, whatever the inputs.
#[inline]
pub(super) fn clamp_inside(x: f64, lo: f64, hi: f64, m: f64) -> f64 {
    if hi - lo > 2.0 * m {
        x.max(lo + m).min(hi - m)
    } else {
        0.5 * (lo + hi)
    }
}

/// Face-local coordinates in `[0, 1]` of point `p` on the face normal to `axis` of the
/// box `[lo, hi]`: along the next axis and the one after (cyclically).
#[inline]
pub(super) fn face_uv(p: Vec3, lo: Vec3, hi: Vec3, axis: usize) -> (f32, f32) {
    let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
    let u = (p[j] - lo[j]) / (hi[j] - lo[j]);
    let v = (p[k] - lo[k]) / (hi[k] - lo[k]);
    (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0))
}

/// The unit vector along `axis` with sign `sign`.
#[inline]
fn axis_vec(axis: usize, sign: f32) -> Vec3 {
    let mut n = Vec3::ZERO;
    n[axis] = sign;
    n
}

/// Relative margin (in units of the point's error bound) by which a surface point is
/// kept away from its face's edges: a ray spawned from it, offset along this face's
/// normal, must still be seen inside the neighbouring faces' slabs.
pub(super) const EDGE_MARGIN: f64 = 4.0;

/// An axis-aligned box `[min, max]`: a closed solid.
///
/// `u`, `v` of a hit are its face-local coordinates in `[0, 1]`, along the two other
/// axes in cyclic order (face normal to x: y then z; to y: z then x; to z: x then y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AaBox {
    min: Vec3,
    max: Vec3,
}

impl AaBox {
    /// The box between corners `min` and `max`.
    ///
    /// # Errors
    /// When a coordinate is not finite or `min` is not below `max` on every axis.
    pub fn new(min: Vec3, max: Vec3) -> Result<Self, ShapeError> {
        if !min.is_finite() || !max.is_finite() {
            return Err(ShapeError::BoxNotFinite { min, max });
        }
        if !min.cmplt(max).all() {
            return Err(ShapeError::BoxNotBelow { min, max });
        }
        Ok(AaBox { min, max })
    }

    /// Lower corner.
    pub fn min(&self) -> Vec3 {
        self.min
    }

    /// Upper corner.
    pub fn max(&self) -> Vec3 {
        self.max
    }

    #[inline]
    fn ends(&self, ray: &Ray) -> Option<(End, End)> {
        if !ray.org.is_finite() || !ray.dir.is_finite() {
            return None;
        }
        slab(ray.org, ray.dir, self.min, self.max)
    }
}

impl Intersect for AaBox {
    /// Exact: the box itself (its corners are f32 values).
    fn bounds(&self) -> Aabb {
        Aabb {
            min: self.min,
            max: self.max,
        }
    }

    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let e = pick(ray, self.ends(ray)?)?;
        let (u, v) = face_uv(ray.at(e.t), self.min, self.max, e.axis);
        Some(ShapeHit {
            t: e.t,
            u,
            v,
            ng: axis_vec(e.axis, e.sign),
        })
    }

    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        self.ends(ray).and_then(|e| pick(ray, e)).is_some()
    }

    /// The hit point snapped onto the face plane (the axis of `ng`'s largest component)
    /// and clamped into the face, a few ulps away from its edges. The point is then on
    /// the box exactly; `err` is an ulp-level bound that also covers what a spawned ray's
    /// slab test sees.
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        let i = hit.ng.abs().max_position();
        let top = hit.ng[i] > 0.0;
        let mut p = ray.at(hit.t);
        p[i] = if top { self.max[i] } else { self.min[i] };
        let err = p.abs() * gamma(2);
        let m = EDGE_MARGIN * err.max_element() as f64;
        for j in [(i + 1) % 3, (i + 2) % 3] {
            p[j] = clamp_inside(p[j] as f64, self.min[j] as f64, self.max[j] as f64, m) as f32;
        }
        SurfacePoint {
            p,
            err: p.abs() * gamma(2),
            ng: axis_vec(i, if top { 1.0 } else { -1.0 }),
        }
    }
}

impl Primitive for AaBox {
    fn is_solid(&self) -> bool {
        true
    }

    fn spans(&self, ray: &Ray, out: &mut Spans) {
        if let Some((a, b)) = self.ends(ray) {
            out.push(Span {
                t_in: a.t,
                n_in: axis_vec(a.axis, a.sign),
                t_out: b.t,
                n_out: axis_vec(b.axis, b.sign),
            });
        }
    }

    fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    fn param(&self, p: Vec3, ng: Vec3) -> Param {
        let (min, max) = (self.min(), self.max());
        box_param(
            p,
            ng,
            (min + max) * 0.5,
            (max - min) * 0.5,
            [Vec3::X, Vec3::Y, Vec3::Z],
        )
    }

    /// Axis-aligned stays axis-aligned under a diagonal linear part.
    fn bake(&self, m: &DAffine3) -> Option<Shape> {
        let l = m.matrix3;
        let diagonal = l.x_axis.y == 0.0
            && l.x_axis.z == 0.0
            && l.y_axis.x == 0.0
            && l.y_axis.z == 0.0
            && l.z_axis.x == 0.0
            && l.z_axis.y == 0.0;
        if !diagonal {
            return None;
        }
        let a = m.transform_point3(self.min().as_dvec3());
        let c = m.transform_point3(self.max().as_dvec3());
        AaBox::new(a.min(c).as_vec3(), a.max(c).as_vec3())
            .ok()
            .map(Shape::from)
    }

    /// Its six faces, exact.
    fn tessellate(&self, _patch: f32) -> Option<Tessellation> {
        Some(boxed(
            (self.min() + self.max()) * 0.5,
            (self.max() - self.min()) * 0.5,
            [Vec3::X, Vec3::Y, Vec3::Z],
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_handles_parallel_rays_and_origins_on_planes() {
        let (lo, hi) = (Vec3::ZERO, Vec3::ONE);
        // Parallel to x and y, inside both slabs: only z decides.
        let (a, b) = slab(Vec3::new(0.5, 0.5, -1.0), Vec3::Z, lo, hi).unwrap();
        assert_eq!(
            (a.t, a.axis, a.sign, b.t, b.axis, b.sign),
            (1.0, 2, -1.0, 2.0, 2, 1.0)
        );
        // Parallel, origin exactly on a slab plane: inside (closed slab), no NaN.
        let (a, b) = slab(Vec3::new(0.0, 0.5, -1.0), Vec3::Z, lo, hi).unwrap();
        assert_eq!((a.t, b.t), (1.0, 2.0));
        // Parallel and outside: no stretch at all.
        assert!(slab(Vec3::new(-0.1, 0.5, -1.0), Vec3::Z, lo, hi).is_none());
        // A zero direction has no stretch either (no slab decides).
        assert!(slab(Vec3::splat(0.5), Vec3::ZERO, lo, hi).is_none());
        // Moving down an axis: enters through the upper plane (normal +e).
        let (a, b) = slab(Vec3::new(0.5, 3.0, 0.5), -Vec3::Y * 2.0, lo, hi).unwrap();
        assert_eq!((a.t, a.axis, a.sign, b.t, b.sign), (1.0, 1, 1.0, 1.5, -1.0));
    }

    #[test]
    fn clamp_inside_keeps_a_margin_or_takes_the_middle() {
        assert_eq!(clamp_inside(-1.0, 0.0, 1.0, 0.1), 0.1);
        assert_eq!(clamp_inside(0.5, 0.0, 1.0, 0.1), 0.5);
        assert_eq!(clamp_inside(2.0, 0.0, 1.0, 0.1), 0.9);
        assert_eq!(clamp_inside(2.0, 0.0, 1.0, 0.6), 0.5);
        assert!(clamp_inside(f64::NAN, 0.0, 1.0, 0.1).is_finite());
    }
}
