use super::{ShapeHit, SurfacePoint};
use crate::math::{Aabb, Ray, Vec3, gamma, gamma64};
use glam::Vec4;
use std::ops::{Add, Mul};

/// A triangle. Its front side is the one from which the vertices appear
/// counterclockwise; the geometric normal `(p1 − p0) × (p2 − p0)` points to it.
/// Intersection is two-sided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// The three vertices.
    pub p: [Vec3; 3],
}

/// A ray prepared for the watertight test (Woop, Benthin and Wald, JCGT 2013): the axis
/// of largest direction component becomes z and the other two are sheared away.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    org: Vec3,
    /// The direction itself, for the f64 fallback ([`refine_in_f64`]).
    dir: Vec3,
    k: [usize; 3],
    shear: Vec3,
    tmin: f32,
    tmax: f32,
}

impl WatertightRay {
    /// Precompute the permutation and shear for `ray`.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        // Arrays, not `Vec3` indexing (a match on the index in glam).
        let d = ray.dir.to_array();
        let a = ray.dir.abs();
        // The first axis of largest magnitude (as `Vec3::max_position` picks it).
        let (mut kz, mut largest) = (0, a.x);
        if a.y > largest {
            (kz, largest) = (1, a.y);
        }
        if a.z > largest {
            kz = 2;
        }
        let (mut kx, mut ky) = ([1, 2, 0][kz], [2, 0, 1][kz]);
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let dz = d[kz];
        WatertightRay {
            org: ray.org,
            dir: ray.dir,
            k: [kx, ky, kz],
            shear: Vec3::new(d[kx] / dz, d[ky] / dz, 1.0 / dz),
            tmin: ray.tmin,
            tmax: ray.tmax,
        }
    }

    /// Narrow the far end of the interval (after a closer hit).
    #[inline]
    pub fn set_tmax(&mut self, tmax: f32) {
        self.tmax = tmax;
    }

    /// Origin, axis permutation, shear and interval, for the 4-wide test
    /// ([`Triangle4`](super::Triangle4)).
    #[inline]
    pub(crate) fn parts(&self) -> (Vec3, [usize; 3], Vec3, f32, f32) {
        (self.org, self.k, self.shear, self.tmin, self.tmax)
    }
}

impl Triangle {
    /// Geometric normal `(p1 − p0) × (p2 − p0)`, not normalised.
    #[inline]
    pub fn normal(&self) -> Vec3 {
        (self.p[1] - self.p[0]).cross(self.p[2] - self.p[0])
    }

