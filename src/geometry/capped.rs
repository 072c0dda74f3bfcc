//! Closed cones, truncated cones and cylinders: a lateral surface and the two end
//! disks (an end of radius 0 is a point and has no disk).
//!
//! Intersection is the classic convex-solid method: the line's stretch inside the
//! infinite cone (one interval of its real nappe) intersected with the slab between the
//! two cap planes. The entry is the later of the two intervals' entries and the exit the
//! earlier exit, so a ray through the rim meets either the cap or the side and can never
//! slip between them.
//!
//! The lateral quadratic is the open [`super::Cone`]'s, with two changes. The ray is
//! re-based at its point nearest an anchor on the axis, so a thin cone seen from afar
//! keeps its discriminant; the anchor is the middle, as for the open cone, except near an
//! apex, which anchors pointed cones so that a line through the tip keeps its roots
//! accurate. And the discriminant is `|r₀ dp − k ds fp|² − |dp × fp|²` (Lagrange's
//! identity) rather than `b² − a c`, which cancels for lines near the axis or the apex.
//! `a → 0` (a ray along a cylinder's axis, or parallel to a cone's side) degenerates to a
//! linear or constant equation instead of dividing by zero.

use super::param::{axis_frame, cylindrical};
use super::tessellate::{Tessellation, revolution};
use super::{
    Intersect, Param, Primitive, Shape, ShapeError, ShapeHit, Span, Spans, SurfacePoint, diff_of_products,
    quadratic_roots,
};
use crate::math::{Aabb, DVec3, Frame, Ray, Vec3, gamma, similarity_scale};
use glam::{DAffine3, Vec2};
use std::sync::Arc;
use std::f32::consts::TAU;

/// Which part of the surface an end of the line's stretch lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Part {
    Side,
    Base,
    Top,
}

/// The line's stretch inside the solid: parameters, parts and outward normals.
#[derive(Clone, Copy, Debug)]
struct Stretch {
    t_in: f32,
    part_in: Part,
    n_in: Vec3,
    t_out: f32,
    part_out: Part,
    n_out: Vec3,
}

/// The lateral quadratic `a dt² + 2 b dt + c` (and its discriminant) for the ray
/// re-based at `org + t0·dir`, with the re-based origin's axial coordinate `fs` (from the
/// anchor) and perpendicular part `fp`, the direction's axial rate `ds` and perpendicular
/// part `dp`, and the radius there `r0`.
#[derive(Clone, Copy, Debug)]
struct Quadratic {
    a: f32,
    b: f32,
    c: f32,
    /// The discriminant `b² − a c`, computed without cancellation.
    disc: f32,
    /// Axial coordinate (from the base) of the point the ray is re-based at and its
    /// axial coordinates `fs` measured from.
    s_ref: f32,
    t0: f32,
    fs: f32,
    ds: f32,
    fp: Vec3,
    dp: Vec3,
    r0: f32,
}

/// Margin, in units of the point's error bound, by which `surface` keeps a point away
/// from the rims, so that a ray spawned from it is still seen inside the other part.
const RIM_MARGIN: f64 = 4.0;

/// The farthest `surface` moves a point along the surface off a rim, in units of its
/// error bound.
const MAX_SHIFT: f64 = 64.0;

/// A closed cone, truncated cone or cylinder: the solid between the base disk (centre
/// `base`, radius `base_radius`) and the top disk (centre `base + height·axis`, radius
/// `top_radius`), bounded by the lateral surface between their rims.
///
/// Hit parameters: `u` is the angle around the axis over 2π (from the x axis of
/// [`Frame::from_z`]`(axis)`), in `[0, 1]`; `v` is the height fraction on the side and
/// the radial fraction on a cap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CappedCone {
    base: Vec3,
    axis: Vec3,
    height: f32,
    base_radius: f32,
    top_radius: f32,
    /// Radius change per unit of height.
    slope: f32,
}

