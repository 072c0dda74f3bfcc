//! The torus: the points at distance `minor` from a circle of radius `major`.
//!
//! # Numerics
//!
//! The ray is taken to the torus's frame, its direction normalised and its origin moved
//! along the line to the point nearest the centre (twice, so the re-based origin is
//! perpendicular to the direction to f64 precision), and all lengths are divided by
//! `major + minor`. The quartic along the line then has no cubic term and O(1)
//! coefficients, and every root lies within the bounding sphere, `|s| ≤ S`.
//!
//! The roots are found without any closed-form solution (Ferrari's loses roots to
//! cancellation): the roots of the quadratic `f''` split `[−S, S]` into pieces where
//! `f'` is monotone, the roots of `f'` found in those split it into pieces where `f` is
//! monotone, and each piece whose ends differ in sign holds exactly one root, found by
//! safeguarded Newton iteration (bisection whenever a Newton step would leave the
//! bracket or converge slowly). Newton on a bracket converges to the last bits, so it is
//! also the polish. `f` itself is evaluated in its factored form
//! `f = g·h`, `g = (ρ − R)² + z² − r²`, `h = (ρ + R)² + z² − r²` (`ρ` the distance from
//! the axis), which is much better conditioned near the surface than the expanded
//! polynomial; `f'` and `f''` come from the polynomial.
//!
//! A simple root is never lost; only double roots (exactly tangent rays) may be reported
//! as two close crossings or none. For self-intersecting (spindle) tori, `minor ≥
//! major`, `h` vanishes on the inner lemon, which lies inside the solid: the crossings
//! are the roots where the sign of `g` (inside or outside the solid), tested between
//! consecutive roots, changes.

use super::param::{MIN_SIN, turn};
use super::quadric::{
    aabb_out, check_finite, check_positive, gamma64, outward_or_dir, rounding_err, unit_axis,
    unit_f32,
};
use super::{Intersect, Param, Primitive, Shape, ShapeError, ShapeHit, Span, Spans, SurfacePoint};
use crate::math::{Aabb, DVec3, Ray, Vec3, similarity_scale};
use glam::{DAffine3, Vec2};
use std::sync::Arc;
use std::f64::consts::TAU;

/// A torus around `axis` through `center`: the circle of radius `major` in the plane
/// perpendicular to the axis, thickened by `minor`. As a solid, the points within
/// `minor` of that circle.
///
/// `u` of a hit is the angle around the axis and `v` the angle around the tube, both
/// divided by 2π into `[0, 1)`: `u = 0` in the direction of [`Torus::frame`]'s first
/// vector, `v = 0` on the outer equator, growing towards the side `axis` points to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Torus {
    /// Centre, f64.
    center: DVec3,
    /// Unit axis.
    axis: DVec3,
    /// First tangent of the frame (`u = 0`).
    ex: DVec3,
    /// Second tangent of the frame (`u = 1/4`).
    ey: DVec3,
    /// Radius of the centre circle.
    major: f64,
    /// Radius of the tube.
    minor: f64,
    /// Centre as given.
    center32: Vec3,
    /// Conservative bounds.
    bounds: Aabb,
}

/// A ray's line in the torus's normalised frame and its crossings with the surface.
struct TorusLine {
    /// Re-based origin (normalised local coordinates).
    p: DVec3,
    /// Unit local direction.
    dn: DVec3,
    /// Distance along the unit direction from the ray origin to `p` (world units).
    t0: f64,
    /// `|ray.dir|`.
    len: f64,
    /// Roots in normalised units from `p`, with whether the line leaves the solid.
    xs: [(f64, bool); 4],
    /// Number of crossings.
    n: usize,
}

impl Torus {
    /// A torus; `axis` need not be unit (it is normalised in f64). Errors: non-finite
    /// values, a zero axis, non-positive radii.
    pub fn new(center: Vec3, axis: Vec3, major: f32, minor: f32) -> Result<Self, ShapeError> {
        check_finite("torus centre", center)?;
        let w = unit_axis("torus axis", axis)?;
        check_positive("torus major radius", major)?;
        check_positive("torus minor radius", minor)?;
        let (ex, ey) = w.any_orthonormal_pair();
        let (rr, r) = (major as f64, minor as f64);
        let c = center.as_dvec3();
        // Half-extent of the centre circle along axis k: R·√(1 − w_k²); plus the tube.
        let k = (DVec3::ONE - w * w).max(DVec3::ZERO);
        let half = DVec3::new(k.x.sqrt(), k.y.sqrt(), k.z.sqrt()) * rr + DVec3::splat(r);
        let slack = (half + c.abs()) * 1e-14;
        Ok(Torus {
            center: c,
            axis: w,
            ex,
            ey,
            major: rr,
            minor: r,
            center32: center,
            bounds: aabb_out(c - half - slack, c + half + slack),
        })
    }