    /// Bounds.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.p[0], self.p[1]).grow(self.p[2])
    }

    /// Area.
    pub fn area(&self) -> f32 {
        0.5 * self.normal().length()
    }

    /// Watertight intersection: no ray passes between two triangles sharing an edge.
    /// Always inlined: it is the inner loop of the BVH's leaves and of every hit's
    /// exact recomputation ([`crate::scene::Geometry::exact_hit`]), whose cost should not
    /// depend on what else the caller inlines.
    #[inline(always)]
    pub fn intersect_wt(&self, r: &WatertightRay) -> Option<ShapeHit> {
        let [kx, ky, kz] = r.k;
        let a = (self.p[0] - r.org).to_array();
        let b = (self.p[1] - r.org).to_array();
        let c = (self.p[2] - r.org).to_array();
        let s = r.shear;
        let ax = a[kx] - s.x * a[kz];
        let ay = a[ky] - s.y * a[kz];
        let bx = b[kx] - s.x * b[kz];
        let by = b[ky] - s.y * b[kz];
        let cx = c[kx] - s.x * c[kz];
        let cy = c[ky] - s.y * c[kz];
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // Exactly on an edge in f32: decide it in f64, as the paper prescribes.
            let (ax, ay, bx, by, cx, cy) = (
                ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64,
            );
            u = (cx * by - cy * bx) as f32;
            v = (ax * cy - ay * cx) as f32;
            w = (bx * ay - by * ax) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let az = s.z * a[kz];
        let bz = s.z * b[kz];
        let cz = s.z * c[kz];
        let tt = u * az + v * bz + w * cz;
        let inv = 1.0 / det;
        let t = tt * inv;
        // NaN fails this too.
        let before_tmax = t < r.tmax;
        if !before_tmax {
            return None;
        }
        let delta_t = distance_error(
            [ax, ay, bx, by, cx, cy],
            [a[kz], b[kz], c[kz]],
            [az, bz, cz],
            [u, v, w],
            inv,
        );
        if !(t > delta_t && t > r.tmin) {
            // Too close to the start of the interval for f32 to tell which side the
            // hit is on (a huge triangle, or one seen edge-on, near the origin):
            // decide it in f64 unless it is certainly before the interval.
            if t + delta_t <= r.tmin.max(0.0) {
                return None;
            }
            return refine_in_f64(&self.p, r).map(|(t, u, v)| ShapeHit {
                t,
                u,
                v,
                ng: self.normal(),
            });
        }
        Some(ShapeHit {
            t,
            u: v * inv,
            v: w * inv,
            ng: self.normal(),
        })
    }

    /// The nearest hit in `(ray.tmin, ray.tmax)`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<ShapeHit> {
        self.intersect_wt(&WatertightRay::new(ray))
    }

    /// The point with barycentrics `(1 − u − v, u, v)` and its error bound.
    ///
    /// pbrt's bound γ₇ Σ|bᵢ pᵢ| (§6.8.4) covers the interpolation, but it is zero along an
    /// axis where all three vertices share a coordinate, and a ray starting exactly on
    /// the plane may then re-hit it at a rounding-level `t` (the plane distance is
    /// computed from edges as large as the triangle). So the bound also has a term
    /// relative to the largest vertex coordinate: still no fixed epsilon, it scales with
    /// the scene.
    pub fn surface(&self, u: f32, v: f32) -> SurfacePoint {
        let b0 = 1.0 - u - v;
        let p = self.p[0] * b0 + self.p[1] * u + self.p[2] * v;
        let magnitude = self.p[0].abs().max(self.p[1].abs()).max(self.p[2].abs());
        let err = ((self.p[0] * b0).abs() + (self.p[1] * u).abs() + (self.p[2] * v).abs())
            * gamma(7)
            + Vec3::splat(magnitude.max_element() * gamma(8));
        SurfacePoint {
            p,
            err,
            ng: self.normal().normalize_or_zero(),
        }
    }
}

/// The arithmetic of [`distance_error`]: f32 (the scalar test), four f32 lanes
/// ([`Triangle4`](super::Triangle4)) or f64 ([`refine_in_f64`]), each with its own
/// `max` and its own unit roundoff.
pub(crate) trait BoundArith: Copy + Add<Output = Self> + Mul<Output = Self> {
    fn abs(self) -> Self;
    fn max(self, other: Self) -> Self;
    /// The constant `v` in every lane.
    fn splat(v: f32) -> Self;
    /// γₙ in this type's precision.
    fn gamma(n: u32) -> Self;
}

/// `BoundArith` for a type with inherent `abs` and `max`, a constant from an f32 by
/// `$splat` and γₙ by `$gamma`.
macro_rules! bound_arith {
    ($t:ty, $splat:expr, $gamma:expr) => {
        impl BoundArith for $t {
            #[inline(always)]
            fn abs(self) -> $t {
                <$t>::abs(self)
            }
            #[inline(always)]
            fn max(self, other: $t) -> $t {
                <$t>::max(self, other)
            }
            #[inline(always)]
            fn splat(v: f32) -> $t {
                $splat(v)
            }
            #[inline(always)]
            fn gamma(n: u32) -> $t {
                $gamma(n)
            }
        }
    };
}

bound_arith!(f32, |v| v, gamma);
bound_arith!(Vec4, Vec4::splat, |n| Vec4::splat(gamma(n)));
bound_arith!(f64, f64::from, gamma64);