impl CappedCone {
    /// The solid with base centre `base_center`, axis direction `axis_dir` (any nonzero
    /// length; normalised), height `height` > 0 and end radii `base_radius`,
    /// `top_radius` ≥ 0, not both 0.
    ///
    /// # Errors
    /// When a number is not finite, the axis is zero, the height is not positive, a
    /// radius is negative, both radii are zero, or the cone is so flat that its slope
    /// overflows.
    pub fn new(
        base_center: Vec3,
        axis_dir: Vec3,
        height: f32,
        base_radius: f32,
        top_radius: f32,
    ) -> Result<Self, ShapeError> {
        Self::build(
            "capped cone",
            base_center,
            axis_dir,
            height,
            base_radius,
            top_radius,
        )
    }

    /// [`CappedCone::new`], with `shape` naming the shape in errors.
    fn build(
        shape: &'static str,
        base_center: Vec3,
        axis_dir: Vec3,
        height: f32,
        base_radius: f32,
        top_radius: f32,
    ) -> Result<Self, ShapeError> {
        if !base_center.is_finite() {
            return Err(ShapeError::parameter_not_finite(
                shape,
                "base centre",
                base_center,
            ));
        }
        if !axis_dir.is_finite() {
            return Err(ShapeError::parameter_not_finite(shape, "axis", axis_dir));
        }
        let a = axis_dir.as_dvec3();
        let len = a.length();
        if !(len.is_finite() && len > 0.0) {
            return Err(ShapeError::ZeroAxis { shape });
        }
        let axis = (a / len).as_vec3();
        if !(height > 0.0 && height.is_finite()) {
            return Err(ShapeError::parameter_not_positive(shape, "height", height));
        }
        for (end, radius) in [("base", base_radius), ("top", top_radius)] {
            if !(radius >= 0.0 && radius.is_finite()) {
                return Err(ShapeError::EndRadius { shape, end, radius });
            }
        }
        if base_radius == 0.0 && top_radius == 0.0 {
            return Err(ShapeError::NoRadius { shape });
        }
        let slope = ((top_radius as f64 - base_radius as f64) / height as f64) as f32;
        if !slope.is_finite() {
            return Err(ShapeError::TooFlat {
                shape,
                height,
                base_radius,
                top_radius,
            });
        }
        let c = CappedCone {
            base: base_center,
            axis,
            height,
            base_radius,
            top_radius,
            slope,
        };
        if !c.bounds().is_finite() {
            return Err(ShapeError::CappedOverflow {
                shape,
                base: base_center,
                height,
            });
        }
        Ok(c)
    }