    /// Centre.
    pub fn center(&self) -> Vec3 {
        self.center32
    }

    /// Unit axis.
    pub fn axis(&self) -> Vec3 {
        self.axis.as_vec3()
    }

    /// Radius of the centre circle.
    pub fn major_radius(&self) -> f32 {
        self.major as f32
    }

    /// Radius of the tube.
    pub fn minor_radius(&self) -> f32 {
        self.minor as f32
    }

    /// The orthonormal frame `(x, y, axis)` of the texture parameters: `u = 0` along `x`,
    /// `u = 1/4` along `y`.
    pub fn frame(&self) -> (Vec3, Vec3, Vec3) {
        (self.ex.as_vec3(), self.ey.as_vec3(), self.axis.as_vec3())
    }

    /// `(ρ − R)² + z² − r²` at world point `p`: negative inside, positive outside.
    pub fn value(&self, p: DVec3) -> f64 {
        let l = self.local(p - self.center);
        let rho = l.x.hypot(l.y);
        (rho - self.major).powi(2) + l.z * l.z - self.minor * self.minor
    }

    /// A world vector in the local frame.
    #[inline]
    fn local(&self, v: DVec3) -> DVec3 {
        DVec3::new(v.dot(self.ex), v.dot(self.ey), v.dot(self.axis))
    }

    /// A local vector in world coordinates.
    #[inline]
    fn world(&self, v: DVec3) -> DVec3 {
        self.ex * v.x + self.ey * v.y + self.axis * v.z
    }

    /// The line of `ray` and its crossings, or `None` for non-finite or zero rays.
    fn line(&self, ray: &Ray) -> Option<TorusLine> {
        if !(ray.org.is_finite() && ray.dir.is_finite()) {
            return None;
        }
        let d = ray.dir.as_dvec3();
        let len = d.length();
        if len == 0.0 {
            return None;
        }
        let sigma = self.major + self.minor;
        let dn = self.local(d / len);
        let ol = self.local(ray.org.as_dvec3() - self.center);
        let mut t0 = -ol.dot(dn);
        let mut p = ol + dn * t0;
        let e = p.dot(dn);
        t0 -= e;
        p -= dn * e;
        let mut line = TorusLine {
            p: p / sigma,
            dn,
            t0,
            len,
            xs: [(0.0, false); 4],
            n: 0,
        };
        self.solve(&mut line);
        Some(line)
    }

