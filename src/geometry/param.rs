//! Surface parameterisations for texturing and bump mapping: the `(u, v)` of a point on
//! a primitive and the tangents `∂p/∂u`, `∂p/∂v` there.
//!
//! They are computed only when a textured material needs them (never in the
//! intersectors), from the accurate hit point and the unit outward geometric normal.
//! Every parameterisation is oriented so that `∂p/∂u × ∂p/∂v` points along the outward
//! normal; that orientation is the tangent frame of normal maps. The world is taken as
//! y-up where a shape has no axis of its own.
//!
//! | shape | (u, v) |
//! |---|---|
//! | sphere | `u = φ/2π` with `φ = atan2(x, z)` about the centre (u = 0 towards +z, growing towards +x), `v = 1 − θ/π` (1 at the +y pole, 0 at the −y pole) |
//! | open and capped cones, cylinders | `u` the angle around the axis / 2π, `v` the height along the axis / its length (0 at the base); caps: the disk mapped onto `[0, 1]²` |
//! | torus | `u` the angle around the axis / 2π (from [`Torus::frame`]'s first vector), `v` the angle around the tube / 2π (0 on the outer equator) |
//! | box, oriented box | each face onto `[0, 1]²`, upright (`v` along +y) on the side faces |
//! | plane, quadric, polyhedron, CSG | planar: world coordinates along two tangents of the normal's frame ([`Frame::from_z`]) |
//! | triangle | the barycentric interpolation of its vertices' `vt` (without `vt`: the barycentric coordinates `(u, v)` themselves) |
//!
//! At the poles of the sphere and the apex of a cone `∂p/∂u` vanishes; there it is
//! replaced by the tangent of the nearest regular point, so the frame never has a NaN.

use super::Triangle;
use crate::math::{Frame, Vec3};
use glam::Vec2;
use std::f32::consts::TAU;

/// A point's texture coordinates and surface tangents.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Param {
    /// Texture coordinates.
    pub uv: Vec2,
    /// `∂p/∂u` (world units per unit of `u`).
    pub dpdu: Vec3,
    /// `∂p/∂v`.
    pub dpdv: Vec3,
}

impl Param {
    /// The planar parameterisation about unit normal `n`: `u`, `v` are the coordinates
    /// of `p` along the first two vectors of [`Frame::from_z`]`(n)`.
    pub fn planar(p: Vec3, n: Vec3) -> Param {
        let f = Frame::from_z(n);
        Param {
            uv: Vec2::new(p.dot(f.x), p.dot(f.y)),
            dpdu: f.x,
            dpdv: f.y,
        }
    }
}

/// Smallest sine of the polar angle used for `∂p/∂u` (poles and apices).
pub(super) const MIN_SIN: f32 = 1e-4;

/// `atan2(y, x) / 2π` in `[0, 1)`.
#[inline]
pub(super) fn turn(y: f32, x: f32) -> f32 {
    let a = y.atan2(x) / TAU;
    if a < 0.0 {
        (a + 1.0).min(next_below_one())
    } else {
        a
    }
}

#[inline]
fn next_below_one() -> f32 {
    1.0 - f32::EPSILON / 2.0
}

/// Two unit vectors completing the unit `axis` to a right-handed frame `(e1, e2, axis)`.
pub(super) fn axis_frame(axis: Vec3) -> (Vec3, Vec3) {
    let f = Frame::from_z(axis);
    (f.x, f.y)
}

/// The cylindrical parameterisation about the axis through `base` with unit `axis`,
/// length `height` and radius growing by `slope` per unit of height.
pub(super) fn cylindrical(p: Vec3, base: Vec3, axis: Vec3, height: f32, slope: f32) -> Param {
    let (e1, e2) = axis_frame(axis);
    let q = p - base;
    let h = q.dot(axis);
    let (x, y) = (q.dot(e1), q.dot(e2));
    let rho = x.hypot(y);
    let phi = y.atan2(x);
    let (s, c) = phi.sin_cos();
    let radial = e1 * c + e2 * s;
    let tangent = e2 * c - e1 * s;
    Param {
        uv: Vec2::new(turn(y, x), h / height),
        dpdu: tangent * (TAU * rho.max(MIN_SIN * height)),
        dpdv: (axis + radial * slope) * height,
    }
}