    /// A closed cylinder of radius `radius` > 0.
    ///
    /// # Errors
    /// As [`CappedCone::new`], and for a radius that is not positive; the messages say
    /// "cylinder".
    pub fn cylinder(
        base_center: Vec3,
        axis_dir: Vec3,
        height: f32,
        radius: f32,
    ) -> Result<Self, ShapeError> {
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(ShapeError::parameter_not_positive(
                "cylinder", "radius", radius,
            ));
        }
        Self::build("cylinder", base_center, axis_dir, height, radius, radius)
    }

    /// Centre of the base disk.
    pub fn base(&self) -> Vec3 {
        self.base
    }

    /// Centre of the top disk.
    pub fn top(&self) -> Vec3 {
        self.base + self.axis * self.height
    }

    /// Unit axis from base to top.
    pub fn axis(&self) -> Vec3 {
        self.axis
    }

    /// Distance between the disks.
    pub fn height(&self) -> f32 {
        self.height
    }

    /// Radius of the base disk.
    pub fn base_radius(&self) -> f32 {
        self.base_radius
    }

    /// Radius of the top disk.
    pub fn top_radius(&self) -> f32 {
        self.top_radius
    }

    /// The point of the axis the quadratic is anchored at, as its axial coordinate from
    /// the base and the radius there: the apex when it is near the solid (the smaller
    /// radius at most a third of the larger), else the middle.
    ///
    /// For a line through (or near) an apex the two roots, one on each nappe, meet there.
    /// Anchored at the middle, the coefficients are as large as the cone and their
    /// rounding moves that double root by √ε of the cone's size, so the normal at the
    /// tip of a pointed cone is wrong. Anchored at the apex, the coefficients vanish with
    /// the line's distance to it and the roots keep their relative accuracy.
    #[inline]
    fn anchor(&self) -> (f32, f32) {
        let (rb, rt, h) = (self.base_radius, self.top_radius, self.height);
        if rt == 0.0 {
            (h, 0.0)
        } else if rb == 0.0 {
            (0.0, 0.0)
        } else if 3.0 * rb.min(rt) <= rb.max(rt) {
            let s = -rb / self.slope;
            (s, rb + self.slope * s)
        } else {
            (0.5 * h, 0.5 * (rb + rt))
        }
    }

    /// The lateral quadratic (as [`super::Cone`]'s, anchored at [`Self::anchor`]), or
    /// `None` for a zero direction.
    #[inline]
    fn quadratic(&self, ray: &Ray) -> Option<Quadratic> {
        let w = self.axis;
        let k = self.slope;
        let (s_ref, r_ref) = self.anchor();
        let anchor = self.base + w * s_ref;
        let dd = ray.dir.dot(ray.dir);
        if !(dd.is_finite() && dd > 0.0) {
            return None;
        }
        let t0 = (anchor - ray.org).dot(ray.dir) / dd;
        let org = ray.org + ray.dir * t0;
        let f = org - anchor;
        let fs = f.dot(w);
        let ds = ray.dir.dot(w);
        let fp = f - w * fs;
        let dp = ray.dir - w * ds;
        let r0 = r_ref + k * fs;
        let kds = k * ds;
        let dpl = dp.length();
        let a = diff_of_products(dpl, dpl, kds, kds);
        let b = dp.dot(fp) - kds * r0;
        let fpl = fp.length();
        let c = diff_of_products(fpl, fpl, r0, r0);
        // b² − a c = |r0 dp − k ds fp|² − |dp × fp|² (Lagrange's identity). For a line
        // along a cylinder's axis or through a cone's apex, b² and a c agree in all their
        // digits and their difference is rounding; this form has no such pair (it is the
        // cone's analogue of the sphere's r² − l²: for a cylinder, |dp|² (r² − l²) with
        // l the line's distance from the axis).
        let ul = (dp * r0 - fp * kds).length();
        let vl = dp.cross(fp).length();
        let disc = diff_of_products(ul, ul, vl, vl);
        Some(Quadratic {
            a,
            b,
            c,
            disc,
            s_ref,
            t0,
            fs,
            ds,
            fp,
            dp,
            r0,
        })
    }

    /// The stretch `[lo, hi]` (re-based parameters, possibly infinite) of the line inside
    /// the real nappe of the infinite cone (the one holding the solid), or `None`.
    #[inline]
    fn lateral(&self, q: &Quadratic) -> Option<(f32, f32)> {
        let (a, b, c, disc) = (q.a, q.b, q.c, q.disc);
        let inf = f32::INFINITY;
        if a == 0.0 {
            // Along a cylinder's axis or parallel to a cone's side: linear or constant.
            return if b == 0.0 {
                (c <= 0.0).then_some((-inf, inf))
            } else {
                let root = -c / (2.0 * b);
                Some(if b > 0.0 { (-inf, root) } else { (root, inf) })
            };
        }
        // The roots labelled by the sign of F' (see `quadratic_roots`); a NaN only when
        // the two coincide with b = 0 (then both are −b/a = 0).
        let roots = |disc: f32| {
            let (e, x) = quadratic_roots(a, b, c, disc);
            let e = if e.is_nan() { x } else { e };
            let x = if x.is_nan() { e } else { x };
            (e, x)
        };
        if a > 0.0 {
            // Shallower than the cone's sides: one bounded stretch (in one nappe or the
            // other; the slab test discards the other).
            if disc.is_nan() || disc < 0.0 {
                return None;
            }
            let (e, x) = roots(disc);
            (!e.is_nan()).then_some((e, x))
        } else {
            // Steeper than the sides: the line is inside both nappes outside the roots,
            // a half-line in each. The solid's nappe is where the radius grows along the
            // line: towards +∞ when k·ds > 0. (A negative discriminant is rounding for a
            // line through the apex.)
            let (e, x) = roots(disc.max(0.0));
            if e.is_nan() {
                return None;
            }
            Some(if self.slope * q.ds > 0.0 {
                (e, inf)
            } else {
                (-inf, x)
            })
        }
    }

    /// Outward normal of the lateral surface at re-based parameter `dt`, from the
    /// re-based quantities (no cancellation against the ray's distance); the end's axis
    /// direction at an apex, where the gradient vanishes.
    #[inline]
    fn side_normal(&self, q: &Quadratic, dt: f32) -> Vec3 {
        let w = self.axis;
        let k = self.slope;
        let qp = q.fp + q.dp * dt;
        let r = q.r0 + k * q.ds * dt;
        let n = qp - w * (k * r);
        // Rounding of the terms (a few ulps of each). At the apex of a pointed end the
        // gradient vanishes: a radius within rounding of zero or below it (a root just
        // past the apex, on the other nappe), or a gradient within rounding of zero, has
        // no reliable direction, and the apex's axis direction is an outward normal
        // there.
        let noise_r = gamma(8) * (q.r0.abs() + (k * q.ds * dt).abs());
        // (fp and dp are differences of vectors as long as f and dir.)
        let noise_q =
            gamma(8) * (q.fs.abs() + q.fp.length() + (q.ds.abs() + q.dp.length()) * dt.abs());
        if n.is_finite() && r > noise_r && n.length() > noise_q + k.abs() * noise_r {
            n
        } else if q.s_ref + q.fs + q.ds * dt > 0.5 * self.height {
            w
        } else {
            -w
        }
    }

    /// The line's stretch inside the solid, or `None`.
    #[inline]
    fn stretch(&self, ray: &Ray) -> Option<Stretch> {
        if !ray.org.is_finite() || !ray.dir.is_finite() {
            return None;
        }
        let q = self.quadratic(ray)?;
        if !(q.a.is_finite() && q.b.is_finite() && q.c.is_finite() && q.disc.is_finite()) {
            return None;
        }
        let (lo, hi) = self.lateral(&q)?;
        // The slab between the cap planes, at axial coordinates p0 and p1 from the anchor
        // (exactly 0 for the plane through an apex).
        let (p0, p1) = (-q.s_ref, self.height - q.s_ref);
        let inf = f32::INFINITY;
        let (s_lo, s_hi, down) = if q.ds > 0.0 {
            ((p0 - q.fs) / q.ds, (p1 - q.fs) / q.ds, false)
        } else if q.ds < 0.0 {
            ((p1 - q.fs) / q.ds, (p0 - q.fs) / q.ds, true)
        } else if q.fs >= p0 && q.fs <= p1 {
            (-inf, inf, false)
        } else {
            return None;
        };
        let w = self.axis;
        let (first_cap, last_cap) = if down {
            ((Part::Top, w), (Part::Base, -w))
        } else {
            ((Part::Base, -w), (Part::Top, w))
        };
        let (dt_in, part_in, n_in) = if s_lo > lo {
            (s_lo, first_cap.0, first_cap.1)
        } else {
            (lo, Part::Side, self.side_normal(&q, lo))
        };
        let (dt_out, part_out, n_out) = if s_hi < hi {
            (s_hi, last_cap.0, last_cap.1)
        } else {
            (hi, Part::Side, self.side_normal(&q, hi))
        };
        if !(dt_in <= dt_out && dt_in.is_finite() && dt_out.is_finite()) {
            return None;
        }
        Some(Stretch {
            t_in: q.t0 + dt_in,
            part_in,
            n_in,
            t_out: q.t0 + dt_out,
            part_out,
            n_out,
        })
    }

    /// `u`, `v` of point `p` on `part`.
    fn uv(&self, p: Vec3, part: Part) -> (f32, f32) {
        let q = p - self.base;
        let s = q.dot(self.axis);
        let f = Frame::from_z(self.axis);
        let (x, y) = (q.dot(f.x), q.dot(f.y));
        let mut u = y.atan2(x) / TAU;
        if u < 0.0 {
            u += 1.0;
        }
        let rho = (x * x + y * y).sqrt();
        let v = match part {
            Part::Side => s / self.height,
            Part::Base if self.base_radius > 0.0 => rho / self.base_radius,
            Part::Top if self.top_radius > 0.0 => rho / self.top_radius,
            _ => 0.0,
        };
        (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0))
    }

    /// The part a hit with normal `ng` at the point with axial coordinate `s` and
    /// distance `rho` from the axis lies on. The caps' normals are ±axis and the side's
    /// make a fixed angle with it; only for cones so flat that the two cannot be told
    /// apart (or a zero normal) the nearest part to the point decides.
    fn part_of(&self, ng: Vec3, s: f64, rho: f64) -> Part {
        let n = ng.as_dvec3();
        let w = self.axis.as_dvec3().normalize();
        let k = self.slope as f64;
        let nn = n.length();
        let nw = n.dot(w);
        let perp = (n - w * nw).length();
        // |n⊥| / |n| of a side normal.
        let side = 1.0 / (1.0 + k * k).sqrt();
        if nn > 0.0 && nn.is_finite() {
            let ratio = perp / (nn * side);
            if ratio > 0.5 {
                return Part::Side;
            }
            if ratio < 1e-2 && side > 1e-4 {
                return if nw > 0.0 { Part::Top } else { Part::Base };
            }
        }
        // Distances in the meridian half-plane (s, ρ) to the three generating segments.
        let h = self.height as f64;
        let (rb, rt) = (self.base_radius as f64, self.top_radius as f64);
        let seg = |a: (f64, f64), b: (f64, f64)| {
            let (ex, ey) = (b.0 - a.0, b.1 - a.1);
            let l2 = ex * ex + ey * ey;
            let t = if l2 > 0.0 {
                (((s - a.0) * ex + (rho - a.1) * ey) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let (dx, dy) = (s - a.0 - t * ex, rho - a.1 - t * ey);
            dx * dx + dy * dy
        };
        let d_side = seg((0.0, rb), (h, rt));
        let d_base = if rb > 0.0 {
            seg((0.0, 0.0), (0.0, rb))
        } else {
            f64::INFINITY
        };
        let d_top = if rt > 0.0 {
            seg((h, 0.0), (h, rt))
        } else {
            f64::INFINITY
        };
        if d_side <= d_base && d_side <= d_top {
            Part::Side
        } else if d_base <= d_top {
            Part::Base
        } else {
            Part::Top
        }
    }

    /// Bound of the position error of a point whose offset from the base is `q`: what
    /// the intersector's re-based quadratic and slab test cannot resolve, which a spawned
    /// ray's offset must exceed.
    fn err_scale(&self, q: DVec3) -> f64 {
        let size = (self.height + self.base_radius.max(self.top_radius)) as f64;
        gamma(16) as f64 * (size + q.abs().max_element())
    }
}

impl Intersect for CappedCone {
    /// Bounds of the two end disks, widened by a few ulps.
    fn bounds(&self) -> Aabb {
        let w = self.axis;
        // Half-extent of a disk of radius r with normal w along axis i: r·√(1 − w_i²).
        let k = (Vec3::ONE - w * w).max(Vec3::ZERO);
        let k = Vec3::new(k.x.sqrt(), k.y.sqrt(), k.z.sqrt());
        let (b, t) = (self.base, self.top());
        let eb = k * self.base_radius;
        let et = k * self.top_radius;
        let bb = Aabb::from_points(b - eb, b + eb).union(&Aabb::from_points(t - et, t + et));
        let slack = (bb.min.abs().max(bb.max.abs())
            + Vec3::splat(self.base_radius.max(self.top_radius) + self.height))
            * gamma(4);
        Aabb {
            min: bb.min - slack,
            max: bb.max + slack,
        }
    }

    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let s = self.stretch(ray)?;
        let (t, part, ng) = if s.t_in > ray.tmin && s.t_in < ray.tmax {
            (s.t_in, s.part_in, s.n_in)
        } else if s.t_out > ray.tmin && s.t_out < ray.tmax {
            (s.t_out, s.part_out, s.n_out)
        } else {
            return None;
        };
        let (u, v) = self.uv(ray.at(t), part);
        Some(ShapeHit { t, u, v, ng })
    }

    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        self.stretch(ray).is_some_and(|s| {
            (s.t_in > ray.tmin && s.t_in < ray.tmax) || (s.t_out > ray.tmin && s.t_out < ray.tmax)
        })
    }

    /// In double precision: the part is told from `ng` (or, for ultra-flat cones, from
    /// the point), then the point `o + t·d` is projected orthogonally onto it (onto the
    /// cone's generator in the meridian half-plane, or onto the cap's plane) and kept a
    /// few error bounds inside the part's rims.
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        let base = self.base.as_dvec3();
        let w = self.axis.as_dvec3().normalize();
        let h = self.height as f64;
        let (rb, rt) = (self.base_radius as f64, self.top_radius as f64);
        let k = (rt - rb) / h;
        let q = ray.at(hit.t).as_dvec3() - base;
        let s = q.dot(w);
        let qp = q - w * s;
        let rho = qp.length();
        let radial = if rho > 0.0 && rho.is_finite() {
            qp / rho
        } else {
            Frame::from_z(self.axis).x.as_dvec3()
        };
        let part = self.part_of(hit.ng, s, rho);
        // The point's error bound (as `err` below); a spawned ray starts about that far
        // off the surface and the intersector cannot resolve much less.
        let e_max = self.err_scale(q) + gamma(2) as f64 * (base + q).abs().max_element();
        let noise = RIM_MARGIN * e_max;
        let offset = 2.0 * e_max;
        let sq = (1.0 + k * k).sqrt();
        // How far along the surface a point may be moved off a rim: enough for ordinary
        // rims; a knife edge (side and cap meeting at a few degrees) would need more and
        // gets only this much, so as not to move the point visibly.
        let max_shift = MAX_SHIFT * e_max;
        let (s1, rho1, n) = match part {
            Part::Side => {
                // Foot of the perpendicular onto the line ρ = rb + k s.
                let delta = (rho - rb - k * s) / (1.0 + k * k);
                // Moving inwards off the side by `offset` changes s by offset·k/√(1+k²):
                // keep that much more from the cap plane it moves towards.
                let towards = offset * k.abs() / sq;
                let lo = (noise + if k < 0.0 { towards } else { 0.0 }).min(max_shift / sq);
                let hi = (noise + if k > 0.0 { towards } else { 0.0 }).min(max_shift / sq);
                let s1 = if h > lo + hi {
                    (s + k * delta).max(lo).min(h - hi)
                } else {
                    0.5 * h
                };
                (s1, rb + k * s1, radial - w * k)
            }
            Part::Base | Part::Top => {
                let (s1, r, n) = if part == Part::Base {
                    (0.0, rb, -w)
                } else {
                    (h, rt, w)
                };
                // Moving inwards off the cap by `offset` shrinks the radius by |k|·offset
                // when the cone narrows away from this cap.
                let narrows = (part == Part::Base) == (k < 0.0);
                let m = (noise + if narrows { offset * k.abs() } else { 0.0 }).min(max_shift);
                (s1, rho.min((r - m).max(0.5 * r)), n)
            }
        };
        let local = w * s1 + radial * rho1;
        let p = (base + local).as_vec3();
        let ng = n
            .normalize_or(-ray.dir.as_dvec3().normalize_or(w))
            .as_vec3();
        SurfacePoint {
            p,
            err: Vec3::splat(self.err_scale(local) as f32) + p.abs() * gamma(2),
            ng,
        }
    }
}