/// The bound on the rounding error of the watertight test's distance `t` (pbrt §6.8.7),
/// from the sheared vertex coordinates `xy` (`ax, ay, bx, by, cx, cy`), the vertices'
/// coordinates `z` along the ray's major axis before and `zt` after the scale by
/// `1/d[kz]`, the edge functions `uvw` and `inv = 1/(u + v + w)`.
///
/// A hit closer than this is rejected, so that a ray leaving the surface from a
/// robustly offset origin cannot re-hit it. The sheared x and y are lengths, with an
/// error relative to |x| + |z| before z is divided by the direction's z (|Sx·z| ≤ |z|
/// as |d[kx]| ≤ |d[kz]|); pbrt adds the divided z there, which makes the bound depend
/// on the direction's length: a shadow ray towards a light (an unnormalised direction)
/// in a scene 10⁻⁴ units across then found its blocker "within rounding of 0" and
/// passed through it.
#[inline(always)]
pub(crate) fn distance_error<T: BoundArith>(
    xy: [T; 6],
    z: [T; 3],
    zt: [T; 3],
    uvw: [T; 3],
    inv: T,
) -> T {
    let [ax, ay, bx, by, cx, cy] = xy;
    let max3 = |[a, b, c]: [T; 3]| a.abs().max(b.abs()).max(c.abs());
    let max_zt = max3(zt);
    let max_z = max3(z);
    let max_xt = max3([ax, bx, cx]);
    let max_yt = max3([ay, by, cy]);
    let delta_z = T::gamma(3) * max_zt;
    let delta_x = T::gamma(5) * (max_xt + max_z);
    let delta_y = T::gamma(5) * (max_yt + max_z);
    let delta_e =
        T::splat(2.0) * (T::gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    let max_e = max3(uvw);
    T::splat(3.0) * (T::gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv.abs()
}

/// The watertight test's distance and barycentrics recomputed in f64, for a ray whose
/// f32 distance is within its own rounding error of the start of its interval: a
/// triangle huge beside its distance from the origin (a floor a million units wide
/// seen from a metre above it), or seen so obliquely that its sheared image is a
/// sliver (an eye a few hundredths above a long triangle), makes that error larger
/// than the distance itself, and f32 cannot tell a hit ahead from one behind.
///
/// The edge functions' signs (inside or outside) were decided in f32 already and stay
/// decided: they are what keeps two triangles sharing an edge watertight. Only the
/// distance, its error bound (now 2²⁹ times smaller) and the barycentrics are
/// recomputed; the hit is kept if the f64 distance is beyond its own error and inside
/// the interval.
#[cold]
#[inline(never)]
pub(crate) fn refine_in_f64(p: &[Vec3; 3], r: &WatertightRay) -> Option<(f32, f32, f32)> {
    let [kx, ky, kz] = r.k;
    let org = r.org.as_dvec3();
    let d = r.dir.as_dvec3().to_array();
    let rel = |v: Vec3| (v.as_dvec3() - org).to_array();
    let (a, b, c) = (rel(p[0]), rel(p[1]), rel(p[2]));
    let (sx, sy, sz) = (d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
    let ax = a[kx] - sx * a[kz];
    let ay = a[ky] - sy * a[kz];
    let bx = b[kx] - sx * b[kz];
    let by = b[ky] - sy * b[kz];
    let cx = c[kx] - sx * c[kz];
    let cy = c[ky] - sy * c[kz];
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let (az, bz, cz) = (sz * a[kz], sz * b[kz], sz * c[kz]);
    let inv = 1.0 / det;
    let t = (u * az + v * bz + w * cz) * inv;
    let delta_t = distance_error(
        [ax, ay, bx, by, cx, cy],
        [a[kz], b[kz], c[kz]],
        [az, bz, cz],
        [u, v, w],
        inv,
    );
    let t32 = t as f32;
    let (bary1, bary2) = ((v * inv) as f32, (w * inv) as f32);
    (t > delta_t && t32 > r.tmin.max(0.0) && t32 < r.tmax).then_some((t32, bary1, bary2))
}