/// The face parameterisation of a box with centre `c`, half extents `half` along the
/// unit axes `axes`, at `p` with unit outward normal `ng`.
pub(super) fn box_param(p: Vec3, ng: Vec3, c: Vec3, half: Vec3, axes: [Vec3; 3]) -> Param {
    let q = p - c;
    let local = Vec3::new(q.dot(axes[0]), q.dot(axes[1]), q.dot(axes[2]));
    let nl = Vec3::new(ng.dot(axes[0]), ng.dot(axes[1]), ng.dot(axes[2]));
    let k = nl.abs().max_position();
    let s = if nl[k] < 0.0 { -1.0 } else { 1.0 };
    // (u axis, u sign, v axis, v sign) on the +k face; the −k face mirrors u.
    let (ua, us, va, vs) = match k {
        0 => (2, -1.0, 1, 1.0),
        1 => (0, 1.0, 2, -1.0),
        _ => (0, 1.0, 1, 1.0),
    };
    let us = us * s;
    let (wu, wv) = (2.0 * half[ua], 2.0 * half[va]);
    Param {
        uv: Vec2::new(0.5 + us * local[ua] / wu, 0.5 + vs * local[va] / wv),
        dpdu: axes[ua] * (us * wu),
        dpdv: axes[va] * (vs * wv),
    }
}

impl Triangle {
    /// The parameterisation of the point with barycentric weights `(1 − b1 − b2, b1,
    /// b2)` given the vertices' texture coordinates `uv` (`None`: `(0,0)`, `(1,0)`,
    /// `(0,1)`). The tangents solve `p_i − p_0 = Δu_i ∂p/∂u + Δv_i ∂p/∂v`; when the
    /// texture coordinates are degenerate, the frame of the geometric normal is used.
    pub fn param(&self, b1: f32, b2: f32, uv: Option<&[Vec2; 3]>) -> Param {
        const UNIT: [Vec2; 3] = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let t = uv.unwrap_or(&UNIT);
        let w = 1.0 - b1 - b2;
        let uv_hit = t[0] * w + t[1] * b1 + t[2] * b2;
        let [p0, p1, p2] = self.p;
        let (d1, d2) = (t[1] - t[0], t[2] - t[0]);
        let (e1, e2) = (p1 - p0, p2 - p0);
        let det = d1.x * d2.y - d1.y * d2.x;
        let ng = e1.cross(e2);
        if det.abs() > 1e-20 * (d1.length_squared() * d2.length_squared()).sqrt() && det != 0.0 {
            let inv = 1.0 / det;
            let dpdu = (e1 * d2.y - e2 * d1.y) * inv;
            let dpdv = (e2 * d1.x - e1 * d2.x) * inv;
            if dpdu.is_finite() && dpdv.is_finite() && dpdu.cross(dpdv) != Vec3::ZERO {
                return Param {
                    uv: uv_hit,
                    dpdu,
                    dpdv,
                };
            }
        }
        let n = ng.normalize_or(Vec3::Z);
        let f = Frame::from_z(n);
        Param {
            uv: uv_hit,
            dpdu: f.x,
            dpdv: f.y,
        }
    }
}

/// The inverse of the bilinear map of the quadrilateral `q` (corners at `(0,0)`,
/// `(1,0)`, `(1,1)`, `(0,1)` in that order): the `(s, t)` with
/// `p = (1−s)(1−t) q0 + s(1−t) q1 + s t q2 + (1−s) t q3`, for `p` in (or near) the
/// quad's plane. `None` when no solution lies in the quad (within a small tolerance) or
/// the quad is degenerate.
///
/// The quad is projected onto the coordinate plane most nearly its own; `t` is a root
/// of `k2 t² + k1 t + k0 = 0` taken in the cancellation-free form
/// (`q = −(k1 + sign(k1)√D)/2`, roots `q/k2` and `k0/q`), and `s` comes from whichever
/// coordinate divides best.
pub fn inverse_bilinear(p: Vec3, q: [Vec3; 4]) -> Option<Vec2> {
    let n = (q[2] - q[0]).cross(q[3] - q[1]);
    let k = n.abs().max_position();
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let flat = |v: Vec3| glam::DVec2::new(f64::from(v[i]), f64::from(v[j]));
    let (a, b, c, d, x) = (flat(q[0]), flat(q[1]), flat(q[2]), flat(q[3]), flat(p));
    let cross = |u: glam::DVec2, v: glam::DVec2| u.x * v.y - u.y * v.x;
    let e = b - a;
    let f = d - a;
    let g = a - b + c - d;
    let h = x - a;
    let k2 = cross(g, f);
    let k1 = cross(e, f) + cross(h, g);
    let k0 = cross(h, e);
    let scale = e.length_squared().max(f.length_squared());
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    const TOL: f64 = 1e-6;
    let inside = |t: f64| (-TOL..=1.0 + TOL).contains(&t);
    let mut roots = [f64::NAN; 2];
    if k2.abs() <= 1e-12 * scale {
        // A parallelogram along t: linear.
        if k1 != 0.0 {
            roots[0] = -k0 / k1;
        }
    } else {
        let disc = k1 * k1 - 4.0 * k0 * k2;
        if disc < 0.0 {
            return None;
        }
        let qq = -0.5 * (k1 + disc.sqrt().copysign(k1));
        roots[0] = qq / k2;
        if qq != 0.0 {
            roots[1] = k0 / qq;
        }
    }
    for t in roots {
        if !t.is_finite() || !inside(t) {
            continue;
        }
        let den = e + g * t;
        let num = h - f * t;
        let s = if den.x.abs() >= den.y.abs() {
            num.x / den.x
        } else {
            num.y / den.y
        };
        if s.is_finite() && inside(s) {
            return Some(Vec2::new(s as f32, t as f32));
        }
    }
    None
}