impl CappedCone {
    /// Whether both ends have the same radius: a (closed) cylinder.
    pub fn is_cylinder(&self) -> bool {
        self.base_radius == self.top_radius
    }
}

impl Primitive for CappedCone {
    fn is_solid(&self) -> bool {
        true
    }

    fn spans(&self, ray: &Ray, out: &mut Spans) {
        if let Some(s) = self.stretch(ray) {
            out.push(Span {
                t_in: s.t_in,
                n_in: s.n_in,
                t_out: s.t_out,
                n_out: s.n_out,
            });
        }
    }

    fn contains(&self, p: Vec3) -> bool {
        let q = p - self.base;
        let s = q.dot(self.axis);
        if !(s >= 0.0 && s <= self.height) {
            return false;
        }
        let r = self.base_radius + self.slope * s;
        (q - self.axis * s).length_squared() <= r * r
    }

    /// The cylindrical parameterisation on the side, a disk onto `[0, 1]²` on the caps
    /// (`ng` the unit outward normal tells them apart).
    fn param(&self, p: Vec3, ng: Vec3) -> Param {
        let axis = self.axis();
        let h = (p - self.base()).dot(axis);
        let on_cap = ng.dot(axis).abs() > 0.999
            && (h.abs() < 1e-3 * self.height() || (h - self.height()).abs() < 1e-3 * self.height());
        if !on_cap {
            let slope = (self.top_radius() - self.base_radius()) / self.height();
            return cylindrical(p, self.base(), axis, self.height(), slope);
        }
        let (e1, e2) = axis_frame(axis);
        let top = h > 0.5 * self.height();
        let (centre, r) = if top {
            (self.top(), self.top_radius())
        } else {
            (self.base(), self.base_radius())
        };
        let r = r.max(f32::MIN_POSITIVE);
        let q = p - centre;
        // The base cap faces −axis: mirror u there so that ∂p/∂u × ∂p/∂v = −axis.
        let su = if top { 1.0 } else { -1.0 };
        Param {
            uv: Vec2::new(
                0.5 + su * q.dot(e1) / (2.0 * r),
                0.5 + q.dot(e2) / (2.0 * r),
            ),
            dpdu: e1 * (su * 2.0 * r),
            dpdv: e2 * (2.0 * r),
        }
    }