    /// Fills in the crossings of `line` (see the module documentation).
    fn solve(&self, line: &mut TorusLine) {
        let sigma = self.major + self.minor;
        let (rn, sn) = (self.major / sigma, self.minor / sigma);
        let (p, dn) = (line.p, line.dn);
        // Slightly beyond the bounding sphere, where f > 0 strictly.
        let bound = 1.0 + 1e-9;
        let pp = p.length_squared();
        if pp >= bound * bound {
            return;
        }
        let s_max = (bound * bound - pp).sqrt();
        let (rn2, sn2) = (rn * rn, sn * sn);
        let k = pp + rn2 - sn2;
        let axy = dn.x * dn.x + dn.y * dn.y;
        let bxy = p.x * dn.x + p.y * dn.y;
        // f(s) = s⁴ + c2·s² + c1·s + c0 (no cubic term: p ⊥ dn).
        let c2 = 2.0 * k - 4.0 * rn2 * axy;
        let c1 = -8.0 * rn2 * bxy;
        let gh = |s: f64| {
            let q = p + dn * s;
            // Normalised coordinates are O(1): no overflow, and sqrt is much cheaper.
            let rho = (q.x * q.x + q.y * q.y).sqrt();
            let z2 = q.z * q.z;
            let g = (rho - rn) * (rho - rn) + z2 - sn2;
            let h = (rho + rn) * (rho + rn) + z2 - sn2;
            (g, h)
        };
        let f = |s: f64| {
            let (g, h) = gh(s);
            g * h
        };
        let f1 = |s: f64| (4.0 * s * s + 2.0 * c2) * s + c1;
        let f2 = |s: f64| 12.0 * s * s + 2.0 * c2;

        // Pieces where f' is monotone: split at the roots of f''.
        let mut cuts: smallvec::SmallVec<[f64; 4]> = smallvec::smallvec![-s_max];
        if c2 < 0.0 {
            let i = (-c2 / 6.0).sqrt();
            if i < s_max {
                cuts.extend([-i, i]);
            }
        }
        cuts.push(s_max);
        // Pieces where f is monotone: split at the roots of f'.
        let mut crit: smallvec::SmallVec<[f64; 5]> = smallvec::smallvec![-s_max];
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let (fa, fb) = (f1(a), f1(b));
            if (fa > 0.0) != (fb > 0.0) {
                crit.push(bracket_root(|s| (f1(s), f2(s)), (a, b), (fa, fb), 1e-12));
            }
        }
        crit.push(s_max);
        let mut roots: smallvec::SmallVec<[f64; 4]> = Default::default();
        // In normalised units, 1e-15 is at the f64 resolution of f's terms (O(1)).
        let mut fa = f(crit[0]);
        for w in crit.windows(2) {
            let fb = f(w[1]);
            if (fa > 0.0) != (fb > 0.0) && roots.len() < 4 {
                let fun = |s: f64| (f(s), f1(s));
                roots.push(bracket_root(fun, (w[0], w[1]), (fa, fb), 1e-15));
            }
            fa = fb;
        }
        // Keep the roots where the line goes in or out of the solid (g changes sign):
        // for ring tori all of them, for spindle tori not those of the inner lemon.
        let mut inside = false;
        for (k, &s) in roots.iter().enumerate() {
            let next_inside = match roots.get(k + 1) {
                Some(&s1) => gh(0.5 * (s + s1)).0 <= 0.0,
                None => false,
            };
            if next_inside != inside {
                line.xs[line.n] = (s, inside);
                line.n += 1;
                inside = next_inside;
            }
        }
    }

    /// Ray parameter of a crossing at normalised `s`.
    #[inline]
    fn t_of(&self, line: &TorusLine, s: f64) -> f64 {
        (line.t0 + s * (self.major + self.minor)) / line.len
    }

    /// Local (normalised) point, outward normal in world space, and `(u, v)` at `s`.
    fn at(&self, line: &TorusLine, s: f64, exit: bool) -> (Vec3, f32, f32) {
        let rn = self.major / (self.major + self.minor);
        let q = line.p + line.dn * s;
        let rho = (q.x * q.x + q.y * q.y).sqrt();
        let radial = if rho > 0.0 {
            DVec3::new(q.x / rho, q.y / rho, 0.0)
        } else {
            DVec3::ZERO
        };
        let n_local = radial * (rho - rn) + DVec3::new(0.0, 0.0, q.z);
        let ng = outward_or_dir(self.world(n_local), self.world(line.dn), exit);
        let u = q.y.atan2(q.x) / TAU;
        let v = q.z.atan2(rho - rn) / TAU;
        (ng, wrap01(u), wrap01(v))
    }

    /// The first crossing accepted by the ray interval.
    fn first(&self, ray: &Ray) -> Option<(TorusLine, f32, f64, bool)> {
        let line = self.line(ray)?;
        for k in 0..line.n {
            let (s, exit) = line.xs[k];
            let t = self.t_of(&line, s) as f32;
            if t > ray.tmin && t < ray.tmax {
                return Some((line, t, s, exit));
            }
        }
        None
    }
}

/// `x` moved into `[0, 1)` by adding 1 to negative values.
fn wrap01(x: f64) -> f32 {
    let x = if x < 0.0 { x + 1.0 } else { x };
    // Rounding of x + 1 for tiny negative x can give exactly 1.
    let x = x as f32;
    if x >= 1.0 { 0.0 } else { x }
}