/// A planar, convex quadrilateral face with texture coordinates at its corners, in
/// order: its points take the `(u, v)` of the bilinear patch through the corners (the
/// inverse bilinear map, then bilinear interpolation of the corners' `uv`), not the
/// per-triangle barycentric interpolation, which bends texture lines along the diagonal
/// of any quad that is not a parallelogram.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadUv {
    /// Corners, in the face's order.
    pub p: [Vec3; 4],
    /// Texture coordinates of the corners.
    pub uv: [Vec2; 4],
}

impl QuadUv {
    /// The record of the quad `p` with texture coordinates `uv`, or `None` unless it is
    /// convex (every corner turns the same way about its normal) and planar within
    /// 10⁻⁴ of its size (the distance of the diagonals from each other).
    pub fn new(p: [Vec3; 4], uv: [Vec2; 4]) -> Option<QuadUv> {
        let d = |v: Vec3| v.as_dvec3();
        let q = p.map(d);
        let n = (q[2] - q[0]).cross(q[3] - q[1]);
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        let n = n / len;
        for k in 0..4 {
            let (a, b, c) = (q[k], q[(k + 1) % 4], q[(k + 2) % 4]);
            if (b - a).cross(c - b).dot(n) <= 0.0 {
                return None;
            }
        }
        // The diagonals lie in parallel planes (normal n); their distance is the twist.
        let size = (q[2] - q[0]).length().max((q[3] - q[1]).length());
        if (q[1] - q[0]).dot(n).abs() > 1e-4 * size {
            return None;
        }
        uv.iter().all(|t| t.is_finite()).then_some(QuadUv { p, uv })
    }

    /// The parameterisation at `x`, a point on the quad: `None` when `x` maps outside
    /// it or the corners' texture coordinates are degenerate there (the caller falls
    /// back to the triangle's own).
    pub fn param(&self, x: Vec3) -> Option<Param> {
        let st = inverse_bilinear(x, self.p)?;
        let (s, t) = (st.x, st.y);
        let [p0, p1, p2, p3] = self.p;
        let [t0, t1, t2, t3] = self.uv;
        let uv = (t0 * (1.0 - s) + t1 * s) * (1.0 - t) + (t3 * (1.0 - s) + t2 * s) * t;
        let dp_ds = (p1 - p0) * (1.0 - t) + (p2 - p3) * t;
        let dp_dt = (p3 - p0) * (1.0 - s) + (p2 - p1) * s;
        let duv_ds = (t1 - t0) * (1.0 - t) + (t2 - t3) * t;
        let duv_dt = (t3 - t0) * (1.0 - s) + (t2 - t1) * s;
        // [∂p/∂u ∂p/∂v] = [∂p/∂s ∂p/∂t] J⁻¹ with J the Jacobian of (u, v) in (s, t).
        let det = duv_ds.x * duv_dt.y - duv_dt.x * duv_ds.y;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let dpdu = (dp_ds * duv_dt.y - dp_dt * duv_ds.y) / det;
        let dpdv = (dp_dt * duv_ds.x - dp_ds * duv_dt.x) / det;
        let ok = dpdu.is_finite() && dpdv.is_finite() && dpdu.cross(dpdv) != Vec3::ZERO;
        ok.then_some(Param { uv, dpdu, dpdv })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Cone, Primitive, Shape, Sphere, Torus};

    fn assert_frame_outward(param: &Param, n: Vec3) {
        let c = param.dpdu.cross(param.dpdv);
        assert!(c.is_finite() && c.dot(n) > 0.0, "{param:?} n={n}");
    }