    /// Under a similarity: the base moved, the axis turned, the lengths scaled.
    fn bake(&self, m: &DAffine3) -> Option<Shape> {
        let k = similarity_scale(m)?;
        CappedCone::new(
            m.transform_point3(self.base().as_dvec3()).as_vec3(),
            (m.matrix3 * self.axis().as_dvec3()).as_vec3(),
            (self.height() as f64 * k) as f32,
            (self.base_radius() as f64 * k) as f32,
            (self.top_radius() as f64 * k) as f32,
        )
        .ok()
        .map(|c| Arc::new(c).into())
    }

    /// The side on an angle × height grid, and the two caps.
    fn tessellate(&self, patch: f32) -> Option<Tessellation> {
        Some(revolution(
            self.base(),
            self.axis(),
            self.height(),
            (self.base_radius(), self.top_radius()),
            patch,
            true,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn anchors_at_the_apex_of_pointed_cones_else_the_middle() {
        let c = |rb, rt| CappedCone::new(Vec3::ZERO, Vec3::Z, 2.0, rb, rt).unwrap();
        assert_eq!(c(1.0, 0.0).anchor(), (2.0, 0.0));
        assert_eq!(c(0.0, 1.0).anchor(), (0.0, 0.0));
        assert_eq!(c(1.0, 1.0).anchor(), (1.0, 1.0));
        assert_eq!(c(1.0, 0.5).anchor(), (1.0, 0.75));
        // Nearly pointed: the apex just above the top.
        let (s, r) = c(1.0, 0.25).anchor();
        assert!((s - 8.0 / 3.0).abs() < 1e-6 && r.abs() < 1e-6, "{s} {r}");
    }

    #[test]
    fn line_through_the_apex_keeps_an_outward_normal() {
        let c = CappedCone::new(Vec3::ZERO, Vec3::Z, 1.0, 0.5, 0.0).unwrap();
        let ray = Ray::new(Vec3::new(0.0, 0.0, -1.0), Vec3::Z);
        let s = c.stretch(&ray).unwrap();
        assert_eq!((s.t_in, s.part_in, s.n_in), (1.0, Part::Base, -Vec3::Z));
        assert!((s.t_out - 2.0).abs() < 1e-6);
        assert!(s.n_out.dot(Vec3::Z) > 0.0, "{:?}", s.n_out);
    }
}