/// The root of a function monotone on `[lo, hi]` whose values `f_lo`, `f_hi` at the two
/// ends differ in sign, by safeguarded Newton iteration (`fun` returns the value and the
/// derivative) from the regula falsi point: Newton steps while they stay inside the
/// shrinking bracket and at least halve the step, bisection otherwise (Numerical
/// Recipes' `rtsafe`). Stops once a step is below `tol` (absolute) or the bracket
/// cannot shrink further.
fn bracket_root(
    fun: impl Fn(f64) -> (f64, f64),
    (lo, hi): (f64, f64),
    (f_lo, f_hi): (f64, f64),
    tol: f64,
) -> f64 {
    let pos_lo = f_lo > 0.0;
    let (mut lo, mut hi) = (lo, hi);
    let guess = lo + (hi - lo) * (f_lo / (f_lo - f_hi));
    let mut x = if guess > lo && guess < hi {
        guess
    } else {
        0.5 * (lo + hi)
    };
    let mut dx_old = hi - lo;
    let mut dx = dx_old;
    let (mut fx, mut dfx) = fun(x);
    for _ in 0..100 {
        if fx == 0.0 {
            return x;
        }
        if (fx > 0.0) == pos_lo {
            lo = x;
        } else {
            hi = x;
        }
        let newton = x - fx / dfx;
        let use_newton = newton > lo && newton < hi && (2.0 * fx).abs() <= (dx_old * dfx).abs();
        dx_old = dx;
        let x_new = if use_newton {
            dx = fx / dfx;
            newton
        } else {
            dx = 0.5 * (hi - lo);
            lo + dx
        };
        if x_new == x || dx.abs() <= tol {
            return x_new;
        }
        x = x_new;
        (fx, dfx) = fun(x);
    }
    x
}

impl Intersect for Torus {
    /// Conservative bounds: the box of the centre circle grown by the tube radius,
    /// rounded outwards.
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The nearest hit in `(ray.tmin, ray.tmax)`, from either side; `ng` is the unit
    /// outward normal.
    fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        let (line, t, s, exit) = self.first(ray)?;
        let (ng, u, v) = self.at(&line, s, exit);
        Some(ShapeHit { t, u, v, ng })
    }

    /// Whether a hit lies in `(ray.tmin, ray.tmax)`.
    fn occluded(&self, ray: &Ray) -> bool {
        self.first(ray).is_some()
    }

    /// The hit point put back onto the torus in f64 (re-solved along the ray within the
    /// rounding of `t`, then projected to the nearest point of the tube's circle in the
    /// point's meridian plane, or for a spindle torus whose projection would cross the
    /// axis to the cusp where the surface meets it), rounded to f32, with the bound of
    /// that rounding plus the f64 error.
    fn surface(&self, ray: &Ray, hit: &ShapeHit) -> SurfacePoint {
        let d = ray.dir.as_dvec3();
        let p0 = ray.org.as_dvec3() + d * hit.t as f64;
        let p0 = if p0.is_finite() { p0 } else { self.center };
        let (rr, r) = (self.major, self.minor);
        // First back onto the ray's own crossing, if it is within the rounding of t:
        // Newton on the signed distance along the ray (its gradient is the unit normal).
        let mut q = self.local(p0 - self.center);
        let dl = d.length();
        if dl > 0.0 {
            let u = self.local(d / dl);
            let t_ulp = (hit.t.abs() * f32::EPSILON) as f64 * dl;
            let mut x = q;
            let mut moved = 0.0f64;
            for _ in 0..4 {
                let rho = x.x.hypot(x.y);
                let (a, z) = (rho - rr, x.z);
                let dist = a.hypot(z);
                if rho == 0.0 || dist == 0.0 {
                    break;
                }
                let n = DVec3::new(a * x.x / (rho * dist), a * x.y / (rho * dist), z / dist);
                let step = (dist - r) / n.dot(u);
                if !step.is_finite() {
                    break;
                }
                x -= u * step;
                moved -= step;
                if step.abs() <= 1e-17 * (rr + r) {
                    break;
                }
            }
            if x.is_finite() && moved.abs() <= 4.0 * t_ulp {
                q = x;
            }
        }
        let rho = q.x.hypot(q.y);
        // The meridian half-plane through q (any one on the axis).
        let radial = if rho > 0.0 {
            DVec3::new(q.x / rho, q.y / rho, 0.0)
        } else {
            DVec3::X
        };
        // Meridian coordinates relative to the tube's centre circle.
        let (a, z) = (rho - rr, q.z);
        let dist = a.hypot(z);
        let (pa, pz, na, nz) = if dist > 0.0 {
            let (na, nz) = (a / dist, z / dist);
            if rr + r * na >= 0.0 {
                (r * na, r * nz, na, nz)
            } else {
                // A spindle torus's tube circle crosses the axis: its end is the cusp,
                // where the outside is the dimple along the axis.
                let zc = (r * r - rr * rr).max(0.0).sqrt().copysign(z);
                (-rr, zc, 0.0, 1.0f64.copysign(z))
            }
        } else {
            (r, 0.0, 1.0, 0.0)
        };
        let local = radial * (rr + pa) + DVec3::new(0.0, 0.0, pz);
        let p = self.center + self.world(local);
        let scale = self.center.abs().max_element() + rr + r;
        let delta = gamma64(16) * (scale + p.abs().max_element());
        let ng = unit_f32(self.world(radial * na + DVec3::new(0.0, 0.0, nz)))
            .or_else(|| hit.ng.try_normalize())
            .unwrap_or(Vec3::Z);
        let p32 = p.as_vec3();
        SurfacePoint {
            p: p32,
            err: rounding_err(p32, delta),
            ng,
        }
    }
}