    #[test]
    fn sphere_uv_and_orientation() {
        let s = Sphere::new(Vec3::new(1.0, 2.0, 3.0), 2.0);
        let at = |d: Vec3| s.param(s.center + d * 2.0, d);
        let z = at(Vec3::Z);
        assert!((z.uv - Vec2::new(0.0, 0.5)).length() < 1e-6);
        let x = at(Vec3::X);
        assert!((x.uv - Vec2::new(0.25, 0.5)).length() < 1e-6);
        assert!((at(Vec3::Y).uv.y - 1.0).abs() < 1e-6);
        assert!(at(-Vec3::Y).uv.y.abs() < 1e-6);
        for d in [
            Vec3::X,
            Vec3::Z,
            -Vec3::X,
            Vec3::new(0.3, 0.8, -0.5).normalize(),
        ] {
            assert_frame_outward(&at(d), d);
        }
        // The poles: finite, non-degenerate frames.
        for d in [Vec3::Y, -Vec3::Y] {
            assert_frame_outward(&at(d), d);
        }
        // ∂p/∂u is the derivative: a small step in u moves by it.
        let d = Vec3::new(0.3, 0.4, 0.5).normalize();
        let p = at(d);
        let phi = d.x.atan2(d.z) + 1e-3 * TAU;
        let th = d.y.acos();
        let d2 = Vec3::new(th.sin() * phi.sin(), th.cos(), th.sin() * phi.cos());
        let fd = (d2 - d) * 2.0 / 1e-3;
        assert!((fd - p.dpdu).length() < 1e-2 * p.dpdu.length());
    }

    #[test]
    fn torus_cylinder_and_box_frames_point_outwards() {
        let t = Torus::new(Vec3::ZERO, Vec3::Y, 2.0, 0.5).unwrap();
        let (ex, _, a) = t.frame();
        let outer = ex * 2.5;
        let p = t.param(outer, ex);
        assert!(p.uv.length() < 1e-6);
        assert_frame_outward(&p, ex);
        let top = ex * 2.0 + a * 0.5;
        let p = t.param(top, a);
        assert!((p.uv.y - 0.25).abs() < 1e-6);
        assert_frame_outward(&p, a);

        let c = Cone::new(Vec3::ZERO, 1.0, Vec3::new(0.0, 0.0, 4.0), 1.0);
        let p = c.param(Vec3::new(1.0, 0.0, 2.0), Vec3::X);
        assert!((p.uv.y - 0.5).abs() < 1e-6);
        assert_frame_outward(&p, Vec3::X);

        let b = Shape::Box(crate::geometry::AaBox::new(Vec3::ZERO, Vec3::ONE).unwrap());
        for n in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            let p = Vec3::splat(0.5) + n * 0.5 + Vec3::new(0.1, 0.2, 0.15) * (Vec3::ONE - n.abs());
            let prm = b.param(p, n);
            assert_frame_outward(&prm, n);
            assert!(prm.uv.min_element() >= 0.0 && prm.uv.max_element() <= 1.0);
        }
    }

    #[test]
    fn triangle_tangents_reproduce_the_edges() {
        let tri = Triangle {
            p: [
                Vec3::ZERO,
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 3.0, 0.0),
            ],
        };
        let uv = [
            Vec2::new(0.5, 0.5),
            Vec2::new(1.0, 0.5),
            Vec2::new(0.5, 1.0),
        ];
        let p = tri.param(0.25, 0.5, Some(&uv));
        assert!((p.uv - Vec2::new(0.625, 0.75)).length() < 1e-6);
        assert!((p.dpdu - Vec3::new(4.0, 0.0, 0.0)).length() < 1e-5);
        assert!((p.dpdv - Vec3::new(0.0, 6.0, 0.0)).length() < 1e-5);
        // Degenerate texture coordinates: a finite frame all the same.
        let flat = [Vec2::ZERO; 3];
        let p = tri.param(0.2, 0.2, Some(&flat));
        assert_frame_outward(&p, Vec3::Z);
    }

    #[test]
    fn quad_record_needs_a_planar_convex_quad() {
        let sq = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let uv = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
        let q = QuadUv::new(sq, uv).expect("a square");
        let prm = q.param(Vec3::new(0.25, 0.5, 0.0)).unwrap();
        assert!((prm.uv - Vec2::new(0.25, 0.5)).length() < 1e-6);
        assert!((prm.dpdu - Vec3::X).length() < 1e-6 && (prm.dpdv - Vec3::Y).length() < 1e-6);
        // Concave (corner 2 pushed inside), twisted, degenerate: no record.
        let concave = [sq[0], sq[1], Vec3::new(0.3, 0.3, 0.0), sq[3]];
        assert!(QuadUv::new(concave, uv).is_none());
        let twisted = [sq[0], sq[1], Vec3::new(1.0, 1.0, 0.1), sq[3]];
        assert!(QuadUv::new(twisted, uv).is_none());
        assert!(QuadUv::new([Vec3::ZERO; 4], uv).is_none());
        // Clockwise order is as good as counter-clockwise.
        assert!(QuadUv::new([sq[0], sq[3], sq[2], sq[1]], uv).is_some());
    }

    #[test]
    fn inverse_bilinear_of_a_square_and_misses() {
        let q = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let st = inverse_bilinear(Vec3::new(0.25, 0.75, 0.0), q).unwrap();
        assert!((st - Vec2::new(0.25, 0.75)).length() < 1e-6);
        assert!(inverse_bilinear(Vec3::new(2.0, 0.5, 0.0), q).is_none());
    }
}