impl Primitive for Torus {
    fn is_solid(&self) -> bool {
        true
    }

    /// The solid's spans along the whole line of `ray` (at most two).
    fn spans(&self, ray: &Ray, out: &mut Spans) {
        let Some(line) = self.line(ray) else {
            return;
        };
        for pair in line.xs[..line.n].chunks_exact(2) {
            let (s_in, s_out) = (pair[0].0, pair[1].0);
            out.push(Span {
                t_in: self.t_of(&line, s_in) as f32,
                n_in: self.at(&line, s_in, false).0,
                t_out: self.t_of(&line, s_out) as f32,
                n_out: self.at(&line, s_out, true).0,
            });
        }
    }

    /// Whether `p` is inside the solid.
    fn contains(&self, p: Vec3) -> bool {
        self.value(p.as_dvec3()) <= 0.0
    }

    /// The toroidal parameterisation at `p`.
    fn param(&self, p: Vec3, _ng: Vec3) -> Param {
        let (ex, ey, a) = self.frame();
        let (big, small) = (self.major_radius(), self.minor_radius());
        let q = p - self.center();
        let (x, y, z) = (q.dot(ex), q.dot(ey), q.dot(a));
        let rho = x.hypot(y);
        let phi = y.atan2(x);
        let psi = z.atan2(rho - big);
        let (sp, cp) = phi.sin_cos();
        let (ss, cs) = psi.sin_cos();
        let radial = ex * cp + ey * sp;
        let tangent = ey * cp - ex * sp;
        Param {
            uv: Vec2::new(turn(y, x), turn(z, rho - big)),
            dpdu: tangent * (std::f32::consts::TAU * (big + small * cs).max(MIN_SIN * small)),
            dpdv: (a * cs - radial * ss) * (std::f32::consts::TAU * small),
        }
    }

    /// Under a similarity: the centre moved, the axis turned, the radii scaled.
    fn bake(&self, m: &DAffine3) -> Option<Shape> {
        let k = similarity_scale(m)?;
        Torus::new(
            m.transform_point3(self.center().as_dvec3()).as_vec3(),
            (m.matrix3 * self.axis().as_dvec3()).as_vec3(),
            (self.major_radius() as f64 * k) as f32,
            (self.minor_radius() as f64 * k) as f32,
        )
        .ok()
        .map(|t| Arc::new(t).into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bracket_root_finds_simple_roots() {
        let f = |x: f64| (x * x - 2.0, 2.0 * x);
        let r = bracket_root(f, (0.0, 2.0), (-2.0, 2.0), 1e-15);
        assert!((r - 2f64.sqrt()).abs() < 1e-15);
        // A flat function (a root of multiplicity 7): bisection still converges.
        let g = |x: f64| ((x - 0.3).powi(7), 7.0 * (x - 0.3).powi(6));
        let r = bracket_root(g, (0.0, 1.0), (g(0.0).0, g(1.0).0), 1e-15);
        assert!((r - 0.3).abs() < 1e-6);
    }

    #[test]
    fn rejects_bad_input() {
        assert!(Torus::new(Vec3::ZERO, Vec3::ZERO, 1.0, 0.5).is_err());
        assert!(Torus::new(Vec3::ZERO, Vec3::Z, 0.0, 0.5).is_err());
        assert!(Torus::new(Vec3::ZERO, Vec3::Z, 1.0, -0.5).is_err());
        assert!(Torus::new(Vec3::splat(f32::NAN), Vec3::Z, 1.0, 0.5).is_err());
        assert!(Torus::new(Vec3::ZERO, Vec3::Z, f32::INFINITY, 0.5).is_err());
    }
}
